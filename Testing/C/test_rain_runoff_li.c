/* Rain runoff tests of the local inertial model's physics
 * (test_rain_runoff.c has main): rain gain, infiltration, the water
 * balance, pooling in a bowl, runoff down a plane, mirror symmetry,
 * determinism, the lake at rest, a spreading column, advance, reset and
 * long runs. */
#include "test_rain_runoff.h"

/* ------------------------------------------------------------------ tests */

/* On flat, impermeable ground nothing flows and every cell rises by
 * r dt per step; the ledger's rain is r t area. */
void test_rain_gain(void) {
  gr_grid g = {40, 32, 2.0, 1.5, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  double area = g.nx * g.dx * g.ny * g.dy;
  float *b = alloc_field(&g, 1);
  for (size_t c = 0; c < n; ++c)
    b[c] = 3.0f;
  /* r = 2^-17 m/s and dt = 0.5 s: every sum is exact in float and double. */
  gr_rain_runoff_params p = params_with(1.0 / 131072.0, 0.0, GR_BOUNDARY_CLOSED);
  gr_rain_runoff *s = make_sim(&g, &p, b, NULL);
  if (!s)
    return;
  CHECK(gr_rain_runoff_step(s, 0.5, 64) == GR_OK);
  float *h = get(s, &g, GR_FIELD_WATER_DEPTH);
  int off = 0;
  for (size_t c = 0; c < n; ++c)
    off += h[c] != (float)(64 * 0.5 / 131072.0);
  CHECK_MSG(off == 0, "%d cells are not exactly r t", off);
  gr_rain_runoff_ledger l = ledger(s);
  CHECK(l.rain_volume == 32.0 / 131072.0 * area);
  CHECK(l.stored_volume == l.rain_volume);
  CHECK(l.balance_error == 0.0);
  CHECK(l.outflow_volume == 0.0 && l.infiltrated_volume == 0.0);
  CHECK(l.steps == 64 && l.time == 32.0);
  free(h);
  gr_rain_runoff_destroy(s);

  /* r = 1e-5 m/s (36 mm/h), not a binary fraction: float rounding only.
   * Depth within 1e-5 of r t; the ledger's rain is r t area in double (r as
   * the float the device uses); balance within 1e-7 of the rain (the device
   * adds r dt rounded to float). */
  p.rain_rate = 1e-5;
  s = make_sim(&g, &p, b, NULL);
  if (!s)
    return;
  CHECK(gr_rain_runoff_step(s, 0.5, 400) == GR_OK);
  h = get(s, &g, GR_FIELD_WATER_DEPTH);
  float *v = get(s, &g, GR_FIELD_VELOCITY), *q = get(s, &g, GR_FIELD_DISCHARGE);
  double rt = 1e-5 * 200.0, worst = 0.0;
  for (size_t c = 0; c < n; ++c) {
    double e = fabs(h[c] - rt) / rt;
    worst = e > worst ? e : worst;
  }
  CHECK_MSG(worst <= 1e-5, "depth off r t by %.3g (relative)", worst);
  int moving = 0;
  for (size_t c = 0; c < n; ++c)
    moving += v[3 * c] != 0.0f || v[3 * c + 1] != 0.0f || v[3 * c + 2] != 0.0f || q[c] != 0.0f;
  CHECK_MSG(moving == 0, "%d cells move on flat ground", moving);
  l = ledger(s);
  double expect = (double)(float)1e-5 * 200.0 * area;
  CHECK_NEAR(l.rain_volume, expect, 1e-12 * expect);
  CHECK_MSG(fabs(l.balance_error) <= 1e-7 * l.rain_volume, "balance %.3g of %.3g", l.balance_error,
            l.rain_volume);
  CHECK_NEAR(l.max_depth, h[0], 0.0);
  printf("rain gain: depth within %.2g of r t, balance %.2g of the rain\n", worst,
         fabs(l.balance_error) / l.rain_volume);

  /* A rain-rate field equal to the parameter everywhere gives the same
   * water bit for bit. */
  gr_rain_runoff *f = make_sim(&g, &p, b, NULL);
  float *r = alloc_field(&g, 1);
  for (size_t c = 0; c < n; ++c)
    r[c] = (float)1e-5;
  if (f) {
    CHECK(gr_rain_runoff_set_field(f, GR_FIELD_RAIN_RATE, r) == GR_OK);
    CHECK(gr_rain_runoff_step(f, 0.5, 400) == GR_OK);
    float *hf = get(f, &g, GR_FIELD_WATER_DEPTH);
    CHECK(memcmp(hf, h, n * sizeof(float)) == 0);
    gr_rain_runoff_ledger lf = ledger(f);
    CHECK(lf.rain_volume == l.rain_volume);
    free(hf);
    gr_rain_runoff_destroy(f);
  }
  free(r);
  free(v);
  free(q);
  free(h);
  free(b);
  gr_rain_runoff_destroy(s);
}

/* With no rain, cells lose k t until dry and never go below 0;
 * the infiltrated field is the loss; k = 0 loses nothing. Two flat basins
 * of equal depth (k = 2e-5 m/s and k = 0) split by a dry wall, so that
 * nothing flows. */
void test_infiltration(void) {
  gr_grid g = {36, 16, 1.0, 1.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  const double k = 2e-5, h0 = 0.01;
  float *b = alloc_field(&g, 1), *d = alloc_field(&g, 1), *perm = alloc_field(&g, 1);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      size_t c = (size_t)j * g.nx + i;
      int wall = i == 17 || i == 18;
      b[c] = wall ? 5.0f : 0.0f;
      d[c] = wall ? 0.0f : (float)h0;
      perm[c] = i < 17 ? (float)k : 0.0f;
    }
  gr_rain_runoff_params p = params_with(0.0, 0.0, GR_BOUNDARY_CLOSED);
  gr_rain_runoff *s = make_sim(&g, &p, b, d);
  if (!s)
    return;
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_PERMEABILITY, perm) == GR_OK);
  /* 300 s: the permeable basin has lost 6 mm of its 10. */
  CHECK(gr_rain_runoff_step(s, 1.0, 300) == GR_OK);
  float *h = get(s, &g, GR_FIELD_WATER_DEPTH), *inf = get(s, &g, GR_FIELD_INFILTRATED);
  double worst_h = 0.0, worst_i = 0.0;
  int kept = 0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      size_t c = (size_t)j * g.nx + i;
      if (i < 17) {
        worst_h = fmax(worst_h, fabs(h[c] - (h0 - k * 300.0)));
        worst_i = fmax(worst_i, fabs(inf[c] - k * 300.0));
        worst_i = fmax(worst_i, fabs((double)inf[c] - ((double)d[c] - h[c])));
      } else {
        kept += h[c] != d[c] || inf[c] != 0.0f;
      }
    }
  CHECK_MSG(worst_h <= 1e-8, "permeable basin off h0 - k t by %.3g m", worst_h);
  CHECK_MSG(worst_i <= 1e-8, "infiltrated off k t (or the loss) by %.3g m", worst_i);
  CHECK_MSG(kept == 0, "%d cells of the impermeable basin or wall changed", kept);
  CHECK(bad_depths(h, n) == 0);
  printf("infiltration at 300 s: depth within %.2g m, infiltrated within %.2g m\n", worst_h,
         worst_i);
  free(h);
  free(inf);

  /* 700 s: the permeable basin is dry (exactly 0, not below) and took all
   * of its water; the ledger agrees. */
  CHECK(gr_rain_runoff_step(s, 1.0, 400) == GR_OK);
  h = get(s, &g, GR_FIELD_WATER_DEPTH);
  inf = get(s, &g, GR_FIELD_INFILTRATED);
  int wet = 0;
  worst_i = 0.0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < 17; ++i) {
      size_t c = (size_t)j * g.nx + i;
      wet += h[c] != 0.0f;
      worst_i = fmax(worst_i, fabs(inf[c] - d[c]));
    }
  CHECK_MSG(wet == 0, "%d permeable cells still hold water", wet);
  CHECK_MSG(worst_i <= 1e-8, "infiltrated off the initial depth by %.3g m", worst_i);
  CHECK(bad_depths(h, n) == 0);
  gr_rain_runoff_ledger l = ledger(s);
  double left = 17.0 * g.ny * h0, right = 17.0 * g.ny * h0; /* m^3, dx = dy = 1 */
  CHECK_NEAR(l.infiltrated_volume, left, 1e-7 * left);
  CHECK_NEAR(l.stored_volume, right, 1e-7 * right);
  CHECK_MSG(fabs(l.balance_error) <= 1e-7 * l.initial_volume, "balance %.3g", l.balance_error);
  free(h);
  free(inf);
  free(b);
  free(d);
  free(perm);
  gr_rain_runoff_destroy(s);
}

/* The terrain, rain and permeability of the conservation and determinism
 * tests: a slope with waves and cell-scale bumps (pits that pond), rain and
 * permeability varying per cell (30 % of the cells impermeable). */
gr_rain_runoff *make_bumpy(const gr_grid *g, gr_boundary boundary) {
  size_t n = cells_of(g);
  float *b = alloc_field(g, 1), *r = alloc_field(g, 1), *k = alloc_field(g, 1);
  float *d = alloc_field(g, 1);
  for (int j = 0; j < g->ny; ++j)
    for (int i = 0; i < g->nx; ++i) {
      size_t c = (size_t)j * g->nx + i;
      double x = i * g->dx, y = j * g->dy;
      b[c] = (float)(100.0 + 0.03 * x + 0.5 * sin(x / 9.0) * cos(y / 7.0) + 0.3 * hash01(i, j, 1));
      r[c] = (float)(2e-5 + 4e-5 * hash01(i, j, 2));
      k[c] = hash01(i, j, 3) < 0.3 ? 0.0f : (float)(1e-5 * hash01(i, j, 4));
      d[c] = (float)(0.02 * hash01(i, j, 5));
    }
  gr_rain_runoff_params p = params_with(0.0, 0.0, boundary);
  gr_rain_runoff *s = make_sim(g, &p, b, d);
  if (s) {
    CHECK(gr_rain_runoff_set_field(s, GR_FIELD_RAIN_RATE, r) == GR_OK);
    CHECK(gr_rain_runoff_set_field(s, GR_FIELD_PERMEABILITY, k) == GR_OK);
  }
  (void)n;
  free(b);
  free(r);
  free(k);
  free(d);
  return s;
}

/* The seed's flow makes and loses water; here initial + rain =
 * infiltrated + outflow + stored, to float rounding: |balance_error| <=
 * 1e-7 (initial + rain) after 400 steps on a bumpy open terrain (the
 * target is 1e-5; the Kahan-summed depth gives
 * about 1e-10 on PoCL); the device's sums agree with the fields read back. */
void test_conservation(void) {
  gr_grid g = {64, 48, 2.0, 2.5, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  gr_rain_runoff *s = make_bumpy(&g, GR_BOUNDARY_OPEN);
  if (!s)
    return;
  run_stable(s, 10, 40);
  gr_rain_runoff_ledger l = ledger(s);
  double in = l.initial_volume + l.rain_volume;
  double rel = fabs(l.balance_error) / in;
  printf("conservation: %lld steps, %.1f s: initial %.4g + rain %.4g = infiltrated %.4g + "
         "outflow %.4g + stored %.4g, balance %.3g of the water in\n",
         l.steps, l.time, l.initial_volume, l.rain_volume, l.infiltrated_volume, l.outflow_volume,
         l.stored_volume, rel);
  CHECK_MSG(rel <= 1e-7, "balance error %.3g of the water in", rel);
  CHECK(l.steps == 400);
  CHECK(l.outflow_volume > 0.0);
  CHECK(l.infiltrated_volume > 0.0);
  CHECK(l.rain_volume > 0.0 && l.initial_volume > 0.0);
  float *h = get(s, &g, GR_FIELD_WATER_DEPTH), *inf = get(s, &g, GR_FIELD_INFILTRATED);
  float *v = get(s, &g, GR_FIELD_VELOCITY), *q = get(s, &g, GR_FIELD_DISCHARGE);
  CHECK(bad_depths(h, n) == 0);
  CHECK(bad_values(v, 3 * n) == 0 && bad_values(q, n) == 0);
  double area = g.dx * g.dy;
  CHECK_NEAR(sum_of(h, n) * area, l.stored_volume, 1e-6 * l.stored_volume);
  CHECK_NEAR(sum_of(inf, n) * area, l.infiltrated_volume, 1e-6 * l.infiltrated_volume);
  float hmax = 0.0f;
  for (size_t c = 0; c < n; ++c)
    hmax = h[c] > hmax ? h[c] : hmax;
  CHECK(l.max_depth == hmax);
  /* Water moved: the pits filled above the initial 2 cm at most. */
  CHECK_MSG(hmax > 0.05f, "deepest %.3g m", hmax);
  free(h);
  free(inf);
  free(v);
  free(q);
  gr_rain_runoff_destroy(s);
}

/* A radially symmetric paraboloid b = a r^2 (r from the grid's centre). */
float *make_bowl(const gr_grid *g, double a) {
  float *b = alloc_field(g, 1);
  double cx = 0.5 * (g->nx - 1) * g->dx, cy = 0.5 * (g->ny - 1) * g->dy;
  for (int j = 0; j < g->ny; ++j)
    for (int i = 0; i < g->nx; ++i) {
      double x = i * g->dx - cx, y = j * g->dy - cy;
      b[(size_t)j * g->nx + i] = (float)(a * (x * x + y * y));
    }
  return b;
}

/* Item 20: rain into a closed bowl pools at the centre, the pond's surface
 * settles level, nothing leaves, and the water is the rain that fell. */
void test_bowl(void) {
  gr_grid g = {48, 48, 2.0, 2.0, 0.0, 0.0, 0, 0};
  float *b = make_bowl(&g, 0.004);
  gr_rain_runoff_params p = params_with(1e-4, 0.0, GR_BOUNDARY_CLOSED);
  gr_rain_runoff *s = make_sim(&g, &p, b, NULL);
  if (!s)
    return;
  int steps = 0;
  CHECK(gr_rain_runoff_advance(s, 300.0, &steps) == GR_OK);
  p.rain_rate = 0.0; /* then let it settle */
  CHECK(gr_rain_runoff_set_params(s, &p) == GR_OK);
  for (int k = 0; k < 12; ++k) {
    int more = 0;
    CHECK(gr_rain_runoff_advance(s, 50.0, &more) == GR_OK);
    steps += more;
  }
  gr_rain_runoff_ledger l = ledger(s);
  float *h = get(s, &g, GR_FIELD_WATER_DEPTH), *eta = get(s, &g, GR_FIELD_WATER_SURFACE);
  float *v = get(s, &g, GR_FIELD_VELOCITY);
  CHECK(l.outflow_volume == 0.0);
  CHECK_NEAR(l.stored_volume, l.rain_volume, 1e-5 * l.rain_volume);
  CHECK_NEAR(l.rain_volume, (double)(float)1e-4 * 300.0 * 96.0 * 96.0, 1e-6 * l.rain_volume);
  size_t centre = (size_t)(g.ny / 2) * g.nx + g.nx / 2, rim = (size_t)(g.ny / 2) * g.nx;
  CHECK_MSG(h[centre] > 0.5f && h[centre] > 100.0f * h[rim], "centre %.3g m, rim %.3g m", h[centre],
            h[rim]);
  /* The pond's middle (within 5 cells of the centre, all deeper than 30 cm)
   * is level to 1e-5 m and still to 1 mm/s; the whole pond (cells deeper
   * than 10 cm, where the last film off the slopes still arrives) level to
   * 1e-4 m. */
  float lo = 1e30f, hi = -1e30f, lo5 = 1e30f, hi5 = -1e30f, vmax = 0.0f;
  int pond = 0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      size_t c = (size_t)j * g.nx + i;
      if (h[c] <= 0.1f)
        continue;
      ++pond;
      lo = fminf(lo, eta[c]);
      hi = fmaxf(hi, eta[c]);
      double ri = i - 0.5 * (g.nx - 1), rj = j - 0.5 * (g.ny - 1);
      if (ri * ri + rj * rj <= 25.0) {
        lo5 = fminf(lo5, eta[c]);
        hi5 = fmaxf(hi5, eta[c]);
        vmax = fmaxf(vmax, sqrtf(v[3 * c] * v[3 * c] + v[3 * c + 1] * v[3 * c + 1]));
      }
    }
  printf("bowl: %d steps, pond of %d cells, centre depth %.3f m, surface spread %.3g m (%.3g m "
         "within 5 cells), fastest there %.3g m/s, stored %.9g of rain %.9g m^3\n",
         steps, pond, h[centre], hi - lo, hi5 - lo5, vmax, l.stored_volume, l.rain_volume);
  CHECK(pond > 50);
  CHECK_MSG(hi5 - lo5 <= 1e-5f && hi - lo <= 1e-4f, "pond surface spread %.3g m, %.3g m", hi5 - lo5,
            hi - lo);
  CHECK_MSG(vmax <= 1e-3f, "pond still moves at %.3g m/s", vmax);
  /* The pond is radially symmetric: mirrored cells agree to 1 mm. */
  float asym = 0.0f;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      float a = h[(size_t)j * g.nx + i], m = h[(size_t)i * g.nx + (g.nx - 1 - j)];
      asym = fabsf(a - m) > asym ? fabsf(a - m) : asym;
    }
  CHECK_MSG(asym <= 1e-3f, "bowl asymmetry %.3g m", asym);
  free(h);
  free(eta);
  free(v);
  free(b);
  gr_rain_runoff_destroy(s);
}

/* Rain on a tilted plane with an open boundary runs off through the
 * low edge: the depth grows downslope, the water flows downslope, and the
 * discharge at the low edge far exceeds that at the high edge. */
void test_tilted_plane(void) {
  gr_grid g = {48, 32, 2.0, 2.0, 0.0, 0.0, 0, 0};
  float *b = alloc_field(&g, 1);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i)
      b[(size_t)j * g.nx + i] = (float)(0.05 * i * g.dx); /* low edge at x = 0 */
  gr_rain_runoff_params p = params_with(1e-4, 0.0, GR_BOUNDARY_OPEN);
  gr_rain_runoff *s = make_sim(&g, &p, b, NULL);
  if (!s)
    return;
  CHECK(gr_rain_runoff_advance(s, 400.0, NULL) == GR_OK);
  gr_rain_runoff_ledger l = ledger(s);
  float *h = get(s, &g, GR_FIELD_WATER_DEPTH), *v = get(s, &g, GR_FIELD_VELOCITY);
  float *q = get(s, &g, GR_FIELD_DISCHARGE);
  CHECK(l.outflow_volume > 0.2 * l.rain_volume);
  CHECK_MSG(fabs(l.balance_error) <= 1e-7 * l.rain_volume, "balance %.3g", l.balance_error);
  /* Mean depth per column, away from the side edges. */
  double col[48];
  for (int i = 0; i < g.nx; ++i) {
    col[i] = 0.0;
    for (int j = 2; j < g.ny - 2; ++j)
      col[i] += h[(size_t)j * g.nx + i] / (g.ny - 4);
  }
  int rising = 0;
  for (int i = 1; i < g.nx; ++i)
    rising += col[i] > col[i - 1] * (1.0 + 1e-6);
  CHECK_MSG(rising == 0, "%d columns are deeper than their downslope neighbour", rising);
  CHECK_MSG(col[0] > 3.0 * col[g.nx - 1], "low edge %.3g m, high edge %.3g m", col[0],
            col[g.nx - 1]);
  int upslope = 0;
  double q_low = 0.0, q_high = 0.0;
  for (int j = 2; j < g.ny - 2; ++j) {
    for (int i = 1; i < g.nx - 1; ++i)
      upslope += v[3 * ((size_t)j * g.nx + i)] >= 0.0f;
    q_low += q[(size_t)j * g.nx];
    q_high += q[(size_t)j * g.nx + g.nx - 1];
  }
  CHECK_MSG(upslope == 0, "%d cells do not flow downslope", upslope);
  CHECK_MSG(q_low > 10.0 * q_high, "discharge at the low edge %.3g, high edge %.3g", q_low, q_high);
  printf("tilted plane: outflow %.3g of the rain, depth at the low edge %.3g m, high edge %.3g m\n",
         l.outflow_volume / l.rain_volume, col[0], col[g.nx - 1]);
  free(h);
  free(v);
  free(q);
  free(b);
  gr_rain_runoff_destroy(s);
}

/* Rain on a dry tilted plane, run with MaxTimeStep 1 s (the old default)
 * and with no cap (the default now): 3 h of 50 mm/h on a plane of 20 cells
 * of 80 m, as on the DEM in Data/, tilted toward its west edge
 * (transmissive: the film leaves at its normal depth; walls elsewhere), n
 * 0.01. Without a cap the first steps of the dry grid were MaxTimeStep
 * long (three steps of 3600 s let out a tenth of the water); the bound on
 * the water the step's rain makes keeps the uncapped run's outflow within
 * 1% of the capped run's, in under half the steps. At the kinematic-wave
 * equilibrium, in steps of one length, the outflow equals the rain within
 * 1e-6 and the depth every column's faces see (the stored depth plus a
 * step's rain, which a longer step adds before the water leaves) is the
 * capped run's within 1%. The slope of 0.3 is the case that needs the
 * thin-film bound (gr_rain_runoff_stable_dt_impl): its film is
 * supercritical (Froude number up to 8), and in gravity-limited steps of 77 s it
 * stood two to three times too deep. */
void test_tilted_plane_uncapped(void) {
  gr_grid g = {20, 3, 80.0, 80.0, 0.0, 0.0, 0, 0};
  const double slopes[2] = {0.01, 0.3}, rain = 50.0 / 3.6e6;
  float *b = alloc_field(&g, 1);
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        b[(size_t)j * g.nx + i] = (float)(slopes[k] * (i + 0.5) * g.dx);
    double out[2] = {0.0, 0.0}, ratio[2] = {0.0, 0.0};
    long long steps[2] = {0, 0};
    float *h[2] = {NULL, NULL};
    for (int capped = 0; capped < 2; ++capped) {
      gr_rain_runoff_params p = params_with(rain, 0.0, GR_BOUNDARY_CLOSED);
      p.boundary[GR_RAIN_RUNOFF_WEST] = GR_BOUNDARY_TRANSMISSIVE;
      p.manning_n = 0.01;
      if (capped)
        p.max_dt = 1.0;
      gr_rain_runoff *s = make_sim(&g, &p, b, NULL);
      if (!s)
        continue;
      CHECK(gr_rain_runoff_advance(s, 10800.0, NULL) == GR_OK);
      gr_rain_runoff_ledger l0 = ledger(s);
      out[capped] = l0.outflow_volume;
      steps[capped] = l0.steps;
      /* Steps of one length: the water each adds before it leaves is then
       * the same; 160 of them to settle from the advance's last ones. */
      double dt = 0.0;
      CHECK(gr_rain_runoff_stable_dt(s, &dt) == GR_OK);
      CHECK(gr_rain_runoff_step(s, dt, 160) == GR_OK);
      l0 = ledger(s);
      CHECK(gr_rain_runoff_step(s, dt, 32) == GR_OK);
      gr_rain_runoff_ledger l1 = ledger(s);
      ratio[capped] = (l1.outflow_volume - l0.outflow_volume) / (l1.rain_volume - l0.rain_volume);
      CHECK(fabs(l1.balance_error) <= 1e-7 * l1.rain_volume);
      h[capped] = get(s, &g, GR_FIELD_WATER_DEPTH);
      for (size_t c = 0; h[capped] && c < cells_of(&g); ++c)
        h[capped][c] += (float)(rain * dt);
      gr_rain_runoff_destroy(s);
    }
    double worst = 0.0;
    for (int i = 0; h[0] && h[1] && i < g.nx; ++i) {
      size_t c = (size_t)(g.ny / 2) * g.nx + i;
      worst = fmax(worst, fabs(h[0][c] - h[1][c]) / h[1][c]);
    }
    printf("tilted plane, slope %g, uncapped / capped at 1 s: outflow %.6g / %.6g m^3, "
           "equilibrium outflow / rain %.9f / %.9f, depths within %.3g%%, steps %lld / %lld\n",
           slopes[k], out[0], out[1], ratio[0], ratio[1], 100.0 * worst, steps[0], steps[1]);
    CHECK_MSG(fabs(out[0] - out[1]) <= 0.01 * out[1], "outflow %.6g m^3, capped %.6g m^3", out[0],
              out[1]);
    CHECK_MSG(fabs(ratio[0] - 1.0) <= 1e-6 && fabs(ratio[1] - 1.0) <= 1e-6,
              "equilibrium outflow / rain %.9f, capped %.9f", ratio[0], ratio[1]);
    CHECK_MSG(worst <= 0.01, "depths off the capped run's by %.3g", worst);
    CHECK_MSG(steps[0] < steps[1] / 2, "steps %lld, capped %lld", steps[0], steps[1]);
    free(h[0]);
    free(h[1]);
  }
  free(b);
}

/* A terrain, rain, permeability and initial depth that are symmetric under
 * x -> -x give a mirrored depth (bit for bit: every face's discharge is
 * computed so that its mirror image is its exact negative) and a mirrored,
 * x-negated velocity. */
void test_symmetry(void) {
  gr_grid g = {40, 24, 2.0, 3.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  float *b = alloc_field(&g, 1), *r = alloc_field(&g, 1), *k = alloc_field(&g, 1);
  float *d = alloc_field(&g, 1);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      int m = i < g.nx - 1 - i ? i : g.nx - 1 - i; /* distance from the edge */
      size_t c = (size_t)j * g.nx + i;
      b[c] = (float)(0.08 * (g.nx / 2 - m) + 0.02 * j + 0.4 * hash01(m, j, 7));
      r[c] = (float)(1e-5 + 5e-5 * hash01(m, j, 8));
      k[c] = (float)(5e-6 * hash01(m, j, 9));
      d[c] = (float)(0.03 * hash01(m, j, 10));
    }
  gr_rain_runoff_params p = params_with(0.0, 0.0, GR_BOUNDARY_OPEN);
  gr_rain_runoff *s = make_sim(&g, &p, b, d);
  if (!s)
    return;
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_RAIN_RATE, r) == GR_OK);
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_PERMEABILITY, k) == GR_OK);
  run_stable(s, 6, 50);
  float *h = get(s, &g, GR_FIELD_WATER_DEPTH), *v = get(s, &g, GR_FIELD_VELOCITY);
  int asym_h = 0, asym_v = 0, moving = 0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      size_t c = (size_t)j * g.nx + i, m = (size_t)j * g.nx + (g.nx - 1 - i);
      asym_h += h[c] != h[m];
      asym_v += v[3 * c] != -v[3 * m] || v[3 * c + 1] != v[3 * m + 1];
      moving += v[3 * c] != 0.0f;
    }
  CHECK_MSG(asym_h == 0, "%d depths differ from their mirror image", asym_h);
  CHECK_MSG(asym_v == 0, "%d velocities differ from their mirror image", asym_v);
  CHECK_MSG(moving > (int)(n / 4), "only %d cells move in x", moving);
  free(h);
  free(v);
  free(b);
  free(r);
  free(k);
  free(d);
  gr_rain_runoff_destroy(s);
}

/* Item 24: two runs from the same inputs give bit-identical fields and
 * ledgers. */
void test_determinism(void) {
  gr_grid g = {64, 48, 2.0, 2.5, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  gr_rain_runoff *a = make_bumpy(&g, GR_BOUNDARY_OPEN), *b = make_bumpy(&g, GR_BOUNDARY_OPEN);
  if (!a || !b) {
    gr_rain_runoff_destroy(a);
    gr_rain_runoff_destroy(b);
    return;
  }
  run_stable(a, 5, 40);
  run_stable(b, 5, 40);
  const gr_field fields[] = {GR_FIELD_WATER_DEPTH, GR_FIELD_VELOCITY, GR_FIELD_DISCHARGE,
                             GR_FIELD_INFILTRATED, GR_FIELD_WATER_SURFACE};
  for (size_t f = 0; f < sizeof(fields) / sizeof(fields[0]); ++f) {
    float *fa = get(a, &g, fields[f]), *fb = get(b, &g, fields[f]);
    size_t bytes = n * (size_t)gr_field_components(fields[f]) * sizeof(float);
    CHECK_MSG(memcmp(fa, fb, bytes) == 0, "%s differs between runs", gr_field_name(fields[f]));
    free(fa);
    free(fb);
  }
  gr_rain_runoff_ledger la = ledger(a), lb = ledger(b);
  CHECK(la.time == lb.time && la.steps == lb.steps && la.rain_volume == lb.rain_volume);
  CHECK(la.infiltrated_volume == lb.infiltrated_volume);
  CHECK(la.outflow_volume == lb.outflow_volume && la.stored_volume == lb.stored_volume);
  CHECK(la.balance_error == lb.balance_error && la.max_depth == lb.max_depth);
  gr_rain_runoff_destroy(a);
  gr_rain_runoff_destroy(b);
}

/* The lake at rest: a still lake in a closed, bumpy bowl stays still
 * (well-balanced). With elevations on a 2^-10 m lattice every depth and
 * level difference is exact and the lake does not move at all; with
 * arbitrary elevations the float rounding of the levels may stir it, by
 * less than 1e-5 m of level and 2e-5 m/s. */
void test_lake_at_rest(void) {
  gr_grid g = {40, 40, 2.0, 2.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  const float level = 1.5f;
  for (int exact = 1; exact >= 0; --exact) {
    float *b = make_bowl(&g, 0.003);
    float *d = alloc_field(&g, 1);
    int wet = 0;
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        size_t c = (size_t)j * g.nx + i;
        double z = b[c] + 0.3 * hash01(i, j, 11);
        b[c] = exact ? (float)(floor(z * 1024.0) / 1024.0) : (float)z;
        d[c] = b[c] < level ? level - b[c] : 0.0f;
        wet += d[c] > 0.0f;
      }
    gr_rain_runoff_params p = params_with(0.0, 0.0, GR_BOUNDARY_CLOSED);
    gr_rain_runoff *s = make_sim(&g, &p, b, d);
    if (!s)
      return;
    int steps = 0;
    CHECK(gr_rain_runoff_advance(s, 200.0, &steps) == GR_OK);
    float *h = get(s, &g, GR_FIELD_WATER_DEPTH), *eta = get(s, &g, GR_FIELD_WATER_SURFACE);
    float *v = get(s, &g, GR_FIELD_VELOCITY);
    float dlevel = 0.0f, vmax = 0.0f;
    int changed = 0;
    for (size_t c = 0; c < n; ++c) {
      changed += h[c] != d[c];
      if (d[c] > 0.0f)
        dlevel = fmaxf(dlevel, fabsf(eta[c] - level));
      vmax = fmaxf(vmax, fmaxf(fabsf(v[3 * c]), fabsf(v[3 * c + 1])));
    }
    printf("lake at rest (%s elevations): %d wet cells, %d steps: %d depths changed, level off "
           "by %.3g m, fastest %.3g m/s\n",
           exact ? "lattice" : "arbitrary", wet, steps, changed, dlevel, vmax);
    CHECK(wet > 300 && wet < (int)n);
    if (exact) {
      CHECK_MSG(changed == 0 && vmax == 0.0f, "%d depths changed, fastest %.3g m/s", changed, vmax);
    } else {
      CHECK_MSG(dlevel <= 1e-5f, "level off by %.3g m", dlevel);
      CHECK_MSG(vmax <= 2e-5f, "lake moves at %.3g m/s", vmax);
    }
    free(h);
    free(eta);
    free(v);
    free(b);
    free(d);
    gr_rain_runoff_destroy(s);
  }
}

/* Item 21 (with the local inertial flow): a single water column on flat
 * ground spreads to its four neighbours in the first step (and not yet to
 * the diagonals), its peak falls, the spreading stays 4-fold symmetric,
 * and no depth is ever negative or NaN. */
void test_column(void) {
  gr_grid g = {33, 33, 1.0, 1.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g), mid = 16 * 33 + 16;
  float *d = alloc_field(&g, 1);
  d[mid] = 1.0f;
  gr_rain_runoff_params p = params_with(0.0, 0.0, GR_BOUNDARY_CLOSED);
  gr_rain_runoff *s = make_sim(&g, &p, NULL, d);
  if (!s)
    return;
  double dt = 0.0;
  CHECK(gr_rain_runoff_stable_dt(s, &dt) == GR_OK);
  /* cfl sqrt(theta) / (sqrt(g h) sqrt(1/dx^2 + 1/dy^2)), theta = 0.8 */
  CHECK_NEAR(dt, 0.7 * sqrt(0.8) / (sqrt(GR_GRAVITY * 1.0) * sqrt(2.0)), 1e-6);
  CHECK(gr_rain_runoff_step(s, dt, 1) == GR_OK);
  float *h = get(s, &g, GR_FIELD_WATER_DEPTH);
  float e = h[mid + 1];
  CHECK_MSG(e > 0.0f && h[mid - 1] == e && h[mid + 33] == e && h[mid - 33] == e,
            "neighbours %g %g %g %g", h[mid - 1], h[mid + 1], h[mid - 33], h[mid + 33]);
  CHECK(h[mid + 34] == 0.0f && h[mid - 34] == 0.0f && h[mid + 2] == 0.0f);
  CHECK(h[mid] < 1.0f);
  /* The peak (the deepest cell anywhere) falls: ripples may lift it for a
   * step or two, but the highest peak of every block of 10 steps is lower
   * than that of the block before. */
  int bad = bad_depths(h, n);
  double block_peak[6] = {0}, prev = 1.0;
  for (int k = 1; k < 60; ++k) {
    gr_rain_runoff_ledger lk = ledger(s);
    block_peak[(k - 1) / 10] = fmax(block_peak[(k - 1) / 10], lk.max_depth);
    CHECK(gr_rain_runoff_step(s, dt, 1) == GR_OK);
  }
  free(h);
  h = get(s, &g, GR_FIELD_WATER_DEPTH);
  bad += bad_depths(h, n);
  for (int k = 0; k < 6; ++k) {
    CHECK_MSG(block_peak[k] < prev, "block %d peak %.4g m, before %.4g m", k, block_peak[k], prev);
    prev = block_peak[k];
  }
  CHECK_MSG(block_peak[5] < 0.02, "peak still %.3g m", block_peak[5]);
  run_stable(s, 10, 50);
  free(h);
  h = get(s, &g, GR_FIELD_WATER_DEPTH);
  bad += bad_depths(h, n);
  CHECK_MSG(bad == 0, "%d negative or NaN depths", bad);
  int asym = 0;
  for (int j = 0; j < 33; ++j)
    for (int i = 0; i < 33; ++i) {
      float a = h[j * 33 + i];
      asym += a != h[i * 33 + j] || a != h[j * 33 + (32 - i)] || a != h[(32 - j) * 33 + i];
    }
  CHECK_MSG(asym == 0, "%d cells break the 4-fold symmetry", asym);
  gr_rain_runoff_ledger l = ledger(s);
  CHECK_NEAR(l.stored_volume, 1.0, 1e-6);
  CHECK(l.outflow_volume == 0.0 && l.initial_volume == 1.0);
  free(h);
  free(d);
  gr_rain_runoff_destroy(s);
}

/* A long advance from dry ground: rain of 50 mm/h on dry, rough hills
 * (100 x 86 points 300 m apart, 800 m of relief, slopes to 0.5: like the
 * DEM in Data/ at a quarter of its resolution), Manning n 0.03,
 * MaxTimeStep 3600 s, 30 minutes in one gr_rain_runoff_advance, as the
 * filter advances to an output time. The first stable step sees only the
 * rain's depth on still water; the water's speed and depth then shrink the
 * stable step fast (115 s, 48 s, 38 s, ... on the DEM), so advance must
 * read it again after each step until it holds: stretches of 4 steps of the
 * first one took the shallow-water model past its Courant limit, where its
 * depths go negative and are cut (the DEM gained 8.5e6 m^3 over the
 * 2.4e7 m^3 of rain in its first 30 minutes; these hills 2.3e9). Both
 * models: the water balance closes to 1e-6 of the rain, no depth is
 * negative, and the deepest water is within 5 % of that of the same 30
 * minutes advanced a minute at a time. */
void test_advance_dry_start(void) {
  gr_grid g = {100, 86, 300.0, 300.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  float *b = alloc_field(&g, 1);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      double x = i * g.dx, y = j * g.dy;
      b[(size_t)j * g.nx + i] = (float)(600.0 + 250.0 * sin(x / 2100.0) * cos(y / 1700.0) +
                                        0.4e-3 * y * 300.0 + 150.0 * hash01(i, j, 91));
    }
  for (int m = 0; m < 2; ++m) {
    gr_rain_runoff_params p = params_with(50.0 / 3.6e6, 0.0, GR_BOUNDARY_OPEN);
    p.flow_model = m ? GR_FLOW_LOCAL_INERTIAL : GR_FLOW_SHALLOW_WATER; /* model_names' order */
    p.manning_n = 0.03;
    p.max_dt = 3600.0;
    gr_rain_runoff *s[2] = {make_sim(&g, &p, b, NULL), make_sim(&g, &p, b, NULL)};
    if (!s[0] || !s[1]) {
      gr_rain_runoff_destroy(s[0]);
      gr_rain_runoff_destroy(s[1]);
      continue;
    }
    int taken = 0, parts = 0;
    CHECK(gr_rain_runoff_advance(s[0], 1800.0, &taken) == GR_OK);
    for (int k = 0; k < 30; ++k) {
      int t = 0;
      CHECK(gr_rain_runoff_advance(s[1], 60.0, &t) == GR_OK);
      parts += t;
    }
    gr_rain_runoff_ledger l[2] = {ledger(s[0]), ledger(s[1])};
    float *h = get(s[0], &g, GR_FIELD_WATER_DEPTH);
    int bad = bad_depths(h, n);
    CHECK_MSG(fabs(l[0].balance_error) < 1e-6 * l[0].rain_volume && bad == 0,
              "%s: balance error %.4g m^3 of %.4g m^3 of rain (stored %.4g, out %.4g), %d bad "
              "depths",
              model_names[m], l[0].balance_error, l[0].rain_volume, l[0].stored_volume,
              l[0].outflow_volume, bad);
    CHECK_MSG(fabs(l[0].max_depth - l[1].max_depth) < 0.05 * l[1].max_depth &&
                  l[1].max_depth > 0.05,
              "%s: deepest %.4g m in one advance, %.4g m a minute at a time", model_names[m],
              l[0].max_depth, l[1].max_depth);
    printf("%s: 30 min in %d steps (%d a minute at a time), balance %.3g of the rain, deepest "
           "%.4f m (%.4f m)\n",
           model_names[m], taken, parts, l[0].balance_error / l[0].rain_volume, l[0].max_depth,
           l[1].max_depth);
    free(h);
    gr_rain_runoff_destroy(s[0]);
    gr_rain_runoff_destroy(s[1]);
  }
  free(b);
}

/* advance: the same state and duration give the same steps, bit for bit;
 * the step count respects the stable step; 0 s does nothing; the ledger's
 * time adds up. */
void test_advance(void) {
  gr_grid g = {32, 32, 2.0, 2.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  float *b = make_bowl(&g, 0.002);
  gr_rain_runoff_params p = params_with(5e-5, 1e-6, GR_BOUNDARY_OPEN);
  p.max_dt = 0.5;
  gr_rain_runoff *a = make_sim(&g, &p, b, NULL), *c = make_sim(&g, &p, b, NULL);
  if (!a || !c)
    return;
  int na = -1, nc = -1;
  CHECK(gr_rain_runoff_advance(a, 0.0, &na) == GR_OK && na == 0);
  CHECK(gr_rain_runoff_advance(a, 60.0, &na) == GR_OK);
  CHECK(gr_rain_runoff_advance(c, 60.0, &nc) == GR_OK);
  CHECK_MSG(na == nc && na >= 120, "steps %d and %d (at least 60 / max_dt = 120)", na, nc);
  double dta = 0.0, dtc = 0.0;
  CHECK(gr_rain_runoff_stable_dt(a, &dta) == GR_OK);
  CHECK(dta > 0.0 && dta <= p.max_dt);
  CHECK(gr_rain_runoff_advance(a, 25.0, &na) == GR_OK);
  CHECK(gr_rain_runoff_advance(c, 25.0, &nc) == GR_OK);
  CHECK(na == nc && na >= (int)ceil(25.0 / dta));
  CHECK(gr_rain_runoff_stable_dt(c, &dtc) == GR_OK);
  float *ha = get(a, &g, GR_FIELD_WATER_DEPTH), *hc = get(c, &g, GR_FIELD_WATER_DEPTH);
  CHECK(memcmp(ha, hc, n * sizeof(float)) == 0);
  gr_rain_runoff_ledger la = ledger(a);
  CHECK_NEAR(la.time, 85.0, 1e-9);
  CHECK(la.rain_volume > 0.0 && la.max_depth > 0.0);
  /* advance(0) changes nothing. */
  CHECK(gr_rain_runoff_advance(a, 0.0, &na) == GR_OK && na == 0);
  gr_rain_runoff_ledger lb = ledger(a);
  CHECK(lb.steps == la.steps && lb.time == la.time);
  /* Steps as long as the stable step: one step of a still, shallow state
   * advances by max_dt. */
  CHECK(gr_rain_runoff_reset(a) == GR_OK);
  CHECK(gr_rain_runoff_advance(a, p.max_dt, &na) == GR_OK && na == 1);
  free(ha);
  free(hc);
  free(b);
  gr_rain_runoff_destroy(a);
  gr_rain_runoff_destroy(c);
}

/* reset returns to the initial depth with no discharge, nothing
 * infiltrated and a zeroed ledger; the rerun matches the first run bit for
 * bit. */
void test_reset(void) {
  gr_grid g = {48, 40, 2.0, 2.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  gr_rain_runoff *s = make_bumpy(&g, GR_BOUNDARY_OPEN);
  if (!s)
    return;
  float *h0 = get(s, &g, GR_FIELD_WATER_DEPTH);
  gr_rain_runoff_ledger l0 = ledger(s);
  run_stable(s, 4, 40);
  float *h1 = get(s, &g, GR_FIELD_WATER_DEPTH), *v1 = get(s, &g, GR_FIELD_VELOCITY);
  float *i1 = get(s, &g, GR_FIELD_INFILTRATED);
  gr_rain_runoff_ledger l1 = ledger(s);
  CHECK(gr_rain_runoff_reset(s) == GR_OK);
  float *hr = get(s, &g, GR_FIELD_WATER_DEPTH), *vr = get(s, &g, GR_FIELD_VELOCITY);
  float *ir = get(s, &g, GR_FIELD_INFILTRATED);
  gr_rain_runoff_ledger lr = ledger(s);
  CHECK(memcmp(hr, h0, n * sizeof(float)) == 0);
  int nonzero = 0;
  for (size_t c = 0; c < n; ++c)
    nonzero += ir[c] != 0.0f || vr[3 * c] != 0.0f || vr[3 * c + 1] != 0.0f;
  CHECK(nonzero == 0);
  CHECK(lr.time == 0.0 && lr.steps == 0 && lr.rain_volume == 0.0);
  CHECK(lr.infiltrated_volume == 0.0 && lr.outflow_volume == 0.0);
  CHECK(lr.initial_volume == l0.initial_volume && lr.stored_volume == l0.stored_volume);
  run_stable(s, 4, 40);
  float *h2 = get(s, &g, GR_FIELD_WATER_DEPTH), *v2 = get(s, &g, GR_FIELD_VELOCITY);
  float *i2 = get(s, &g, GR_FIELD_INFILTRATED);
  gr_rain_runoff_ledger l2 = ledger(s);
  CHECK(memcmp(h1, h2, n * sizeof(float)) == 0);
  CHECK(memcmp(v1, v2, 3 * n * sizeof(float)) == 0);
  CHECK(memcmp(i1, i2, n * sizeof(float)) == 0);
  CHECK(l1.time == l2.time && l1.stored_volume == l2.stored_volume &&
        l1.outflow_volume == l2.outflow_volume && l1.balance_error == l2.balance_error);

  /* WATER_DEPTH set after steps replaces the water: the ledger counts what
   * was added as initial water (the balance still closes, time goes on),
   * and reset now returns to it. */
  float *pond = alloc_field(&g, 1);
  for (size_t c = 0; c < n; ++c)
    pond[c] = (float)(0.05 * hash01((int)c, 1, 12));
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_WATER_DEPTH, pond) == GR_OK);
  gr_rain_runoff_ledger l3 = ledger(s);
  double in3 = l3.initial_volume + l3.rain_volume;
  CHECK(l3.time == l2.time && l3.steps == l2.steps);
  CHECK_NEAR(l3.stored_volume, sum_of(pond, n) * g.dx * g.dy, 1e-9 * l3.stored_volume);
  CHECK_MSG(fabs(l3.balance_error) <= 1e-7 * in3, "balance %.3g", l3.balance_error);
  run_stable(s, 2, 40);
  gr_rain_runoff_ledger l4 = ledger(s);
  CHECK_MSG(fabs(l4.balance_error) <= 1e-7 * (l4.initial_volume + l4.rain_volume), "balance %.3g",
            l4.balance_error);
  CHECK(gr_rain_runoff_reset(s) == GR_OK);
  float *hp = get(s, &g, GR_FIELD_WATER_DEPTH);
  CHECK(memcmp(hp, pond, n * sizeof(float)) == 0);
  gr_rain_runoff_ledger l5 = ledger(s);
  CHECK_NEAR(l5.initial_volume, sum_of(pond, n) * g.dx * g.dy, 1e-9 * l5.initial_volume);
  CHECK(l5.steps == 0 && l5.balance_error == l5.initial_volume - l5.stored_volume);
  free(hp);
  free(pond);
  free(h0);
  free(h1);
  free(v1);
  free(i1);
  free(hr);
  free(vr);
  free(ir);
  free(h2);
  free(v2);
  free(i2);
  gr_rain_runoff_destroy(s);
}

/* Long runs: the cumulative infiltration is Kahan-summed, so 2 10^4 tiny
 * increments (3e-7 m each) add up to k t within 1e-6 (a plain float sum
 * would be off by about 1e-3). */
void test_long_run(int steps) {
  gr_grid g = {8, 8, 1.0, 1.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  float *d = alloc_field(&g, 1);
  for (size_t c = 0; c < n; ++c)
    d[c] = 0.5f;
  gr_rain_runoff_params p = params_with(0.0, 3e-7, GR_BOUNDARY_CLOSED);
  gr_rain_runoff *s = make_sim(&g, &p, NULL, d);
  if (!s)
    return;
  CHECK(gr_rain_runoff_step(s, 1.0, steps) == GR_OK);
  float *inf = get(s, &g, GR_FIELD_INFILTRATED);
  double expect = (double)(float)3e-7 * (double)steps, worst = 0.0;
  for (size_t c = 0; c < n; ++c)
    worst = fmax(worst, fabs(inf[c] - expect) / expect);
  printf("long run: %d steps, infiltrated within %.2g of k t\n", steps, worst);
  CHECK_MSG(worst <= 1e-6, "infiltrated off k t by %.3g", worst);
  gr_rain_runoff_ledger l = ledger(s);
  CHECK_NEAR(l.infiltrated_volume, expect * (double)n, 1e-6 * expect * (double)n);
  free(inf);
  free(d);
  gr_rain_runoff_destroy(s);
}
