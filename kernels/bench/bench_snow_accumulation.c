/* graupel-bench --core snow_accumulation: the exposure view plus one step
 * of snowfall, one minute, on a 50 m square whatever the grid's size, with
 * a field of boxes as occluders, 12 triangles each, about 10^4 triangles
 * in all. Two scenes:
 *  - one grid (no --devices): snowfall tilted 20 degrees over gently
 *    rolling ground, which then never rises above another point's ray, so
 *    the view holds the boxes alone (the scene of RESULTS.md's figures);
 *  - --devices K (1 included, and --verify's whole grid), or
 *    GRAUPEL_BENCH_RIDGES=1: snowfall tilted 35 degrees and 20 degrees off
 *    x over ridges that rise 2 m per m, so the terrain is drawn into the
 *    view and the pieces combine their views (the core's non-local part),
 *    the boxes standing on the ground, and a wall of 1 x 30 x 1.5 m across
 *    the middle rows, across every cut.
 * Flutter 2 degrees in both. Two environment variables change the set-up:
 * GRAUPEL_BENCH_TRIANGLES (occluder triangles, rounded to whole boxes) and
 * GRAUPEL_BENCH_RESOLUTION (ExposureResolution, default 1024). The report
 * times the stages of ten more steps separately. */
#include "bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BENCH_SPAN 50.0
#define BENCH_PI 3.14159265358979323846

/* A box's 12 triangles over its 8 corners (0-3 the bottom, 4-7 the top). */
static const int box_triangles[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                    1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};

typedef struct snow_accumulation_bench {
  gr_snow_accumulation *sim;
  gr_mesh *meshes;
  float *vertices;
  int *triangles;
  float wall[24];
  int nboxes, n, ridges;
} snow_accumulation_bench;

static void snow_accumulation_teardown(void *state) {
  snow_accumulation_bench *b = state;
  if (b) {
    gr_snow_accumulation_destroy(b->sim);
    free(b->meshes);
    free(b->vertices);
    free(b->triangles);
  }
  free(b);
}

static int env_int(const char *name, int fallback) {
  const char *v = getenv(name);
  int x = v ? atoi(v) : 0;
  return x > 0 ? x : fallback;
}

/* The ridges' ground at (x, y), m from grid point (0, 0): ridges along y
 * rising 2 m per m at the steepest (steeper than the snow's descent, so the
 * terrain is drawn into the view), on gently rolling ground. */
static double bench_ridges(double x, double y) {
  return 2.5 * sin(0.8 * x) * cos(0.12 * y) + 0.3 * sin(0.2 * x) * cos(0.15 * y);
}

/* Box corner v of the box [x0, x1] x [y0, y1] x [z0, z1]. */
static void bench_corner(float *p, int v, double x0, double x1, double y0, double y1, double z0,
                         double z1) {
  p[0] = (float)((v == 1 || v == 2 || v == 5 || v == 6) ? x1 : x0);
  p[1] = (float)((v == 2 || v == 3 || v == 6 || v == 7) ? y1 : y0);
  p[2] = (float)(v >= 4 ? z1 : z0);
}

/* nboxes boxes of 0.3 x 0.3 x 0.8 m on a square lattice over the grid
 * (from z = -0.2 m; on the ridges, from 0.5 m under the ground at their
 * centres), one mesh each (one object per box, so per-object bookkeeping is
 * timed too: at most GR_SNOW_ACCUMULATION_MAX_OBJECTS, one less on the
 * ridges; the rest are merged into the last box object's mesh), then on
 * the ridges the wall: a box of 1 x 30 x 1.5 m (above the highest ground
 * under it) across the middle rows, so that an object spans the cuts of a
 * split. */
static int snow_accumulation_boxes(snow_accumulation_bench *b) {
  int nb = b->nboxes, side = (int)ceil(sqrt((double)nb));
  b->vertices = malloc((size_t)nb * 24 * sizeof(float));
  b->triangles = malloc((size_t)nb * 36 * sizeof(int));
  int cap = GR_SNOW_ACCUMULATION_MAX_OBJECTS - (b->ridges ? 1 : 0);
  int nobj = nb < cap ? nb : cap;
  b->meshes = calloc((size_t)nobj + 1, sizeof(gr_mesh));
  if (!b->vertices || !b->triangles || !b->meshes)
    return 0;
  double pitch = (BENCH_SPAN - 4.0) / side;
  for (int k = 0; k < nb; ++k) {
    double cx = 2.0 + pitch * (k % side + 0.5), cy = 2.0 + pitch * (k / side + 0.5);
    double z0 = b->ridges ? bench_ridges(cx, cy) - 0.5 : -0.2, z1 = z0 + (b->ridges ? 1.3 : 1.0);
    for (int v = 0; v < 8; ++v)
      bench_corner(b->vertices + 24 * (size_t)k + 3 * v, v, cx - 0.15, cx + 0.15, cy - 0.15,
                   cy + 0.15, z0, z1);
  }
  /* Object o holds boxes [o * per, ...): vertices and indices relative to
   * its first box. */
  int per = (nb + nobj - 1) / nobj;
  for (int o = 0; o < nobj; ++o) {
    int k0 = o * per, k1 = k0 + per < nb ? k0 + per : nb;
    for (int k = k0; k < k1; ++k)
      for (int q = 0; q < 36; ++q)
        b->triangles[36 * (size_t)k + q] = box_triangles[q] + 8 * (k - k0);
    gr_mesh *m = &b->meshes[o];
    m->vertices = b->vertices + 24 * (size_t)k0;
    m->nvertices = 8 * (k1 - k0);
    m->triangles = b->triangles + 36 * (size_t)k0;
    m->ntriangles = 12 * (k1 - k0);
    for (int e = 0; e < 16; ++e)
      m->transform[e] = (e % 5 == 0) ? 1.0 : 0.0;
    if (k1 <= k0)
      nobj = o;
  }
  b->nboxes = nobj; /* now the number of objects */
  if (!b->ridges)
    return 1;
  double top = 0.0;
  for (int k = 0; k <= 60; ++k)
    top = fmax(top, bench_ridges(25.0, 10.0 + 0.5 * k));
  for (int v = 0; v < 8; ++v)
    bench_corner(b->wall + 3 * v, v, 24.5, 25.5, 10.0, 40.0, -3.0, top + 1.5);
  gr_mesh *w = &b->meshes[nobj];
  w->vertices = b->wall;
  w->nvertices = 8;
  w->triangles = box_triangles;
  w->ntriangles = 12;
  for (int e = 0; e < 16; ++e)
    w->transform[e] = (e % 5 == 0) ? 1.0 : 0.0;
  b->nboxes = nobj + 1; /* the wall's included */
  return 1;
}

static void snow_accumulation_bench_params(gr_snow_accumulation_params *p, int ridges) {
  gr_snow_accumulation_params_init(p);
  p->exposure_resolution = env_int("GRAUPEL_BENCH_RESOLUTION", 1024);
  double tilt = (ridges ? 35.0 : 20.0) * BENCH_PI / 180.0;
  double turn = (ridges ? 20.0 : 0.0) * BENCH_PI / 180.0;
  p->direction[0] = sin(tilt) * cos(turn);
  p->direction[1] = sin(tilt) * sin(turn);
  p->direction[2] = -cos(tilt);
  p->flutter = 2.0 * BENCH_PI / 180.0;
}

/* Rows j0 .. j0 + ny - 1 of the n by n set-up (the whole grid for j0 = 0,
 * ny = n) of either scene, with the ring the parameters need toward each
 * neighbouring strip; every piece sets every object (the core's piece
 * contract). */
static gr_status snow_accumulation_setup_scene(gr_context *ctx, int n, int j0, int ny,
                                               const gr_bench_link *link, int ridges,
                                               void **state) {
  double d = BENCH_SPAN / (n > 1 ? n - 1 : 1);
  int whole = j0 == 0 && ny == n;
  gr_snow_accumulation_params p;
  snow_accumulation_bench_params(&p, ridges);
  gr_grid g = {.nx = n, .ny = ny, .dx = d, .dy = d, .j0 = j0};
  int lo = j0, hi = j0 + ny; /* the local arrays' rows */
  if (!whole) {
    g.global_nx = n;
    g.global_ny = n;
    g.ghost = gr_snow_accumulation_ghost(&p);
    lo = j0 > 0 ? j0 - g.ghost : 0;
    hi = j0 + ny < n ? j0 + ny + g.ghost : n;
  }
  snow_accumulation_bench *b = calloc(1, sizeof(*b));
  if (!b)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  b->n = n;
  b->ridges = ridges;
  b->nboxes = (env_int("GRAUPEL_BENCH_TRIANGLES", 10000) + 11) / 12;
  if (!snow_accumulation_boxes(b)) {
    snow_accumulation_teardown(b);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  float *e = malloc((size_t)n * (size_t)(hi - lo) * sizeof(float));
  if (!e) {
    snow_accumulation_teardown(b);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  for (int j = lo; j < hi; ++j)
    for (int i = 0; i < n; ++i)
      e[(size_t)(j - lo) * n + i] =
          (float)(ridges ? bench_ridges(i * d, j * d) : 0.3 * sin(0.2 * i * d) * cos(0.15 * j * d));
  gr_status st = gr_snow_accumulation_create(ctx, &g, &p, &b->sim);
  if (st == GR_OK && !whole && link) {
    gr_snow_accumulation_set_allreduce(b->sim, link->allreduce, link->allreduce_user);
    gr_snow_accumulation_set_halo_exchange(b->sim, link->exchange, link->exchange_user);
  }
  if (st == GR_OK)
    st = gr_snow_accumulation_set_field(b->sim, GR_FIELD_ELEVATION, e);
  if (st == GR_OK)
    st = gr_snow_accumulation_set_objects(b->sim, b->meshes, b->nboxes);
  free(e);
  if (st != GR_OK) {
    snow_accumulation_teardown(b);
    return st;
  }
  *state = b;
  return GR_OK;
}

static gr_status snow_accumulation_setup(gr_context *ctx, int n, void **state) {
  const char *r = getenv("GRAUPEL_BENCH_RIDGES");
  return snow_accumulation_setup_scene(ctx, n, 0, n, NULL, r && atoi(r) > 0, state);
}

/* --devices: the ridges, whose terrain is in the view. */
static gr_status snow_accumulation_setup_piece(gr_context *ctx, int n, int j0, int ny,
                                               const gr_bench_link *link, void **state) {
  return snow_accumulation_setup_scene(ctx, n, j0, ny, link, 1, state);
}

/* A step of one minute; the objects stay where they are (their poses are
 * set once: a filter sets them only when they move). */
static gr_status snow_accumulation_step(void *state) {
  snow_accumulation_bench *b = state;
  return gr_snow_accumulation_step(b->sim, 60.0);
}

/* Ten more steps with the stages timed (each stage waits for the device),
 * into one line. Collective on a piece (the steps are). */
static gr_status snow_accumulation_stage_line(snow_accumulation_bench *b, char *line, size_t len) {
  gr_snow_accumulation_timing tm;
  const int timed = 10;
  gr_status st = GR_OK;
  gr_snow_accumulation_set_timing(b->sim, 1);
  for (int k = 0; st == GR_OK && k < timed; ++k)
    st = snow_accumulation_step(b);
  if (st == GR_OK)
    st = gr_snow_accumulation_timing_get(b->sim, &tm);
  gr_snow_accumulation_set_timing(b->sim, 0);
  if (st == GR_OK) {
    double q = 1.0 / (double)tm.steps;
    double total = (tm.host_ms + tm.view_ms + tm.exposure_ms + tm.blur_ms + tm.apply_ms +
                    tm.objects_ms + tm.combine_ms) *
                   q;
    snprintf(line, len,
             "ms/step over %lld steps, ExposureResolution %d: host %.3f, view (clear + raster) "
             "%.3f, exposure+growth %.3f, blur+dilation %.3f, increment+stability %.3f, mesh "
             "points %.3f, combine (pieces) %.3f; total %.3f",
             tm.steps, env_int("GRAUPEL_BENCH_RESOLUTION", 1024), tm.host_ms * q, tm.view_ms * q,
             tm.exposure_ms * q, tm.blur_ms * q, tm.apply_ms * q, tm.objects_ms * q,
             tm.combine_ms * q, total);
  }
  return st;
}

static gr_status snow_accumulation_report(void *state, gr_context *ctx) {
  snow_accumulation_bench *b = state;
  gr_snow_accumulation_ledger l;
  (void)ctx;
  gr_status st = gr_snow_accumulation_ledger_get(b->sim, &l);
  int tris = 0;
  for (int o = 0; o < b->nboxes; ++o)
    tris += b->meshes[o].ntriangles;
  if (st == GR_OK)
    printf("snow_accumulation: %lld steps, %.0f s; %d occluder triangles in %d objects; "
           "stored %.4g m^3 (objects %.4g), shed %.4g, balance %.3g of the snowfall\n",
           l.steps, l.time, tris, b->nboxes, l.stored_volume, l.stored_volume_objects,
           l.shed_volume, l.snowfall_volume > 0 ? fabs(l.balance_error) / l.snowfall_volume : 0.0);
  char line[400];
  if (st == GR_OK)
    st = snow_accumulation_stage_line(b, line, sizeof(line));
  if (st == GR_OK)
    printf("snow_accumulation stages (%s)\n", line);
  return st;
}

/* ------------------------------------------------------------ as pieces */

static int snow_accumulation_ring(void) {
  gr_snow_accumulation_params p;
  snow_accumulation_bench_params(&p, 1);
  return gr_snow_accumulation_ghost(&p);
}

static gr_status snow_accumulation_halo_size(void *state, int side, size_t *bytes) {
  return gr_snow_accumulation_halo_size(((snow_accumulation_bench *)state)->sim, side, bytes);
}

static gr_status snow_accumulation_halo_get(void *state, int side, void *host, size_t bytes) {
  return gr_snow_accumulation_halo_get(((snow_accumulation_bench *)state)->sim, side, host, bytes);
}

static gr_status snow_accumulation_halo_set(void *state, int side, const void *host, size_t bytes) {
  return gr_snow_accumulation_halo_set(((snow_accumulation_bench *)state)->sim, side, host, bytes);
}

_Static_assert((int)GR_SNOW_ACCUMULATION_SOUTH == (int)GR_BENCH_SOUTH &&
                   (int)GR_SNOW_ACCUMULATION_NORTH == (int)GR_BENCH_NORTH,
               "bench.h's sides are the core's");

static const gr_field verify_fields[] = {GR_FIELD_SNOW_DEPTH, GR_FIELD_SNOW_SURFACE,
                                         GR_FIELD_EXPOSURE};

static gr_status snow_accumulation_output(void *state, int i, const char **name, int *components,
                                          float *host) {
  *name = gr_field_name(verify_fields[i]);
  *components = 1;
  return host ? gr_snow_accumulation_get_field(((snow_accumulation_bench *)state)->sim,
                                               verify_fields[i], host)
              : GR_OK;
}

/* The ledger (the same bits on every piece and on the whole grid, see the
 * header's "Pieces"), the wall's snow and its exposed mesh points: the
 * object across the cuts, printed to the bit for a look beside the whole
 * grid's run. */
static gr_status snow_accumulation_summary(void *state, char *line, size_t len) {
  snow_accumulation_bench *b = state;
  gr_snow_accumulation_ledger l;
  float depth[8], exposure[8];
  int wall = b->nboxes - 1;
  gr_status st = gr_snow_accumulation_ledger_get(b->sim, &l);
  memset(depth, 0, sizeof(depth)), memset(exposure, 0, sizeof(exposure));
  if (st == GR_OK && b->ridges)
    st = gr_snow_accumulation_get_object_field(b->sim, wall, GR_FIELD_SNOW_DEPTH, depth, 8);
  if (st == GR_OK && b->ridges)
    st = gr_snow_accumulation_get_object_field(b->sim, wall, GR_FIELD_EXPOSURE, exposure, 8);
  if (st == GR_OK) {
    double wall_snow = 0.0;
    int exposed = 0;
    for (int v = 0; v < 8; ++v)
      wall_snow += depth[v], exposed += exposure[v] > 0.0f;
    snprintf(line, len,
             "snow_accumulation: %lld steps; stored %.17g m^3 (objects %.17g), shed %.17g, "
             "balance %.3g of the snowfall; the wall: %.9g m of snow over its corners, %d of 8 "
             "exposed",
             l.steps, l.stored_volume, l.stored_volume_objects, l.shed_volume,
             l.snowfall_volume > 0 ? fabs(l.balance_error) / l.snowfall_volume : 0.0, wall_snow,
             exposed);
  }
  return st;
}

static const char *snow_accumulation_last_error(void *state) {
  return gr_snow_accumulation_last_error(((snow_accumulation_bench *)state)->sim);
}

static gr_status snow_accumulation_stages(void *state, char *line, size_t len) {
  return snow_accumulation_stage_line(state, line, len);
}

static const gr_bench_split split = {
    snow_accumulation_setup_piece, snow_accumulation_ring,
    snow_accumulation_halo_size,   snow_accumulation_halo_get,
    snow_accumulation_halo_set,    (int)(sizeof(verify_fields) / sizeof(verify_fields[0])),
    snow_accumulation_output,      snow_accumulation_summary,
    snow_accumulation_last_error,  snow_accumulation_stages};

/* Per grid point and step, roughly: the raster reads 2 arrays, the
 * exposure reads 2 (and their neighbours) and writes 2, blur reads and
 * writes 1 twice, the increment reads 8 and writes 6 (the pairs). The view
 * and the mesh points come on top. */
static const gr_bench_core bench = {
    "snowfall tilted 20 deg on rolling ground among boxes (10^4 triangles); --devices: 35 deg "
    "over ridges (the terrain in the view), a wall across the cuts (seed 002)",
    snow_accumulation_setup,
    snow_accumulation_step,
    snow_accumulation_teardown,
    96.0,
    snow_accumulation_report,
    &split};

const gr_bench_core *gr_bench_snow_accumulation(void) {
  return &bench;
}
