/* Procedural terrain tests: an independent double-precision reference of the
 * documented noise (graupel/procedural_terrain.h), determinism, seeds, octave
 * energy, linear height scale, bounds, tiling by origin, inversion, every
 * device agreeing with the first, parameter errors, the parameter table
 * against the validator, per-generator errors on a shared context, and
 * set_params across kernel variants. `test_procedural_terrain memcheck` (what
 * valgrind runs) covers every host entry point and error path once on tiny
 * grids. */
#include "graupel/cl_runtime.h"
#include "graupel/procedural_terrain.h"
#include "gr_test.h"

#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ---- reference (the same definition as procedural_terrain.cl, in double) ---- */

static uint32_t ref_hash(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}
static uint32_t ref_hash3(int32_t a, int32_t b, uint32_t c) {
  uint32_t h = ref_hash((uint32_t)a * 0x9e3779b1U);
  h = ref_hash(h ^ ((uint32_t)b * 0x85ebca77U));
  return ref_hash(h ^ (c * 0xc2b2ae3dU));
}
static double ref_fade(double t) {
  return t * t * t * (t * (t * 6 - 15) + 10);
}
static double ref_corner(int64_t ix, int64_t iy, uint32_t seed, double fx, double fy) {
  double ang =
      (double)(ref_hash3((int32_t)ix, (int32_t)iy, seed) & 15U) * (3.14159265358979323846 / 8.0);
  return cos(ang) * fx + sin(ang) * fy;
}
static double ref_gradient(double x, double y, uint32_t seed) {
  double flx = floor(x), fly = floor(y);
  int64_t ix = (int64_t)flx, iy = (int64_t)fly;
  double fx = x - flx, fy = y - fly, u = ref_fade(fx), v = ref_fade(fy);
  double n00 = ref_corner(ix, iy, seed, fx, fy);
  double n10 = ref_corner(ix + 1, iy, seed, fx - 1, fy);
  double n01 = ref_corner(ix, iy + 1, seed, fx, fy - 1);
  double n11 = ref_corner(ix + 1, iy + 1, seed, fx - 1, fy - 1);
  double a = n00 + u * (n10 - n00), b = n01 + u * (n11 - n01);
  double n = (a + v * (b - a)) * sqrt(2.0);
  return n < -1 ? -1 : n > 1 ? 1 : n;
}
static double ref_elevation(const gr_procedural_terrain_params *p, double x, double y) {
  double f = p->frequency / 1000.0, m = 1.0, amp = 1.0, w = 1.0;
  double sum = 0, norm = 0;
  for (int o = 0; o < p->octaves; ++o) {
    /* The octave's shift off the world axes (graupel/procedural_terrain.h). */
    double sx = 0.25 + 0.6180339887498949 * o, sy = 0.25 + 0.4142135623730951 * o;
    double g = ref_gradient(x * f * m + (sx - floor(sx)), y * f * m + (sy - floor(sy)),
                            (uint32_t)p->seed + (uint32_t)o);
    if (p->type == GR_NOISE_RIDGED) {
      double s = p->offset - fabs(g);
      s = s * s * w;
      w = s * p->gain;
      w = w < 0 ? 0 : w > 1 ? 1 : w;
      sum += s * amp;
      norm += p->offset * p->offset * amp;
      amp *= pow(p->lacunarity, -p->h);
    } else {
      sum += (p->type == GR_NOISE_BILLOW ? 2 * fabs(g) - 1 : g) * amp;
      norm += amp;
      amp *= p->persistence;
    }
    m *= p->lacunarity;
  }
  double n = p->type == GR_NOISE_RIDGED ? sum / norm : 0.5 * (sum / norm + 1);
  if (p->type == GR_NOISE_RIDGED && p->invert)
    n = 1 - n;
  return p->height_scale * (n < 0 ? 0 : n > 1 ? 1 : n);
}

/* ---------------------------------------------------------------- helpers */

static gr_context *ctx;

static float *make(const gr_grid *g, const gr_procedural_terrain_params *p) {
  float *h = malloc(sizeof(float) * (size_t)g->nx * (size_t)g->ny);
  gr_status st = gr_procedural_terrain_generate(ctx, g, p, h);
  CHECK_MSG(st == GR_OK, "%s", gr_last_error(ctx));
  if (st != GR_OK) {
    free(h);
    return NULL;
  }
  return h;
}

static double variance(const float *h, int n) {
  double m = 0, v = 0;
  for (int i = 0; i < n; ++i)
    m += h[i];
  m /= n;
  for (int i = 0; i < n; ++i)
    v += (h[i] - m) * (h[i] - m);
  return v / n;
}

/* Mean squared 5-point Laplacian over the interior: high-frequency energy. */
static double laplacian_energy(const float *h, int nx, int ny) {
  double e = 0;
  for (int j = 1; j < ny - 1; ++j)
    for (int i = 1; i < nx - 1; ++i) {
      double l = h[j * nx + i - 1] + h[j * nx + i + 1] + h[(j - 1) * nx + i] + h[(j + 1) * nx + i] -
                 4.0 * h[j * nx + i];
      e += l * l;
    }
  return e / ((double)(nx - 2) * (ny - 2));
}

/* ------------------------------------------------------------------ tests */

static void test_reference(void) {
  gr_grid g = {48, 40, 7.0, 5.0, -123.0, 4567.0};
  for (int type = 0; type < 3; ++type)
    for (int inv = 0; inv < 2; ++inv) {
      gr_procedural_terrain_params p;
      gr_procedural_terrain_params_init(&p);
      p.type = (gr_noise_type)type;
      p.invert = inv;
      p.seed = 1234 + type;
      p.frequency = 9.0;
      p.lacunarity = 2.1;
      float *h = make(&g, &p);
      if (!h)
        return;
      double worst = 0;
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) {
          double r = ref_elevation(&p, g.x0 + i * g.dx, g.y0 + j * g.dy);
          double d = fabs(r - h[j * g.nx + i]);
          worst = d > worst ? d : worst;
        }
      /* float32 evaluation of the same formula: well under a millimetre
       * on a 120 m terrain. */
      CHECK_MSG(worst < 1e-4 * p.height_scale, "type %d invert %d: %.3g m", type, inv, worst);
      free(h);
    }
}

static void test_determinism_and_seeds(void) {
  gr_grid g = {200, 150, 2.0, 2.0, 0.0, 0.0};
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  float *a = make(&g, &p), *b = make(&g, &p);
  p.seed = 1;
  float *c = make(&g, &p);
  if (!a || !b || !c)
    return;
  int n = g.nx * g.ny;
  CHECK(memcmp(a, b, sizeof(float) * (size_t)n) == 0);
  double diff = 0;
  for (int i = 0; i < n; ++i)
    diff += (a[i] - c[i]) * (a[i] - c[i]);
  diff = sqrt(diff / n);
  /* Different seeds are unrelated fields: their RMS difference is of the
   * order of the fields' own spread. */
  CHECK_MSG(diff > 0.5 * sqrt(variance(a, n)), "rms diff %.3g", diff);
  free(a);
  free(b);
  free(c);
}

/* No seam on the world axes: every octave's lattice used to have a line at
 * x = 0 and y = 0, where gradient noise has half its spread, so all octaves
 * dipped together there (edge rows of a terrain at the origin averaged 36 m
 * against 52 m inside). Averaged over 64 seeds, the rows on the axes must be
 * as high as the interior's, within 5% (seed sets differ by up to 4%). */
static void test_no_axis_seam(void) {
  gr_grid g = {192, 192, 4.0, 4.0, 0.0, 0.0};
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  double axes = 0, inside = 0;
  long n_axes = 0, n_inside = 0;
  for (int seed = 0; seed < 64; ++seed) {
    p.seed = 100 + seed;
    float *h = make(&g, &p);
    if (!h)
      return;
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        double v = h[j * g.nx + i];
        if (i == 0 || j == 0) {
          axes += v;
          ++n_axes;
        } else if (i >= 16 && j >= 16 && i < g.nx - 16 && j < g.ny - 16) {
          inside += v;
          ++n_inside;
        }
      }
    free(h);
  }
  axes /= (double)n_axes;
  inside /= (double)n_inside;
  printf("mean over 64 seeds: %.2f m on the axes x = 0, y = 0; %.2f m inside\n", axes, inside);
  CHECK_MSG(fabs(axes - inside) < 0.05 * inside, "axes %.2f m, inside %.2f m", axes, inside);
}

static void test_octaves_energy(void) {
  gr_grid g = {256, 256, 2.0, 2.0, 0.0, 0.0};
  for (int type = 0; type < 3; ++type) {
    gr_procedural_terrain_params p;
    gr_procedural_terrain_params_init(&p);
    p.type = (gr_noise_type)type;
    p.octaves = 1;
    float *h1 = make(&g, &p);
    p.octaves = 6;
    float *h6 = make(&g, &p);
    if (!h1 || !h6)
      return;
    int n = g.nx * g.ny;
    double r1 = laplacian_energy(h1, g.nx, g.ny) / variance(h1, n);
    double r6 = laplacian_energy(h6, g.nx, g.ny) / variance(h6, n);
    CHECK_MSG(r6 > 4.0 * r1, "type %d: relative HF energy %.3g vs %.3g", type, r6, r1);
    free(h1);
    free(h6);
  }
}

static void test_height_scale_and_bounds(void) {
  gr_grid g = {128, 96, 3.0, 3.0, 50.0, -70.0};
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  float *a = make(&g, &p);
  p.height_scale = 30.0;
  float *b = make(&g, &p);
  if (!a || !b)
    return;
  int n = g.nx * g.ny;
  double worst = 0;
  for (int i = 0; i < n; ++i) {
    double d = fabs(b[i] - a[i] * 0.25);
    worst = d > worst ? d : worst;
  }
  CHECK_MSG(worst <= 1e-6 * 120.0, "HeightScale not linear: %.3g", worst);
  free(a);
  free(b);

  /* 0 <= elevation <= HeightScale for every type, extreme parameters too,
   * and the default terrain uses a good part of that range. */
  const double gains[] = {0.0, 2.0, 16.0}, offsets[] = {0.25, 1.0, 4.0};
  for (int type = 0; type < 3; ++type)
    for (int k = 0; k < 3; ++k) {
      gr_procedural_terrain_params q;
      gr_procedural_terrain_params_init(&q);
      q.type = (gr_noise_type)type;
      q.gain = gains[k];
      q.offset = offsets[k];
      q.persistence = k * 0.5;
      q.octaves = 1 + 5 * k;
      float *h = make(&g, &q);
      if (!h)
        return;
      float lo = h[0], hi = h[0];
      for (int i = 0; i < n; ++i) {
        lo = h[i] < lo ? h[i] : lo;
        hi = h[i] > hi ? h[i] : hi;
      }
      CHECK_MSG(lo >= 0.0f && hi <= (float)q.height_scale, "type %d k %d: [%g, %g]", type, k, lo,
                hi);
      if (k == 1)
        CHECK_MSG(hi - lo > 0.2 * q.height_scale, "type %d: range %g", type, hi - lo);
      free(h);
    }
}

static void test_tiling_and_inversion(void) {
  /* A grid whose origin is k cells further east is the same terrain shifted:
   * tiles (and MPI pieces) join without seams. */
  gr_grid g = {100, 80, 2.0, 2.0, 1000.0, 2000.0};
  gr_grid s = g;
  s.x0 += 30 * g.dx;
  s.y0 += 10 * g.dy;
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  float *a = make(&g, &p), *b = make(&s, &p);
  if (!a || !b)
    return;
  double worst = 0;
  for (int j = 0; j < g.ny - 10; ++j)
    for (int i = 0; i < g.nx - 30; ++i) {
      double d = fabs(a[(j + 10) * g.nx + i + 30] - b[j * g.nx + i]);
      worst = d > worst ? d : worst;
    }
  CHECK_MSG(worst < 1e-4 * p.height_scale, "tile seam %.3g m", worst);
  free(b);

  /* A piece of the grid (global index offset i0, j0, the whole grid's
   * origin) is bit for bit that part of the whole: MPI ranks agree. */
  gr_grid piece = g;
  piece.nx = 37;
  piece.ny = 21;
  piece.i0 = 30;
  piece.j0 = 10;
  b = make(&piece, &p);
  if (!b)
    return;
  int mismatched = 0;
  for (int j = 0; j < piece.ny; ++j)
    for (int i = 0; i < piece.nx; ++i)
      mismatched += b[j * piece.nx + i] != a[(j + 10) * g.nx + i + 30];
  CHECK_MSG(mismatched == 0, "%d piece values differ from the whole", mismatched);
  free(b);

  /* Inverted ridged is exactly HeightScale minus the plain ridged field. */
  p.invert = 0;
  b = make(&g, &p);
  if (!b)
    return;
  worst = 0;
  for (int i = 0; i < g.nx * g.ny; ++i) {
    double d = fabs((double)a[i] + (double)b[i] - p.height_scale);
    worst = d > worst ? d : worst;
  }
  CHECK_MSG(worst < 1e-5 * p.height_scale, "inversion %.3g", worst);
  free(a);
  free(b);

  /* Far from the origin the terrain is as detailed as near it. */
  gr_grid far = {64, 64, 2.0, 2.0, 3.0e6, -2.0e6};
  float *h = make(&far, &p);
  if (!h)
    return;
  double worst_ref = 0;
  for (int j = 0; j < far.ny; j += 7)
    for (int i = 0; i < far.nx; i += 5) {
      double r = ref_elevation(&p, far.x0 + i * far.dx, far.y0 + j * far.dy);
      double d = fabs(r - h[j * far.nx + i]);
      worst_ref = d > worst_ref ? d : worst_ref;
    }
  CHECK_MSG(worst_ref < 1e-3 * p.height_scale, "far tile %.3g m", worst_ref);
  free(h);
}

static void test_devices_agree(void) {
  int count = 0;
  gr_device_info infos[8];
  if (gr_device_list(infos, 8, &count) != GR_OK || count < 2) {
    printf("one OpenCL device: cross-device agreement not tested here\n");
    return;
  }
  gr_grid g = {300, 200, 2.0, 2.0, -500.0, 800.0};
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  float *first = NULL;
  for (int d = 0; d < count && d < 8; ++d) {
    gr_context_options opt;
    gr_context_options_init(&opt);
    opt.device = infos[d].name;
    gr_context *c = NULL;
    CHECK(gr_context_create(&opt, &c) == GR_OK);
    float *h = malloc(sizeof(float) * 300 * 200);
    CHECK(gr_procedural_terrain_generate(c, &g, &p, h) == GR_OK);
    if (!first) {
      first = h;
    } else {
      double worst = 0;
      for (int i = 0; i < 300 * 200; ++i) {
        double r = fabs((double)h[i] - first[i]) / p.height_scale;
        worst = r > worst ? r : worst;
      }
      printf("%s vs %s: max difference %.3g of HeightScale\n", infos[d].name, infos[0].name, worst);
      CHECK_MSG(worst <= 1e-5, "%s disagrees: %.3g", infos[d].name, worst);
      free(h);
    }
    gr_context_release(c);
  }
  free(first);
}

static void test_errors(void) {
  char msg[256];
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  CHECK(gr_procedural_terrain_params_validate(&p, msg, sizeof(msg)) == GR_OK);
  /* Each out-of-range parameter is refused with its name in the sentence. */
  gr_procedural_terrain_params q;
#define BAD(field, value, word)                                                                    \
  do {                                                                                             \
    q = p;                                                                                         \
    q.field = value;                                                                               \
    CHECK(gr_procedural_terrain_params_validate(&q, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT); \
    CHECK_MSG(strstr(msg, word) != NULL, "'%s' lacks '%s'", msg, word);                            \
  } while (0)
  BAD(octaves, 0, "Octaves");
  BAD(octaves, 17, "Octaves");
  BAD(frequency, 0.0, "Frequency");
  BAD(frequency, NAN, "Frequency");
  BAD(lacunarity, 0.5, "Lacunarity");
  BAD(persistence, 1.5, "Persistence");
  BAD(offset, -1.0, "Offset");
  BAD(offset, 0.0, "Offset");
  BAD(gain, INFINITY, "Gain");
  BAD(h, -0.1, "H");
  BAD(height_scale, -1.0, "HeightScale");
  BAD(type, (gr_noise_type)7, "NoiseType");
#undef BAD

  gr_grid g = {16, 16, 1.0, 1.0, 0.0, 0.0};
  gr_procedural_terrain *t = NULL;
  q = p;
  q.octaves = 0;
  CHECK(gr_procedural_terrain_create(ctx, &g, &q, &t) == GR_ERR_INVALID_ARGUMENT);
  CHECK(t == NULL && strstr(gr_last_error(ctx), "Octaves") != NULL);
  g.dy = -1.0;
  CHECK(gr_procedural_terrain_create(ctx, &g, &p, &t) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_last_error(ctx), "spacing") != NULL);
  g.dy = 1.0;
  g.x0 = 1e14; /* lattice coordinates would overflow */
  CHECK(gr_procedural_terrain_create(ctx, &g, &p, &t) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_last_error(ctx), "Origin") != NULL);
  g.x0 = 0.0;

  /* set_params refuses bad values and keeps the generator working. */
  CHECK(gr_procedural_terrain_create(ctx, &g, &p, &t) == GR_OK);
  float before[256], after[256];
  CHECK(gr_procedural_terrain_compute(t) == GR_OK);
  CHECK(gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, before) == GR_OK);
  CHECK(gr_procedural_terrain_set_params(t, &q) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_procedural_terrain_compute(t) == GR_OK);
  CHECK(gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, after) == GR_OK);
  CHECK(memcmp(before, after, sizeof(before)) == 0);
  q = p;
  q.seed = 99;
  CHECK(gr_procedural_terrain_set_params(t, &q) == GR_OK);
  CHECK(gr_procedural_terrain_compute(t) == GR_OK);
  CHECK(gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, after) == GR_OK);
  CHECK(memcmp(before, after, sizeof(before)) != 0);
  CHECK(gr_procedural_terrain_get_field(t, GR_FIELD_SNOW_DEPTH, after) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_last_error(ctx), "snow_depth") != NULL);
  gr_procedural_terrain_destroy(t);
  gr_procedural_terrain_destroy(NULL);

  /* A grid whose elevation buffer exceeds the device's largest allocation
   * (or the memory there is) is refused before anything is allocated, with
   * the limit in the sentence (memory.h). */
  gr_grid huge;
  if (gr_test_grid_beyond_device(ctx, &huge)) {
    t = NULL;
    CHECK(gr_procedural_terrain_create(ctx, &huge, &p, &t) == GR_ERR_TOO_LARGE);
    CHECK_MSG(t == NULL && (strstr(gr_last_error(ctx), "allows at most") ||
                            strstr(gr_last_error(ctx), "can use")),
              "'%s'", gr_last_error(ctx));
  } else {
    printf("the device allows buffers beyond the grid limit: too-large case not reachable\n");
  }
}

static void test_bands(void) {
  /* Computing band by band (as the VTK filter does, for progress and abort)
   * gives exactly the whole-grid result; bands outside the grid are refused. */
  gr_grid g = {70, 53, 2.0, 2.0, 10.0, 20.0, 0, 0};
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  float *whole = make(&g, &p);
  gr_procedural_terrain *t = NULL;
  CHECK(gr_procedural_terrain_create(ctx, &g, &p, &t) == GR_OK);
  if (!whole || !t)
    return;
  float *banded = calloc((size_t)g.nx * g.ny, sizeof(float));
  for (int row = 0; row < g.ny; row += 17)
    CHECK(gr_procedural_terrain_compute_rows(t, row, row + 17 <= g.ny ? 17 : g.ny - row) == GR_OK);
  CHECK(gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, banded) == GR_OK);
  CHECK(memcmp(whole, banded, sizeof(float) * (size_t)g.nx * g.ny) == 0);
  CHECK(gr_procedural_terrain_compute_rows(t, 50, 4) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_procedural_terrain_compute_rows(t, -1, 4) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_procedural_terrain_compute_rows(t, 0, 0) == GR_OK);
  gr_procedural_terrain_destroy(t);
  free(banded);
  free(whole);
}

static void test_build_failure(void) {
  /* A program that fails to build (here: bad options from GRAUPEL_CL_OPTIONS)
   * gives GR_ERR_BUILD and a sentence; once fixed, the next create works. */
  gr_grid g = {8, 8, 1.0, 1.0, 0.0, 0.0, 0, 0};
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  p.octaves = 5; /* a variant not built yet in this context */
  gr_procedural_terrain *t = NULL;
  setenv("GRAUPEL_CL_OPTIONS", "-DGR_BROKEN_OPTION=( -cl-no-such-option", 1);
  gr_status st = gr_procedural_terrain_create(ctx, &g, &p, &t);
  CHECK_MSG(st == GR_ERR_BUILD, "%s: %s", gr_status_string(st), gr_last_error(ctx));
  CHECK(t == NULL && strstr(gr_last_error(ctx), "procedural_terrain") != NULL);
  unsetenv("GRAUPEL_CL_OPTIONS");
  CHECK(gr_procedural_terrain_create(ctx, &g, &p, &t) == GR_OK);
  gr_procedural_terrain_destroy(t);
}

/* The parameter of a table row, by the row's property name. */
static int set_by_name(gr_procedural_terrain_params *p, const char *property, double v) {
  if (strcmp(property, "Seed") == 0)
    p->seed = (int)v;
  else if (strcmp(property, "NoiseType") == 0)
    p->type = (gr_noise_type)(int)v;
  else if (strcmp(property, "Octaves") == 0)
    p->octaves = (int)v;
  else if (strcmp(property, "Frequency") == 0)
    p->frequency = v;
  else if (strcmp(property, "Lacunarity") == 0)
    p->lacunarity = v;
  else if (strcmp(property, "Persistence") == 0)
    p->persistence = v;
  else if (strcmp(property, "Offset") == 0)
    p->offset = v;
  else if (strcmp(property, "Gain") == 0)
    p->gain = v;
  else if (strcmp(property, "SpectralExponent") == 0)
    p->h = v;
  else if (strcmp(property, "Invert") == 0)
    p->invert = (int)v;
  else if (strcmp(property, "HeightScale") == 0)
    p->height_scale = v;
  else
    return 0;
  return 1;
}

static double get_by_name(const gr_procedural_terrain_params *p, const char *property) {
  static const char *const names[] = {
      "Seed",   "NoiseType", "Octaves",          "Frequency", "Lacunarity", "Persistence",
      "Offset", "Gain",      "SpectralExponent", "Invert",    "HeightScale"};
  const double values[] = {p->seed,       p->type,        p->octaves,     p->frequency,
                           p->lacunarity, p->persistence, p->offset,      p->gain,
                           p->h,          p->invert,      p->height_scale};
  for (int i = 0; i < 11; ++i)
    if (strcmp(names[i], property) == 0)
      return values[i];
  return NAN;
}

static void test_param_table(void) {
  int n = 0;
  const gr_param_bound *rows = gr_procedural_terrain_param_bounds(&n);
  static const char *const order[] = {
      "Seed",   "NoiseType", "Octaves",          "Frequency", "Lacunarity", "Persistence",
      "Offset", "Gain",      "SpectralExponent", "Invert",    "HeightScale"};
  CHECK(rows != NULL && n == 11);
  CHECK(gr_procedural_terrain_param_bounds(NULL) == rows);
  if (!rows || n != 11)
    return;
  gr_procedural_terrain_params def;
  gr_procedural_terrain_params_init(&def);
  char msg[256];
  for (int r = 0; r < n; ++r) {
    const gr_param_bound *b = &rows[r];
    CHECK_MSG(strcmp(b->property, order[r]) == 0, "row %d is %s", r, b->property);
    CHECK(b->unit != NULL && b->min < b->max && b->to_core == 1.0);
    /* The default lies in the range and is what params_init gives. */
    CHECK_MSG(get_by_name(&def, b->property) == b->default_value, "%s default", b->property);
    CHECK(b->default_value > b->min || (!b->min_open && b->default_value == b->min));
    CHECK(b->default_value <= b->max);
    gr_procedural_terrain_params q = def;
    /* At the bounds: max accepted; min accepted unless the row says open. */
    CHECK(set_by_name(&q, b->property, b->max));
    CHECK_MSG(gr_procedural_terrain_params_validate(&q, msg, sizeof(msg)) == GR_OK, "%s at max: %s",
              b->property, msg);
    q = def;
    set_by_name(&q, b->property, b->min);
    gr_status at_min = gr_procedural_terrain_params_validate(&q, msg, sizeof(msg));
    CHECK_MSG(at_min == (b->min_open ? GR_ERR_INVALID_ARGUMENT : GR_OK), "%s at min %g: %s",
              b->property, b->min, msg);
    if (b->min_open)
      CHECK_MSG(strstr(msg, b->property) && strstr(msg, "above"), "'%s'", msg);
    /* Just outside: refused with the property's name (whole numbers one
     * step out, where int holds it; doubles one ulp out). */
    double below = b->integer ? b->min - 1.0 : nextafter(b->min, -INFINITY);
    double above = b->integer ? b->max + 1.0 : nextafter(b->max, INFINITY);
    if (!b->integer || below >= (double)INT_MIN) {
      q = def;
      set_by_name(&q, b->property, below);
      CHECK_MSG(gr_procedural_terrain_params_validate(&q, msg, sizeof(msg)) ==
                        GR_ERR_INVALID_ARGUMENT &&
                    strstr(msg, b->property) != NULL,
                "%s below min: '%s'", b->property, msg);
    }
    if (!b->integer || above <= (double)INT_MAX) {
      q = def;
      set_by_name(&q, b->property, above);
      CHECK_MSG(gr_procedural_terrain_params_validate(&q, msg, sizeof(msg)) ==
                        GR_ERR_INVALID_ARGUMENT &&
                    strstr(msg, b->property) != NULL,
                "%s above max: '%s'", b->property, msg);
    }
    if (!b->integer) {
      q = def;
      set_by_name(&q, b->property, NAN);
      CHECK(gr_procedural_terrain_params_validate(&q, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
    }
  }
  /* The octave macros are the table's Octaves row. */
  CHECK(rows[2].min == GR_PROCEDURAL_TERRAIN_OCTAVES_MIN &&
        rows[2].max == GR_PROCEDURAL_TERRAIN_OCTAVES_MAX);
  /* Offset 0 is refused for every noise type (ridged noise vanishes there). */
  for (int type = 0; type < 3; ++type) {
    gr_procedural_terrain_params q = def;
    q.type = (gr_noise_type)type;
    q.offset = 0.0;
    CHECK(gr_procedural_terrain_params_validate(&q, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  }
}

static void test_shared_context_errors(void) {
  /* Two generators on one shared context (two filters) fail differently;
   * each keeps its own sentence, whatever the other did later. */
  gr_context *c1 = NULL, *c2 = NULL;
  CHECK(gr_context_acquire(NULL, &c1) == GR_OK);
  CHECK(gr_context_acquire(NULL, &c2) == GR_OK);
  CHECK(c1 != NULL && c1 == c2);
  if (!c1 || !c2)
    return;
  gr_grid g = {16, 16, 1.0, 1.0, 0.0, 0.0, 0, 0};
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  gr_procedural_terrain *a = NULL, *b = NULL;
  CHECK(gr_procedural_terrain_create(c1, &g, &p, &a) == GR_OK);
  CHECK(gr_procedural_terrain_create(c2, &g, &p, &b) == GR_OK);
  if (a && b) {
    CHECK(strcmp(gr_procedural_terrain_last_error(a), "") == 0);
    CHECK(gr_procedural_terrain_compute_rows(a, 10, 10) == GR_ERR_INVALID_ARGUMENT);
    float out[256];
    CHECK(gr_procedural_terrain_get_field(b, GR_FIELD_SNOW_DEPTH, out) == GR_ERR_INVALID_ARGUMENT);
    gr_procedural_terrain_params q = p;
    q.gain = -1.0;
    CHECK(gr_procedural_terrain_set_params(b, &q) == GR_ERR_INVALID_ARGUMENT);
    const char *ea = gr_procedural_terrain_last_error(a), *eb = gr_procedural_terrain_last_error(b);
    CHECK_MSG(strstr(ea, "Rows 10 to 19") && !strstr(ea, "Gain"), "a: '%s'", ea);
    CHECK_MSG(strstr(eb, "Gain") && !strstr(eb, "Rows"), "b: '%s'", eb);
    /* The thread's latest error is the last failure, b's. */
    CHECK(strcmp(gr_last_error(c1), eb) == 0);
    /* A later success does not erase a handle's last error. */
    CHECK(gr_procedural_terrain_compute(a) == GR_OK);
    CHECK(strstr(gr_procedural_terrain_last_error(a), "Rows 10 to 19") != NULL);
  }
  /* A failed create has no handle: NULL gives the thread's sentence. */
  gr_procedural_terrain *none = NULL;
  gr_procedural_terrain_params bad = p;
  bad.octaves = 99;
  CHECK(gr_procedural_terrain_create(c1, &g, &bad, &none) == GR_ERR_INVALID_ARGUMENT);
  CHECK(none == NULL && strstr(gr_procedural_terrain_last_error(NULL), "Octaves is 99") != NULL);
  gr_procedural_terrain_destroy(a);
  gr_procedural_terrain_destroy(b);
  gr_context_release(c1);
  gr_context_release(c2);
}

static void test_set_params_variants(void) {
  /* Octaves and NoiseType are compiled into the kernel: set_params with
   * others gives exactly what a new generator with them gives. */
  gr_grid g = {40, 30, 3.0, 3.0, 5.0, 7.0, 0, 0};
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  gr_procedural_terrain *t = NULL;
  CHECK(gr_procedural_terrain_create(ctx, &g, &p, &t) == GR_OK);
  if (!t)
    return;
  float got[40 * 30];
  for (int k = 0; k < 3; ++k) {
    gr_procedural_terrain_params q = p;
    /* Variants other subtests build too (PoCL's cache keeps them). */
    q.octaves = k == 0 ? 1 : 6;
    q.type = (gr_noise_type)((k + 1) % 3);
    q.seed = 11 * k;
    float *want = make(&g, &q);
    CHECK(gr_procedural_terrain_set_params(t, &q) == GR_OK);
    CHECK(gr_procedural_terrain_compute(t) == GR_OK);
    CHECK(gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, got) == GR_OK);
    CHECK_MSG(want && memcmp(want, got, sizeof(got)) == 0, "octaves %d type %d differ", q.octaves,
              k);
    free(want);
  }
  gr_procedural_terrain_destroy(t);
}

/* Largest difference between a generated grid and the double reference. */
static double worst_vs_reference(const gr_grid *g, const gr_procedural_terrain_params *p,
                                 const float *h) {
  double worst = 0;
  for (int j = 0; j < g->ny; ++j)
    for (int i = 0; i < g->nx; ++i) {
      double d = fabs(ref_elevation(p, g->x0 + (g->i0 + i) * g->dx, g->y0 + (g->j0 + j) * g->dy) -
                      h[j * g->nx + i]);
      worst = d > worst ? d : worst;
    }
  return worst;
}

/* For valgrind, where building a kernel variant takes many seconds: every
 * entry point once on a tiny grid with two variants only (the default and
 * octaves 1 fBm, both built by the other subtests, so PoCL's cache has
 * them) and one failing build. */
static void test_memcheck_tiny(void) {
  gr_grid g = {9, 7, 3.0, 2.0, 15.0, -4.0, 0, 0};
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  float *whole = make(&g, &p);
  gr_procedural_terrain *t = NULL;
  CHECK(gr_procedural_terrain_create(ctx, &g, &p, &t) == GR_OK);
  if (!whole || !t) {
    free(whole);
    gr_procedural_terrain_destroy(t);
    return;
  }
  CHECK_MSG(worst_vs_reference(&g, &p, whole) < 1e-4 * p.height_scale, "default %.3g m",
            worst_vs_reference(&g, &p, whole));

  /* Bands give the whole grid; a band outside is refused. */
  float got[9 * 7], back[9 * 7];
  memset(got, 0, sizeof(got));
  CHECK(gr_procedural_terrain_compute_rows(t, 0, 4) == GR_OK);
  CHECK(gr_procedural_terrain_compute_rows(t, 4, 3) == GR_OK);
  CHECK(gr_procedural_terrain_compute_rows(t, 5, 3) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_procedural_terrain_last_error(t), "Rows 5 to 7") != NULL);
  CHECK(gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, got) == GR_OK);
  CHECK(memcmp(whole, got, sizeof(got)) == 0);

  /* The kernel switch: a failing build keeps the old variant working... */
  gr_procedural_terrain_params q = p;
  q.octaves = 1;
  q.type = GR_NOISE_FBM;
  q.seed = 5;
  setenv("GRAUPEL_CL_OPTIONS", "-DGR_BROKEN_OPTION=( -cl-no-such-option", 1);
  gr_status st = gr_procedural_terrain_set_params(t, &q);
  unsetenv("GRAUPEL_CL_OPTIONS");
  CHECK_MSG(st == GR_ERR_BUILD, "%s", gr_status_string(st));
  CHECK(strstr(gr_procedural_terrain_last_error(t), "procedural_terrain") != NULL);
  CHECK(gr_procedural_terrain_compute(t) == GR_OK);
  CHECK(gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, got) == GR_OK);
  CHECK(memcmp(whole, got, sizeof(got)) == 0);
  /* ...and once fixed, the other variant computes its own terrain... */
  CHECK(gr_procedural_terrain_set_params(t, &q) == GR_OK);
  CHECK(gr_procedural_terrain_compute(t) == GR_OK);
  CHECK(gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, got) == GR_OK);
  CHECK_MSG(worst_vs_reference(&g, &q, got) < 1e-4 * q.height_scale, "fBm %.3g m",
            worst_vs_reference(&g, &q, got));
  CHECK(memcmp(whole, got, sizeof(got)) != 0);
  /* ...and going back reuses the context's first variant, bit for bit. */
  CHECK(gr_procedural_terrain_set_params(t, &p) == GR_OK);
  CHECK(gr_procedural_terrain_compute(t) == GR_OK);
  CHECK(gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, back) == GR_OK);
  CHECK(memcmp(whole, back, sizeof(back)) == 0);

  /* A piece (i0, j0) of a larger grid is that part of the whole. */
  gr_grid piece = g;
  piece.nx = 4;
  piece.ny = 3;
  piece.i0 = 5;
  piece.j0 = 4;
  float *h = make(&piece, &p);
  int mismatched = h ? 0 : 1;
  for (int j = 0; h && j < piece.ny; ++j)
    for (int i = 0; i < piece.nx; ++i)
      mismatched += h[j * piece.nx + i] != whole[(j + 4) * g.nx + i + 5];
  CHECK_MSG(mismatched == 0, "%d piece values differ", mismatched);
  free(h);

  /* NULL handles are refused with a sentence, not a crash. */
  CHECK(gr_procedural_terrain_compute(NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_procedural_terrain_compute_rows(NULL, 0, 1) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_procedural_terrain_set_params(NULL, &p) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, NULL) == GR_ERR_INVALID_ARGUMENT);
  gr_procedural_terrain *none = NULL;
  CHECK(gr_procedural_terrain_create(NULL, &g, &p, &none) == GR_ERR_INVALID_ARGUMENT);
  CHECK(none == NULL && strlen(gr_procedural_terrain_last_error(NULL)) > 10);
  gr_procedural_terrain_destroy(t);
  free(whole);
}

/* What valgrind runs (memcheck.procedural_terrain): every host entry point
 * and error path once, on tiny grids, with as few kernel builds as possible;
 * the larger subtests run natively and under ASan. */
static void test_memcheck(void) {
  test_errors();
  test_param_table();
  test_shared_context_errors();
  test_memcheck_tiny();
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
    {"reference", test_reference, 0},
    {"determinism_and_seeds", test_determinism_and_seeds, 0},
    {"octaves_energy", test_octaves_energy, 0},
    {"no_axis_seam", test_no_axis_seam, 0},
    {"height_scale_and_bounds", test_height_scale_and_bounds, 0},
    {"tiling_and_inversion", test_tiling_and_inversion, 0},
    {"devices_agree", test_devices_agree, 0},
    {"errors", test_errors, 0},
    {"param_table", test_param_table, 0},
    {"shared_context_errors", test_shared_context_errors, 0},
    {"set_params_variants", test_set_params_variants, 0},
    {"bands", test_bands, 0},
    {"build_failure", test_build_failure, 0},
    {"memcheck", test_memcheck, 1},
};

int main(int argc, char **argv) {
  return gr_test_main(argc, argv, tests, (int)(sizeof(tests) / sizeof(tests[0])), setup, teardown);
}
