/* Terrain analysis tests: planes of known slope and aspect (slope and aspect
 * within 1e-3 degrees, unit normals), a flat field (normal exactly (0, 0, 1),
 * aspect -1, hillshade sin E, no shadow), hillshade against the Lambert and
 * ESRI formulas, the snow cover n_z^k and the cover classes on planes just
 * below and above RockSlope and across WaterLevel, a spike's shadow of
 * length h / tan E along the anti-sun azimuth and nowhere else, the soft
 * edge (monotone along the shadow and in the sun's elevation), shadows of
 * planes agreeing with their hillshade, ModelShadows, determinism, and the
 * error paths. */
#include "graupel/terrain_analysis.h"
#include "gr_test.h"

#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
#define RAD (PI / 180.0)

static gr_context *ctx;

/* One analysis run: outputs requested by non-NULL pointers. */
typedef struct result {
  float *normal, *slope, *aspect, *hillshade, *snow_cover, *shadow;
  unsigned char *cover_class;
} result;

static void result_free(result *r) {
  free(r->normal);
  free(r->slope);
  free(r->aspect);
  free(r->hillshade);
  free(r->snow_cover);
  free(r->shadow);
  free(r->cover_class);
  memset(r, 0, sizeof(*r));
}

/* Everything for heights h on grid g with parameters p; 0 on failure. */
static int run(const gr_grid *g, const gr_terrain_analysis_params *p, const float *h, result *r) {
  memset(r, 0, sizeof(*r));
  size_t n = (size_t)g->nx * (size_t)g->ny;
  gr_terrain_analysis *t = NULL;
  gr_status st = gr_terrain_analysis_create(ctx, g, p, &t);
  CHECK_MSG(st == GR_OK, "%s", gr_terrain_analysis_last_error(NULL));
  if (st != GR_OK)
    return 0;
  st = gr_terrain_analysis_set_heights(t, h);
  if (st == GR_OK)
    st = gr_terrain_analysis_compute_shadow(t);
  if (st == GR_OK)
    st = gr_terrain_analysis_compute(t);
  r->normal = malloc(3 * n * sizeof(float));
  r->slope = malloc(n * sizeof(float));
  r->aspect = malloc(n * sizeof(float));
  r->hillshade = malloc(n * sizeof(float));
  r->snow_cover = malloc(n * sizeof(float));
  r->shadow = malloc(n * sizeof(float));
  r->cover_class = malloc(n);
  float *f[] = {r->normal, r->slope, r->aspect, r->hillshade, r->snow_cover, r->shadow};
  gr_terrain_output o[] = {GR_TERRAIN_NORMAL,    GR_TERRAIN_SLOPE,      GR_TERRAIN_ASPECT,
                           GR_TERRAIN_HILLSHADE, GR_TERRAIN_SNOW_COVER, GR_TERRAIN_SHADOW};
  for (int k = 0; st == GR_OK && k < 6; ++k)
    st = gr_terrain_analysis_get_output(t, o[k], f[k]);
  if (st == GR_OK)
    st = gr_terrain_analysis_get_cover_class(t, r->cover_class);
  CHECK_MSG(st == GR_OK, "%s", gr_terrain_analysis_last_error(t));
  gr_terrain_analysis_destroy(t);
  if (st != GR_OK)
    result_free(r);
  return st == GR_OK;
}

/* h = a x + b y + c on grid g. */
static float *plane(const gr_grid *g, double a, double b, double c) {
  float *h = malloc(sizeof(float) * (size_t)g->nx * (size_t)g->ny);
  for (int j = 0; j < g->ny; ++j)
    for (int i = 0; i < g->nx; ++i)
      h[j * g->nx + i] = (float)(a * (g->x0 + i * g->dx) + b * (g->y0 + j * g->dy) + c);
  return h;
}

/* A plane of slope s degrees whose downslope points to bearing asp. */
static float *tilted(const gr_grid *g, double s, double asp, double c) {
  double m = tan(s * RAD);
  return plane(g, -m * sin(asp * RAD), -m * cos(asp * RAD), c);
}

static double angle_diff(double a, double b) {
  double d = fmod(fabs(a - b), 360.0);
  return d > 180.0 ? 360.0 - d : d;
}

/* ------------------------------------------------------------------ tests */

static void test_planes(void) {
  /* Unequal spacing, and every point including the edges: one-sided
   * differences are exact on a plane too. */
  gr_grid g = {23, 17, 2.0, 1.5, -10.0, 30.0};
  static const double cases[][2] = {{10, 0},  {10, 90}, {25, 180}, {25, 270}, {35, 135},
                                    {5, 300}, {60, 45}, {80, 200}, {1, 10}};
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  for (size_t c = 0; c < sizeof(cases) / sizeof(cases[0]); ++c) {
    double s = cases[c][0], asp = cases[c][1];
    /* Heights near 0 m: float32's step there keeps even a 1-degree
     * plane's aspect within 1e-4 degrees. */
    float *h = tilted(&g, s, asp, 0.0);
    result r;
    if (!run(&g, &p, h, &r)) {
      free(h);
      return;
    }
    double m = tan(s * RAD), gx = -m * sin(asp * RAD), gy = -m * cos(asp * RAD);
    double len = sqrt(gx * gx + gy * gy + 1.0);
    double ws = 0, wa = 0, wn = 0, wu = 0;
    for (int k = 0; k < g.nx * g.ny; ++k) {
      ws = fmax(ws, fabs(r.slope[k] - s));
      wa = fmax(wa, angle_diff(r.aspect[k], asp));
      const float *n = r.normal + 3 * k;
      wn = fmax(wn, fabs(n[0] + gx / len) + fabs(n[1] + gy / len) + fabs(n[2] - 1.0 / len));
      wu = fmax(wu,
                fabs(sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]) - 1.0));
    }
    CHECK_MSG(ws < 1e-3, "slope %g aspect %g: slope off by %.3g deg", s, asp, ws);
    CHECK_MSG(wa < 1e-3, "slope %g aspect %g: aspect off by %.3g deg", s, asp, wa);
    CHECK_MSG(wn < 3e-6, "slope %g aspect %g: normal off by %.3g", s, asp, wn);
    CHECK_MSG(wu < 1e-6, "slope %g aspect %g: |normal| - 1 = %.3g", s, asp, wu);
    result_free(&r);
    free(h);
  }
}

static void test_flat(void) {
  gr_grid g = {31, 19, 3.0, 2.0, 0.0, 0.0};
  float *h = plane(&g, 0, 0, 123.5);
  static const double elevations[] = {1.0, 10.0, 45.0, 80.0, 90.0};
  for (int e = 0; e < 5; ++e)
    for (int soft = 0; soft < 2; ++soft) {
      gr_terrain_analysis_params p;
      gr_terrain_analysis_params_init(&p);
      p.sun_elevation = elevations[e];
      p.sun_azimuth = 37.0 * e;
      p.penumbra_width = soft ? 0.5 : 0.0;
      p.model_shadows = 1;
      result r;
      if (!run(&g, &p, h, &r))
        break;
      int bad_normal = 0, bad_slope = 0, bad_aspect = 0, bad_shade = 0, bad_shadow = 0;
      int bad_cover = 0;
      float want = (float)sin(p.sun_elevation * RAD);
      for (int k = 0; k < g.nx * g.ny; ++k) {
        const float *n = r.normal + 3 * k;
        /* Exactly (0, 0, 1), and +0 rather than -0. */
        bad_normal +=
            !(n[0] == 0.0f && n[1] == 0.0f && n[2] == 1.0f && !signbit(n[0]) && !signbit(n[1]));
        bad_slope += r.slope[k] != 0.0f;
        bad_aspect += r.aspect[k] != -1.0f;
        bad_shade += fabsf(r.hillshade[k] - want) > 1e-6f;
        bad_shadow += r.shadow[k] != 1.0f;
        bad_cover += r.snow_cover[k] != 1.0f || r.cover_class[k] != GR_COVER_SNOW;
      }
      CHECK_MSG(bad_normal == 0, "E %g: %d normals are not (0, 0, 1)", p.sun_elevation, bad_normal);
      CHECK_MSG(bad_slope + bad_aspect == 0, "E %g: %d slopes, %d aspects", p.sun_elevation,
                bad_slope, bad_aspect);
      CHECK_MSG(bad_shade == 0, "E %g: %d hillshades differ from sin E = %.7g", p.sun_elevation,
                bad_shade, want);
      CHECK_MSG(bad_shadow == 0, "E %g soft %d: %d shadowed points on flat ground", p.sun_elevation,
                soft, bad_shadow);
      CHECK_MSG(bad_cover == 0, "E %g: %d points not fully snow", p.sun_elevation, bad_cover);
      result_free(&r);
    }
  free(h);
}

static void test_hillshade(void) {
  gr_grid g = {12, 10, 1.0, 1.0, 0.0, 0.0};
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  p.sun_azimuth = 120.0;
  p.sun_elevation = 35.0;
  static const double cases[][2] = {{55, 120}, {20, 300}, {30, 80}, {70, 300}, {40, 0}};
  for (int c = 0; c < 5; ++c) {
    double s = cases[c][0], asp = cases[c][1];
    float *h = tilted(&g, s, asp, 0.0);
    result r;
    if (!run(&g, &p, h, &r)) {
      free(h);
      return;
    }
    /* ESRI's formula: cos Z cos S + sin Z sin S cos(Az - aspect), at 0 below. */
    double z = (90.0 - p.sun_elevation) * RAD;
    double esri = cos(z) * cos(s * RAD) + sin(z) * sin(s * RAD) * cos((p.sun_azimuth - asp) * RAD);
    esri = esri < 0 ? 0 : esri;
    double worst = 0;
    for (int k = 0; k < g.nx * g.ny; ++k)
      worst = fmax(worst, fabs(r.hillshade[k] - esri));
    CHECK_MSG(worst < 2e-6, "slope %g aspect %g: hillshade off ESRI's %.7g by %.3g", s, asp, esri,
              worst);
    result_free(&r);
    free(h);
  }
  /* A plane facing the sun squarely (slope 90 - E towards it) is fully lit. */
  float *h = tilted(&g, 90.0 - p.sun_elevation, p.sun_azimuth, 0.0);
  result r;
  if (run(&g, &p, h, &r)) {
    CHECK_NEAR(r.hillshade[5 * g.nx + 5], 1.0, 2e-6);
    result_free(&r);
  }
  free(h);
}

static void test_cover(void) {
  gr_grid g = {9, 8, 1.0, 1.0, 0.0, 0.0};
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  p.water_level = -1e4;
  /* snow_cover = n_z^k = cos(slope)^k; the seed's 45-degree plane has (sqrt 2 / 2)^k. */
  static const double slopes[] = {0, 30, 45, 60};
  static const double ks[] = {1, 4, 9.5};
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 3; ++b) {
      p.snow_exponent = ks[b];
      float *h = tilted(&g, slopes[a], 210.0, 5.0);
      result r;
      if (!run(&g, &p, h, &r)) {
        free(h);
        return;
      }
      double want = pow(cos(slopes[a] * RAD), ks[b]);
      CHECK_MSG(fabs(r.snow_cover[20] - want) < 2e-6 * (1 + ks[b]), "slope %g k %g: %.7g vs %.7g",
                slopes[a], ks[b], r.snow_cover[20], want);
      result_free(&r);
      free(h);
    }

  /* Just below and just above RockSlope: snow, then rock; in threshold mode
   * the cover switches from 1 to 0 at the same slope. */
  static const double rocks[] = {45.0, 30.0, 62.5};
  for (int m = 0; m < 2; ++m)
    for (int q = 0; q < 3; ++q) {
      gr_terrain_analysis_params_init(&p);
      p.water_level = -1e4;
      p.cover_mode = m;
      p.snow_exponent = 1.0;
      p.snow_cover_limit = 0.3;
      p.rock_slope = rocks[q];
      for (int side = -1; side <= 1; side += 2) {
        float *h = tilted(&g, p.rock_slope + side * 0.01, 75.0, 0.0);
        result r;
        if (!run(&g, &p, h, &r)) {
          free(h);
          return;
        }
        int want = side < 0 ? GR_COVER_SNOW : GR_COVER_ROCK, wrong = 0, wrong_cover = 0;
        for (int k = 0; k < g.nx * g.ny; ++k) {
          wrong += r.cover_class[k] != want;
          if (m == 1)
            wrong_cover += r.snow_cover[k] != (side < 0 ? 1.0f : 0.0f);
        }
        CHECK_MSG(wrong == 0 && wrong_cover == 0,
                  "mode %d RockSlope %g%+.2f: %d classes not %d, %d covers wrong", m, p.rock_slope,
                  side * 0.01, wrong, want, wrong_cover);
        result_free(&r);
        free(h);
      }
    }

  /* Ground: below RockSlope but too steep for the smooth cover to reach
   * SnowCoverLimit (cos 40^4 = 0.344 < 0.5). */
  gr_terrain_analysis_params_init(&p);
  p.water_level = -1e4;
  float *h = tilted(&g, 40.0, 0.0, 0.0);
  result r;
  if (run(&g, &p, h, &r)) {
    int wrong = 0;
    for (int k = 0; k < g.nx * g.ny; ++k)
      wrong += r.cover_class[k] != GR_COVER_GROUND;
    CHECK_MSG(wrong == 0, "%d points of a 40-degree plane are not ground", wrong);
    result_free(&r);
  }
  free(h);

  /* Ice below WaterLevel, whatever the slope: a plane from -4 m to 12 m
   * across x, 2 m per point (63.4 degrees, rock above the water). */
  gr_terrain_analysis_params_init(&p);
  p.water_level = 0.5;
  h = plane(&g, 2.0, 0.0, -4.0);
  if (run(&g, &p, h, &r)) {
    int wrong = 0;
    for (int k = 0; k < g.nx * g.ny; ++k) {
      int want = h[k] < 0.5f ? GR_COVER_ICE : GR_COVER_ROCK;
      wrong += r.cover_class[k] != want;
    }
    CHECK_MSG(wrong == 0, "%d points misclassed across WaterLevel", wrong);
    result_free(&r);
  }
  free(h);
}

/* Shadow of a spike of height H at (ci, cj) on flat ground of spacing d. */
#define SN 64
static void spike_shadow(double azimuth, double elevation, double d, double penumbra,
                         float *shadow) {
  gr_grid g = {SN, SN, d, d, 0.0, 0.0};
  float *h = plane(&g, 0, 0, 2.0);
  h[32 * SN + 32] += 10.0f;
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  p.sun_azimuth = azimuth;
  p.sun_elevation = elevation;
  p.penumbra_width = penumbra;
  gr_terrain_analysis *t = NULL;
  gr_status st = gr_terrain_analysis_create(ctx, &g, &p, &t);
  if (st == GR_OK)
    st = gr_terrain_analysis_set_heights(t, h);
  if (st == GR_OK)
    st = gr_terrain_analysis_compute_shadow(t);
  if (st == GR_OK)
    st = gr_terrain_analysis_get_output(t, GR_TERRAIN_SHADOW, shadow);
  CHECK_MSG(st == GR_OK, "%s", gr_terrain_analysis_last_error(t));
  gr_terrain_analysis_destroy(t);
  free(h);
}

static void test_spike_shadow(void) {
  static float shadow[SN * SN];
  static const double azimuths[] = {0, 90, 180, 270, 45, 225};
  static const double elevations[] = {30, 60, 20};
  static const double spacings[] = {1.0, 0.5, 1.0};
  for (int e = 0; e < 3; ++e)
    for (int a = 0; a < 6; ++a) {
      double az = azimuths[a], el = elevations[e], d = spacings[e];
      spike_shadow(az, el, d, 0.0, shadow);
      /* The shadow runs away from the sun: unit steps (di, dj) of the grid
       * along the anti-sun bearing. */
      int di = (int)lround(-sin(az * RAD) * (fmod(az, 90.0) == 0 ? 1 : sqrt(2.0)));
      int dj = (int)lround(-cos(az * RAD) * (fmod(az, 90.0) == 0 ? 1 : sqrt(2.0)));
      double cell = d * sqrt((double)(di * di + dj * dj));
      double length = 10.0 / tan(el * RAD);
      int farthest = 0, on_line = 0, elsewhere = 0;
      for (int j = 0; j < SN; ++j)
        for (int i = 0; i < SN; ++i) {
          if (shadow[j * SN + i] == 1.0f)
            continue;
          int r = di ? (i - 32) / di : (j - 32) / dj;
          if (r > 0 && i == 32 + r * di && j == 32 + r * dj) {
            ++on_line;
            farthest = r > farthest ? r : farthest;
          } else {
            ++elsewhere;
          }
        }
      double shadow_length = farthest * cell;
      CHECK_MSG(fabs(shadow_length - length) <= cell,
                "az %g E %g: shadow %.3f m long, h / tan E = %.3f m", az, el, shadow_length,
                length);
      /* Unbroken from the spike to its end, and nothing anywhere else. */
      CHECK_MSG(on_line == farthest && elsewhere == 0,
                "az %g E %g: %d shadowed points on the line of %d, %d elsewhere", az, el, on_line,
                farthest, elsewhere);
    }
}

static void test_soft_edge(void) {
  static float shadow[SN * SN], higher[SN * SN];
  const double el = 25.0, w = 6.0;
  spike_shadow(270.0, el, 1.0, w, shadow); /* sun in the west: shadow to the east */
  /* Along the shadow: non-decreasing away from the spike, fully dark where
   * even the penumbra's top is hidden, fully lit past the bottom's reach. */
  int monotone = 1, partial = 0, dark_ok = 1, lit_ok = 1;
  double dark_end = 10.0 / tan((el + w / 2) * RAD), lit_start = 10.0 / tan((el - w / 2) * RAD);
  for (int r = 1; 32 + r < SN; ++r) {
    float v = shadow[32 * SN + 32 + r];
    if (r > 1 && v < shadow[32 * SN + 31 + r])
      monotone = 0;
    partial += v > 0.0f && v < 1.0f;
    if (r < dark_end - 1e-3)
      dark_ok &= v == 0.0f;
    if (r > lit_start + 1e-3)
      lit_ok &= v == 1.0f;
    /* The lit part of the band: 0.5 + (E - H) / W with H = atan(10 / r). */
    double want = 0.5 + (el - atan(10.0 / r) / RAD) / w;
    want = want < 0 ? 0 : want > 1 ? 1 : want;
    CHECK_MSG(fabs(v - want) < 1e-4, "r %d: %.6f vs %.6f", r, v, want);
  }
  CHECK(monotone);
  CHECK_MSG(partial >= 3, "%d points in the penumbra", partial);
  CHECK(dark_ok && lit_ok);
  /* Off the line, fully lit. */
  int off = 0;
  for (int k = 0; k < SN * SN; ++k)
    off += k / SN != 32 && shadow[k] != 1.0f;
  CHECK_MSG(off == 0, "%d shadowed points off the line", off);
  /* A higher sun lights every point at least as much, and some more. */
  spike_shadow(270.0, el + 5.0, 1.0, w, higher);
  int darker = 0, lighter = 0;
  for (int k = 0; k < SN * SN; ++k) {
    darker += higher[k] < shadow[k];
    lighter += higher[k] > shadow[k];
  }
  CHECK_MSG(darker == 0 && lighter > 0, "%d darker, %d lighter under a higher sun", darker,
            lighter);
}

static void test_plane_shadows(void) {
  /* A plane rising towards the sun more steeply than the sun stands is in
   * its own shadow (hillshade 0 too); a gentler one is lit. The row nearest
   * the sun is lit (its rays leave the grid at once). */
  gr_grid g = {20, 16, 1.0, 1.0, 0.0, 0.0};
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  p.sun_azimuth = 0.0; /* north */
  p.sun_elevation = 30.0;
  p.model_shadows = 1;
  for (int steep = 0; steep < 2; ++steep) {
    /* Rising to the north = downslope to the south (aspect 180). */
    float *h = tilted(&g, steep ? 32.0 : 28.0, 180.0, 0.0);
    result r;
    if (!run(&g, &p, h, &r)) {
      free(h);
      return;
    }
    int wrong = 0, shade_wrong = 0;
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        int k = j * g.nx + i;
        float want = (steep && j < g.ny - 1) ? 0.0f : 1.0f;
        wrong += r.shadow[k] != want;
        if (j < g.ny - 1)
          shade_wrong += (r.hillshade[k] == 0.0f) != (steep != 0);
      }
    CHECK_MSG(wrong == 0 && shade_wrong == 0, "slope %s: %d shadows, %d hillshades wrong",
              steep ? "32" : "28", wrong, shade_wrong);
    result_free(&r);
    free(h);
  }
}

static void test_model_shadows(void) {
  /* hillshade with ModelShadows = hillshade without it x shadow, bit for
   * bit; and two runs agree bit for bit. */
  gr_grid g = {48, 40, 2.0, 2.0, 0.0, 0.0};
  float *h = malloc(sizeof(float) * 48 * 40);
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 48; ++i)
      h[j * 48 + i] = (float)(15.0 * sin(0.2 * i) * cos(0.13 * j) + 4.0 * sin(0.7 * (i + j)));
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  p.sun_elevation = 15.0;
  p.sun_azimuth = 200.0;
  p.penumbra_width = 2.0;
  result a, b, c;
  if (run(&g, &p, h, &a)) {
    p.model_shadows = 1;
    if (run(&g, &p, h, &b)) {
      int wrong = 0, shaded = 0, partial = 0;
      for (int k = 0; k < 48 * 40; ++k) {
        wrong += b.hillshade[k] != a.hillshade[k] * a.shadow[k];
        shaded += a.shadow[k] < 1.0f && a.hillshade[k] > 0.0f;
        partial += a.shadow[k] > 0.0f && a.shadow[k] < 1.0f;
      }
      CHECK_MSG(wrong == 0, "%d hillshades are not hillshade x shadow", wrong);
      CHECK_MSG(shaded > 20 && partial > 5, "a test terrain with cast shadows (%d, %d)", shaded,
                partial);
      if (run(&g, &p, h, &c)) {
        size_t n = 48 * 40;
        CHECK(memcmp(b.hillshade, c.hillshade, n * 4) == 0 &&
              memcmp(b.shadow, c.shadow, n * 4) == 0 &&
              memcmp(b.normal, c.normal, 3 * n * 4) == 0 &&
              memcmp(b.cover_class, c.cover_class, n) == 0);
        result_free(&c);
      }
      result_free(&b);
    }
    result_free(&a);
  }
  free(h);
}

static void test_bands(void) {
  /* A shadow computed band by band equals the whole, and counts as made
   * only once every row is. */
  gr_grid g = {40, 30, 1.0, 1.0, 0.0, 0.0};
  float *h = malloc(sizeof(float) * 40 * 30);
  for (int k = 0; k < 40 * 30; ++k)
    h[k] = (float)(6.0 * sin(0.3 * (k % 40)) + 3.0 * cos(0.5 * (k / 40)));
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  p.sun_elevation = 20.0;
  static float whole[40 * 30], banded[40 * 30];
  gr_terrain_analysis *t = NULL;
  CHECK(gr_terrain_analysis_create(ctx, &g, &p, &t) == GR_OK);
  CHECK(gr_terrain_analysis_set_heights(t, h) == GR_OK);
  CHECK(gr_terrain_analysis_compute_shadow(t) == GR_OK);
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_SHADOW, whole) == GR_OK);
  CHECK(gr_terrain_analysis_set_heights(t, h) == GR_OK);
  CHECK(gr_terrain_analysis_compute_shadow_rows(t, 0, 7) == GR_OK);
  CHECK(gr_terrain_analysis_compute_shadow_rows(t, 7, 20) == GR_OK);
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_SHADOW, banded) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_terrain_analysis_last_error(t), "shadow") != NULL);
  CHECK(gr_terrain_analysis_compute_shadow_rows(t, 27, 3) == GR_OK);
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_SHADOW, banded) == GR_OK);
  CHECK(memcmp(whole, banded, sizeof(whole)) == 0);
  CHECK(gr_terrain_analysis_compute_shadow_rows(t, 25, 6) == GR_ERR_INVALID_ARGUMENT);
  gr_terrain_analysis_destroy(t);
  free(h);
}

static void test_errors(void) {
  char msg[256];
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  CHECK(gr_terrain_analysis_params_validate(&p, msg, sizeof(msg)) == GR_OK);
  p.sun_elevation = 0.0;
  CHECK(gr_terrain_analysis_params_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "SunElevation") && strstr(msg, "deg") && msg[strlen(msg) - 1] == '.', "%s",
            msg);
  gr_terrain_analysis_params_init(&p);
  p.snow_exponent = NAN;
  CHECK(gr_terrain_analysis_params_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "SnowExponent") != NULL, "%s", msg);
  gr_terrain_analysis_params_init(&p);
  p.cover_mode = 2;
  CHECK(gr_terrain_analysis_params_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "CoverMode") && strstr(msg, "whole number"), "%s", msg);
  CHECK(gr_terrain_analysis_params_validate(NULL, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);

  gr_terrain_analysis_params_init(&p);
  gr_grid g = {6, 5, 1.0, 1.0, 0.0, 0.0};
  gr_terrain_analysis *t = NULL;
  gr_grid piece = g;
  piece.global_nx = 12;
  CHECK(gr_terrain_analysis_create(ctx, &piece, &p, &t) == GR_ERR_INVALID_ARGUMENT && !t);
  CHECK(strstr(gr_terrain_analysis_last_error(NULL), "whole grid") != NULL);
  gr_grid bad = g;
  bad.dx = 0.0;
  CHECK(gr_terrain_analysis_create(ctx, &bad, &p, &t) == GR_ERR_INVALID_ARGUMENT && !t);
  p.rock_slope = 91.0;
  CHECK(gr_terrain_analysis_create(ctx, &g, &p, &t) == GR_ERR_INVALID_ARGUMENT && !t);
  CHECK(strstr(gr_terrain_analysis_last_error(NULL), "RockSlope") != NULL);
  gr_terrain_analysis_params_init(&p);
  CHECK(gr_terrain_analysis_create(NULL, &g, &p, &t) == GR_ERR_INVALID_ARGUMENT);

  CHECK(gr_terrain_analysis_create(ctx, &g, &p, &t) == GR_OK);
  if (!t)
    return;
  float h[30], out[90];
  unsigned char cls[30];
  for (int k = 0; k < 30; ++k)
    h[k] = (float)k;
  /* Nothing to read before heights and a compute. */
  CHECK(gr_terrain_analysis_compute(t) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_terrain_analysis_last_error(t), "heights") != NULL);
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_SLOPE, out) == GR_ERR_INVALID_ARGUMENT);
  /* A NaN is named with its point. */
  h[13] = NAN;
  CHECK(gr_terrain_analysis_set_heights(t, h) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(gr_terrain_analysis_last_error(t), "NaN at point (1, 2)") != NULL, "%s",
            gr_terrain_analysis_last_error(t));
  h[13] = INFINITY;
  CHECK(gr_terrain_analysis_set_heights(t, h) == GR_ERR_INVALID_ARGUMENT);
  h[13] = 13.0f;
  CHECK(gr_terrain_analysis_set_heights(t, h) == GR_OK);
  CHECK(gr_terrain_analysis_compute(t) == GR_OK);
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_SLOPE, out) == GR_OK);
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_NORMAL, out) == GR_OK);
  CHECK(gr_terrain_analysis_get_cover_class(t, cls) == GR_OK);
  /* The shadow was not asked for (ModelShadows off). */
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_SHADOW, out) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_COVER_CLASS, out) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_OUTPUT_COUNT, out) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_SLOPE, NULL) == GR_ERR_INVALID_ARGUMENT);
  /* New parameters: refused ones keep the old; accepted ones need a compute. */
  p.penumbra_width = 25.0;
  CHECK(gr_terrain_analysis_set_params(t, &p) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_terrain_analysis_last_error(t), "PenumbraWidth") != NULL);
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_SLOPE, out) == GR_OK);
  p.penumbra_width = 1.0;
  CHECK(gr_terrain_analysis_set_params(t, &p) == GR_OK);
  CHECK(gr_terrain_analysis_get_output(t, GR_TERRAIN_SLOPE, out) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_terrain_analysis_compute_shadow(NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_terrain_analysis_compute(NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_terrain_analysis_set_heights(NULL, h) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strcmp(gr_terrain_output_name(GR_TERRAIN_COVER_CLASS), "cover_class") == 0);
  CHECK(gr_terrain_output_name(GR_TERRAIN_OUTPUT_COUNT) == NULL);
  gr_terrain_analysis_destroy(t);
  gr_terrain_analysis_destroy(NULL);
}

static void test_param_table(void) {
  int n = 0;
  const gr_param_bound *b = gr_terrain_analysis_param_bounds(&n);
  CHECK(n == 9);
  gr_terrain_analysis_params p, d;
  gr_terrain_analysis_params_init(&d);
  /* The defaults are the table's, and each row's ends are accepted or
   * refused as the table says. */
  double *fields[] = {&d.sun_azimuth,      &d.sun_elevation, &d.snow_exponent, NULL,
                      &d.snow_cover_limit, &d.rock_slope,    &d.water_level,   NULL,
                      &d.penumbra_width};
  for (int r = 0; r < n; ++r) {
    char msg[256];
    p = d;
    double def = fields[r] ? *fields[r] : (r == 3 ? d.cover_mode : d.model_shadows);
    CHECK_MSG(def == b[r].default_value, "%s default", b[r].property);
#define SET(v)                                                                                     \
  do {                                                                                             \
    p = d;                                                                                         \
    if (fields[r])                                                                                 \
      *(double *)((char *)&p + ((char *)fields[r] - (char *)&d)) = (v);                            \
    else if (r == 3)                                                                               \
      p.cover_mode = (int)(v);                                                                     \
    else                                                                                           \
      p.model_shadows = (int)(v);                                                                  \
  } while (0)
    SET(b[r].max);
    CHECK_MSG(gr_terrain_analysis_params_validate(&p, msg, sizeof(msg)) == GR_OK, "%s max",
              b[r].property);
    SET(b[r].min);
    CHECK_MSG((gr_terrain_analysis_params_validate(&p, msg, sizeof(msg)) == GR_OK) ==
                  !b[r].min_open,
              "%s min", b[r].property);
    SET(b[r].integer ? b[r].max + 1 : b[r].max * 1.001 + 1e-9);
    CHECK_MSG(gr_terrain_analysis_params_validate(&p, msg, sizeof(msg)) != GR_OK &&
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

/* For valgrind (memcheck.terrain_analysis): every host entry point once on a
 * tiny grid, and a refused call, so their allocations and frees are seen. */
static void test_memcheck(void) {
  gr_grid g = {6, 5, 1.0, 1.0, 0.0, 0.0, 0, 0};
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  gr_terrain_analysis *t = NULL;
  CHECK(gr_terrain_analysis_create(ctx, &g, &p, &t) == GR_OK);
  if (!t)
    return;
  float h[30], out[90];
  unsigned char cls[30];
  for (int k = 0; k < 30; ++k)
    h[k] = (float)(k % 6) * 0.5f + (float)(k / 6) * 0.2f;
  CHECK(gr_terrain_analysis_set_heights(t, h) == GR_OK);
  CHECK(gr_terrain_analysis_compute_shadow(t) == GR_OK);
  CHECK(gr_terrain_analysis_compute_shadow_rows(t, 1, 2) == GR_OK);
  CHECK(gr_terrain_analysis_compute(t) == GR_OK);
  for (int o = 0; o < GR_TERRAIN_OUTPUT_COUNT; ++o) /* cover_class is bytes */
    CHECK((gr_terrain_analysis_get_output(t, (gr_terrain_output)o, out) == GR_OK) ==
          (o != GR_TERRAIN_COVER_CLASS));
  CHECK(gr_terrain_analysis_get_cover_class(t, cls) == GR_OK);
  p.sun_elevation = 0.0;
  CHECK(gr_terrain_analysis_set_params(t, &p) != GR_OK);
  CHECK(gr_terrain_analysis_last_error(t)[0] != '\0');
  gr_terrain_analysis_destroy(t);
}

static const gr_subtest tests[] = {
    {"planes", test_planes, 0},
    {"flat", test_flat, 0},
    {"hillshade", test_hillshade, 0},
    {"cover", test_cover, 0},
    {"spike_shadow", test_spike_shadow, 0},
    {"soft_edge", test_soft_edge, 0},
    {"plane_shadows", test_plane_shadows, 0},
    {"model_shadows", test_model_shadows, 0},
    {"bands", test_bands, 0},
    {"errors", test_errors, 0},
    {"param_table", test_param_table, 0},
    {"memcheck", test_memcheck, 1},
};

int main(int argc, char **argv) {
  return gr_test_main(argc, argv, tests, (int)(sizeof(tests) / sizeof(tests[0])), setup, teardown);
}
