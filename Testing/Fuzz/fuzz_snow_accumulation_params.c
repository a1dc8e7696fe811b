/* libFuzzer harness: gr_snow_accumulation_params_validate and
 * gr_snow_accumulation_field_validate. No OpenCL is touched.
 *
 * Input layout (missing bytes read as 0): byte 0 picks the mode, byte 1 the
 * length of a small message buffer, byte 2 the field to validate, byte 3 the
 * row length nx, then:
 *   mode 0  the parameters from raw bytes (8 per double, 4 per int: the
 *           direction's three components, then the rows' values), so NaN,
 *           infinities and huge values appear;
 *   mode 1  one byte per value picks an edge value: a bound of any row of
 *           the parameter table (gr_snow_accumulation_param_bounds) in the
 *           core's unit, one ulp either side, or 0, -0, NaN, infinities;
 * and the rest of the input is the field, as raw floats.
 *
 * Checks: the status is GR_OK or GR_ERR_INVALID_ARGUMENT; a failure comes with
 * a non-empty message ending in '.'; parameters are accepted exactly when they
 * lie in the table's ranges (open minimum and whole numbers where a row says
 * so) and the direction is finite, not zero and at most
 * GR_SNOW_ACCUMULATION_MAX_TILT degrees from straight down; fields exactly
 * when every value is finite and within the documented range (elevations
 * +-1e6 m, depths 0 to 1e4 m); other fields are refused; a short message
 * buffer is never overrun and always terminated. */
#include "fuzz_common.h"
#include "graupel/snow_accumulation.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static const gr_param_bound *row_of(const char *property) {
  int n = 0;
  const gr_param_bound *t = gr_snow_accumulation_param_bounds(&n);
  return fuzz_row(t, n, property);
}

static double edge_double(uint8_t b) {
  static const double fixed[] = {0.0, -0.0, -1e-12, 1e30, -1.0, 0.5, 1.0, -0.9659258262890683};
  int n = 0;
  const gr_param_bound *t = gr_snow_accumulation_param_bounds(&n);
  return fuzz_table_edge(t, n, fixed, sizeof fixed / sizeof fixed[0], b);
}

static int in_row(const char *property, double v) {
  return fuzz_in_row(row_of(property), v);
}

/* The harness's own statement of the direction rule. */
static int direction_documented(const double *d) {
  double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!isfinite(d[0]) || !isfinite(d[1]) || !isfinite(d[2]) || !isfinite(len) || len < 1e-9)
    return 0;
  return -d[2] / len >= cos(GR_SNOW_ACCUMULATION_MAX_TILT * 3.14159265358979323846 / 180.0);
}

static int params_documented(const gr_snow_accumulation_params *p) {
  return in_row("Flutter", p->flutter) && in_row("SnowfallRate", p->snowfall_rate) &&
         in_row("NoiseAmplitude", p->noise_amplitude) && in_row("NoiseScale", p->noise_scale) &&
         in_row("Seed", (double)p->seed) &&
         in_row("ExposureResolution", (double)p->exposure_resolution) &&
         in_row("BlurRadius", (double)p->blur_radius) && in_row("Dilation", (double)p->dilation) &&
         in_row("MaxDepth", p->max_depth) && in_row("StabilityFactor", p->stability_factor) &&
         in_row("SnowDensity", p->snow_density) &&
         in_row("AccumulationTextureSize", (double)p->texture_size) &&
         direction_documented(p->direction);
}

static int field_documented(gr_field f, const float *v, size_t n) {
  double lo = -1e6, hi = 1e6;
  if (f == GR_FIELD_SNOW_DEPTH)
    lo = 0.0, hi = 1e4;
  for (size_t i = 0; i < n; ++i) {
    const double x = v[i];
    if (!isfinite(x) || !(x >= lo && x <= hi))
      return 0;
  }
  return 1;
}

static int is_input(gr_field f) {
  return f == GR_FIELD_ELEVATION || f == GR_FIELD_SNOW_DEPTH;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  reader r = {data, size};
  gr_snow_accumulation_params p;
  char msg[1024];
  const int mode = take_byte(&r) % 2;
  const size_t small_len = take_byte(&r) % 96;
  const gr_field f = (gr_field)(take_byte(&r) % (GR_FIELD_COUNT + 1));
  const size_t nx = take_byte(&r) % 17;
  double *d[10];
  int *in[5];

  memset(&p, 0, sizeof p);
  d[0] = &p.direction[0];
  d[1] = &p.direction[1];
  d[2] = &p.direction[2];
  d[3] = &p.flutter;
  d[4] = &p.snowfall_rate;
  d[5] = &p.noise_amplitude;
  d[6] = &p.noise_scale;
  d[7] = &p.max_depth;
  d[8] = &p.stability_factor;
  d[9] = &p.snow_density;
  in[0] = &p.seed;
  in[1] = &p.exposure_resolution;
  in[2] = &p.blur_radius;
  in[3] = &p.dilation;
  in[4] = &p.texture_size;
  for (int k = 0; k < 10; ++k) {
    if (mode == 0)
      take(&r, d[k], sizeof(double));
    else
      *d[k] = edge_double(take_byte(&r));
  }
  for (int k = 0; k < 5; ++k) {
    if (mode == 0) {
      take(&r, in[k], sizeof(int));
    } else {
      static const int ints[] = {-1, 0, 1, 2, 16, 17, 1024, 65536, 65537, 0x7fffffff};
      *in[k] = ints[take_byte(&r) % 10];
    }
  }

  msg[0] = '\0';
  const gr_status sp = gr_snow_accumulation_params_validate(&p, msg, sizeof msg);
  check_message(sp, msg);
  REQUIRE((sp == GR_OK) == params_documented(&p));
  REQUIRE(gr_snow_accumulation_params_validate(&p, NULL, 0) == sp);

  /* The rest of the input is the field (a copy, so it is aligned). */
  const size_t n = r.n / sizeof(float);
  float *values = (float *)malloc((n > 0 ? n : 1) * sizeof(float));
  REQUIRE(values != NULL);
  if (n > 0)
    memcpy(values, r.p, n * sizeof(float));
  msg[0] = '\0';
  const gr_status sf = gr_snow_accumulation_field_validate(f, values, n, nx, msg, sizeof msg);
  check_message(sf, msg);
  if (!is_input(f))
    REQUIRE(sf == GR_ERR_INVALID_ARGUMENT);
  else
    REQUIRE((sf == GR_OK) == field_documented(f, values, n));
  REQUIRE(gr_snow_accumulation_field_validate(f, values, n, nx, NULL, 0) == sf);

  if (small_len > 0) {
    char *small = (char *)malloc(small_len);
    REQUIRE(small != NULL);
    memset(small, 'x', small_len);
    REQUIRE(gr_snow_accumulation_params_validate(&p, small, small_len) == sp);
    if (sp != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
    memset(small, 'x', small_len);
    REQUIRE(gr_snow_accumulation_field_validate(f, values, n, nx, small, small_len) == sf);
    if (sf != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
    free(small);
  }
  free(values);

  msg[0] = '\0';
  check_message(gr_snow_accumulation_params_validate(NULL, msg, sizeof msg), msg);
  REQUIRE(msg[0] != '\0');
  msg[0] = '\0';
  check_message(
      gr_snow_accumulation_field_validate(GR_FIELD_ELEVATION, NULL, 4, 2, msg, sizeof msg), msg);
  REQUIRE(msg[0] != '\0');
  return 0;
}
