/* Rain runoff tests of the optional inputs (test_rain_runoff.c has main):
 * point and edge inflows, the hyetograph, the Manning map and no-data
 * cells. */
#include "test_rain_runoff.h"

/* ----------------------------------------------------------- inflows */

/* A point inflow in a walled, flat basin raises the level by Q t / area:
 * Q for 600 s (two sources, one of them twice in the same cell), then 1800
 * s to settle; every cell within 1 mm of Q t / area, the ledger's inflow Q t
 * to float rounding and the stored water inflow - outflow (0). */
void test_inflow_point(void) {
  gr_grid g = {20, 16, 2.0, 3.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  const double area = 40.0 * 48.0, T = 600.0;
  const int ij[6] = {3, 4, 15, 11, 3, 4};
  const double q[3] = {0.1, 0.15, 0.05}, Q = 0.3;
  for (int m = 0; m < 2; ++m) {
    gr_rain_runoff_params p = edge_params(m);
    p.manning_n = 0.05;
    gr_rain_runoff *s = make_sim(&g, &p, NULL, NULL);
    if (!s)
      continue;
    CHECK(gr_rain_runoff_set_point_inflows(s, ij, q, 3) == GR_OK);
    CHECK(gr_rain_runoff_advance(s, T, NULL) == GR_OK);
    gr_rain_runoff_ledger l1 = ledger(s);
    CHECK(gr_rain_runoff_set_point_inflows(s, NULL, NULL, 0) == GR_OK);
    CHECK(gr_rain_runoff_advance(s, 1800.0, NULL) == GR_OK);
    gr_rain_runoff_ledger l2 = ledger(s);
    float *h = get(s, &g, GR_FIELD_WATER_DEPTH);
    double rise = Q * T / area, worst = 0.0;
    for (size_t c = 0; c < n; ++c)
      worst = fmax(worst, fabs(h[c] - rise));
    CHECK_MSG(fabs(l1.inflow_volume - Q * T) < 1e-6 * Q * T, "%s: inflow %.9g, Q t %.9g",
              model_names[m], l1.inflow_volume, Q * T);
    CHECK(l2.inflow_volume == l1.inflow_volume && l2.outflow_volume == 0.0);
    CHECK_NEAR(l2.stored_volume, l2.inflow_volume, 1e-6 * l2.inflow_volume);
    CHECK(fabs(l2.balance_error) < 1e-6 * l2.inflow_volume);
    CHECK_MSG(worst < 1e-3, "%s: a cell is %.2e m off the level Q t / area = %.4f m",
              model_names[m], worst, rise);
    printf("%s: point inflows of %g m^3/s for %g s: inflow %.6f m^3 (Q t %.6f), level %.5f m "
           "(Q t / area %.5f), every cell within %.1e m\n",
           model_names[m], Q, T, l1.inflow_volume, Q * T, l2.stored_volume / area, rise, worst);
    free(h);
    gr_rain_runoff_destroy(s);
  }
}

/* An inflow hydrograph along the west edge of a channel whose east edge is
 * an outfall: the ledger's inflow is the table's integral, whatever the
 * steps (some straddle its corners), to float rounding; stored = inflow -
 * outflow; and the same table on a walled basin fills it by that much. */
void test_inflow_edge(void) {
  gr_grid g = {24, 6, 5.0, 4.0, 0.0, 0.0, 0, 0};
  float *b = alloc_field(&g, 1);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i)
      b[(size_t)j * g.nx + i] = (float)(0.01 * (g.nx - i) + 0.02 * hash01(i, j, 41));
  const double t[4] = {0.0, 100.0, 300.0, 400.0}, q[4] = {0.0, 0.5, 0.5, 0.0};
  const double expect = 150.0; /* the trapezoids: 25 + 100 + 25 m^3 */
  for (int m = 0; m < 2; ++m)
    for (int walled = 0; walled < 2; ++walled) {
      gr_rain_runoff_params p = edge_params(m);
      if (!walled)
        p.boundary[GR_RAIN_RUNOFF_EAST] = GR_BOUNDARY_OPEN;
      gr_rain_runoff *s = make_sim(&g, &p, walled ? NULL : b, NULL);
      if (!s)
        continue;
      CHECK(gr_rain_runoff_set_edge_inflow(s, GR_RAIN_RUNOFF_WEST, t, q, 4) == GR_OK);
      /* Stretches that end off the table's corners. */
      const double spans[4] = {73.0, 141.5, 200.25, 85.25};
      for (int k = 0; k < 4; ++k)
        CHECK(gr_rain_runoff_advance(s, spans[k], NULL) == GR_OK);
      gr_rain_runoff_ledger l = ledger(s);
      CHECK_MSG(fabs(l.inflow_volume - expect) < 1e-6 * expect,
                "%s: inflow %.9g m^3, the hydrograph's integral %.9g", model_names[m],
                l.inflow_volume, expect);
      CHECK_NEAR(l.stored_volume, l.inflow_volume - l.outflow_volume, 1e-6 * expect);
      CHECK(walled ? l.outflow_volume == 0.0 : l.outflow_volume > 0.05 * expect);
      printf("%s, %s: hydrograph inflow %.7f m^3 (integral %g), outflow %.3f, stored %.3f, "
             "balance %.1e\n",
             model_names[m], walled ? "walled basin" : "channel", l.inflow_volume, expect,
             l.outflow_volume, l.stored_volume, l.balance_error);
      gr_rain_runoff_destroy(s);
    }
  free(b);
}

/* Bad inflows: one sentence naming the row or source and its value; the
 * inflows stay as they were. */
void test_inflow_errors(void) {
  gr_grid g = {8, 6, 1.0, 1.0, 0.0, 0.0, 0, 0};
  gr_rain_runoff_params p = edge_params(0);
  gr_rain_runoff *s = make_sim(&g, &p, NULL, NULL);
  if (!s)
    return;
  const double t_bad[3] = {0.0, 10.0, 10.0}, t_ok[3] = {0.0, 10.0, 20.0};
  const double q_ok[3] = {1.0, 2.0, 0.0}, q_neg[3] = {1.0, -2.0, 0.0}, q_nan[3] = {1.0, NAN, 0.0};
  const char *e;
  CHECK(gr_rain_runoff_set_edge_inflow(s, GR_RAIN_RUNOFF_EAST, t_bad, q_ok, 3) ==
        GR_ERR_INVALID_ARGUMENT);
  e = gr_rain_runoff_last_error(s);
  CHECK_MSG(has(e, "east edge's inflow hydrograph's times must increase") && has(e, "row 2"),
            "'%s'", e);
  CHECK(gr_rain_runoff_set_edge_inflow(s, GR_RAIN_RUNOFF_NORTH, t_ok, q_neg, 3) ==
        GR_ERR_INVALID_ARGUMENT);
  e = gr_rain_runoff_last_error(s);
  CHECK_MSG(has(e, "north edge's") && has(e, "-2 m^3/s in row 1"), "'%s'", e);
  CHECK(gr_rain_runoff_set_edge_inflow(s, GR_RAIN_RUNOFF_NORTH, t_ok, q_nan, 3) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_set_edge_inflow(s, 4, t_ok, q_ok, 3) == GR_ERR_INVALID_ARGUMENT);
  CHECK(has(gr_rain_runoff_last_error(s), "got 4"));
  CHECK(gr_rain_runoff_set_edge_inflow(s, 0, NULL, q_ok, 3) == GR_ERR_INVALID_ARGUMENT);
  const int ij[4] = {2, 2, 8, 1};
  const double pq[2] = {1.0, 1.0}, pneg[2] = {-1.0, 1.0};
  CHECK(gr_rain_runoff_set_point_inflows(s, ij, pq, 2) == GR_ERR_INVALID_ARGUMENT);
  e = gr_rain_runoff_last_error(s);
  CHECK_MSG(has(e, "Point inflow 1 is the cell (8, 1), outside"), "'%s'", e);
  CHECK(gr_rain_runoff_set_point_inflows(s, ij, pneg, 1) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(gr_rain_runoff_last_error(s), "Point inflow 0 has the discharge -1 m^3/s"), "'%s'",
            gr_rain_runoff_last_error(s));
  CHECK(gr_rain_runoff_set_point_inflows(s, ij, pq, -1) == GR_ERR_INVALID_ARGUMENT);
  /* Nothing was taken: no inflow. */
  CHECK(gr_rain_runoff_advance(s, 5.0, NULL) == GR_OK);
  CHECK(ledger(s).inflow_volume == 0.0);
  gr_rain_runoff_destroy(s);
}

/* ------------------------------------------- hyetograph, Manning map */

/* Rain from a hyetograph (a triangle, 0 to 50 mm/h at 60 s and back to 0 at
 * 120 s, then nothing) on flat, walled ground: the ledger's rain is the
 * table's integral times the area and every cell holds that integral, to
 * float rounding, whatever the steps; removed, RainRate rains again. */
void test_hyetograph(void) {
  gr_grid g = {10, 8, 2.0, 3.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  const double area = 20.0 * 24.0, mmh = 1.0 / 3.6e6;
  const double t[3] = {0.0, 60.0, 120.0}, r[3] = {0.0, 50.0 * mmh, 0.0};
  const double depth = 0.5 * 120.0 * 50.0 * mmh;
  for (int m = 0; m < 2; ++m) {
    gr_rain_runoff_params p = edge_params(m);
    p.rain_rate = 7.0 * mmh; /* replaced while the hyetograph is set */
    gr_rain_runoff *s = make_sim(&g, &p, NULL, NULL);
    if (!s)
      continue;
    CHECK(gr_rain_runoff_set_hyetograph(s, t, r, 3) == GR_OK);
    const double spans[3] = {37.0, 51.5, 111.5};
    for (int k = 0; k < 3; ++k)
      CHECK(gr_rain_runoff_advance(s, spans[k], NULL) == GR_OK);
    gr_rain_runoff_ledger l = ledger(s);
    float *h = get(s, &g, GR_FIELD_WATER_DEPTH);
    double worst = 0.0;
    for (size_t c = 0; c < n; ++c)
      worst = fmax(worst, fabs(h[c] - depth));
    CHECK_MSG(fabs(l.rain_volume - depth * area) < 1e-6 * depth * area,
              "%s: rain %.9g m^3, the hyetograph's integral times the area %.9g", model_names[m],
              l.rain_volume, depth * area);
    CHECK_MSG(worst < 1e-6 * depth, "%s: a depth is %.2e m off %.6e m", model_names[m], worst,
              depth);
    CHECK(fabs(l.balance_error) < 1e-6 * l.rain_volume);
    printf("%s: hyetograph rain %.9f m^3 (integral x area %.9f), depths within %.1e m\n",
           model_names[m], l.rain_volume, depth * area, worst);
    CHECK(gr_rain_runoff_set_hyetograph(s, NULL, NULL, 0) == GR_OK);
    CHECK(gr_rain_runoff_advance(s, 100.0, NULL) == GR_OK);
    gr_rain_runoff_ledger l2 = ledger(s);
    CHECK_NEAR(l2.rain_volume - l.rain_volume, 7.0 * mmh * 100.0 * area, 1e-6 * l2.rain_volume);
    free(h);
    /* Bad tables: a sentence naming the row; the table stays removed. */
    const double tb[3] = {0.0, 60.0, 30.0}, rb[3] = {0.0, 5000.0 * mmh, 0.0};
    CHECK(gr_rain_runoff_set_hyetograph(s, tb, r, 3) == GR_ERR_INVALID_ARGUMENT);
    CHECK_MSG(has(gr_rain_runoff_last_error(s), "times must increase") &&
                  has(gr_rain_runoff_last_error(s), "row 2 has 30 s after 60 s"),
              "'%s'", gr_rain_runoff_last_error(s));
    CHECK(gr_rain_runoff_set_hyetograph(s, t, rb, 3) == GR_ERR_INVALID_ARGUMENT);
    CHECK_MSG(has(gr_rain_runoff_last_error(s), "rain rate 5000 mm/h in row 1") &&
                  has(gr_rain_runoff_last_error(s), "between 0 and 3600 mm/h"),
              "'%s'", gr_rain_runoff_last_error(s));
    gr_rain_runoff_destroy(s);
  }
}

/* A Manning map of ManningN everywhere is the uniform run bit for bit; a
 * rougher south half (n 0.1 against 0.03) of a plane tilted to the west
 * slows the sheet flow there (deeper, slower: kinematic-wave theory says
 * speeds (0.03 / 0.1)^(3/5) = 0.49 times; measured 0.47 shallow water,
 * 0.43 local inertial: within 15%); bad maps are refused. */
void test_manning_map(void) {
  gr_grid g = {30, 20, 2.0, 2.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  float *b = alloc_field(&g, 1);
  double *nmap = malloc(n * sizeof(double));
  for (int m = 0; m < 2; ++m) {
    /* The same map in a bumpy bowl: bit for bit. */
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        b[(size_t)j * g.nx + i] = (float)(0.02 * i + 0.2 * hash01(i, j, 51));
    for (size_t c = 0; c < n; ++c)
      nmap[c] = 0.045;
    gr_rain_runoff_params p = edge_params(m);
    p.manning_n = 0.045;
    p.rain_rate = 80.0 / 3.6e6;
    p.boundary[GR_RAIN_RUNOFF_WEST] = GR_BOUNDARY_OPEN;
    gr_rain_runoff *u = make_sim(&g, &p, b, NULL), *v = make_sim(&g, &p, b, NULL);
    if (u && v) {
      CHECK(gr_rain_runoff_set_manning_map(v, nmap) == GR_OK);
      run_stable(u, 6, 40);
      run_stable(v, 6, 40);
      const gr_field fields[] = {GR_FIELD_WATER_DEPTH, GR_FIELD_VELOCITY};
      long diff = 0;
      for (int f = 0; f < 2; ++f) {
        float *x = get(u, &g, fields[f]), *y = get(v, &g, fields[f]);
        diff += memcmp(x, y, n * (size_t)gr_field_components(fields[f]) * sizeof(float)) != 0;
        free(x);
        free(y);
      }
      CHECK_MSG(diff == 0, "%s: a map of ManningN everywhere differs from the uniform run",
                model_names[m]);
      CHECK(ledger(u).outflow_volume == ledger(v).outflow_volume && ledger(u).steps > 0);
    }
    gr_rain_runoff_destroy(u);
    gr_rain_runoff_destroy(v);
    /* A rougher south half on a plane tilted to the west. */
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        b[(size_t)j * g.nx + i] = (float)(0.02 * g.dx * i);
        nmap[(size_t)j * g.nx + i] = j < g.ny / 2 ? 0.1 : 0.03;
      }
    p.manning_n = 0.03;
    gr_rain_runoff *r = make_sim(&g, &p, b, NULL);
    if (!r)
      continue;
    CHECK(gr_rain_runoff_set_manning_map(r, nmap) == GR_OK);
    CHECK(gr_rain_runoff_advance(r, 1800.0, NULL) == GR_OK);
    float *h = get(r, &g, GR_FIELD_WATER_DEPTH), *vel = get(r, &g, GR_FIELD_VELOCITY);
    /* Rows away from the halves' seam, column 5 (60 m of plane upstream). */
    double us = 0.0, ur = 0.0, hs = 0.0, hr = 0.0;
    for (int j = 2; j < 7; ++j) {
      size_t cr = (size_t)j * g.nx + 5, cs = (size_t)(g.ny - 1 - j) * g.nx + 5;
      ur += fabs(vel[3 * cr]) / 5.0;
      us += fabs(vel[3 * cs]) / 5.0;
      hr += h[cr] / 5.0;
      hs += h[cs] / 5.0;
    }
    double ratio = ur / us, expect = pow(0.03 / 0.1, 0.6);
    CHECK_MSG(fabs(ratio - expect) < 0.15 * expect && hr > hs,
              "%s: the rough half flows %.3f times as fast as the smooth one (theory %.3f), "
              "%.4f m deep against %.4f m",
              model_names[m], ratio, expect, hr, hs);
    printf("%s: rough half (n 0.1) %.4f m/s, %.4f m; smooth half (n 0.03) %.4f m/s, %.4f m: "
           "speed ratio %.3f (kinematic wave %.3f)\n",
           model_names[m], ur, hr, us, hs, ratio, expect);
    free(h);
    free(vel);
    /* Bad maps: a sentence naming the cell; FlowModel 1 needs 0.005. */
    nmap[7] = 2.0;
    CHECK(gr_rain_runoff_set_manning_map(r, nmap) == GR_ERR_INVALID_ARGUMENT);
    CHECK_MSG(has(gr_rain_runoff_last_error(r), "value 2 s/m^(1/3) at cell (7, 0)"), "'%s'",
              gr_rain_runoff_last_error(r));
    nmap[7] = 0.001;
    if (m == 0) {
      CHECK(gr_rain_runoff_set_manning_map(r, nmap) == GR_OK);
      gr_rain_runoff_params q = p;
      q.flow_model = GR_FLOW_LOCAL_INERTIAL;
      CHECK(gr_rain_runoff_set_params(r, &q) == GR_ERR_INVALID_ARGUMENT);
      CHECK(has(gr_rain_runoff_last_error(r), "smallest n is 0.001"));
    } else {
      CHECK(gr_rain_runoff_set_manning_map(r, nmap) == GR_ERR_INVALID_ARGUMENT);
      CHECK(has(gr_rain_runoff_last_error(r), "for FlowModel 1"));
    }
    gr_rain_runoff_destroy(r);
  }
  free(b);
  free(nmap);
}

/* ---------------------------------------------------------- no-data cells */

/* A DEM with a NaN border (2 cells) and a NaN hole (4 x 3 cells): rain on
 * it, both models, the no-data cells walls (the default) and outfalls.
 * Walls: nothing leaves, the rain is that of the domain's cells only, the
 * ledger closes; outfalls: water leaves over the brinks, the ledger closes;
 * either way every output is NaN on the no-data cells and finite
 * elsewhere. And a lake at rest around the hole stays at rest. */
void test_no_data(void) {
  gr_grid g = {30, 24, 2.0, 2.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  float *b = alloc_field(&g, 1);
  int holes = 0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      size_t c = (size_t)j * g.nx + i;
      int border = i < 2 || j < 2 || i >= g.nx - 2 || j >= g.ny - 2;
      int hole = i >= 12 && i < 16 && j >= 10 && j < 13;
      b[c] = border || hole ? NAN : (float)(0.03 * i + 0.01 * j + 0.1 * hash01(i, j, 61));
      holes += border || hole;
    }
  const double r = 50.0 / 3.6e6, T = 600.0, area = 4.0;
  const double rain = (double)(n - (size_t)holes) * (double)(float)r * T * area;
  for (int m = 0; m < 2; ++m)
    for (int k = 0; k < 2; ++k) {
      gr_rain_runoff_params p = edge_params(m);
      set_edges(&p, GR_BOUNDARY_OPEN);
      p.rain_rate = r;
      p.no_data = k ? GR_BOUNDARY_OPEN : GR_BOUNDARY_CLOSED;
      gr_rain_runoff *s = make_sim(&g, &p, b, NULL);
      if (!s)
        continue;
      CHECK(gr_rain_runoff_advance(s, T, NULL) == GR_OK);
      gr_rain_runoff_ledger l = ledger(s);
      CHECK_MSG(fabs(l.rain_volume - rain) < 1e-6 * rain,
                "%s: rain %.9g m^3 on the domain's cells, expected %.9g", model_names[m],
                l.rain_volume, rain);
      CHECK_MSG(fabs(l.balance_error) < 1e-6 * rain, "%s, %s: balance %g of %g", model_names[m],
                k ? "outfalls" : "walls", l.balance_error, rain);
      if (k == 0)
        CHECK_MSG(l.outflow_volume == 0.0 && l.stored_volume > 0.99 * rain,
                  "%s: walls let %g m^3 out", model_names[m], l.outflow_volume);
      else
        CHECK_MSG(l.outflow_volume > 0.1 * rain, "%s: outfalls let only %g of %g m^3 out",
                  model_names[m], l.outflow_volume, rain);
      const gr_field fields[] = {GR_FIELD_WATER_DEPTH, GR_FIELD_WATER_SURFACE, GR_FIELD_VELOCITY,
                                 GR_FIELD_DISCHARGE, GR_FIELD_ELEVATION};
      long wrong = 0;
      for (size_t f = 0; f < sizeof(fields) / sizeof(fields[0]); ++f) {
        int comps = gr_field_components(fields[f]);
        float *v = get(s, &g, fields[f]);
        for (size_t c = 0; c < n; ++c)
          for (int q = 0; q < comps; ++q)
            wrong += isnan(b[c]) != isnan(v[c * (size_t)comps + (size_t)q]);
        free(v);
      }
      for (int map = 0; map < GR_RAIN_RUNOFF_MAP_COUNT; ++map) {
        if (map == GR_RAIN_RUNOFF_ARRIVAL_TIME)
          continue; /* NaN also where never wet */
        float *v = get_map(s, &g, (gr_rain_runoff_map)map);
        for (size_t c = 0; c < n; ++c)
          wrong += isnan(b[c]) != isnan(v[c]);
        free(v);
      }
      CHECK_MSG(wrong == 0, "%s: %ld values are NaN off the no-data cells or not NaN on them",
                model_names[m], wrong);
      printf("%s, no-data cells as %s: rain %.4f m^3 (domain cells only), outflow %.4f, stored "
             "%.4f, balance %.1e; NaN exactly on the %d no-data cells\n",
             model_names[m], k ? "outfalls" : "walls", l.rain_volume, l.outflow_volume,
             l.stored_volume, l.balance_error, holes);
      /* Switching the kind later rebuilds the cells: walls again hold it. */
      if (k == 1) {
        p.no_data = GR_BOUNDARY_CLOSED;
        CHECK(gr_rain_runoff_set_params(s, &p) == GR_OK);
        double out = ledger(s).outflow_volume;
        CHECK(gr_rain_runoff_advance(s, 60.0, NULL) == GR_OK);
        CHECK(ledger(s).outflow_volume == out);
      }
      gr_rain_runoff_destroy(s);
    }
  /* A lake at rest, 1 m deep on a flat bed, around the hole and inside the
   * border: still after 300 steps, no water goes anywhere. */
  float *d = alloc_field(&g, 1);
  for (size_t c = 0; c < n; ++c) {
    d[c] = 1.0f;
    if (!isnan(b[c]))
      b[c] = 0.0f;
  }
  for (int m = 0; m < 2; ++m) {
    gr_rain_runoff_params p = edge_params(m);
    gr_rain_runoff *s = make_sim(&g, &p, b, d);
    if (!s)
      continue;
    run_stable(s, 6, 50);
    float *v = get(s, &g, GR_FIELD_VELOCITY), *h = get(s, &g, GR_FIELD_WATER_DEPTH);
    double vmax = 0.0, hdev = 0.0;
    for (size_t c = 0; c < n; ++c)
      if (!isnan(b[c])) {
        vmax = fmax(vmax, fmax(fabs(v[3 * c]), fabs(v[3 * c + 1])));
        hdev = fmax(hdev, fabs(h[c] - 1.0));
      }
    gr_rain_runoff_ledger l = ledger(s);
    CHECK_MSG(vmax < 1e-6 && hdev < 1e-6, "%s: the lake moves around the hole (%.2e m/s, %.2e m)",
              model_names[m], vmax, hdev);
    CHECK(fabs(l.initial_volume - (double)(n - (size_t)holes) * area) < 1e-9 * l.initial_volume);
    printf("%s: a lake at rest around the hole: speeds %.1e m/s, depths within %.1e m\n",
           model_names[m], vmax, hdev);
    free(v);
    free(h);
    gr_rain_runoff_destroy(s);
  }
  free(d);
  free(b);
}
