/* libFuzzer harness: gr_procedural_terrain_params_validate and gr_grid_validate.
 * No OpenCL is touched.
 *
 * Input layout (missing bytes read as 0): byte 0 picks how the 19 fields
 * (11 of gr_procedural_terrain_params, then 8 of gr_grid, in declaration order)
 * are made, byte 1 the length of a small message buffer, then:
 *   mode 0  every field from raw bytes (4 per int or enum, 8 per double), so
 *           NaN, infinities, subnormals and huge values appear;
 *   mode 1  the defaults (gr_procedural_terrain_params_init; a 64 x 64 grid of
 *           2 m) with the fields whose bit is set in the next 3 bytes read
 *           raw, as in mode 0;
 *   mode 2  one byte per field picks from a table of edge values (range
 *           ends, one ulp either side, 0, -0, NaN, infinities, extremes).
 *
 * Checks: the status is GR_OK or GR_ERR_INVALID_ARGUMENT; a failure comes
 * with a non-empty message ending in '.'; accepted parameters lie in the
 * ranges of the parameter table (gr_procedural_terrain_param_bounds, which
 * the XML, the VTK clamps and the docs pages follow), and parameters in those
 * ranges are accepted; an accepted grid has the documented dimensions,
 * spacing, origin and offsets; a short message buffer is never overrun and is
 * always terminated; the answer does not depend on the buffer. */
#include "fuzz_common.h"
#include "graupel/procedural_terrain.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static const double edge_doubles[] = {0.0,    -0.0,  1.0,   -1.0, 0.5,   2.0,  4.0,  8.0,
                                      16.0,   3.9,   120.0, 1e4,  1e5,   1e12, 1e15, -1e15,
                                      1e-300, 1e300, -4.0,  7.99, 0.999, 1e-3, 1e13, 2.0e9};
#define N_EDGE_DOUBLES (sizeof edge_doubles / sizeof edge_doubles[0])

static double edge_double(uint8_t b) {
  /* Values that are not constant expressions come first; the table after. */
  switch (b % (N_EDGE_DOUBLES + 14)) {
  case 0:
    return NAN;
  case 1:
    return INFINITY;
  case 2:
    return -INFINITY;
  case 3:
    return DBL_MAX;
  case 4:
    return -DBL_MAX;
  case 5:
    return DBL_MIN;
  case 6:
    return nextafter(0.0, 1.0);
  case 7:
    return nextafter(1.0, 0.0);
  case 8:
    return nextafter(8.0, 16.0);
  case 9:
    return nextafter(4.0, 8.0);
  case 10:
    return nextafter(16.0, 32.0);
  case 11:
    return nextafter(1e4, 1e5);
  case 12:
    return nextafter(1e5, 1e6);
  case 13:
    return nextafter(0.0, -1.0);
  default:
    return edge_doubles[b % (N_EDGE_DOUBLES + 14) - 14];
  }
}

static int edge_int(uint8_t b) {
  static const int v[] = {0,     1,       -1,      2,           3,          6,
                          15,    16,      17,      64,          65536,      65537,
                          46341, 1 << 30, INT_MAX, INT_MAX - 1, INT_MIN,    INT_MIN + 1,
                          -2,    1000000, 100000,  2000000000,  2147483583, 63245};
  return v[b % (sizeof v / sizeof v[0])];
}

/* Field kinds in order: 'i' int or enum, 'd' double. */
static const char kinds[] = "iiiddddddid" /* params */ "iiddddii" /* grid */;

static void *field_ptr(gr_procedural_terrain_params *p, gr_grid *g, int f) {
  switch (f) {
  case 0:
    return &p->seed;
  case 1:
    return &p->type;
  case 2:
    return &p->octaves;
  case 3:
    return &p->frequency;
  case 4:
    return &p->lacunarity;
  case 5:
    return &p->persistence;
  case 6:
    return &p->offset;
  case 7:
    return &p->gain;
  case 8:
    return &p->h;
  case 9:
    return &p->invert;
  case 10:
    return &p->height_scale;
  case 11:
    return &g->nx;
  case 12:
    return &g->ny;
  case 13:
    return &g->dx;
  case 14:
    return &g->dy;
  case 15:
    return &g->x0;
  case 16:
    return &g->y0;
  case 17:
    return &g->i0;
  default:
    return &g->j0;
  }
}

static void set_raw(reader *r, gr_procedural_terrain_params *p, gr_grid *g, int f) {
  /* Raw bytes straight into the field: an enum gets any int bit pattern. */
  take(r, field_ptr(p, g, f), kinds[f] == 'd' ? sizeof(double) : sizeof(int));
}

static void set_edge(reader *r, gr_procedural_terrain_params *p, gr_grid *g, int f) {
  uint8_t b = take_byte(r);
  if (kinds[f] == 'd') {
    double v = edge_double(b);
    memcpy(field_ptr(p, g, f), &v, sizeof v);
  } else {
    int v = edge_int(b);
    memcpy(field_ptr(p, g, f), &v, sizeof v);
  }
}

/* A parameter by its table row's property name, as the harness reads the
 * struct (not through the core's own mapping). */
static double param_value(const gr_procedural_terrain_params *p, const char *property) {
  int type;
  memcpy(&type, &p->type, sizeof type);
  if (strcmp(property, "Seed") == 0)
    return p->seed;
  if (strcmp(property, "NoiseType") == 0)
    return type;
  if (strcmp(property, "Octaves") == 0)
    return p->octaves;
  if (strcmp(property, "Frequency") == 0)
    return p->frequency;
  if (strcmp(property, "Lacunarity") == 0)
    return p->lacunarity;
  if (strcmp(property, "Persistence") == 0)
    return p->persistence;
  if (strcmp(property, "Offset") == 0)
    return p->offset;
  if (strcmp(property, "Gain") == 0)
    return p->gain;
  if (strcmp(property, "SpectralExponent") == 0)
    return p->h;
  if (strcmp(property, "Invert") == 0)
    return p->invert;
  if (strcmp(property, "HeightScale") == 0)
    return p->height_scale;
  return NAN; /* a row the harness does not know: refused below */
}

/* The parameter table (gr_procedural_terrain_param_bounds) is the documented
 * range: every row's value in [min, max], or (min, max] where min_open. The
 * table itself must cover the eleven parameters. */
static int params_documented(const gr_procedural_terrain_params *p) {
  int n = 0;
  const gr_param_bound *rows = gr_procedural_terrain_param_bounds(&n);
  REQUIRE(rows != NULL && n == 11);
  for (int r = 0; r < n; ++r) {
    double v = param_value(p, rows[r].property);
    REQUIRE(rows[r].min < rows[r].max);
    if (!(rows[r].min_open ? v > rows[r].min : v >= rows[r].min) || !(v <= rows[r].max))
      return 0;
  }
  return 1;
}

/* gr_grid's documentation and gr_grid_validate's sentences. */
static int grid_documented(const gr_grid *g) {
  return g->nx >= 1 && g->ny >= 1 && g->dx > 0.0 && g->dy > 0.0 && isfinite(g->dx) &&
         isfinite(g->dy) && isfinite(g->x0) && isfinite(g->y0) &&
         (double)g->nx * (double)g->ny <= 4.0e9 && g->i0 >= 0 && g->j0 >= 0 &&
         (long long)g->i0 + g->nx <= INT_MAX && (long long)g->j0 + g->ny <= INT_MAX;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  gr_procedural_terrain_params p;
  gr_grid g;
  reader r;
  char msg[1024];
  char *small;
  size_t small_len;
  gr_status sp, sg;
  int f, mode;

  r.p = data;
  r.n = size;
  mode = take_byte(&r) % 3;
  small_len = take_byte(&r) % 96;
  memset(&p, 0, sizeof p);
  memset(&g, 0, sizeof g);
  if (mode == 1) {
    uint8_t bits[3];
    gr_procedural_terrain_params_init(&p);
    g.nx = 64;
    g.ny = 64;
    g.dx = 2.0;
    g.dy = 2.0;
    take(&r, bits, sizeof bits);
    for (f = 0; f < 19; ++f)
      if (bits[f / 8] & (1u << (f % 8)))
        set_raw(&r, &p, &g, f);
  } else {
    for (f = 0; f < 19; ++f) {
      if (mode == 0)
        set_raw(&r, &p, &g, f);
      else
        set_edge(&r, &p, &g, f);
    }
  }

  msg[0] = '\0';
  sp = gr_procedural_terrain_params_validate(&p, msg, sizeof msg);
  check_message(sp, msg);
  REQUIRE((sp == GR_OK) == params_documented(&p));
  msg[0] = '\0';
  sg = gr_grid_validate(&g, msg, sizeof msg);
  check_message(sg, msg);
  if (sg == GR_OK)
    REQUIRE(grid_documented(&g));

  /* No buffer, and a short one on the heap (AddressSanitizer sees an
   * overrun): the same answers, and a terminated message. */
  REQUIRE(gr_procedural_terrain_params_validate(&p, NULL, 0) == sp);
  REQUIRE(gr_procedural_terrain_params_validate(&p, NULL, 64) == sp);
  REQUIRE(gr_grid_validate(&g, NULL, 0) == sg);
  small = (char *)malloc(small_len > 0 ? small_len : 1);
  REQUIRE(small != NULL);
  if (small_len > 0) {
    memset(small, 'x', small_len);
    REQUIRE(gr_procedural_terrain_params_validate(&p, small, small_len) == sp);
    if (sp != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
    memset(small, 'x', small_len);
    REQUIRE(gr_grid_validate(&g, small, small_len) == sg);
    if (sg != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
  }
  free(small);

  /* No parameters and no grid at all. */
  msg[0] = '\0';
  check_message(gr_procedural_terrain_params_validate(NULL, msg, sizeof msg), msg);
  REQUIRE(msg[0] != '\0');
  msg[0] = '\0';
  check_message(gr_grid_validate(NULL, msg, sizeof msg), msg);
  REQUIRE(msg[0] != '\0');
  return 0;
}
