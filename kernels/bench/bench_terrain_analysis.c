/* graupel-bench --core terrain_analysis: per step, the shadow (sun at
 * azimuth 315, elevation 20 degrees) and the derivatives, hillshade and
 * cover of a rolling terrain of sines. GRAUPEL_BENCH_SHADOWS=0: without
 * shadows (ModelShadows off), the derivatives, hillshade and cover alone. */
#include "bench.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* GRAUPEL_BENCH_SHADOWS=0 leaves the shadow out; anything else keeps it. */
static int analysis_shadows(void) {
  const char *v = getenv("GRAUPEL_BENCH_SHADOWS");
  return !(v && strcmp(v, "0") == 0);
}

static gr_status analysis_setup(gr_context *ctx, int n, void **state) {
  gr_grid g = {.nx = n, .ny = n, .dx = 2.0, .dy = 2.0};
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  p.sun_elevation = 20.0;
  p.model_shadows = analysis_shadows();
  float *h = malloc(sizeof(float) * (size_t)n * (size_t)n);
  if (!h)
    return GR_ERR_OUT_OF_MEMORY;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      h[(size_t)j * (size_t)n + (size_t)i] =
          (float)(20.0 * sin(0.031 * i) * cos(0.023 * j) + 8.0 * sin(0.11 * (i + j)));
  gr_terrain_analysis *t = NULL;
  gr_status st = gr_terrain_analysis_create(ctx, &g, &p, &t);
  if (st == GR_OK)
    st = gr_terrain_analysis_set_heights(t, h);
  free(h);
  if (st != GR_OK) {
    gr_terrain_analysis_destroy(t);
    return st;
  }
  *state = t;
  return GR_OK;
}

static gr_status analysis_step(void *state) {
  gr_status st = analysis_shadows() ? gr_terrain_analysis_compute_shadow(state) : GR_OK;
  return st == GR_OK ? gr_terrain_analysis_compute(state) : st;
}

static void analysis_teardown(void *state) {
  gr_terrain_analysis_destroy(state);
}

/* Heights read once, normal (3), slope, aspect, hillshade, snow cover and
 * shadow written, shadow read: 9 floats and a class byte per cell (the ray
 * march's reads hit the cache). Without shadows: heights read, normal (3),
 * slope, aspect, hillshade and cover written: 8 floats and a class byte. */
static gr_bench_core bench = {
    "terrain analysis: shadow ray march + normals, slope, aspect, hillshade, cover (seed 001)",
    analysis_setup,
    analysis_step,
    analysis_teardown,
    37.0,
    NULL,
    NULL};

const gr_bench_core *gr_bench_terrain_analysis(void) {
  bench.bytes_per_cell = analysis_shadows() ? 37.0 : 33.0;
  return &bench;
}
