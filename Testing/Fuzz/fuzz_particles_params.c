/* libFuzzer harness: gr_particles_params_validate. No OpenCL is touched.
 *
 * Input layout (missing bytes read as 0): byte 0 picks how the 15 fields of
 * gr_particles_params (kind, count, rain_rate, exposure_time, seed,
 * flutter_amplitude, wind[3], region[6]) are made, byte 1 the length of a
 * small message buffer, then:
 *   mode 0  every field from raw bytes (4 per int, 8 per double), so NaN,
 *           infinities, subnormals and huge values appear;
 *   mode 1  the defaults (gr_particles_params_init) with the fields whose
 *           bit is set in the next 2 bytes read raw, as in mode 0;
 *   mode 2  one byte per field picks an edge value: NaN, infinities,
 *           extremes, a fixed value, or a table row's min, max, default or
 *           one ulp beyond.
 *
 * Checks: the status is GR_OK or GR_ERR_INVALID_ARGUMENT; a failure comes
 * with a non-empty message ending in '.'; parameters are accepted exactly
 * when the kind is rain or snow, every tabled field lies in its row of the
 * parameter table (gr_particles_param_bounds), every wind component within
 * +-GR_PARTICLES_MAX_WIND and every axis of the region finite, within 1e9 m
 * and of a size above 0 in float; a short message buffer is never overrun
 * and is always terminated; the answer does not depend on the buffer. */
#include "fuzz_common.h"
#include "graupel/particles.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* The fields in declaration order. */
static const fuzz_field fields[] = {FUZZ_FIELD_I(gr_particles_params, kind),
                                    FUZZ_FIELD_I(gr_particles_params, count),
                                    FUZZ_FIELD_D(gr_particles_params, rain_rate),
                                    FUZZ_FIELD_D(gr_particles_params, exposure_time),
                                    FUZZ_FIELD_I(gr_particles_params, seed),
                                    FUZZ_FIELD_D(gr_particles_params, flutter_amplitude),
                                    FUZZ_FIELD_D(gr_particles_params, wind[0]),
                                    FUZZ_FIELD_D(gr_particles_params, wind[1]),
                                    FUZZ_FIELD_D(gr_particles_params, wind[2]),
                                    FUZZ_FIELD_D(gr_particles_params, region[0]),
                                    FUZZ_FIELD_D(gr_particles_params, region[1]),
                                    FUZZ_FIELD_D(gr_particles_params, region[2]),
                                    FUZZ_FIELD_D(gr_particles_params, region[3]),
                                    FUZZ_FIELD_D(gr_particles_params, region[4]),
                                    FUZZ_FIELD_D(gr_particles_params, region[5])};
#define NFIELDS ((int)(sizeof fields / sizeof fields[0]))
/* The table row of fields 1..5 (kind, wind and region are checked apart). */
static const char *const rows[] = {NULL,           "Count", "RainRate",
                                   "ExposureTime", "Seed",  "FlutterAmplitude"};

/* The harness's own statement of the rules outside the table. */
static int region_axis_ok(double lo, double hi) {
  return isfinite(lo) && isfinite(hi) && hi > lo && (float)hi - (float)lo > 0.0f &&
         fabs(lo) < 1e9 && fabs(hi) < 1e9;
}

static gr_status validate(const void *p, char *msg, size_t len) {
  return gr_particles_params_validate((const gr_particles_params *)p, msg, len);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static const double fixed[] = {0.0, -0.0, 1.0, -1.0, 0.5, 100.0, -100.0, 1e9, 1e300, 2.0};
  gr_particles_params p;
  reader r;
  int n = 0;
  const gr_param_bound *table = gr_particles_param_bounds(&n);
  REQUIRE(table != NULL && n == 5);

  r.p = data;
  r.n = size;
  int mode = take_byte(&r) % 3;
  size_t small_len = take_byte(&r) % 96;
  memset(&p, 0, sizeof p);
  if (mode == 1)
    gr_particles_params_init(&p);
  fuzz_fill(&r, mode, &p, fields, NFIELDS, table, n, fixed, sizeof fixed / sizeof fixed[0]);

  int documented = p.kind == GR_PARTICLES_RAIN || p.kind == GR_PARTICLES_SNOW;
  for (int f = 1; f < 6; ++f)
    documented &= fuzz_in_row(fuzz_row(table, n, rows[f]), fuzz_field_value(&p, &fields[f]));
  for (int c = 0; c < 3; ++c) {
    documented &= fabs(p.wind[c]) <= GR_PARTICLES_MAX_WIND;
    documented &= region_axis_ok(p.region[2 * c], p.region[2 * c + 1]);
  }
  fuzz_check_validator(validate, &p, documented, small_len);
  return 0;
}
