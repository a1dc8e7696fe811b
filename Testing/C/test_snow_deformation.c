/* Tests of the snow deformation core (graupel/snow_deformation.h): the
 * ledger (mass and volume), the imprint, the contour and the direction
 * weights, the talus relaxation (and the thesis' Alg. 4.11 loss it fixes),
 * the resistance, determinism, checkpoints, the parameter table and the
 * error paths. */
#include "gr_test.h"
#include "gr_test_mesh.h"
#include "gr_test_team.h"

#include "graupel/snow_deformation.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static gr_context *ctx;

static int has(const char *text, const char *word) {
  return text && strstr(text, word) != NULL;
}

/* A latitude-longitude sphere of radius r: poles and st - 1 rings of sl. */
static void mesh_sphere(test_mesh *tm, double r, int st, int sl) {
  int nv = 2 + (st - 1) * sl, nt = 2 * sl * (st - 1);
  tm->v = malloc((size_t)nv * 3 * sizeof(float));
  tm->t = malloc((size_t)nt * 3 * sizeof(int));
  float *v = tm->v;
  v[0] = 0.0f, v[1] = 0.0f, v[2] = (float)r;
  for (int a = 1; a < st; ++a)
    for (int b = 0; b < sl; ++b) {
      double th = M_PI * a / st, ph = 2.0 * M_PI * b / sl;
      float *p = v + 3 * (1 + (a - 1) * sl + b);
      p[0] = (float)(r * sin(th) * cos(ph));
      p[1] = (float)(r * sin(th) * sin(ph));
      p[2] = (float)(r * cos(th));
    }
  float *s = v + 3 * (nv - 1);
  s[0] = 0.0f, s[1] = 0.0f, s[2] = (float)-r;
  int *t = tm->t, k = 0;
#define RING(a, b) (1 + ((a)-1) * sl + ((b) % sl))
  for (int b = 0; b < sl; ++b) {
    t[k++] = 0, t[k++] = RING(1, b), t[k++] = RING(1, b + 1);
    t[k++] = nv - 1, t[k++] = RING(st - 1, b + 1), t[k++] = RING(st - 1, b);
  }
  for (int a = 1; a < st - 1; ++a)
    for (int b = 0; b < sl; ++b) {
      t[k++] = RING(a, b), t[k++] = RING(a + 1, b), t[k++] = RING(a + 1, b + 1);
      t[k++] = RING(a, b), t[k++] = RING(a + 1, b + 1), t[k++] = RING(a, b + 1);
    }
#undef RING
  tm->m.vertices = v;
  tm->m.nvertices = nv;
  tm->m.triangles = t;
  tm->m.ntriangles = k / 3;
  mesh_pose(tm, 0, 0, 0);
}

static gr_snow_deformation *make_sim(int nx, int ny, double dx,
                                     const gr_snow_deformation_params *p) {
  gr_grid g = {.nx = nx, .ny = ny, .dx = dx, .dy = dx};
  gr_snow_deformation *s = NULL;
  gr_status st = gr_snow_deformation_create(ctx, &g, p, &s);
  CHECK_MSG(st == GR_OK, "create: %s", gr_last_error(ctx));
  return s;
}

static float *get(gr_snow_deformation *s, gr_field f, int n) {
  float *a = malloc((size_t)n * sizeof(float));
  CHECK(gr_snow_deformation_get_field(s, f, a) == GR_OK);
  return a;
}

static void test_param_table(void) {
  int n = 0;
  const gr_param_bound *t = gr_snow_deformation_param_bounds(&n);
  CHECK(n == 10);
  const char *names[] = {"InitialSnowDepth", "InitialDensity",     "MinDensity",
                         "MaxDensity",       "CompressionModel",   "MaxSlope",
                         "DirectionFalloff", "MaxRelaxIterations", "RelaxTolerance",
                         "SlumpSpeed"};
  for (int r = 0; r < n && r < 10; ++r)
    CHECK(strcmp(t[r].property, names[r]) == 0);
  gr_snow_deformation_params p, q;
  gr_snow_deformation_params_init(&p);
  char msg[256];
  CHECK(gr_snow_deformation_params_validate(&p, msg, sizeof(msg)) == GR_OK);
  CHECK(p.max_slope == 0.6 && p.direction_falloff == 8.0 && p.compression_model == 0);
  CHECK(p.min_density == 100.0 && p.max_density == 400.0 && p.initial_density == 150.0);
  /* Each row: its bounds accepted, beyond them refused with a sentence that
   * names the property; the validator follows the table. */
  double *fields[] = {&q.initial_snow_depth,
                      &q.initial_density,
                      &q.min_density,
                      &q.max_density,
                      NULL,
                      &q.max_slope,
                      &q.direction_falloff,
                      NULL,
                      &q.relax_tolerance,
                      &q.slump_speed};
  for (int r = 0; r < 10; ++r) {
    double lo = t[r].min * t[r].to_core, hi = t[r].max * t[r].to_core;
    double vals[4] = {lo, hi, lo - 1.0, hi + 1.0};
    if (r == 5 || r == 8) /* open minimum: the bound itself is refused */
      vals[0] = 0.5 * hi, vals[2] = lo;
    for (int k = 0; k < 4; ++k) {
      gr_snow_deformation_params_init(&q);
      q.min_density = 1.0, q.max_density = 3000.0, q.initial_density = 100.0;
      if (r == 4)
        q.compression_model = (int)vals[k];
      else if (r == 7)
        q.max_relax_iterations = (int)vals[k];
      else if (r >= 1 && r <= 3 && k < 2) /* the three densities must agree */
        q.initial_density = q.min_density = q.max_density = vals[k];
      else
        *fields[r] = vals[k];
      msg[0] = 0;
      gr_status st = gr_snow_deformation_params_validate(&q, msg, sizeof(msg));
      if (k < 2)
        CHECK_MSG(st == GR_OK, "row %s value %g: %s", t[r].property, vals[k], msg);
      else
        CHECK_MSG(st == GR_ERR_INVALID_ARGUMENT && strstr(msg, t[r].property),
                  "row %s value %g: %s", t[r].property, vals[k], msg);
    }
  }
  gr_snow_deformation_params_init(&q);
  q.relax_tolerance = NAN;
  CHECK(gr_snow_deformation_params_validate(&q, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  gr_snow_deformation_params_init(&q);
  q.min_density = 500.0;
  CHECK(gr_snow_deformation_params_validate(&q, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT &&
        strstr(msg, "MinDensity"));
  gr_snow_deformation_params_init(&q);
  q.initial_density = 50.0;
  CHECK(gr_snow_deformation_params_validate(&q, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT &&
        strstr(msg, "InitialDensity"));
  CHECK(gr_snow_deformation_params_validate(NULL, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
}

/* A box of 0.6 x 0.4 m, 0.2 m under the snow surface (0.5 m), dragged
 * steps times at speed along x across a 64 x 48 grid of 5 cm. */
static void plough(gr_snow_deformation *s, int steps, double speed, double dt) {
  test_mesh box;
  mesh_box(&box, 0.3, 0.2, 0.25);
  double v[3] = {speed, 0.0, -0.0};
  for (int k = 0; k < steps; ++k) {
    double x = 0.6 + fmod(speed * dt * k, 2.0);
    mesh_pose(&box, x, 1.2, 0.3 + 0.25);
    CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, v) == GR_OK);
    gr_status st = gr_snow_deformation_step(s, dt);
    if (st != GR_OK) {
      CHECK_MSG(0, "step %d: %s", k, gr_snow_deformation_last_error(s));
      break;
    }
  }
  mesh_free(&box);
}

/* The target: volume kept to 1e-6 over 10^4 steps. The talus gets 8 iterations a step (the snow
 * need not settle for the books to close, and the test stays quick); every amount that moves is
 * whole quanta (snow_deformation_shared.h), so the volume closes to the rounding of the ledger's
 * own double sums. */
#define MASS_STEPS 10000

static void test_mass_no_compression(void) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.initial_density = p.max_density; /* nothing can be compressed */
  p.max_relax_iterations = 8;
  gr_snow_deformation *s = make_sim(64, 48, 0.05, &p);
  if (!s)
    return;
  gr_snow_deformation_ledger l;
  plough(s, MASS_STEPS, 1.5, 1.0 / 60.0);
  CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK);
  double rel = fabs(l.snow_volume - l.initial_volume) / l.initial_volume;
  printf("no compression: %lld steps, volume %.12g of %.12g (rel %.3g), displaced %.4g m^3, "
         "compressed %.3g\n",
         l.steps, l.snow_volume, l.initial_volume, rel, l.displaced_volume, l.compressed_volume);
  CHECK(l.steps == MASS_STEPS);
  CHECK(rel < 1e-12); /* the target is 1e-6 */
  CHECK(l.compressed_volume == 0.0);
  CHECK(l.displaced_volume > 1.0); /* the box did move snow */
  CHECK(fabs(l.balance_error) / l.initial_mass < 1e-6);
  gr_snow_deformation_destroy(s);
}

static void test_mass_compression(void) {
  for (int model = 0; model < 2; ++model) {
    gr_snow_deformation_params p;
    gr_snow_deformation_params_init(&p);
    p.compression_model = model;
    p.max_relax_iterations = 8;
    gr_snow_deformation *s = make_sim(64, 48, 0.05, &p);
    if (!s)
      return;
    gr_snow_deformation_ledger l;
    plough(s, 1, 1.5, 1.0 / 60.0);
    CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK);
    /* First step: the density is 150 in [100, 400], W = 1/6 (model 0) or
     * the constant 0.85 (model 1) of the overlap is displaced. */
    /* Every point under the box is pressed alike (0.2 m), and its share
     * rounds to the same whole quantum: within half a quantum of 0.2 m. */
    double frac = l.compressed_volume / (l.compressed_volume + l.displaced_volume);
    printf("model %d: compressed fraction of the first press %.9f\n", model, frac);
    CHECK_NEAR(frac, model == 0 ? 5.0 / 6.0 : 0.15, 0.5 / 1048576.0 / 0.2 + 1e-9);
    /* The volume closes exactly; the mass, depth times a float density,
     * to the densities' rounding. */
    plough(s, MASS_STEPS, 1.5, 1.0 / 60.0);
    CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK);
    double mrel = fabs(l.balance_error) / l.initial_mass;
    double vrel = fabs(l.volume_error) / l.initial_volume;
    printf("model %d: %lld steps, mass error %.3g, volume error %.3g (compressed %.5g m^3 of "
           "%.5g)\n",
           model, l.steps, mrel, vrel, l.compressed_volume, l.initial_volume);
    CHECK(mrel < 1e-6);
    CHECK(vrel < 1e-12);
    CHECK(l.compressed_volume > 1e-3);
    CHECK(l.snow_volume < l.initial_volume - 1e-3);
    /* Densities stay in the range: compression never goes beyond rho_max. */
    float *rho = get(s, GR_FIELD_SNOW_DENSITY, 64 * 48);
    float lo = 1e30f, hi = 0.0f;
    for (int c = 0; c < 64 * 48; ++c)
      lo = fminf(lo, rho[c]), hi = fmaxf(hi, rho[c]);
    printf("model %d: densities %.6g to %.6g kg/m^3\n", model, (double)lo, (double)hi);
    CHECK(lo >= 150.0f - 1e-3f && hi <= 400.0f + 1e-3f && hi > 160.0f);
    free(rho);
    gr_snow_deformation_destroy(s);
  }
}

/* A sphere of radius 0.5 m pressed straight down 0.3 m into 0.5 m of snow:
 * the hole is the spherical cap, its rim within one cell. */
static void test_imprint_sphere(void) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  int n = 81;
  double dx = 0.025, R = 0.5, cx = 40 * dx, cy = 40 * dx, zc = 0.2 + R;
  gr_snow_deformation *s = make_sim(n, n, dx, &p);
  if (!s)
    return;
  test_mesh sp;
  mesh_sphere(&sp, R, 64, 128);
  mesh_pose(&sp, cx, cy, zc);
  double v[3] = {0.0, 0.0, -1.0};
  CHECK(gr_snow_deformation_set_objects(s, &sp.m, 1, v) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.1) == GR_OK);
  float *h = get(s, GR_FIELD_SNOW_SURFACE, n * n), *c = get(s, GR_FIELD_CONTACT, n * n);
  double rcap = sqrt(R * R - (zc - 0.5) * (zc - 0.5)), worst_under = 0.0;
  int bad_in = 0, bad_out = 0, in_hole = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double r = hypot(i * dx - cx, j * dx - cy);
      float hv = h[j * n + i];
      int hole = hv < 0.5f - 1e-4f;
      in_hole += hole;
      if (r < rcap - dx && !hole)
        ++bad_in;
      if (r > rcap + dx && hole)
        ++bad_out;
      if (r < R && c[j * n + i] > 0.5f) {
        double under = zc - sqrt(R * R - r * r);
        worst_under = fmax(worst_under, hv - under);
      }
    }
  printf("sphere: %d points in the hole (disc %.1f), surface above underside by at most %.4g m\n",
         in_hole, M_PI * rcap * rcap / (dx * dx), worst_under);
  CHECK(bad_in == 0 && bad_out == 0);
  /* The faceted sphere lies within R (1 - cos(pi / 128)) < 0.2 mm of the
   * true one: the imprint meets the underside within 1 mm. */
  CHECK(worst_under <= 1e-3);
  CHECK(in_hole > 0);
  mesh_free(&sp);
  free(h);
  free(c);
  gr_snow_deformation_destroy(s);
}

/* A box covering exactly the k x k points (10..10+k-1)^2, pressed with
 * the talus off: the deposit marks the contour. */
static void press_square(int k, const double v[3], float **depth_out, int n, double dx) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.max_relax_iterations = 0;
  p.initial_density = p.max_density; /* all displaced */
  gr_snow_deformation *s = make_sim(n, n, dx, &p);
  *depth_out = NULL;
  if (!s)
    return;
  test_mesh box;
  double h = 0.5 * k * dx;
  mesh_box(&box, h, h, 0.25);
  mesh_pose(&box, (10 - 0.5) * dx + h, (10 - 0.5) * dx + h, 0.3 + 0.25);
  CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, v) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.1) == GR_OK);
  *depth_out = get(s, GR_FIELD_SNOW_DEPTH, n * n);
  double f[3], area;
  CHECK(gr_snow_deformation_object_forces(s, f, &area, 1) == GR_OK);
  CHECK_NEAR(area, k * k * dx * dx, 1e-9);
  mesh_free(&box);
  gr_snow_deformation_destroy(s);
}

static void test_contour_direction(void) {
  int n = 40, k = 7;
  double dx = 0.05;
  double vertical[3] = {0.0, 0.0, -2.0}, ahead[3] = {1.0, 0.0, 0.0};
  float *d = NULL;
  press_square(k, vertical, &d, n, dx);
  if (!d)
    return;
  int ring = 0, under = 0;
  double lo = 1e30, hi = 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      float x = d[j * n + i];
      if (x > 0.5f + 1e-6f) {
        ++ring;
        lo = fmin(lo, x - 0.5), hi = fmax(hi, x - 0.5);
        /* only the ring around the square */
        CHECK(i >= 9 && i <= 10 + k && j >= 9 && j <= 10 + k);
      } else if (x < 0.4f)
        ++under;
    }
  printf("contour: %d cells (4k+4 = %d), vertical deposit %.6g..%.6g m\n", ring, 4 * k + 4, lo, hi);
  CHECK(ring == 4 * k + 4);
  CHECK(under == k * k);
  CHECK((hi - lo) <= 0.05 * hi); /* uniform within 5 % (exactly, in fact) */
  free(d);
  /* Horizontal motion along +x: the column ahead gets weight 1, its two
   * corners 1/sqrt(2), everything else nothing. */
  press_square(k, ahead, &d, n, dx);
  if (!d)
    return;
  double front = 0.0, all = 0.0, behind = 0.0, side = 0.0, a_edge = d[12 * n + 10 + k] - 0.5;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double add = d[j * n + i] - 0.5;
      if (add <= 0.0)
        continue;
      all += add;
      if (i > 10 + k - 1)
        front += add;
      if (i < 10) /* the back column */
        behind += add;
      if (i >= 10 && i < 10 + k - 1) /* the sides, but for their front ends */
        side += add;
    }
  double corner = d[(9) * n + 10 + k] - 0.5, corner2 = d[(10 + k) * n + 10 + k] - 0.5;
  printf("direction: ahead %.4f of the deposit, behind %.3g; corner/edge %.6f\n", front / all,
         behind, corner / a_edge);
  CHECK(front / all >= 0.85);
  CHECK(behind == 0.0 && side == 0.0);
  CHECK_NEAR(corner / a_edge, 1.0 / sqrt(2.0), 1e-5);
  CHECK_NEAR(corner2 / a_edge, 1.0 / sqrt(2.0), 1e-5);
  free(d);
}

/* A tall column on flat ground: afterwards no pair exceeds MaxSlope and the
 * volume is kept; its top is near the cone of that volume. */
/* The largest amount by which a surface h (nx x ny, spacing dx) stands
 * above an 8-neighbour beyond the talus slope. */
static double worst_excess(const float *h, int nx, int ny, double dx, double slope) {
  double worst = -1.0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          int a = i + di, b = j + dj;
          if ((di | dj) == 0 || a < 0 || b < 0 || a >= nx || b >= ny)
            continue;
          double dist = dx * sqrt((double)(di * di + dj * dj));
          worst = fmax(worst, (h[j * nx + i] - h[b * nx + a]) - slope * dist);
        }
  return worst;
}

static void test_talus_column(void) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.initial_snow_depth = 0.0;
  p.slump_speed = 0.0; /* instant: the talus' own iterations */
  p.max_relax_iterations = 100000;
  p.relax_tolerance = 1e-5;
  int n = 41;
  double dx = 0.1;
  gr_snow_deformation *s = make_sim(n, n, dx, &p);
  if (!s)
    return;
  float *d0 = calloc((size_t)n * n, sizeof(float));
  d0[20 * n + 20] = 2.0f;
  CHECK(gr_snow_deformation_set_field(s, GR_FIELD_SNOW_DEPTH, d0) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.1) == GR_OK);
  gr_snow_deformation_ledger l;
  CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK);
  float *h = get(s, GR_FIELD_SNOW_SURFACE, n * n);
  double worst = worst_excess(h, n, n, dx, p.max_slope);
  double vol = 2.0 * dx * dx, r = cbrt(3.0 * vol / (M_PI * p.max_slope));
  double cone_top = p.max_slope * r;
  printf("talus: %d iterations, worst excess %.3g m, volume %.9g of %.9g, top %.4g (cone %.4g)\n",
         l.relax_iterations, worst, l.snow_volume, vol, (double)h[20 * n + 20], cone_top);
  CHECK(worst <= 1e-4);
  CHECK(fabs(l.snow_volume - vol) / vol < 1e-6);
  CHECK(fabs(l.snow_mass - vol * 150.0) / (vol * 150.0) < 1e-6);
  CHECK(h[20 * n + 20] > 0.6 * cone_top && h[20 * n + 20] < 1.4 * cone_top);
  /* thermal erosion's share: 24 iterations (88 at a tenth per excess) */
  CHECK(l.relax_iterations > 1 && l.relax_iterations <= 40);
  free(h);
  free(d0);
  gr_snow_deformation_destroy(s);
}

/* A relaxation cut short by MaxRelaxIterations goes on where it stopped in
 * the next steps, with no object anywhere: the talus column, 2 iterations
 * a step, ends the cone of the uncut relaxation, to the bit. (Before, the next step's
 * window was the objects' boxes alone: the column stayed a spike.) */
static void test_talus_resumes(void) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.initial_snow_depth = 0.0;
  p.slump_speed = 0.0; /* instant: the talus' own iterations */
  p.max_relax_iterations = 2;
  p.relax_tolerance = 1e-5;
  int n = 41, steps = 0, last = -1;
  double dx = 0.1;
  gr_snow_deformation *s = make_sim(n, n, dx, &p);
  if (!s)
    return;
  float *d0 = calloc((size_t)n * n, sizeof(float));
  d0[20 * n + 20] = 2.0f;
  CHECK(gr_snow_deformation_set_field(s, GR_FIELD_SNOW_DEPTH, d0) == GR_OK);
  CHECK(gr_snow_deformation_set_objects(s, NULL, 0, NULL) == GR_OK);
  gr_snow_deformation_ledger l;
  while (last != 0 && steps < 40) {
    CHECK(gr_snow_deformation_step(s, 0.1) == GR_OK);
    CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK);
    last = l.relax_iterations;
    ++steps;
  }
  float *h = get(s, GR_FIELD_SNOW_SURFACE, n * n);
  double worst = worst_excess(h, n, n, dx, p.max_slope);
  printf("talus resumes: %d steps of at most 2 iterations, the last %d; worst excess %.3g m, "
         "top %.4g m, volume %.9g\n",
         steps, last, worst, (double)h[20 * n + 20], l.snow_volume);
  /* the same iterations as one uncut relaxation: the same bits */
  p.max_relax_iterations = 100000;
  gr_snow_deformation *u = make_sim(n, n, dx, &p);
  float *hu = NULL;
  int differ = -1;
  if (u) {
    CHECK(gr_snow_deformation_set_field(u, GR_FIELD_SNOW_DEPTH, d0) == GR_OK);
    CHECK(gr_snow_deformation_step(u, 0.1) == GR_OK);
    hu = get(u, GR_FIELD_SNOW_SURFACE, n * n);
    differ = 0;
    for (int c = 0; c < n * n; ++c)
      differ += h[c] != hu[c];
  }
  printf("talus resumes: %d points differ from the uncut relaxation's\n", differ);
  CHECK(steps >= 2 && last == 0);
  CHECK(worst <= 1e-4);
  CHECK(l.snow_volume == l.initial_volume);
  CHECK(differ == 0);
  free(h), free(hu), free(d0);
  gr_snow_deformation_destroy(u);
  gr_snow_deformation_destroy(s);
}

/* Seed 000's Alg. 4.11 (its talus flattening) on the host: it removes
 * the total excess s but hands out only s/m. */
/* SlumpSpeed: a pile (0.5 m^3 on a block 0.3 m wide, 5.6 m high)
 * collapses at c = 2 m/s. A talus iteration moves snow one point, and a step
 * of dt reaches ceil(c dt / dx) points from where snow could move, so the
 * pile's edge (the farthest point holding snow, in points along x or y from
 * the middle) moves at most that far each step: 1 + 2k points after k steps of 0.1 s (0.2 m a
 * step), and exactly that while the pile is steep; without the bound one step spreads the pile to
 * its final edge. On a grid twice as fine (4 points a step) the edge is at the same place in
 * metres. Once still, the pile is at rest, with the volume it had, within 2 cm of the cone the
 * relaxation without the bound makes (measured 9.5 mm: each step settles the snow within its reach,
 * so the slide takes another path than one relaxation; with the talus cut to a number of iterations
 * instead the two ended bit for bit alike, and a pile an object feeds grew into a wall: test_berm).
 */
static int pile_edge(const float *d, int n) {
  int edge = 0, m = n / 2;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (d[j * n + i] > 0.0f) {
        int e = abs(i - m) > abs(j - m) ? abs(i - m) : abs(j - m);
        edge = e > edge ? e : edge;
      }
  return edge;
}

static float *slump(int n, double dx, double speed, int steps, int *edges) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.initial_snow_depth = 0.0;
  p.max_relax_iterations = 100000;
  p.relax_tolerance = 1e-5;
  p.slump_speed = speed;
  gr_snow_deformation *s = make_sim(n, n, dx, &p);
  if (!s)
    return NULL;
  float *d0 = calloc((size_t)n * n, sizeof(float)), *d = NULL;
  const int m = n / 2, hw = dx < 0.075 ? 2 : 1, side = 2 * hw + 1;
  for (int j = -hw; j <= hw; ++j)
    for (int i = -hw; i <= hw; ++i)
      d0[(m + j) * n + m + i] = (float)(0.5 / (side * side * dx * dx));
  CHECK(gr_snow_deformation_set_field(s, GR_FIELD_SNOW_DEPTH, d0) == GR_OK);
  CHECK(gr_snow_deformation_set_objects(s, NULL, 0, NULL) == GR_OK);
  for (int t = 0; t < steps; ++t) {
    CHECK(gr_snow_deformation_step(s, 0.1) == GR_OK);
    free(d);
    d = get(s, GR_FIELD_SNOW_DEPTH, n * n);
    if (d && edges)
      edges[t] = pile_edge(d, n);
  }
  free(d0);
  gr_snow_deformation_destroy(s);
  return d;
}

static void test_slump_speed(void) {
  enum { STEPS = 60, SEEN = 8 };
  const int n = 41;
  int fast[STEPS], slow[STEPS], fine[3];
  float *a = slump(n, 0.1, 0.0, 1, fast), *b = slump(n, 0.1, 2.0, STEPS, slow);
  float *c = slump(2 * n - 1, 0.05, 2.0, 3, fine);
  if (!a || !b || !c) {
    free(a), free(b), free(c);
    return;
  }
  int differ = 0, bound_ok = 1;
  double apart = 0.0, va = 0.0, vb = 0.0;
  for (int k = 0; k < n * n; ++k) {
    differ += a[k] != b[k];
    apart = fmax(apart, fabs((double)a[k] - b[k]));
    va += a[k], vb += b[k];
  }
  double steep = worst_excess(b, n, n, 0.1, 0.6);
  for (int t = 0; t < SEEN; ++t)
    bound_ok &= slow[t] <= 1 + 2 * (t + 1) && (t >= 2 || slow[t] == 1 + 2 * (t + 1));
  printf("slump: the edge after one step %d points instant; at 2 m/s %d %d %d %d %d %d %d %d; "
         "twice as fine %.2f %.2f %.2f m against %.2f %.2f %.2f m; after %d steps %d of %d depths "
         "differ from the instant cone, by %.3g m at most; worst excess %.3g m; volume %.9g of "
         "%.9g (sums of depths)\n",
         fast[0], slow[0], slow[1], slow[2], slow[3], slow[4], slow[5], slow[6], slow[7],
         fine[0] * 0.05, fine[1] * 0.05, fine[2] * 0.05, slow[0] * 0.1, slow[1] * 0.1,
         slow[2] * 0.1, STEPS, differ, n * n, apart, steep, vb, va);
  CHECK_MSG(fast[0] >= 8, "the instant pile spreads to %d points only", fast[0]);
  CHECK_MSG(bound_ok, "the edge moves faster than 2 points a step, or slower while steep");
  CHECK(slow[SEEN - 1] == fast[0]);
  for (int t = 0; t < 3; ++t) /* at most 0.2 m a step, and the same edge while steep */
    CHECK(fine[t] <= 2 + 4 * (t + 1) && (t >= 2 || fine[t] == 2 * slow[t]));
  CHECK_MSG(steep <= 1e-4, "the pile is still steeper than MaxSlope by %.3g m", steep);
  CHECK_MSG(apart <= 0.02, "the pile ends %.3g m from the instant cone", apart);
  CHECK(va == vb); /* whole quanta: the sums are exact */
  free(a), free(b), free(c);
}

static double alg411_once(const float *h, float *out, int n, double phi) {
  for (int c = 0; c < n * n; ++c)
    out[c] = 0.0f;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      double H = h[y * n + x], sum = 0.0;
      int lower = 0, exceed = 0;
      for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i) {
          int a = x + i, b = y + j;
          if ((i | j) == 0 || a < 0 || b < 0 || a >= n || b >= n)
            continue;
          double o = h[b * n + a];
          if (H > o) {
            ++lower;
            if (H - phi > o)
              ++exceed, sum += H - phi - o;
          }
        }
      if (exceed > 0) {
        double t = (sum / exceed) / lower;
        for (int j = -1; j <= 1; ++j)
          for (int i = -1; i <= 1; ++i) {
            int a = x + i, b = y + j;
            if ((i | j) == 0 || a < 0 || b < 0 || a >= n || b >= n)
              continue;
            if (H > h[b * n + a])
              out[b * n + a] += (float)t;
          }
      }
      out[y * n + x] += (float)(H - sum);
    }
  double total = 0.0;
  for (int c = 0; c < n * n; ++c)
    total += out[c];
  return total;
}

static void test_alg411_loss(void) {
  int n = 21;
  double dx = 0.1;
  float *h = calloc((size_t)n * n, sizeof(float)), *o = calloc((size_t)n * n, sizeof(float));
  h[10 * n + 10] = 1.0f;
  double thesis = alg411_once(h, o, n, 0.6 * dx);
  printf("Alg. 4.11: one pass keeps %.4f of a 1 m column\n", thesis);
  CHECK(thesis < 0.5); /* it loses 7/8 of the excess */
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.initial_snow_depth = 0.0;
  p.max_relax_iterations = 1;
  gr_snow_deformation *s = make_sim(n, n, dx, &p);
  if (s) {
    CHECK(gr_snow_deformation_set_field(s, GR_FIELD_SNOW_DEPTH, h) == GR_OK);
    CHECK(gr_snow_deformation_step(s, 0.1) == GR_OK);
    float *d = get(s, GR_FIELD_SNOW_DEPTH, n * n);
    double total = 0.0;
    for (int c = 0; c < n * n; ++c)
      total += d[c];
    printf("core: one iteration keeps %.9f, centre %.4f\n", total, (double)d[10 * n + 10]);
    CHECK(fabs(total - 1.0) < 1e-6);
    CHECK(d[10 * n + 10] < 1.0f); /* something moved */
    free(d);
    gr_snow_deformation_destroy(s);
  }
  free(h);
  free(o);
}

static void run_plough(float **depth, float **rho, int steps, gr_snow_deformation **keep) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  gr_snow_deformation *s = make_sim(64, 48, 0.05, &p);
  *depth = *rho = NULL;
  if (!s)
    return;
  plough(s, steps, 1.5, 1.0 / 60.0);
  *depth = get(s, GR_FIELD_SNOW_DEPTH, 64 * 48);
  *rho = get(s, GR_FIELD_SNOW_DENSITY, 64 * 48);
  if (keep)
    *keep = s;
  else
    gr_snow_deformation_destroy(s);
}

static void test_determinism(void) {
  float *a, *ar, *b, *br;
  run_plough(&a, &ar, 60, NULL);
  run_plough(&b, &br, 60, NULL);
  if (a && b) {
    CHECK(memcmp(a, b, 64 * 48 * sizeof(float)) == 0);
    CHECK(memcmp(ar, br, 64 * 48 * sizeof(float)) == 0);
  }
  free(a), free(ar), free(b), free(br);
}

static void test_checkpoint(void) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  gr_snow_deformation *s = make_sim(64, 48, 0.05, &p);
  if (!s)
    return;
  plough(s, 10, 1.5, 1.0 / 60.0);
  size_t bytes = 0;
  CHECK(gr_snow_deformation_state_size(s, &bytes) == GR_OK && bytes > 0);
  void *buf = malloc(bytes);
  CHECK(gr_snow_deformation_state_save(s, buf, bytes) == GR_OK);
  /* The same 10 more steps twice: from the live state and from the loaded one. */
  test_mesh box;
  mesh_box(&box, 0.3, 0.2, 0.25);
  double v[3] = {1.5, 0.0, 0.0};
  float *after[2];
  gr_snow_deformation_ledger l[2];
  for (int run = 0; run < 2; ++run) {
    if (run == 1)
      CHECK(gr_snow_deformation_state_load(s, buf, bytes) == GR_OK);
    for (int k = 0; k < 10; ++k) {
      mesh_pose(&box, 1.0 + 0.025 * k, 1.2, 0.55);
      CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, v) == GR_OK);
      CHECK(gr_snow_deformation_step(s, 1.0 / 60.0) == GR_OK);
    }
    after[run] = get(s, GR_FIELD_SNOW_DEPTH, 64 * 48);
    CHECK(gr_snow_deformation_ledger_get(s, &l[run]) == GR_OK);
  }
  CHECK(memcmp(after[0], after[1], 64 * 48 * sizeof(float)) == 0);
  CHECK(l[0].steps == 20 && l[1].steps == 20 && l[0].snow_mass == l[1].snow_mass);
  CHECK(gr_snow_deformation_state_load(s, buf, bytes - 1) == GR_ERR_INVALID_ARGUMENT);
  ((unsigned char *)buf)[0] ^= 0xff;
  CHECK(gr_snow_deformation_state_load(s, buf, bytes) == GR_ERR_FORMAT);
  CHECK(strlen(gr_snow_deformation_last_error(s)) > 10);
  free(after[0]), free(after[1]), free(buf);
  mesh_free(&box);
  gr_snow_deformation_destroy(s);
}

/* The force on a box ploughing one step: opposite the motion, growing with
 * speed and density, zero without contact. */
static double force_of(double speed, double density, double z) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.initial_density = density;
  gr_snow_deformation *s = make_sim(64, 48, 0.05, &p);
  if (!s)
    return NAN;
  test_mesh box;
  mesh_box(&box, 0.3, 0.2, 0.25);
  mesh_pose(&box, 1.0, 1.2, z);
  double v[3] = {speed, 0.0, 0.0}, f[3] = {0, 0, 0}, area = -1.0;
  CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, v) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 1.0 / 60.0) == GR_OK);
  CHECK(gr_snow_deformation_object_forces(s, f, &area, 1) == GR_OK);
  CHECK(f[1] == 0.0 && f[2] == 0.0);
  if (z > 1.0)
    CHECK(area == 0.0);
  mesh_free(&box);
  gr_snow_deformation_destroy(s);
  return f[0];
}

static void test_force(void) {
  double f1 = force_of(1.0, 150.0, 0.55), f2 = force_of(2.0, 150.0, 0.55);
  double f3 = force_of(1.0, 300.0, 0.55), f0 = force_of(1.0, 150.0, 5.0);
  printf("force: %.4g N at 1 m/s, %.4g N at 2 m/s, %.4g N at rho 300, %.4g without contact\n", f1,
         f2, f3, f0);
  /* m v / dt, m = D rho dx dy over the 13 x 9 points under the box (edges
   * included): 117 * 0.0025 m^2 * 0.2 m * 150 kg/m^3 * 60/s * 1 m/s */
  CHECK_NEAR(f1, -117 * 0.0025 * 0.2 * 150.0 * 60.0, 1e-3 * 526.5);
  CHECK_NEAR(f2, 2.0 * f1, 1e-6 * 1053.0);
  CHECK_NEAR(f3, 2.0 * f1, 1e-6 * 1053.0);
  CHECK(f2 < f1 && f3 < f1 && f1 < 0.0);
  CHECK(f0 == 0.0);
}

static void test_errors(void) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  gr_grid g = {.nx = 32, .ny = 32, .dx = 0.05, .dy = 0.05};
  gr_snow_deformation *s = NULL;
  p.max_slope = -1.0;
  CHECK(gr_snow_deformation_create(ctx, &g, &p, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  CHECK(strstr(gr_last_error(ctx), "MaxSlope") != NULL);
  gr_snow_deformation_params_init(&p);
  gr_grid piece = g; /* a piece with a neighbour to the east and no ring */
  piece.global_nx = 64;
  CHECK(gr_snow_deformation_create(ctx, &piece, &p, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  CHECK(strstr(gr_last_error(ctx), "ghost ring") != NULL);
  CHECK(gr_snow_deformation_create(ctx, &g, &p, &s) == GR_OK);
  if (!s)
    return;
  /* NaN elevation: refused with the point named; the state is kept. */
  float *e = calloc(32 * 32, sizeof(float));
  e[3 * 32 + 5] = NAN;
  CHECK(gr_snow_deformation_set_field(s, GR_FIELD_ELEVATION, e) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_snow_deformation_last_error(s), "elevation") &&
        strstr(gr_snow_deformation_last_error(s), "(5, 3)"));
  e[3 * 32 + 5] = 50.0f; /* density outside the range */
  CHECK(gr_snow_deformation_set_field(s, GR_FIELD_SNOW_DENSITY, e) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_snow_deformation_set_field(s, GR_FIELD_VELOCITY, e) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_snow_deformation_get_field(s, GR_FIELD_VELOCITY, e) == GR_ERR_INVALID_ARGUMENT);
  /* An open mesh: one triangle gone. */
  test_mesh box;
  mesh_box(&box, 0.2, 0.2, 0.2);
  box.m.ntriangles = 11;
  CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(gr_snow_deformation_last_error(s), "Object 0") != NULL);
  box.m.ntriangles = 12;
  double vbad[3] = {NAN, 0, 0};
  CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, vbad) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_snow_deformation_set_objects(s, &box.m, -1, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_snow_deformation_step(s, 0.0) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_snow_deformation_step(s, NAN) == GR_ERR_INVALID_ARGUMENT);
  double f[6];
  CHECK(gr_snow_deformation_object_forces(s, f, NULL, 2) == GR_ERR_INVALID_ARGUMENT);
  /* An object far outside the grid: accepted, no contact, nothing changes. */
  mesh_pose(&box, 100.0, -50.0, 0.3);
  CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, NULL) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.1) == GR_OK);
  double area = -1.0;
  CHECK(gr_snow_deformation_object_forces(s, f, &area, 1) == GR_OK && area == 0.0);
  float *d = get(s, GR_FIELD_SNOW_DEPTH, 32 * 32), *c = get(s, GR_FIELD_CONTACT, 32 * 32);
  int changed = 0, touched = 0;
  for (int k = 0; k < 32 * 32; ++k)
    changed += d[k] != 0.5f, touched += c[k] != 0.0f;
  CHECK(changed == 0 && touched == 0);
  /* The next step after the errors works and presses. */
  mesh_pose(&box, 0.8, 0.8, 0.5);
  CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, NULL) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.1) == GR_OK);
  CHECK(gr_snow_deformation_object_forces(s, f, &area, 1) == GR_OK && area > 0.1);
  CHECK(strcmp(gr_snow_deformation_last_error(s), "") != 0); /* kept from before */
  mesh_free(&box);
  free(e), free(d), free(c);
  gr_snow_deformation_destroy(s);
}

/* A box of 12 triangles over most of a 200 x 150 grid: each triangle of
 * the raster's scatter covers thousands of points (the large-triangle case
 * of one work-item per triangle); the imprint is still exactly the points
 * under the box (its sides lie half a cell off the points), each pressed by
 * the 0.2 m overlap. */
static void test_raster_large(void) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  gr_snow_deformation *s = make_sim(200, 150, 0.01, &p);
  if (!s)
    return;
  test_mesh box;
  mesh_box(&box, 0.9, 0.6, 0.15);
  mesh_pose(&box, 1.005, 0.755, 0.3 + 0.15); /* x 0.105..1.905, y 0.155..1.355 */
  CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, NULL) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.05) == GR_OK);
  float *o = get(s, GR_FIELD_OVERLAP, 200 * 150);
  int inside = 0, wrong = 0;
  for (int j = 0; j < 150; ++j)
    for (int i = 0; i < 200; ++i) {
      int under = i >= 11 && i <= 190 && j >= 16 && j <= 135;
      float d = o[j * 200 + i];
      inside += d > 0.0f;
      wrong += under ? fabsf(d - 0.2f) > 1e-5f : d != 0.0f;
    }
  printf("raster, large triangles: %d points pressed (180 x 120 = 21600), %d wrong\n", inside,
         wrong);
  CHECK(inside == 21600 && wrong == 0);
  free(o);
  mesh_free(&box);
  gr_snow_deformation_destroy(s);
}

/* Two boxes pressed straight down at once, far apart: each leaves its own
 * imprint, gets its own contact area and force, and the ledger closes. */
static void test_two_objects(void) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  int nx = 64, ny = 48;
  double dx = 0.05;
  gr_snow_deformation *s = make_sim(nx, ny, dx, &p);
  if (!s)
    return;
  test_mesh a, b;
  mesh_box(&a, 0.2, 0.2, 0.25);
  mesh_box(&b, 0.3, 0.15, 0.25);
  mesh_pose(&a, 0.8, 1.2, 0.35 + 0.25); /* bottom at 0.35 m */
  mesh_pose(&b, 2.3, 1.0, 0.25 + 0.25); /* bottom at 0.25 m */
  gr_mesh m[2] = {a.m, b.m};
  double v[6] = {0.0, 0.0, -1.0, 0.5, 0.0, -0.5};
  CHECK(gr_snow_deformation_set_objects(s, m, 2, v) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.1) == GR_OK);
  float *h = get(s, GR_FIELD_SNOW_SURFACE, nx * ny);
  double f[6], area[2];
  CHECK(gr_snow_deformation_object_forces(s, f, area, 2) == GR_OK);
  int in_a = 0, in_b = 0, bad = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      double x = i * dx, y = j * dx, hv = h[j * nx + i];
      if (fabs(x - 0.8) <= 0.2 - 1e-6 && fabs(y - 1.2) <= 0.2 - 1e-6)
        ++in_a, bad += hv > 0.35 + 1e-3;
      if (fabs(x - 2.3) <= 0.3 - 1e-6 && fabs(y - 1.0) <= 0.15 - 1e-6)
        ++in_b, bad += hv > 0.25 + 1e-3;
    }
  gr_snow_deformation_ledger l;
  CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK);
  printf("two objects: %d and %d points under them, %d above their undersides; areas %.4g and "
         "%.4g m^2; forces z %.4g and x %.4g N; mass error %.3g, %d talus iterations\n",
         in_a, in_b, bad, area[0], area[1], f[2], f[3], fabs(l.balance_error) / l.initial_mass,
         l.relax_iterations);
  CHECK(in_a > 0 && in_b > 0 && bad == 0);
  /* Contact counts the points within the gap of the underside: the box
   * covers (7 or 9) x (9 or 7) grid points, edges included. */
  CHECK_NEAR(area[0], 9 * 9 * dx * dx, 1e-9);
  CHECK_NEAR(area[1], 13 * 7 * dx * dx, 1e-9);
  CHECK(f[2] > 0.0 && f[0] == 0.0 && f[3] < 0.0 && f[5] > 0.0);
  CHECK(fabs(l.balance_error) / l.initial_mass < 1e-6);
  CHECK(fabs(l.volume_error) / l.initial_volume < 1e-6);
  free(h);
  mesh_free(&a);
  mesh_free(&b);
  gr_snow_deformation_destroy(s);
}

/* The trench of a box dragged along y = 1.2 m from x = 0.6 to x0_end at
 * speed * dt per step (a fraction of its 0.6 m length), then lifted off
 * for one more step: surfaces per column. Returns the surface. */
static float *drag_with(int steps, double dt, double speed, int *iterations, int blocked, int group,
                        int max_iterations, double slump) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.slump_speed = slump;             /* 0: instant, the talus' own iterations */
  p.initial_density = p.max_density; /* dense snow: all of it is displaced */
  if (max_iterations >= 0)
    p.max_relax_iterations = max_iterations;
  gr_snow_deformation *s = make_sim(64, 48, 0.05, &p);
  if (!s)
    return NULL;
  if (blocked >= 0)
    gr_snow_deformation_set_blocked(s, blocked);
  if (group >= 0)
    gr_snow_deformation_set_group(s, group);
  test_mesh box;
  mesh_box(&box, 0.3, 0.2, 0.25);
  double v[3] = {speed, 0.0, 0.0};
  int most = 0;
  for (int k = 1; k <= steps; ++k) {
    mesh_pose(&box, 0.6 + speed * dt * k, 1.2, 0.3 + 0.25);
    CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, v) == GR_OK);
    CHECK(gr_snow_deformation_step(s, dt) == GR_OK);
    gr_snow_deformation_ledger l;
    CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK);
    most = l.relax_iterations > most ? l.relax_iterations : most;
  }
  CHECK(gr_snow_deformation_set_objects(s, NULL, 0, NULL) == GR_OK);
  CHECK(gr_snow_deformation_step(s, dt) == GR_OK);
  if (iterations)
    *iterations = most;
  float *h = get(s, GR_FIELD_SNOW_SURFACE, 64 * 48);
  float *r = get(s, GR_FIELD_SNOW_DENSITY, 64 * 48);
  h = realloc(h, 2 * 64 * 48 * sizeof(float));
  if (h && r)
    memcpy(h + 64 * 48, r, 64 * 48 * sizeof(float)); /* the densities after the surface */
  free(r);
  mesh_free(&box);
  gr_snow_deformation_destroy(s);
  return h;
}

static float *drag(int steps, double dt, double speed, int *iterations) {
  return drag_with(steps, dt, speed, iterations, -1, -1, -1, 0.0);
}

/* The talus in blocks of iterations per launch (the GPU's way) and in two
 * launches per iteration (the CPU's way) give the same bits, converged
 * (the default cap) or cut short every step (8 iterations), instant or
 * on a SlumpSpeed's reach (2 m/s); without the one-group tail, which this
 * grid would otherwise run whole. */
static void test_blocked(void) {
  for (int k = 0; k < 4; ++k) {
    int its[2] = {0, 0}, max = (k & 1) ? 8 : -1;
    double slump = (k & 2) ? 2.0 : 0.0;
    float *a = drag_with(30, 1.0 / 60.0, 1.5, &its[0], 0, 0, max, slump);
    float *b = drag_with(30, 1.0 / 60.0, 1.5, &its[1], 1, 0, max, slump);
    if (!a || !b) {
      free(a), free(b);
      return;
    }
    int differ = 0;
    for (int c = 0; c < 2 * 64 * 48; ++c)
      differ += memcmp(&a[c], &b[c], sizeof(float)) != 0;
    printf("blocked talus (cap %d, SlumpSpeed %g): %d of %d values differ; up to %d and %d "
           "iterations a step\n",
           max, slump, differ, 2 * 64 * 48, its[0], its[1]);
    /* The blocked launches are checked every 8 iterations, the others every
     * 4: the counts agree to that (the instant drag's happen to be equal). */
    CHECK(differ == 0 && abs(its[0] - its[1]) < 8 && (slump > 0.0 || its[0] == its[1]) &&
          its[0] > 4);
    free(a), free(b);
  }
}

/* The talus' tail in one work-group gives the bits and the iteration
 * counts of the launches it replaces, after each kind of launch (blocked
 * or not), converged or cut short every step by a cap that is not a
 * multiple of the check's stride (7), instant or on a SlumpSpeed's reach. */
static void test_group(void) {
  for (int k = 0; k < 8; ++k) {
    int blocked = k & 1, max = (k & 2) ? 7 : -1, its[2] = {0, 0};
    double slump = (k & 4) ? 2.0 : 0.0;
    float *a = drag_with(30, 1.0 / 60.0, 1.5, &its[0], blocked, 0, max, slump);
    float *b = drag_with(30, 1.0 / 60.0, 1.5, &its[1], blocked, 1, max, slump);
    if (!a || !b) {
      free(a), free(b);
      return;
    }
    int differ = 0;
    for (int c = 0; c < 2 * 64 * 48; ++c)
      differ += memcmp(&a[c], &b[c], sizeof(float)) != 0;
    printf("one-group tail (blocked %d, cap %d, SlumpSpeed %g): %d of %d values differ; up to %d "
           "and %d iterations a step\n",
           blocked, max, slump, differ, 2 * 64 * 48, its[0], its[1]);
    CHECK(differ == 0 && its[0] == its[1] && its[0] > 4);
    free(a), free(b);
  }
}

/* A trail in dense snow (all of the overlap displaced): every column the
 * box crossed from x = 0.5 m to where its back stopped (1.8 m) keeps a
 * trench below the initial surface along the path after the object has
 * gone, and the front bulge lies ahead. With horizontal motion the
 * direction weights give the side contour nothing (s_w = max(0, v . w),
 * r = 0), so the rims are the talus of the bulge as it is pushed along:
 * beside the path from where the box first stood (its front at 0.925 m:
 * the snow of that first press all went ahead) on; under the last imprint
 * the bulge slumps back in. */
static void test_trail(void) {
  int its = 0;
  float *h = drag(60, 1.0 / 60.0, 1.5, &its); /* 0.025 m a step, to x = 2.1 m */
  if (!h)
    return;
  int nx = 64, trench = 0, rim = 0, cols = 0, rim_cols = 0;
  double shallowest = 1.0, bulge = 0.0;
  for (int i = (int)ceil(0.5 / 0.05); i <= (int)floor(1.75 / 0.05); ++i) {
    ++cols;
    double centre = h[24 * nx + i], top = 0.0;
    for (int j = 0; j < 48; ++j)
      top = fmax(top, h[j * nx + i]);
    trench += centre < 0.5 - 0.05;
    if (centre >= 0.5 - 0.05)
      printf("trail: column %d (x %.2f m) centre %.4f m\n", i, i * 0.05, centre);
    if (i * 0.05 >= 0.95) {
      ++rim_cols;
      rim += top > 0.5 + 0.005;
    }
    shallowest = fmin(shallowest, 0.5 - centre);
  }
  for (int i = (int)ceil(2.4 / 0.05); i < nx; ++i)
    for (int j = 0; j < 48; ++j)
      bulge = fmax(bulge, h[j * nx + i] - 0.5);
  printf("trail: %d columns, %d with a trench (shallowest %.4g m), %d of %d with a rim; front "
         "bulge %.4g m; up to %d talus iterations a step\n",
         cols, trench, shallowest, rim, rim_cols, bulge, its);
  CHECK(cols == 26 && trench == cols && rim_cols == 17 && rim == rim_cols);
  CHECK(bulge > 0.05);
  free(h);
}

/* 10 steps of dt and 5 of 2 dt, the object at the same times and places:
 * the trench ends within one cell of each other. */
static void test_time_step(void) {
  float *a = drag(10, 1.0 / 60.0, 3.0, NULL), *b = drag(5, 2.0 / 60.0, 3.0, NULL);
  if (!a || !b) {
    free(a), free(b);
    return;
  }
  int nx = 64, lo[2] = {nx, nx}, hi[2] = {-1, -1}, n[2] = {0, 0};
  for (int r = 0; r < 2; ++r) {
    const float *h = r ? b : a;
    for (int j = 0; j < 48; ++j)
      for (int i = 0; i < nx; ++i)
        if (h[j * nx + i] < 0.5f - 0.05f) {
          ++n[r];
          lo[r] = i < lo[r] ? i : lo[r];
          hi[r] = i > hi[r] ? i : hi[r];
        }
  }
  printf("time step: trench x %d..%d (%d points) with dt, %d..%d (%d points) with 2 dt\n", lo[0],
         hi[0], n[0], lo[1], hi[1], n[1]);
  CHECK(n[0] > 0 && n[1] > 0);
  CHECK(abs(lo[0] - lo[1]) <= 1 && abs(hi[0] - hi[1]) <= 1);
  CHECK(abs(n[0] - n[1]) <= 0.1 * n[0]);
  free(a), free(b);
}

/* A box the size of one point pressed into that point's snow, one quantum
 * (2^-20 m) deep, on bare ground: the quantum displaced, shared over the 8
 * contour points, is an eighth of a quantum each and rounds to nothing
 * (it waits as pending snow); the bare contour stays bare and its density
 * finite (it was 0/0 = NaN, found by the accumulation demo's sledge beside
 * bare ground), and the ledger closes. */
static void test_bare_ground(void) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.initial_density = p.max_density; /* all of the overlap displaced */
  gr_snow_deformation *s = make_sim(40, 40, 0.05, &p);
  if (!s)
    return;
  float *d0 = calloc(40 * 40, sizeof(float));
  d0[20 * 40 + 20] = 1.0f / 1048576.0f;
  CHECK(gr_snow_deformation_set_field(s, GR_FIELD_SNOW_DEPTH, d0) == GR_OK);
  test_mesh box;
  mesh_box(&box, 0.02, 0.02, 0.1);
  mesh_pose(&box, 20 * 0.05, 20 * 0.05, 0.1 - 0.05); /* its bottom 5 cm below the ground */
  double v[3] = {0.0, 0.0, -1.0};
  CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, v) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.1) == GR_OK);
  float *rho = get(s, GR_FIELD_SNOW_DENSITY, 40 * 40), *d = get(s, GR_FIELD_SNOW_DEPTH, 40 * 40);
  int bad = 0;
  for (int c = 0; c < 40 * 40; ++c)
    bad += !(rho[c] >= 100.0f && rho[c] <= 400.0f) || !(d[c] >= 0.0f);
  gr_snow_deformation_ledger l;
  CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK);
  printf("bare ground: %d points with a density or depth out of range; displaced %.3g m^3, "
         "volume %.6g of %.6g, mass error %.3g kg\n",
         bad, l.displaced_volume, l.snow_volume, l.initial_volume, l.balance_error);
  CHECK(bad == 0);
  CHECK(l.displaced_volume > 0.0);
  CHECK(isfinite(l.balance_error) && fabs(l.snow_volume - l.initial_volume) <= 1e-12);
  free(rho), free(d), free(d0);
  mesh_free(&box);
  gr_snow_deformation_destroy(s);
}

/* Snow slides in under an object but never up to it: snow on a ledge 0.5 m
 * high, a box hovering beside it with its underside 0.3 m above the lower
 * ground. The ledge's snow falls into the space under the box, which fills
 * to the box's underside less the clearance (twice
 * GR_SNOW_DEFORMATION_CONTACT_GAP) and no higher, so the talus neither
 * touches the box nor counts as contact. (The rule it replaced, no snow
 * into a point whose underside is below the giver's surface, left the
 * ledge full and the space empty: every giver stands above 0.3 m.) */
static void test_talus_room(void) {
  const int nx = 30, ny = 8, ledge = 9;
  const double dx = 0.1, under = 0.3;
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.initial_snow_depth = 0.0;
  p.slump_speed = 0.0; /* instant: the talus' own iterations */
  p.max_relax_iterations = 100000;
  p.relax_tolerance = 1e-5;
  gr_snow_deformation *s = make_sim(nx, ny, dx, &p);
  if (!s)
    return;
  float *g0 = calloc((size_t)nx * ny, sizeof(float)), *d0 = calloc((size_t)nx * ny, sizeof(float));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i <= ledge; ++i)
      g0[j * nx + i] = d0[j * nx + i] = 0.5f;
  CHECK(gr_snow_deformation_set_field(s, GR_FIELD_ELEVATION, g0) == GR_OK);
  CHECK(gr_snow_deformation_set_field(s, GR_FIELD_SNOW_DEPTH, d0) == GR_OK);
  test_mesh box; /* x from 0.95 (between the ledge and the next point) to 2.95 m */
  mesh_box(&box, 1.0, 0.6, 0.1);
  mesh_pose(&box, 1.95, 0.35, under + 0.1);
  double v[3] = {0.0, 0.0, 0.0};
  CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, v) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.1) == GR_OK);
  gr_snow_deformation_ledger l;
  CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK);
  float *h = get(s, GR_FIELD_SNOW_SURFACE, nx * ny), *c = get(s, GR_FIELD_CONTACT, nx * ny);
  double ceiling = under - 2.0 * GR_SNOW_DEFORMATION_CONTACT_GAP, highest = 0.0, worst = -1.0;
  double first = 0.0; /* the lowest of the first column under the box */
  int touching = 0;
  for (int j = 0; j < ny; ++j) {
    first = j == 0 ? h[j * nx + ledge + 1] : fmin(first, h[j * nx + ledge + 1]);
    for (int i = ledge + 1; i < nx; ++i) {
      highest = fmax(highest, h[j * nx + i]);
      touching += c[j * nx + i] != 0.0f;
    }
    /* the ledge's own pairs, whose lower end is not under the box */
    for (int i = 0; i < ledge; ++i)
      worst = fmax(worst, fabs(h[j * nx + i] - h[j * nx + i + 1]) - p.max_slope * dx);
  }
  printf("talus room: the first column under the box filled to %.4f m (ceiling %.4f m), the "
         "highest %.6f m; %d points in contact; ledge excess %.3g m; volume %.9g of %.9g; %d "
         "iterations\n",
         first, ceiling, highest, touching, worst, l.snow_volume, l.initial_volume,
         l.relax_iterations);
  CHECK(first > ceiling - 0.01);    /* the space under the box filled */
  CHECK(highest <= ceiling + 1e-6); /* and no higher than the clearance */
  CHECK(touching == 0);
  CHECK(worst <= 1e-4);
  CHECK(l.snow_volume == l.initial_volume);
  free(h), free(c), free(g0), free(d0);
  mesh_free(&box);
  gr_snow_deformation_destroy(s);
}

/* The underside of a posed mesh at the points of an nx x ny grid of
 * spacing dx (origin at point (0, 0)): the lowest crossing of each point's
 * vertical by a triangle, +inf where none crosses it (the core's raster,
 * on the host in double, for the checks below), but for the triangles
 * steeper than 10:1: at a sphere's silhouette a vertical line only grazes
 * it (a point exactly at r = R met the equator in double and missed it in
 * the core's floats). */
static void host_underside(const gr_mesh *m, int nx, int ny, double dx, double *u) {
  const double *t = m->transform;
  for (int c = 0; c < nx * ny; ++c)
    u[c] = INFINITY;
  for (int k = 0; k < m->ntriangles; ++k) {
    double p[3][3];
    for (int a = 0; a < 3; ++a) {
      const float *v = m->vertices + 3 * m->triangles[3 * k + a];
      for (int r = 0; r < 3; ++r)
        p[a][r] = t[r] * v[0] + t[4 + r] * v[1] + t[8 + r] * v[2] + t[12 + r];
    }
    double area =
        (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
    double e1[3], e2[3];
    for (int r = 0; r < 3; ++r)
      e1[r] = p[1][r] - p[0][r], e2[r] = p[2][r] - p[0][r];
    double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2];
    if (fabs(area) < 0.1 * sqrt(cx * cx + cy * cy + area * area))
      continue;
    double lo[2], hi[2];
    for (int r = 0; r < 2; ++r) {
      lo[r] = fmin(p[0][r], fmin(p[1][r], p[2][r]));
      hi[r] = fmax(p[0][r], fmax(p[1][r], p[2][r]));
    }
    int i0 = (int)ceil(lo[0] / dx), i1 = (int)floor(hi[0] / dx);
    int j0 = (int)ceil(lo[1] / dx), j1 = (int)floor(hi[1] / dx);
    for (int j = j0 < 0 ? 0 : j0; j <= j1 && j < ny; ++j)
      for (int i = i0 < 0 ? 0 : i0; i <= i1 && i < nx; ++i) {
        double x = i * dx, y = j * dx, w[3];
        for (int a = 0; a < 3; ++a) {
          const double *b = p[(a + 1) % 3], *c = p[(a + 2) % 3];
          w[a] = ((b[0] - x) * (c[1] - y) - (b[1] - y) * (c[0] - x)) / area;
        }
        if (w[0] < -1e-9 || w[1] < -1e-9 || w[2] < -1e-9)
          continue;
        u[j * nx + i] = fmin(u[j * nx + i], w[0] * p[0][2] + w[1] * p[1][2] + w[2] * p[2][2]);
      }
  }
}

/* Snow is never put under an object (the header's step 5): a sphere of
 * R 0.4 m at rho_max (all of its overlap displaced) presses 0.2 m into 0.5
 * m of snow over 1 s (steps of dt), or ploughs at 1 m/s with its centre 0.1
 * m above the snow, 0.3 m deep. After every step, at every point the sphere
 * covers, the snow surface stays below its underside (within 1e-4 m: the
 * press leaves it less than a quantum above), and the ledger closes. Before
 * the fix the displaced snow went to the contour ring however little room
 * the overhang left above it: 11 of the 20 outputs of the press at 1/60 s
 * had the surface more than 1 mm above the underside at points with
 * neither contact nor overlap, 10.9 mm at worst (10.5 at 1/120 s). */
static void press_under(double dt, int plough, double *worst, int *above_mm, int *steps_out,
                        double *vol_err, double *mass_err) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.initial_density = p.max_density;
  const double dx = 0.025, R = 0.4;
  const int nx = plough ? 121 : 81, ny = 81, n = nx * ny;
  *worst = INFINITY, *above_mm = 0, *steps_out = 0;
  gr_snow_deformation *s = make_sim(nx, ny, dx, &p);
  if (!s)
    return;
  test_mesh sp;
  mesh_sphere(&sp, R, 48, 96);
  double *u = malloc((size_t)n * sizeof(double));
  float *h = malloc((size_t)n * sizeof(float));
  double v[3] = {plough ? 1.0 : 0.0, 0.0, plough ? 0.0 : -0.2};
  int steps = (int)lround((plough ? 1.6 : 1.0) / dt);
  *worst = -INFINITY;
  for (int k = 1; k <= steps && u && h; ++k) {
    double x = plough ? 0.5 + v[0] * dt * k : 1.0, z = plough ? 0.6 : 0.9 + v[2] * dt * k;
    mesh_pose(&sp, x, 1.0, z);
    CHECK(gr_snow_deformation_set_objects(s, &sp.m, 1, v) == GR_OK);
    if (gr_snow_deformation_step(s, dt) != GR_OK) {
      CHECK_MSG(0, "step %d: %s", k, gr_snow_deformation_last_error(s));
      break;
    }
    CHECK(gr_snow_deformation_get_field(s, GR_FIELD_SNOW_SURFACE, h) == GR_OK);
    host_underside(&sp.m, nx, ny, dx, u);
    double step_worst = -INFINITY;
    for (int c = 0; c < n; ++c)
      if (isfinite(u[c]))
        step_worst = fmax(step_worst, h[c] - u[c]);
    *worst = fmax(*worst, step_worst);
    *above_mm += step_worst > 1e-3;
    ++*steps_out;
  }
  gr_snow_deformation_ledger l;
  CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK);
  *vol_err = fabs(l.volume_error) / l.initial_volume;
  *mass_err = fabs(l.balance_error) / l.initial_mass;
  free(u), free(h);
  mesh_free(&sp);
  gr_snow_deformation_destroy(s);
}

static void test_never_under(void) {
  const struct {
    double dt;
    int plough;
  } runs[] = {{1.0 / 60.0, 0}, {1.0 / 120.0, 0}, {1.0 / 60.0, 1}};
  for (int r = 0; r < 3; ++r) {
    double worst, ve, me;
    int above, steps;
    press_under(runs[r].dt, runs[r].plough, &worst, &above, &steps, &ve, &me);
    printf("never under: %s at dt 1/%.0f s: the surface at most %.3g m above the underside "
           "(%d of %d steps more than 1 mm); volume error %.3g, mass error %.3g\n",
           runs[r].plough ? "plough" : "press", 1.0 / runs[r].dt, worst, above, steps, ve, me);
    CHECK(steps > 0);
    CHECK_MSG(worst <= 1e-4, "snow %.3g m above the underside", worst);
    CHECK(ve < 1e-12 && me < 1e-6);
  }
}

/* The bulldozed berm (SlumpSpeed, the header's talus): a box 0.4 m long, 0.6
 * m wide and 0.4 m high (its top at 0.7 m), or a sphere of R 0.3 m, its
 * bottom 0.3 m above the ground, pushed at 1 m/s for 1 s through 0.5 m of
 * snow of 350 kg/m^3 with the default SlumpSpeed (2 m/s) and MaxSlope (0.6),
 * on a grid of dx. From t = 0.5 s: the bulge (the highest snow ahead of the
 * object's front above the 0.5 m surface), the pushed snow's volume V (all
 * snow above 0.5 m) and the steep pairs: 8-neighbours ahead of the
 * object's front, neither under it (contact), beyond MaxSlope by more than
 * 1 mm, both ends farther than a slump distance (SlumpSpeed dt, plus a
 * point) from every point the object fed this step (the ring of its
 * overlap). */
typedef struct berm {
  double bulge;            /* m above the snow surface, the most from t = 0.5 s */
  double worst_over_bound; /* the most bulge - bound (m; bound: see test_berm) */
  int steep;               /* steep pairs, summed over the steps */
  double steep_excess;     /* the largest excess among them (m) */
  double vol_err;          /* relative */
} berm;

static void push_berm(double dx, int sphere, berm *out) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.initial_density = 350.0;
  const double dt = 1.0 / 60.0, speed = 1.0, slope = p.max_slope, half = sphere ? 0.3 : 0.2;
  const double reach = p.slump_speed * dt + dx;
  const int nx = (int)lround(3.0 / dx) + 1, ny = (int)lround(2.0 / dx) + 1, n = nx * ny;
  memset(out, 0, sizeof(*out));
  out->worst_over_bound = -INFINITY;
  gr_snow_deformation *s = make_sim(nx, ny, dx, &p);
  if (!s)
    return;
  test_mesh ob;
  if (sphere)
    mesh_sphere(&ob, 0.3, 48, 96);
  else
    mesh_box(&ob, 0.2, 0.3, 0.2);
  double v[3] = {speed, 0.0, 0.0};
  float *h = malloc((size_t)n * sizeof(float)), *o = malloc((size_t)n * sizeof(float)),
        *c = malloc((size_t)n * sizeof(float));
  int *fed = malloc((size_t)n * 2 * sizeof(int));
  for (int k = 1; k <= 60 && h && o && c && fed; ++k) {
    double x = 0.5 + speed * dt * k, front = x + half;
    mesh_pose(&ob, x, 1.0, sphere ? 0.6 : 0.5);
    CHECK(gr_snow_deformation_set_objects(s, &ob.m, 1, v) == GR_OK);
    if (gr_snow_deformation_step(s, dt) != GR_OK) {
      CHECK_MSG(0, "step %d: %s", k, gr_snow_deformation_last_error(s));
      break;
    }
    if (k < 30)
      continue;
    CHECK(gr_snow_deformation_get_field(s, GR_FIELD_SNOW_SURFACE, h) == GR_OK);
    CHECK(gr_snow_deformation_get_field(s, GR_FIELD_OVERLAP, o) == GR_OK);
    CHECK(gr_snow_deformation_get_field(s, GR_FIELD_CONTACT, c) == GR_OK);
    double bulge = 0.0, vol = 0.0;
    int nfed = 0;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        double a = h[j * nx + i] - 0.5;
        vol += fmax(0.0, a) * dx * dx;
        if (i * dx > front)
          bulge = fmax(bulge, a);
        int f = 0;
        for (int dj = -1; dj <= 1 && o[j * nx + i] <= 0.0f; ++dj)
          for (int di = -1; di <= 1; ++di) {
            int a2 = i + di, b2 = j + dj;
            f |= a2 >= 0 && b2 >= 0 && a2 < nx && b2 < ny && o[b2 * nx + a2] > 0.0f;
          }
        if (f)
          fed[2 * nfed] = i, fed[2 * nfed + 1] = j, ++nfed;
      }
    /* A heap of height b whose slopes nowhere exceed MaxSlope S holds the
     * half cone about its top at least (the other half may lean on the
     * object): pi b^3 / (6 S^2) <= V; allowed: one slump distance of slope
     * at the fed points. */
    double bound = cbrt(6.0 * slope * slope * vol / M_PI) + slope * reach;
    out->bulge = fmax(out->bulge, bulge);
    out->worst_over_bound = fmax(out->worst_over_bound, bulge - bound);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (int q = 0; q < 4; ++q) { /* each pair once: E, NE, N, NW */
          int di = q == 0 ? 1 : q == 1 ? 1 : q == 2 ? 0 : -1, dj = q == 0 ? 0 : 1;
          int a = i + di, b = j + dj;
          if (a < 0 || b < 0 || a >= nx || b >= ny || c[j * nx + i] > 0.0f ||
              c[b * nx + a] > 0.0f || i * dx <= front || a * dx <= front)
            continue;
          double d = dx * sqrt((double)(di * di + dj * dj));
          double ex = fabs((double)h[j * nx + i] - h[b * nx + a]) - slope * d;
          if (ex <= 1e-3)
            continue;
          double near = INFINITY;
          for (int f = 0; f < nfed; ++f) {
            double d1 = hypot(fed[2 * f] - i, fed[2 * f + 1] - j) * dx;
            double d2 = hypot(fed[2 * f] - a, fed[2 * f + 1] - b) * dx;
            near = fmin(near, fmin(d1, d2));
          }
          if (near > reach) {
            ++out->steep;
            out->steep_excess = fmax(out->steep_excess, ex);
          }
        }
  }
  gr_snow_deformation_ledger l;
  CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK);
  out->vol_err = fabs(l.volume_error) / l.initial_volume;
  free(h), free(o), free(c), free(fed);
  mesh_free(&ob);
  gr_snow_deformation_destroy(s);
}

/* Before the fix (the talus cut to ceil(SlumpSpeed dt / dx) iterations a
 * step, which carry a flux that shrinks with dx) the box built a wall one
 * point thick: bulges of 0.88 m at dx 0.05 and 1.27 m at 0.025, far above
 * what the pushed snow could hold as a heap, with steep pairs all through
 * the berm; the sphere none. */
static void test_berm(void) {
  berm b[3];
  const double dx[3] = {0.05, 0.025, 0.025};
  for (int r = 0; r < 3; ++r) {
    push_berm(dx[r], r == 2, &b[r]);
    printf("berm: %s at dx %.3f m: bulge %.4f m (the heap bound %s by %.3g m), %d steep pairs "
           "beyond a slump distance of the fed points (the worst %.3g m over), volume error "
           "%.3g\n",
           r == 2 ? "sphere" : "box", dx[r], b[r].bulge,
           b[r].worst_over_bound > 0.0 ? "exceeded" : "kept", fabs(b[r].worst_over_bound),
           b[r].steep, b[r].steep_excess, b[r].vol_err);
    CHECK(b[r].bulge > 0.05); /* a heap there is */
    CHECK_MSG(b[r].worst_over_bound <= 0.0, "the bulge exceeds the heap bound by %.3g m",
              b[r].worst_over_bound);
    /* At dx 0.05 the box reaches a new column of points every third step
     * only, and the heap's toe, a point a step, lags the lump each press
     * sends down its face for that step: by less than one more talus
     * threshold (measured 1.8 cm). */
    if (dx[r] > 0.04)
      CHECK_MSG(b[r].steep_excess <= 0.6 * dx[r], "the toe stands %.3g m over MaxSlope",
                b[r].steep_excess);
    else
      CHECK_MSG(b[r].steep == 0, "%d steep pairs away from the fed points", b[r].steep);
    CHECK(b[r].vol_err < 1e-12);
  }
  double rel = fabs(b[0].bulge - b[1].bulge) / b[1].bulge;
  printf("berm: the box's bulge at dx 0.05 and 0.025 m %.1f %% apart\n", 100.0 * rel);
  CHECK_MSG(rel <= 0.10, "the bulge changes by %.1f %% when dx halves", 100.0 * rel);
}

/* Every OpenCL device here ploughs the same trail (the box drag of the
 * trail test, 40 steps, the talus converged each step): surfaces within
 * 1e-5 m of the first device's. Measured on the H200 against
 * PoCL: the same bits (divisions correctly rounded; 7.4e-5 m apart
 * without). On a machine with one device this says so and checks nothing. */
static void test_devices_agree(void) {
  int count = 0;
  gr_device_info infos[8];
  if (gr_device_list(infos, 8, &count) != GR_OK || count < 2) {
    printf("one OpenCL device: cross-device agreement not tested here\n");
    return;
  }
  gr_context *own = ctx;
  float *first = NULL;
  for (int d = 0; d < count && d < 8; ++d) {
    gr_context_options opt;
    gr_context_options_init(&opt);
    opt.device = infos[d].name;
    if (gr_context_create(&opt, &ctx) != GR_OK) {
      CHECK_MSG(0, "%s: %s", infos[d].name, gr_last_error(NULL));
      ctx = own;
      continue;
    }
    int its = 0;
    float *h = drag(40, 1.0 / 60.0, 1.5, &its);
    if (h && !first) {
      first = h;
    } else if (h) {
      double worst = 0.0, dense = 0.0;
      for (int c = 0; c < 64 * 48; ++c) {
        worst = fmax(worst, fabs((double)h[c] - first[c]));
        dense = fmax(dense, fabs((double)h[64 * 48 + c] - first[64 * 48 + c]));
      }
      printf("%s vs %s: surfaces differ by at most %.3g m, densities by %.3g kg/m^3 (up to %d "
             "talus iterations a step)\n",
             infos[d].name, infos[0].name, worst, dense, its);
      CHECK_MSG(worst <= 1e-5, "%s disagrees by %.3g m", infos[d].name, worst);
      free(h);
    }
    gr_context_release(ctx);
    ctx = own;
  }
  free(first);
}

static int stop_now(void *user, double t) {
  (void)t;
  return ++*(int *)user >= 2;
}

/* Every entry point once on a tiny grid (for valgrind). */
static void test_memcheck(void) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  gr_snow_deformation *s = make_sim(12, 10, 0.1, &p);
  if (!s)
    return;
  float f[120];
  for (int k = 0; k < 120; ++k)
    f[k] = 0.01f * (float)(k % 7);
  CHECK(gr_snow_deformation_set_field(s, GR_FIELD_ELEVATION, f) == GR_OK);
  test_mesh box;
  mesh_box(&box, 0.2, 0.2, 0.2);
  mesh_pose(&box, 0.5, 0.5, 0.6);
  double v[3] = {0.5, 0.1, -0.1}, force[3], area;
  CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, v) == GR_OK);
  int calls = 0;
  gr_snow_deformation_set_progress(s, stop_now, &calls);
  CHECK(gr_snow_deformation_step(s, 0.05) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.05) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.05) == GR_ERR_ABORTED);
  gr_snow_deformation_set_progress(s, NULL, NULL);
  CHECK(gr_snow_deformation_step(s, 0.05) == GR_OK);
  CHECK(gr_snow_deformation_object_forces(s, force, &area, 1) == GR_OK);
  gr_field outs[] = {GR_FIELD_SNOW_DEPTH, GR_FIELD_SNOW_SURFACE, GR_FIELD_SNOW_DENSITY,
                     GR_FIELD_OVERLAP,    GR_FIELD_CONTACT,      GR_FIELD_ELEVATION};
  for (int k = 0; k < 6; ++k)
    CHECK(gr_snow_deformation_get_field(s, outs[k], f) == GR_OK);
  gr_snow_deformation_ledger l;
  CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK && l.steps == 3);
  size_t bytes;
  CHECK(gr_snow_deformation_state_size(s, &bytes) == GR_OK);
  void *buf = malloc(bytes);
  CHECK(gr_snow_deformation_state_save(s, buf, bytes) == GR_OK);
  CHECK(gr_snow_deformation_state_load(s, buf, bytes) == GR_OK);
  CHECK(gr_snow_deformation_set_params(s, &p) == GR_OK);
  CHECK(gr_snow_deformation_reset(s) == GR_OK);
  CHECK(gr_snow_deformation_ledger_get(s, &l) == GR_OK && l.steps == 0);
  CHECK(gr_snow_deformation_step(s, 0.0) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_snow_deformation_set_objects(s, NULL, 0, NULL) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.05) == GR_OK);
  /* The host-side field check and the stage timing. */
  char m[256];
  CHECK(gr_snow_deformation_field_validate(&p, GR_FIELD_SNOW_DEPTH, f, 120, 12, m, sizeof(m)) ==
        GR_OK);
  f[13] = -1.0f;
  CHECK(gr_snow_deformation_field_validate(&p, GR_FIELD_SNOW_DEPTH, f, 120, 12, m, sizeof(m)) ==
            GR_ERR_INVALID_ARGUMENT &&
        strstr(m, "(1, 1)"));
  CHECK(gr_snow_deformation_field_validate(NULL, GR_FIELD_SNOW_DENSITY, f, 120, 12, m, sizeof(m)) ==
        GR_ERR_INVALID_ARGUMENT);
  gr_snow_deformation_timing tm;
  gr_snow_deformation_set_timing(s, 1);
  CHECK(gr_snow_deformation_set_objects(s, &box.m, 1, v) == GR_OK);
  CHECK(gr_snow_deformation_step(s, 0.05) == GR_OK);
  CHECK(gr_snow_deformation_timing_get(s, &tm) == GR_OK && tm.steps == 1 && tm.raster_ms >= 0.0 &&
        tm.relax_ms >= 0.0);
  gr_snow_deformation_set_timing(s, 0);
  CHECK(gr_snow_deformation_timing_get(s, &tm) == GR_OK && tm.steps == 0);
  CHECK(gr_snow_deformation_timing_get(NULL, &tm) == GR_ERR_INVALID_ARGUMENT);
  free(buf);
  mesh_free(&box);
  gr_snow_deformation_destroy(s);
  gr_snow_deformation_destroy(NULL);
  CHECK(strcmp(gr_snow_deformation_last_error(NULL), "") == 0);
}

/* ------------------------------------------------------------- pieces */

/* The whole domain for the split tests: 64 x 48 points of 5 cm, a bumpy
 * ground and snow of varying depth and density (so the first step's talus
 * runs over the whole domain, across the split). */
typedef struct domain {
  gr_grid g;
  float *b, *d, *r;
} domain;

static double hash01(int i, int j, unsigned seed) {
  unsigned h = (unsigned)i * 73856093u ^ (unsigned)j * 19349663u ^ seed * 83492791u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return (double)(h & 0xffffffu) / 16777216.0;
}

static domain make_domain(void) {
  domain dm;
  gr_grid g = {.nx = 64, .ny = 48, .dx = 0.05, .dy = 0.05, .x0 = -0.3, .y0 = 0.2};
  dm.g = g;
  size_t n = (size_t)g.nx * g.ny;
  dm.b = malloc(n * sizeof(float));
  dm.d = malloc(n * sizeof(float));
  dm.r = malloc(n * sizeof(float));
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      size_t c = (size_t)j * g.nx + i;
      double x = i * g.dx, y = j * g.dy;
      dm.b[c] = (float)(0.05 * sin(x / 0.7) * cos(y / 0.5) + 0.01 * hash01(i, j, 1));
      dm.d[c] = (float)(0.45 + 0.1 * hash01(i, j, 2));
      /* Two piles of 0.4 m more, astride the splits at x = 1.5 m and at
       * y = 1.3 m: their talus takes dozens of iterations in the first
       * step, across the split. */
      if ((abs(i - 30) <= 2 && abs(j - 12) <= 2) || (abs(i - 42) <= 2 && abs(j - 26) <= 2))
        dm.d[c] += 0.4f;
      dm.r[c] = (float)(130.0 + 60.0 * hash01(i, j, 3));
    }
  return dm;
}

static void free_domain(domain *dm) {
  free(dm->b), free(dm->d), free(dm->r);
}

/* The objects of the split tests at step k: a box dragged along x (pieces
 * split in x), or a sphere rolling north-east and a box pressed straight
 * down (pieces split in y); n objects, velocities v. */
typedef struct scene {
  int kind; /* 0: box along x; 1: sphere and box; 2: box along x, gone after 10 steps */
  double dt;
  test_mesh box, ball;
} scene;

static int scene_pose(scene *sc, int k, gr_mesh *m, double *v) {
  if (sc->kind == 2 && k >= 10)
    return 0;
  if (sc->kind != 1) {
    v[0] = 1.5, v[1] = 0.0, v[2] = 0.0;
    mesh_pose(&sc->box, (sc->kind == 2 ? 0.0 : 0.3) + 1.5 * sc->dt * k, 1.0,
              0.3 + 0.25); /* the domain's x0 = -0.3 */
    m[0] = sc->box.m;
    return 1;
  }
  v[0] = 0.4, v[1] = 1.2, v[2] = -0.2;
  mesh_pose(&sc->ball, 1.0 + 0.4 * sc->dt * k, 0.6 + 1.2 * sc->dt * k, 0.2 + 0.25 + 0.3);
  v[3] = 0.0, v[4] = 0.0, v[5] = -1.0;
  mesh_pose(&sc->box, 2.2, 1.35, 0.35 + 0.25); /* astride the split, 1.3 m from y0 */
  m[0] = sc->ball.m;
  m[1] = sc->box.m;
  return 2;
}

static void scene_init(scene *sc, int kind) {
  sc->kind = kind;
  sc->dt = 1.0 / 60.0;
  mesh_box(&sc->box, 0.3, 0.2, 0.25);
  mesh_sphere(&sc->ball, 0.3, 8, 12);
}

static void scene_free(scene *sc) {
  mesh_free(&sc->box);
  mesh_free(&sc->ball);
}

/* One piece: its grid, rings, local size and simulation. */
typedef struct piece {
  gr_grid g;
  int ring[4], nxl, nyl;
  gr_snow_deformation *s;
} piece;

static float *cut(const float *global, int gnx, int x0, int y0, int w, int h) {
  float *out = malloc((size_t)w * (size_t)h * sizeof(float));
  for (int j = 0; j < h; ++j)
    memcpy(out + (size_t)j * w, global + (size_t)(y0 + j) * gnx + x0, (size_t)w * sizeof(float));
  return out;
}

/* The ring make_piece asks for (grid.ghost). */
static int piece_ghost = GR_SNOW_DEFORMATION_GHOST;

static int make_piece(piece *p, const domain *dm, const gr_snow_deformation_params *prm, int i0,
                      int j0, int nx, int ny) {
  const int G = piece_ghost;
  memset(p, 0, sizeof(*p));
  p->g = dm->g;
  p->g.nx = nx, p->g.ny = ny, p->g.i0 = i0, p->g.j0 = j0;
  p->g.global_nx = dm->g.nx, p->g.global_ny = dm->g.ny, p->g.ghost = G;
  p->ring[0] = i0 > 0 ? G : 0;
  p->ring[1] = i0 + nx < dm->g.nx ? G : 0;
  p->ring[2] = j0 > 0 ? G : 0;
  p->ring[3] = j0 + ny < dm->g.ny ? G : 0;
  p->nxl = nx + p->ring[0] + p->ring[1];
  p->nyl = ny + p->ring[2] + p->ring[3];
  gr_status st = gr_snow_deformation_create(ctx, &p->g, prm, &p->s);
  CHECK_MSG(st == GR_OK, "piece: %s", gr_last_error(ctx));
  const float *fields[] = {dm->b, dm->d, dm->r};
  const gr_field names[] = {GR_FIELD_ELEVATION, GR_FIELD_SNOW_DEPTH, GR_FIELD_SNOW_DENSITY};
  for (int f = 0; st == GR_OK && f < 3; ++f) {
    float *local = cut(fields[f], dm->g.nx, i0 - p->ring[0], j0 - p->ring[2], p->nxl, p->nyl);
    st = gr_snow_deformation_set_field(p->s, names[f], local);
    CHECK_MSG(st == GR_OK, "piece field: %s", gr_snow_deformation_last_error(p->s));
    free(local);
  }
  return st == GR_OK;
}

static gr_snow_deformation *make_whole(const domain *dm, const gr_snow_deformation_params *prm) {
  gr_snow_deformation *s = NULL;
  gr_status st = gr_snow_deformation_create(ctx, &dm->g, prm, &s);
  CHECK_MSG(st == GR_OK, "whole: %s", gr_last_error(ctx));
  if (st == GR_OK)
    st = gr_snow_deformation_set_field(s, GR_FIELD_ELEVATION, dm->b);
  if (st == GR_OK)
    st = gr_snow_deformation_set_field(s, GR_FIELD_SNOW_DEPTH, dm->d);
  if (st == GR_OK)
    st = gr_snow_deformation_set_field(s, GR_FIELD_SNOW_DENSITY, dm->r);
  CHECK(st == GR_OK);
  return s;
}

/* Two threads, one piece each: an allreduce through a barrier (combined in
 * rank order, so both get the same bits) and a halo exchange through a
 * mailbox, which the core calls inside its steps. */
typedef struct runner {
  gr_test_team *t;
  int rank, side, steps, stop_at, calls, exchanges, taken, fail_exchange;
  piece *p;
  scene sc;
  gr_status st, last;
  gr_snow_deformation_ledger l;
  double force[6], area[2];
} runner;

static gr_status team_halo(void *s, int side, void *host, size_t bytes, int set) {
  return set ? gr_snow_deformation_halo_set(s, side, host, bytes)
             : gr_snow_deformation_halo_get(s, side, host, bytes);
}

static gr_status team_allreduce(void *user, double *values, int n, gr_reduce_op op) {
  runner *r = user;
  return gr_test_team_allreduce(r->t, r->rank, values, n, op);
}

/* From exchange fail_exchange on, every piece's exchange fails (after the
 * strips went through, so no piece waits for ever). */
static gr_status team_exchange(void *user) {
  runner *r = user;
  ++r->exchanges;
  gr_status st = gr_test_team_exchange(r->t, r->rank, r->p->s, team_halo);
  if (r->fail_exchange && r->exchanges >= r->fail_exchange)
    return GR_ERR_IO;
  return st;
}

static int stop_at_step(void *user, double time) {
  runner *r = user;
  (void)time;
  return ++r->calls >= r->stop_at;
}

/* Steps the piece through the scene until it has taken r->steps steps or a
 * step fails (GR_ERR_ABORTED after a stop); then the (collective) ledger
 * and the forces. */
/* The objects a scene has at its end. */
static int scene_objects(int kind) {
  return kind == 0 ? 1 : kind == 1 ? 2 : 0;
}

static void *runner_run(void *arg) {
  runner *r = arg;
  gr_mesh m[2];
  double v[6];
  gr_status st = GR_OK;
  for (int k = 0; st == GR_OK && k < r->steps; ++k) {
    int n = scene_pose(&r->sc, k, m, v);
    st = gr_snow_deformation_set_objects(r->p->s, m, n, v);
    if (st == GR_OK)
      st = gr_snow_deformation_step(r->p->s, r->sc.dt);
    if (st == GR_OK)
      ++r->taken;
  }
  r->last = st;
  gr_status s2 = gr_snow_deformation_ledger_get(r->p->s, &r->l);
  if (st == GR_OK)
    st = s2;
  if (st == GR_OK)
    st = gr_snow_deformation_object_forces(r->p->s, r->force, r->area, scene_objects(r->sc.kind));
  r->st = st;
  return NULL;
}

/* Runs both pieces on two threads; side0: piece 0's side toward piece 1. */
static void run_team(piece pc[2], runner rn[2], int side0, int kind, int steps, int stop_rank,
                     int stop_at, int fail_exchange) {
  gr_test_team t;
  gr_test_team_init(&t, 2, 32);
  for (int k = 0; k < 2; ++k) {
    memset(&rn[k], 0, sizeof(rn[k]));
    rn[k].t = &t;
    rn[k].rank = k;
    rn[k].side = k == 0 ? side0 : side0 ^ 1;
    rn[k].steps = steps;
    rn[k].fail_exchange = fail_exchange;
    rn[k].p = &pc[k];
    scene_init(&rn[k].sc, kind);
    size_t bytes = 0;
    CHECK(gr_snow_deformation_halo_size(pc[k].s, rn[k].side, &bytes) == GR_OK);
    CHECK(bytes > 0);
    gr_test_team_mail(&t, k, rn[k].side, bytes);
    gr_snow_deformation_set_allreduce(pc[k].s, team_allreduce, &rn[k]);
    gr_snow_deformation_set_halo_exchange(pc[k].s, team_exchange, &rn[k]);
    if (k == stop_rank) {
      rn[k].stop_at = stop_at;
      gr_snow_deformation_set_progress(pc[k].s, stop_at_step, &rn[k]);
    }
  }
  CHECK(t.bytes[0][rn[0].side] == t.bytes[1][rn[1].side]);
  gr_test_team_run(2, runner_run, rn, sizeof(rn[0]));
  for (int k = 0; k < 2; ++k) {
    gr_snow_deformation_set_progress(pc[k].s, NULL, NULL);
    scene_free(&rn[k].sc);
  }
  gr_test_team_destroy(&t);
}

/* The whole grid through the same scene. */
static void run_whole(gr_snow_deformation *s, int kind, int steps, gr_snow_deformation_ledger *l,
                      double *force, double *area) {
  scene sc;
  scene_init(&sc, kind);
  gr_mesh m[2];
  double v[6];
  int n = scene_objects(kind);
  for (int k = 0; k < steps; ++k) {
    n = scene_pose(&sc, k, m, v);
    CHECK(gr_snow_deformation_set_objects(s, m, n, v) == GR_OK);
    gr_status st = gr_snow_deformation_step(s, sc.dt);
    CHECK_MSG(st == GR_OK, "whole step %d: %s", k, gr_snow_deformation_last_error(s));
    if (st != GR_OK)
      break;
  }
  CHECK(gr_snow_deformation_ledger_get(s, l) == GR_OK);
  CHECK(gr_snow_deformation_object_forces(s, force, area, n) == GR_OK);
  scene_free(&sc);
}

/* The own points of piece p whose field f differs in any bit from the
 * whole grid's. */
static long piece_diff(piece *p, gr_snow_deformation *whole, const domain *dm, gr_field f) {
  float *w = get(whole, f, dm->g.nx * dm->g.ny), *v = get(p->s, f, p->g.nx * p->g.ny);
  long diff = 0;
  for (int j = 0; j < p->g.ny; ++j)
    for (int i = 0; i < p->g.nx; ++i)
      diff += memcmp(&v[(size_t)j * p->g.nx + i],
                     &w[(size_t)(p->g.j0 + j) * dm->g.nx + p->g.i0 + i], sizeof(float)) != 0;
  free(w), free(v);
  return diff;
}

/* Every own point of every field, the ledger, the forces and the contact
 * areas of both pieces against the whole grid's, to the bit. */
static void check_pieces(piece pc[2], runner rn[2], gr_snow_deformation *whole, const domain *dm,
                         const gr_snow_deformation_ledger *lw, const double *fw, const double *aw,
                         int nobj, const char *what) {
  const gr_field fields[] = {GR_FIELD_SNOW_DEPTH, GR_FIELD_SNOW_DENSITY, GR_FIELD_SNOW_SURFACE,
                             GR_FIELD_OVERLAP, GR_FIELD_CONTACT};
  long total = 0;
  for (int k = 0; k < 2; ++k) {
    for (size_t f = 0; f < sizeof(fields) / sizeof(fields[0]); ++f) {
      long d = piece_diff(&pc[k], whole, dm, fields[f]);
      CHECK_MSG(d == 0, "%s: piece %d: %ld points of %s differ from the whole grid", what, k, d,
                gr_field_name(fields[f]));
      total += d;
    }
    const gr_snow_deformation_ledger *l = &rn[k].l;
    CHECK_MSG(l->steps == lw->steps && l->time == lw->time && l->snow_volume == lw->snow_volume &&
                  l->snow_mass == lw->snow_mass && l->initial_volume == lw->initial_volume &&
                  l->initial_mass == lw->initial_mass &&
                  l->compressed_volume == lw->compressed_volume &&
                  l->displaced_volume == lw->displaced_volume &&
                  l->relax_iterations == lw->relax_iterations,
              "%s: piece %d's ledger: volume %.17g mass %.17g compressed %.17g displaced %.17g "
              "(whole %.17g %.17g %.17g %.17g)",
              what, k, l->snow_volume, l->snow_mass, l->compressed_volume, l->displaced_volume,
              lw->snow_volume, lw->snow_mass, lw->compressed_volume, lw->displaced_volume);
    int same = 1;
    for (int o = 0; o < nobj; ++o) {
      same &= rn[k].area[o] == aw[o];
      for (int a = 0; a < 3; ++a)
        same &= rn[k].force[3 * o + a] == fw[3 * o + a];
    }
    CHECK_MSG(same, "%s: piece %d's forces or contact areas differ from the whole grid's", what, k);
  }
  printf("%s: %ld points differ from the whole grid in any bit; ledger volume %.9g m^3, mass "
         "%.9g kg, compressed %.6g m^3, displaced %.6g m^3 (equal: %d); force x %.6g N, contact "
         "%.4g m^2; %d exchanges per piece\n",
         what, total, lw->snow_volume, lw->snow_mass, lw->compressed_volume, lw->displaced_volume,
         rn[0].l.snow_mass == lw->snow_mass && rn[1].l.snow_mass == lw->snow_mass, fw[0], aw[0],
         rn[0].exchanges);
}

/* Halves split in x (30 + 34 points), the box dragged 40 steps across the
 * split (its front passes the split, 1.5 m from the domain's edge, at step
 * 24), the talus in one launch per iteration: bit for bit the whole
 * grid's. Then the error paths of pieces. */
static void test_pieces_x(void) {
  domain dm = make_domain();
  gr_snow_deformation_params prm;
  gr_snow_deformation_params_init(&prm);
  gr_snow_deformation *whole = make_whole(&dm, &prm);
  piece pc[2];
  int ok =
      make_piece(&pc[0], &dm, &prm, 0, 0, 30, 48) && make_piece(&pc[1], &dm, &prm, 30, 0, 34, 48);
  CHECK(pc[0].nxl == 38 && pc[1].nxl == 42 && pc[0].nyl == 48);
  if (ok && whole) {
    const int steps = 40;
    gr_snow_deformation_ledger lw;
    double fw[3], aw[1];
    for (int k = 0; k < 2; ++k)
      gr_snow_deformation_set_blocked(pc[k].s, 0);
    gr_snow_deformation_set_blocked(whole, 0);
    runner rn[2];
    run_team(pc, rn, GR_SNOW_DEFORMATION_EAST, 0, steps, -1, 0, 0);
    for (int k = 0; k < 2; ++k)
      CHECK_MSG(rn[k].st == GR_OK && rn[k].taken == steps, "piece %d: %s", k,
                gr_snow_deformation_last_error(pc[k].s));
    run_whole(whole, 0, steps, &lw, fw, aw);
    CHECK(lw.displaced_volume > 1e-3 && fw[0] < 0.0 && aw[0] > 0.0);
    check_pieces(pc, rn, whole, &dm, &lw, fw, aw, 1, "split in x, 40 steps");
    /* Checkpoints of both pieces: 6 more steps from the live state and
     * from the loaded one end on the same bits. */
    void *saved[2];
    size_t sb[2];
    float *after[2][2];
    for (int k = 0; k < 2; ++k) {
      CHECK(gr_snow_deformation_state_size(pc[k].s, &sb[k]) == GR_OK);
      saved[k] = malloc(sb[k]);
      CHECK(gr_snow_deformation_state_save(pc[k].s, saved[k], sb[k]) == GR_OK);
    }
    for (int run = 0; run < 2; ++run) {
      for (int k = 0; run == 1 && k < 2; ++k)
        CHECK(gr_snow_deformation_state_load(pc[k].s, saved[k], sb[k]) == GR_OK);
      run_team(pc, rn, GR_SNOW_DEFORMATION_EAST, 0, 6, -1, 0, 0);
      for (int k = 0; k < 2; ++k)
        after[run][k] = get(pc[k].s, GR_FIELD_SNOW_DEPTH, pc[k].g.nx * pc[k].g.ny);
    }
    for (int k = 0; k < 2; ++k) {
      CHECK(memcmp(after[0][k], after[1][k], (size_t)pc[k].g.nx * pc[k].g.ny * sizeof(float)) == 0);
      free(after[0][k]), free(after[1][k]), free(saved[k]);
    }
    /* A piece with neighbours and no callbacks does not step. */
    gr_snow_deformation_set_allreduce(pc[0].s, NULL, NULL);
    gr_snow_deformation_set_halo_exchange(pc[0].s, NULL, NULL);
    CHECK(gr_snow_deformation_step(pc[0].s, 0.01) == GR_ERR_INVALID_ARGUMENT);
    CHECK(has(gr_snow_deformation_last_error(pc[0].s), "halo exchange"));
    /* Halo calls on a side without a neighbour, and with a wrong size. */
    size_t bytes = 1;
    CHECK(gr_snow_deformation_halo_size(pc[0].s, GR_SNOW_DEFORMATION_WEST, &bytes) == GR_OK &&
          bytes == 0);
    CHECK(gr_snow_deformation_halo_size(pc[0].s, GR_SNOW_DEFORMATION_EAST, &bytes) == GR_OK &&
          bytes == 2 * 8 * 48 * sizeof(float));
    float strip[4];
    CHECK(gr_snow_deformation_halo_get(pc[0].s, GR_SNOW_DEFORMATION_WEST, strip, sizeof(strip)) ==
          GR_ERR_INVALID_ARGUMENT);
    CHECK(has(gr_snow_deformation_last_error(pc[0].s), "no neighbour on side 0"));
    CHECK(gr_snow_deformation_halo_set(pc[0].s, GR_SNOW_DEFORMATION_EAST, strip, sizeof(strip)) ==
          GR_ERR_INVALID_ARGUMENT);
    CHECK(has(gr_snow_deformation_last_error(pc[0].s), "gr_snow_deformation_halo_size"));
    CHECK(gr_snow_deformation_halo_get(pc[0].s, GR_SNOW_DEFORMATION_EAST, NULL, bytes) ==
          GR_ERR_INVALID_ARGUMENT);
    /* A piece's checkpoint loads into itself only. */
    size_t b0 = 0, b1 = 0;
    CHECK(gr_snow_deformation_state_size(pc[0].s, &b0) == GR_OK);
    CHECK(gr_snow_deformation_state_size(pc[1].s, &b1) == GR_OK);
    void *buf = malloc(b0);
    CHECK(gr_snow_deformation_state_save(pc[0].s, buf, b0) == GR_OK);
    CHECK(gr_snow_deformation_state_load(pc[0].s, buf, b0) == GR_OK);
    CHECK(b0 != b1 && gr_snow_deformation_state_load(pc[1].s, buf, b0) != GR_OK);
    free(buf);
  }
  /* Pieces the core refuses: the wrong ring, beyond the domain, too narrow. */
  gr_grid bad = pc[0].g;
  gr_snow_deformation *s = NULL;
  bad.ghost = 3;
  CHECK(gr_snow_deformation_create(ctx, &bad, &prm, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  CHECK(has(gr_last_error(ctx), "ghost ring of 8"));
  bad = pc[1].g;
  bad.nx = 40;
  CHECK(gr_snow_deformation_create(ctx, &bad, &prm, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  CHECK(has(gr_last_error(ctx), "beyond the domain"));
  bad = pc[1].g;
  bad.i0 = 58;
  bad.nx = 6;
  CHECK(gr_snow_deformation_create(ctx, &bad, &prm, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  CHECK(has(gr_last_error(ctx), "narrower than its ghost ring"));
  for (int k = 0; k < 2; ++k)
    gr_snow_deformation_destroy(pc[k].s);
  gr_snow_deformation_destroy(whole);
  free_domain(&dm);
}

/* Halves split in y (26 + 22 points), a sphere rolling north-east across
 * the split and a box pressed down astride it, 40 steps, the talus in
 * blocked launches: bit for bit the whole grid's. */
static void test_pieces_y(void) {
  domain dm = make_domain();
  gr_snow_deformation_params prm;
  gr_snow_deformation_params_init(&prm);
  prm.compression_model = GR_SNOW_COMPRESSION_CONSTANT;
  prm.slump_speed = 30.0; /* a reach of 10 points: the mask in two passes, exchanged between */
  gr_snow_deformation *whole = make_whole(&dm, &prm);
  piece pc[2];
  int ok =
      make_piece(&pc[0], &dm, &prm, 0, 0, 64, 26) && make_piece(&pc[1], &dm, &prm, 0, 26, 64, 22);
  if (ok && whole) {
    const int steps = 40;
    gr_snow_deformation_ledger lw;
    double fw[6], aw[2];
    for (int k = 0; k < 2; ++k)
      gr_snow_deformation_set_blocked(pc[k].s, 1);
    gr_snow_deformation_set_blocked(whole, 1);
    runner rn[2];
    run_team(pc, rn, GR_SNOW_DEFORMATION_NORTH, 1, steps, -1, 0, 0);
    for (int k = 0; k < 2; ++k)
      CHECK_MSG(rn[k].st == GR_OK && rn[k].taken == steps, "piece %d: %s", k,
                gr_snow_deformation_last_error(pc[k].s));
    run_whole(whole, 1, steps, &lw, fw, aw);
    CHECK(lw.displaced_volume > 1e-3 && lw.compressed_volume > 1e-4 && aw[0] > 0.0 && aw[1] > 0.0);
    check_pieces(pc, rn, whole, &dm, &lw, fw, aw, 2, "split in y, blocked talus, 40 steps");
  }
  for (int k = 0; k < 2; ++k)
    gr_snow_deformation_destroy(pc[k].s);
  gr_snow_deformation_destroy(whole);
  free_domain(&dm);
}

/* A wider ring (temporal blocking across the cut): 2 and 3 times
 * GR_SNOW_DEFORMATION_GHOST, so 2 and 3 talus launches between exchanges
 * and a reach's mask in one pass, end on the whole grid's bits in fewer
 * exchanges than the narrow ring, in blocked and in one-launch iterations
 * (pieces_y's scene split in y, 26 + 22 points; pieces_x's split in x, 30 +
 * 34; on the split tests' snow and on rough snow). Widths the core does
 * not take are refused. */
static void test_pieces_wide(void) {
  const int G = GR_SNOW_DEFORMATION_GHOST;
  domain dm = make_domain(), rough = make_domain();
  /* Rough snow, up to 2 m deeper at random: the talus runs on every point
   * for many launches, its windows on the rings' outer edges too (one
   * launch more than a ring holds before its exchange changes bits here,
   * with a ring of 8 and of 16). */
  for (int j = 0; j < rough.g.ny; ++j)
    for (int i = 0; i < rough.g.nx; ++i)
      rough.d[(size_t)j * rough.g.nx + i] += (float)(2.0 * hash01(i, j, 5));
  for (int run = 0; run < 5; ++run) {
    /* 0: in y, blocked; 1: in y, one launch an iteration; 2: in x, one
     * launch; 3, 4: 0 and 2 on rough snow */
    const int split = run < 3 ? run : run == 3 ? 0 : 2;
    const domain *dp = run < 3 ? &dm : &rough;
    gr_snow_deformation_params prm;
    gr_snow_deformation_params_init(&prm);
    int kind = split < 2 ? 1 : 0, blocked = split == 0, wide = split < 2 ? 2 * G : 3 * G;
    if (kind == 1) {
      prm.compression_model = GR_SNOW_COMPRESSION_CONSTANT;
      prm.slump_speed = 30.0; /* a reach of 10 points: two passes with a ring of 8, one wider */
    }
    const int steps = 40;
    gr_snow_deformation_ledger lw;
    double fw[6], aw[2];
    gr_snow_deformation *whole = make_whole(dp, &prm);
    if (!whole)
      break;
    gr_snow_deformation_set_blocked(whole, blocked);
    run_whole(whole, kind, steps, &lw, fw, aw);
    CHECK(lw.displaced_volume > 1e-3);
    int exchanges[2] = {0, 0};
    for (int w = 0; w < 2; ++w) {
      piece pc[2];
      runner rn[2];
      memset(pc, 0, sizeof(pc));
      piece_ghost = w ? wide : G;
      int ok = split < 2 ? make_piece(&pc[0], dp, &prm, 0, 0, 64, 26) &&
                               make_piece(&pc[1], dp, &prm, 0, 26, 64, 22)
                         : make_piece(&pc[0], dp, &prm, 0, 0, 30, 48) &&
                               make_piece(&pc[1], dp, &prm, 30, 0, 34, 48);
      piece_ghost = G;
      if (ok) {
        for (int k = 0; k < 2; ++k)
          gr_snow_deformation_set_blocked(pc[k].s, blocked);
        size_t bytes = 0;
        CHECK(gr_snow_deformation_halo_size(
                  pc[0].s, split < 2 ? GR_SNOW_DEFORMATION_NORTH : GR_SNOW_DEFORMATION_EAST,
                  &bytes) == GR_OK &&
              bytes == 2 * (size_t)(w ? wide : G) * (split < 2 ? 64 : 48) * sizeof(float));
        run_team(pc, rn, split < 2 ? GR_SNOW_DEFORMATION_NORTH : GR_SNOW_DEFORMATION_EAST, kind,
                 steps, -1, 0, 0);
        for (int k = 0; k < 2; ++k)
          CHECK_MSG(rn[k].st == GR_OK && rn[k].taken == steps, "piece %d: %s", k,
                    gr_snow_deformation_last_error(pc[k].s));
        char what[120];
        snprintf(what, sizeof(what), "split in %s, %s talus, %s snow, ring %d, %d steps",
                 split < 2 ? "y" : "x", blocked ? "blocked" : "one-launch",
                 run < 3 ? "the" : "rough", w ? wide : G, steps);
        check_pieces(pc, rn, whole, dp, &lw, fw, aw, scene_objects(kind), what);
        exchanges[w] = rn[0].exchanges;
        CHECK(rn[1].exchanges == rn[0].exchanges);
      }
      for (int k = 0; k < 2; ++k)
        gr_snow_deformation_destroy(pc[k].s);
    }
    printf("exchanges in %d steps: %d with a ring of %d, %d with a ring of %d\n", steps,
           exchanges[0], G, exchanges[1], wide);
    CHECK(exchanges[1] > 0 && exchanges[1] < exchanges[0]);
    gr_snow_deformation_destroy(whole);
  }
  /* Rings the core refuses: not a multiple of 8, beyond the widest, and a
   * piece narrower than its wide ring. */
  gr_snow_deformation_params prm;
  gr_snow_deformation_params_init(&prm);
  gr_grid bad = dm.g;
  bad.nx = 30, bad.global_nx = dm.g.nx, bad.global_ny = dm.g.ny;
  gr_snow_deformation *s = NULL;
  const int refused[] = {12, GR_SNOW_DEFORMATION_GHOST_MAX + G, 4 * G};
  for (int q = 0; q < 3; ++q) {
    bad.ghost = refused[q];
    CHECK(gr_snow_deformation_create(ctx, &bad, &prm, &s) == GR_ERR_INVALID_ARGUMENT && !s);
    CHECK_MSG(has(gr_last_error(ctx), q < 2 ? "ghost ring of 8 points (or a multiple of 8 up to 64)"
                                            : "narrower than its ghost ring of 32"),
              "ghost %d: %s", bad.ghost, gr_last_error(ctx));
  }
  free_domain(&dm);
  free_domain(&rough);
}

/* A stop asked by piece 1's progress callback after its 7th step stops
 * both pieces after that step (piece 0 has no callback); a failing halo
 * exchange on one piece returns its status with a sentence. */
/* The talus goes on after the objects are gone, from the box where the
 * last step's reach may have left snow moving (the box ploughs 10 steps on
 * the western piece, then is taken away, and its heap slides on): the
 * pieces go on alike and end on the whole grid's bits. That box is the
 * domain's on every piece, not cut to a piece's arrays, so that no piece
 * ever sees nothing to relax while another one exchanges. */
static void test_pieces_leave(void) {
  domain dm = make_domain();
  for (int j = 0; j < dm.g.ny; ++j) /* without the piles across the splits */
    for (int i = 0; i < dm.g.nx; ++i)
      if ((abs(i - 30) <= 2 && abs(j - 12) <= 2) || (abs(i - 42) <= 2 && abs(j - 26) <= 2))
        dm.d[j * dm.g.nx + i] -= 0.4f;
  gr_snow_deformation_params prm;
  gr_snow_deformation_params_init(&prm);
  prm.initial_density = prm.max_density; /* all displaced: a heap that slides on */
  gr_snow_deformation *whole = make_whole(&dm, &prm);
  piece pc[2];
  int ok =
      make_piece(&pc[0], &dm, &prm, 0, 0, 30, 48) && make_piece(&pc[1], &dm, &prm, 30, 0, 34, 48);
  if (ok && whole) {
    const int steps = 30;
    gr_snow_deformation_ledger lw;
    double fw[3] = {0.0, 0.0, 0.0}, aw[1] = {0.0};
    runner rn[2];
    run_team(pc, rn, GR_SNOW_DEFORMATION_EAST, 2, steps, -1, 0, 0);
    for (int k = 0; k < 2; ++k)
      CHECK_MSG(rn[k].st == GR_OK && rn[k].taken == steps, "piece %d: %s", k,
                gr_snow_deformation_last_error(pc[k].s));
    run_whole(whole, 2, steps, &lw, fw, aw);
    CHECK(lw.displaced_volume > 1e-3);
    check_pieces(pc, rn, whole, &dm, &lw, fw, aw, 0, "split in x, the box gone after 10 steps");
  }
  for (int k = 0; k < 2; ++k)
    gr_snow_deformation_destroy(pc[k].s);
  gr_snow_deformation_destroy(whole);
  free_domain(&dm);
}

static void test_pieces_abort(void) {
  domain dm = make_domain();
  gr_snow_deformation_params prm;
  gr_snow_deformation_params_init(&prm);
  piece pc[2];
  int ok =
      make_piece(&pc[0], &dm, &prm, 0, 0, 30, 48) && make_piece(&pc[1], &dm, &prm, 30, 0, 34, 48);
  if (ok) {
    runner rn[2];
    run_team(pc, rn, GR_SNOW_DEFORMATION_EAST, 0, 20, 1, 7, 0);
    printf("abort: piece 0 took %d steps (%s), piece 1 %d (%s); ledgers at step %lld and %lld\n",
           rn[0].taken, gr_status_string(rn[0].last), rn[1].taken, gr_status_string(rn[1].last),
           rn[0].l.steps, rn[1].l.steps);
    for (int k = 0; k < 2; ++k) {
      CHECK(rn[k].taken == 7 && rn[k].last == GR_ERR_ABORTED && rn[k].l.steps == 7);
      CHECK(has(gr_snow_deformation_last_error(pc[k].s), "another piece"));
    }
    CHECK(rn[0].l.snow_volume == rn[1].l.snow_volume && rn[0].l.time == rn[1].l.time);
    /* Both pieces' exchanges fail at their 12th call (the stop cleared):
     * the step returns the callback's status with a sentence, on both
     * pieces in the same step. */
    run_team(pc, rn, GR_SNOW_DEFORMATION_EAST, 0, 20, -1, 0, 12);
    printf("failing exchange: pieces took %d and %d more steps (%s, %s)\n", rn[0].taken,
           rn[1].taken, gr_status_string(rn[0].last), gr_status_string(rn[1].last));
    for (int k = 0; k < 2; ++k) {
      CHECK(rn[k].last == GR_ERR_IO && rn[k].taken < 20 && rn[k].taken == rn[0].taken);
      CHECK(has(gr_snow_deformation_last_error(pc[k].s), "halo exchange"));
    }
  }
  for (int k = 0; k < 2; ++k)
    gr_snow_deformation_destroy(pc[k].s);
  free_domain(&dm);
}

static const gr_subtest tests[] = {
    {"param_table", test_param_table, 0},
    {"mass_no_compression", test_mass_no_compression, 0},
    {"mass_compression", test_mass_compression, 0},
    {"imprint_sphere", test_imprint_sphere, 0},
    {"contour_direction", test_contour_direction, 0},
    {"talus_column", test_talus_column, 0},
    {"alg411_loss", test_alg411_loss, 0},
    {"determinism", test_determinism, 0},
    {"checkpoint", test_checkpoint, 0},
    {"force", test_force, 0},
    {"errors", test_errors, 0},
    {"raster_large", test_raster_large, 0},
    {"two_objects", test_two_objects, 0},
    {"trail", test_trail, 0},
    {"time_step", test_time_step, 0},
    {"blocked", test_blocked, 0},
    {"group", test_group, 0},
    {"devices_agree", test_devices_agree, 0},
    {"bare_ground", test_bare_ground, 0},
    {"talus_room", test_talus_room, 0},
    {"talus_resumes", test_talus_resumes, 0},
    {"slump_speed", test_slump_speed, 0},
    {"never_under", test_never_under, 0},
    {"berm", test_berm, 0},
    {"pieces_x", test_pieces_x, 0},
    {"pieces_y", test_pieces_y, 0},
    {"pieces_leave", test_pieces_leave, 0},
    {"pieces_wide", test_pieces_wide, 0},
    {"pieces_abort", test_pieces_abort, 0},
    {"memcheck", test_memcheck, 1},
};

static int setup(void) {
  if (gr_context_create(NULL, &ctx) != GR_OK)
    return 0;
  printf("device: %s\n", gr_context_device_name(ctx));
  return 1;
}

static void teardown(void) {
  gr_context_release(ctx);
}

int main(int argc, char **argv) {
  return gr_test_main(argc, argv, tests, (int)(sizeof(tests) / sizeof(tests[0])), setup, teardown);
}
