/* graupel-bench --core water_surface: a lake over a bowl (the rim dry, about
 * 80 % of the points wet), 2 m spacing, WaveSpeed 3 m/s, Damping 0.05 /s and
 * raindrops at 0.05 per m^2 a second (DropRadius 1 m): one step of the
 * stable length is the wave update with its drops. --devices K:
 * the same lake in K strips along y (a ring of 1 + the drops' reach, 3
 * rows; one row of wave height exchanged per step on the host), --verify
 * comparing every output with one whole grid's, bit for bit.
 * GRAUPEL_BENCH_DROPS=0: no raindrops (DropRate 0), the wave update alone. */
#include "bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

static void water_params(gr_water_surface_params *p) {
  gr_water_surface_params_init(p);
  p->wave_speed = 3.0;
  p->damping = 0.05;
  p->use_lake_level = 1;
  p->lake_level = 4.0;
  const char *drops = getenv("GRAUPEL_BENCH_DROPS");
  p->drop_rate = drops && strcmp(drops, "0") == 0 ? 0.0 : 0.05;
  p->drop_radius = 1.0;
}

/* Rows j0 .. j0 + ny - 1 of the n by n lake (the whole grid for j0 = 0,
 * ny = n), with the core's ring toward each neighbour. */
static gr_status water_setup_piece(gr_context *ctx, int n, int j0, int ny,
                                   const gr_bench_link *link, void **state) {
  const double d = 2.0;
  int whole = j0 == 0 && ny == n;
  gr_water_surface_params p;
  water_params(&p);
  gr_grid g = {.nx = n, .ny = ny, .dx = d, .dy = d, .j0 = j0};
  int lo = j0, hi = j0 + ny; /* the local arrays' rows */
  if (!whole) {
    g.global_nx = n;
    g.global_ny = n;
    g.ghost = gr_water_surface_ghost(&p, d);
    lo = j0 > 0 ? j0 - g.ghost : 0;
    hi = j0 + ny < n ? j0 + ny + g.ghost : n;
  }
  water_bench *w = calloc(1, sizeof(*w));
  float *b = malloc(sizeof(float) * (size_t)n * (size_t)(hi - lo));
  if (!w || !b) {
    free(w);
    free(b);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  double half = 0.5 * (n - 1);
  for (int j = lo; j < hi; ++j)
    for (int i = 0; i < n; ++i) {
      double x = (i - half) / (half > 0.0 ? half : 1.0), y = (j - half) / (half > 0.0 ? half : 1.0);
      b[(size_t)(j - lo) * (size_t)n + (size_t)i] = (float)(5.0 * (x * x + y * y));
    }
  gr_status st = gr_water_surface_create(ctx, &g, &p, &w->sim);
  if (st == GR_OK && !whole && link) {
    gr_water_surface_set_allreduce(w->sim, link->allreduce, link->allreduce_user);
    gr_water_surface_set_halo_exchange(w->sim, link->exchange, link->exchange_user);
  }
  if (st == GR_OK)
    st = gr_water_surface_set_field(w->sim, GR_FIELD_ELEVATION, b);
  if (st == GR_OK)
    st = gr_water_surface_stable_dt(w->sim, &w->dt);
  /* Finds the water and the initial volume once (collective: the ledger's
   * allreduce; no step here, since the halos are sized after set-up). */
  gr_water_surface_ledger l;
  if (st == GR_OK)
    st = gr_water_surface_ledger_get(w->sim, &l);
  free(b);
  if (st != GR_OK) {
    water_teardown(w);
    return st;
  }
  *state = w;
  return GR_OK;
}

static gr_status water_setup(gr_context *ctx, int n, void **state) {
  return water_setup_piece(ctx, n, 0, n, NULL, state);
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

/* ------------------------------------------------------------ as pieces */

static int water_ring(void) {
  gr_water_surface_params p;
  water_params(&p);
  return gr_water_surface_ghost(&p, 2.0);
}

static gr_status water_halo_size(void *state, int side, size_t *bytes) {
  return gr_water_surface_halo_size(((water_bench *)state)->sim, side, bytes);
}

static gr_status water_halo_get(void *state, int side, void *host, size_t bytes) {
  return gr_water_surface_halo_get(((water_bench *)state)->sim, side, host, bytes);
}

static gr_status water_halo_set(void *state, int side, const void *host, size_t bytes) {
  return gr_water_surface_halo_set(((water_bench *)state)->sim, side, host, bytes);
}

_Static_assert((int)GR_WATER_SURFACE_SOUTH == (int)GR_BENCH_SOUTH &&
                   (int)GR_WATER_SURFACE_NORTH == (int)GR_BENCH_NORTH,
               "bench.h's sides are the core's");

static const gr_water_surface_output verify_outputs[] = {GR_WATER_WAVE_HEIGHT, GR_WATER_NORMAL,
                                                         GR_WATER_SURFACE, GR_WATER_WET};

static gr_status water_output(void *state, int i, const char **name, int *components, float *host) {
  *name = gr_water_surface_output_name(verify_outputs[i]);
  *components = gr_water_surface_output_components(verify_outputs[i]);
  return host ? gr_water_surface_get(((water_bench *)state)->sim, verify_outputs[i], host) : GR_OK;
}

/* The ledger: fixed-point sums added over the pieces exactly, so the same
 * bits on every piece and on the whole grid; printed to the bit. */
static gr_status water_summary(void *state, char *line, size_t len) {
  water_bench *w = state;
  gr_water_surface_ledger l;
  gr_status st = gr_water_surface_ledger_get(w->sim, &l);
  if (st == GR_OK)
    snprintf(line, len,
             "water_surface: %lld steps; %lld wet points, wave volume %.17g m^3 (initial %.17g), "
             "energy %.17g m^4/s^2, max |wave| %.9g m",
             l.steps, l.wet_points, l.wave_volume, l.initial_volume, l.energy, l.max_wave);
  return st;
}

static const char *water_last_error(void *state) {
  return gr_water_surface_last_error(((water_bench *)state)->sim);
}

static const gr_bench_split split = {
    water_setup_piece, water_ring,
    water_halo_size,   water_halo_get,
    water_halo_set,    (int)(sizeof(verify_outputs) / sizeof(verify_outputs[0])),
    water_output,      water_summary,
    water_last_error,  NULL};

/* Per point and step: h, v and the wet mask read, h and v written (17 B);
 * the drops are hashed and their Gaussians summed in local memory, the
 * neighbours' reads hit the cache. */
static const gr_bench_core bench = {
    "lake waves with raindrops: damped wave equation, reflecting shores (seeds 003, 004)",
    water_setup,
    water_step,
    water_teardown,
    17.0,
    water_report,
    &split};

const gr_bench_core *gr_bench_water_surface(void) {
  return &bench;
}
