/* Sky tests. Lightning: bit-identical bolts for one seed and different ones
 * for another, the point count ControlPoints + Strands * max(2,
 * ControlPoints / 2) and the layout of strand ids and intensities, Start
 * and End exact, a straight line without jitter, every branch rooted
 * exactly on a main-strand point and leaving it at 20 to 45 degrees, the
 * middle's lateral spread Jitter L / 2 per axis over 4000 seeds, the strike
 * on a terrain, the shape at a time Variant + floor(t FlickerRate). Cloud cover: the clouded
 * fraction within 0.05 of Cover on a large image, exactly 0 and 1 at the ends, monotone in Cover
 * pixel by pixel, determinism (also band by band), the drift an exact shift for whole pixels and
 * within the interpolation error for half a pixel, and the error paths. */
#include "graupel/sky.h"
#include "gr_test.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static gr_context *ctx;

/* ------------------------------------------------------------- lightning */

typedef struct bolt {
  long n;
  double *xyz;
  float *intensity;
  int *strand;
} bolt;

static int make_bolt(const gr_lightning_params *p, bolt *b) {
  char msg[256];
  b->n = gr_lightning_point_count(p);
  b->xyz = malloc(sizeof(double) * 3 * (size_t)b->n);
  b->intensity = malloc(sizeof(float) * (size_t)b->n);
  b->strand = malloc(sizeof(int) * (size_t)b->n);
  gr_status st = gr_lightning_generate(p, b->xyz, b->intensity, b->strand, msg, sizeof(msg));
  CHECK_MSG(st == GR_OK, "%s", msg);
  return st == GR_OK;
}

static void free_bolt(bolt *b) {
  free(b->xyz);
  free(b->intensity);
  free(b->strand);
  memset(b, 0, sizeof(*b));
}

static gr_lightning_params slanted(void) {
  gr_lightning_params p;
  gr_lightning_params_init(&p);
  double s[3] = {120.0, -40.0, 1500.0}, e[3] = {-60.0, 210.0, 35.5};
  memcpy(p.start, s, sizeof(s));
  memcpy(p.end, e, sizeof(e));
  return p;
}

static void test_lightning_determinism(void) {
  gr_lightning_params p = slanted();
  bolt a, b, c, d;
  if (!make_bolt(&p, &a) || !make_bolt(&p, &b))
    return;
  CHECK(a.n == b.n);
  CHECK(memcmp(a.xyz, b.xyz, sizeof(double) * 3 * (size_t)a.n) == 0);
  CHECK(memcmp(a.intensity, b.intensity, sizeof(float) * (size_t)a.n) == 0);
  CHECK(memcmp(a.strand, b.strand, sizeof(int) * (size_t)a.n) == 0);
  p.seed = 1;
  make_bolt(&p, &c);
  p.seed = 0;
  p.variant = 1;
  make_bolt(&p, &d);
  /* Another seed (or reshape) moves every point but the two ends. */
  long moved_c = 0, moved_d = 0;
  for (long k = 0; k < a.n; ++k) {
    moved_c += memcmp(a.xyz + 3 * k, c.xyz + 3 * k, 3 * sizeof(double)) != 0;
    moved_d += memcmp(a.xyz + 3 * k, d.xyz + 3 * k, 3 * sizeof(double)) != 0;
  }
  CHECK_MSG(moved_c >= a.n - 2 - p.strands, "seed 1 moved %ld of %ld points", moved_c, a.n);
  CHECK_MSG(moved_d >= a.n - 2 - p.strands, "variant 1 moved %ld of %ld points", moved_d, a.n);
  printf("  another seed moves %ld of %ld points, another variant %ld\n", moved_c, a.n, moved_d);
  free_bolt(&a);
  free_bolt(&b);
  free_bolt(&c);
  free_bolt(&d);
}

static void test_lightning_counts(void) {
  static const int cases[][2] = {{50, 0}, {50, 4}, {2, 3}, {3, 1}, {5, 7}, {51, 10}, {1000, 100}};
  for (size_t c = 0; c < sizeof(cases) / sizeof(cases[0]); ++c) {
    gr_lightning_params p = slanted();
    p.control_points = cases[c][0];
    p.strands = cases[c][1];
    int m = p.control_points / 2 > 2 ? p.control_points / 2 : 2;
    long want = p.control_points + (long)p.strands * m;
    CHECK(gr_lightning_branch_points(p.control_points) == m);
    bolt b;
    if (!make_bolt(&p, &b))
      return;
    CHECK_MSG(b.n == want, "N %d, S %d: %ld points, want %ld", p.control_points, p.strands, b.n,
              want);
    long main_points = 0;
    int ok = 1;
    for (long k = 0; k < b.n; ++k) {
      int s = k < p.control_points ? 0 : 1 + (int)((k - p.control_points) / m);
      ok &= b.strand[k] == s;
      main_points += b.strand[k] == 0;
      ok &= s == 0 ? b.intensity[k] == 1.0f : b.intensity[k] > 0.0f && b.intensity[k] <= 0.5f;
    }
    CHECK_MSG(ok, "N %d, S %d: strand ids or intensities out of layout", p.control_points,
              p.strands);
    CHECK(main_points == p.control_points);
    free_bolt(&b);
  }
  /* The default is the seed's 50 control points. */
  gr_lightning_params d;
  gr_lightning_params_init(&d);
  CHECK(d.control_points == 50);
}

static void test_lightning_ends(void) {
  for (int seed = 0; seed < 50; ++seed) {
    gr_lightning_params p = slanted();
    p.seed = seed * 7919 - 100;
    p.jitter = 0.02 * (seed % 10);
    if (seed % 3 == 1) { /* a level bolt between two clouds */
      p.end[2] = p.start[2];
    }
    bolt b;
    if (!make_bolt(&p, &b))
      return;
    long last = p.control_points - 1;
    CHECK(memcmp(b.xyz, p.start, sizeof(p.start)) == 0);
    CHECK(memcmp(b.xyz + 3 * last, p.end, sizeof(p.end)) == 0);
    free_bolt(&b);
  }
  /* No jitter: every main point on the segment, evenly spaced. */
  gr_lightning_params p = slanted();
  p.jitter = 0.0;
  bolt b;
  if (!make_bolt(&p, &b))
    return;
  double worst = 0.0;
  for (int k = 0; k < p.control_points; ++k) {
    double t = (double)k / (p.control_points - 1);
    for (int c = 0; c < 3; ++c)
      worst = fmax(worst, fabs(b.xyz[3 * k + c] - (p.start[c] + t * (p.end[c] - p.start[c]))));
  }
  CHECK_MSG(worst < 1e-9, "off the segment by %g m", worst);
  free_bolt(&b);
}

static void test_lightning_branches(void) {
  double worst_angle_lo = 90.0, worst_angle_hi = 0.0;
  for (int seed = 0; seed < 40; ++seed) {
    gr_lightning_params p = slanted();
    p.seed = seed;
    p.strands = 8;
    p.jitter = seed < 20 ? 0.1 : 0.0;
    bolt b;
    if (!make_bolt(&p, &b))
      return;
    const int n = p.control_points, m = gr_lightning_branch_points(n);
    double u[3], len = 0.0;
    for (int c = 0; c < 3; ++c) {
      u[c] = p.end[c] - p.start[c];
      len += u[c] * u[c];
    }
    len = sqrt(len);
    for (int c = 0; c < 3; ++c)
      u[c] /= len;
    for (int s = 1; s <= p.strands; ++s) {
      const double *q = b.xyz + 3 * ((long)n + (long)(s - 1) * m);
      int root = -1;
      for (int k = 0; k < n && root < 0; ++k)
        if (memcmp(q, b.xyz + 3 * k, 3 * sizeof(double)) == 0)
          root = k;
      CHECK_MSG(root >= 0 && root <= 0.8 * (n - 1),
                "seed %d branch %d: root %d not on the main strand's upper 80 %%", seed, s, root);
      if (p.jitter == 0.0 && root >= 0) {
        /* Without jitter a branch is straight: its angle to the bolt and its
         * length are the documented ones. */
        const double *tip = q + 3 * (m - 1);
        double d[3], dl = 0.0, dot = 0.0;
        for (int c = 0; c < 3; ++c) {
          d[c] = tip[c] - q[c];
          dl += d[c] * d[c];
        }
        dl = sqrt(dl);
        for (int c = 0; c < 3; ++c)
          dot += d[c] / dl * u[c];
        double angle = acos(fmin(1.0, dot)) * 180.0 / PI;
        worst_angle_lo = fmin(worst_angle_lo, angle);
        worst_angle_hi = fmax(worst_angle_hi, angle);
        double rest = len * (1.0 - (double)root / (n - 1));
        CHECK_MSG(dl >= 0.15 * rest - 1e-9 && dl <= 0.4 * rest + 1e-9,
                  "seed %d branch %d: length %g of the rest %g", seed, s, dl, rest);
      }
    }
    free_bolt(&b);
  }
  printf("  branch angles %.2f .. %.2f degrees\n", worst_angle_lo, worst_angle_hi);
  CHECK(worst_angle_lo >= 20.0 - 1e-9 && worst_angle_hi <= 45.0 + 1e-9);
}

static void test_lightning_spread(void) {
  /* The bridge's middle (t = 1/2 with 51 points): lateral offset of
   * variance (Jitter L / 2)^2 per axis, so E|offset|^2 = Jitter^2 L^2 / 2. */
  const int seeds = 4000;
  double sum2 = 0.0, along = 0.0;
  gr_lightning_params p = slanted();
  p.control_points = 51;
  p.strands = 0;
  p.jitter = 0.2;
  double len = 0.0, u[3];
  for (int c = 0; c < 3; ++c) {
    u[c] = p.end[c] - p.start[c];
    len += u[c] * u[c];
  }
  len = sqrt(len);
  for (int c = 0; c < 3; ++c)
    u[c] /= len;
  double xyz[3 * 51];
  for (int s = 0; s < seeds; ++s) {
    p.seed = s;
    CHECK(gr_lightning_generate(&p, xyz, NULL, NULL, NULL, 0) == GR_OK);
    double off[3], dot = 0.0;
    for (int c = 0; c < 3; ++c) {
      off[c] = xyz[75 + c] - 0.5 * (p.start[c] + p.end[c]);
      dot += off[c] * u[c];
    }
    along = fmax(along, fabs(dot));
    sum2 += off[0] * off[0] + off[1] * off[1] + off[2] * off[2];
  }
  double ratio = sum2 / seeds / (p.jitter * p.jitter * len * len / 2.0);
  printf("  mean square lateral offset / (Jitter L)^2 / 2 = %.4f over %d seeds\n", ratio, seeds);
  CHECK_NEAR(ratio, 1.0, 0.08);
  CHECK_MSG(along < 1e-9 * len, "offsets are lateral: %g m along the bolt", along);
}

static void test_lightning_strike(void) {
  const long npoints = 1000;
  int distinct = 0;
  unsigned char seen[1000] = {0};
  for (int s = 0; s < 200; ++s) {
    long k = gr_lightning_strike_index(s, 0, npoints);
    CHECK(k >= 0 && k < npoints);
    CHECK(k == gr_lightning_strike_index(s, 0, npoints));
    if (k >= 0 && k < npoints && !seen[k]) {
      seen[k] = 1;
      ++distinct;
    }
  }
  CHECK_MSG(distinct > 150, "200 seeds strike %d distinct points of 1000", distinct);
  CHECK(gr_lightning_strike_index(3, 0, 0) == -1);
  CHECK(gr_lightning_strike_index(3, 0, 1) == 0);
  double bounds[6] = {-500, 1500, 0, 1000, 20, 180}, end[3] = {10, 20, 50}, start[3];
  gr_lightning_start_over(5, 0, bounds, end, start);
  /* 1000 m (half the larger extent) above the highest point, leaning at
   * most a third of that. */
  CHECK_NEAR(start[2], 1180.0, 1e-9);
  CHECK(hypot(start[0] - end[0], start[1] - end[1]) <= 1000.0 / 3.0 + 1e-9);
}

static void test_lightning_flicker(void) {
  /* The shape at time t is Variant + floor(t FlickerRate): at 4 reshapes a
   * second, t = 0.3 s draws Variant 1's bolt and t = 0.24 s Variant 0's,
   * bit for bit; FlickerRate 0 draws one shape at every time. */
  gr_lightning_params p = slanted();
  p.strands = 3;
  bolt still, one, later, fixed;
  make_bolt(&p, &still);
  p.variant = 1;
  make_bolt(&p, &one);
  p.variant = 0;
  p.flicker_rate = 4.0;
  static const double times[] = {0.0, 0.1, 0.24, 0.25, 0.3, 0.49, 7.76};
  static const int shapes[] = {0, 0, 0, 1, 1, 1, 31};
  for (int k = 0; k < 7; ++k) {
    p.time = times[k];
    CHECK_MSG(gr_lightning_shape(&p) == shapes[k], "t %g: shape %d", times[k],
              gr_lightning_shape(&p));
  }
  p.time = 0.3;
  make_bolt(&p, &later);
  p.flicker_rate = 0.0;
  p.time = 1234.5;
  make_bolt(&p, &fixed);
  size_t bytes = sizeof(double) * 3 * (size_t)still.n;
  CHECK(memcmp(later.xyz, one.xyz, bytes) == 0);
  CHECK(memcmp(later.xyz, still.xyz, bytes) != 0);
  CHECK(memcmp(fixed.xyz, still.xyz, bytes) == 0);
  p.time = NAN;
  char msg[256];
  CHECK(gr_lightning_params_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT &&
        strstr(msg, "time"));
  free_bolt(&still);
  free_bolt(&one);
  free_bolt(&later);
  free_bolt(&fixed);
}

static void test_lightning_errors(void) {
  char msg[256];
  double xyz[3 * 200];
  gr_lightning_params p = slanted();
  gr_lightning_params bad;
#define REFUSED(edit, word)                                                                        \
  do {                                                                                             \
    bad = p;                                                                                       \
    edit;                                                                                          \
    msg[0] = 0;                                                                                    \
    gr_status st_ = gr_lightning_generate(&bad, xyz, NULL, NULL, msg, sizeof(msg));                \
    CHECK_MSG(st_ == GR_ERR_INVALID_ARGUMENT && strstr(msg, word) && msg[strlen(msg) - 1] == '.',  \
              "%s: '%s'", #edit, msg);                                                             \
    CHECK(gr_lightning_point_count(&bad) == 0);                                                    \
  } while (0)
  REFUSED(bad.control_points = 1, "ControlPoints");
  REFUSED(bad.control_points = 0, "ControlPoints");
  REFUSED(bad.control_points = -3, "ControlPoints");
  REFUSED(bad.strands = -1, "Strands");
  REFUSED(bad.strands = 101, "Strands");
  REFUSED(bad.jitter = NAN, "Jitter");
  REFUSED(bad.jitter = 1.5, "Jitter");
  REFUSED(bad.flicker_rate = -1.0, "FlickerRate");
  REFUSED(memcpy(bad.end, bad.start, sizeof(bad.start)), "same point");
  REFUSED(bad.start[1] = INFINITY, "finite");
#undef REFUSED
  printf("  e.g. %s\n", msg);
  bad = p;
  bad.control_points = 1;
  gr_lightning_generate(&bad, xyz, NULL, NULL, msg, sizeof(msg));
  printf("  e.g. %s\n", msg);
  /* The next good call works. */
  p.strands = 2;
  CHECK(gr_lightning_generate(&p, xyz, NULL, NULL, msg, sizeof(msg)) == GR_OK);
  CHECK(gr_lightning_generate(&p, NULL, NULL, NULL, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
}

/* ----------------------------------------------------------- cloud cover */

static float *clouds_at(const gr_cloud_cover_params *p, double t, unsigned char *rgb) {
  gr_cloud_cover *c = NULL;
  gr_status st = gr_cloud_cover_create(ctx, p, &c);
  CHECK_MSG(st == GR_OK, "%s", gr_cloud_cover_last_error(NULL));
  if (st != GR_OK)
    return NULL;
  float *f = malloc(sizeof(float) * (size_t)p->resolution * (size_t)p->resolution);
  st = gr_cloud_cover_compute(c, t);
  if (st == GR_OK)
    st = gr_cloud_cover_get(c, f, rgb);
  CHECK_MSG(st == GR_OK, "%s", gr_cloud_cover_last_error(c));
  gr_cloud_cover_destroy(c);
  return f;
}

static double clouded(const float *f, long n) {
  long k = 0;
  for (long i = 0; i < n; ++i)
    k += f[i] > 0.0f;
  return (double)k / (double)n;
}

static void test_cloud_fraction(void) {
  /* 64 x 64 wavelengths of the first octave on 1024^2 pixels. */
  gr_cloud_cover_params p;
  gr_cloud_cover_params_init(&p);
  p.resolution = 1024;
  p.size = 131072.0;
  p.scale = 2048.0;
  const long n = (long)p.resolution * p.resolution;
  for (int seed = 0; seed < 2; ++seed) {
    p.seed = seed * 12345 + 7;
    gr_cloud_cover *c = NULL;
    if (gr_cloud_cover_create(ctx, &p, &c) != GR_OK) {
      CHECK_MSG(0, "%s", gr_cloud_cover_last_error(NULL));
      return;
    }
    float *prev = malloc(sizeof(float) * (size_t)n), *f = malloc(sizeof(float) * (size_t)n);
    double prev_frac = -1.0, worst = 0.0, prev_t = 2.0;
    long dropped = 0;
    for (int step = 0; step <= 10; ++step) {
      p.cover = step / 10.0;
      CHECK(gr_cloud_cover_set_params(c, &p) == GR_OK);
      double t = gr_cloud_cover_threshold(c);
      CHECK(t <= prev_t);
      prev_t = t;
      CHECK(gr_cloud_cover_compute(c, 0.0) == GR_OK);
      CHECK(gr_cloud_cover_get(c, f, NULL) == GR_OK);
      double frac = clouded(f, n);
      worst = fmax(worst, fabs(frac - p.cover));
      CHECK_MSG(frac >= prev_frac, "Cover %.2f: clouded %.5f below %.5f", p.cover, frac, prev_frac);
      if (step > 0)
        for (long i = 0; i < n; ++i)
          dropped += f[i] < prev[i];
      if (step == 0)
        CHECK_MSG(frac == 0.0, "Cover 0 clouds %.6f of the sky", frac);
      if (step == 10)
        CHECK_MSG(frac == 1.0, "Cover 1 clouds %.6f of the sky", frac);
      if (step % 5 == 0 || step == 1)
        printf("  seed %d Cover %.2f: clouded %.4f (T = %.4f)\n", p.seed, p.cover, frac, t);
      prev_frac = frac;
      float *tmp = prev;
      prev = f;
      f = tmp;
    }
    printf("  seed %d: |clouded - Cover| at most %.4f over Cover 0, 0.1, .., 1\n", p.seed, worst);
    CHECK_MSG(worst <= 0.05, "clouded fraction %.4f from Cover", worst);
    CHECK_MSG(dropped == 0, "%ld pixels thinned as Cover rose", dropped);
    free(prev);
    free(f);
    gr_cloud_cover_destroy(c);
  }
}

static void test_cloud_determinism(void) {
  gr_cloud_cover_params p;
  gr_cloud_cover_params_init(&p);
  p.resolution = 200;
  const size_t n = 200 * 200;
  unsigned char *rgb_a = malloc(3 * n), *rgb_b = malloc(3 * n);
  float *a = clouds_at(&p, 123.0, rgb_a), *b = clouds_at(&p, 123.0, rgb_b);
  if (!a || !b)
    return;
  CHECK(memcmp(a, b, n * sizeof(float)) == 0);
  CHECK(memcmp(rgb_a, rgb_b, 3 * n) == 0);
  /* Band by band (progress, abort) is the same image. */
  gr_cloud_cover *c = NULL;
  CHECK(gr_cloud_cover_create(ctx, &p, &c) == GR_OK);
  float *bands = malloc(n * sizeof(float));
  CHECK(gr_cloud_cover_compute_rows(c, 123.0, 0, 77) == GR_OK);
  CHECK(gr_cloud_cover_get(c, bands, NULL) == GR_ERR_INVALID_ARGUMENT); /* half made */
  CHECK(gr_cloud_cover_compute_rows(c, 123.0, 77, 123) == GR_OK);
  CHECK(gr_cloud_cover_get(c, bands, NULL) == GR_OK);
  CHECK(memcmp(a, bands, n * sizeof(float)) == 0);
  gr_cloud_cover_destroy(c);
  /* sky_rgb: blue where clear, white-grey where clouded. */
  int colours = 1;
  for (size_t k = 0; k < n; ++k) {
    const unsigned char *px = rgb_a + 3 * k;
    if (a[k] == 0.0f)
      colours &= px[0] == 74 && px[1] == 128 && px[2] == 214;
    if (a[k] > 0.9f)
      colours &= px[2] >= 150 && abs(px[0] - px[2]) < 30;
  }
  CHECK(colours);
  p.seed = 1;
  float *d = clouds_at(&p, 123.0, NULL);
  long differ = 0;
  for (size_t k = 0; d && k < n; ++k)
    differ += a[k] != d[k];
  printf("  seed 1 differs from seed 0 at %.1f %% of the pixels\n", 100.0 * differ / n);
  CHECK(differ > (long)n / 2);
  free(a);
  free(b);
  free(d);
  free(bands);
  free(rgb_a);
  free(rgb_b);
}

/* Worst |f1(i, j) - f0(i - di, j - dj)| over the pixels both images have. */
static double shifted_diff(const float *f0, const float *f1, int n, int di, int dj) {
  double worst = 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int i0 = i - di, j0 = j - dj;
      if (i0 < 0 || j0 < 0 || i0 >= n || j0 >= n)
        continue;
      worst = fmax(worst, fabs(f1[j * n + i] - f0[j0 * n + i0]));
    }
  return worst;
}

static void test_cloud_drift(void) {
  gr_cloud_cover_params p;
  gr_cloud_cover_params_init(&p);
  p.resolution = 256;
  p.size = 8192.0; /* 32 m pixels */
  p.scale = 2000.0;
  p.wind_speed = 10.0;
  const int n = p.resolution;
  static const struct {
    double direction, speed, dt;
    int di, dj;
  } cases[] = {
      {90.0, 10.0, 9.6, 3, 0},                    /* east, 3 pixels */
      {0.0, 10.0, 32.0, 0, 10},                   /* north, 10 pixels */
      {225.0, 48.0 * 1.41421356237, 2.0, -3, -3}, /* south-west, 3 pixels each way */
  };
  for (size_t c = 0; c < sizeof(cases) / sizeof(cases[0]); ++c) {
    p.wind_direction = cases[c].direction;
    p.wind_speed = cases[c].speed;
    double dt = cases[c].dt;
    int di = cases[c].di, dj = cases[c].dj;
    float *f0 = clouds_at(&p, 1000.0, NULL), *f1 = clouds_at(&p, 1000.0 + dt, NULL);
    if (!f0 || !f1)
      return;
    double same = shifted_diff(f0, f1, n, di, dj), unshifted = shifted_diff(f0, f1, n, 0, 0);
    printf("  wind %g m/s towards %g deg, %g s: shifted by (%d, %d) px the fields agree within "
           "%.2g (unshifted %.2g)\n",
           p.wind_speed, p.wind_direction, dt, di, dj, same, unshifted);
    CHECK_MSG(same < 2e-4, "%g", same);
    CHECK(unshifted > 0.1);
    free(f0);
    free(f1);
  }
  /* Half a pixel east on smooth clouds: Scale 256 pixels (the finest
   * octave 8), Cover 1 and Sharpness 0.999, so that cloud = 1 - exp(-0.255
   * n) has no threshold's kink. The field equals the mean of its two
   * neighbours at the earlier time within the linear interpolation's error
   * |f''| h^2 / 8, bounded per pixel by a quarter of the larger neighbouring
   * second difference (twice the estimate). */
  p.scale = 8192.0;
  p.cover = 1.0;
  p.sharpness = 0.999;
  p.wind_direction = 90.0;
  p.wind_speed = 16.0;
  float *f0 = clouds_at(&p, 0.0, NULL), *f1 = clouds_at(&p, 1.0, NULL);
  if (!f0 || !f1)
    return;
  double worst_excess = -1.0, worst_err = 0.0, worst_change = 0.0;
  long beyond = 0, counted = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 2; i < n - 1; ++i) {
      const float *r = f0 + j * n;
      double lerp = 0.5 * (r[i] + r[i - 1]);
      double err = fabs(f1[j * n + i] - lerp);
      double bound = 0.25 * fmax(fabs(r[i] - 2.0 * r[i - 1] + r[i - 2]),
                                 fabs(r[i + 1] - 2.0 * r[i] + r[i - 1])) +
                     1e-5;
      worst_err = fmax(worst_err, err);
      worst_change = fmax(worst_change, fabs(f1[j * n + i] - r[i]));
      worst_excess = fmax(worst_excess, err - bound);
      beyond += err > bound;
      ++counted;
    }
  printf("  half a pixel: worst |f(t+dt) - lerp| %.3g (change %.3g), beyond the bound at %ld of "
         "%ld pixels\n",
         worst_err, worst_change, beyond, counted);
  CHECK(beyond == 0);
  CHECK(worst_err < 0.2 * worst_change);
  free(f0);
  free(f1);
}

static void test_cloud_errors(void) {
  gr_cloud_cover_params p, bad;
  gr_cloud_cover_params_init(&p);
  p.resolution = 64;
  gr_cloud_cover *c = NULL;
#define REFUSED(edit, word)                                                                        \
  do {                                                                                             \
    bad = p;                                                                                       \
    edit;                                                                                          \
    gr_status st_ = gr_cloud_cover_create(ctx, &bad, &c);                                          \
    const char *m_ = gr_cloud_cover_last_error(NULL);                                              \
    CHECK_MSG(st_ == GR_ERR_INVALID_ARGUMENT && c == NULL && strstr(m_, word) &&                   \
                  m_[strlen(m_) - 1] == '.',                                                       \
              "%s: '%s'", #edit, m_);                                                              \
  } while (0)
  REFUSED(bad.cover = -0.1, "Cover");
  REFUSED(bad.cover = 1.1, "Cover");
  REFUSED(bad.cover = NAN, "Cover");
  REFUSED(bad.resolution = 0, "Resolution");
  printf("  e.g. %s\n", gr_cloud_cover_last_error(NULL));
  REFUSED(bad.resolution = -4, "Resolution");
  REFUSED(bad.scale = 0.0, "Scale");
  REFUSED(bad.size = -1.0, "Size");
  REFUSED(bad.sharpness = 1.0, "Sharpness");
  REFUSED(bad.wind_speed = INFINITY, "WindSpeed");
  REFUSED(bad.wind_direction = 400.0, "WindDirection");
#undef REFUSED
  /* After refusals a good image works; a bad set_params keeps the image. */
  CHECK(gr_cloud_cover_create(ctx, &p, &c) == GR_OK);
  float f[64 * 64], g[64 * 64];
  CHECK(gr_cloud_cover_get(c, f, NULL) == GR_ERR_INVALID_ARGUMENT); /* nothing computed */
  CHECK(gr_cloud_cover_compute(c, 5.0) == GR_OK);
  CHECK(gr_cloud_cover_get(c, f, NULL) == GR_OK);
  bad = p;
  bad.cover = 2.0;
  CHECK(gr_cloud_cover_set_params(c, &bad) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_cloud_cover_last_error(c), "Cover") != NULL);
  CHECK(gr_cloud_cover_compute(c, NAN) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_cloud_cover_compute_rows(c, 5.0, 60, 10) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_cloud_cover_compute(c, 5.0) == GR_OK);
  CHECK(gr_cloud_cover_get(c, g, NULL) == GR_OK);
  CHECK(memcmp(f, g, sizeof(f)) == 0);
  /* A drift far beyond the lattice's range is refused, not wrapped. */
  CHECK(gr_cloud_cover_compute(c, 1e15) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_cloud_cover_last_error(c), "Scale") != NULL);
  gr_cloud_cover_destroy(c);
  gr_cloud_cover_destroy(NULL);
}

static void test_param_table(void) {
  int count = 0;
  const gr_param_bound *b = gr_sky_param_bounds(&count);
  CHECK(count == 12);
  char msg[256];
  gr_lightning_params lp;
  gr_cloud_cover_params cp;
  for (int r = 0; r < count; ++r) {
    /* Each row belongs to the lightning, the clouds or (Seed) both. */
    int is_l = 0, is_c = 0;
#define SET(v)                                                                                     \
  do {                                                                                             \
    gr_lightning_params_init(&lp);                                                                 \
    gr_cloud_cover_params_init(&cp);                                                               \
    const char *q = b[r].property;                                                                 \
    double x = (v);                                                                                \
    if (!strcmp(q, "ControlPoints"))                                                               \
      lp.control_points = (int)x, is_l = 1;                                                        \
    else if (!strcmp(q, "Strands"))                                                                \
      lp.strands = (int)x, is_l = 1;                                                               \
    else if (!strcmp(q, "Jitter"))                                                                 \
      lp.jitter = x, is_l = 1;                                                                     \
    else if (!strcmp(q, "Seed"))                                                                   \
      lp.seed = cp.seed = (int)x, is_l = is_c = 1;                                                 \
    else if (!strcmp(q, "FlickerRate"))                                                            \
      lp.flicker_rate = x, is_l = 1;                                                               \
    else if (!strcmp(q, "Cover"))                                                                  \
      cp.cover = x, is_c = 1;                                                                      \
    else if (!strcmp(q, "Scale"))                                                                  \
      cp.scale = x, is_c = 1;                                                                      \
    else if (!strcmp(q, "Sharpness"))                                                              \
      cp.sharpness = x, is_c = 1;                                                                  \
    else if (!strcmp(q, "WindSpeed"))                                                              \
      cp.wind_speed = x, is_c = 1;                                                                 \
    else if (!strcmp(q, "WindDirection"))                                                          \
      cp.wind_direction = x, is_c = 1;                                                             \
    else if (!strcmp(q, "Resolution"))                                                             \
      cp.resolution = (int)x, is_c = 1;                                                            \
    else if (!strcmp(q, "Size"))                                                                   \
      cp.size = x, is_c = 1;                                                                       \
  } while (0)
#define VALID()                                                                                    \
  ((!is_l || gr_lightning_params_validate(&lp, msg, sizeof(msg)) == GR_OK) &&                      \
   (!is_c || gr_cloud_cover_params_validate(&cp, msg, sizeof(msg)) == GR_OK))
    SET(b[r].default_value);
    CHECK_MSG(is_l || is_c, "row %s belongs to no source", b[r].property);
    CHECK_MSG(VALID(), "%s default", b[r].property);
    SET(b[r].max);
    CHECK_MSG(VALID(), "%s max", b[r].property);
    SET(b[r].min);
    CHECK_MSG(VALID() == !b[r].min_open, "%s min", b[r].property);
    if (!(b[r].integer && b[r].max >= INT_MAX)) {
      SET(b[r].integer ? b[r].max + 1 : b[r].max * 1.001 + 1e-9);
      CHECK_MSG(!VALID() && strstr(msg, b[r].property), "%s above max", b[r].property);
    }
#undef SET
#undef VALID
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

/* For valgrind (memcheck.sky): a bolt, a small cloud image whole and by
 * rows, a refused change of parameters. */
static void test_memcheck(void) {
  gr_lightning_params lp;
  gr_lightning_params_init(&lp);
  long n = gr_lightning_point_count(&lp);
  double *xyz = malloc((size_t)n * 3 * sizeof(double));
  float *intensity = malloc((size_t)n * sizeof(float));
  int *strand = malloc((size_t)n * sizeof(int));
  char msg[256];
  CHECK(gr_lightning_generate(&lp, xyz, intensity, strand, msg, sizeof(msg)) == GR_OK);
  free(xyz), free(intensity), free(strand);
  gr_cloud_cover_params cp;
  gr_cloud_cover_params_init(&cp);
  cp.resolution = 16;
  gr_cloud_cover *c = NULL;
  CHECK(gr_cloud_cover_create(ctx, &cp, &c) == GR_OK);
  if (!c)
    return;
  float cloud[256];
  unsigned char rgb[3 * 256];
  CHECK(gr_cloud_cover_compute(c, 2.0) == GR_OK);
  CHECK(gr_cloud_cover_compute_rows(c, 3.0, 4, 4) == GR_OK);
  CHECK(gr_cloud_cover_get(c, cloud, rgb) == GR_OK);
  cp.cover = 2.0;
  CHECK(gr_cloud_cover_set_params(c, &cp) != GR_OK);
  CHECK(gr_cloud_cover_last_error(c)[0] != '\0');
  gr_cloud_cover_destroy(c);
}

static const gr_subtest tests[] = {
    {"lightning_determinism", test_lightning_determinism, 0},
    {"lightning_counts", test_lightning_counts, 0},
    {"lightning_ends", test_lightning_ends, 0},
    {"lightning_branches", test_lightning_branches, 0},
    {"lightning_spread", test_lightning_spread, 0},
    {"lightning_strike", test_lightning_strike, 0},
    {"lightning_flicker", test_lightning_flicker, 0},
    {"lightning_errors", test_lightning_errors, 0},
    {"cloud_fraction", test_cloud_fraction, 0},
    {"cloud_determinism", test_cloud_determinism, 0},
    {"cloud_drift", test_cloud_drift, 0},
    {"cloud_errors", test_cloud_errors, 0},
    {"param_table", test_param_table, 0},
    {"memcheck", test_memcheck, 1},
};

int main(int argc, char **argv) {
  return gr_test_main(argc, argv, tests, (int)(sizeof(tests) / sizeof(tests[0])), setup, teardown);
}
