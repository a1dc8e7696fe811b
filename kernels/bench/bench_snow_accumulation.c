/* graupel-bench --core snow_accumulation: the exposure view plus one step
 * of snowfall tilted 20 degrees, over a 50 m square of gently rolling
 * ground with a field of boxes standing on it as occluders, 12 triangles
 * each, about 10^4 triangles in all (issue 9); the grid spans 50 m
 * whatever its size. Two environment variables change the set-up:
 * GRAUPEL_BENCH_TRIANGLES (occluder triangles, rounded to whole boxes) and
 * GRAUPEL_BENCH_RESOLUTION (ExposureResolution, default 1024). The report
 * times the stages of ten more steps separately. */
#include "bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define BENCH_SPAN 50.0

typedef struct snow_accumulation_bench {
  gr_snow_accumulation *sim;
  gr_mesh *meshes;
  float *vertices;
  int *triangles;
  int nboxes, n;
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

/* nboxes boxes of 0.3 x 0.3 x 0.8 m on a square lattice over the grid,
 * one mesh each (one object per box, so per-object bookkeeping is timed
 * too: at most GR_SNOW_ACCUMULATION_MAX_OBJECTS; the rest are merged into
 * the last object's mesh). */
static int snow_accumulation_boxes(snow_accumulation_bench *b) {
  static const int tri[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                            1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  int nb = b->nboxes, side = (int)ceil(sqrt((double)nb));
  b->vertices = malloc((size_t)nb * 24 * sizeof(float));
  b->triangles = malloc((size_t)nb * 36 * sizeof(int));
  int nobj = nb < GR_SNOW_ACCUMULATION_MAX_OBJECTS ? nb : GR_SNOW_ACCUMULATION_MAX_OBJECTS;
  b->meshes = calloc((size_t)nobj, sizeof(gr_mesh));
  if (!b->vertices || !b->triangles || !b->meshes)
    return 0;
  double pitch = (BENCH_SPAN - 4.0) / side;
  for (int k = 0; k < nb; ++k) {
    double cx = 2.0 + pitch * (k % side + 0.5), cy = 2.0 + pitch * (k / side + 0.5);
    for (int v = 0; v < 8; ++v) {
      float *p = b->vertices + 24 * (size_t)k + 3 * v;
      p[0] = (float)(cx + ((v == 1 || v == 2 || v == 5 || v == 6) ? 0.15 : -0.15));
      p[1] = (float)(cy + ((v == 2 || v == 3 || v == 6 || v == 7) ? 0.15 : -0.15));
      p[2] = (float)(v >= 4 ? 0.8 : -0.2);
    }
  }
  /* Object o holds boxes [o * per, ...): vertices and indices relative to
   * its first box. */
  int per = (nb + nobj - 1) / nobj;
  for (int o = 0; o < nobj; ++o) {
    int k0 = o * per, k1 = k0 + per < nb ? k0 + per : nb;
    for (int k = k0; k < k1; ++k)
      for (int q = 0; q < 36; ++q)
        b->triangles[36 * (size_t)k + q] = tri[q] + 8 * (k - k0);
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
  return 1;
}

static gr_status snow_accumulation_setup(gr_context *ctx, int n, void **state) {
  double d = BENCH_SPAN / (n > 1 ? n - 1 : 1);
  gr_grid g = {.nx = n, .ny = n, .dx = d, .dy = d};
  gr_snow_accumulation_params p;
  gr_snow_accumulation_params_init(&p);
  p.exposure_resolution = env_int("GRAUPEL_BENCH_RESOLUTION", 1024);
  p.direction[0] = sin(20.0 * 3.14159265358979 / 180.0);
  p.direction[2] = -cos(20.0 * 3.14159265358979 / 180.0);
  p.flutter = 2.0 * 3.14159265358979 / 180.0;
  snow_accumulation_bench *b = calloc(1, sizeof(*b));
  if (!b)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  b->n = n;
  b->nboxes = (env_int("GRAUPEL_BENCH_TRIANGLES", 10000) + 11) / 12;
  if (!snow_accumulation_boxes(b)) {
    snow_accumulation_teardown(b);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  float *e = malloc((size_t)n * (size_t)n * sizeof(float));
  if (!e) {
    snow_accumulation_teardown(b);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      e[(size_t)j * n + i] = (float)(0.3 * sin(0.2 * i * d) * cos(0.15 * j * d));
  gr_status st = gr_snow_accumulation_create(ctx, &g, &p, &b->sim);
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

/* A step of one minute; the objects stay where they are (their poses are
 * set once: a filter sets them only when they move). */
static gr_status snow_accumulation_step(void *state) {
  snow_accumulation_bench *b = state;
  return gr_snow_accumulation_step(b->sim, 60.0);
}

static gr_status snow_accumulation_report(void *state, gr_context *ctx) {
  snow_accumulation_bench *b = state;
  gr_snow_accumulation_ledger l;
  gr_snow_accumulation_timing tm;
  const int timed = 10;
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
  gr_snow_accumulation_set_timing(b->sim, 1);
  for (int k = 0; st == GR_OK && k < timed; ++k)
    st = snow_accumulation_step(b);
  if (st == GR_OK)
    st = gr_snow_accumulation_timing_get(b->sim, &tm);
  gr_snow_accumulation_set_timing(b->sim, 0);
  if (st == GR_OK) {
    double q = 1.0 / (double)tm.steps;
    double total =
        (tm.host_ms + tm.view_ms + tm.exposure_ms + tm.blur_ms + tm.apply_ms + tm.objects_ms) * q;
    printf("snow_accumulation stages (ms/step over %lld steps, ExposureResolution %d): host %.3f, "
           "view (clear + raster) %.3f, exposure+growth %.3f, blur+dilation %.3f, "
           "increment+stability %.3f, mesh points %.3f; total %.3f\n",
           tm.steps, env_int("GRAUPEL_BENCH_RESOLUTION", 1024), tm.host_ms * q, tm.view_ms * q,
           tm.exposure_ms * q, tm.blur_ms * q, tm.apply_ms * q, tm.objects_ms * q, total);
  }
  return st;
}

/* Per grid point and step, roughly: the raster reads 2 arrays, the
 * exposure reads 2 (and their neighbours) and writes 2, blur reads and
 * writes 1 twice, the increment reads 8 and writes 6 (the pairs). The view
 * and the mesh points come on top. */
static const gr_bench_core bench = {
    "snowfall tilted 20 deg on rolling ground among boxes (10^4 triangles): view, exposure, "
    "blur, increment, stability (seed 002)",
    snow_accumulation_setup,
    snow_accumulation_step,
    snow_accumulation_teardown,
    96.0,
    snow_accumulation_report,
    NULL};

const gr_bench_core *gr_bench_snow_accumulation(void) {
  return &bench;
}
