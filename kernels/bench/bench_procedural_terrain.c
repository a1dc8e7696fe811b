/* graupel-bench --core procedural_terrain: one evaluation of the default
 * terrain (6-octave inverted ridged multifractal, seed 001) per step. */
#include "bench.h"

static gr_status terrain_setup(gr_context *ctx, int n, void **state) {
  gr_grid g = {.nx = n, .ny = n, .dx = 2.0, .dy = 2.0};
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  return gr_procedural_terrain_create(ctx, &g, &p, (gr_procedural_terrain **)state);
}

static gr_status terrain_step(void *state) {
  return gr_procedural_terrain_compute(state);
}

static void terrain_teardown(void *state) {
  gr_procedural_terrain_destroy(state);
}

static const gr_bench_core bench = {
    "procedural terrain, 6-octave inverted ridged multifractal (seed 001)",
    terrain_setup,
    terrain_step,
    terrain_teardown,
    4.0,
    NULL,
    NULL};

const gr_bench_core *gr_bench_procedural_terrain(void) {
  return &bench;
}
