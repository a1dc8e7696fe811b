/* libFuzzer harness: gr_terrain_analysis_params_validate. No OpenCL is
 * touched.
 *
 * Input layout (missing bytes read as 0): byte 0 picks how the 9 fields of
 * gr_terrain_analysis_params (in declaration order) are made, byte 1 the
 * length of a small message buffer, then:
 *   mode 0  every field from raw bytes (4 per int, 8 per double), so NaN,
 *           infinities, subnormals and huge values appear;
 *   mode 1  the defaults (gr_terrain_analysis_params_init) with the fields
 *           whose bit is set in the next 2 bytes read raw, as in mode 0;
 *   mode 2  one byte per field picks an edge value: NaN, infinities,
 *           extremes, or a table row's min, max, default or one ulp beyond.
 *
 * Checks: the status is GR_OK or GR_ERR_INVALID_ARGUMENT; a failure comes
 * with a non-empty message ending in '.'; parameters are accepted exactly
 * when every one lies in its row of the parameter table
 * (gr_terrain_analysis_param_bounds, which the XML, the VTK clamps and the
 * docs pages follow); a short message buffer is never overrun and is always
 * terminated; the answer does not depend on the buffer. */
#include "fuzz_common.h"
#include "graupel/terrain_analysis.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* The fields in declaration order. */
static const fuzz_field fields[] = {FUZZ_FIELD_D(gr_terrain_analysis_params, sun_azimuth),
                                    FUZZ_FIELD_D(gr_terrain_analysis_params, sun_elevation),
                                    FUZZ_FIELD_D(gr_terrain_analysis_params, snow_exponent),
                                    FUZZ_FIELD_I(gr_terrain_analysis_params, cover_mode),
                                    FUZZ_FIELD_D(gr_terrain_analysis_params, snow_cover_limit),
                                    FUZZ_FIELD_D(gr_terrain_analysis_params, rock_slope),
                                    FUZZ_FIELD_D(gr_terrain_analysis_params, water_level),
                                    FUZZ_FIELD_I(gr_terrain_analysis_params, model_shadows),
                                    FUZZ_FIELD_D(gr_terrain_analysis_params, penumbra_width)};
#define NFIELDS ((int)(sizeof fields / sizeof fields[0]))
/* The table row of each field. */
static const char *const rows[] = {"SunAzimuth", "SunElevation",   "SnowExponent",
                                   "CoverMode",  "SnowCoverLimit", "RockSlope",
                                   "WaterLevel", "ModelShadows",   "PenumbraWidth"};

static gr_status validate(const void *p, char *msg, size_t len) {
  return gr_terrain_analysis_params_validate((const gr_terrain_analysis_params *)p, msg, len);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static const double fixed[] = {0.0, -0.0, 1.0, -1.0, 0.5, 90.0, 360.0, 1e300, -1e300, 2.0};
  gr_terrain_analysis_params p;
  reader r;
  int n = 0;
  const gr_param_bound *table = gr_terrain_analysis_param_bounds(&n);
  REQUIRE(table != NULL && n == NFIELDS);

  r.p = data;
  r.n = size;
  int mode = take_byte(&r) % 3;
  size_t small_len = take_byte(&r) % 96;
  memset(&p, 0, sizeof p);
  if (mode == 1)
    gr_terrain_analysis_params_init(&p);
  fuzz_fill(&r, mode, &p, fields, NFIELDS, table, n, fixed, sizeof fixed / sizeof fixed[0]);

  int documented = 1;
  for (int f = 0; f < NFIELDS; ++f)
    documented &= fuzz_in_row(fuzz_row(table, n, rows[f]), fuzz_field_value(&p, &fields[f]));
  fuzz_check_validator(validate, &p, documented, small_len);
  return 0;
}
