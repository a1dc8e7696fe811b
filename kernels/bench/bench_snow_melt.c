/* graupel-bench --core snow_melt: a metre of snow (300 kg/m^3) on rolling
 * hills of 10 m spacing (relief about 260 m), 2 degC at the valley floor with
 * the standard lapse rate and 1 mm/h of precipitation (rain below, snow
 * above), the sun at 46 N on 10 April from 06:00, cast shadows from 32
 * horizon sectors: one step is one hour (4 sun sub-steps). The horizons are
 * found once, at set-up (timed in the report). */
#include "bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct melt_bench {
  gr_snow_melt *sim;
  double horizon_s;
} melt_bench;

static void melt_teardown(void *state) {
  melt_bench *b = state;
  if (b)
    gr_snow_melt_destroy(b->sim);
  free(b);
}

static gr_status melt_setup(gr_context *ctx, int n, void **state) {
  gr_grid g = {.nx = n, .ny = n, .dx = 10.0, .dy = 10.0};
  gr_snow_melt_params p;
  gr_snow_melt_params_init(&p);
  p.start_hour = 6.0;
  size_t cells = (size_t)n * (size_t)n;
  melt_bench *b = calloc(1, sizeof(*b));
  float *z = malloc(sizeof(float) * cells), *depth = malloc(sizeof(float) * cells);
  float *rho = malloc(sizeof(float) * cells);
  gr_status st = b && z && depth && rho ? GR_OK : GR_ERR_OUT_OF_MEMORY;
  for (size_t c = 0; st == GR_OK && c < cells; ++c) {
    double i = (double)(c % (size_t)n), j = (double)(c / (size_t)n);
    z[c] = (float)(100.0 + 80.0 * sin(0.021 * i) * cos(0.017 * j) + 50.0 * sin(0.063 * (i + j)));
    depth[c] = 1.0f;
    rho[c] = 300.0f;
  }
  if (st == GR_OK)
    st = gr_snow_melt_create(ctx, &g, &p, &b->sim);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(b->sim, GR_FIELD_ELEVATION, z);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(b->sim, GR_FIELD_SNOW_DEPTH, depth);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(b->sim, GR_FIELD_SNOW_DENSITY, rho);
  double t0 = gr_bench_now_s();
  if (st == GR_OK)
    st = gr_snow_melt_set_terrain(b->sim, z);
  if (b)
    b->horizon_s = gr_bench_now_s() - t0;
  gr_snow_melt_forcing f = {2.0, 1.0, 0, 0};
  if (st == GR_OK)
    st = gr_snow_melt_set_forcing(b->sim, &f);
  free(z), free(depth), free(rho);
  if (st != GR_OK) {
    melt_teardown(b);
    return st;
  }
  *state = b;
  return GR_OK;
}

static gr_status melt_step(void *state) {
  melt_bench *b = state;
  return gr_snow_melt_advance(b->sim, 3600.0, NULL);
}

/* The horizons' time, the ledger (one reduction), and what the run left. */
static gr_status melt_report(void *state, gr_context *ctx) {
  melt_bench *b = state;
  gr_snow_melt_ledger l;
  double t0 = gr_bench_now_s();
  gr_status st = gr_snow_melt_ledger_get(b->sim, &l);
  double t1 = gr_bench_now_s();
  if (st == GR_OK)
    printf("snow_melt: horizons (32 sectors) %.2f s at set-up; ledger %.2f ms; %lld steps: "
           "melt %.4g m^3, released %.4g m^3, stored %.4g m^3 of %.4g in, balance error %.3g "
           "m^3\n",
           b->horizon_s, 1e3 * (t1 - t0), l.steps, l.melt_volume, l.released_volume,
           l.stored_swe_volume + l.stored_liquid_volume,
           l.snowfall_in + l.snowfall_volume + l.rain_volume, l.balance_error);
  (void)ctx;
  return st;
}

/* Per point and step: frozen and liquid (8 + 8 B) and the density read and
 * written, the 7 accumulators read and written (112 B), the elevation and
 * normal read (20 B), the radiation written, two horizon sectors read per
 * sun sub-step (32 B for 4): about 220 B. */
static const gr_bench_core bench = {
    "snowmelt: Hock's temperature index with clear-sky radiation and cast shadows, hourly steps",
    melt_setup,
    melt_step,
    melt_teardown,
    220.0,
    melt_report,
    NULL};

const gr_bench_core *gr_bench_snow_melt(void) {
  return &bench;
}
