/* libFuzzer harness: gr_rain_runoff_params_validate and
 * gr_rain_runoff_field_validate. No OpenCL is touched.
 *
 * Input layout (missing bytes read as 0): byte 0 picks the mode, byte 1 the
 * length of a small message buffer, byte 2 the field to validate, then:
 *   mode 0  the six parameters from raw bytes (8 per double, 4 for the
 *           boundary enum), so NaN, infinities and huge values appear;
 *   mode 1  one byte per parameter picks from a table of edge values (range
 *           ends, one ulp either side, 0, -0, NaN, infinities);
 * and the rest of the input is the field, as raw floats.
 *
 * Checks: the status is GR_OK or GR_ERR_INVALID_ARGUMENT; a failure comes with
 * a non-empty message ending in '.'; parameters are accepted exactly when they
 * lie in the ranges rain_runoff.h documents, fields exactly when every value
 * is finite and, for the depth, permeability and rain-rate inputs, within
 * their documented ranges; outputs-only fields are refused; a short message
 * buffer is never overrun and always terminated. */
#include "fuzz_common.h"
#include "graupel/rain_runoff.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static double edge_double(uint8_t b) {
  static const double table[] = {0.0,  -0.0, 1e-3,   1e-2, 0.005, 1.0,    3600.0, 2.7777e-6,
                                 0.03, 0.7,  -1e-12, 1e30, -1.0,  3601.0, 0.5,    2.0};
  const size_t n = sizeof table / sizeof table[0];
  switch (b % (n + 12)) {
  case 0:
    return NAN;
  case 1:
    return INFINITY;
  case 2:
    return -INFINITY;
  case 3:
    return DBL_MAX;
  case 4:
    return nextafter(0.0, 1.0);
  case 5:
    return nextafter(1e-3, 1.0);
  case 6:
    return nextafter(1e-2, 1.0);
  case 7:
    return nextafter(0.005, 0.0);
  case 8:
    return nextafter(1.0, 2.0);
  case 9:
    return nextafter(3600.0, 4000.0);
  case 10:
    return nextafter(0.0, -1.0);
  case 11:
    return DBL_MIN;
  default:
    return table[b % (n + 12) - 12];
  }
}

static int in_range(double v, double lo, double hi) {
  return v >= lo && v <= hi;
}

/* rain_runoff.h's documented ranges. */
static int params_documented(const gr_rain_runoff_params *p) {
  int boundary;
  memcpy(&boundary, &p->boundary, sizeof boundary);
  return in_range(p->rain_rate, 0.0, 1e-3) && in_range(p->permeability, 0.0, 1e-2) &&
         in_range(p->manning_n, 0.005, 1.0) && p->cfl > 0.0 && p->cfl <= 1.0 && p->max_dt > 0.0 &&
         p->max_dt <= 3600.0 && (boundary == GR_BOUNDARY_OPEN || boundary == GR_BOUNDARY_CLOSED);
}

static int field_documented(gr_field f, const float *v, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    const double x = v[i];
    if (!isfinite(x))
      return 0;
    if (f == GR_FIELD_WATER_DEPTH && !(x >= 0.0))
      return 0;
    if (f == GR_FIELD_PERMEABILITY && !in_range(x, 0.0, 1e-2))
      return 0;
    if (f == GR_FIELD_RAIN_RATE && !in_range(x, 0.0, 1e-3))
      return 0;
  }
  return 1;
}

static int is_input(gr_field f) {
  return f == GR_FIELD_ELEVATION || f == GR_FIELD_WATER_DEPTH || f == GR_FIELD_PERMEABILITY ||
         f == GR_FIELD_RAIN_RATE;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  reader r = {data, size};
  gr_rain_runoff_params p;
  char msg[1024];
  const int mode = take_byte(&r) % 2;
  const size_t small_len = take_byte(&r) % 96;
  const gr_field f = (gr_field)(take_byte(&r) % (GR_FIELD_COUNT + 1));
  double *d[5];

  memset(&p, 0, sizeof p);
  d[0] = &p.rain_rate;
  d[1] = &p.permeability;
  d[2] = &p.manning_n;
  d[3] = &p.cfl;
  d[4] = &p.max_dt;
  for (int k = 0; k < 5; ++k) {
    if (mode == 0)
      take(&r, d[k], sizeof(double));
    else
      *d[k] = edge_double(take_byte(&r));
  }
  if (mode == 0) {
    take(&r, &p.boundary, sizeof(int));
  } else {
    int b = (int)take_byte(&r) % 4 - 1; /* -1, 0, 1, 2 */
    memcpy(&p.boundary, &b, sizeof b);
  }

  msg[0] = '\0';
  const gr_status sp = gr_rain_runoff_params_validate(&p, msg, sizeof msg);
  check_message(sp, msg);
  REQUIRE((sp == GR_OK) == params_documented(&p));
  REQUIRE(gr_rain_runoff_params_validate(&p, NULL, 0) == sp);

  /* The rest of the input is the field (a copy, so it is aligned). */
  const size_t n = r.n / sizeof(float);
  float *values = (float *)malloc((n > 0 ? n : 1) * sizeof(float));
  REQUIRE(values != NULL);
  if (n > 0)
    memcpy(values, r.p, n * sizeof(float));
  msg[0] = '\0';
  const gr_status sf = gr_rain_runoff_field_validate(f, values, n, msg, sizeof msg);
  check_message(sf, msg);
  if (!is_input(f))
    REQUIRE(sf == GR_ERR_INVALID_ARGUMENT);
  else
    REQUIRE((sf == GR_OK) == field_documented(f, values, n));
  REQUIRE(gr_rain_runoff_field_validate(f, values, n, NULL, 0) == sf);

  /* A short heap buffer (AddressSanitizer sees an overrun): the same
   * answers, and a terminated message. */
  if (small_len > 0) {
    char *small = (char *)malloc(small_len);
    REQUIRE(small != NULL);
    memset(small, 'x', small_len);
    REQUIRE(gr_rain_runoff_params_validate(&p, small, small_len) == sp);
    if (sp != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
    memset(small, 'x', small_len);
    REQUIRE(gr_rain_runoff_field_validate(f, values, n, small, small_len) == sf);
    if (sf != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
    free(small);
  }
  free(values);

  /* No parameters, no values. */
  msg[0] = '\0';
  check_message(gr_rain_runoff_params_validate(NULL, msg, sizeof msg), msg);
  REQUIRE(msg[0] != '\0');
  msg[0] = '\0';
  check_message(gr_rain_runoff_field_validate(GR_FIELD_ELEVATION, NULL, 4, msg, sizeof msg), msg);
  REQUIRE(msg[0] != '\0');
  return 0;
}
