/* graupel-bench --core water_surface: a lake over a bowl (the rim dry, about
 * 80 % of the points wet), 2 m spacing, WaveSpeed 3 m/s, Damping 0.05 /s and
 * raindrops at 0.05 per m^2 a second (DropRadius 1 m): one step of the
 * stable length is the drops' Gaussians and the wave update. */
#include "bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct water_bench {
  gr_water_surface *sim;
  double dt;
} water_bench;

static void water_teardown(void *state) {
  water_bench *w = state;
  if (w)
    gr_water_surface_destroy(w->sim);
  free(w);
}

static gr_status water_setup(gr_context *ctx, int n, void **state) {
  gr_grid g = {.nx = n, .ny = n, .dx = 2.0, .dy = 2.0};
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.wave_speed = 3.0;
  p.damping = 0.05;
  p.use_lake_level = 1;
  p.lake_level = 4.0;
  p.drop_rate = 0.05;
  p.drop_radius = 1.0;
  water_bench *w = calloc(1, sizeof(*w));
  float *b = malloc(sizeof(float) * (size_t)n * (size_t)n);
  if (!w || !b) {
    free(w);
    free(b);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  double half = 0.5 * (n - 1);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double x = (i - half) / (half > 0.0 ? half : 1.0), y = (j - half) / (half > 0.0 ? half : 1.0);
      b[(size_t)j * (size_t)n + (size_t)i] = (float)(5.0 * (x * x + y * y));
    }
  gr_status st = gr_water_surface_create(ctx, &g, &p, &w->sim);
  if (st == GR_OK)
    st = gr_water_surface_set_field(w->sim, GR_FIELD_ELEVATION, b);
  if (st == GR_OK)
    st = gr_water_surface_stable_dt(w->sim, &w->dt);
  if (st == GR_OK)
    st = gr_water_surface_step(w->sim, w->dt, 1); /* finds the water once */
  free(b);
  if (st != GR_OK) {
    water_teardown(w);
    return st;
  }
  *state = w;
  return GR_OK;
}

static gr_status water_step(void *state) {
  water_bench *w = state;
  return gr_water_surface_step(w->sim, w->dt, 1);
}

/* The ledger (one reduction and its read-back), and what the run left. */
static gr_status water_report(void *state, gr_context *ctx) {
  water_bench *w = state;
  gr_water_surface_ledger l;
  gr_status st = gr_water_surface_ledger_get(w->sim, &l);
  const int reps = 10;
  double t0 = gr_bench_now_s();
  for (int i = 0; st == GR_OK && i < reps; ++i)
    st = gr_water_surface_ledger_get(w->sim, &l);
  double t1 = gr_bench_now_s();
  if (st == GR_OK)
    printf("water_surface: ledger %.4f ms; dt %.4g s; %lld wet points, max |wave| %.3g m, "
           "mean level drift %.3g m\n",
           1e3 * (t1 - t0) / reps, w->dt, l.wet_points, l.max_wave,
           (l.wave_volume - l.initial_volume) / (4.0 * (double)l.wet_points));
  (void)ctx;
  return st;
}

/* Per point and step: the drops read the wet mask and write g (5 B; their
 * window's reads hit the cache); the update reads h, v, wet and g and writes
 * h and v (21 B). */
static const gr_bench_core bench = {
    "lake waves with raindrops: damped wave equation, reflecting shores (seeds 003, 004)",
    water_setup,
    water_step,
    water_teardown,
    26.0,
    water_report,
    NULL};

const gr_bench_core *gr_bench_water_surface(void) {
  return &bench;
}
