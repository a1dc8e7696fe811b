/* Water surface tests: the wave speed (a pulse in a 1-D channel travels c t;
 * standing modes of a square basin keep the period 2 L / (c sqrt(m^2 +
 * n^2))), the mean level (the sum of the wave over the wet points constant
 * to float rounding, with damping and raindrops too), the energy (conserved
 * without damping, decaying as exp(-gamma t) with it), reflecting shores
 * (dry points never move; a pulse comes back from the shore at the right
 * time with its sign), normals (exactly (0, 0, 1) on a level surface, those
 * of a tilted plane), raindrops (only on wet points, none at DropRate 0),
 * determinism and checkpoints (bit for bit), pieces of a split domain (2
 * and 3 strips on threads give the whole grid's bits, fields and ledger),
 * the error paths and the parameter table.
 *
 *   test_water_surface            every subtest but memcheck
 *   test_water_surface memcheck   the host-code paths only, on tiny grids */
#include "graupel/water_surface.h"
#include "gr_test.h"
#include "gr_test_team.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static gr_context *ctx;

/* A lake at level 1 m over flat ground at 0 (every point wet) unless bed is
 * given; p may be NULL for the defaults without drops. */
static gr_water_surface *lake(const gr_grid *g, const gr_water_surface_params *p,
                              const float *bed) {
  gr_water_surface_params q;
  if (p) {
    q = *p;
  } else {
    gr_water_surface_params_init(&q);
    q.drop_rate = 0.0;
    q.damping = 0.0;
    q.lake_level = 1.0;
  }
  q.use_lake_level = 1;
  gr_water_surface *s = NULL;
  gr_status st = gr_water_surface_create(ctx, g, &q, &s);
  CHECK_MSG(st == GR_OK, "%s", gr_last_error(NULL));
  if (st == GR_OK && bed)
    st = gr_water_surface_set_field(s, GR_FIELD_ELEVATION, bed);
  CHECK_MSG(st == GR_OK, "%s", gr_water_surface_last_error(s));
  return s;
}

static float *field(const gr_grid *g, int comps) {
  return calloc((size_t)g->nx * (size_t)g->ny * (size_t)comps, sizeof(float));
}

/* The peak of row 1 at i > from, refined by a parabola through its neighbours. */
static double peak_after(const float *h, int nx, int from) {
  int best = from + 1;
  for (int i = from + 1; i < nx - 1; ++i)
    if (h[nx + i] > h[nx + best])
      best = i;
  double a = h[nx + best - 1], b = h[nx + best], c = h[nx + best + 1];
  double den = a - 2.0 * b + c;
  return best + (den != 0.0 ? 0.5 * (a - c) / den : 0.0);
}

/* ------------------------------------------------------------------ tests */

/* A Gaussian pulse in a channel 3 points wide splits into two halves that
 * travel at c: the right half's peak after t lies at x0 + c t. */
static void test_pulse_speed(void) {
  gr_grid g = {600, 3, 0.5, 0.5, 0.0, 0.0};
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.drop_rate = 0.0;
  p.damping = 0.0;
  p.wave_speed = 2.5;
  p.lake_level = 1.0;
  gr_water_surface *s = lake(&g, &p, NULL);
  float *h = field(&g, 1);
  const int x0 = 150;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i)
      h[j * g.nx + i] = (float)(0.1 * exp(-0.5 * pow((i - x0) * g.dx / 2.0, 2.0)));
  CHECK(gr_water_surface_set_wave(s, h) == GR_OK);
  const double t = 60.0; /* 150 m: 300 points */
  int steps = 0;
  CHECK_MSG(gr_water_surface_advance(s, t, &steps) == GR_OK, "%s", gr_water_surface_last_error(s));
  CHECK(gr_water_surface_get(s, GR_WATER_WAVE_HEIGHT, h) == GR_OK);
  double x = (peak_after(h, g.nx, x0 + 10) - x0) * g.dx, speed = x / t;
  printf("pulse: %d steps, travelled %.3f m in %.0f s: %.4f m/s for c = %.2f (%.3f %%); peak "
         "%.4f m (half the pulse: 0.05)\n",
         steps, x, t, speed, p.wave_speed, 100.0 * (speed / p.wave_speed - 1.0),
         h[g.nx + (int)(x0 + x / g.dx + 0.5)]);
  CHECK_MSG(fabs(speed / p.wave_speed - 1.0) < 0.01, "speed %g vs c %g", speed, p.wave_speed);
  CHECK_NEAR(h[g.nx + (int)(x0 + x / g.dx + 0.5)], 0.05, 0.005);
  free(h);
  gr_water_surface_destroy(s);
}

/* The value at point (i, j) over time; the period from its upward zero
 * crossings (linear interpolation between steps). */
static double standing_period(int m, int n, double c, double *expected) {
  const int N = 32;
  gr_grid g = {N, N, 1.0, 1.0, 0.0, 0.0};
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.drop_rate = 0.0;
  p.damping = 0.0;
  p.wave_speed = c;
  p.lake_level = 1.0;
  gr_water_surface *s = lake(&g, &p, NULL);
  float *h = field(&g, 1);
  /* The basin's wall lies half a spacing beyond the edge points: L = N dx,
   * and cos(m pi (i + 1/2) / N) is a mode of the masked Laplacian. */
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i)
      h[j * N + i] = (float)(0.01 * cos(m * PI * (i + 0.5) / N) * cos(n * PI * (j + 0.5) / N));
  CHECK(gr_water_surface_set_wave(s, h) == GR_OK);
  double dt = 0.0;
  CHECK(gr_water_surface_stable_dt(s, &dt) == GR_OK);
  *expected = 2.0 * N * g.dx / (c * sqrt((double)(m * m + n * n)));
  int total = (int)ceil(4.5 * *expected / dt), crossings = 0;
  double first = 0.0, last = 0.0, prev = h[0];
  for (int k = 1; k <= total; ++k) {
    if (gr_water_surface_step(s, dt, 1) != GR_OK ||
        gr_water_surface_get(s, GR_WATER_WAVE_HEIGHT, h) != GR_OK) {
      CHECK_MSG(0, "%s", gr_water_surface_last_error(s));
      break;
    }
    double now = h[0];
    if (prev < 0.0 && now >= 0.0) {
      double tc = (k - 1 + prev / (prev - now)) * dt;
      if (crossings++ == 0)
        first = tc;
      last = tc;
    }
    prev = now;
  }
  free(h);
  gr_water_surface_destroy(s);
  return crossings > 1 ? (last - first) / (crossings - 1) : 0.0;
}

static void test_standing_modes(void) {
  static const int modes[][2] = {{1, 0}, {1, 1}, {2, 1}};
  for (int k = 0; k < 3; ++k) {
    double expected = 0.0, c = 1.5;
    double T = standing_period(modes[k][0], modes[k][1], c, &expected);
    printf("mode (%d, %d): period %.4f s, 2 L / (c sqrt(m^2 + n^2)) = %.4f s (%.3f %%)\n",
           modes[k][0], modes[k][1], T, expected, 100.0 * (T / expected - 1.0));
    CHECK_MSG(fabs(T / expected - 1.0) < 0.01, "mode (%d, %d)", modes[k][0], modes[k][1]);
  }
}

/* An irregular lake (islands, a ragged shore) with bumps on it. */
static float *islands(const gr_grid *g) {
  float *b = field(g, 1);
  for (int j = 0; j < g->ny; ++j)
    for (int i = 0; i < g->nx; ++i) {
      double x = (double)i / g->nx, y = (double)j / g->ny;
      b[j * g->nx + i] = (float)(0.8 * sin(7.0 * x) * cos(5.0 * y) + 0.6 * sin(13.0 * x * y) +
                                 2.0 * (pow(x - 0.5, 2.0) + pow(y - 0.5, 2.0)));
    }
  return b;
}

static float *bumps(const gr_grid *g) {
  float *h = field(g, 1);
  for (int j = 0; j < g->ny; ++j)
    for (int i = 0; i < g->nx; ++i)
      h[j * g->nx + i] = (float)(0.05 * exp(-(pow(i - 20.0, 2.0) + pow(j - 30.0, 2.0)) / 18.0) -
                                 0.03 * exp(-(pow(i - 45.0, 2.0) + pow(j - 25.0, 2.0)) / 8.0));
  return h;
}

/* The sum of the wave over the wet points is the initial one to rounding:
 * without damping, with damping, and with raindrops (volume neutral). */
static void test_mean_level(void) {
  gr_grid g = {64, 56, 2.0, 1.5, 0.0, 0.0};
  float *b = islands(&g), *h0 = bumps(&g), *h = field(&g, 1), *wet = field(&g, 1);
  const double damping[] = {0.0, 0.3, 0.0}, rate[] = {0.0, 0.0, 0.5};
  for (int k = 0; k < 3; ++k) {
    gr_water_surface_params p;
    gr_water_surface_params_init(&p);
    p.lake_level = 0.9;
    p.wave_speed = 2.0;
    p.damping = damping[k];
    p.drop_rate = rate[k];
    p.drop_amplitude = 0.02;
    p.drop_radius = 2.0;
    gr_water_surface *s = lake(&g, &p, b);
    CHECK(gr_water_surface_set_wave(s, h0) == GR_OK);
    CHECK(gr_water_surface_advance(s, 120.0, NULL) == GR_OK);
    gr_water_surface_ledger l;
    CHECK(gr_water_surface_ledger_get(s, &l) == GR_OK);
    CHECK(gr_water_surface_get(s, GR_WATER_WAVE_HEIGHT, h) == GR_OK);
    CHECK(gr_water_surface_get(s, GR_WATER_WET, wet) == GR_OK);
    /* The host's own sum over the wet points, and the scale of the rounding:
     * the sum of |h|. */
    double sum = 0.0, l1 = 0.0, sum0 = 0.0;
    long long nwet = 0;
    for (int c = 0; c < g.nx * g.ny; ++c)
      if (wet[c] == 1.0f) {
        sum += h[c];
        l1 += fabs(h[c]);
        sum0 += h0[c];
        ++nwet;
      } else {
        CHECK(h[c] == 0.0f);
      }
    double area = g.dx * g.dy;
    printf("mean level (damping %.1f /s, drops %.1f /m^2/s): %lld of %d points wet, %lld steps, "
           "sum %.9g m vs %.9g m at t = 0 (drift %.3g of sum |h| = %.4g m), energy %.4g m^4/s^2, "
           "max |h| %.4f m\n",
           damping[k], rate[k], nwet, g.nx * g.ny, l.steps, sum, sum0, fabs(sum - sum0) / l1, l1,
           l.energy, l.max_wave);
    CHECK(nwet > g.nx * g.ny / 3 && nwet < g.nx * g.ny);
    CHECK(l.wet_points == nwet);
    CHECK_MSG(fabs(sum - sum0) <= 2e-6 * l1, "drift %g of %g", sum - sum0, l1);
    CHECK_NEAR(l.initial_volume, sum0 * area, 1e-9 * l1 * area);
    CHECK_NEAR(l.wave_volume, sum * area, 1e-6 * l1 * area);
    if (rate[k] > 0.0)
      CHECK(l.max_wave > 0.005); /* the drops made ripples */
    gr_water_surface_destroy(s);
  }
  free(b);
  free(h0);
  free(h);
  free(wet);
}

/* Energy of a standing mode: constant without damping (the scheme's
 * oscillation aside), and decaying at the rate gamma with it (a least-squares
 * fit of log E over several periods). */
static double energy_rate(double gamma, double *spread) {
  const int N = 32;
  gr_grid g = {N, N, 1.0, 1.0, 0.0, 0.0};
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.drop_rate = 0.0;
  p.damping = gamma;
  p.wave_speed = 6.0; /* mode (1, 1): omega = 0.83 rad/s, well above gamma */
  p.lake_level = 1.0;
  gr_water_surface *s = lake(&g, &p, NULL);
  float *h = field(&g, 1);
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i)
      h[j * N + i] = (float)(0.01 * cos(PI * (i + 0.5) / N) * cos(PI * (j + 0.5) / N));
  CHECK(gr_water_surface_set_wave(s, h) == GR_OK);
  free(h);
  double st = 0, stt = 0, sl = 0, stl = 0, emin = HUGE_VAL, emax = 0.0;
  int n = 0;
  for (int k = 0; k <= 120; ++k) {
    gr_water_surface_ledger l;
    if ((k > 0 && gr_water_surface_advance(s, 0.25, NULL) != GR_OK) ||
        gr_water_surface_ledger_get(s, &l) != GR_OK) {
      CHECK_MSG(0, "%s", gr_water_surface_last_error(s));
      break;
    }
    double e = l.energy * exp(gamma * l.time);
    emin = fmin(emin, e);
    emax = fmax(emax, e);
    st += l.time;
    stt += l.time * l.time;
    sl += log(l.energy);
    stl += l.time * log(l.energy);
    ++n;
  }
  gr_water_surface_destroy(s);
  *spread = (emax - emin) / emax;
  return -(n * stl - st * sl) / (n * stt - st * st);
}

static void test_energy(void) {
  double spread = 0.0, rate = energy_rate(0.0, &spread);
  printf("energy without damping: spread %.3g %%, fitted rate %.3g /s\n", 100.0 * spread, rate);
  CHECK_MSG(spread < 1e-5, "spread %g", spread);
  CHECK(fabs(rate) < 1e-3);
  const double gammas[] = {0.05, 0.2};
  for (int k = 0; k < 2; ++k) {
    rate = energy_rate(gammas[k], &spread);
    printf("energy with damping %.2f /s: decays at %.4f /s (%.2f %%)\n", gammas[k], rate,
           100.0 * (rate / gammas[k] - 1.0));
    CHECK_MSG(fabs(rate / gammas[k] - 1.0) < 0.05, "rate %g vs %g", rate, gammas[k]);
  }
}

/* A channel whose right part is dry (water_depth 0 there): a pulse's right
 * half meets the shore half a spacing beyond the last wet point, and comes
 * back with its sign; the dry points never move. */
static void test_shore(void) {
  gr_grid g = {300, 3, 1.0, 1.0, 0.0, 0.0};
  const int wet_end = 200, x0 = 100; /* points 0 .. 199 wet: the wall at 199.5 */
  float *d = field(&g, 1), *h = field(&g, 1);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      d[j * g.nx + i] = i < wet_end ? 0.5f : (i == wet_end ? 0.005f : 0.0f);
      h[j * g.nx + i] = (float)(0.1 * exp(-0.5 * pow((i - x0) / 4.0, 2.0)));
    }
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.drop_rate = 0.0;
  p.damping = 0.0;
  p.wave_speed = 2.0;
  gr_water_surface *s = NULL;
  CHECK(gr_water_surface_create(ctx, &g, &p, &s) == GR_OK);
  CHECK(gr_water_surface_set_field(s, GR_FIELD_WATER_DEPTH, d) == GR_OK);
  CHECK(gr_water_surface_set_wave(s, h) == GR_OK); /* nonzero on dry points until a step */
  double moved = 0.0;
  for (int k = 0; k < 30; ++k) {
    CHECK(gr_water_surface_advance(s, 2.0, NULL) == GR_OK);
    CHECK(gr_water_surface_get(s, GR_WATER_WAVE_HEIGHT, h) == GR_OK);
    for (int j = 0; j < g.ny; ++j)
      for (int i = wet_end; i < g.nx; ++i)
        moved = fmax(moved, fabs(h[j * g.nx + i]));
  }
  /* At t = 60 s the right half has run 120 m: 99.5 m to the wall and 20.5 m
   * back, so its peak is at 199.5 - 20.5 = 179 and it travels left. */
  int best = 0;
  for (int i = 110; i < wet_end; ++i)
    if (h[g.nx + i] > h[g.nx + best])
      best = i;
  double a = h[g.nx + best - 1], b = h[g.nx + best], c = h[g.nx + best + 1];
  double at = best + 0.5 * (a - c) / (a - 2.0 * b + c);
  printf("shore: dry points moved at most %g m; reflected peak %.4f m at %.2f (expected 179)\n",
         moved, b, at);
  CHECK(moved == 0.0);
  CHECK_NEAR(at, 179.0, 1.0);
  CHECK_NEAR(b, 0.05, 0.005);
  free(d);
  free(h);
  gr_water_surface_destroy(s);
}

/* A level lake has the normal (0, 0, 1) exactly, water_surface = LakeLevel on
 * the wet points and the ground on the dry ones; a tilted wave gives the
 * plane's normal where both neighbours are wet. */
static void test_normals(void) {
  gr_grid g = {40, 30, 2.0, 0.5, 100.0, 50.0};
  float *b = islands(&g), *n = field(&g, 3), *surf = field(&g, 1), *wet = field(&g, 1);
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.drop_rate = 0.0;
  p.lake_level = 0.9;
  gr_water_surface *s = lake(&g, &p, b);
  CHECK(gr_water_surface_step(s, 0.1, 3) == GR_OK);
  CHECK(gr_water_surface_get(s, GR_WATER_NORMAL, n) == GR_OK);
  CHECK(gr_water_surface_get(s, GR_WATER_SURFACE, surf) == GR_OK);
  CHECK(gr_water_surface_get(s, GR_WATER_WET, wet) == GR_OK);
  int exact = 1, surface_ok = 1, nwet = 0;
  for (int c = 0; c < g.nx * g.ny; ++c) {
    exact &= n[3 * c] == 0.0f && n[3 * c + 1] == 0.0f && n[3 * c + 2] == 1.0f;
    surface_ok &= wet[c] == 1.0f ? surf[c] == 0.9f : surf[c] == b[c];
    nwet += wet[c] == 1.0f;
  }
  CHECK(exact);
  CHECK(surface_ok);
  CHECK(nwet > 0 && nwet < g.nx * g.ny);
  gr_water_surface_destroy(s);
  /* h = 0.01 x - 0.02 y on an all-wet lake, read before any step. */
  s = lake(&g, NULL, NULL);
  float *h = field(&g, 1);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i)
      h[j * g.nx + i] = (float)(0.01 * i * g.dx - 0.02 * j * g.dy);
  CHECK(gr_water_surface_set_wave(s, h) == GR_OK);
  CHECK(gr_water_surface_get(s, GR_WATER_NORMAL, n) == GR_OK);
  double len = sqrt(0.01 * 0.01 + 0.02 * 0.02 + 1.0), worst = 0.0;
  for (int c = 0; c < g.nx * g.ny; ++c)
    worst = fmax(worst, fabs(n[3 * c] + 0.01 / len) + fabs(n[3 * c + 1] - 0.02 / len) +
                            fabs(n[3 * c + 2] - 1.0 / len));
  printf("normals: level lake exact (0, 0, 1); tilted wave's normals within %.2g\n", worst);
  CHECK(worst < 1e-4);
  free(h);
  free(b);
  free(n);
  free(surf);
  free(wet);
  gr_water_surface_destroy(s);
}

/* Raindrops: ripples on the wet points only, none at DropRate 0, a dimple of
 * about DropAmplitude where a drop fell alone. */
static void test_drops(void) {
  gr_grid g = {64, 64, 1.0, 1.0, 0.0, 0.0};
  float *b = islands(&g), *h = field(&g, 1), *wet = field(&g, 1);
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.lake_level = 0.9;
  p.drop_rate = 0.0;
  gr_water_surface *s = lake(&g, &p, b);
  CHECK(gr_water_surface_advance(s, 20.0, NULL) == GR_OK);
  CHECK(gr_water_surface_get(s, GR_WATER_WAVE_HEIGHT, h) == GR_OK);
  int still = 1;
  for (int c = 0; c < g.nx * g.ny; ++c)
    still &= h[c] == 0.0f;
  CHECK(still);
  gr_water_surface_destroy(s);
  /* One step with a chance of 1e-3 per point: a few lone drops; the deepest
   * point of each is about -DropAmplitude (a Gaussian of 2 spacings). */
  p.drop_rate = 1e-3 / 0.1;
  p.drop_amplitude = 0.01;
  p.drop_radius = 2.0;
  s = lake(&g, &p, b);
  CHECK(gr_water_surface_step(s, 0.1, 1) == GR_OK);
  CHECK(gr_water_surface_get(s, GR_WATER_WAVE_HEIGHT, h) == GR_OK);
  CHECK(gr_water_surface_get(s, GR_WATER_WET, wet) == GR_OK);
  double lowest = 0.0, dry_max = 0.0;
  for (int c = 0; c < g.nx * g.ny; ++c) {
    lowest = fmin(lowest, h[c]);
    if (wet[c] == 0.0f)
      dry_max = fmax(dry_max, fabs(h[c]));
  }
  gr_water_surface_destroy(s);
  /* Many steps at a high rate: ripples everywhere on the water. */
  p.drop_rate = 0.5;
  s = lake(&g, &p, b);
  CHECK(gr_water_surface_advance(s, 10.0, NULL) == GR_OK);
  gr_water_surface_ledger l;
  CHECK(gr_water_surface_ledger_get(s, &l) == GR_OK);
  printf("drops: a lone drop's dimple %.5f m (DropAmplitude 0.01); dry points %g; after 10 s at "
         "0.5 /m^2/s max |h| %.4f m, energy %.3g\n",
         lowest, dry_max, l.max_wave, l.energy);
  CHECK(lowest < -0.007 && lowest > -0.0125);
  CHECK(dry_max == 0.0);
  CHECK(l.max_wave > 0.005 && l.energy > 0.0);
  free(b);
  free(h);
  free(wet);
  gr_water_surface_destroy(s);
}

/* Two runs are bit-identical; a checkpoint saved midway and loaded into
 * another simulation continues bit for bit (drops included); reset returns
 * to the same run. */
static void test_determinism(void) {
  gr_grid g = {48, 40, 1.5, 1.5, 0.0, 0.0};
  float *b = islands(&g), *h0 = bumps(&g);
  size_t n = (size_t)g.nx * g.ny;
  float *a = field(&g, 1), *c = field(&g, 1), *d = field(&g, 1);
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.lake_level = 0.9;
  p.drop_rate = 0.2;
  p.seed = 7;
  gr_water_surface *s1 = lake(&g, &p, b), *s2 = lake(&g, &p, b), *s3 = lake(&g, &p, b);
  CHECK(gr_water_surface_set_wave(s1, h0) == GR_OK);
  CHECK(gr_water_surface_set_wave(s2, h0) == GR_OK);
  CHECK(gr_water_surface_set_wave(s3, h0) == GR_OK);
  CHECK(gr_water_surface_advance(s1, 15.0, NULL) == GR_OK);
  size_t bytes = 0;
  CHECK(gr_water_surface_state_size(s1, &bytes) == GR_OK);
  void *state = malloc(bytes);
  CHECK(gr_water_surface_state_save(s1, state, bytes) == GR_OK);
  CHECK(gr_water_surface_advance(s1, 15.0, NULL) == GR_OK);
  CHECK(gr_water_surface_get(s1, GR_WATER_WAVE_HEIGHT, a) == GR_OK);
  CHECK(gr_water_surface_advance(s2, 15.0, NULL) == GR_OK);
  CHECK(gr_water_surface_advance(s2, 15.0, NULL) == GR_OK);
  CHECK(gr_water_surface_get(s2, GR_WATER_WAVE_HEIGHT, c) == GR_OK);
  CHECK(memcmp(a, c, n * sizeof(float)) == 0);
  CHECK(gr_water_surface_state_load(s3, state, bytes) == GR_OK);
  CHECK(gr_water_surface_advance(s3, 15.0, NULL) == GR_OK);
  CHECK(gr_water_surface_get(s3, GR_WATER_WAVE_HEIGHT, d) == GR_OK);
  CHECK(memcmp(a, d, n * sizeof(float)) == 0);
  gr_water_surface_ledger l1, l3;
  CHECK(gr_water_surface_ledger_get(s1, &l1) == GR_OK);
  CHECK(gr_water_surface_ledger_get(s3, &l3) == GR_OK);
  CHECK(l1.steps == l3.steps && l1.time == l3.time && l1.initial_volume == l3.initial_volume);
  /* Reset, and the same run again. */
  CHECK(gr_water_surface_reset(s2) == GR_OK);
  CHECK(gr_water_surface_advance(s2, 15.0, NULL) == GR_OK);
  CHECK(gr_water_surface_advance(s2, 15.0, NULL) == GR_OK);
  CHECK(gr_water_surface_get(s2, GR_WATER_WAVE_HEIGHT, c) == GR_OK);
  CHECK(memcmp(a, c, n * sizeof(float)) == 0);
  /* Another seed: other drops. */
  p.seed = 8;
  p.use_lake_level = 1;
  CHECK(gr_water_surface_set_params(s2, &p) == GR_OK);
  CHECK(gr_water_surface_reset(s2) == GR_OK);
  CHECK_MSG(gr_water_surface_advance(s2, 30.0, NULL) == GR_OK, "%s",
            gr_water_surface_last_error(s2));
  CHECK(gr_water_surface_get(s2, GR_WATER_WAVE_HEIGHT, c) == GR_OK);
  CHECK(memcmp(a, c, n * sizeof(float)) != 0);
  /* A damaged checkpoint is refused with a sentence. */
  ((unsigned char *)state)[0] ^= 0xff;
  CHECK(gr_water_surface_state_load(s3, state, bytes) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_water_surface_last_error(s3), "not a water surface state") != NULL);
  CHECK(gr_water_surface_state_load(s3, state, bytes / 2) == GR_ERR_INVALID_ARGUMENT);
  free(state);
  free(a);
  free(c);
  free(d);
  free(b);
  free(h0);
  gr_water_surface_destroy(s1);
  gr_water_surface_destroy(s2);
  gr_water_surface_destroy(s3);
}

static int progress_calls;
static int stop_now(void *user, double time) {
  (void)user;
  (void)time;
  ++progress_calls;
  return 1;
}

static void test_errors(void) {
  gr_grid g = {16, 12, 1.0, 1.0, 0.0, 0.0};
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  gr_water_surface *s = NULL;
  char msg[256];
  float *b = field(&g, 1), *out = field(&g, 3);
  /* No water: neither a depth nor a lake. */
  CHECK(gr_water_surface_create(ctx, &g, &p, &s) == GR_OK);
  CHECK(gr_water_surface_step(s, 0.1, 1) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_water_surface_last_error(s), "no water") != NULL);
  CHECK(gr_water_surface_get(s, GR_WATER_WAVE_HEIGHT, out) == GR_ERR_INVALID_ARGUMENT);
  printf("errors: %s\n", gr_water_surface_last_error(s));
  /* A lake below all the ground, or too thin water: no wet point, which is
   * not an error (runoff early in a storm): nothing moves. */
  for (int c = 0; c < g.nx * g.ny; ++c)
    b[c] = 5.0f + 0.1f * (float)c;
  CHECK(gr_water_surface_set_field(s, GR_FIELD_ELEVATION, b) == GR_OK);
  p.use_lake_level = 1;
  p.lake_level = 4.0;
  CHECK(gr_water_surface_set_params(s, &p) == GR_OK);
  gr_water_surface_ledger l0, l1;
  CHECK(gr_water_surface_advance(s, 1.0, NULL) == GR_OK);
  CHECK(gr_water_surface_ledger_get(s, &l0) == GR_OK);
  CHECK(l0.wet_points == 0 && l0.max_wave == 0.0 && l0.steps > 0);
  float *d = field(&g, 1);
  for (int c = 0; c < g.nx * g.ny; ++c)
    d[c] = 0.004f;
  p.use_lake_level = 0;
  CHECK(gr_water_surface_set_params(s, &p) == GR_OK);
  CHECK(gr_water_surface_set_field(s, GR_FIELD_WATER_DEPTH, d) == GR_OK);
  CHECK(gr_water_surface_step(s, 0.1, 1) == GR_OK);
  CHECK(gr_water_surface_ledger_get(s, &l0) == GR_OK);
  CHECK(l0.wet_points == 0);
  /* NaN elevation, negative depth: refused, naming the point; the state stays. */
  b[3 * g.nx + 5] = NAN;
  CHECK(gr_water_surface_set_field(s, GR_FIELD_ELEVATION, b) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_water_surface_last_error(s), "NaN at point (5, 3)") != NULL);
  printf("errors: %s\n", gr_water_surface_last_error(s));
  d[7] = -1.0f;
  CHECK(gr_water_surface_set_field(s, GR_FIELD_WATER_DEPTH, d) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_water_surface_set_field(s, GR_FIELD_VELOCITY, d) == GR_ERR_INVALID_ARGUMENT);
  /* And then it works: deeper water. */
  for (int c = 0; c < g.nx * g.ny; ++c)
    d[c] = 0.3f;
  CHECK(gr_water_surface_set_field(s, GR_FIELD_WATER_DEPTH, d) == GR_OK);
  CHECK_MSG(gr_water_surface_advance(s, 1.0, NULL) == GR_OK, "%s", gr_water_surface_last_error(s));
  /* A step beyond the CFL limit is refused. */
  double dt = 0.0;
  CHECK(gr_water_surface_stable_dt(s, &dt) == GR_OK);
  CHECK_NEAR(dt, 0.5 / sqrt(2.0), 1e-12);
  CHECK(gr_water_surface_step(s, 1.0 / sqrt(2.0), 1) == GR_OK);
  CHECK(gr_water_surface_step(s, 0.71, 1) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_water_surface_last_error(s), "CFL") != NULL);
  CHECK(gr_water_surface_step(s, 0.1, -1) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_water_surface_advance(s, NAN, NULL) == GR_ERR_INVALID_ARGUMENT);
  /* Progress: a stop at a step boundary. */
  gr_water_surface_set_progress(s, stop_now, NULL);
  CHECK(gr_water_surface_ledger_get(s, &l0) == GR_OK);
  gr_status st = gr_water_surface_advance(s, 1e5, NULL);
  CHECK(st == GR_ERR_ABORTED && progress_calls == 1);
  CHECK(gr_water_surface_ledger_get(s, &l1) == GR_OK);
  CHECK(l1.steps > l0.steps && l1.time < l0.time + 1e5);
  gr_water_surface_set_progress(s, NULL, NULL);
  /* Bad parameters: WaveSpeed <= 0, NaN. */
  p.wave_speed = 0.0;
  CHECK(gr_water_surface_params_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(msg, "WaveSpeed") != NULL);
  printf("errors: %s\n", msg);
  CHECK(gr_water_surface_set_params(s, &p) == GR_ERR_INVALID_ARGUMENT);
  p.wave_speed = -1.0;
  gr_water_surface *t = s;
  CHECK(gr_water_surface_create(ctx, &g, &p, &t) == GR_ERR_INVALID_ARGUMENT);
  CHECK(t == NULL);
  gr_water_surface_params_init(&p);
  p.damping = NAN;
  CHECK(gr_water_surface_params_validate(&p, NULL, 0) == GR_ERR_INVALID_ARGUMENT);
  gr_water_surface_params_init(&p);
  /* A piece split along x is refused (strips of whole rows only). */
  gr_grid piece = g;
  piece.global_nx = 2 * g.nx;
  CHECK(gr_water_surface_create(ctx, &piece, &p, &t) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_last_error(NULL), "along y only") != NULL);
  /* NULLs. */
  CHECK(gr_water_surface_step(NULL, 0.1, 1) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_water_surface_get(NULL, GR_WATER_WET, out) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_water_surface_set_wave(NULL, out) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strcmp(gr_water_surface_output_name(GR_WATER_NORMAL), "normal") == 0);
  CHECK(gr_water_surface_output_name(GR_WATER_OUTPUT_COUNT) == NULL);
  CHECK(gr_water_surface_output_components(GR_WATER_NORMAL) == 3);
  CHECK(strcmp(gr_water_surface_last_error(NULL), "") == 0);
  gr_water_surface_destroy(NULL);
  gr_water_surface_destroy(s);
  free(b);
  free(d);
  free(out);
}

static void test_param_table(void) {
  int n = 0;
  const gr_param_bound *b = gr_water_surface_param_bounds(&n);
  CHECK(n == 10);
  gr_water_surface_params d, p;
  gr_water_surface_params_init(&d);
  for (int r = 0; r < n; ++r) {
    char msg[256];
    /* Every row moves one field: set it through a copy and the table's name. */
#define SET(v)                                                                                     \
  do {                                                                                             \
    p = d;                                                                                         \
    double v_ = (v);                                                                               \
    switch (r) {                                                                                   \
    case 0:                                                                                        \
      p.wave_speed = v_;                                                                           \
      break;                                                                                       \
    case 1:                                                                                        \
      p.damping = v_;                                                                              \
      break;                                                                                       \
    case 2:                                                                                        \
      p.wet_depth = v_;                                                                            \
      break;                                                                                       \
    case 3:                                                                                        \
      p.use_lake_level = (int)v_;                                                                  \
      break;                                                                                       \
    case 4:                                                                                        \
      p.lake_level = v_;                                                                           \
      break;                                                                                       \
    case 5:                                                                                        \
      p.drop_rate = v_;                                                                            \
      break;                                                                                       \
    case 6:                                                                                        \
      p.drop_amplitude = v_;                                                                       \
      break;                                                                                       \
    case 7:                                                                                        \
      p.drop_radius = v_;                                                                          \
      break;                                                                                       \
    case 8:                                                                                        \
      p.seed = (int)v_;                                                                            \
      break;                                                                                       \
    default:                                                                                       \
      p.cfl = v_;                                                                                  \
    }                                                                                              \
  } while (0)
    SET(b[r].default_value);
    CHECK_MSG(memcmp(&p, &d, sizeof(p)) == 0, "%s default", b[r].property);
    SET(b[r].max);
    CHECK_MSG(gr_water_surface_params_validate(&p, msg, sizeof(msg)) == GR_OK, "%s max",
              b[r].property);
    SET(b[r].min);
    CHECK_MSG((gr_water_surface_params_validate(&p, msg, sizeof(msg)) == GR_OK) == !b[r].min_open,
              "%s min", b[r].property);
    if (!b[r].integer || b[r].max < 2e9) {
      SET(b[r].integer ? b[r].max + 1 : b[r].max * 1.001 + 1e-9);
      CHECK_MSG(gr_water_surface_params_validate(&p, msg, sizeof(msg)) != GR_OK &&
                    strstr(msg, b[r].property),
                "%s above max", b[r].property);
    }
#undef SET
  }
}

/* Every host entry point once on tiny grids (for valgrind). */
static void test_memcheck(void) {
  gr_grid g = {8, 6, 1.0, 1.0, 0.0, 0.0};
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.use_lake_level = 1;
  p.lake_level = 1.0;
  p.drop_rate = 2.0;
  gr_water_surface *s = NULL;
  CHECK(gr_water_surface_create(ctx, &g, &p, &s) == GR_OK);
  float *h = field(&g, 3);
  CHECK(gr_water_surface_set_field(s, GR_FIELD_ELEVATION, h) == GR_OK);
  CHECK(gr_water_surface_set_wave(s, h) == GR_OK);
  CHECK(gr_water_surface_advance(s, 2.0, NULL) == GR_OK);
  for (int o = 0; o < GR_WATER_OUTPUT_COUNT; ++o)
    CHECK(gr_water_surface_get(s, (gr_water_surface_output)o, h) == GR_OK);
  gr_water_surface_ledger l;
  CHECK(gr_water_surface_ledger_get(s, &l) == GR_OK);
  size_t bytes = 0;
  CHECK(gr_water_surface_state_size(s, &bytes) == GR_OK);
  void *state = malloc(bytes);
  CHECK(gr_water_surface_state_save(s, state, bytes) == GR_OK);
  CHECK(gr_water_surface_reset(s) == GR_OK);
  CHECK(gr_water_surface_state_load(s, state, bytes) == GR_OK);
  CHECK(gr_water_surface_set_field(s, GR_FIELD_WATER_DEPTH, h) == GR_OK);
  free(state);
  free(h);
  gr_water_surface_destroy(s);
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

/* ------------------------------------------------------------- pieces */

/* The split domain: 40 x 48 points of 0.5 m, a lake at 0 over a bed with
 * islands (shores cross every cut), a wave bump across row 24 and drops of
 * DropRadius 0.5 m (a ring of 1 + 4 rows), damping on. */
enum { PC_NX = 40, PC_NY = 48, PC_MAX = 3, PC_STEPS = 40 };

typedef struct pc_domain {
  gr_grid g;
  float *b, *h0;
} pc_domain;

static pc_domain pc_make_domain(void) {
  pc_domain dm;
  gr_grid g = {.nx = PC_NX, .ny = PC_NY, .dx = 0.5, .dy = 0.5, .x0 = 2.0, .y0 = -3.0};
  dm.g = g;
  size_t n = (size_t)g.nx * g.ny;
  dm.b = malloc(n * sizeof(float));
  dm.h0 = malloc(n * sizeof(float));
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      double x = i * g.dx, y = j * g.dy;
      dm.b[(size_t)j * g.nx + i] = (float)(-0.6 + 0.75 * sin(x * 0.55) * cos(y * 0.45));
      double r2 = (x - 9.0) * (x - 9.0) + (y - 12.0) * (y - 12.0);
      dm.h0[(size_t)j * g.nx + i] = (float)(0.05 * exp(-r2 / 4.0));
    }
  return dm;
}

static void pc_params(gr_water_surface_params *p) {
  gr_water_surface_params_init(p);
  p->use_lake_level = 1;
  p->lake_level = 0.0;
  p->damping = 0.05;
  p->drop_rate = 0.5;
  p->drop_amplitude = 0.01;
  p->drop_radius = 0.5;
  p->seed = 11;
}

typedef struct pc_runner {
  gr_test_team *t;
  int rank, exchanges, reductions, skip_exchange;
  /* Steps k0 .. k1 - 1 of dt; the state saved after save_at of them (0:
   * none); or, with duration > 0, one advance by it, stopped by this
   * piece's progress callback when stop is set. */
  int k0, k1, save_at, taken, stop;
  double dt, duration;
  gr_grid g;
  gr_water_surface *s;
  gr_status st;
  gr_water_surface_ledger l;
  void *state;
  size_t state_bytes;
} pc_runner;

static int pc_stop(void *user, double time) {
  (void)user, (void)time;
  return 1;
}

static gr_status pc_halo(void *s, int side, void *host, size_t bytes, int set) {
  return set ? gr_water_surface_halo_set(s, side, host, bytes)
             : gr_water_surface_halo_get(s, side, host, bytes);
}

static gr_status pc_allreduce(void *user, double *values, int n, gr_reduce_op op) {
  pc_runner *r = user;
  gr_status st = gr_test_team_allreduce(r->t, r->rank, values, n, op);
  r->reductions += st == GR_OK;
  return st;
}

/* Each piece's strips out, then the neighbours' in; with skip_exchange,
 * nothing (the rings keep their first values). */
static gr_status pc_exchange(void *user) {
  pc_runner *r = user;
  ++r->exchanges;
  return r->skip_exchange ? GR_OK : gr_test_team_exchange(r->t, r->rank, r->s, pc_halo);
}

static void *pc_run(void *arg) {
  pc_runner *r = arg;
  gr_status st = GR_OK;
  if (r->duration > 0.0) {
    gr_water_surface_set_progress(r->s, r->stop ? pc_stop : NULL, r);
    st = gr_water_surface_advance(r->s, r->duration, &r->taken);
  }
  for (int k = r->k0; st == GR_OK && k < r->k1; ++k) {
    st = gr_water_surface_step(r->s, r->dt, 1);
    if (st == GR_OK && ++r->taken == r->save_at) {
      st = gr_water_surface_state_size(r->s, &r->state_bytes);
      r->state = st == GR_OK ? malloc(r->state_bytes) : NULL;
      if (r->state)
        st = gr_water_surface_state_save(r->s, r->state, r->state_bytes);
    }
  }
  gr_status s2 = gr_water_surface_ledger_get(r->s, &r->l);
  r->st = st != GR_OK ? st : s2;
  gr_water_surface_set_progress(r->s, NULL, NULL);
  return NULL;
}

/* A piece of rows j0 .. j0 + ny - 1 with rings of ghost rows: its local
 * arrays cut from the domain's. */
static gr_water_surface *pc_piece(const pc_domain *dm, const gr_water_surface_params *p, int j0,
                                  int ny, int ghost, gr_grid *g) {
  *g = dm->g;
  g->ny = ny, g->j0 = j0, g->global_ny = dm->g.ny, g->ghost = ghost;
  int lo = j0 > 0 ? j0 - ghost : 0;
  gr_water_surface *s = NULL;
  gr_status st = gr_water_surface_create(ctx, g, p, &s);
  CHECK_MSG(st == GR_OK, "piece: %s", gr_last_error(NULL));
  size_t off = (size_t)lo * dm->g.nx;
  if (st == GR_OK)
    st = gr_water_surface_set_field(s, GR_FIELD_ELEVATION, dm->b + off);
  if (st == GR_OK)
    st = gr_water_surface_set_wave(s, dm->h0 + off);
  CHECK_MSG(st == GR_OK, "piece input: %s", s ? gr_water_surface_last_error(s) : "");
  return s;
}

/* The outputs compared, and the points of the own rows that differ in any. */
static const gr_water_surface_output pc_outputs[4] = {GR_WATER_WAVE_HEIGHT, GR_WATER_NORMAL,
                                                      GR_WATER_SURFACE, GR_WATER_WET};

static long pc_differ(gr_water_surface *s, const gr_grid *g, float *const whole[4]) {
  long d = 0;
  for (int o = 0; o < 4; ++o) {
    size_t comps = (size_t)gr_water_surface_output_components(pc_outputs[o]);
    size_t own = comps * (size_t)g->nx * (size_t)g->ny, at = comps * (size_t)g->j0 * g->nx;
    float *v = malloc(own * sizeof(float));
    CHECK(gr_water_surface_get(s, pc_outputs[o], v) == GR_OK);
    for (size_t c = 0; c < own; ++c)
      d += memcmp(&v[c], &whole[o][at + c], sizeof(float)) != 0;
    free(v);
  }
  return d;
}

static int pc_same_ledger(const gr_water_surface_ledger *a, const gr_water_surface_ledger *b) {
  return memcmp(&a->time, &b->time, sizeof(double)) == 0 && a->steps == b->steps &&
         a->wet_points == b->wet_points &&
         memcmp(&a->wave_volume, &b->wave_volume, sizeof(double)) == 0 &&
         memcmp(&a->initial_volume, &b->initial_volume, sizeof(double)) == 0 &&
         memcmp(&a->energy, &b->energy, sizeof(double)) == 0 &&
         memcmp(&a->max_wave, &b->max_wave, sizeof(double)) == 0;
}

/* The whole grid's outputs and ledger after `steps` steps of dt (from rest
 * at the bump), or after an advance by duration when steps < 0. */
static void pc_whole(const pc_domain *dm, int steps, double dt, float *out[4],
                     gr_water_surface_ledger *l) {
  gr_water_surface_params p;
  pc_params(&p);
  gr_water_surface *w = NULL;
  CHECK(gr_water_surface_create(ctx, &dm->g, &p, &w) == GR_OK);
  CHECK(gr_water_surface_set_field(w, GR_FIELD_ELEVATION, dm->b) == GR_OK);
  CHECK(gr_water_surface_set_wave(w, dm->h0) == GR_OK);
  CHECK(gr_water_surface_step(w, dt, steps) == GR_OK);
  CHECK(gr_water_surface_ledger_get(w, l) == GR_OK);
  for (int o = 0; o < 4; ++o) {
    size_t comps = (size_t)gr_water_surface_output_components(pc_outputs[o]);
    out[o] = malloc(comps * PC_NX * PC_NY * sizeof(float));
    CHECK(gr_water_surface_get(w, pc_outputs[o], out[o]) == GR_OK);
  }
  gr_water_surface_destroy(w);
}

/* n pieces (cut at rows cuts[0..n-2]) against the whole grid: PC_STEPS
 * steps, bit for bit in every output and the ledger; the second half again
 * from each piece's checkpoint; a stop asked by the last piece's progress
 * callback stops every piece after the same step, the whole grid's state
 * after that many steps; and, with the exchange skipped, the pieces differ.
 * Returns piece 0's exchanges in the first run. */
static int pc_split(const pc_domain *dm, int n, const int *cuts, double dt, float *const wf[4],
                    const gr_water_surface_ledger *lw) {
  gr_water_surface_params p;
  pc_params(&p);
  int ghost = gr_water_surface_ghost(&p, dm->g.dy);
  gr_test_team t;
  gr_test_team_init(&t, n, 16);
  pc_runner rn[PC_MAX];
  int ok = 1;
  for (int k = 0; k < n; ++k) {
    memset(&rn[k], 0, sizeof(rn[k]));
    int j0 = k ? cuts[k - 1] : 0, j1 = k + 1 < n ? cuts[k] : dm->g.ny;
    rn[k].t = &t, rn[k].rank = k, rn[k].k1 = PC_STEPS, rn[k].save_at = PC_STEPS / 2;
    rn[k].dt = dt;
    rn[k].s = pc_piece(dm, &p, j0, j1 - j0, ghost, &rn[k].g);
    ok = ok && rn[k].s;
    for (int side = 2; ok && side < 4; ++side) {
      size_t bytes = 0;
      CHECK(gr_water_surface_halo_size(rn[k].s, side, &bytes) == GR_OK);
      int has = side == 2 ? k > 0 : k + 1 < n;
      CHECK(bytes == (has ? (size_t)PC_NX * sizeof(float) : 0));
      gr_test_team_mail(&t, k, side, bytes);
    }
    if (ok) {
      gr_water_surface_set_allreduce(rn[k].s, pc_allreduce, &rn[k]);
      gr_water_surface_set_halo_exchange(rn[k].s, pc_exchange, &rn[k]);
    }
  }
  int exchanges = 0, reductions = 0;
  if (ok) {
    gr_test_team_run(n, pc_run, rn, sizeof(rn[0]));
    exchanges = rn[0].exchanges, reductions = rn[0].reductions;
    for (int k = 0; k < n; ++k) {
      CHECK_MSG(rn[k].st == GR_OK, "%d pieces, piece %d: %s", n, k,
                gr_water_surface_last_error(rn[k].s));
      long d = pc_differ(rn[k].s, &rn[k].g, wf);
      CHECK_MSG(d == 0,
                "%d pieces: piece %d: %ld values of its own rows differ from the whole grid", n, k,
                d);
      CHECK_MSG(pc_same_ledger(&rn[k].l, lw),
                "%d pieces: piece %d's ledger: wave %.17g energy %.17g wet %lld max %.17g, the "
                "whole grid's %.17g %.17g %lld %.17g",
                n, k, rn[k].l.wave_volume, rn[k].l.energy, rn[k].l.wet_points, rn[k].l.max_wave,
                lw->wave_volume, lw->energy, lw->wet_points, lw->max_wave);
    }
    CHECK_MSG(exchanges == PC_STEPS, "%d exchanges in %d steps", exchanges, PC_STEPS);
  }
  /* From the checkpoints after half the steps. */
  for (int k = 0; ok && k < n; ++k) {
    CHECK(rn[k].state != NULL);
    ok = rn[k].state &&
         gr_water_surface_state_load(rn[k].s, rn[k].state, rn[k].state_bytes) == GR_OK;
    rn[k].k0 = PC_STEPS / 2, rn[k].save_at = 0, rn[k].taken = 0;
  }
  if (ok) {
    /* A piece's state loads into that piece only. */
    CHECK(gr_water_surface_state_load(rn[1].s, rn[0].state, rn[0].state_bytes) != GR_OK);
    gr_test_team_run(n, pc_run, rn, sizeof(rn[0]));
    for (int k = 0; k < n; ++k) {
      CHECK(rn[k].st == GR_OK);
      long d = pc_differ(rn[k].s, &rn[k].g, wf);
      CHECK_MSG(d == 0 && pc_same_ledger(&rn[k].l, lw),
                "%d pieces from the checkpoints: piece %d: %ld values differ (ledger %s)", n, k, d,
                pc_same_ledger(&rn[k].l, lw) ? "equal" : "differs");
    }
  }
  /* A stop on the last piece, inside an advance of 4000 steps. */
  double stable = 0.0;
  CHECK(gr_water_surface_stable_dt(rn[0].s, &stable) == GR_OK);
  for (int k = 0; ok && k < n; ++k) {
    ok = gr_water_surface_reset(rn[k].s) == GR_OK;
    rn[k].k0 = rn[k].k1 = 0, rn[k].taken = 0, rn[k].stop = k == n - 1;
    rn[k].duration = 4000.0 * stable;
  }
  int stopped = 0;
  if (ok) {
    gr_test_team_run(n, pc_run, rn, sizeof(rn[0]));
    stopped = rn[0].taken;
    for (int k = 0; k < n; ++k)
      CHECK_MSG(rn[k].st == GR_ERR_ABORTED && rn[k].taken == stopped && rn[k].l.steps == stopped &&
                    stopped > 0 && stopped < 4000,
                "%d pieces, piece %d: %d steps taken (%s), piece 0 %d, after a stop on piece %d", n,
                k, rn[k].taken, gr_status_string(rn[k].st), stopped, n - 1);
    float *sf[4];
    gr_water_surface_ledger ls;
    double nsteps = ceil(rn[0].duration / stable);
    pc_whole(dm, stopped, rn[0].duration / nsteps, sf, &ls);
    for (int k = 0; k < n; ++k) {
      long d = pc_differ(rn[k].s, &rn[k].g, sf);
      CHECK_MSG(d == 0 && pc_same_ledger(&rn[k].l, &ls),
                "%d pieces stopped after %d steps: piece %d: %ld values differ from the whole "
                "grid's after as many steps",
                n, stopped, k, d);
    }
    for (int o = 0; o < 4; ++o)
      free(sf[o]);
  }
  /* Without the exchange the rings go stale and the pieces go wrong. */
  long wrong = 0;
  for (int k = 0; ok && k < n; ++k) {
    ok = gr_water_surface_reset(rn[k].s) == GR_OK;
    rn[k].k0 = 0, rn[k].k1 = PC_STEPS, rn[k].taken = 0, rn[k].stop = 0, rn[k].duration = 0.0;
    rn[k].skip_exchange = 1;
  }
  if (ok) {
    gr_test_team_run(n, pc_run, rn, sizeof(rn[0]));
    for (int k = 0; k < n; ++k)
      wrong += pc_differ(rn[k].s, &rn[k].g, wf);
    CHECK_MSG(wrong > 0, "%d pieces without the exchange still give the whole grid", n);
  }
  CHECK(ok);
  printf("pieces: %d pieces, ring %d rows: outputs and ledger equal the whole grid's after %d "
         "steps (%d exchanges, %d reductions on piece 0), from the checkpoints too; a stop on "
         "piece %d stopped all after %d steps, equal to the whole grid's; without the "
         "exchange %ld values differ\n",
         n, ghost, PC_STEPS, exchanges, reductions, n - 1, stopped, wrong);
  for (int k = 0; k < n; ++k) {
    gr_water_surface_destroy(rn[k].s);
    free(rn[k].state);
  }
  gr_test_team_destroy(&t);
  return exchanges;
}

/* Two and three pieces in one process (threads) give the whole grid's bits,
 * waves crossing the cuts, shores on them and drops near them; then the
 * error paths of pieces. */
static void test_pieces(void) {
  pc_domain dm = pc_make_domain();
  gr_water_surface_params p;
  pc_params(&p);
  CHECK(gr_water_surface_ghost(&p, dm.g.dy) == 5);
  CHECK(gr_water_surface_ghost(&p, 2.0) == 2);
  CHECK(gr_water_surface_ghost(NULL, 1.0) == 0);
  double dt = 0.0;
  {
    gr_water_surface *w = NULL;
    CHECK(gr_water_surface_create(ctx, &dm.g, &p, &w) == GR_OK);
    CHECK(gr_water_surface_stable_dt(w, &dt) == GR_OK);
    gr_water_surface_destroy(w);
  }
  float *wf[4];
  gr_water_surface_ledger lw;
  pc_whole(&dm, PC_STEPS, dt, wf, &lw);
  /* The scene does what it is for: shores (dry points) and drops. */
  long dry = 0;
  for (int c = 0; c < PC_NX * PC_NY; ++c)
    dry += wf[3][c] == 0.0f;
  printf("pieces: whole grid: %lld wet, %ld dry points; wave %.6g m^3 (initial %.6g), energy "
         "%.4g, max |h| %.4g m\n",
         lw.wet_points, dry, lw.wave_volume, lw.initial_volume, lw.energy, lw.max_wave);
  CHECK(dry > 100 && lw.wet_points > 1000);
  CHECK(lw.max_wave > 0.01);
  const int cuts2[1] = {24}, cuts3[2] = {16, 32};
  pc_split(&dm, 2, cuts2, dt, wf, &lw);
  pc_split(&dm, 3, cuts3, dt, wf, &lw);
  for (int o = 0; o < 4; ++o)
    free(wf[o]);
  /* Error paths: a ring narrower than the drops need, a strip narrower than
   * its ring, a strip beyond the domain, a piece stepping without
   * callbacks, a wider drop than the ring holds, halo sides. */
  gr_water_surface *s = NULL;
  gr_grid g = dm.g;
  g.ny = 24, g.j0 = 24, g.global_ny = PC_NY, g.ghost = 4;
  CHECK(gr_water_surface_create(ctx, &g, &p, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  CHECK(strstr(gr_last_error(NULL), "ghost ring") != NULL);
  g.ny = 4, g.ghost = 5;
  CHECK(gr_water_surface_create(ctx, &g, &p, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  g.ny = 24, g.j0 = 30;
  CHECK(gr_water_surface_create(ctx, &g, &p, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  g.j0 = 24;
  CHECK(gr_water_surface_create(ctx, &g, &p, &s) == GR_OK && s);
  if (s) {
    CHECK(gr_water_surface_step(s, dt, 1) == GR_ERR_INVALID_ARGUMENT);
    CHECK(strstr(gr_water_surface_last_error(s), "allreduce") != NULL);
    gr_water_surface_params wide = p;
    wide.drop_radius = 0.7;
    CHECK(gr_water_surface_set_params(s, &wide) == GR_ERR_INVALID_ARGUMENT);
    CHECK(strstr(gr_water_surface_last_error(s), "DropRadius 0.7") != NULL);
    size_t bytes = 1;
    CHECK(gr_water_surface_halo_size(s, 2, &bytes) == GR_OK && bytes == PC_NX * sizeof(float));
    CHECK(gr_water_surface_halo_size(s, 3, &bytes) == GR_OK && bytes == 0);
    float strip[4];
    CHECK(gr_water_surface_halo_get(s, 3, strip, sizeof(strip)) == GR_ERR_INVALID_ARGUMENT);
    CHECK(gr_water_surface_halo_set(s, 2, strip, sizeof(strip)) == GR_ERR_INVALID_ARGUMENT);
  }
  gr_water_surface_destroy(s);
  free(dm.b), free(dm.h0);
}

static const gr_subtest tests[] = {
    {"pulse_speed", test_pulse_speed, 0},
    {"standing_modes", test_standing_modes, 0},
    {"mean_level", test_mean_level, 0},
    {"energy", test_energy, 0},
    {"shore", test_shore, 0},
    {"normals", test_normals, 0},
    {"drops", test_drops, 0},
    {"determinism", test_determinism, 0},
    {"pieces", test_pieces, 0},
    {"errors", test_errors, 0},
    {"param_table", test_param_table, 0},
    {"memcheck", test_memcheck, 1},
};

int main(int argc, char **argv) {
  return gr_test_main(argc, argv, tests, (int)(sizeof(tests) / sizeof(tests[0])), setup, teardown);
}
