/* Rain runoff tests of the boundaries per edge (test_rain_runoff.c has
 * main): walls, level edges, transmissive edges and their mirror images. */
#include "test_rain_runoff.h"

/* ------------------------------------------------ boundaries per edge */

/* Parameters of model m (0 shallow water, 1 local inertial) with every edge
 * a wall and no rain. */
gr_rain_runoff_params edge_params(int m) {
  gr_rain_runoff_params p = params_with(0.0, 0.0, GR_BOUNDARY_CLOSED);
  p.flow_model = m ? GR_FLOW_LOCAL_INERTIAL : GR_FLOW_SHALLOW_WATER;
  return p;
}

/* A terrain falling toward edge e (0 west, 1 east, 2 south, 3 north) by
 * 0.05 per cell, with bumps. */
static void tilt_toward(const gr_grid *g, int e, float *b) {
  for (int j = 0; j < g->ny; ++j)
    for (int i = 0; i < g->nx; ++i) {
      int d = e == 0 ? i : (e == 1 ? g->nx - 1 - i : (e == 2 ? j : g->ny - 1 - j));
      b[(size_t)j * g->nx + i] = (float)(0.05 * d + 0.03 * hash01(i, j, 21));
    }
}

/* A wall passes nothing: rain on a terrain tilted toward one edge, all four
 * edges walls: no outflow, no inflow, the ledger closed. Each edge on its
 * own: open, it lets most of the rain go (the kinds reach the right
 * sides); the opposite edge open instead lets little go (the top's film). */
void test_edges_wall(void) {
  gr_grid g = {16, 14, 2.0, 2.0, 0.0, 0.0, 0, 0};
  float *b = alloc_field(&g, 1);
  for (int m = 0; m < 2; ++m)
    for (int e = 0; e < 4; ++e) {
      tilt_toward(&g, e, b);
      gr_rain_runoff_params p = edge_params(m);
      p.rain_rate = 100.0 / 3.6e6;
      double out[3] = {0.0, 0.0, 0.0};
      for (int k = 0; k < 3; ++k) {
        /* k 0: every edge a wall; 1: edge e open; 2: the opposite edge open. */
        set_edges(&p, GR_BOUNDARY_CLOSED);
        if (k)
          p.boundary[k == 1 ? e : e ^ 1] = GR_BOUNDARY_OPEN;
        gr_rain_runoff *s = make_sim(&g, &p, b, NULL);
        if (!s)
          continue;
        CHECK(gr_rain_runoff_advance(s, 300.0, NULL) == GR_OK);
        gr_rain_runoff_ledger l = ledger(s);
        out[k] = l.outflow_volume / l.rain_volume;
        CHECK_MSG(fabs(l.balance_error) < 1e-6 * l.rain_volume, "%s, edge %d, case %d: balance %g",
                  model_names[m], e, k, l.balance_error);
        CHECK(l.inflow_volume == 0.0);
        if (k == 0)
          CHECK_MSG(l.outflow_volume == 0.0, "%s: walls let %g m^3 out", model_names[m],
                    l.outflow_volume);
        gr_rain_runoff_destroy(s);
      }
      CHECK_MSG(out[1] > 0.3 && out[2] < 0.1 * out[1],
                "%s, edge %d: the low edge open lets %.3f of the rain out, the high one %.4f",
                model_names[m], e, out[1], out[2]);
      if (e == 0)
        printf("%s: walls 0 out; the low edge open %.3f of the rain out, the high one %.4f\n",
               model_names[m], out[1], out[2]);
    }
  free(b);
}

/* A level edge fills a flat, dry basin (walls elsewhere) to its level, then
 * drains it to a lower one: every cell within 1 mm of the level, the
 * water that came in (went out) in the ledger's inflow (outflow), which
 * closes. */
void test_edges_level(void) {
  gr_grid g = {12, 10, 5.0, 5.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  double area = 60.0 * 50.0;
  for (int m = 0; m < 2; ++m) {
    gr_rain_runoff_params p = edge_params(m);
    p.manning_n = 0.1;
    p.boundary[GR_RAIN_RUNOFF_WEST] = GR_BOUNDARY_LEVEL;
    p.boundary_level[GR_RAIN_RUNOFF_WEST] = 1.0;
    gr_rain_runoff *s = make_sim(&g, &p, NULL, NULL);
    if (!s)
      continue;
    const double levels[2] = {1.0, 0.4};
    for (int phase = 0; phase < 2; ++phase) {
      p.boundary_level[GR_RAIN_RUNOFF_WEST] = levels[phase];
      CHECK(gr_rain_runoff_set_params(s, &p) == GR_OK);
      CHECK(gr_rain_runoff_advance(s, 3600.0, NULL) == GR_OK);
      float *h = get(s, &g, GR_FIELD_WATER_DEPTH);
      double worst = 0.0;
      for (size_t c = 0; c < n; ++c)
        worst = fmax(worst, fabs(h[c] - levels[phase]));
      gr_rain_runoff_ledger l = ledger(s);
      CHECK_MSG(worst < 1e-3, "%s: a depth is %.2e m off the level %g m", model_names[m], worst,
                levels[phase]);
      CHECK_NEAR(l.stored_volume, levels[phase] * area, 1e-3 * area);
      CHECK_NEAR(l.inflow_volume - l.outflow_volume, l.stored_volume, 1e-6 * l.inflow_volume);
      CHECK_MSG(fabs(l.balance_error) < 1e-6 * l.inflow_volume, "%s: balance %g of %g in",
                model_names[m], l.balance_error, l.inflow_volume);
      printf("%s: level %g m: depths within %.1e m, inflow %.2f, outflow %.2f, stored %.2f m^3, "
             "balance %.1e\n",
             model_names[m], levels[phase], worst, l.inflow_volume, l.outflow_volume,
             l.stored_volume, l.balance_error);
      free(h);
    }
    gr_rain_runoff_destroy(s);
  }
}

/* A transmissive edge lets steady, uniform flow down a tilted channel leave
 * without reflection: a level edge upstream feeds it, walls at the sides;
 * at the steady state the depth at the transmissive edge is the normal
 * depth of Manning's formula for the discharge that leaves, h = (q n /
 * sqrt(S))^(3/5), within 1%. A free outfall there instead draws the depth
 * down (toward the critical depth), more than 1% off: the test tells the
 * two apart. */
void test_edges_transmissive(void) {
  gr_grid g = {60, 3, 5.0, 5.0, 0.0, 0.0, 0, 0};
  const double S = 0.005, n_m = 0.03, h0 = 0.5;
  float *b = alloc_field(&g, 1), *d = alloc_field(&g, 1);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      b[(size_t)j * g.nx + i] = (float)(S * g.dx * (g.nx - i));
      d[(size_t)j * g.nx + i] = (float)h0;
    }
  for (int m = 0; m < 2; ++m)
    for (int k = 0; k < 2; ++k) {
      gr_rain_runoff_params p = edge_params(m);
      p.manning_n = n_m;
      p.boundary[GR_RAIN_RUNOFF_WEST] = GR_BOUNDARY_LEVEL;
      p.boundary_level[GR_RAIN_RUNOFF_WEST] = S * g.dx * (g.nx + 1) + h0;
      p.boundary[GR_RAIN_RUNOFF_EAST] = k ? GR_BOUNDARY_OPEN : GR_BOUNDARY_TRANSMISSIVE;
      gr_rain_runoff *s = make_sim(&g, &p, b, d);
      if (!s)
        continue;
      CHECK(gr_rain_runoff_advance(s, 1500.0, NULL) == GR_OK);
      gr_rain_runoff_ledger l1 = ledger(s);
      CHECK(gr_rain_runoff_advance(s, 300.0, NULL) == GR_OK);
      gr_rain_runoff_ledger l2 = ledger(s);
      double q = (l2.outflow_volume - l1.outflow_volume) / (l2.time - l1.time) / (g.ny * g.dy);
      double qin = (l2.inflow_volume - l1.inflow_volume) / (l2.time - l1.time) / (g.ny * g.dy);
      double hn = pow(q * n_m / sqrt(S), 0.6);
      float *h = get(s, &g, GR_FIELD_WATER_DEPTH);
      double edge = 0.0, mid = 0.0;
      for (int j = 0; j < g.ny; ++j) {
        edge += h[(size_t)j * g.nx + g.nx - 1] / g.ny;
        mid += h[(size_t)j * g.nx + g.nx / 2] / g.ny;
      }
      double err = fabs(edge - hn) / hn;
      CHECK_MSG(fabs(q - qin) < 1e-3 * q, "%s: not steady: %g in, %g out m^2/s", model_names[m],
                qin, q);
      CHECK_MSG(fabs(l2.balance_error) < 1e-6 * l2.inflow_volume, "%s: balance %g", model_names[m],
                l2.balance_error);
      if (k == 0) {
        CHECK_MSG(err < 0.01 && fabs(mid - hn) < 0.01 * hn,
                  "%s: the depth at the transmissive edge %.4f m, mid-channel %.4f m, normal "
                  "depth %.4f m",
                  model_names[m], edge, mid, hn);
      } else {
        CHECK_MSG(err > 0.01, "%s: an outfall keeps the normal depth (%.4f m, %.4f m)",
                  model_names[m], edge, hn);
      }
      printf("%s, %s edge: q %.4f m^2/s, normal depth %.4f m, at the edge %.4f m (%.2f%%), "
             "mid-channel %.4f m\n",
             model_names[m], k ? "outfall" : "transmissive", q, hn, edge, 100.0 * err, mid);
      free(h);
      gr_rain_runoff_destroy(s);
    }
  free(b);
  free(d);
}

/* Mirrored set-ups give mirrored fields, bit for bit: a terrain and its
 * mirror image in x, with the west and east edges' kinds and levels
 * swapped (a level edge, a transmissive one; a wall south, an outfall
 * north), in both models. */
void test_edges_mirror(void) {
  gr_grid g = {30, 16, 2.0, 2.5, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  float *b[2] = {alloc_field(&g, 1), alloc_field(&g, 1)};
  float *r[2] = {alloc_field(&g, 1), alloc_field(&g, 1)};
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      size_t c = (size_t)j * g.nx + i, mc = (size_t)j * g.nx + (g.nx - 1 - i);
      b[0][c] = b[1][mc] = (float)(0.9 - 0.03 * i + 0.01 * j + 0.2 * hash01(i, j, 31));
      r[0][c] = r[1][mc] = (float)(2e-5 * hash01(i, j, 32));
    }
  for (int m = 0; m < 2; ++m) {
    gr_rain_runoff *s[2] = {NULL, NULL};
    for (int k = 0; k < 2; ++k) {
      gr_rain_runoff_params p = edge_params(m);
      p.boundary[k ? GR_RAIN_RUNOFF_EAST : GR_RAIN_RUNOFF_WEST] = GR_BOUNDARY_LEVEL;
      p.boundary_level[k ? GR_RAIN_RUNOFF_EAST : GR_RAIN_RUNOFF_WEST] = 1.3;
      p.boundary[k ? GR_RAIN_RUNOFF_WEST : GR_RAIN_RUNOFF_EAST] = GR_BOUNDARY_TRANSMISSIVE;
      p.boundary[GR_RAIN_RUNOFF_NORTH] = GR_BOUNDARY_OPEN;
      s[k] = make_sim(&g, &p, b[k], NULL);
      if (s[k])
        CHECK(gr_rain_runoff_set_field(s[k], GR_FIELD_RAIN_RATE, r[k]) == GR_OK);
    }
    if (s[0] && s[1]) {
      run_stable(s[0], 8, 50);
      run_stable(s[1], 8, 50);
      float *h0 = get(s[0], &g, GR_FIELD_WATER_DEPTH), *h1 = get(s[1], &g, GR_FIELD_WATER_DEPTH);
      float *v0 = get(s[0], &g, GR_FIELD_VELOCITY), *v1 = get(s[1], &g, GR_FIELD_VELOCITY);
      int asym_h = 0, asym_v = 0, wet = 0;
      double dh = 0.0, dv = 0.0;
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) {
          size_t c = (size_t)j * g.nx + i, mc = (size_t)j * g.nx + (g.nx - 1 - i);
          asym_h += h0[c] != h1[mc];
          asym_v += v0[3 * c] != -v1[3 * mc] || v0[3 * c + 1] != v1[3 * mc + 1];
          dh = fmax(dh, fabs(h0[c] - h1[mc]));
          dv = fmax(dv, fmax(fabs(v0[3 * c] + v1[3 * mc]), fabs(v0[3 * c + 1] - v1[3 * mc + 1])));
          wet += h0[c] > 0.01f;
        }
      gr_rain_runoff_ledger l0 = ledger(s[0]), l1 = ledger(s[1]);
      CHECK(l0.inflow_volume > 0.0 && l0.outflow_volume > 0.0 && wet > (int)(n / 4));
      if (m == 1) {
        /* The local inertial model's faces are mirror-exact (test_symmetry). */
        CHECK_MSG(asym_h == 0 && asym_v == 0,
                  "%s: %d depths and %d velocities differ from their mirror image", model_names[m],
                  asym_h, asym_v);
        CHECK(l0.inflow_volume == l1.inflow_volume && l0.outflow_volume == l1.outflow_volume &&
              l0.stored_volume == l1.stored_volume);
      } else {
        /* The shallow-water HLL flux is F_L plus a difference (exact for a
         * lake at rest), which mirrors to rounding only. */
        CHECK_MSG(dh < 1e-6 && dv < 1e-5, "%s: mirrored depths %.2e m, velocities %.2e m/s apart",
                  model_names[m], dh, dv);
        CHECK_NEAR(l0.inflow_volume, l1.inflow_volume, 1e-6 * l0.inflow_volume);
        CHECK_NEAR(l0.outflow_volume, l1.outflow_volume, 1e-6 * l0.inflow_volume);
      }
      printf("%s: mirrored edges, %d wet cells, inflow %.3f, outflow %.3f m^3; %d depths, %d "
             "velocities differ, by %.1e m, %.1e m/s at most\n",
             model_names[m], wet, l0.inflow_volume, l0.outflow_volume, asym_h, asym_v, dh, dv);
      free(h0);
      free(h1);
      free(v0);
      free(v1);
    }
    gr_rain_runoff_destroy(s[0]);
    gr_rain_runoff_destroy(s[1]);
  }
  for (int k = 0; k < 2; ++k) {
    free(b[k]);
    free(r[k]);
  }
}
