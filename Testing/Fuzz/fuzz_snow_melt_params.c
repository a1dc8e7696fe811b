/* libFuzzer harness: gr_snow_melt_params_validate. No OpenCL is touched.
 *
 * Input layout (missing bytes read as 0): byte 0 picks how the 19 fields of
 * gr_snow_melt_params (in declaration order) are made, byte 1 the length of
 * a small message buffer, then:
 *   mode 0  every field from raw bytes (4 per int, 8 per double), so NaN,
 *           infinities, subnormals and huge values appear;
 *   mode 1  the defaults (gr_snow_melt_params_init) with those of the first
 *           16 fields whose bit is set in the next 2 bytes read raw;
 *   mode 2  one byte per field picks an edge value: NaN, infinities,
 *           extremes, or a table row's min, max, default or one ulp beyond.
 *
 * Checks: the status is GR_OK or GR_ERR_INVALID_ARGUMENT; a failure comes
 * with a non-empty message ending in '.'; parameters are accepted exactly
 * when every one lies in its row of the parameter table
 * (gr_snow_melt_param_bounds) and MaxDensity is at least NewSnowDensity (the
 * one rule across rows); a short message buffer is never overrun and is
 * always terminated; the answer does not depend on the buffer. */
#include "fuzz_common.h"
#include "graupel/snow_melt.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* The fields in declaration order. */
static const fuzz_field fields[] = {FUZZ_FIELD_D(gr_snow_melt_params, latitude),
                                    FUZZ_FIELD_I(gr_snow_melt_params, start_day),
                                    FUZZ_FIELD_D(gr_snow_melt_params, start_hour),
                                    FUZZ_FIELD_D(gr_snow_melt_params, time_step),
                                    FUZZ_FIELD_D(gr_snow_melt_params, melt_factor),
                                    FUZZ_FIELD_D(gr_snow_melt_params, radiation_factor),
                                    FUZZ_FIELD_D(gr_snow_melt_params, threshold),
                                    FUZZ_FIELD_D(gr_snow_melt_params, lapse_rate),
                                    FUZZ_FIELD_D(gr_snow_melt_params, reference_elevation),
                                    FUZZ_FIELD_D(gr_snow_melt_params, transmissivity),
                                    FUZZ_FIELD_D(gr_snow_melt_params, rain_snow_threshold),
                                    FUZZ_FIELD_D(gr_snow_melt_params, rain_snow_band),
                                    FUZZ_FIELD_D(gr_snow_melt_params, new_snow_density),
                                    FUZZ_FIELD_D(gr_snow_melt_params, max_density),
                                    FUZZ_FIELD_D(gr_snow_melt_params, settling_time),
                                    FUZZ_FIELD_D(gr_snow_melt_params, liquid_capacity),
                                    FUZZ_FIELD_D(gr_snow_melt_params, refreeze_factor),
                                    FUZZ_FIELD_I(gr_snow_melt_params, cast_shadows),
                                    FUZZ_FIELD_I(gr_snow_melt_params, horizon_sectors)};
#define NFIELDS ((int)(sizeof fields / sizeof fields[0]))
/* The table row of each field. */
static const char *const rows[] = {"Latitude",
                                   "StartDayOfYear",
                                   "StartHour",
                                   "TimeStep",
                                   "MeltFactor",
                                   "RadiationFactor",
                                   "ThresholdTemperature",
                                   "LapseRate",
                                   "ReferenceElevation",
                                   "Transmissivity",
                                   "RainSnowThreshold",
                                   "RainSnowBand",
                                   "NewSnowDensity",
                                   "MaxDensity",
                                   "SettlingTime",
                                   "LiquidWaterCapacity",
                                   "RefreezeFactor",
                                   "CastShadows",
                                   "HorizonSectors"};

static gr_status validate(const void *p, char *msg, size_t len) {
  return gr_snow_melt_params_validate((const gr_snow_melt_params *)p, msg, len);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static const double fixed[] = {0.0, -0.0, 1.0, -1.0, 0.5, 90.0, 3600.0, 864000.0, 1e300, 450.0};
  gr_snow_melt_params p;
  reader r;
  int n = 0;
  const gr_param_bound *table = gr_snow_melt_param_bounds(&n);
  REQUIRE(table != NULL && n == NFIELDS);

  r.p = data;
  r.n = size;
  int mode = take_byte(&r) % 3;
  size_t small_len = take_byte(&r) % 96;
  memset(&p, 0, sizeof p);
  if (mode == 1)
    gr_snow_melt_params_init(&p);
  fuzz_fill(&r, mode, &p, fields, NFIELDS, table, n, fixed, sizeof fixed / sizeof fixed[0]);

  int documented = 1;
  for (int f = 0; f < NFIELDS; ++f)
    documented &= fuzz_in_row(fuzz_row(table, n, rows[f]), fuzz_field_value(&p, &fields[f]));
  documented &= p.max_density >= p.new_snow_density;
  fuzz_check_validator(validate, &p, documented, small_len);
  return 0;
}
