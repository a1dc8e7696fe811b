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

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define NFIELDS 15

/* Field kinds in order: 'i' int, 'd' double. */
static const char kinds[] = "iiddid"
                            "ddd"
                            "dddddd";
/* The table row of each field; NULL for the fields the table does not hold. */
static const char *const rows[NFIELDS] = {NULL,           "Count", "RainRate",
                                          "ExposureTime", "Seed",  "FlutterAmplitude"};

static void *field_ptr(gr_particles_params *p, int f) {
  switch (f) {
  case 0:
    return &p->kind;
  case 1:
    return &p->count;
  case 2:
    return &p->rain_rate;
  case 3:
    return &p->exposure_time;
  case 4:
    return &p->seed;
  case 5:
    return &p->flutter_amplitude;
  default:
    return f < 9 ? (void *)&p->wind[f - 6] : (void *)&p->region[f - 9];
  }
}

static double field_value(gr_particles_params *p, int f) {
  if (kinds[f] == 'd') {
    double v;
    memcpy(&v, field_ptr(p, f), sizeof v);
    return v;
  }
  int v;
  memcpy(&v, field_ptr(p, f), sizeof v);
  return v;
}

/* The harness's own statement of the rules outside the table. */
static int region_axis_ok(double lo, double hi) {
  return isfinite(lo) && isfinite(hi) && hi > lo && (float)hi - (float)lo > 0.0f &&
         fabs(lo) < 1e9 && fabs(hi) < 1e9;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static const double fixed[] = {0.0, -0.0, 1.0, -1.0, 0.5, 100.0, -100.0, 1e9, 1e300, 2.0};
  gr_particles_params p;
  reader r;
  char msg[1024];
  int n = 0;
  const gr_param_bound *table = gr_particles_param_bounds(&n);
  REQUIRE(table != NULL && n == 5);

  r.p = data;
  r.n = size;
  int mode = take_byte(&r) % 3;
  size_t small_len = take_byte(&r) % 96;
  memset(&p, 0, sizeof p);
  if (mode == 1) {
    uint8_t bits[2];
    gr_particles_params_init(&p);
    take(&r, bits, sizeof bits);
    for (int f = 0; f < NFIELDS; ++f)
      if (bits[f / 8] & (1u << (f % 8)))
        take(&r, field_ptr(&p, f), kinds[f] == 'd' ? sizeof(double) : sizeof(int));
  } else {
    for (int f = 0; f < NFIELDS; ++f) {
      if (mode == 0) {
        take(&r, field_ptr(&p, f), kinds[f] == 'd' ? sizeof(double) : sizeof(int));
      } else {
        double v = fuzz_table_edge(table, n, fixed, sizeof fixed / sizeof fixed[0], take_byte(&r));
        if (kinds[f] == 'd') {
          memcpy(field_ptr(&p, f), &v, sizeof v);
        } else {
          int iv = isfinite(v) && fabs(v) < 2e9 ? (int)v : -1;
          memcpy(field_ptr(&p, f), &iv, sizeof iv);
        }
      }
    }
  }

  int documented = p.kind == GR_PARTICLES_RAIN || p.kind == GR_PARTICLES_SNOW;
  for (int f = 1; f < 6; ++f)
    documented &= fuzz_in_row(fuzz_row(table, n, rows[f]), field_value(&p, f));
  for (int c = 0; c < 3; ++c) {
    documented &= fabs(p.wind[c]) <= GR_PARTICLES_MAX_WIND;
    documented &= region_axis_ok(p.region[2 * c], p.region[2 * c + 1]);
  }

  msg[0] = '\0';
  gr_status sp = gr_particles_params_validate(&p, msg, sizeof msg);
  check_message(sp, msg);
  REQUIRE((sp == GR_OK) == documented);

  REQUIRE(gr_particles_params_validate(&p, NULL, 0) == sp);
  REQUIRE(gr_particles_params_validate(&p, NULL, 64) == sp);
  char *small = (char *)malloc(small_len > 0 ? small_len : 1);
  REQUIRE(small != NULL);
  if (small_len > 0) {
    memset(small, 'x', small_len);
    REQUIRE(gr_particles_params_validate(&p, small, small_len) == sp);
    if (sp != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
  }
  free(small);

  msg[0] = '\0';
  check_message(gr_particles_params_validate(NULL, msg, sizeof msg), msg);
  REQUIRE(msg[0] != '\0');
  return 0;
}
