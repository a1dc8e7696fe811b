/* libFuzzer harness: gr_rain_runoff_params_validate and
 * gr_rain_runoff_field_validate. No OpenCL is touched.
 *
 * Input layout (missing bytes read as 0): byte 0 picks the mode, byte 1 the
 * length of a small message buffer, byte 2 the field to validate, then:
 *   mode 0  the parameters from raw bytes (8 per double: the seven and the
 *           four edges' levels; 4 for each of the four edges' kinds, the
 *           flow model and the no-data kind), so NaN, infinities and huge
 *           values appear;
 *   mode 1  one byte per parameter picks an edge value: a bound of any row
 *           of the parameter table (gr_rain_runoff_param_bounds) in the
 *           core's unit, one ulp either side, or 0, -0, NaN, infinities;
 * and the rest of the input is the field, as raw floats.
 *
 * Checks: the status is GR_OK or GR_ERR_INVALID_ARGUMENT; a failure comes with
 * a non-empty message ending in '.'; parameters are accepted exactly when they
 * lie in the table's ranges (user bounds times to_core; open minimum and
 * whole numbers where a row says so) and, for FlowModel 1 (local inertial),
 * ManningN is at least 0.005; fields exactly when every value is
 * finite (or, for elevations, NaN: a no-data cell) and, for the depth, permeability and rain-rate
 * inputs, within the RainRate and Permeability rows' ranges (velocities within +-1000 m/s);
 * outputs-only fields are refused; a short message
 * buffer is never overrun and always terminated. */
#include "fuzz_common.h"
#include "graupel/rain_runoff.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static const gr_param_bound *row_of(const char *property) {
  int n = 0;
  const gr_param_bound *t = gr_rain_runoff_param_bounds(&n);
  return fuzz_row(t, n, property);
}

static double edge_double(uint8_t b) {
  static const double fixed[] = {0.0, -0.0, -1e-12, 1e30, -1.0, 0.5, 2.0, 7200.0};
  int n = 0;
  const gr_param_bound *t = gr_rain_runoff_param_bounds(&n);
  return fuzz_table_edge(t, n, fixed, sizeof fixed / sizeof fixed[0], b);
}

static int in_row(const char *property, double v) {
  return fuzz_in_row(row_of(property), v);
}

static int params_documented(const gr_rain_runoff_params *p) {
  static const char *const kinds[4] = {"BoundaryWest", "BoundaryEast", "BoundarySouth",
                                       "BoundaryNorth"};
  static const char *const levels[4] = {"LevelWest", "LevelEast", "LevelSouth", "LevelNorth"};
  int model, no_data;
  memcpy(&model, &p->flow_model, sizeof model);
  memcpy(&no_data, &p->no_data, sizeof no_data);
  if (!in_row("NoDataBoundary", (double)no_data))
    return 0;
  for (int e = 0; e < 4; ++e) {
    int kind;
    memcpy(&kind, &p->boundary[e], sizeof kind);
    if (!in_row(kinds[e], (double)kind) || !in_row(levels[e], p->boundary_level[e]))
      return 0;
  }
  return in_row("RainRate", p->rain_rate) && in_row("Permeability", p->permeability) &&
         in_row("ManningN", p->manning_n) && in_row("CourantNumber", p->cfl) &&
         in_row("MaxTimeStep", p->max_dt) && in_row("FlowModel", (double)model) &&
         in_row("WettingDepth", p->wetting_depth) && in_row("DebrisFactor", p->debris_factor) &&
         (model != 1 || p->manning_n >= 0.005);
}

static int field_documented(gr_field f, const float *v, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    const double x = v[i];
    if (f == GR_FIELD_ELEVATION && isnan(x))
      continue; /* a no-data cell */
    if (!isfinite(x))
      return 0;
    if (f == GR_FIELD_WATER_DEPTH && !(x >= 0.0))
      return 0;
    if (f == GR_FIELD_PERMEABILITY && !in_row("Permeability", x))
      return 0;
    if (f == GR_FIELD_RAIN_RATE && !in_row("RainRate", x))
      return 0;
    if (f == GR_FIELD_VELOCITY && !(x >= -1000.0 && x <= 1000.0))
      return 0;
  }
  return 1;
}

static int is_input(gr_field f) {
  return f == GR_FIELD_ELEVATION || f == GR_FIELD_WATER_DEPTH || f == GR_FIELD_PERMEABILITY ||
         f == GR_FIELD_RAIN_RATE || f == GR_FIELD_WATER_SURFACE || f == GR_FIELD_VELOCITY;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  reader r = {data, size};
  gr_rain_runoff_params p;
  char msg[1024];
  const int mode = take_byte(&r) % 2;
  const size_t small_len = take_byte(&r) % 96;
  const gr_field f = (gr_field)(take_byte(&r) % (GR_FIELD_COUNT + 1));
  double *d[11];

  memset(&p, 0, sizeof p);
  d[0] = &p.rain_rate;
  d[1] = &p.permeability;
  d[2] = &p.manning_n;
  d[3] = &p.cfl;
  d[4] = &p.max_dt;
  d[5] = &p.wetting_depth;
  d[6] = &p.debris_factor;
  for (int e = 0; e < 4; ++e)
    d[7 + e] = &p.boundary_level[e];
  for (int k = 0; k < 11; ++k) {
    if (mode == 0)
      take(&r, d[k], sizeof(double));
    else
      *d[k] = edge_double(take_byte(&r));
  }
  if (mode == 0) {
    for (int e = 0; e < 4; ++e)
      take(&r, &p.boundary[e], sizeof(int));
    take(&r, &p.flow_model, sizeof(int));
    take(&r, &p.no_data, sizeof(int));
  } else {
    int b;
    for (int e = 0; e < 4; ++e) {
      b = (int)take_byte(&r) % 6 - 1; /* -1 to 4 */
      memcpy(&p.boundary[e], &b, sizeof b);
    }
    b = (int)take_byte(&r) % 4 - 1; /* -1, 0, 1, 2 */
    memcpy(&p.flow_model, &b, sizeof b);
    b = (int)take_byte(&r) % 4 - 1;
    memcpy(&p.no_data, &b, sizeof b);
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
