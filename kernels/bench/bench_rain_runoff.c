/* graupel-bench --core rain_runoff: rain on a bowl tilted towards x = 0 (5 m
 * deep over the grid's half-width, 1 % slope), 5 cm of water everywhere so
 * that every face flows from the first step, 50 mm/h of rain, 5 mm/h of
 * infiltration, an open boundary; a fixed stable step taken once at set-up.
 * The local inertial model, as the earlier figures in RESULTS.md;
 * GRAUPEL_BENCH_FLOW_MODEL=0 benchmarks the shallow-water model. */
#include "bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct rain_runoff_bench {
  gr_rain_runoff *sim;
  double dt;
} rain_runoff_bench;

static void rain_runoff_teardown(void *state) {
  rain_runoff_bench *r = state;
  if (r)
    gr_rain_runoff_destroy(r->sim);
  free(r);
}

static gr_status rain_runoff_setup(gr_context *ctx, int n, void **state) {
  gr_grid g = {.nx = n, .ny = n, .dx = 2.0, .dy = 2.0};
  gr_rain_runoff_params p;
  gr_rain_runoff_params_init(&p);
  p.rain_rate = 50.0 / 3.6e6;
  p.permeability = 5.0 / 3.6e6;
  p.max_dt = 0.25; /* stays stable while the bowl fills during the run */
  const char *model = getenv("GRAUPEL_BENCH_FLOW_MODEL");
  p.flow_model = model && atoi(model) == 0 ? GR_FLOW_SHALLOW_WATER : GR_FLOW_LOCAL_INERTIAL;
  rain_runoff_bench *r = calloc(1, sizeof(*r));
  size_t cells = (size_t)n * (size_t)n;
  float *b = malloc(cells * sizeof(float)), *d = malloc(cells * sizeof(float));
  if (!r || !b || !d) {
    free(r);
    free(b);
    free(d);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  double half = 0.5 * (n - 1);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double x = (i - half) / (half > 0.0 ? half : 1.0), y = (j - half) / (half > 0.0 ? half : 1.0);
      b[(size_t)j * n + i] = (float)(5.0 * (x * x + y * y) + 0.01 * i * g.dx);
      d[(size_t)j * n + i] = 0.05f;
    }
  gr_status st = gr_rain_runoff_create(ctx, &g, &p, &r->sim);
  if (st == GR_OK)
    st = gr_rain_runoff_set_field(r->sim, GR_FIELD_ELEVATION, b);
  if (st == GR_OK)
    st = gr_rain_runoff_set_field(r->sim, GR_FIELD_WATER_DEPTH, d);
  if (st == GR_OK)
    st = gr_rain_runoff_stable_dt(r->sim, &r->dt);
  free(b);
  free(d);
  if (st != GR_OK) {
    rain_runoff_teardown(r);
    return st;
  }
  *state = r;
  return GR_OK;
}

static gr_status rain_runoff_step(void *state) {
  rain_runoff_bench *r = state;
  return gr_rain_runoff_step(r->sim, r->dt, 1);
}

/* What a caller pays besides the steps: the ledger (one reduction and its
 * read-back) and the stable step (the same reduction). */
static gr_status rain_runoff_report(void *state, gr_context *ctx) {
  rain_runoff_bench *r = state;
  gr_rain_runoff_ledger l;
  gr_status st = gr_rain_runoff_ledger_get(r->sim, &l); /* warm-up */
  const int reps = 10;
  double t0 = gr_bench_now_s();
  for (int i = 0; st == GR_OK && i < reps; ++i)
    st = gr_rain_runoff_ledger_get(r->sim, &l);
  double t1 = gr_bench_now_s();
  if (st == GR_OK)
    printf("rain_runoff: ledger (reduction and read-back) %.4f ms; dt %.4g s; after the run "
           "%.4g m^3 stored, %.4g m^3 out, balance %.3g of the water in\n",
           1e3 * (t1 - t0) / reps, r->dt, l.stored_volume, l.outflow_volume,
           fabs(l.balance_error) / (l.initial_volume + l.rain_volume));
  (void)ctx;
  return st;
}

/* Per cell and step, each array once per launch (neighbours come from
 * cache): flux reads depth, elevation, the old discharges and the limiter and
 * writes the new discharges (28 B); limit reads depth and discharges and
 * writes the limiter (16 B); update reads depth and its compensation,
 * discharges, limiter, infiltrated and its compensation and writes depth,
 * infiltrated and their compensations (44 B). */
static const gr_bench_core bench = {
    "rain on a tilted bowl: local inertial runoff (GRAUPEL_BENCH_FLOW_MODEL=0: shallow water), "
    "infiltration, open boundary (seed 004)",
    rain_runoff_setup,
    rain_runoff_step,
    rain_runoff_teardown,
    88.0,
    rain_runoff_report};

const gr_bench_core *gr_bench_rain_runoff(void) {
  return &bench;
}
