/* graupel-bench --core rain_runoff: rain on a bowl tilted towards x = 0 (5 m
 * deep over the grid's half-width, 1 % slope), 5 cm of water everywhere so
 * that every face flows from the first step, 50 mm/h of rain, 5 mm/h of
 * infiltration, an open boundary; a fixed stable step taken once at set-up.
 * The local inertial model, as the earlier figures in RESULTS.md;
 * GRAUPEL_BENCH_FLOW_MODEL=0 benchmarks the shallow-water model;
 * GRAUPEL_BENCH_SW_FUSED=0/1 forces its stages' separate launches or one
 * launch each (gr_rain_runoff_set_sw_fused), GRAUPEL_BENCH_SW_TILE=TXxTY
 * the fused stages' tile (gr_rain_runoff_set_sw_tile);
 * GRAUPEL_BENCH_FUSED=0/1 forces the local inertial step's three launches
 * or its one (gr_rain_runoff_set_fused); GRAUPEL_BENCH_SPECIALISED=0 takes
 * the kernels compiled for every optional input. */
#include "bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct rain_runoff_bench {
  gr_rain_runoff *sim;
  double dt;
  int nx, ny; /* owned cells */
} rain_runoff_bench;

static void rain_runoff_teardown(void *state) {
  rain_runoff_bench *r = state;
  if (r)
    gr_rain_runoff_destroy(r->sim);
  free(r);
}

static gr_flow_model bench_flow_model(void) {
  const char *model = getenv("GRAUPEL_BENCH_FLOW_MODEL");
  return model && atoi(model) == 0 ? GR_FLOW_SHALLOW_WATER : GR_FLOW_LOCAL_INERTIAL;
}

static int rain_runoff_ring(void) {
  return bench_flow_model() == GR_FLOW_SHALLOW_WATER ? GR_RAIN_RUNOFF_GHOST_SW
                                                     : GR_RAIN_RUNOFF_GHOST;
}

/* Rows j0 .. j0 + ny - 1 of the n by n bowl (the whole grid for j0 = 0,
 * ny = n), with a ring toward each neighbouring strip: every input is a
 * function of the global (i, j), so the strips hold the whole grid's floats. */
static gr_status rain_runoff_setup_piece(gr_context *ctx, int n, int j0, int ny,
                                         const gr_bench_link *link, void **state) {
  int whole = j0 == 0 && ny == n, ring = whole ? 0 : rain_runoff_ring();
  int south = j0 > 0 ? ring : 0, north = j0 + ny < n ? ring : 0;
  gr_grid g = {.nx = n, .ny = ny, .dx = 2.0, .dy = 2.0, .j0 = j0};
  if (!whole) {
    g.global_nx = n;
    g.global_ny = n;
    g.ghost = ring;
  }
  gr_rain_runoff_params p;
  gr_rain_runoff_params_init(&p);
  p.rain_rate = 50.0 / 3.6e6;
  p.permeability = 5.0 / 3.6e6;
  p.max_dt = 0.25; /* stays stable while the bowl fills during the run */
  p.flow_model = bench_flow_model();
  rain_runoff_bench *r = calloc(1, sizeof(*r));
  int rows = ny + south + north;
  size_t cells = (size_t)n * (size_t)rows;
  float *b = malloc(cells * sizeof(float)), *d = malloc(cells * sizeof(float));
  if (!r || !b || !d) {
    free(r);
    free(b);
    free(d);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  r->nx = n;
  r->ny = ny;
  double half = 0.5 * (n - 1);
  for (int jl = 0; jl < rows; ++jl)
    for (int i = 0; i < n; ++i) {
      int j = j0 - south + jl;
      double x = (i - half) / (half > 0.0 ? half : 1.0), y = (j - half) / (half > 0.0 ? half : 1.0);
      b[(size_t)jl * n + i] = (float)(5.0 * (x * x + y * y) + 0.01 * i * g.dx);
      d[(size_t)jl * n + i] = 0.05f;
    }
  gr_status st = gr_rain_runoff_create(ctx, &g, &p, &r->sim);
  /* GRAUPEL_BENCH_FUSED=0/1: the local inertial step in three launches or
   * one (the device's default without it). */
  const char *fused = getenv("GRAUPEL_BENCH_FUSED");
  if (st == GR_OK && fused && *fused)
    gr_rain_runoff_set_fused(r->sim, atoi(fused));
  /* GRAUPEL_BENCH_SPECIALISED=0: the kernels for every optional input
   * (gr_rain_runoff_set_specialised), as before they were compiled for the
   * inputs in use. */
  const char *spec = getenv("GRAUPEL_BENCH_SPECIALISED");
  if (st == GR_OK && spec && *spec)
    gr_rain_runoff_set_specialised(r->sim, atoi(spec));
  if (st == GR_OK && !whole && link) {
    gr_rain_runoff_set_allreduce(r->sim, link->allreduce, link->allreduce_user);
    gr_rain_runoff_set_halo_exchange(r->sim, link->exchange, link->exchange_user);
  }
  /* The shallow-water step's launch path and tile, when asked for (the
   * device's defaults without them). */
  const char *sw_fused = getenv("GRAUPEL_BENCH_SW_FUSED"),
             *sw_tile = getenv("GRAUPEL_BENCH_SW_TILE");
  if (st == GR_OK && sw_fused && *sw_fused)
    gr_rain_runoff_set_sw_fused(r->sim, atoi(sw_fused));
  int tx = 0, ty = 0;
  if (st == GR_OK && sw_tile && sscanf(sw_tile, "%dx%d", &tx, &ty) == 2)
    st = gr_rain_runoff_set_sw_tile(r->sim, tx, ty);
  if (st == GR_OK)
    st = gr_rain_runoff_set_field(r->sim, GR_FIELD_ELEVATION, b);
  if (st == GR_OK)
    st = gr_rain_runoff_set_field(r->sim, GR_FIELD_WATER_DEPTH, d);
  /* A piece's stable step is the whole grid's: the allreduce takes the
   * largest depth over every piece. */
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

static gr_status rain_runoff_setup(gr_context *ctx, int n, void **state) {
  return rain_runoff_setup_piece(ctx, n, 0, n, NULL, state);
}

static gr_status rain_runoff_step(void *state) {
  rain_runoff_bench *r = state;
  return gr_rain_runoff_step(r->sim, r->dt, 1);
}

/* What a caller pays besides the steps: the ledger (one reduction and its
 * read-back) and the stable step (the same reduction, reading only the
 * depth in the local inertial model); and a step against
 * plain 5-point stencil passes measured in the same run (steps and
 * passes timed back to back, so that a busy machine slows both). */
static gr_status rain_runoff_report(void *state, gr_context *ctx) {
  rain_runoff_bench *r = state;
  gr_rain_runoff_ledger l;
  double stencil = 0.0, step = 0.0;
  const int timed = 10;
  gr_status st = gr_finish(ctx);
  double s0 = gr_bench_now_s();
  for (int k = 0; st == GR_OK && k < timed; ++k)
    st = rain_runoff_step(r);
  if (st == GR_OK)
    st = gr_finish(ctx);
  step = 1e3 * (gr_bench_now_s() - s0) / timed;
  if (st == GR_OK)
    st = gr_bench_stencil_ms(ctx, r->nx, r->ny, &stencil);
  if (st == GR_OK)
    printf("rain_runoff: %s step %.4f ms, 5-point stencil pass %.4f ms at %d x %d: a step costs "
           "%.1f passes (the target for the local inertial step at 1024^2: 30 passes or fewer)\n",
           bench_flow_model() == GR_FLOW_SHALLOW_WATER ? "shallow-water" : "local inertial", step,
           stencil, r->nx, r->ny, stencil > 0.0 ? step / stencil : 0.0);
  if (st == GR_OK)
    st = gr_rain_runoff_ledger_get(r->sim, &l); /* warm-up */
  const int reps = 10;
  double t0 = gr_bench_now_s();
  for (int i = 0; st == GR_OK && i < reps; ++i)
    st = gr_rain_runoff_ledger_get(r->sim, &l);
  double t1 = gr_bench_now_s();
  double dt = 0.0;
  for (int i = 0; st == GR_OK && i < reps; ++i)
    st = gr_rain_runoff_stable_dt(r->sim, &dt);
  double t2 = gr_bench_now_s();
  if (st == GR_OK)
    printf("rain_runoff: ledger (reduction and read-back) %.4f ms, stable step %.4f ms; dt %.4g "
           "s; after the run %.4g m^3 stored, %.4g m^3 out, balance %.3g of the water in\n",
           1e3 * (t1 - t0) / reps, 1e3 * (t2 - t1) / reps, r->dt, l.stored_volume, l.outflow_volume,
           fabs(l.balance_error) / (l.initial_volume + l.rain_volume));
  (void)ctx;
  return st;
}

/* ------------------------------------------------------------ as pieces */

static gr_status rain_runoff_halo_size(void *state, int side, size_t *bytes) {
  return gr_rain_runoff_halo_size(((rain_runoff_bench *)state)->sim, side, bytes);
}

static gr_status rain_runoff_halo_get(void *state, int side, void *host, size_t bytes) {
  return gr_rain_runoff_halo_get(((rain_runoff_bench *)state)->sim, side, host, bytes);
}

static gr_status rain_runoff_halo_set(void *state, int side, const void *host, size_t bytes) {
  return gr_rain_runoff_halo_set(((rain_runoff_bench *)state)->sim, side, host, bytes);
}

_Static_assert((int)GR_RAIN_RUNOFF_SOUTH == (int)GR_BENCH_SOUTH &&
                   (int)GR_RAIN_RUNOFF_NORTH == (int)GR_BENCH_NORTH,
               "bench.h's sides are the core's");

/* Every field a reader gets, then every flood map. */
static const gr_field verify_fields[] = {GR_FIELD_WATER_DEPTH, GR_FIELD_VELOCITY,
                                         GR_FIELD_DISCHARGE, GR_FIELD_INFILTRATED,
                                         GR_FIELD_WATER_SURFACE};
#define VERIFY_FIELDS ((int)(sizeof(verify_fields) / sizeof(verify_fields[0])))

static gr_status rain_runoff_output(void *state, int i, const char **name, int *components,
                                    float *host) {
  rain_runoff_bench *r = state;
  if (i < VERIFY_FIELDS) {
    *name = gr_field_name(verify_fields[i]);
    *components = gr_field_components(verify_fields[i]);
    return host ? gr_rain_runoff_get_field(r->sim, verify_fields[i], host) : GR_OK;
  }
  gr_rain_runoff_map m = (gr_rain_runoff_map)(i - VERIFY_FIELDS);
  *name = gr_rain_runoff_map_name(m);
  *components = 1;
  return host ? gr_rain_runoff_get_map(r->sim, m, host) : GR_OK;
}

static gr_status rain_runoff_summary(void *state, char *line, size_t len) {
  rain_runoff_bench *r = state;
  gr_rain_runoff_ledger l;
  gr_status st = gr_rain_runoff_ledger_get(r->sim, &l);
  if (st == GR_OK)
    snprintf(line, len,
             "rain_runoff: dt %.4g s; after the run %.6g m^3 stored, %.6g m^3 out, balance %.3g "
             "of the water in",
             r->dt, l.stored_volume, l.outflow_volume,
             fabs(l.balance_error) / (l.initial_volume + l.rain_volume));
  return st;
}

static const char *rain_runoff_last_error(void *state) {
  return gr_rain_runoff_last_error(((rain_runoff_bench *)state)->sim);
}

static const gr_bench_split split = {
    rain_runoff_setup_piece, rain_runoff_ring,
    rain_runoff_halo_size,   rain_runoff_halo_get,
    rain_runoff_halo_set,    VERIFY_FIELDS + GR_RAIN_RUNOFF_MAP_COUNT,
    rain_runoff_output,      rain_runoff_summary,
    rain_runoff_last_error,  NULL};

/* Per cell and step of the local inertial model, each array once per
 * launch (neighbours come from cache): flux reads depth, elevation, the old
 * discharges and the limiter and writes the new discharges (28 B); limit
 * reads depth and discharges and writes the limiter (16 B); update reads
 * depth and its compensation, discharges, limiter, infiltrated and its
 * compensation and writes depth, infiltrated and their compensations (44 B),
 * and reads the six flood maps it folds the new state into (24 B; writes
 * only where they change). */
static const gr_bench_core bench = {
    "rain on a tilted bowl: local inertial runoff (GRAUPEL_BENCH_FLOW_MODEL=0: shallow water), "
    "infiltration, open boundary (seed 004)",
    rain_runoff_setup,
    rain_runoff_step,
    rain_runoff_teardown,
    112.0,
    rain_runoff_report,
    &split};

const gr_bench_core *gr_bench_rain_runoff(void) {
  return &bench;
}
