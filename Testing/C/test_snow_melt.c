/* Snow melt tests: the temperature index (SWE falls as MF (T - T0) t; the
 * release begins at the step the analysis gives), refreezing (all held
 * water), rain (held on snow, its heat c_w R T / L_f, nothing at 0 degC;
 * through on bare ground), radiation (north- and south-facing planes
 * against an independent sun-geometry formula; a point behind a wall gets
 * the temperature term only), settling (independent of the step), the
 * ledger over 10^4 steps of mixed weather, determinism, pieces (2 and 3
 * strips on threads give the whole grid's bits), checkpoints, every OpenCL
 * device present against the first (a GPU against PoCL: the integer state
 * within a stated tolerance, each ledger closed exactly), bad input and the
 * parameter table.
 *
 *   test_snow_melt            every subtest but memcheck
 *   test_snow_melt memcheck   the host-code paths only, on tiny grids */
#include "graupel/snow_melt.h"
#include "gr_test.h"
#include "gr_test_team.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static gr_context *ctx;

/* The defaults without radiation, shadows or settling's effect on tests of
 * water: a pure temperature index. */
static void plain_params(gr_snow_melt_params *p) {
  gr_snow_melt_params_init(p);
  p->radiation_factor = 0.0;
  p->cast_shadows = 0;
}

static float *filled(const gr_grid *g, float v) {
  size_t n = (size_t)g->nx * (size_t)g->ny;
  float *f = malloc(n * sizeof(float));
  for (size_t c = 0; c < n; ++c)
    f[c] = v;
  return f;
}

/* A simulation on g with uniform snow (depth m, rho kg/m^3) over ground z
 * (NULL: flat 0), the terrain set when p casts shadows. */
static gr_snow_melt *make(const gr_grid *g, const gr_snow_melt_params *p, const float *z,
                          float depth, float rho) {
  gr_snow_melt *s = NULL;
  gr_status st = gr_snow_melt_create(ctx, g, p, &s);
  CHECK_MSG(st == GR_OK, "%s", gr_last_error(NULL));
  if (st != GR_OK)
    return NULL;
  float *flat = filled(g, 0.0f), *d = filled(g, depth), *r = filled(g, rho);
  const float *ground = z ? z : flat;
  st = gr_snow_melt_set_field(s, GR_FIELD_ELEVATION, ground);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(s, GR_FIELD_SNOW_DEPTH, d);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(s, GR_FIELD_SNOW_DENSITY, r);
  if (st == GR_OK && p->cast_shadows)
    st = gr_snow_melt_set_terrain(s, ground);
  CHECK_MSG(st == GR_OK, "%s", gr_snow_melt_last_error(s));
  free(flat), free(d), free(r);
  return s;
}

static void force(gr_snow_melt *s, double t, double p) {
  gr_snow_melt_forcing f = {t, p, 0, 0};
  gr_status st = gr_snow_melt_set_forcing(s, &f);
  CHECK_MSG(st == GR_OK, "%s", gr_snow_melt_last_error(s));
}

static void advance(gr_snow_melt *s, double duration) {
  gr_status st = gr_snow_melt_advance(s, duration, NULL);
  CHECK_MSG(st == GR_OK, "%s", gr_snow_melt_last_error(s));
}

/* Output o at point c (of g's own points). */
static double at(gr_snow_melt *s, const gr_grid *g, gr_snow_melt_output o, int c) {
  float *v = filled(g, -1.0f);
  CHECK_MSG(gr_snow_melt_get(s, o, v) == GR_OK, "%s", gr_snow_melt_last_error(s));
  double x = v[c];
  free(v);
  return x;
}

static gr_snow_melt_ledger ledger(gr_snow_melt *s) {
  gr_snow_melt_ledger l;
  memset(&l, 0, sizeof(l));
  CHECK_MSG(gr_snow_melt_ledger_get(s, &l) == GR_OK, "%s", gr_snow_melt_last_error(s));
  return l;
}

/* ------------------------------------------------------------------ tests */

/* Flat snow at 5 degC, no radiation, no capacity: SWE falls as MF (T - T0)
 * t, all of it released. Then with capacity 0.1: the release begins at the
 * first step k with k m > 0.1 (F0 - k m), m the melt of a step. */
static void test_temperature_index(void) {
  const gr_grid g = {4, 3, 10.0, 10.0};
  gr_snow_melt_params p;
  plain_params(&p);
  p.liquid_capacity = 0.0;
  gr_snow_melt *s = make(&g, &p, NULL, 1.0f, 300.0f);
  force(s, 5.0, 0.0);
  advance(s, 10.0 * 86400.0);
  double want = 0.3 - p.melt_factor * 5.0 * 10.0 / 1000.0; /* 0.21 m */
  double swe = at(s, &g, GR_SNOW_MELT_SWE, 5);
  gr_snow_melt_ledger l = ledger(s);
  double area = g.dx * g.dy * g.nx * g.ny;
  printf("temperature index: SWE %.9f m after 10 days at 5 degC (MF %.1f): %.9f m; released "
         "%.9f m, melt rate %.6f mm/h\n",
         swe, p.melt_factor, want, l.released_volume / area, at(s, &g, GR_SNOW_MELT_MELT_RATE, 0));
  CHECK_NEAR(swe, want, 1e-6);
  CHECK_NEAR(l.melt_volume / area, 0.09, 1e-6);
  CHECK_NEAR(l.released_volume / area, 0.09, 1e-6);
  CHECK(l.stored_liquid_volume == 0.0);
  CHECK_NEAR(at(s, &g, GR_SNOW_MELT_MELT_RATE, 7), p.melt_factor * 5.0 / 24.0, 1e-6);
  CHECK_NEAR(at(s, &g, GR_SNOW_MELT_WATER_RELEASE, 7), p.melt_factor * 5.0 / 24.0, 1e-6);
  CHECK(l.balance_error == 0.0);
  gr_snow_melt_destroy(s);

  /* Capacity 0.1: melt m a step is held while k m <= 0.1 (0.3 - k m). */
  p.liquid_capacity = 0.1;
  s = make(&g, &p, NULL, 1.0f, 300.0f);
  force(s, 5.0, 0.0);
  double m = p.melt_factor * 5.0 / 24.0 / 1000.0, f0 = 0.3;
  int onset = (int)floor(p.liquid_capacity * f0 / (m * (1.0 + p.liquid_capacity))) + 1; /* 73 */
  int first = 0;
  for (int k = 1; k <= 100 && !first; ++k) {
    advance(s, 3600.0);
    gr_snow_melt_ledger lk = ledger(s);
    if (lk.released_volume > 0.0)
      first = k;
    else
      CHECK_NEAR(lk.stored_liquid_volume / area, k * m, 1e-8); /* float melt: 1e-7 relative */
  }
  printf("temperature index: with capacity 0.1 the release begins at step %d (analysis: %d, "
         "held water %.6f m = 0.1 x %.6f m)\n",
         first, onset, onset * m, f0 - onset * m);
  CHECK(onset == 73);
  CHECK(first == onset);
  double liquid = at(s, &g, GR_SNOW_MELT_LIQUID_WATER, 0), swe_now = at(s, &g, GR_SNOW_MELT_SWE, 0);
  CHECK_NEAR(liquid, p.liquid_capacity * (swe_now - liquid), 1e-8);
  gr_snow_melt_destroy(s);
}

/* Water held at the capacity refreezes when T drops below T0: at
 * RefreezeFactor (T0 - T) a day, and all of it in the end. */
static void test_refreeze(void) {
  const gr_grid g = {3, 3, 5.0, 5.0};
  gr_snow_melt_params p;
  plain_params(&p);
  p.liquid_capacity = 0.2;
  gr_snow_melt *s = make(&g, &p, NULL, 0.5f, 400.0f);
  force(s, 3.0, 0.0);
  advance(s, 24.0 * 3600.0);
  double area = g.dx * g.dy * g.nx * g.ny;
  gr_snow_melt_ledger warm = ledger(s);
  double held = warm.stored_liquid_volume / area;
  CHECK_NEAR(held, 1.8 * 3.0 / 1000.0, 1e-8); /* a day's melt, all held */
  force(s, -5.0, 0.0);
  advance(s, 3600.0 * 6.0);
  gr_snow_melt_ledger six = ledger(s);
  double rate = p.refreeze_factor * 5.0 / 1000.0; /* m a day */
  CHECK_NEAR((six.refrozen_volume - warm.refrozen_volume) / area, rate * 0.25, 1e-8);
  advance(s, 3.0 * 86400.0);
  gr_snow_melt_ledger cold = ledger(s);
  printf("refreeze: %.6f m held; %.6f m refroze in 6 h at -5 degC (%.6f); after 3 days %.9f m "
         "refrozen, %.3g m liquid left\n",
         held, (six.refrozen_volume - warm.refrozen_volume) / area, rate * 0.25,
         cold.refrozen_volume / area, cold.stored_liquid_volume / area);
  CHECK_NEAR(cold.refrozen_volume / area, held, 1e-6);
  CHECK(cold.stored_liquid_volume == 0.0);
  CHECK(at(s, &g, GR_SNOW_MELT_LIQUID_WATER, 4) == 0.0);
  CHECK_NEAR(at(s, &g, GR_SNOW_MELT_SWE, 4), 0.2 - 0.0054 + held, 1e-6);
  CHECK(cold.balance_error == 0.0);
  gr_snow_melt_destroy(s);
}

/* Rain at 0 degC on snow is held and melts nothing; at 4 degC its heat
 * melts c_w R T / L_f besides the temperature index. */
static void test_rain(void) {
  const gr_grid g = {3, 2, 10.0, 10.0};
  gr_snow_melt_params p;
  plain_params(&p);
  p.liquid_capacity = 0.5;
  p.rain_snow_threshold = -2.0; /* all rain from -1 degC */
  gr_snow_melt *s = make(&g, &p, NULL, 1.0f, 250.0f);
  force(s, 0.0, 2.0);
  advance(s, 5.0 * 3600.0);
  double area = g.dx * g.dy * g.nx * g.ny;
  gr_snow_melt_ledger l = ledger(s);
  printf("rain at 0 degC: liquid %.9f m for 10 mm of rain, melt %g m^3, snowfall %g m^3\n",
         at(s, &g, GR_SNOW_MELT_LIQUID_WATER, 2), l.melt_volume, l.snowfall_volume);
  CHECK_NEAR(at(s, &g, GR_SNOW_MELT_LIQUID_WATER, 2), 0.010, 1e-9);
  CHECK(l.melt_volume == 0.0);
  CHECK(l.snowfall_volume == 0.0);
  CHECK_NEAR(l.rain_volume / area, 0.010, 1e-9);
  CHECK(l.released_volume == 0.0);
  gr_snow_melt_destroy(s);

  s = make(&g, &p, NULL, 1.0f, 250.0f);
  force(s, 4.0, 2.0);
  advance(s, 3600.0);
  l = ledger(s);
  double rain_melt = 2.0 * 4186.0 * 4.0 / 334000.0, index = p.melt_factor * 4.0 / 24.0; /* mm */
  printf("rain at 4 degC: melt %.9f mm in an hour: rain heat %.9f + index %.9f mm\n",
         1000.0 * l.melt_volume / area, rain_melt, index);
  CHECK_NEAR(1000.0 * l.melt_volume / area, rain_melt + index, 1e-6);
  gr_snow_melt_destroy(s);
}

/* Rain on bare ground passes through: released = rain. */
static void test_bare_ground(void) {
  const gr_grid g = {3, 3, 2.0, 2.0};
  gr_snow_melt_params p;
  plain_params(&p);
  gr_snow_melt *s = make(&g, &p, NULL, 0.0f, 0.0f);
  force(s, 5.0, 3.0);
  CHECK(gr_snow_melt_mark(s) == GR_OK);
  advance(s, 2.0 * 3600.0);
  gr_snow_melt_ledger l = ledger(s);
  double area = g.dx * g.dy * g.nx * g.ny;
  printf("bare ground: rain %.9f m, released %.9f m, release rate %.6f mm/h, swe %g\n",
         l.rain_volume / area, l.released_volume / area, at(s, &g, GR_SNOW_MELT_WATER_RELEASE, 4),
         at(s, &g, GR_SNOW_MELT_SWE, 4));
  CHECK_NEAR(l.rain_volume / area, 0.006, 1e-9);
  CHECK(l.released_volume == l.rain_volume);
  CHECK(l.released_since_mark == l.rain_volume);
  CHECK_NEAR(at(s, &g, GR_SNOW_MELT_WATER_RELEASE, 4), 3.0, 1e-5);
  CHECK_NEAR(at(s, &g, GR_SNOW_MELT_RELEASED, 4), 0.006, 1e-9);
  CHECK(at(s, &g, GR_SNOW_MELT_SWE, 4) == 0.0 && at(s, &g, GR_SNOW_MELT_SNOW_DEPTH, 4) == 0.0);
  gr_snow_melt_destroy(s);
}

/* ------------------------------------------------------------- the sun */

/* The sun's unit vector (east, north, up) at local solar hour h of day d
 * and latitude lat (deg), worked out independently of the core: the sun's
 * direction in the equatorial frame (x towards the local meridian's
 * equator, y east, z the pole) dotted with the local east, north and
 * zenith; Spencer's (1971) declination and eccentricity. */
static void sun_vector(double lat, double d, double h, double v[3], double *ecc) {
  double g = 2.0 * PI * (d - 1.0) / 365.0;
  double decl = 0.006918 - 0.399912 * cos(g) + 0.070257 * sin(g) - 0.006758 * cos(2 * g) +
                0.000907 * sin(2 * g) - 0.002697 * cos(3 * g) + 0.00148 * sin(3 * g);
  *ecc = 1.000110 + 0.034221 * cos(g) + 0.001280 * sin(g) + 0.000719 * cos(2 * g) +
         0.000077 * sin(2 * g);
  double w = (h - 12.0) * PI / 12.0, phi = lat * PI / 180.0;
  double s[3] = {cos(decl) * cos(w), -cos(decl) * sin(w), sin(decl)};
  double east[3] = {0.0, 1.0, 0.0}, north[3] = {-sin(phi), 0.0, cos(phi)};
  double zenith[3] = {cos(phi), 0.0, sin(phi)};
  v[0] = s[0] * east[0] + s[1] * east[1] + s[2] * east[2];
  v[1] = s[0] * north[0] + s[1] * north[1] + s[2] * north[2];
  v[2] = s[0] * zenith[0] + s[1] * zenith[1] + s[2] * zenith[2];
}

/* Hock's I on a surface of unit normal n at sea level, averaged over the
 * 15-minute sub-steps of [h0, h0 + hours). */
static double mean_radiation(double lat, double day, double h0, double hours, const double n[3],
                             double psi) {
  int ns = (int)ceil(hours * 4.0 - 1e-9);
  double sum = 0.0;
  for (int q = 0; q < ns; ++q) {
    double v[3], ecc;
    sun_vector(lat, day, h0 + (q + 0.5) * hours / ns, v, &ecc);
    double cos_theta = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
    if (v[2] > 0.0 && cos_theta > 0.0)
      sum += 1368.0 * ecc * pow(psi, 1.0 / v[2]) * cos_theta;
  }
  return sum / ns;
}

/* A plane tilted 30 degrees facing north, one facing south (no shadows,
 * MF 0): over 3 hours from 09:00 on 21 June at 46 N their melt stands in the
 * ratio of the analytic I, each to 1e-4. Then a point behind an east-west
 * wall at noon (the sun due south, on sector 16 of 32) gets the temperature
 * term only, and a point before it the sun's. */
static void test_radiation(void) {
  const gr_grid g = {5, 5, 10.0, 10.0};
  gr_snow_melt_params p;
  gr_snow_melt_params_init(&p);
  p.melt_factor = 0.0;
  p.cast_shadows = 0;
  p.lapse_rate = 0.0;
  p.latitude = 46.0;
  p.start_day = 172;
  p.start_hour = 9.0;
  double tb = tan(30.0 * PI / 180.0), melt[2], want[2];
  for (int face = 0; face < 2; ++face) { /* 0: facing south (rising north), 1: north */
    float *z = filled(&g, 0.0f);
    double sign = face == 0 ? 1.0 : -1.0;
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        z[j * g.nx + i] = (float)(sign * tb * (j - 2) * g.dy);
    gr_snow_melt *s = make(&g, &p, z, 2.0f, 300.0f);
    force(s, 5.0, 0.0);
    advance(s, 3.0 * 3600.0);
    double n[3] = {0.0, -sign * tb / sqrt(1.0 + tb * tb), 1.0 / sqrt(1.0 + tb * tb)};
    double I = mean_radiation(p.latitude, p.start_day, p.start_hour, 3.0, n, p.transmissivity);
    want[face] = p.radiation_factor * I * 5.0; /* mm/h */
    melt[face] = at(s, &g, GR_SNOW_MELT_MELT_RATE, 12);
    double rad = at(s, &g, GR_SNOW_MELT_RADIATION, 12);
    printf("radiation: %s-facing 30 deg: melt %.6f mm/h (analytic %.6f), last-step I %.2f W/m^2, "
           "3-hour mean I %.2f W/m^2\n",
           face ? "north" : "south", melt[face], want[face], rad, I);
    CHECK_MSG(fabs(melt[face] / want[face] - 1.0) < 1e-4, "%.9g vs %.9g", melt[face], want[face]);
    free(z);
    gr_snow_melt_destroy(s);
  }
  double ratio = melt[0] / melt[1], ratio_want = want[0] / want[1];
  printf("radiation: south/north ratio %.6f, analytic %.6f\n", ratio, ratio_want);
  CHECK(ratio > 1.5);
  CHECK_MSG(fabs(ratio / ratio_want - 1.0) < 1e-4, "%.9g vs %.9g", ratio, ratio_want);

  /* The wall: 50 m high along row 20 of a flat 32 x 32 grid of 1 m; a step
   * of 60 s around noon (one sub-step, the sun due south). */
  const gr_grid w = {32, 32, 1.0, 1.0};
  p.melt_factor = 1.8;
  p.cast_shadows = 1;
  p.time_step = 60.0;
  p.start_hour = 12.0 - 0.5 / 60.0;
  float *z = filled(&w, 0.0f);
  for (int i = 0; i < w.nx; ++i)
    z[20 * w.nx + i] = 50.0f;
  gr_snow_melt *s = make(&w, &p, z, 1.0f, 300.0f);
  force(s, 5.0, 0.0);
  advance(s, 60.0);
  int behind = 24 * w.nx + 16, before = 10 * w.nx + 16;
  double index = p.melt_factor / 24.0 * 5.0; /* mm/h */
  double shade_melt = at(s, &w, GR_SNOW_MELT_MELT_RATE, behind);
  double lit_melt = at(s, &w, GR_SNOW_MELT_MELT_RATE, before);
  double up[3] = {0.0, 0.0, 1.0};
  double I =
      mean_radiation(p.latitude, p.start_day, p.start_hour, 1.0 / 60.0, up, p.transmissivity);
  printf("shadow: behind the wall melt %.6f mm/h (index alone %.6f), radiation %g; before it "
         "%.6f mm/h (%.6f), radiation %.2f W/m^2 (analytic %.2f)\n",
         shade_melt, index, at(s, &w, GR_SNOW_MELT_RADIATION, behind), lit_melt,
         (p.melt_factor / 24.0 + p.radiation_factor * I) * 5.0,
         at(s, &w, GR_SNOW_MELT_RADIATION, before), I);
  CHECK(at(s, &w, GR_SNOW_MELT_RADIATION, behind) == 0.0);
  /* To the state's resolution: one 2^-32 m unit in the 60 s step, 1.4e-5 mm/h. */
  CHECK_NEAR(shade_melt, index, 1000.0 * 3600.0 / 60.0 / 4294967296.0);
  CHECK_MSG(fabs(at(s, &w, GR_SNOW_MELT_RADIATION, before) / I - 1.0) < 1e-4, "lit I");
  CHECK_NEAR(lit_melt, (p.melt_factor / 24.0 + p.radiation_factor * I) * 5.0, 1e-4 * lit_melt);
  free(z);
  gr_snow_melt_destroy(s);
}

/* Settling towards MaxDensity: ten steps of a day and 240 of an hour give
 * the same density, MaxDensity - (MaxDensity - rho0) e^-1 after 10 days. */
static void test_settling(void) {
  const gr_grid g = {2, 2, 1.0, 1.0};
  gr_snow_melt_params p;
  plain_params(&p);
  double rho[2], depth[2];
  for (int k = 0; k < 2; ++k) {
    p.time_step = k ? 3600.0 : 86400.0;
    gr_snow_melt *s = make(&g, &p, NULL, 1.0f, 150.0f);
    force(s, -5.0, 0.0);
    advance(s, 10.0 * 86400.0);
    rho[k] = at(s, &g, GR_SNOW_MELT_SNOW_DENSITY, 3);
    depth[k] = at(s, &g, GR_SNOW_MELT_SNOW_DEPTH, 3);
    CHECK(ledger(s).steps == (k ? 240 : 10));
    gr_snow_melt_destroy(s);
  }
  double want = p.max_density - (p.max_density - 150.0) * exp(-1.0);
  printf("settling: 10 days in 10 steps %.6f kg/m^3, in 240 steps %.6f, analytic %.6f; depth "
         "%.6f m (SWE 0.15 m)\n",
         rho[0], rho[1], want, depth[1]);
  CHECK_NEAR(rho[0], rho[1], 1e-5 * want);
  CHECK_NEAR(rho[1], want, 1e-5 * want);
  CHECK_NEAR(depth[1], 0.15 * 1000.0 / rho[1], 1e-6);
}

/* Hills of 16 x 12 points with snow deeper on the heights, 10^4 hourly
 * steps of changing weather (snowfall, rain, warm, cold, a per-point
 * temperature), marked every 50: the balance closes to 1e-6 of the water
 * in (it is exact), the outputs agree with the ledger, and every process
 * took part. */
static void test_ledger(void) {
  const gr_grid g = {16, 12, 20.0, 20.0};
  const size_t n = (size_t)g.nx * g.ny;
  gr_snow_melt_params p;
  gr_snow_melt_params_init(&p);
  p.start_day = 60;
  float *z = malloc(n * sizeof(float)), *d = malloc(n * sizeof(float));
  float *tf = malloc(n * sizeof(float)), *v = malloc(n * sizeof(float));
  for (size_t c = 0; c < n; ++c) {
    double i = (double)(c % g.nx), j = (double)(c / g.nx);
    z[c] = (float)(1500.0 + 120.0 * sin(0.5 * i) * cos(0.4 * j) + 8.0 * j);
    d[c] = (float)(0.2 + 0.6 * (z[c] - 1380.0) / 240.0);
    tf[c] = (float)(1.5 - 0.3 * i);
  }
  gr_snow_melt *s = make(&g, &p, z, 0.0f, 200.0f);
  CHECK(gr_snow_melt_set_field(s, GR_FIELD_SNOW_DEPTH, d) == GR_OK);
  CHECK(gr_snow_melt_set_field(s, GR_SNOW_MELT_TEMPERATURE, tf) == GR_OK);
  const double weather[5][2] = {{-3.0, 2.0}, {4.0, 3.0}, {8.0, 0.0}, {-8.0, 0.5}, {0.0, 1.0}};
  double released_by_marks = 0.0;
  const double area = g.dx * g.dy;
  for (int k = 0; k < 200; ++k) {
    gr_snow_melt_forcing f = {weather[k % 5][0] + 3.0, weather[k % 5][1], k % 7 == 3, 0};
    CHECK(gr_snow_melt_set_forcing(s, &f) == GR_OK);
    CHECK(gr_snow_melt_mark(s) == GR_OK);
    advance(s, 50.0 * 3600.0);
    CHECK(gr_snow_melt_get(s, GR_SNOW_MELT_RELEASED, v) == GR_OK);
    for (size_t c = 0; c < n; ++c)
      released_by_marks += v[c] * area;
  }
  gr_snow_melt_ledger l = ledger(s);
  double in = l.snowfall_in + l.snowfall_volume + l.rain_volume;
  double out = l.stored_swe_volume + l.stored_liquid_volume + l.released_volume;
  CHECK(gr_snow_melt_get(s, GR_SNOW_MELT_SWE, v) == GR_OK);
  double swe = 0.0;
  for (size_t c = 0; c < n; ++c)
    swe += v[c] * area;
  printf("ledger: %lld steps; in %.6f m^3 (initial %.6f, snow %.6f, rain %.6f); melt %.6f, "
         "refrozen %.6f, released %.6f (by marks %.6f), stored %.6f + %.6f; balance error %.3g "
         "m^3, in - out %.3g m^3\n",
         l.steps, in, l.snowfall_in, l.snowfall_volume, l.rain_volume, l.melt_volume,
         l.refrozen_volume, l.released_volume, released_by_marks, l.stored_swe_volume,
         l.stored_liquid_volume, l.balance_error, in - out);
  CHECK(l.steps == 10000);
  CHECK(fabs(l.balance_error) <= 1e-6 * in);
  CHECK(fabs(in - out) <= 1e-6 * in);
  CHECK(l.snowfall_volume > 0.0 && l.rain_volume > 0.0 && l.melt_volume > 0.0);
  CHECK(l.refrozen_volume > 0.0 && l.released_volume > 0.0);
  CHECK_NEAR(released_by_marks, l.released_volume, 1e-6 * l.released_volume);
  CHECK_NEAR(swe, l.stored_swe_volume + l.stored_liquid_volume, 1e-6 * in);
  free(z), free(d), free(tf), free(v);
  gr_snow_melt_destroy(s);
}

/* ---------------------------------------------- determinism and pieces */

/* The domain the bit-for-bit tests share: 20 x 24 points of 5 m, hills and
 * a wall across row 13 (shadows across the cuts), snow varying, a
 * per-point precipitation field; three advances of changing weather with
 * marks between. */
enum { PC_NX = 20, PC_NY = 24, PC_MAX = 3 };

typedef struct pc_domain {
  gr_grid g;
  float *z, *depth, *rho, *precip;
} pc_domain;

static pc_domain pc_make(void) {
  pc_domain dm;
  gr_grid g = {.nx = PC_NX, .ny = PC_NY, .dx = 5.0, .dy = 5.0, .x0 = 3.0, .y0 = -2.0};
  dm.g = g;
  size_t n = (size_t)PC_NX * PC_NY;
  dm.z = malloc(n * 4), dm.depth = malloc(n * 4), dm.rho = malloc(n * 4), dm.precip = malloc(n * 4);
  for (size_t c = 0; c < n; ++c) {
    int i = (int)(c % PC_NX), j = (int)(c / PC_NX);
    dm.z[c] = (float)(800.0 + 30.0 * sin(0.4 * i) * cos(0.3 * j) + (j == 13 ? 25.0 : 0.0));
    dm.depth[c] = (float)(0.3 + 0.02 * ((i * 7 + j * 3) % 11));
    dm.rho[c] = (float)(180.0 + 5.0 * ((i + 2 * j) % 9));
    dm.precip[c] = (float)(0.5 + 0.1 * (i % 5));
  }
  return dm;
}

static void pc_free(pc_domain *dm) {
  free(dm->z), free(dm->depth), free(dm->rho), free(dm->precip);
}

static void pc_params(gr_snow_melt_params *p) {
  gr_snow_melt_params_init(p);
  p->start_day = 80;
  p->start_hour = 7.0;
  p->time_step = 1800.0;
}

/* The weather of run part k: T_ref, precipitation, the field or not. */
static const double pc_weather[4][3] = {
    {9.0, 1.0, 1}, {2.0, 0.0, 0}, {-4.0, 2.0, 1}, {12.0, 0.5, 0}};

/* Advances parts k0 .. k1 - 1 of the run (each 7 h, marked first). */
static gr_status pc_drive(gr_snow_melt *s, int k0, int k1) {
  gr_status st = GR_OK;
  for (int k = k0; st == GR_OK && k < k1; ++k) {
    gr_snow_melt_forcing f = {pc_weather[k][0], pc_weather[k][1], 0, (int)pc_weather[k][2]};
    st = gr_snow_melt_set_forcing(s, &f);
    if (st == GR_OK)
      st = gr_snow_melt_mark(s);
    if (st == GR_OK)
      st = gr_snow_melt_advance(s, 7.0 * 3600.0, NULL);
  }
  return st;
}

/* A piece of rows j0 .. j0 + ny - 1 (the whole grid for j0 0, ny PC_NY),
 * its local arrays cut from the domain's with a ring of 1. */
static gr_snow_melt *pc_piece(const pc_domain *dm, int j0, int ny, gr_grid *g) {
  *g = dm->g;
  int whole = j0 == 0 && ny == PC_NY;
  g->ny = ny, g->j0 = j0;
  if (!whole)
    g->global_ny = PC_NY, g->global_nx = PC_NX, g->ghost = 1;
  int lo = j0 > 0 && !whole ? j0 - 1 : 0;
  gr_snow_melt_params p;
  pc_params(&p);
  gr_snow_melt *s = NULL;
  gr_status st = gr_snow_melt_create(ctx, g, &p, &s);
  CHECK_MSG(st == GR_OK, "piece: %s", gr_last_error(NULL));
  size_t off = (size_t)lo * PC_NX;
  if (st == GR_OK)
    st = gr_snow_melt_set_field(s, GR_FIELD_ELEVATION, dm->z + off);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(s, GR_FIELD_SNOW_DEPTH, dm->depth + off);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(s, GR_FIELD_SNOW_DENSITY, dm->rho + off);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(s, GR_SNOW_MELT_PRECIPITATION, dm->precip + off);
  if (st == GR_OK)
    st = gr_snow_melt_set_terrain(s, dm->z);
  CHECK_MSG(st == GR_OK, "piece input: %s", s ? gr_snow_melt_last_error(s) : "");
  return s;
}

/* Every output of the own rows, one after another (8 x nx x ny floats). */
static float *pc_outputs(gr_snow_melt *s, const gr_grid *g) {
  size_t own = (size_t)g->nx * g->ny;
  float *v = malloc(GR_SNOW_MELT_OUTPUT_COUNT * own * sizeof(float));
  for (int o = 0; o < GR_SNOW_MELT_OUTPUT_COUNT; ++o)
    CHECK(gr_snow_melt_get(s, (gr_snow_melt_output)o, v + o * own) == GR_OK);
  return v;
}

/* Values of a piece's outputs that differ from the whole grid's, by bits. */
static long pc_differ(const float *piece, const gr_grid *g, const float *whole) {
  size_t own = (size_t)g->nx * g->ny, all = (size_t)PC_NX * PC_NY;
  long d = 0;
  for (int o = 0; o < GR_SNOW_MELT_OUTPUT_COUNT; ++o)
    for (size_t c = 0; c < own; ++c)
      d += memcmp(&piece[o * own + c], &whole[o * all + (size_t)g->j0 * PC_NX + c], 4) != 0;
  return d;
}

/* Two runs of the whole domain: the same bits in every output and the
 * ledger; and the run does something everywhere (shadows, rain, melt). */
static void test_determinism(void) {
  pc_domain dm = pc_make();
  float *out[2];
  gr_snow_melt_ledger l[2];
  for (int r = 0; r < 2; ++r) {
    gr_grid g;
    gr_snow_melt *s = pc_piece(&dm, 0, PC_NY, &g);
    CHECK(pc_drive(s, 0, 4) == GR_OK);
    out[r] = pc_outputs(s, &g);
    l[r] = ledger(s);
    gr_snow_melt_destroy(s);
  }
  size_t all = (size_t)GR_SNOW_MELT_OUTPUT_COUNT * PC_NX * PC_NY;
  CHECK(memcmp(out[0], out[1], all * sizeof(float)) == 0);
  CHECK(memcmp(&l[0], &l[1], sizeof(l[0])) == 0);
  printf("determinism: two runs, %zu output values and the ledger the same bits; melt %.4f m^3, "
         "released %.4f m^3, rain %.4f m^3\n",
         all, l[0].melt_volume, l[0].released_volume, l[0].rain_volume);
  CHECK(l[0].melt_volume > 0.0 && l[0].rain_volume > 0.0 && l[0].snowfall_volume > 0.0);
  free(out[0]), free(out[1]);
  pc_free(&dm);
}

typedef struct pc_runner {
  gr_test_team *t;
  int rank, k0, k1, save_after, reductions;
  gr_grid g;
  gr_snow_melt *s;
  gr_status st;
  gr_snow_melt_ledger l;
  void *state;
  size_t state_bytes;
} pc_runner;

static gr_status pc_allreduce(void *user, double *values, int n, gr_reduce_op op) {
  pc_runner *r = user;
  gr_status st = gr_test_team_allreduce(r->t, r->rank, values, n, op);
  r->reductions += st == GR_OK;
  return st;
}

static void *pc_run(void *arg) {
  pc_runner *r = arg;
  gr_status st = pc_drive(r->s, r->k0, r->save_after ? r->save_after : r->k1);
  if (st == GR_OK && r->save_after) {
    st = gr_snow_melt_state_size(r->s, &r->state_bytes);
    r->state = st == GR_OK ? malloc(r->state_bytes) : NULL;
    if (r->state)
      st = gr_snow_melt_state_save(r->s, r->state, r->state_bytes);
    if (st == GR_OK)
      st = pc_drive(r->s, r->save_after, r->k1);
  }
  gr_status s2 = gr_snow_melt_ledger_get(r->s, &r->l);
  r->st = st != GR_OK ? st : s2;
  return NULL;
}

/* n pieces (cut at rows cuts[]) on threads against the whole grid: every
 * output and the ledger the same bits; again from each piece's checkpoint
 * after the second part. */
static void pc_split(const pc_domain *dm, int n, const int *cuts, const float *whole,
                     const gr_snow_melt_ledger *lw) {
  gr_test_team t;
  gr_test_team_init(&t, n, 64);
  pc_runner rn[PC_MAX];
  int ok = 1;
  for (int k = 0; k < n; ++k) {
    memset(&rn[k], 0, sizeof(rn[k]));
    int j0 = k ? cuts[k - 1] : 0, j1 = k + 1 < n ? cuts[k] : PC_NY;
    rn[k].t = &t, rn[k].rank = k, rn[k].k1 = 4, rn[k].save_after = 2;
    rn[k].s = pc_piece(dm, j0, j1 - j0, &rn[k].g);
    ok = ok && rn[k].s;
    if (rn[k].s)
      gr_snow_melt_set_allreduce(rn[k].s, pc_allreduce, &rn[k]);
  }
  for (int pass = 0; ok && pass < 2; ++pass) {
    gr_test_team_run(n, pc_run, rn, sizeof(rn[0]));
    for (int k = 0; k < n; ++k) {
      CHECK_MSG(rn[k].st == GR_OK, "%d pieces, piece %d: %s", n, k,
                gr_snow_melt_last_error(rn[k].s));
      float *v = pc_outputs(rn[k].s, &rn[k].g);
      long d = pc_differ(v, &rn[k].g, whole);
      free(v);
      int same = memcmp(&rn[k].l, lw, sizeof(*lw)) == 0;
      CHECK_MSG(d == 0 && same,
                "%d pieces%s: piece %d: %ld output values differ from the whole grid's, the "
                "ledger %s (released %.17g vs %.17g)",
                n, pass ? " from the checkpoints" : "", k, d, same ? "equal" : "differs",
                rn[k].l.released_volume, lw->released_volume);
    }
    /* Again from the checkpoints saved after the second part. */
    for (int k = 0; k < n; ++k) {
      ok = ok && rn[k].state &&
           gr_snow_melt_state_load(rn[k].s, rn[k].state, rn[k].state_bytes) == GR_OK;
      rn[k].k0 = 2, rn[k].save_after = 0;
    }
  }
  CHECK(ok);
  if (ok && n > 1)
    CHECK(gr_snow_melt_state_load(rn[1].s, rn[0].state, rn[0].state_bytes) ==
          GR_ERR_INVALID_ARGUMENT);
  printf("pieces: %d strips (ring 1 row): every output and the ledger equal the whole grid's "
         "bits, from the checkpoints too (%d reductions on piece 0)\n",
         n, rn[0].reductions);
  for (int k = 0; k < n; ++k) {
    gr_snow_melt_destroy(rn[k].s);
    free(rn[k].state);
  }
  gr_test_team_destroy(&t);
}

static void test_pieces(void) {
  pc_domain dm = pc_make();
  gr_grid g;
  gr_snow_melt *s = pc_piece(&dm, 0, PC_NY, &g);
  CHECK(pc_drive(s, 0, 4) == GR_OK);
  float *whole = pc_outputs(s, &g);
  gr_snow_melt_ledger lw = ledger(s);
  gr_snow_melt_destroy(s);
  /* The shadows reach across the cuts: the wall's shade lies north of row 13. */
  const int cuts2[1] = {12}, cuts3[2] = {8, 14};
  pc_split(&dm, 2, cuts2, whole, &lw);
  pc_split(&dm, 3, cuts3, whole, &lw);
  /* The contract: whole rows, a ring of 1. */
  gr_snow_melt_params p;
  pc_params(&p);
  g = dm.g;
  g.ny = 12, g.j0 = 12, g.global_ny = PC_NY, g.ghost = 0;
  CHECK(gr_snow_melt_create(ctx, &g, &p, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  g.ghost = 1, g.nx = 10, g.global_nx = PC_NX;
  CHECK(gr_snow_melt_create(ctx, &g, &p, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  free(whole);
  pc_free(&dm);
}

/* Save after 2 parts, go on; load into a new simulation, go on: the same
 * bits. */
static void test_checkpoint(void) {
  pc_domain dm = pc_make();
  gr_grid g;
  gr_snow_melt *a = pc_piece(&dm, 0, PC_NY, &g), *b = pc_piece(&dm, 0, PC_NY, &g);
  CHECK(pc_drive(a, 0, 2) == GR_OK);
  size_t bytes = 0;
  CHECK(gr_snow_melt_state_size(a, &bytes) == GR_OK && bytes > 0);
  void *state = malloc(bytes);
  CHECK(gr_snow_melt_state_save(a, state, bytes) == GR_OK);
  CHECK(pc_drive(a, 2, 4) == GR_OK);
  CHECK(gr_snow_melt_state_load(b, state, bytes - 1) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_snow_melt_state_load(b, state, bytes) == GR_OK);
  CHECK(pc_drive(b, 2, 4) == GR_OK);
  float *va = pc_outputs(a, &g), *vb = pc_outputs(b, &g);
  gr_snow_melt_ledger la = ledger(a), lb = ledger(b);
  size_t all = (size_t)GR_SNOW_MELT_OUTPUT_COUNT * PC_NX * PC_NY;
  CHECK(memcmp(va, vb, all * sizeof(float)) == 0);
  CHECK(memcmp(&la, &lb, sizeof(la)) == 0);
  printf("checkpoint: %zu bytes; the loaded run equals the uninterrupted one (%lld steps, "
         "released %.6f m^3)\n",
         bytes, lb.steps, lb.released_volume);
  /* Reset: back to the initial snow. */
  CHECK(gr_snow_melt_reset(b) == GR_OK);
  gr_snow_melt_ledger l0 = ledger(b);
  CHECK(l0.steps == 0 && l0.time == 0.0 && l0.stored_swe_volume == la.snowfall_in);
  free(va), free(vb), free(state);
  gr_snow_melt_destroy(a);
  gr_snow_melt_destroy(b);
  pc_free(&dm);
}

/* --------------------------------------------------- devices agree */

/* Bytes before the frozen integers in a checkpoint: the state's size of a
 * 2 x 2 and a 3 x 2 grid give the bytes a point and the header; the
 * frozen (8 a point) and then the liquid integers (8) follow it
 * (snow_melt_step.c's gr_sm_state_parts). */
static size_t dv_header_bytes(gr_context *c) {
  gr_snow_melt_params p;
  plain_params(&p);
  size_t size[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    gr_grid g = {2 + k, 2, 1.0, 1.0};
    gr_snow_melt *s = NULL;
    CHECK(gr_snow_melt_create(c, &g, &p, &s) == GR_OK);
    CHECK(gr_snow_melt_state_size(s, &size[k]) == GR_OK);
    gr_snow_melt_destroy(s);
  }
  size_t per_point = (size[1] - size[0]) / 2;
  return size[0] - 4 * per_point;
}

enum { DV_NX = 64, DV_NY = 48, DV_MAX = 8 };

/* One device's run: the integer state, every output, the ledger. */
typedef struct dv_run {
  char name[128];
  long long *frozen, *liquid;
  float *out;
  gr_snow_melt_ledger l;
} dv_run;

/* The scenario on device `name`: 64 x 48 hills of 25 m (1150 to 1650 m),
 * sun and cast shadows on, varying snow, 48 hourly steps in 4 parts of
 * 12 h, each marked first: warm sun (melt, the liquid held and released),
 * rain on the lower and snow on the upper slopes (the per-point
 * precipitation field), a cold night with snowfall (refreezing), a warm
 * morning again. 0 when the device could not run it. */
static int dv_scenario(const char *name, dv_run *r) {
  gr_context_options opt;
  gr_context_options_init(&opt);
  opt.device = name;
  gr_context *c = NULL;
  gr_status st = gr_context_create(&opt, &c);
  CHECK_MSG(st == GR_OK, "%s: %s", name, gr_last_error(NULL));
  if (st != GR_OK)
    return 0;
  const gr_grid g = {DV_NX, DV_NY, 25.0, 25.0, 1000.0, 2000.0};
  const size_t n = (size_t)DV_NX * DV_NY;
  float *z = malloc(n * 4), *d = malloc(n * 4), *rho = malloc(n * 4), *pr = malloc(n * 4);
  for (size_t k = 0; k < n; ++k) {
    double i = (double)(k % DV_NX), j = (double)(k / DV_NX);
    z[k] = (float)(1400.0 + 150.0 * sin(0.21 * i) * cos(0.17 * j) + 4.0 * j -
                   60.0 * exp(-((i - 40.0) * (i - 40.0) + (j - 20.0) * (j - 20.0)) / 50.0));
    d[k] = (float)(0.15 + 0.5 * (z[k] - 1150.0) / 500.0 + 0.05 * sin(0.9 * i + 0.4 * j));
    rho[k] = (float)(220.0 + 40.0 * cos(0.3 * i - 0.2 * j));
    pr[k] = (float)(1.0 + 0.8 * sin(0.11 * i + 0.07 * j));
  }
  gr_snow_melt_params p;
  gr_snow_melt_params_init(&p);
  p.start_day = 110;
  p.start_hour = 5.0;
  p.time_step = 3600.0;
  p.reference_elevation = 1400.0;
  p.cast_shadows = 1;
  /* T_ref at 1400 m, precipitation (constant, or the field) by part. */
  const gr_snow_melt_forcing weather[4] = {
      {7.0, 0.0, 0, 0}, {1.0, 0.0, 0, 1}, {-6.0, 0.6, 0, 0}, {9.0, 0.0, 0, 0}};
  gr_snow_melt *s = NULL;
  st = gr_snow_melt_create(c, &g, &p, &s);
  CHECK_MSG(st == GR_OK, "%s: %s", name, gr_last_error(NULL));
  const int fields[4] = {GR_FIELD_ELEVATION, GR_FIELD_SNOW_DEPTH, GR_FIELD_SNOW_DENSITY,
                         GR_SNOW_MELT_PRECIPITATION};
  const float *values[4] = {z, d, rho, pr};
  for (int k = 0; st == GR_OK && k < 4; ++k)
    st = gr_snow_melt_set_field(s, fields[k], values[k]);
  if (st == GR_OK)
    st = gr_snow_melt_set_terrain(s, z);
  for (int k = 0; st == GR_OK && k < 4; ++k) {
    st = gr_snow_melt_set_forcing(s, &weather[k]);
    if (st == GR_OK)
      st = gr_snow_melt_mark(s);
    if (st == GR_OK)
      st = gr_snow_melt_advance(s, 12.0 * 3600.0, NULL);
  }
  CHECK_MSG(st == GR_OK, "%s: %s", name, s ? gr_snow_melt_last_error(s) : "");
  size_t bytes = 0, head = dv_header_bytes(c);
  unsigned char *state = NULL;
  if (st == GR_OK)
    st = gr_snow_melt_state_size(s, &bytes);
  if (st == GR_OK && bytes >= head + 16 * n) {
    state = malloc(bytes);
    st = gr_snow_melt_state_save(s, state, bytes);
  }
  CHECK_MSG(st == GR_OK && state, "%s: state of %zu bytes", name, bytes);
  int ok = st == GR_OK && state != NULL;
  if (ok) {
    snprintf(r->name, sizeof(r->name), "%s", name);
    r->frozen = malloc(8 * n), r->liquid = malloc(8 * n);
    memcpy(r->frozen, state + head, 8 * n);
    memcpy(r->liquid, state + head + 8 * n, 8 * n);
    r->out = pc_outputs(s, &g);
    r->l = ledger(s);
  }
  free(state), free(z), free(d), free(rho), free(pr);
  gr_snow_melt_destroy(s);
  gr_context_release(c);
  return ok;
}

/* The scenario above on every OpenCL device present (a GPU against PoCL),
 * as test_procedural_terrain's devices_agree: with one device there is
 * nothing to compare. Each device closes its ledger exactly (balance 0:
 * integers). Between devices the transfers are rounded to the state's
 * integers (2^-32 m) from floats that the transcendental functions feed
 * (exp in the radiation, sin, cos and atan in the horizons, divisions in
 * the rain fraction and the density): OpenCL 1.2 lets them differ by a few
 * ULP (exp 3, sin/cos 4, atan 5, divide 2.5), and FP_CONTRACT is off, so
 * nothing else differs. A step's largest transfer here is about 2e7 units
 * (5 mm); a few ULP of it, about 5 units, over 48 steps bound a point's
 * frozen and liquid integers to some 250 units: they are held to DV_UNITS
 * (1024 units, 2.4e-7 m w.e.). An H200 against PoCL 5.0 differs at 70 %
 * of the points by at most 10 units. Beyond that, a point whose horizon
 * angle and the sun's elevation differ by no more than those ULPs would be
 * lit in a sub-step on one device and shaded on the other (a quarter hour
 * of sun, up to some mm w.e.; none seen): at most DV_FLIPS_PER_MILLE points
 * a thousand may do that, by at most 1 cm w.e. */
#define DV_UNITS 1024LL
#define DV_FLIPS_PER_MILLE 5
static void test_devices_agree(void) {
  int count = 0;
  gr_device_info infos[DV_MAX];
  if (gr_device_list(infos, DV_MAX, &count) != GR_OK || count < 2) {
    printf("one OpenCL device: cross-device agreement not tested here\n");
    return;
  }
  const size_t n = (size_t)DV_NX * DV_NY;
  dv_run runs[DV_MAX];
  memset(runs, 0, sizeof(runs));
  int have = 0;
  for (int k = 0; k < count && k < DV_MAX; ++k) {
    /* Identical GPUs share a name: the first of them stands for all. */
    int seen = 0;
    for (int q = 0; q < have; ++q)
      seen |= strcmp(runs[q].name, infos[k].name) == 0;
    if (seen || !dv_scenario(infos[k].name, &runs[have]))
      continue;
    const gr_snow_melt_ledger *l = &runs[have].l;
    printf("%s: balance error %.3g m^3; melt %.6f, rain %.6f, snow %.6f, refrozen %.6f, "
           "released %.6f m^3 over %lld steps\n",
           infos[k].name, l->balance_error, l->melt_volume, l->rain_volume, l->snowfall_volume,
           l->refrozen_volume, l->released_volume, l->steps);
    CHECK_MSG(l->balance_error == 0.0, "%s: balance error %.3g m^3", infos[k].name,
              l->balance_error);
    CHECK(l->steps == 48 && l->melt_volume > 0.0 && l->rain_volume > 0.0 &&
          l->snowfall_volume > 0.0 && l->refrozen_volume > 0.0 && l->released_volume > 0.0);
    ++have;
  }
  for (int k = 1; k < have; ++k) {
    long long worst = 0, worst_flip = 0;
    long differ = 0, flips = 0, out_differ = 0;
    for (size_t c = 0; c < n; ++c) {
      long long dF = llabs(runs[k].frozen[c] - runs[0].frozen[c]);
      long long dL = llabs(runs[k].liquid[c] - runs[0].liquid[c]);
      long long dmax = dF > dL ? dF : dL;
      differ += dmax != 0;
      if (dmax > DV_UNITS) {
        ++flips;
        worst_flip = dmax > worst_flip ? dmax : worst_flip;
      } else {
        worst = dmax > worst ? dmax : worst;
      }
    }
    for (size_t v = 0; v < GR_SNOW_MELT_OUTPUT_COUNT * n; ++v)
      out_differ += memcmp(&runs[k].out[v], &runs[0].out[v], 4) != 0;
    double mean_melt = runs[0].l.melt_volume / (25.0 * 25.0 * (double)n);
    printf("%s vs %s: frozen/liquid integers differ at %ld of %zu points, by at most %lld "
           "units (%.3g m) within the ULP tolerance; %ld points beyond %lld units (shadow "
           "flips), the largest %.3g m (mean melt %.4f m); %ld of %zu output values differ in "
           "their bits\n",
           runs[k].name, runs[0].name, differ, n, worst, (double)worst * 0x1p-32, flips, DV_UNITS,
           (double)worst_flip * 0x1p-32, mean_melt, out_differ,
           (size_t)GR_SNOW_MELT_OUTPUT_COUNT * n);
    CHECK_MSG((size_t)flips * 1000 <= (size_t)DV_FLIPS_PER_MILLE * n,
              "%s: %ld points differ by more than %lld units", runs[k].name, flips, DV_UNITS);
    CHECK_MSG(worst_flip <= (long long)(0.01 * 4294967296.0), "%s: a point differs by %.3g m w.e.",
              runs[k].name, (double)worst_flip * 0x1p-32);
  }
  for (int k = 0; k < have; ++k)
    free(runs[k].frozen), free(runs[k].liquid), free(runs[k].out);
}

/* ------------------------------------------------------------ bad input */

/* One sentence: not empty, ends with a full stop, no new line. */
static int one_sentence(const char *m) {
  size_t n = strlen(m);
  return n > 10 && m[n - 1] == '.' && !strchr(m, '\n');
}

static void test_errors(void) {
  const gr_grid g = {4, 4, 1.0, 1.0};
  gr_snow_melt_params p;
  gr_snow_melt_params_init(&p);
  char msg[256];
  /* Latitude 91. */
  p.latitude = 91.0;
  CHECK(gr_snow_melt_params_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "Latitude") && one_sentence(msg), "%s", msg);
  gr_snow_melt *s = NULL;
  CHECK(gr_snow_melt_create(ctx, &g, &p, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  CHECK(strstr(gr_last_error(NULL), "Latitude") != NULL);
  /* MaxDensity below NewSnowDensity. */
  gr_snow_melt_params_init(&p);
  p.max_density = 80.0;
  CHECK(gr_snow_melt_params_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "MaxDensity") && one_sentence(msg), "%s", msg);
  gr_snow_melt_params_init(&p);
  CHECK(gr_snow_melt_create(ctx, &g, &p, &s) == GR_OK && s);
  if (!s)
    return;
  /* Shadows without the terrain. */
  CHECK(gr_snow_melt_advance(s, 3600.0, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(gr_snow_melt_last_error(s), "terrain") &&
                one_sentence(gr_snow_melt_last_error(s)),
            "%s", gr_snow_melt_last_error(s));
  /* NaN forcing. */
  gr_snow_melt_forcing f = {NAN, 0.0, 0, 0};
  CHECK(gr_snow_melt_set_forcing(s, &f) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(gr_snow_melt_last_error(s), "air temperature") &&
                one_sentence(gr_snow_melt_last_error(s)),
            "%s", gr_snow_melt_last_error(s));
  f.air_temperature = 1.0, f.precipitation = INFINITY;
  CHECK(gr_snow_melt_set_forcing(s, &f) == GR_ERR_INVALID_ARGUMENT);
  f.precipitation = 0.0, f.use_temperature_field = 1;
  CHECK(gr_snow_melt_set_forcing(s, &f) == GR_ERR_INVALID_ARGUMENT); /* never set */
  /* A negative depth, a NaN temperature, a NaN terrain: the point named. */
  float *v = filled(&g, 0.5f);
  v[6] = -0.1f;
  CHECK(gr_snow_melt_set_field(s, GR_FIELD_SNOW_DEPTH, v) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(gr_snow_melt_last_error(s), "snow_depth") &&
                strstr(gr_snow_melt_last_error(s), "(2, 1)") &&
                one_sentence(gr_snow_melt_last_error(s)),
            "%s", gr_snow_melt_last_error(s));
  v[6] = NAN;
  CHECK(gr_snow_melt_set_field(s, GR_SNOW_MELT_TEMPERATURE, v) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_snow_melt_last_error(s), "NaN") != NULL);
  CHECK(gr_snow_melt_set_terrain(s, v) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_snow_melt_set_field(s, GR_FIELD_VELOCITY, v) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_snow_melt_advance(s, NAN, NULL) == GR_ERR_INVALID_ARGUMENT);
  /* Snow with a density of 0 is refused at the first step. */
  v[6] = 0.5f;
  CHECK(gr_snow_melt_set_field(s, GR_FIELD_SNOW_DEPTH, v) == GR_OK);
  float *zero = filled(&g, 0.0f);
  CHECK(gr_snow_melt_set_field(s, GR_FIELD_SNOW_DENSITY, zero) == GR_OK);
  CHECK(gr_snow_melt_set_terrain(s, zero) == GR_OK);
  CHECK(gr_snow_melt_advance(s, 3600.0, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_snow_melt_last_error(s), "density") != NULL);
  /* The initial snow is set before the first step only. */
  float *dense = filled(&g, 300.0f);
  CHECK(gr_snow_melt_set_field(s, GR_FIELD_SNOW_DENSITY, dense) == GR_OK);
  free(dense);
  CHECK(gr_snow_melt_advance(s, 3600.0, NULL) == GR_OK);
  CHECK(gr_snow_melt_set_field(s, GR_FIELD_SNOW_DEPTH, v) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_snow_melt_last_error(s), "reset") != NULL);
  CHECK(gr_snow_melt_get(s, GR_SNOW_MELT_OUTPUT_COUNT, v) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strcmp(gr_snow_melt_last_error(NULL), "") == 0);
  gr_snow_melt_destroy(s);
  gr_snow_melt_destroy(NULL);
  free(v), free(zero);
}

/* The table: the defaults pass; each row's ends pass and beyond them not. */
static void test_param_table(void) {
  int count = 0;
  const gr_param_bound *t = gr_snow_melt_param_bounds(&count);
  CHECK(t && count == 19);
  gr_snow_melt_params p;
  gr_snow_melt_params_init(&p);
  char msg[256];
  CHECK_MSG(gr_snow_melt_params_validate(&p, msg, sizeof(msg)) == GR_OK, "%s", msg);
  CHECK(p.settling_time == 10.0 * 86400.0 && p.horizon_sectors == 32 && p.cast_shadows == 1);
  CHECK(p.radiation_factor == 0.0006 && p.melt_factor == 1.8 && p.lapse_rate == -6.5);
  CHECK(gr_snow_melt_params_validate(NULL, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  const gr_param_bound *lat = gr_param_find(t, count, "Latitude");
  CHECK(lat && gr_param_accepts(lat, 90.0) && gr_param_accepts(lat, -90.0) &&
        !gr_param_accepts(lat, 90.5));
  const gr_param_bound *psi = gr_param_find(t, count, "Transmissivity");
  CHECK(psi && !gr_param_accepts(psi, 0.0) && gr_param_accepts(psi, 1.0));
  p.time_step = 0.5;
  CHECK(gr_snow_melt_params_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  gr_snow_melt_params_init(&p);
  p.start_day = 367;
  CHECK(gr_snow_melt_params_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  for (int o = 0; o < GR_SNOW_MELT_OUTPUT_COUNT; ++o)
    CHECK(gr_snow_melt_output_name((gr_snow_melt_output)o) != NULL);
  CHECK(gr_snow_melt_output_name(GR_SNOW_MELT_OUTPUT_COUNT) == NULL);
  gr_memory_need need;
  gr_grid g = {100, 50, 1.0, 1.0};
  CHECK(gr_snow_melt_memory(&g, NULL, &need) == GR_OK);
  CHECK(need.device == (112.0 + 128.0) * 5000.0 + 4.0 * 5000.0 && need.state == 80.0 * 5000 + 64);
}

/* Every host entry point once on a tiny grid (for valgrind). */
static void test_memcheck(void) {
  const gr_grid g = {3, 2, 1.0, 1.0};
  gr_snow_melt_params p;
  gr_snow_melt_params_init(&p);
  p.horizon_sectors = 8;
  gr_snow_melt *s = make(&g, &p, NULL, 0.4f, 200.0f);
  if (!s)
    return;
  float *v = filled(&g, 1.0f);
  CHECK(gr_snow_melt_set_field(s, GR_SNOW_MELT_TEMPERATURE, v) == GR_OK);
  CHECK(gr_snow_melt_set_field(s, GR_SNOW_MELT_PRECIPITATION, v) == GR_OK);
  gr_snow_melt_forcing f = {2.0, 1.0, 1, 1};
  CHECK(gr_snow_melt_set_forcing(s, &f) == GR_OK);
  CHECK(gr_snow_melt_mark(s) == GR_OK);
  CHECK(gr_snow_melt_advance(s, 7200.0, NULL) == GR_OK);
  for (int o = 0; o < GR_SNOW_MELT_OUTPUT_COUNT; ++o)
    CHECK(gr_snow_melt_get(s, (gr_snow_melt_output)o, v) == GR_OK);
  gr_snow_melt_ledger l = ledger(s);
  CHECK(l.steps == 2 && l.balance_error == 0.0);
  size_t bytes = 0;
  CHECK(gr_snow_melt_state_size(s, &bytes) == GR_OK);
  void *state = malloc(bytes);
  CHECK(gr_snow_melt_state_save(s, state, bytes) == GR_OK);
  CHECK(gr_snow_melt_state_load(s, state, bytes) == GR_OK);
  CHECK(gr_snow_melt_reset(s) == GR_OK);
  CHECK(gr_snow_melt_set_forcing(s, &(gr_snow_melt_forcing){NAN, 0.0, 0, 0}) ==
        GR_ERR_INVALID_ARGUMENT);
  free(state), free(v);
  gr_snow_melt_destroy(s);
}

static int setup(void) {
  if (gr_context_create(NULL, &ctx) != GR_OK)
    return 0;
  printf("device: %s\n", gr_context_device_name(ctx));
  return 1;
}

static void teardown(void) {
  gr_context_release(ctx);
}

static const gr_subtest tests[] = {
    {"temperature_index", test_temperature_index, 0},
    {"refreeze", test_refreeze, 0},
    {"rain", test_rain, 0},
    {"bare_ground", test_bare_ground, 0},
    {"radiation", test_radiation, 0},
    {"settling", test_settling, 0},
    {"ledger", test_ledger, 0},
    {"determinism", test_determinism, 0},
    {"pieces", test_pieces, 0},
    {"checkpoint", test_checkpoint, 0},
    {"devices_agree", test_devices_agree, 0},
    {"errors", test_errors, 0},
    {"param_table", test_param_table, 0},
    {"memcheck", test_memcheck, 1},
};

int main(int argc, char **argv) {
  return gr_test_main(argc, argv, tests, (int)(sizeof(tests) / sizeof(tests[0])), setup, teardown);
}
