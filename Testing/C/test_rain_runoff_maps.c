/* Rain runoff tests of the flood maps and gauges (test_rain_runoff.c has
 * main). */
#include "test_rain_runoff.h"

/* ------------------------------------------------------------ flood maps */

float *get_map(gr_rain_runoff *s, const gr_grid *g, gr_rain_runoff_map m) {
  float *v = alloc_field(g, 1);
  gr_status st = gr_rain_runoff_get_map(s, m, v);
  CHECK_MSG(st == GR_OK, "get map %s: %s", gr_rain_runoff_map_name(m), gr_last_error(ctx));
  return v;
}

/* FD2321's rating of depth d (m) and speed v (m/s) with debris factor df,
 * by hand: df counts above 0.25 m only. */
static double hazard_of(double d, double v, double df) {
  return d * (v + 0.5) + (d > 0.25 ? df : 0.0);
}

/* The maps against a run that reads the depth and the velocity back after
 * every step (and at time 0): max_depth is the maximum of the depths, bit
 * for bit (so at least the depth at every step), max_speed and
 * hazard_rating the maxima of |velocity| and h (|v| + 0.5) + DF to float
 * rounding (the speed where the depth exceeds the wetting depth only),
 * arrival_time the end time of the first step that left the cell
 * above the wetting depth (NaN where none did), wet_duration the sum of
 * those steps' dt, hazard_class the class of the rating; both flow models,
 * a dam break of 1 m on a bumpy bed with rain, DebrisFactor 0.5. */
void test_maps_every_step(void) {
  for (int model = 0; model < 2; ++model) {
    gr_grid g = {24, 10, 1.0, 1.0, 0.0, 0.0, 0, 0};
    size_t n = cells_of(&g);
    float *b = alloc_field(&g, 1), *d0 = alloc_field(&g, 1);
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        size_t c = (size_t)j * g.nx + i;
        b[c] = (float)(0.05 * hash01(i, j, 7) + 0.01 * i);
        d0[c] = i < 6 ? 1.0f : 0.0f;
      }
    gr_rain_runoff_params p;
    gr_rain_runoff_params_init(&p);
    p.flow_model = model ? GR_FLOW_LOCAL_INERTIAL : GR_FLOW_SHALLOW_WATER;
    p.rain_rate = 50.0 / 3.6e6;
    p.debris_factor = 0.5;
    set_edges(&p, GR_BOUNDARY_OPEN);
    gr_rain_runoff *s = make_sim(&g, &p, b, d0);
    if (!s) {
      free(b);
      free(d0);
      return;
    }
    double *hmax = calloc(n, sizeof(double)), *vmax = calloc(n, sizeof(double));
    double *hrmax = calloc(n, sizeof(double)), *wet = calloc(n, sizeof(double));
    double *arrive = malloc(n * sizeof(double));
    for (size_t c = 0; c < n; ++c)
      arrive[c] = -1.0;
    double t = 0.0, dt = 0.0;
    const int steps = 150;
    int below = 0; /* depths above max_depth at some step: must stay 0 */
    for (int k = 0; k <= steps; ++k) {
      if (k > 0) {
        gr_rain_runoff_stable_dt(s, &dt);
        CHECK(gr_rain_runoff_step(s, dt, 1) == GR_OK);
        t += dt;
      }
      float *h = get(s, &g, GR_FIELD_WATER_DEPTH), *v = get(s, &g, GR_FIELD_VELOCITY);
      float *mx = get_map(s, &g, GR_RAIN_RUNOFF_MAX_DEPTH);
      for (size_t c = 0; c < n; ++c) {
        double sp = sqrt((double)v[3 * c] * v[3 * c] + (double)v[3 * c + 1] * v[3 * c + 1]);
        hmax[c] = fmax(hmax[c], h[c]);
        if (h[c] > p.wetting_depth)
          vmax[c] = fmax(vmax[c], sp);
        hrmax[c] = fmax(hrmax[c], hazard_of(h[c], sp, p.debris_factor));
        below += h[c] > mx[c];
        if (h[c] > p.wetting_depth) {
          if (arrive[c] < 0.0)
            arrive[c] = (float)t;
          wet[c] += k > 0 ? (double)(float)dt : 0.0;
        }
      }
      free(h);
      free(v);
      free(mx);
    }
    float *md = get_map(s, &g, GR_RAIN_RUNOFF_MAX_DEPTH),
          *ms = get_map(s, &g, GR_RAIN_RUNOFF_MAX_SPEED);
    float *at = get_map(s, &g, GR_RAIN_RUNOFF_ARRIVAL_TIME);
    float *wd = get_map(s, &g, GR_RAIN_RUNOFF_WET_DURATION);
    float *hr = get_map(s, &g, GR_RAIN_RUNOFF_HAZARD_RATING);
    float *hc = get_map(s, &g, GR_RAIN_RUNOFF_HAZARD_CLASS);
    int depth_bits = 0, never = 0, classes[4] = {0, 0, 0, 0}, arrival_bits = 0;
    double speed_err = 0.0, hazard_err = 0.0, wet_err = 0.0, vtop = 0.0, hrtop = 0.0;
    for (size_t c = 0; c < n; ++c) {
      depth_bits += md[c] != (float)hmax[c];
      speed_err = fmax(speed_err, fabs(ms[c] - vmax[c]));
      hazard_err = fmax(hazard_err, fabs(hr[c] - hrmax[c]));
      vtop = fmax(vtop, vmax[c]);
      hrtop = fmax(hrtop, hrmax[c]);
      if (arrive[c] < 0.0)
        never += isnan(at[c]) && wd[c] == 0.0f;
      else
        arrival_bits += at[c] != (float)arrive[c];
      wet_err = fmax(wet_err, fabs(wd[c] - wet[c]) / fmax(wet[c], 1e-30));
      int cls = (int)hc[c];
      CHECK(cls == gr_rain_runoff_hazard_class(hr[c]));
      if (cls >= 0 && cls < 4)
        classes[cls]++;
    }
    int wet_cells = 0;
    for (size_t c = 0; c < n; ++c)
      wet_cells += arrive[c] >= 0.0;
    printf("maps, FlowModel %d, %d steps to %.3f s: max_depth differs in %d cells (%d depths "
           "above it); max_speed off by %.3g m/s (top %.3f), hazard by %.3g (top %.3f); arrival "
           "differs in %d of %d wet cells, %d never wet; wet_duration off by %.3g relative; "
           "classes %d/%d/%d/%d\n",
           model, steps, t, depth_bits, below, speed_err, vtop, hazard_err, hrtop, arrival_bits,
           wet_cells, never, wet_err, classes[0], classes[1], classes[2], classes[3]);
    CHECK(depth_bits == 0 && below == 0);
    CHECK_MSG(speed_err <= 1e-6 * fmax(vtop, 1.0), "max_speed off by %g", speed_err);
    CHECK_MSG(hazard_err <= 1e-6 * fmax(hrtop, 1.0), "hazard off by %g", hazard_err);
    CHECK(arrival_bits == 0 && wet_cells + never == (int)n && wet_cells > 0);
    CHECK_MSG(wet_err <= 1e-6, "wet_duration off by %g relative", wet_err);
    /* The run reaches several classes (the dam's 1 m with DF 0.5 is above 1.25). */
    CHECK(classes[0] > 0 && classes[2] + classes[3] > 0);
    free(md);
    free(ms);
    free(at);
    free(wd);
    free(hr);
    free(hc);
    free(hmax);
    free(vmax);
    free(hrmax);
    free(wet);
    free(arrive);
    free(b);
    free(d0);
    gr_rain_runoff_destroy(s);
  }
}

/* A dry dam break (1 m behind the dam at x0 = 20 m, frictionless, shallow
 * water): the arrival time at gauges downstream, from a run that advances
 * in one call (its own steps), lies within one step of the end of the
 * step after which a run stepping one step at a time first reads the
 * gauge above the wetting depth; and near Ritter's, where the depth h_w =
 * 1 cm travels at 2 c0 - 3 sqrt(g h_w): the scheme's thin tip lags, so the
 * exact 1 cm point at the arrival time lies within 6 cells of the gauge
 * (sw_ritter: 4 cells at 30 s). wet_duration counts the steps that end
 * wet, so for the cells that stay wet (all of them here: a closed
 * channel) wet_duration + arrival_time = the run's end plus the first wet
 * step: between T and T + the longest step. */
void test_maps_arrival(void) {
  gr_grid g = {120, 3, 1.0, 1.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  const double x0 = 20.0, h0 = 1.0, T = 12.0, g0 = GR_GRAVITY;
  float *d0 = alloc_field(&g, 1);
  for (size_t c = 0; c < n; ++c)
    d0[c] = (c % (size_t)g.nx) + 0.5 < x0 ? (float)h0 : 0.0f;
  gr_rain_runoff_params p;
  gr_rain_runoff_params_init(&p);
  p.rain_rate = 0.0;
  p.manning_n = 0.0;
  set_edges(&p, GR_BOUNDARY_CLOSED);
  gr_rain_runoff *a = make_sim(&g, &p, NULL, d0), *bsim = make_sim(&g, &p, NULL, d0);
  if (!a || !bsim) {
    gr_rain_runoff_destroy(a);
    gr_rain_runoff_destroy(bsim);
    free(d0);
    return;
  }
  enum { GAUGES = 4 };
  const int gauge[GAUGES] = {30, 45, 60, 75};
  double first[GAUGES] = {-1.0, -1.0, -1.0, -1.0}, dt_at[GAUGES] = {0.0, 0.0, 0.0, 0.0};
  double t = 0.0, dtmax = 0.0;
  int steps = 0;
  while (t < T - 1e-9) {
    double dt = 0.0;
    gr_rain_runoff_stable_dt(a, &dt);
    if (t + dt > T)
      dt = T - t;
    CHECK(gr_rain_runoff_step(a, dt, 1) == GR_OK);
    t += dt;
    ++steps;
    dtmax = fmax(dtmax, dt);
    float *h = get(a, &g, GR_FIELD_WATER_DEPTH);
    for (int k = 0; k < GAUGES; ++k)
      if (first[k] < 0.0 && h[g.nx + gauge[k]] > p.wetting_depth) {
        first[k] = t;
        dt_at[k] = dt;
      }
    free(h);
  }
  int taken = 0;
  CHECK(gr_rain_runoff_advance(bsim, T, &taken) == GR_OK);
  float *ta = get_map(a, &g, GR_RAIN_RUNOFF_ARRIVAL_TIME);
  float *tb = get_map(bsim, &g, GR_RAIN_RUNOFF_ARRIVAL_TIME);
  float *wb = get_map(bsim, &g, GR_RAIN_RUNOFF_WET_DURATION);
  const double speed = 2.0 * sqrt(g0 * h0) - 3.0 * sqrt(g0 * p.wetting_depth);
  for (int k = 0; k < GAUGES; ++k) {
    size_t c = (size_t)g.nx + (size_t)gauge[k];
    double ritter = ((gauge[k] + 0.5) - x0) / speed;
    printf("gauge at %d m: arrival %.4f s (advance, %d steps), %.4f s (step by step, %d steps, "
           "step %.4f s there), Ritter %.4f s; wet %.4f s + arrival = %.5f s\n",
           gauge[k], tb[c], taken, ta[c], steps, dt_at[k], ritter, wb[c], wb[c] + tb[c]);
    CHECK(first[k] > 0.0 && ta[c] == (float)first[k]);
    CHECK_MSG(fabs(tb[c] - first[k]) <= fmax(dt_at[k], dtmax), "gauge %d: %g vs %g", gauge[k],
              tb[c], first[k]);
    CHECK_MSG(fabs(tb[c] - ritter) * speed <= 6.0 * g.dx, "gauge %d: %g vs Ritter %g", gauge[k],
              tb[c], ritter);
  }
  /* Every cell that got wet stayed wet: its wet time is the rest of the run. */
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  int wet = 0;
  for (size_t c = 0; c < n; ++c)
    if (!isnan(tb[c])) {
      lo = fmin(lo, wb[c] + tb[c] - T);
      hi = fmax(hi, wb[c] + tb[c] - T);
      ++wet;
    }
  printf("wet_duration + arrival_time - %g s: %.3g to %.3g s over %d wet cells (steps up to %.4f "
         "s)\n",
         T, lo, hi, wet, dtmax);
  CHECK(wet > 0 && lo >= -1e-5 * T && hi <= dtmax + 1e-5 * T);
  free(ta);
  free(tb);
  free(wb);
  free(d0);
  gr_rain_runoff_destroy(a);
  gr_rain_runoff_destroy(bsim);
}

/* The hazard rating on uniform flows, by hand: h (|v| + 0.5) + DF, DF only
 * above 0.25 m, and its FD2321 class. A frictionless uniform flow on a flat
 * bed stays uniform in the middle, so the rating there holds after steps
 * too. */
void test_maps_hazard(void) {
  const struct {
    double h, u, v, df, rating;
    int cls;
  } cases[] = {
      {0.5, 1.2, 0.5, 0.0, 0.9, 1},   /* 0.5 (1.3 + 0.5) */
      {0.5, 1.2, 0.5, 0.5, 1.4, 2},   /* + DF above 0.25 m */
      {0.2, 1.2, 0.5, 1.0, 0.36, 0},  /* no DF at 0.2 m */
      {1.0, 0.0, 1.5, 0.5, 2.5, 3},   /* 1.0 (1.5 + 0.5) + 0.5 */
      {0.3, 0.6, -0.8, 0.0, 0.45, 0}, /* 0.3 (1.0 + 0.5) */
  };
  gr_grid g = {16, 16, 1.0, 1.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g), mid = (size_t)8 * 16 + 8;
  for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); ++k) {
    float *d = alloc_field(&g, 1), *vel = alloc_field(&g, 3);
    for (size_t c = 0; c < n; ++c) {
      d[c] = (float)cases[k].h;
      vel[3 * c] = (float)cases[k].u;
      vel[3 * c + 1] = (float)cases[k].v;
    }
    gr_rain_runoff_params p;
    gr_rain_runoff_params_init(&p);
    p.rain_rate = 0.0;
    p.manning_n = 0.0;
    p.debris_factor = cases[k].df;
    gr_rain_runoff *s = make_sim(&g, &p, NULL, d);
    if (!s || gr_rain_runoff_set_field(s, GR_FIELD_VELOCITY, vel) != GR_OK) {
      CHECK(0);
      gr_rain_runoff_destroy(s);
      free(d);
      free(vel);
      return;
    }
    float *hr0 = get_map(s, &g, GR_RAIN_RUNOFF_HAZARD_RATING);
    float *cl0 = get_map(s, &g, GR_RAIN_RUNOFF_HAZARD_CLASS);
    CHECK(gr_rain_runoff_step(s, 0.02, 5) == GR_OK);
    float *hr1 = get_map(s, &g, GR_RAIN_RUNOFF_HAZARD_RATING);
    float *ms = get_map(s, &g, GR_RAIN_RUNOFF_MAX_SPEED);
    double speed = sqrt(cases[k].u * cases[k].u + cases[k].v * cases[k].v);
    printf("hazard: h %.2f m, v %.3f m/s, DF %.1f: %.6f (by hand %.6f), class %g (%d); after 5 "
           "steps %.6f, max_speed %.6f\n",
           cases[k].h, speed, cases[k].df, hr0[mid], cases[k].rating, cl0[mid], cases[k].cls,
           hr1[mid], ms[mid]);
    CHECK(fabs(hazard_of(cases[k].h, speed, cases[k].df) - cases[k].rating) < 1e-12);
    CHECK(fabs(hr0[mid] - cases[k].rating) <= 2e-6 * cases[k].rating);
    CHECK((int)cl0[mid] == cases[k].cls);
    CHECK(fabs(hr1[mid] - cases[k].rating) <= 2e-6 * cases[k].rating);
    CHECK(fabs(ms[mid] - speed) <= 2e-6 * speed);
    free(hr0);
    free(cl0);
    free(hr1);
    free(ms);
    free(d);
    free(vel);
    gr_rain_runoff_destroy(s);
  }
  /* The class boundaries of FD2321/TR2 Table 13.1. */
  CHECK(gr_rain_runoff_hazard_class(0.7499) == 0 && gr_rain_runoff_hazard_class(0.75) == 1 &&
        gr_rain_runoff_hazard_class(1.2499) == 1 && gr_rain_runoff_hazard_class(1.25) == 2 &&
        gr_rain_runoff_hazard_class(2.0) == 2 && gr_rain_runoff_hazard_class(2.0001) == 3 &&
        gr_rain_runoff_hazard_class(NAN) == 0);
  CHECK(gr_rain_runoff_map_name(GR_RAIN_RUNOFF_MAX_DEPTH) &&
        strcmp(gr_rain_runoff_map_name(GR_RAIN_RUNOFF_HAZARD_CLASS), "hazard_class") == 0 &&
        gr_rain_runoff_map_name(GR_RAIN_RUNOFF_MAP_COUNT) == NULL);
}

/* A reset gives the maps of the initial water again, and a reloaded
 * checkpoint the maps of its time (same_bits compares the maps). */
void test_maps_reset(void) {
  gr_grid g = {20, 12, 1.0, 1.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  float *d0 = alloc_field(&g, 1);
  for (size_t c = 0; c < n; ++c)
    d0[c] = (c % (size_t)g.nx) < 5 ? 0.6f : 0.0f;
  gr_rain_runoff_params p;
  gr_rain_runoff_params_init(&p);
  p.rain_rate = 10.0 / 3.6e6; /* 10 mm/h, this test's rain (the default's before 100) */
  gr_rain_runoff *a = make_sim(&g, &p, NULL, d0), *b = make_sim(&g, &p, NULL, d0);
  if (!a || !b) {
    gr_rain_runoff_destroy(a);
    gr_rain_runoff_destroy(b);
    free(d0);
    return;
  }
  CHECK(gr_rain_runoff_advance(a, 20.0, NULL) == GR_OK);
  float *md = get_map(a, &g, GR_RAIN_RUNOFF_MAX_DEPTH);
  CHECK(gr_rain_runoff_reset(a) == GR_OK);
  float *m0 = get_map(a, &g, GR_RAIN_RUNOFF_MAX_DEPTH),
        *a0 = get_map(a, &g, GR_RAIN_RUNOFF_ARRIVAL_TIME);
  float *w0 = get_map(a, &g, GR_RAIN_RUNOFF_WET_DURATION);
  int differ = 0, wetter = 0;
  for (size_t c = 0; c < n; ++c) {
    differ += m0[c] != d0[c] || w0[c] != 0.0f || (d0[c] > 0.0f ? a0[c] != 0.0f : !isnan(a0[c]));
    wetter += md[c] > d0[c];
  }
  CHECK_MSG(differ == 0 && wetter > 0, "%d cells differ after the reset (%d got deeper)", differ,
            wetter);
  CHECK(same_bits(a, b, &g, "reset and fresh maps"));
  CHECK(gr_rain_runoff_advance(a, 20.0, NULL) == GR_OK);
  CHECK(gr_rain_runoff_advance(b, 20.0, NULL) == GR_OK);
  CHECK(same_bits(a, b, &g, "maps after a reset and fresh"));
  free(md);
  free(m0);
  free(a0);
  free(w0);
  free(d0);
  gr_rain_runoff_destroy(a);
  gr_rain_runoff_destroy(b);
}

/* Gauges: gr_rain_runoff_sample gives at each cell the floats that
 * get_field's depth, surface and discharge hold there (both models, a
 * flowing state); a cell outside the grid is refused with a sentence. */
void test_gauges(void) {
  for (int model = 0; model < 2; ++model) {
    gr_grid g = {23, 17, 1.5, 2.0, 0.0, 0.0, 0, 0};
    size_t n = cells_of(&g);
    float *b = alloc_field(&g, 1), *d0 = alloc_field(&g, 1);
    for (size_t c = 0; c < n; ++c) {
      b[c] = (float)(100.0 + 0.3 * hash01((int)c, 2, 3) + 0.02 * (double)(c % (size_t)g.nx));
      d0[c] = (c % (size_t)g.nx) < 6 ? 0.8f : 0.0f;
    }
    gr_rain_runoff_params p = params_with(20.0 / 3.6e6, 0.0, GR_BOUNDARY_OPEN);
    p.flow_model = model ? GR_FLOW_LOCAL_INERTIAL : GR_FLOW_SHALLOW_WATER;
    gr_rain_runoff *s = make_sim(&g, &p, b, d0);
    if (!s) {
      free(b);
      free(d0);
      return;
    }
    CHECK(gr_rain_runoff_advance(s, 15.0, NULL) == GR_OK);
    const int ij[] = {0, 0, 22, 16, 7, 8, 5, 3, 12, 9};
    const int k = (int)(sizeof(ij) / sizeof(ij[0]) / 2);
    float got[3 * 5];
    CHECK(gr_rain_runoff_sample(s, ij, k, got) == GR_OK);
    float *h = get(s, &g, GR_FIELD_WATER_DEPTH), *z = get(s, &g, GR_FIELD_WATER_SURFACE);
    float *q = get(s, &g, GR_FIELD_DISCHARGE);
    int differ = 0, flowing = 0;
    for (int m = 0; m < k; ++m) {
      size_t c = (size_t)ij[2 * m + 1] * (size_t)g.nx + (size_t)ij[2 * m];
      differ += got[3 * m] != h[c] || got[3 * m + 1] != z[c] || got[3 * m + 2] != q[c];
      flowing += q[c] > 0.0f;
    }
    printf("gauges, FlowModel %d: %d of %d differ from the fields; %d with flow\n", model, differ,
           k, flowing);
    CHECK(differ == 0 && flowing > 0);
    const int outside[] = {3, 4, 23, 0};
    CHECK(gr_rain_runoff_sample(s, outside, 2, got) == GR_ERR_INVALID_ARGUMENT);
    CHECK_MSG(strstr(gr_rain_runoff_last_error(s), "(23, 0), outside the 23 x 17 grid") != NULL,
              "'%s'", gr_rain_runoff_last_error(s));
    CHECK(gr_rain_runoff_sample(s, NULL, 0, NULL) == GR_OK);
    free(h);
    free(z);
    free(q);
    free(b);
    free(d0);
    gr_rain_runoff_destroy(s);
  }
}

/* The wet duration by wet spells (gr_rain_runoff_wet_turn): on a bumpy bed
 * (3 cm) with a permeability that varies by cell, a hyetograph that rains 360 mm/h,
 * stops from 300 to 600 s and rains again, so that cells turn wet, dry and
 * wet again at different steps, and the wetting depth changed twice between
 * steps (1 cm, 6 mm from 700 s, 12 mm from 850 s). Steps of 0.5 s, so every
 * time is a float exactly: after every 50th step and at the end, for every
 * cell, wet_duration is the sum of the dt of the steps after which the
 * depth (read back after every step) was above the wetting depth then in
 * force, to the bit, and arrival_time the end of the first of them (or the
 * time a new wetting depth made the cell wet), to the bit. Both flow
 * models. */
void test_maps_wet_spells(void) {
  for (int model = 0; model < 2; ++model) {
    gr_grid g = {12, 8, 2.0, 2.0, 0.0, 0.0, 0, 0};
    size_t n = cells_of(&g);
    float *b = alloc_field(&g, 1), *d0 = alloc_field(&g, 1), *k = alloc_field(&g, 1);
    for (size_t c = 0; c < n; ++c) {
      int i = (int)(c % 12), j = (int)(c / 12);
      k[c] = (float)((3.0 + 4.0 * hash01(i, j, 21)) * 1e-5);
      b[c] = (float)(0.03 * hash01(i, j, 22)); /* pools that stay wet, tops that dry */
    }
    gr_rain_runoff_params p = params_with(0.0, 0.0, GR_BOUNDARY_CLOSED);
    p.flow_model = model ? GR_FLOW_LOCAL_INERTIAL : GR_FLOW_SHALLOW_WATER;
    gr_rain_runoff *s = make_sim(&g, &p, b, d0);
    const double ht[6] = {0.0, 300.0, 300.5, 600.0, 600.5, 1000.0};
    const double hr[6] = {1e-4, 1e-4, 0.0, 0.0, 1e-4, 1e-4};
    if (!s || gr_rain_runoff_set_field(s, GR_FIELD_PERMEABILITY, k) != GR_OK ||
        gr_rain_runoff_set_hyetograph(s, ht, hr, 6) != GR_OK) {
      CHECK(0);
      gr_rain_runoff_destroy(s);
      free(b);
      free(d0);
      free(k);
      return;
    }
    double *wet = calloc(n, sizeof(double)), *arrive = malloc(n * sizeof(double));
    int *state = calloc(n, sizeof(int)), *ended = calloc(n, sizeof(int));
    for (size_t c = 0; c < n; ++c)
      arrive[c] = -1.0;
    const double dt = 0.5;
    double t = 0.0;
    long wrong = 0, checked = 0;
    for (int step = 1; step <= 2000; ++step) {
      if (step == 1401 || step == 1701) {
        /* A new wetting depth at t = 700 s, then 850 s: the cells turn wet
         * or dry at that time. */
        p.wetting_depth = step == 1401 ? 0.006 : 0.012;
        CHECK(gr_rain_runoff_set_params(s, &p) == GR_OK);
        float *h = get(s, &g, GR_FIELD_WATER_DEPTH);
        for (size_t c = 0; c < n; ++c) {
          int now = h[c] > (float)p.wetting_depth;
          ended[c] += state[c] && !now;
          if (now && arrive[c] < 0.0)
            arrive[c] = t;
          state[c] = now;
        }
        free(h);
      }
      CHECK(gr_rain_runoff_step(s, dt, 1) == GR_OK);
      t += dt;
      float *h = get(s, &g, GR_FIELD_WATER_DEPTH);
      for (size_t c = 0; c < n; ++c) {
        int now = h[c] > (float)p.wetting_depth;
        ended[c] += state[c] && !now;
        if (now) {
          wet[c] += dt;
          if (arrive[c] < 0.0)
            arrive[c] = t;
        }
        state[c] = now;
      }
      free(h);
      if (step % 50 == 0) {
        float *wd = get_map(s, &g, GR_RAIN_RUNOFF_WET_DURATION);
        float *at = get_map(s, &g, GR_RAIN_RUNOFF_ARRIVAL_TIME);
        for (size_t c = 0; c < n; ++c) {
          int bad = wd[c] != (float)wet[c] ||
                    (arrive[c] < 0.0 ? !isnan(at[c]) : at[c] != (float)arrive[c]);
          CHECK_MSG(!bad || wrong > 0, "step %d, cell %zu: wet %.9g s (by hand %.9g), arrival %.9g",
                    step, c, wd[c], wet[c], at[c]);
          wrong += bad;
          ++checked;
        }
        free(wd);
        free(at);
      }
    }
    int spells = 0, again = 0, never = 0, always = 0;
    for (size_t c = 0; c < n; ++c) {
      spells += ended[c] > 0;
      again += ended[c] > 0 && state[c];
      never += arrive[c] < 0.0;
      always += ended[c] == 0 && state[c];
    }
    printf("wet spells, FlowModel %d, %.0f s: %ld of %ld readings differ from the sum of dt over "
           "wet steps; %d cells dried after a spell (%d of them wet again at the end), %d wet "
           "from their arrival to the end, %d never wet\n",
           model, t, wrong, checked, spells, again, always, never);
    CHECK(wrong == 0 && checked == 40 * (long)n);
    CHECK(spells > 0 && again > 0 && always > 0);
    free(wet);
    free(arrive);
    free(state);
    free(ended);
    free(b);
    free(d0);
    free(k);
    gr_rain_runoff_destroy(s);
  }
}
