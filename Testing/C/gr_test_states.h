/* The five cores that keep checkpoints (gr_<core>_state_size / _save /
 * _load) behind one table of calls, each with a small simulation that has
 * something in its state: rain on a slope, snow on ridges under a box, snow
 * under a box that moves, melting snow, a lake with waves. Shared by the
 * state tests (test_state_load.c) and the state fuzz harness
 * (Testing/Fuzz/fuzz_state_load.c), so that both load into the same
 * simulations. */
#ifndef GR_TEST_STATES_H
#define GR_TEST_STATES_H

#include "graupel/rain_runoff.h"
#include "graupel/runtime.h"
#include "graupel/snow_accumulation.h"
#include "graupel/snow_deformation.h"
#include "graupel/snow_melt.h"
#include "graupel/water_surface.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define GR_STATE_NX 20
#define GR_STATE_NY 16
#define GR_STATE_CELLS (GR_STATE_NX * GR_STATE_NY)
#define GR_STATE_CORES 5

/* One core behind the same calls. */
typedef struct gr_state_core {
  const char *name;
  void *sim;
  gr_status (*size)(const void *s, size_t *bytes);
  gr_status (*save)(void *s, void *host, size_t bytes);
  gr_status (*load)(void *s, const void *host, size_t bytes);
  gr_status (*step)(void *s);
  gr_status (*ledger)(void *s);
  const char *(*last_error)(const void *s);
  void (*destroy)(void *s);
  unsigned char *valid, *stepped; /* the state, and one step on */
  size_t bytes;
} gr_state_core;

/* ---------------------------------------------------------- the adapters */

#define GR_STATE_ADAPT(core, step_call)                                                            \
  static gr_status core##_size(const void *s, size_t *b) {                                         \
    return gr_##core##_state_size((const gr_##core *)s, b);                                        \
  }                                                                                                \
  static gr_status core##_save(void *s, void *h, size_t b) {                                       \
    return gr_##core##_state_save((gr_##core *)s, h, b);                                           \
  }                                                                                                \
  static gr_status core##_load(void *s, const void *h, size_t b) {                                 \
    return gr_##core##_state_load((gr_##core *)s, h, b);                                           \
  }                                                                                                \
  static gr_status core##_step(void *sim) {                                                        \
    gr_##core *s = (gr_##core *)sim;                                                               \
    return step_call;                                                                              \
  }                                                                                                \
  static gr_status core##_ledger(void *s) {                                                        \
    gr_##core##_ledger led;                                                                        \
    return gr_##core##_ledger_get((gr_##core *)s, &led);                                           \
  }                                                                                                \
  static const char *core##_last_error(const void *s) {                                            \
    return gr_##core##_last_error((const gr_##core *)s);                                           \
  }                                                                                                \
  static void core##_destroy(void *s) {                                                            \
    gr_##core##_destroy((gr_##core *)s);                                                           \
  }

GR_STATE_ADAPT(rain_runoff, gr_rain_runoff_step(s, 0.5, 1))
GR_STATE_ADAPT(snow_accumulation, gr_snow_accumulation_step(s, 60.0))
GR_STATE_ADAPT(snow_deformation, gr_snow_deformation_step(s, 1.0 / 64.0))
GR_STATE_ADAPT(snow_melt, gr_snow_melt_advance(s, 3600.0, NULL))
GR_STATE_ADAPT(water_surface, gr_water_surface_step(s, 0.05, 1))

#define GR_STATE_ROW(core)                                                                         \
  {                                                                                                \
#core, NULL, core##_size, core##_save, core##_load, core##_step, core##_ledger,                \
        core##_last_error, core##_destroy, NULL, NULL, 0                                           \
  }

/* A box 0.5 m across (a closed mesh, counter-clockwise seen from outside). */
static const float gr_state_box_v[] = {
    -0.25f, -0.25f, -0.25f, 0.25f, -0.25f, -0.25f, 0.25f, 0.25f, -0.25f, -0.25f, 0.25f, -0.25f,
    -0.25f, -0.25f, 0.25f,  0.25f, -0.25f, 0.25f,  0.25f, 0.25f, 0.25f,  -0.25f, 0.25f, 0.25f};
static const int gr_state_box_t[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                     1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};

static gr_mesh gr_state_box_at(double x, double y, double z) {
  gr_mesh m = {gr_state_box_v, 8, gr_state_box_t, 12, {0}};
  m.transform[0] = m.transform[5] = m.transform[10] = m.transform[15] = 1.0;
  m.transform[12] = x, m.transform[13] = y, m.transform[14] = z;
  return m;
}

/* ------------------------------------------------------------- the set-up */

static gr_status gr_state_make_rain_runoff(gr_context *ctx, void **out) {
  const gr_grid g = {GR_STATE_NX, GR_STATE_NY, 5.0, 5.0, 0.0, 0.0, 0, 0, 0, 0, 0};
  float z[GR_STATE_CELLS];
  for (int c = 0; c < GR_STATE_CELLS; ++c)
    z[c] = (float)(0.05 * (c % GR_STATE_NX) + 0.3 * sin(0.7 * (c / GR_STATE_NX)));
  gr_rain_runoff_params p;
  gr_rain_runoff_params_init(&p);
  p.rain_rate = 50.0 / 3.6e6;
  gr_rain_runoff *s = NULL;
  gr_status st = gr_rain_runoff_create(ctx, &g, &p, &s);
  if (st == GR_OK)
    st = gr_rain_runoff_set_field(s, GR_FIELD_ELEVATION, z);
  if (st == GR_OK)
    st = gr_rain_runoff_step(s, 0.5, 8);
  *out = s;
  return st;
}

static gr_status gr_state_make_snow_accumulation(gr_context *ctx, void **out) {
  const gr_grid g = {GR_STATE_NX, GR_STATE_NY, 0.2, 0.2, 0.0, 0.0, 0, 0, 0, 0, 0};
  float z[GR_STATE_CELLS];
  for (int c = 0; c < GR_STATE_CELLS; ++c)
    z[c] = (float)(0.2 * sin(0.9 * (c % GR_STATE_NX)) * cos(0.5 * (c / GR_STATE_NX)));
  gr_snow_accumulation_params p;
  gr_snow_accumulation_params_init(&p);
  p.exposure_resolution = 16;
  p.snowfall_rate = 1e-4;
  p.blur_radius = 1;
  gr_snow_accumulation *s = NULL;
  gr_mesh box = gr_state_box_at(1.2, 1.0, 0.8);
  gr_status st = gr_snow_accumulation_create(ctx, &g, &p, &s);
  if (st == GR_OK)
    st = gr_snow_accumulation_set_field(s, GR_FIELD_ELEVATION, z);
  if (st == GR_OK)
    st = gr_snow_accumulation_set_objects(s, &box, 1);
  for (int k = 0; st == GR_OK && k < 3; ++k)
    st = gr_snow_accumulation_step(s, 60.0);
  *out = s;
  return st;
}

static gr_status gr_state_make_snow_deformation(gr_context *ctx, void **out) {
  const gr_grid g = {GR_STATE_NX, GR_STATE_NY, 0.1, 0.1, 0.0, 0.0, 0, 0, 0, 0, 0};
  float z[GR_STATE_CELLS], d[GR_STATE_CELLS];
  for (int c = 0; c < GR_STATE_CELLS; ++c) {
    z[c] = (float)(0.02 * (c % GR_STATE_NX));
    d[c] = (float)(0.3 + 0.05 * cos(c));
  }
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  gr_snow_deformation *s = NULL;
  gr_mesh box = gr_state_box_at(0.6, 0.5, 0.4);
  const double v[3] = {0.5, 0.0, 0.0};
  gr_status st = gr_snow_deformation_create(ctx, &g, &p, &s);
  if (st == GR_OK)
    st = gr_snow_deformation_set_field(s, GR_FIELD_ELEVATION, z);
  if (st == GR_OK)
    st = gr_snow_deformation_set_field(s, GR_FIELD_SNOW_DEPTH, d);
  if (st == GR_OK)
    st = gr_snow_deformation_set_objects(s, &box, 1, v);
  for (int k = 0; st == GR_OK && k < 3; ++k)
    st = gr_snow_deformation_step(s, 1.0 / 64.0);
  *out = s;
  return st;
}

static gr_status gr_state_make_snow_melt(gr_context *ctx, void **out) {
  const gr_grid g = {GR_STATE_NX, GR_STATE_NY, 25.0, 25.0, 0.0, 0.0, 0, 0, 0, 0, 0};
  float z[GR_STATE_CELLS], d[GR_STATE_CELLS], rho[GR_STATE_CELLS];
  for (int c = 0; c < GR_STATE_CELLS; ++c) {
    z[c] = (float)(1200.0 + 100.0 * sin(0.4 * (c % GR_STATE_NX)) + 10.0 * (c / GR_STATE_NX));
    d[c] = (float)(0.5 + 0.3 * sin(0.2 * c));
    rho[c] = 250.0f;
  }
  gr_snow_melt_params p;
  gr_snow_melt_params_init(&p);
  gr_snow_melt *s = NULL;
  const gr_snow_melt_forcing f = {4.0, 1.0, 0, 0};
  gr_status st = gr_snow_melt_create(ctx, &g, &p, &s);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(s, GR_FIELD_ELEVATION, z);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(s, GR_FIELD_SNOW_DEPTH, d);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(s, GR_FIELD_SNOW_DENSITY, rho);
  if (st == GR_OK)
    st = gr_snow_melt_set_terrain(s, z);
  if (st == GR_OK)
    st = gr_snow_melt_set_forcing(s, &f);
  if (st == GR_OK)
    st = gr_snow_melt_advance(s, 3.0 * 3600.0, NULL);
  *out = s;
  return st;
}

static gr_status gr_state_make_water_surface(gr_context *ctx, void **out) {
  const gr_grid g = {GR_STATE_NX, GR_STATE_NY, 0.5, 0.5, 0.0, 0.0, 0, 0, 0, 0, 0};
  float z[GR_STATE_CELLS], h[GR_STATE_CELLS];
  for (int c = 0; c < GR_STATE_CELLS; ++c) {
    double x = (c % GR_STATE_NX - 0.5 * (GR_STATE_NX - 1)) / (0.5 * GR_STATE_NX);
    double y = (c / GR_STATE_NX - 0.5 * (GR_STATE_NY - 1)) / (0.5 * GR_STATE_NY);
    z[c] = (float)(2.0 * (x * x + y * y) - 1.0);
    h[c] = (float)(0.01 * exp(-8.0 * (x * x + y * y)));
  }
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.use_lake_level = 1;
  p.lake_level = 0.0;
  p.drop_rate = 1.0;
  p.drop_amplitude = 0.01;
  gr_water_surface *s = NULL;
  gr_status st = gr_water_surface_create(ctx, &g, &p, &s);
  if (st == GR_OK)
    st = gr_water_surface_set_field(s, GR_FIELD_ELEVATION, z);
  if (st == GR_OK)
    st = gr_water_surface_set_wave(s, h);
  if (st == GR_OK)
    st = gr_water_surface_step(s, 0.05, 6);
  *out = s;
  return st;
}

/* Makes the five simulations on ctx (rows of cores in the order above),
 * each with its state saved in valid, stepped once and saved in stepped,
 * and left at the valid state again. GR_OK, or the failing status with the
 * core's name in *failed and its sentence in gr_last_error or its
 * last_error. */
static gr_status gr_state_cores_make(gr_context *ctx, gr_state_core cores[GR_STATE_CORES],
                                     const char **failed) {
  static const gr_state_core rows[GR_STATE_CORES] = {
      GR_STATE_ROW(rain_runoff), GR_STATE_ROW(snow_accumulation), GR_STATE_ROW(snow_deformation),
      GR_STATE_ROW(snow_melt), GR_STATE_ROW(water_surface)};
  gr_status (*make[GR_STATE_CORES])(gr_context *, void **) = {
      gr_state_make_rain_runoff, gr_state_make_snow_accumulation, gr_state_make_snow_deformation,
      gr_state_make_snow_melt, gr_state_make_water_surface};
  gr_status st = GR_OK;
  for (int k = 0; k < GR_STATE_CORES; ++k)
    cores[k] = rows[k];
  for (int k = 0; st == GR_OK && k < GR_STATE_CORES; ++k) {
    gr_state_core *c = &cores[k];
    *failed = c->name;
    st = make[k](ctx, &c->sim);
    if (st == GR_OK)
      st = c->size(c->sim, &c->bytes);
    if (st == GR_OK) {
      c->valid = malloc(c->bytes);
      c->stepped = malloc(c->bytes);
      if (!c->valid || !c->stepped)
        st = GR_ERR_OUT_OF_MEMORY;
    }
    if (st == GR_OK)
      st = c->save(c->sim, c->valid, c->bytes);
    if (st == GR_OK)
      st = c->step(c->sim);
    if (st == GR_OK)
      st = c->save(c->sim, c->stepped, c->bytes);
    if (st == GR_OK)
      st = c->load(c->sim, c->valid, c->bytes);
  }
  return st;
}

static void gr_state_cores_free(gr_state_core cores[GR_STATE_CORES]) {
  for (int k = 0; k < GR_STATE_CORES; ++k) {
    if (cores[k].sim)
      cores[k].destroy(cores[k].sim);
    free(cores[k].valid);
    free(cores[k].stepped);
    cores[k].sim = NULL;
    cores[k].valid = cores[k].stepped = NULL;
  }
}

#endif
