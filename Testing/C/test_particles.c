/* Rain and snowfall particle tests: exact counts; bit-identical particles for
 * the same (seed, t) whatever the order of the times asked for; the drop
 * sizes' mean and distribution against Marshall-Palmer truncated to
 * 0.1-6 mm at two rain rates; fall speeds against Atlas et al.'s formula by
 * diameter (and the formula against Gunn and Kinzer's measurements); drops
 * falling at their speed between two times and respawning at the top; the
 * mean horizontal drift = wind * dt within 1%; every particle inside the
 * region; flakes' fall speeds within 0.5-1.5 m/s and their sway bounded;
 * streaks; the error paths and the parameter table. */
#include "graupel/particles.h"
#include "gr_test.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static gr_context *ctx;

/* The particles of p at time t (outputs malloc'd; NULL on failure). */
typedef struct snapshot {
  int n;
  float *pos, *vel, *size, *streak;
} snapshot;

static void snapshot_free(snapshot *s) {
  free(s->pos);
  free(s->vel);
  free(s->size);
  free(s->streak);
  memset(s, 0, sizeof(*s));
}

static int read_all(gr_particles *h, snapshot *s) {
  int n = gr_particles_count(h);
  memset(s, 0, sizeof(*s));
  s->n = n;
  s->pos = malloc(3 * (size_t)n * sizeof(float));
  s->vel = malloc(3 * (size_t)n * sizeof(float));
  s->size = malloc((size_t)n * sizeof(float));
  s->streak = malloc(3 * (size_t)n * sizeof(float));
  float *out[] = {s->pos, s->vel, s->size, s->streak};
  for (int o = 0; o < GR_PARTICLES_OUTPUT_COUNT; ++o) {
    /* NaN first: a value the kernel did not write shows. */
    for (size_t k = 0; k < (size_t)n * (size_t)gr_particles_output_components(o); ++k)
      out[o][k] = NAN;
    gr_status st = gr_particles_get_output(h, (gr_particles_output)o, out[o]);
    CHECK_MSG(st == GR_OK, "%s", gr_particles_last_error(h));
    if (st != GR_OK) {
      snapshot_free(s);
      return 0;
    }
  }
  return 1;
}

static int take(const gr_particles_params *p, double t, snapshot *s) {
  gr_particles *h = NULL;
  gr_status st = gr_particles_create(ctx, p, &h);
  CHECK_MSG(st == GR_OK, "%s", gr_particles_last_error(NULL));
  if (st != GR_OK)
    return 0;
  st = gr_particles_compute(h, t);
  CHECK_MSG(st == GR_OK, "%s", gr_particles_last_error(h));
  int ok = st == GR_OK && read_all(h, s);
  gr_particles_destroy(h);
  return ok;
}

static gr_particles_params rain(int count, double mm_h) {
  gr_particles_params p;
  gr_particles_params_init(&p);
  p.count = count;
  p.rain_rate = mm_h / 3.6e6;
  return p;
}

/* The shortest displacement from a to b on a circle of length w. */
static double unwrap(double a, double b, double w) {
  double d = b - a;
  return d - w * floor(d / w + 0.5);
}

static void test_counts(void) {
  const int counts[] = {1024, 1000 * 1000, 1 << 18};
  for (int c = 0; c < 3; ++c) {
    gr_particles_params p = rain(counts[c], 10.0);
    p.kind = c == 1 ? GR_PARTICLES_SNOW : GR_PARTICLES_RAIN;
    snapshot s;
    if (!take(&p, 3.0, &s))
      continue;
    CHECK(s.n == counts[c]);
    int finite = 1;
    for (int i = 0; i < 3 * s.n; ++i)
      finite &= isfinite(s.pos[i]) && isfinite(s.vel[i]) && isfinite(s.streak[i]);
    for (int i = 0; i < s.n; ++i)
      finite &= isfinite(s.size[i]);
    CHECK_MSG(finite, "every one of %d particles written", s.n);
    snapshot_free(&s);
  }
  /* A new Count reallocates: the next compute gives exactly that many. */
  gr_particles_params p = rain(2048, 10.0);
  gr_particles *h = NULL;
  CHECK(gr_particles_create(ctx, &p, &h) == GR_OK);
  p.count = 4096;
  CHECK(gr_particles_set_params(h, &p) == GR_OK && gr_particles_count(h) == 4096);
  snapshot s;
  CHECK(gr_particles_compute(h, 1.0) == GR_OK && read_all(h, &s) && s.n == 4096);
  snapshot_free(&s);
  gr_particles_destroy(h);
}

static int same_bits(const snapshot *a, const snapshot *b) {
  size_t v = 3 * (size_t)a->n * sizeof(float), f = (size_t)a->n * sizeof(float);
  return a->n == b->n && !memcmp(a->pos, b->pos, v) && !memcmp(a->vel, b->vel, v) &&
         !memcmp(a->size, b->size, f) && !memcmp(a->streak, b->streak, v);
}

static void test_determinism(void) {
  for (int kind = 0; kind < 2; ++kind) {
    gr_particles_params p = rain(1 << 14, 25.0);
    p.kind = kind;
    p.seed = 77;
    p.wind[0] = 4.0;
    p.wind[1] = -1.5;
    gr_particles *h = NULL;
    CHECK(gr_particles_create(ctx, &p, &h) == GR_OK);
    if (!h)
      continue;
    /* Times asked for out of order, with the first asked again last. */
    const double times[] = {12.5, 3.0, 40.0, 0.0, 12.5};
    snapshot s[5];
    for (int k = 0; k < 5; ++k) {
      CHECK(gr_particles_compute(h, times[k]) == GR_OK);
      CHECK(read_all(h, &s[k]));
    }
    CHECK_MSG(same_bits(&s[0], &s[4]), "kind %d: t = 12.5 again, after 3, 40 and 0", kind);
    snapshot fresh, other;
    CHECK(take(&p, 12.5, &fresh) && same_bits(&s[0], &fresh));
    p.seed = 78;
    CHECK(take(&p, 12.5, &other));
    int differ = 0;
    for (int i = 0; i < other.n; ++i)
      differ += other.pos[3 * i] != fresh.pos[3 * i];
    CHECK_MSG(differ > other.n * 9 / 10, "kind %d: another seed moves %d of %d particles", kind,
              differ, other.n);
    CHECK(!same_bits(&s[0], &s[1]));
    for (int k = 0; k < 5; ++k)
      snapshot_free(&s[k]);
    snapshot_free(&fresh);
    snapshot_free(&other);
    gr_particles_destroy(h);
  }
}

/* Marshall-Palmer truncated to [0.1, 6] mm, written here from the paper's
 * constants: Lambda = 4.1 R^-0.21. */
static double mp_lambda(double r) {
  return 4.1 * pow(r, -0.21);
}

static double mp_cdf(double r, double d) {
  double l = mp_lambda(r);
  return (1.0 - exp(-l * (d - 0.1))) / (1.0 - exp(-l * 5.9));
}

static void test_drop_sizes(void) {
  const double rates[] = {5.0, 50.0};
  double means[2] = {0.0, 0.0};
  for (int r = 0; r < 2; ++r) {
    gr_particles_params p = rain(1 << 18, rates[r]);
    snapshot s;
    if (!take(&p, 0.0, &s))
      continue;
    double sum = 0.0, lo = 1e9, hi = -1e9;
    const double edges[] = {0.2, 0.5, 1.0, 2.0};
    int below[4] = {0, 0, 0, 0};
    for (int i = 0; i < s.n; ++i) {
      double d = s.size[i];
      sum += d;
      lo = fmin(lo, d);
      hi = fmax(hi, d);
      for (int e = 0; e < 4; ++e)
        below[e] += d < edges[e];
    }
    double mean = sum / s.n, l = mp_lambda(rates[r]), e = exp(-l * 5.9);
    double want = 0.1 + 1.0 / l - 5.9 * e / (1.0 - e);
    means[r] = mean;
    printf("R = %g mm/h: mean diameter %.5f mm, Marshall-Palmer truncated %.5f mm (1/Lambda "
           "%.5f)\n",
           rates[r], mean, want, 1.0 / l);
    CHECK_NEAR(mean / want, 1.0, 0.01);
    CHECK_NEAR(gr_particles_mean_diameter(rates[r]), want, 1e-12);
    CHECK(lo >= 0.1 - 1e-6 && hi <= 6.0 + 1e-5);
    /* The distribution, not only its mean: the empirical CDF at four sizes
     * within 0.005 of the truncated exponential's (its sampling error at
     * 2^18 drops is below 0.001). */
    for (int k = 0; k < 4; ++k)
      CHECK_NEAR((double)below[k] / s.n, mp_cdf(rates[r], edges[k]), 0.005);
    snapshot_free(&s);
  }
  /* Heavier rain, larger drops. */
  CHECK(means[1] > means[0] * 1.4);
}

static void test_fall_speeds(void) {
  /* The formula against Gunn and Kinzer's (1949) measured terminal speeds
   * (m/s) of drops of 1, 2, 3 and 5 mm: within 2%. */
  const double d_mm[] = {1.0, 2.0, 3.0, 5.0}, gk[] = {4.03, 6.49, 8.06, 9.09};
  for (int k = 0; k < 4; ++k)
    CHECK_NEAR(gr_particles_rain_fall_speed(d_mm[k]) / gk[k], 1.0, 0.02);
  CHECK(gr_particles_rain_fall_speed(0.05) == 0.0);
  gr_particles_params p = rain(1 << 16, 30.0);
  p.wind[0] = 3.0;
  p.wind[2] = -0.5;
  p.exposure_time = 0.04;
  snapshot s;
  if (!take(&p, 7.0, &s))
    return;
  double worst = 0.0, worst_streak = 0.0;
  for (int i = 0; i < s.n; ++i) {
    double d = s.size[i];
    double v = fmax(9.65 - 10.3 * exp(-0.6 * d), 0.0);
    worst = fmax(worst, fabs((p.wind[2] - s.vel[3 * i + 2]) - v));
    worst = fmax(worst, fabs(s.vel[3 * i] - 3.0) + fabs(s.vel[3 * i + 1]));
    for (int c = 0; c < 3; ++c)
      worst_streak = fmax(worst_streak, fabs(s.streak[3 * i + c] - 0.04 * s.vel[3 * i + c]));
  }
  printf("fall speeds: largest deviation from 9.65 - 10.3 exp(-0.6 D) %.3g m/s\n", worst);
  CHECK(worst < 1e-5);
  CHECK(worst_streak < 1e-6);
  snapshot_free(&s);
}

/* Between two times each drop falls by its speed times dt, or has respawned
 * at the top; its horizontal motion is the wind's. */
static void drift(double wx, double wy, double *mean_x, double *mean_y, int *respawned) {
  gr_particles_params p = rain(1 << 16, 10.0);
  p.wind[0] = wx;
  p.wind[1] = wy;
  const double t1 = 20.0, t2 = 20.75;
  snapshot a, b;
  if (!take(&p, t1, &a) || !take(&p, t2, &b))
    return;
  double w = p.region[1] - p.region[0], l = p.region[3] - p.region[2];
  double sx = 0.0, sy = 0.0, worst_fall = 0.0;
  int kept = 0, up = 0;
  for (int i = 0; i < a.n; ++i) {
    double za = a.pos[3 * i + 2], zb = b.pos[3 * i + 2];
    double speed = -a.vel[3 * i + 2];
    if (zb > za || speed * (t2 - t1) > za - p.region[4]) {
      ++up; /* respawned: a new life */
      continue;
    }
    worst_fall = fmax(worst_fall, fabs((za - zb) - speed * (t2 - t1)));
    sx += unwrap(a.pos[3 * i], b.pos[3 * i], w);
    sy += unwrap(a.pos[3 * i + 1], b.pos[3 * i + 1], l);
    ++kept;
  }
  CHECK_MSG(worst_fall < 1e-3, "drops fall by speed * dt (worst %.3g m)", worst_fall);
  *mean_x = sx / kept;
  *mean_y = sy / kept;
  *respawned = up;
  snapshot_free(&a);
  snapshot_free(&b);
}

static void test_drift(void) {
  const double winds[][2] = {{0.0, 0.0}, {2.0, 0.0}, {8.0, -3.0}, {-20.0, 5.0}};
  double last = -1.0;
  for (int k = 0; k < 4; ++k) {
    double mx = NAN, my = NAN;
    int up = 0;
    drift(winds[k][0], winds[k][1], &mx, &my, &up);
    double want_x = winds[k][0] * 0.75, want_y = winds[k][1] * 0.75;
    double len = hypot(mx, my), want = hypot(want_x, want_y);
    printf("wind (%g, %g) m/s: mean drift over 0.75 s (%.5f, %.5f) m, wind * dt (%g, %g); %d "
           "respawned\n",
           winds[k][0], winds[k][1], mx, my, want_x, want_y, up);
    if (want == 0.0) {
      CHECK(len < 1e-5);
    } else {
      CHECK_NEAR(mx, want_x, 0.01 * want);
      CHECK_NEAR(my, want_y, 0.01 * want);
    }
    CHECK_MSG(len > last, "drift grows with the wind: %g after %g", len, last);
    last = len;
    /* Some drops do reach the bottom in 0.75 s: respawning was exercised. */
    CHECK(up > 0);
  }
}

static void check_inside(const gr_particles_params *p, const snapshot *s, const char *what) {
  int out = 0;
  for (int i = 0; i < s->n; ++i)
    for (int c = 0; c < 3; ++c) {
      float v = s->pos[3 * i + c];
      out += !((double)v >= (float)p->region[2 * c] && (double)v <= (float)p->region[2 * c + 1]);
    }
  CHECK_MSG(out == 0, "%s: %d coordinates outside the region", what, out);
}

static void test_inside(void) {
  for (int kind = 0; kind < 2; ++kind) {
    gr_particles_params p = rain(1 << 14, 80.0);
    p.kind = kind;
    p.flutter_amplitude = 4.0;
    const double region[6] = {-35.5, 12.25, 1000.0, 1003.0, 240.0, 260.0};
    memcpy(p.region, region, sizeof(region));
    /* Strong wind across a narrow box, an updraft stronger than snow falls,
     * and a downdraft. */
    const double wz[] = {0.0, 3.0, -6.0};
    const double times[] = {0.0, 0.3, 17.0, 1234.5, -50.0};
    for (int w = 0; w < 3; ++w) {
      p.wind[0] = -23.0;
      p.wind[1] = 41.0;
      p.wind[2] = wz[w];
      for (int k = 0; k < 5; ++k) {
        snapshot s;
        if (!take(&p, times[k], &s))
          continue;
        char what[96];
        snprintf(what, sizeof(what), "kind %d, wind z %g, t = %g", kind, wz[w], times[k]);
        check_inside(&p, &s, what);
        snapshot_free(&s);
      }
    }
  }
}

static void test_snowfall(void) {
  gr_particles_params p = rain(1 << 16, 10.0);
  p.kind = GR_PARTICLES_SNOW;
  p.flutter_amplitude = 0.5;
  p.wind[0] = 2.0;
  p.wind[1] = 1.0;
  p.exposure_time = 0.001;
  const double t1 = 30.0, t2 = 31.0;
  snapshot a, b;
  if (!take(&p, t1, &a) || !take(&p, t2, &b))
    return;
  double vmin = 1e9, vmax = -1e9, smin = 1e9, smax = -1e9, sway_max = 0.0, streak_err = 0.0;
  /* The sway's speed is at most 2 pi f a <= 2 pi 0.8 0.5. */
  const double sway_bound = 2.0 * 3.14159265358979 * 0.8 * 0.5 * (1.0 + 1e-5);
  int over = 0;
  double sx = 0.0, sy = 0.0;
  int kept = 0;
  for (int i = 0; i < a.n; ++i) {
    double fall = p.wind[2] - a.vel[3 * i + 2];
    vmin = fmin(vmin, fall);
    vmax = fmax(vmax, fall);
    smin = fmin(smin, a.size[i]);
    smax = fmax(smax, a.size[i]);
    double sway = hypot(a.vel[3 * i] - p.wind[0], a.vel[3 * i + 1] - p.wind[1]);
    sway_max = fmax(sway_max, sway);
    over += sway > sway_bound;
    for (int c = 0; c < 3; ++c)
      streak_err = fmax(streak_err, fabs(a.streak[3 * i + c] - p.exposure_time * a.vel[3 * i + c]));
    double za = a.pos[3 * i + 2], zb = b.pos[3 * i + 2];
    if (zb < za && za - zb < 1.6) {
      sx += unwrap(a.pos[3 * i], b.pos[3 * i], 100.0);
      sy += unwrap(a.pos[3 * i + 1], b.pos[3 * i + 1], 100.0);
      ++kept;
    }
  }
  printf("snow: fall speeds %.4f .. %.4f m/s, sizes %.3f .. %.3f mm, largest sway speed %.4f "
         "m/s, mean drift (%.4f, %.4f) m over 1 s\n",
         vmin, vmax, smin, smax, sway_max, sx / kept, sy / kept);
  CHECK(vmin >= 0.5 - 1e-6 && vmax <= 1.5 + 1e-6);
  CHECK(vmin < 0.51 && vmax > 1.49); /* the range is used, not one speed */
  CHECK(smin >= 2.0 - 1e-6 && smax <= 10.0 + 1e-5);
  CHECK(over == 0);
  CHECK(sway_max > 0.5 * sway_bound); /* the flakes do flutter */
  /* Over 1 ms the streak is the velocity times the exposure (the sway's
   * curvature adds (2 pi f)^2 a E^2 / 2, below 1e-5 m). */
  CHECK(streak_err < 1e-5);
  /* The sways of 65536 flakes average out: the mean drift is the wind's. */
  CHECK_NEAR(sx / kept, 2.0, 0.02);
  CHECK_NEAR(sy / kept, 1.0, 0.02);
  snapshot_free(&a);
  snapshot_free(&b);
  /* Without wind and flutter a flake falls straight: no horizontal motion. */
  p.wind[0] = p.wind[1] = 0.0;
  p.flutter_amplitude = 0.0;
  if (!take(&p, t1, &a) || !take(&p, t2, &b))
    return;
  int moved = 0;
  for (int i = 0; i < a.n; ++i) {
    int same_life = b.pos[3 * i + 2] < a.pos[3 * i + 2];
    moved += same_life && (a.pos[3 * i] != b.pos[3 * i] || a.pos[3 * i + 1] != b.pos[3 * i + 1]);
  }
  CHECK(moved == 0);
  snapshot_free(&a);
  snapshot_free(&b);
}

/* A streak is the motion over the exposure: the position at t minus the
 * one at t - E, for particles in the same life then and now. */
static void test_streaks(void) {
  for (int kind = 0; kind < 2; ++kind) {
    gr_particles_params p = rain(1 << 14, 20.0);
    p.kind = kind;
    p.exposure_time = 0.4;
    p.flutter_amplitude = 1.0;
    p.wind[0] = -3.0;
    p.wind[1] = 1.25;
    const double t = 9.0;
    snapshot now, then;
    if (!take(&p, t, &now))
      continue;
    if (!take(&p, t - p.exposure_time, &then)) {
      snapshot_free(&now);
      continue;
    }
    double worst = 0.0;
    int kept = 0;
    for (int i = 0; i < now.n; ++i) {
      if (!(now.pos[3 * i + 2] < then.pos[3 * i + 2]))
        continue;
      ++kept;
      double d[3] = {unwrap(then.pos[3 * i], now.pos[3 * i], 100.0),
                     unwrap(then.pos[3 * i + 1], now.pos[3 * i + 1], 100.0),
                     now.pos[3 * i + 2] - then.pos[3 * i + 2]};
      for (int c = 0; c < 3; ++c)
        worst = fmax(worst, fabs(d[c] - now.streak[3 * i + c]));
    }
    printf("kind %d: streaks of %d particles match their motion over %g s within %.3g m\n", kind,
           kept, p.exposure_time, worst);
    CHECK(kept > now.n / 2);
    CHECK(worst < 1e-3);
    snapshot_free(&now);
    snapshot_free(&then);
  }
}

static void test_errors(void) {
  char msg[256];
  gr_particles_params p = rain(1 << 12, 10.0);
  CHECK(gr_particles_params_validate(&p, msg, sizeof(msg)) == GR_OK);
  /* Each spoilt parameter and the word its sentence must name. */
  const char *words[8] = {"Count",  "Count",  "RainRate", "RainRate",
                          "region", "region", "wind",     "kind"};
  gr_particles_params bad[8];
  for (int k = 0; k < 8; ++k)
    bad[k] = p;
  bad[0].count = 1023;
  bad[1].count = (1 << 24) + 1;
  bad[2].rain_rate = -1.0 / 3.6e6;
  bad[3].rain_rate = 0.0;
  bad[4].region[5] = bad[4].region[4];
  bad[5].region[1] = NAN;
  bad[6].wind[1] = INFINITY;
  bad[7].kind = 2;
  gr_particles *h = NULL;
  CHECK(gr_particles_create(ctx, &p, &h) == GR_OK);
  CHECK(gr_particles_get_output(h, GR_PARTICLES_POSITION, (float[3 << 12]){0}) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_particles_last_error(h), "gr_particles_compute") != NULL);
  for (int k = 0; k < 8; ++k) {
    CHECK(gr_particles_params_validate(&bad[k], msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
    CHECK_MSG(strstr(msg, words[k]) && msg[strlen(msg) - 1] == '.', "case %d: %s", k, msg);
    gr_particles *none = NULL;
    CHECK(gr_particles_create(ctx, &bad[k], &none) == GR_ERR_INVALID_ARGUMENT && !none);
    /* A refused update keeps the particles as they were: the next works. */
    CHECK(gr_particles_set_params(h, &bad[k]) == GR_ERR_INVALID_ARGUMENT);
    CHECK(strstr(gr_particles_last_error(h), words[k]) != NULL);
    CHECK(gr_particles_count(h) == 1 << 12);
    CHECK(gr_particles_compute(h, 1.0) == GR_OK);
  }
  printf("e.g.: %s\n", gr_particles_last_error(h));
  gr_particles_params_validate(&bad[2], msg, sizeof(msg));
  CHECK_MSG(strstr(msg, "mm/h") && strstr(msg, "-1"), "%s", msg);
  CHECK(gr_particles_compute(h, NAN) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_particles_last_error(h), "time") != NULL);
  CHECK(gr_particles_get_output(h, GR_PARTICLES_OUTPUT_COUNT, (float[3]){0}) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_particles_params_validate(NULL, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_particles_create(NULL, &p, &h) == GR_ERR_INVALID_ARGUMENT);
  gr_particles_destroy(h);
  gr_particles_destroy(NULL);
  CHECK(gr_particles_output_name(GR_PARTICLES_RAIN, GR_PARTICLES_SIZE) &&
        !strcmp(gr_particles_output_name(GR_PARTICLES_RAIN, GR_PARTICLES_SIZE), "diameter"));
  CHECK(!strcmp(gr_particles_output_name(GR_PARTICLES_SNOW, GR_PARTICLES_SIZE), "size"));
  CHECK(gr_particles_output_name(GR_PARTICLES_SNOW, GR_PARTICLES_OUTPUT_COUNT) == NULL);
}

static void test_param_table(void) {
  int n = 0;
  const gr_param_bound *b = gr_particles_param_bounds(&n);
  CHECK(n == 5);
  gr_particles_params d, p;
  gr_particles_params_init(&d);
  for (int r = 0; r < n; ++r) {
    char msg[256];
#define SET(v)                                                                                     \
  do {                                                                                             \
    p = d;                                                                                         \
    double core_ = (v)*b[r].to_core;                                                               \
    if (r == 0)                                                                                    \
      p.count = (int)core_;                                                                        \
    else if (r == 1)                                                                               \
      p.rain_rate = core_;                                                                         \
    else if (r == 2)                                                                               \
      p.exposure_time = core_;                                                                     \
    else if (r == 3)                                                                               \
      p.seed = (int)core_;                                                                         \
    else                                                                                           \
      p.flutter_amplitude = core_;                                                                 \
  } while (0)
    double defaults[] = {d.count, d.rain_rate, d.exposure_time, d.seed, d.flutter_amplitude};
    CHECK_MSG(defaults[r] == b[r].default_value * b[r].to_core, "%s default", b[r].property);
    SET(b[r].max);
    CHECK_MSG(gr_particles_params_validate(&p, msg, sizeof(msg)) == GR_OK, "%s max", b[r].property);
    SET(b[r].min);
    CHECK_MSG((gr_particles_params_validate(&p, msg, sizeof(msg)) == GR_OK) == !b[r].min_open,
              "%s min", b[r].property);
    if (r == 3)
      continue; /* Seed: every int */
    SET(b[r].integer ? b[r].max + 1 : b[r].max * 1.001 + 1e-9);
    CHECK_MSG(gr_particles_params_validate(&p, msg, sizeof(msg)) != GR_OK &&
                  strstr(msg, b[r].property),
              "%s above max", b[r].property);
#undef SET
  }
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

/* For valgrind (memcheck.particles): both kinds of particle once, every
 * output read, a refused change of parameters. */
static void test_memcheck(void) {
  for (int kind = 0; kind < 2; ++kind) {
    gr_particles_params p;
    gr_particles_params_init(&p);
    p.kind = kind;
    p.count = 1024;
    gr_particles *s = NULL;
    CHECK(gr_particles_create(ctx, &p, &s) == GR_OK);
    if (!s)
      return;
    float *out = malloc((size_t)gr_particles_count(s) * 3 * sizeof(float));
    CHECK(gr_particles_compute(s, 1.5) == GR_OK);
    for (int o = 0; o < GR_PARTICLES_OUTPUT_COUNT; ++o)
      CHECK(gr_particles_get_output(s, (gr_particles_output)o, out) == GR_OK);
    p.count = 1;
    CHECK(gr_particles_set_params(s, &p) != GR_OK);
    CHECK(gr_particles_last_error(s)[0] != '\0');
    free(out);
    gr_particles_destroy(s);
  }
}

static const gr_subtest tests[] = {
    {"counts", test_counts, 0},         {"determinism", test_determinism, 0},
    {"drop_sizes", test_drop_sizes, 0}, {"fall_speeds", test_fall_speeds, 0},
    {"drift", test_drift, 0},           {"inside", test_inside, 0},
    {"snowfall", test_snowfall, 0},     {"streaks", test_streaks, 0},
    {"errors", test_errors, 0},         {"param_table", test_param_table, 0},
    {"memcheck", test_memcheck, 1},
};

int main(int argc, char **argv) {
  return gr_test_main(argc, argv, tests, (int)(sizeof(tests) / sizeof(tests[0])), setup, teardown);
}
