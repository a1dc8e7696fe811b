/* libFuzzer harness: gr_snow_deformation_params_validate and
 * gr_snow_deformation_field_validate. No OpenCL is touched.
 *
 * Input layout (missing bytes read as 0): byte 0 picks the mode, byte 1 the
 * length of a small message buffer, byte 2 the field to validate, byte 3 the
 * row length nx, then:
 *   mode 0  the nine parameters from raw bytes (8 per double, 4 per int), so
 *           NaN, infinities and huge values appear;
 *   mode 1  one byte per parameter picks an edge value: a bound of any row
 *           of the parameter table (gr_snow_deformation_param_bounds) in the
 *           core's unit, one ulp either side, or 0, -0, NaN, infinities;
 * and the rest of the input is the field, as raw floats.
 *
 * Checks: the status is GR_OK or GR_ERR_INVALID_ARGUMENT; a failure comes with
 * a non-empty message ending in '.'; parameters are accepted exactly when they
 * lie in the table's ranges (open minimum and whole numbers where a row says
 * so) and MinDensity <= InitialDensity <= MaxDensity; fields exactly when
 * every value is finite and within the documented range (elevations +-1e6 m,
 * depths 0 to 1e4 m, densities within [min, max] as floats; a density field
 * needs parameters); other fields are refused; a short message buffer is never
 * overrun and always terminated. */
#include "fuzz_common.h"
#include "graupel/snow_deformation.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static const gr_param_bound *row_of(const char *property) {
  int n = 0;
  const gr_param_bound *t = gr_snow_deformation_param_bounds(&n);
  return fuzz_row(t, n, property);
}

static double edge_double(uint8_t b) {
  static const double fixed[] = {0.0, -0.0, -1e-12, 1e30, -1.0, 0.5, 150.0, 400.0};
  int n = 0;
  const gr_param_bound *t = gr_snow_deformation_param_bounds(&n);
  return fuzz_table_edge(t, n, fixed, sizeof fixed / sizeof fixed[0], b);
}

static int in_row(const char *property, double v) {
  return fuzz_in_row(row_of(property), v);
}

static int params_documented(const gr_snow_deformation_params *p) {
  return in_row("InitialSnowDepth", p->initial_snow_depth) &&
         in_row("InitialDensity", p->initial_density) && in_row("MinDensity", p->min_density) &&
         in_row("MaxDensity", p->max_density) &&
         in_row("CompressionModel", (double)p->compression_model) &&
         in_row("MaxSlope", p->max_slope) && in_row("DirectionFalloff", p->direction_falloff) &&
         in_row("MaxRelaxIterations", (double)p->max_relax_iterations) &&
         in_row("RelaxTolerance", p->relax_tolerance) && in_row("SlumpSpeed", p->slump_speed) &&
         p->min_density <= p->max_density && p->initial_density >= p->min_density &&
         p->initial_density <= p->max_density;
}

static int field_documented(const gr_snow_deformation_params *p, gr_field f, const float *v,
                            size_t n) {
  double lo = -1e6, hi = 1e6;
  if (f == GR_FIELD_SNOW_DEPTH)
    lo = 0.0, hi = 1e4;
  if (f == GR_FIELD_SNOW_DENSITY) {
    if (!p)
      return 0;
    lo = (double)(float)p->min_density, hi = (double)(float)p->max_density;
  }
  for (size_t i = 0; i < n; ++i) {
    const double x = v[i];
    if (!isfinite(x) || !(x >= lo && x <= hi))
      return 0;
  }
  return 1;
}

static int is_input(gr_field f) {
  return f == GR_FIELD_ELEVATION || f == GR_FIELD_SNOW_DEPTH || f == GR_FIELD_SNOW_DENSITY;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  reader r = {data, size};
  gr_snow_deformation_params p;
  char msg[1024];
  const int mode = take_byte(&r) % 2;
  const size_t small_len = take_byte(&r) % 96;
  const gr_field f = (gr_field)(take_byte(&r) % (GR_FIELD_COUNT + 1));
  const size_t nx = take_byte(&r) % 17;
  double *d[8];
  int *in[2];

  memset(&p, 0, sizeof p);
  d[0] = &p.initial_snow_depth;
  d[1] = &p.initial_density;
  d[2] = &p.min_density;
  d[3] = &p.max_density;
  d[4] = &p.max_slope;
  d[5] = &p.direction_falloff;
  d[6] = &p.relax_tolerance;
  d[7] = &p.slump_speed;
  in[0] = &p.compression_model;
  in[1] = &p.max_relax_iterations;
  for (int k = 0; k < 8; ++k) {
    if (mode == 0)
      take(&r, d[k], sizeof(double));
    else
      *d[k] = edge_double(take_byte(&r));
  }
  for (int k = 0; k < 2; ++k) {
    if (mode == 0) {
      take(&r, in[k], sizeof(int));
    } else {
      static const int ints[] = {-1, 0, 1, 2, 200, 100000, 100001, 0x7fffffff};
      *in[k] = ints[take_byte(&r) % 8];
    }
  }

  msg[0] = '\0';
  const gr_status sp = gr_snow_deformation_params_validate(&p, msg, sizeof msg);
  check_message(sp, msg);
  REQUIRE((sp == GR_OK) == params_documented(&p));
  REQUIRE(gr_snow_deformation_params_validate(&p, NULL, 0) == sp);

  /* The rest of the input is the field (a copy, so it is aligned); checked
   * against these parameters and against none. */
  const size_t n = r.n / sizeof(float);
  float *values = (float *)malloc((n > 0 ? n : 1) * sizeof(float));
  REQUIRE(values != NULL);
  if (n > 0)
    memcpy(values, r.p, n * sizeof(float));
  gr_status sf = GR_OK;
  for (int with = 0; with < 2; ++with) {
    const gr_snow_deformation_params *pp = with ? &p : NULL;
    msg[0] = '\0';
    sf = gr_snow_deformation_field_validate(pp, f, values, n, nx, msg, sizeof msg);
    check_message(sf, msg);
    if (!is_input(f))
      REQUIRE(sf == GR_ERR_INVALID_ARGUMENT);
    else
      REQUIRE((sf == GR_OK) == field_documented(pp, f, values, n));
    REQUIRE(gr_snow_deformation_field_validate(pp, f, values, n, nx, NULL, 0) == sf);
  }

  if (small_len > 0) {
    char *small = (char *)malloc(small_len);
    REQUIRE(small != NULL);
    memset(small, 'x', small_len);
    REQUIRE(gr_snow_deformation_params_validate(&p, small, small_len) == sp);
    if (sp != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
    memset(small, 'x', small_len);
    REQUIRE(gr_snow_deformation_field_validate(&p, f, values, n, nx, small, small_len) == sf);
    if (sf != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
    free(small);
  }
  free(values);

  msg[0] = '\0';
  check_message(gr_snow_deformation_params_validate(NULL, msg, sizeof msg), msg);
  REQUIRE(msg[0] != '\0');
  msg[0] = '\0';
  check_message(
      gr_snow_deformation_field_validate(NULL, GR_FIELD_ELEVATION, NULL, 4, 2, msg, sizeof msg),
      msg);
  REQUIRE(msg[0] != '\0');
  return 0;
}
