/* Rain runoff tests of the interface (test_rain_runoff.c has main):
 * every device agreeing, every error path, the memcheck run, the parameter
 * table, checkpoints, progress, a shared context and the ledger's fixed
 * point. */
#include "test_rain_runoff.h"

int has(const char *text, const char *word) {
  return strstr(text, word) != NULL;
}

/* Every OpenCL device gives the same water: rain on a bumpy bowl with an open
 * edge, 600 fixed steps of 0.2 s, compared with the first device. Float
 * operations that OpenCL lets devices round differently (sqrt, division)
 * make the fields differ in their last bits, not more. */
/* The flow model test_devices_agree runs (test_sw_devices_agree: shallow
 * water). */
static gr_flow_model agree_model = GR_FLOW_LOCAL_INERTIAL;

void test_devices_agree(void) {
  int count = 0;
  gr_device_info infos[8];
  if (gr_device_list(infos, 8, &count) != GR_OK || count < 2) {
    printf("one OpenCL device: cross-device agreement not tested here\n");
    return;
  }
  gr_grid g = {64, 48, 2.0, 2.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  float *b = make_bowl(&g, 0.004);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i)
      b[(size_t)j * g.nx + i] += (float)(0.05 * hash01(i, j, 7));
  gr_rain_runoff_params p = params_with(50.0 / 3.6e6, 5.0 / 3.6e6, GR_BOUNDARY_OPEN);
  p.flow_model = agree_model;
  gr_context *own = ctx;
  float *first = NULL;
  gr_rain_runoff_ledger first_l;
  memset(&first_l, 0, sizeof(first_l));
  for (int d = 0; d < count && d < 8; ++d) {
    gr_context_options opt;
    gr_context_options_init(&opt);
    opt.device = infos[d].name;
    if (gr_context_create(&opt, &ctx) != GR_OK) {
      CHECK_MSG(0, "%s: %s", infos[d].name, gr_last_error(NULL));
      ctx = own;
      continue;
    }
    gr_rain_runoff *s = make_sim(&g, &p, b, NULL);
    if (s) {
      CHECK(gr_rain_runoff_step(s, 0.2, 600) == GR_OK);
      float *h = get(s, &g, GR_FIELD_WATER_DEPTH);
      gr_rain_runoff_ledger l = ledger(s);
      if (!first) {
        first = h;
        first_l = l;
      } else {
        double worst = 0.0, deepest = 0.0;
        for (size_t c = 0; c < n; ++c) {
          worst = fmax(worst, fabs((double)h[c] - first[c]));
          deepest = fmax(deepest, first[c]);
        }
        double dstored = fabs(l.stored_volume - first_l.stored_volume) / first_l.stored_volume;
        printf("%s vs %s: depth differs by at most %.3g m (deepest %.3g m); stored volume by "
               "%.3g of itself; balance %.3g and %.3g of the water in\n",
               infos[d].name, infos[0].name, worst, deepest, dstored,
               fabs(l.balance_error) / l.rain_volume,
               fabs(first_l.balance_error) / first_l.rain_volume);
        /* Measured H100 vs PoCL: 5.5e-8 of the deepest water, 3.8e-11 of
         * the stored volume. */
        CHECK_MSG(worst <= 1e-6 * deepest, "%s disagrees: %.3g m", infos[d].name, worst);
        CHECK_MSG(dstored <= 1e-8, "%s stores %.3g more or less", infos[d].name, dstored);
        free(h);
      }
      gr_rain_runoff_destroy(s);
    }
    gr_context_release(ctx);
    ctx = own;
  }
  free(first);
  free(b);
}

void test_errors(void) {
  char msg[512];
  gr_rain_runoff_params p;
  gr_rain_runoff_params_init(&p);
  CHECK(gr_rain_runoff_params_validate(&p, msg, sizeof(msg)) == GR_OK);
  CHECK_NEAR(p.rain_rate, 100.0 / 3.6e6, 1e-15);
  CHECK(p.permeability == 0.0 && p.manning_n == 0.03 && p.cfl == 0.7 && p.max_dt == 3600.0 &&
        p.boundary[0] == GR_BOUNDARY_OPEN && p.boundary[3] == GR_BOUNDARY_OPEN &&
        p.boundary_level[2] == 0.0 && p.flow_model == GR_FLOW_SHALLOW_WATER);
  gr_rain_runoff_params q;
#define BAD(field, value, word)                                                                    \
  do {                                                                                             \
    q = p;                                                                                         \
    q.field = value;                                                                               \
    CHECK(gr_rain_runoff_params_validate(&q, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);        \
    CHECK_MSG(has(msg, word), "'%s' lacks '%s'", msg, word);                                       \
  } while (0)
  BAD(rain_rate, -1e-9, "RainRate");
  BAD(rain_rate, 2e-3, "RainRate");
  BAD(rain_rate, NAN, "RainRate");
  BAD(permeability, -1.0, "Permeability");
  BAD(permeability, 0.02, "Permeability");
  BAD(permeability, INFINITY, "Permeability");
  BAD(manning_n, -0.001, "ManningN");
  BAD(manning_n, NAN, "ManningN");
  BAD(flow_model, (gr_flow_model)2, "FlowModel");
  /* Frictionless is for the shallow-water model only. */
  q = p;
  q.manning_n = 0.0;
  CHECK(gr_rain_runoff_params_validate(&q, msg, sizeof(msg)) == GR_OK);
  q.flow_model = GR_FLOW_LOCAL_INERTIAL;
  CHECK(gr_rain_runoff_params_validate(&q, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(msg, "ManningN must be at least 0.005") && has(msg, "FlowModel"), "'%s'", msg);
  q.manning_n = 0.001;
  CHECK(gr_rain_runoff_params_validate(&q, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  BAD(cfl, 0.0, "CourantNumber");
  BAD(cfl, 1.5, "CourantNumber");
  BAD(max_dt, 0.0, "MaxTimeStep");
  BAD(max_dt, 4000.0, "MaxTimeStep");
  BAD(max_dt, NAN, "MaxTimeStep");
  BAD(boundary[0], (gr_boundary)4, "BoundaryWest");
  BAD(boundary[3], (gr_boundary)-1, "BoundaryNorth");
  BAD(boundary_level[1], NAN, "LevelEast");
  BAD(boundary_level[2], 2e6, "LevelSouth");
#undef BAD
  CHECK(gr_rain_runoff_params_validate(NULL, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_params_validate(&q, NULL, 0) == GR_ERR_INVALID_ARGUMENT);
  gr_rain_runoff_params_init(NULL);

  /* Fields: every value finite; depth, permeability and rain in range; the
   * first bad value is named. */
  float vals[6] = {0.0f, 1.0f, 2.0f, NAN, -1.0f, 3.0f};
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_ELEVATION, vals, 3, msg, sizeof(msg)) == GR_OK);
  /* A NaN elevation is a no-data cell; an infinite one is refused. */
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_ELEVATION, vals, 6, msg, sizeof(msg)) == GR_OK);
  vals[3] = -INFINITY;
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_ELEVATION, vals, 6, msg, sizeof(msg)) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(msg, "elevation") && has(msg, "index 3") && has(msg, "inf"), "'%s'", msg);
  vals[3] = NAN;
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_WATER_DEPTH, vals, 6, msg, sizeof(msg)) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(msg, "water_depth") && has(msg, "index 3") && has(msg, "nan"), "'%s'", msg);
  vals[3] = 0.5f;
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_ELEVATION, vals, 6, msg, sizeof(msg)) == GR_OK);
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_WATER_DEPTH, vals, 6, msg, sizeof(msg)) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(msg, "water_depth") && has(msg, "index 4") && has(msg, "-1"), "'%s'", msg);
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_RAIN_RATE, vals, 2, msg, sizeof(msg)) ==
        GR_ERR_INVALID_ARGUMENT); /* 1 m/s */
  CHECK(has(msg, "rain_rate") && has(msg, "index 1"));
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_PERMEABILITY, vals, 1, msg, sizeof(msg)) == GR_OK);
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_PERMEABILITY, vals, 2, msg, sizeof(msg)) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_DISCHARGE, vals, 2, msg, sizeof(msg)) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK(has(msg, "discharge") && has(msg, "not an input"));
  /* Velocities (3 per cell) are finite and below 1000 m/s. */
  float vel[6] = {1.0f, -2.0f, 0.0f, 0.5f, 2000.0f, 0.0f};
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_VELOCITY, vel, 3, msg, sizeof(msg)) == GR_OK);
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_VELOCITY, vel, 6, msg, sizeof(msg)) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(msg, "velocity") && has(msg, "index 4") && has(msg, "1000 m/s"), "'%s'", msg);
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_ELEVATION, NULL, 2, msg, sizeof(msg)) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_field_validate((gr_field)99, vals, 2, msg, sizeof(msg)) ==
        GR_ERR_INVALID_ARGUMENT);

  /* create refuses bad grids, parameters and NULLs. */
  gr_grid g = {12, 10, 1.0, 1.0, 0.0, 0.0, 0, 0};
  gr_rain_runoff *s = NULL;
  q = p;
  q.cfl = -1.0;
  CHECK(gr_rain_runoff_create(ctx, &g, &q, &s) == GR_ERR_INVALID_ARGUMENT);
  CHECK(s == NULL && has(gr_last_error(ctx), "CourantNumber"));
  gr_grid bad = g;
  bad.dx = 0.0;
  CHECK(gr_rain_runoff_create(ctx, &bad, &p, &s) == GR_ERR_INVALID_ARGUMENT);
  CHECK(s == NULL && has(gr_last_error(ctx), "spacing"));
  CHECK(gr_rain_runoff_create(ctx, NULL, &p, &s) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_create(ctx, &g, NULL, &s) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_create(NULL, &g, &p, &s) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_last_error(NULL)[0] != '\0');
  CHECK(gr_rain_runoff_create(ctx, &g, &p, NULL) == GR_ERR_INVALID_ARGUMENT);

  /* NULL simulations are refused by every entry point. */
  float host[120];
  double dt = 0.0;
  int steps = 0;
  gr_rain_runoff_ledger l;
  CHECK(gr_rain_runoff_set_params(NULL, &p) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_set_field(NULL, GR_FIELD_ELEVATION, host) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_step(NULL, 1.0, 1) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_stable_dt(NULL, &dt) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_advance(NULL, 1.0, &steps) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_get_field(NULL, GR_FIELD_WATER_DEPTH, host) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_ledger_get(NULL, &l) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_reset(NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(has(gr_last_error(NULL), "simulation"));
  gr_rain_runoff_destroy(NULL);

  CHECK(gr_rain_runoff_create(ctx, &g, &p, &s) == GR_OK);
  if (!s)
    return;
  /* Bad arguments of a live simulation: refused, with a sentence. */
  CHECK(gr_rain_runoff_set_params(s, NULL) == GR_ERR_INVALID_ARGUMENT);
  q = p;
  q.manning_n = 2.0;
  CHECK(gr_rain_runoff_set_params(s, &q) == GR_ERR_INVALID_ARGUMENT);
  CHECK(has(gr_last_error(ctx), "ManningN"));
  const double bad_dt[] = {0.0, -1.0, NAN, INFINITY, 1e-40, 7200.0};
  for (size_t k = 0; k < sizeof(bad_dt) / sizeof(bad_dt[0]); ++k) {
    CHECK(gr_rain_runoff_step(s, bad_dt[k], 1) == GR_ERR_INVALID_ARGUMENT);
    CHECK(has(gr_last_error(ctx), "dt"));
  }
  CHECK(gr_rain_runoff_step(s, 1.0, -1) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_step(s, 1.0, 0) == GR_OK);
  CHECK(gr_rain_runoff_advance(s, -1.0, &steps) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_advance(s, NAN, &steps) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_advance(s, INFINITY, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(has(gr_last_error(ctx), "duration"));
  CHECK(gr_rain_runoff_advance(s, 1e12, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(has(gr_last_error(ctx), "in parts"));
  CHECK(gr_rain_runoff_stable_dt(s, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_ledger_get(s, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_get_field(s, GR_FIELD_WATER_DEPTH, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_get_field(s, GR_FIELD_SNOW_DEPTH, host) == GR_ERR_INVALID_ARGUMENT);
  CHECK(has(gr_last_error(ctx), "snow_depth"));
  CHECK(gr_rain_runoff_get_field(s, (gr_field)-3, host) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_DISCHARGE, host) == GR_ERR_INVALID_ARGUMENT);
  CHECK(has(gr_last_error(ctx), "discharge") && has(gr_last_error(ctx), "not an input"));
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_ELEVATION, NULL) == GR_ERR_INVALID_ARGUMENT);
  /* Default permeability and rain come back as uniform fields. */
  CHECK(gr_rain_runoff_get_field(s, GR_FIELD_RAIN_RATE, host) == GR_OK);
  CHECK(host[0] == (float)p.rain_rate && host[119] == (float)p.rain_rate);
  CHECK(gr_rain_runoff_get_field(s, GR_FIELD_PERMEABILITY, host) == GR_OK && host[7] == 0.0f);

  /* Bad fields are refused, the cell named, and the state kept. */
  float depth[120], before[120], after[120];
  for (int c = 0; c < 120; ++c)
    depth[c] = 0.01f * (float)(c % 7);
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_WATER_DEPTH, depth) == GR_OK);
  CHECK(gr_rain_runoff_step(s, 0.1, 3) == GR_OK);
  CHECK(gr_rain_runoff_get_field(s, GR_FIELD_WATER_DEPTH, before) == GR_OK);
  gr_rain_runoff_ledger lb = ledger(s);
  memcpy(host, depth, sizeof(depth));
  host[2 * 12 + 5] = -0.25f;
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_WATER_DEPTH, host) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(gr_last_error(ctx), "(5, 2)") && has(gr_last_error(ctx), "-0.25") &&
                has(gr_last_error(ctx), "water_depth"),
            "'%s'", gr_last_error(ctx));
  host[2 * 12 + 5] = INFINITY;
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_ELEVATION, host) == GR_ERR_INVALID_ARGUMENT);
  CHECK(has(gr_last_error(ctx), "elevation") && has(gr_last_error(ctx), "inf"));
  host[2 * 12 + 5] = 1e9f; /* finite, but beyond set_field's 1e6 m */
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_ELEVATION, host) == GR_ERR_INVALID_ARGUMENT);
  host[2 * 12 + 5] = 0.5f;
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_RAIN_RATE, host) == GR_ERR_INVALID_ARGUMENT);
  CHECK(has(gr_last_error(ctx), "rain_rate") && has(gr_last_error(ctx), "0.001"));
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_PERMEABILITY, host) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_set_field(s, (gr_field)42, host) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_get_field(s, GR_FIELD_WATER_DEPTH, after) == GR_OK);
  CHECK(memcmp(before, after, sizeof(before)) == 0);
  gr_rain_runoff_ledger la = ledger(s);
  CHECK(la.steps == lb.steps && la.stored_volume == lb.stored_volume &&
        la.initial_volume == lb.initial_volume);
  CHECK(gr_rain_runoff_get_field(s, GR_FIELD_RAIN_RATE, host) == GR_OK &&
        host[29] == (float)p.rain_rate);
  gr_rain_runoff_destroy(s);

  /* A grid whose buffers exceed the device's limits is refused before
   * anything is allocated. */
  gr_grid huge;
  if (gr_test_grid_beyond_device(ctx, &huge)) {
    s = NULL;
    gr_status st = gr_rain_runoff_create(ctx, &huge, &p, &s);
    CHECK_MSG(st == GR_ERR_TOO_LARGE || st == GR_ERR_OUT_OF_MEMORY, "%s: %s", gr_status_string(st),
              gr_last_error(ctx));
    CHECK(s == NULL && has(gr_last_error(ctx), "grid"));
  }
  gr_grid wide = {60000, 60000, 1.0, 1.0, 0.0, 0.0, 0, 0}; /* 3.6e9 points */
  CHECK(gr_rain_runoff_create(ctx, &wide, &p, &s) == GR_ERR_TOO_LARGE);
  CHECK(s == NULL);
}

double wall_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int on_progress(void *user, double time) {
  progress_log *log = user;
  ++log->calls;
  if (!(time > log->last))
    log->increasing = 0;
  log->last = time;
  if (log->stop_at > 0 && log->calls >= log->stop_at) {
    log->stopped_at_wall = wall_now();
    return 1;
  }
  return 0;
}

/* A tiny run of every entry point, for valgrind: each kernel runs once or a
 * few times on a 6 x 5 grid. */
void test_memcheck(void) {
  gr_grid g = {6, 5, 1.0, 1.0, 0.0, 0.0, 0, 0};
  size_t n = cells_of(&g);
  float b[30], d[30], r[30], k[30], out[90];
  for (size_t c = 0; c < n; ++c) {
    b[c] = (float)(0.1 * (double)(c % 6));
    d[c] = 0.01f;
    r[c] = 1e-5f;
    k[c] = 1e-6f;
  }
  gr_rain_runoff_params p = params_with(1e-5, 0.0, GR_BOUNDARY_OPEN);
  gr_rain_runoff *s = make_sim(&g, &p, b, d);
  if (!s)
    return;
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_RAIN_RATE, r) == GR_OK);
  CHECK(gr_rain_runoff_set_field(s, GR_FIELD_PERMEABILITY, k) == GR_OK);
  int steps = 0;
  CHECK(gr_rain_runoff_advance(s, 2.0, &steps) == GR_OK && steps >= 2);
  const gr_field fields[] = {GR_FIELD_WATER_DEPTH,  GR_FIELD_WATER_SURFACE, GR_FIELD_VELOCITY,
                             GR_FIELD_DISCHARGE,    GR_FIELD_INFILTRATED,   GR_FIELD_ELEVATION,
                             GR_FIELD_PERMEABILITY, GR_FIELD_RAIN_RATE};
  for (size_t f = 0; f < sizeof(fields) / sizeof(fields[0]); ++f)
    CHECK(gr_rain_runoff_get_field(s, fields[f], out) == GR_OK);
  /* The flood maps and the gauges' reads. */
  for (int m = 0; m < GR_RAIN_RUNOFF_MAP_COUNT; ++m)
    CHECK(gr_rain_runoff_get_map(s, (gr_rain_runoff_map)m, out) == GR_OK);
  const int gauge_ij[] = {0, 0, 5, 4, 2, 3};
  CHECK(gr_rain_runoff_sample(s, gauge_ij, 3, out) == GR_OK);
  gr_rain_runoff_ledger l = ledger(s);
  CHECK(fabs(l.balance_error) <= 1e-5 * (l.initial_volume + l.rain_volume));
  CHECK(gr_rain_runoff_reset(s) == GR_OK);
  CHECK(gr_rain_runoff_step(s, 0.5, 2) == GR_OK);
  CHECK(gr_rain_runoff_get_field(s, GR_FIELD_WATER_DEPTH, out) == GR_OK);
  CHECK(bad_depths(out, n) == 0);
  /* A checkpoint round trip and an advance with a progress callback. */
  size_t bytes = 0;
  CHECK(gr_rain_runoff_state_size(s, &bytes) == GR_OK);
  void *saved = malloc(bytes);
  CHECK(saved && gr_rain_runoff_state_save(s, saved, bytes) == GR_OK);
  CHECK(gr_rain_runoff_step(s, 0.5, 2) == GR_OK);
  CHECK(saved && gr_rain_runoff_state_load(s, saved, bytes) == GR_OK);
  CHECK(gr_rain_runoff_get_field(s, GR_FIELD_WATER_DEPTH, out + 30) == GR_OK);
  CHECK(memcmp(out, out + 30, n * sizeof(float)) == 0);
  free(saved);
  progress_log log = {0, 1, 0, 0.0, 0.0};
  gr_rain_runoff_set_progress(s, on_progress, &log);
  CHECK(gr_rain_runoff_advance(s, 1.0, &steps) == GR_OK && log.increasing);
  /* The programs swapped: the other FlowModel's, then the general one. */
  p.flow_model = GR_FLOW_SHALLOW_WATER;
  CHECK(gr_rain_runoff_set_params(s, &p) == GR_OK);
  CHECK(gr_rain_runoff_step(s, 0.1, 1) == GR_OK);
  gr_rain_runoff_set_specialised(s, 0);
  CHECK(gr_rain_runoff_step(s, 0.1, 1) == GR_OK &&
        gr_rain_runoff_specialised_for(s) == GR_RAIN_RUNOFF_INPUT_ALL);
  gr_rain_runoff_destroy(s);
}

void test_long_run_default(void) {
  test_long_run(20000);
}

/* CPU and GPU agree on the shallow-water model as on the local inertial
 * one (the same kernels, FP_CONTRACT off, gathers only): test_devices_agree
 * with FlowModel 0 (its fixed 0.2 s step is stable on that bowl: 3.4 cm
 * deep at most, balance 5e-8, on PoCL alone). */
void test_sw_devices_agree(void) {
  agree_model = GR_FLOW_SHALLOW_WATER;
  test_devices_agree();
  agree_model = GR_FLOW_LOCAL_INERTIAL;
}

/* ------------------------------------------- table, checkpoints, progress */

static void set_param(gr_rain_runoff_params *p, const char *property, double v) {
  if (strcmp(property, "RainRate") == 0)
    p->rain_rate = v;
  else if (strcmp(property, "Permeability") == 0)
    p->permeability = v;
  else if (strcmp(property, "ManningN") == 0)
    p->manning_n = v;
  else if (strcmp(property, "MaxTimeStep") == 0)
    p->max_dt = v;
  else if (strcmp(property, "CourantNumber") == 0)
    p->cfl = v;
  else if (strncmp(property, "Boundary", 8) == 0 || strncmp(property, "Level", 5) == 0) {
    const char *sides[4] = {"West", "East", "South", "North"};
    const char *side = property + (property[0] == 'B' ? 8 : 5);
    int e = 0;
    while (e < 4 && strcmp(side, sides[e]) != 0)
      ++e;
    CHECK_MSG(e < 4, "the table has an unknown property '%s'", property);
    if (e < 4 && property[0] == 'B')
      p->boundary[e] = (gr_boundary)(int)v;
    else if (e < 4)
      p->boundary_level[e] = v;
  } else if (strcmp(property, "FlowModel") == 0)
    p->flow_model = (gr_flow_model)(int)v;
  else if (strcmp(property, "WettingDepth") == 0)
    p->wetting_depth = v;
  else if (strcmp(property, "DebrisFactor") == 0)
    p->debris_factor = v;
  else if (strcmp(property, "NoDataBoundary") == 0)
    p->no_data = (gr_boundary)(int)v;
  else
    CHECK_MSG(0, "the table has an unknown property '%s'", property);
}

static int accepted(const gr_rain_runoff_params *p, char *msg, size_t len) {
  msg[0] = '\0';
  return gr_rain_runoff_params_validate(p, msg, len) == GR_OK;
}

/* The parameter table is what the validator follows: at every row's bounds
 * (the user's bound times to_core) the bound itself is accepted unless the
 * row says it is open, the next double beyond it is refused, and the
 * sentence names the property and its range in the user's unit. */
void test_param_table(void) {
  int n = 0;
  const gr_param_bound *t = gr_rain_runoff_param_bounds(&n);
  const char *names[] = {"RainRate",      "Permeability", "ManningN",     "MaxTimeStep",
                         "CourantNumber", "BoundaryWest", "BoundaryEast", "BoundarySouth",
                         "BoundaryNorth", "LevelWest",    "LevelEast",    "LevelSouth",
                         "LevelNorth",    "FlowModel",    "WettingDepth", "DebrisFactor",
                         "NoDataBoundary"};
  CHECK(t != NULL && n == 17);
  if (!t || n != 17)
    return;
  CHECK(gr_rain_runoff_param_bounds(NULL) == t);
  for (int r = 0; r < n; ++r)
    CHECK_MSG(strcmp(t[r].property, names[r]) == 0, "row %d is '%s'", r, t[r].property);
  CHECK(strcmp(t[0].unit, "mm/h") == 0 && t[0].min == 0.0 && t[0].max == 3600.0);
  CHECK(t[0].to_core == 1.0 / 3.6e6 && t[1].to_core == 1.0 / 3.6e6);
  CHECK(t[3].min_open && t[4].min_open && !t[0].min_open && t[5].integer && !t[4].integer &&
        t[13].integer && t[13].default_value == 0.0 && t[2].min == 0.0);
  /* Four edges: kinds 0-3 (open by default), levels in m as the elevations. */
  for (int e = 0; e < 4; ++e)
    CHECK(t[5 + e].integer && t[5 + e].max == 3.0 && t[5 + e].default_value == 0.0 &&
          !t[9 + e].integer && strcmp(t[9 + e].unit, "m") == 0 && t[9 + e].min == -1e6 &&
          t[9 + e].max == 1e6);
  /* WettingDepth 1 cm, above 0; DebrisFactor FD2321's 0 to 1, 0 by default. */
  CHECK(t[14].min_open && t[14].min == 0.0 && t[14].default_value == 0.01 && !t[15].min_open &&
        t[15].min == 0.0 && t[15].max == 1.0 && t[15].default_value == 0.0);
  gr_rain_runoff_params p, q;
  gr_rain_runoff_params_init(&p);
  /* The defaults are the table's. */
  CHECK(p.rain_rate == t[0].default_value * t[0].to_core && t[0].default_value == 100.0);
  CHECK(p.permeability == t[1].default_value * t[1].to_core && p.manning_n == t[2].default_value);
  CHECK(p.max_dt == t[3].default_value && p.cfl == t[4].default_value &&
        (double)p.flow_model == t[13].default_value);
  for (int e = 0; e < 4; ++e)
    CHECK((double)p.boundary[e] == t[5 + e].default_value &&
          p.boundary_level[e] == t[9 + e].default_value);
  CHECK(p.wetting_depth == t[14].default_value && p.debris_factor == t[15].default_value);
  /* No-data cells are walls by default (1 closed, 0 an outfall). */
  CHECK(t[16].integer && t[16].default_value == 1.0 && t[16].max == 1.0 &&
        (double)p.no_data == t[16].default_value && p.no_data == GR_BOUNDARY_CLOSED);
  char msg[512], range[160];
  int bounds_checked = 0;
  for (int r = 0; r < n; ++r) {
    const gr_param_bound *row = &t[r];
    double lo = row->min * row->to_core, hi = row->max * row->to_core;
    /* The default lies inside. */
    CHECK(row->default_value >= row->min && row->default_value <= row->max);
    q = p;
    set_param(&q, row->property, hi);
    CHECK_MSG(accepted(&q, msg, sizeof(msg)), "%s at its max %g %s: %s", row->property, row->max,
              row->unit, msg);
    q = p;
    set_param(&q, row->property, row->integer ? row->max + 1.0 : nextafter(hi, HUGE_VAL));
    CHECK_MSG(!accepted(&q, msg, sizeof(msg)), "%s above its max accepted", row->property);
    if (row->integer)
      snprintf(range, sizeof(range), "%s must be a whole number from %g to %g", row->property,
               row->min, row->max);
    else if (row->min_open)
      snprintf(range, sizeof(range), "%s must be above %g and at most %g%s%s", row->property,
               row->min, row->max, row->unit[0] ? " " : "", row->unit);
    else
      snprintf(range, sizeof(range), "%s must lie between %g and %g%s%s", row->property, row->min,
               row->max, row->unit[0] ? " " : "", row->unit);
    CHECK_MSG(has(msg, range), "'%s' lacks '%s'", msg, range);
    q = p;
    set_param(&q, row->property, lo);
    CHECK_MSG(accepted(&q, msg, sizeof(msg)) == !row->min_open, "%s at its min %g: %s",
              row->property, row->min, msg);
    q = p;
    set_param(&q, row->property,
              row->integer    ? row->min - 1.0
              : row->min_open ? lo
                              : nextafter(lo, -HUGE_VAL));
    CHECK_MSG(!accepted(&q, msg, sizeof(msg)), "%s below its min accepted", row->property);
    CHECK_MSG(has(msg, range), "'%s' lacks '%s'", msg, range);
    if (row->min_open) {
      q = p;
      set_param(&q, row->property, nextafter(lo, HUGE_VAL));
      CHECK_MSG(accepted(&q, msg, sizeof(msg)), "%s just above its open min: %s", row->property,
                msg);
    }
    if (!row->integer) {
      q = p;
      set_param(&q, row->property, NAN);
      CHECK(!accepted(&q, msg, sizeof(msg)) && has(msg, row->property));
    }
    bounds_checked += 2;
  }
  CHECK(bounds_checked == 34);
  /* The maps' parameters' sentences, one each. */
  q = p;
  q.wetting_depth = 0.0;
  CHECK(!accepted(&q, msg, sizeof(msg)));
  CHECK_MSG(has(msg, "WettingDepth must be above 0 and at most 10 m (got 0 m)"), "'%s'", msg);
  q = p;
  q.debris_factor = -0.5;
  CHECK(!accepted(&q, msg, sizeof(msg)));
  CHECK_MSG(has(msg, "DebrisFactor must lie between 0 and 1 (got -0.5)"), "'%s'", msg);
  /* The sentence speaks the user's unit. */
  q = p;
  q.rain_rate = 7200.0 / 3.6e6;
  CHECK(!accepted(&q, msg, sizeof(msg)));
  CHECK_MSG(has(msg, "RainRate must lie between 0 and 3600 mm/h (got 7200 mm/h)"), "'%s'", msg);
  /* The maps follow the same rows (in m/s). */
  float v[2] = {0.0f, (float)(t[0].max * t[0].to_core)};
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_RAIN_RATE, v, 2, msg, sizeof(msg)) == GR_OK ||
        (double)v[1] > t[0].max * t[0].to_core);
  v[1] = (float)(2.0 * t[1].max * t[1].to_core);
  CHECK(gr_rain_runoff_field_validate(GR_FIELD_PERMEABILITY, v, 2, msg, sizeof(msg)) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(msg, "36000 mm/h") && has(msg, "Permeability"), "'%s'", msg);
}

/* Compares every field and the ledger of two simulations on grid g. */
int same_bits(gr_rain_runoff *a, gr_rain_runoff *b, const gr_grid *g, const char *what) {
  const gr_field fields[] = {GR_FIELD_WATER_DEPTH, GR_FIELD_VELOCITY, GR_FIELD_DISCHARGE,
                             GR_FIELD_INFILTRATED, GR_FIELD_WATER_SURFACE};
  int same = 1;
  for (size_t f = 0; f < sizeof(fields) / sizeof(fields[0]); ++f) {
    float *fa = get(a, g, fields[f]), *fb = get(b, g, fields[f]);
    size_t bytes = cells_of(g) * (size_t)gr_field_components(fields[f]) * sizeof(float);
    int eq = memcmp(fa, fb, bytes) == 0;
    CHECK_MSG(eq, "%s: %s differs", what, gr_field_name(fields[f]));
    same &= eq;
    free(fa);
    free(fb);
  }
  for (int m = 0; m < GR_RAIN_RUNOFF_MAP_COUNT; ++m) {
    float *fa = alloc_field(g, 1), *fb = alloc_field(g, 1);
    gr_status st = gr_rain_runoff_get_map(a, (gr_rain_runoff_map)m, fa);
    if (st == GR_OK)
      st = gr_rain_runoff_get_map(b, (gr_rain_runoff_map)m, fb);
    int eq = st == GR_OK && memcmp(fa, fb, cells_of(g) * sizeof(float)) == 0;
    CHECK_MSG(eq, "%s: the map %s differs", what, gr_rain_runoff_map_name((gr_rain_runoff_map)m));
    same &= eq;
    free(fa);
    free(fb);
  }
  gr_rain_runoff_ledger la = ledger(a), lb = ledger(b);
  int eq = la.time == lb.time && la.steps == lb.steps && la.rain_volume == lb.rain_volume &&
           la.initial_volume == lb.initial_volume &&
           la.infiltrated_volume == lb.infiltrated_volume &&
           la.outflow_volume == lb.outflow_volume && la.stored_volume == lb.stored_volume &&
           la.balance_error == lb.balance_error && la.max_depth == lb.max_depth;
  CHECK_MSG(eq, "%s: the ledgers differ (t %.17g vs %.17g, stored %.17g vs %.17g)", what, la.time,
            lb.time, la.stored_volume, lb.stored_volume);
  return same && eq;
}

/* Checkpoints: save at t1, run to t2, load, run to t2 again: the same bits
 * and ledger; loaded into a second simulation of the same grid and inputs:
 * the same bits again; bad sizes, headers and grids are refused with a
 * sentence and leave the state as it was. */
void test_checkpoint(void) {
  gr_grid g = {40, 30, 2.0, 2.5, 0.0, 0.0, 0, 0};
  gr_rain_runoff *a = make_bumpy(&g, GR_BOUNDARY_OPEN), *b = make_bumpy(&g, GR_BOUNDARY_OPEN);
  gr_grid g2 = g;
  g2.nx = 41;
  gr_rain_runoff *c = make_bumpy(&g2, GR_BOUNDARY_OPEN);
  if (!a || !b || !c) {
    gr_rain_runoff_destroy(a);
    gr_rain_runoff_destroy(b);
    gr_rain_runoff_destroy(c);
    return;
  }
  run_stable(a, 3, 20);
  size_t bytes = 0;
  CHECK(gr_rain_runoff_state_size(a, &bytes) == GR_OK);
  size_t cells = cells_of(&g), faces = (size_t)41 * 30 + (size_t)40 * 31;
  CHECK_MSG(bytes > (19 * cells + faces) * sizeof(float) &&
                bytes < (19 * cells + faces) * sizeof(float) + 128,
            "%zu bytes", bytes);
  unsigned char *saved = malloc(bytes), *bad = malloc(bytes + 1);
  CHECK(gr_rain_runoff_state_save(a, saved, bytes) == GR_OK);
  gr_rain_runoff_ledger l1 = ledger(a);
  run_stable(a, 4, 25);
  CHECK(gr_rain_runoff_advance(a, 7.5, NULL) == GR_OK);
  float *h2 = get(a, &g, GR_FIELD_WATER_DEPTH);
  gr_rain_runoff_ledger l2 = ledger(a);
  CHECK(l2.time > l1.time && l2.steps >= l1.steps + 100);

  /* b takes a's state at t1 and runs the same way; a goes back to t1. */
  CHECK(gr_rain_runoff_state_load(b, saved, bytes) == GR_OK);
  gr_rain_runoff_ledger lb1 = ledger(b);
  CHECK(lb1.time == l1.time && lb1.steps == l1.steps && lb1.stored_volume == l1.stored_volume &&
        lb1.balance_error == l1.balance_error);
  CHECK(gr_rain_runoff_state_load(a, saved, bytes) == GR_OK);
  gr_rain_runoff_ledger la1 = ledger(a);
  CHECK(la1.time == l1.time && la1.steps == l1.steps && la1.rain_volume == l1.rain_volume);
  run_stable(a, 4, 25);
  CHECK(gr_rain_runoff_advance(a, 7.5, NULL) == GR_OK);
  run_stable(b, 4, 25);
  CHECK(gr_rain_runoff_advance(b, 7.5, NULL) == GR_OK);
  float *again = get(a, &g, GR_FIELD_WATER_DEPTH);
  CHECK_MSG(memcmp(h2, again, cells * sizeof(float)) == 0, "the depth after a reload differs");
  gr_rain_runoff_ledger la2 = ledger(a);
  CHECK(la2.time == l2.time && la2.steps == l2.steps && la2.rain_volume == l2.rain_volume &&
        la2.stored_volume == l2.stored_volume && la2.balance_error == l2.balance_error);
  CHECK(same_bits(a, b, &g, "a reloaded and b loaded"));
  printf("checkpoint: %zu bytes; t1 %.3f s, t2 %.3f s (%lld steps), the same bits after a reload "
         "and in a second simulation\n",
         bytes, l1.time, l2.time, l2.steps - l1.steps);

  /* Refused: the wrong size, a damaged header, another grid, no buffer. */
  CHECK(gr_rain_runoff_state_save(a, saved, bytes - 1) == GR_ERR_INVALID_ARGUMENT);
  CHECK(has(gr_rain_runoff_last_error(a), "gr_rain_runoff_state_size"));
  CHECK(gr_rain_runoff_state_load(b, saved, bytes - 4) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(gr_rain_runoff_last_error(b), "bytes"), "'%s'", gr_rain_runoff_last_error(b));
  memcpy(bad, saved, bytes);
  bad[bytes] = 0;
  CHECK(gr_rain_runoff_state_load(b, bad, bytes + 1) == GR_ERR_INVALID_ARGUMENT);
  bad[0] ^= 0x5a;
  CHECK(gr_rain_runoff_state_load(b, bad, bytes) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(gr_rain_runoff_last_error(b), "not a rain runoff state"), "'%s'",
            gr_rain_runoff_last_error(b));
  CHECK(gr_rain_runoff_state_load(b, bad, 3) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_state_load(c, saved, bytes) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(gr_rain_runoff_last_error(c), "40 x 30") &&
                has(gr_rain_runoff_last_error(c), "41 x 30"),
            "'%s'", gr_rain_runoff_last_error(c));
  CHECK(gr_rain_runoff_state_load(b, NULL, bytes) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_state_save(b, NULL, bytes) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_state_size(b, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_state_size(NULL, &bytes) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_state_save(NULL, saved, bytes) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_rain_runoff_state_load(NULL, saved, bytes) == GR_ERR_INVALID_ARGUMENT);
  /* b was left as it was by every refusal. */
  CHECK(same_bits(a, b, &g, "b after refused loads"));
  free(h2);
  free(again);
  free(saved);
  free(bad);
  gr_rain_runoff_destroy(a);
  gr_rain_runoff_destroy(b);
  gr_rain_runoff_destroy(c);
}

/* A checkpoint of version 6, whose wet duration was a Kahan sum of every
 * wet step's dt (planes 12 and 14 of 17 per-cell arrays: the sum and its
 * compensation), is still read: made here from a version 7 state (version
 * 6's header is version 7's; its wet duration the map read at the save,
 * compensation 0, and without version 7's last two per-cell arrays, the
 * wet spells' starts), it loads into a fresh simulation with every field
 * and map of the saved one, bit for bit (the spells under way start at the
 * checkpoint's time), and stepping on from both gives the same fields and
 * maps, the wet duration to two roundings (the saved one keeps its spells'
 * starts to twice float precision). Other versions, and a version 6 state
 * of the wrong size, are refused with a sentence. */
void test_checkpoint_v6(void) {
  gr_grid g = {40, 30, 2.0, 2.5, 0.0, 0.0, 0, 0};
  gr_rain_runoff *a = make_bumpy(&g, GR_BOUNDARY_OPEN), *b = make_bumpy(&g, GR_BOUNDARY_OPEN);
  if (!a || !b) {
    gr_rain_runoff_destroy(a);
    gr_rain_runoff_destroy(b);
    return;
  }
  run_stable(a, 3, 20);
  size_t bytes = 0, cells = cells_of(&g), faces = (size_t)41 * 30 + (size_t)40 * 31;
  CHECK(gr_rain_runoff_state_size(a, &bytes) == GR_OK);
  size_t plane = cells * sizeof(float), head = bytes - (19 * cells + faces) * sizeof(float);
  size_t old = head + (17 * cells + faces) * sizeof(float);
  unsigned char *v7 = malloc(bytes), *v6 = malloc(bytes);
  float *wet = get_map(a, &g, GR_RAIN_RUNOFF_WET_DURATION);
  CHECK(gr_rain_runoff_state_save(a, v7, bytes) == GR_OK);
  memcpy(v6, v7, head + 17 * plane);
  const uint32_t six = 6;
  memcpy(v6 + 4, &six, sizeof(six));
  memcpy(v6 + head + 12 * plane, wet, plane);
  memset(v6 + head + 14 * plane, 0, plane);
  memcpy(v6 + head + 17 * plane, v7 + head + 19 * plane, faces * sizeof(float));
  int spell = 0;
  for (size_t c = 0; c < cells; ++c)
    spell += wet[c] > 0.0f;
  CHECK(gr_rain_runoff_state_load(b, v6, old) == GR_OK);
  CHECK(same_bits(a, b, &g, "a version 6 state loaded"));
  /* On from both: 40 steps of the same dt. */
  double dt = 0.0;
  CHECK(gr_rain_runoff_stable_dt(a, &dt) == GR_OK);
  CHECK(gr_rain_runoff_step(a, dt, 40) == GR_OK);
  CHECK(gr_rain_runoff_step(b, dt, 40) == GR_OK);
  long differ = 0;
  double wet_err = 0.0;
  for (int m = 0; m < GR_RAIN_RUNOFF_MAP_COUNT; ++m) {
    float *ma = get_map(a, &g, (gr_rain_runoff_map)m), *mb = get_map(b, &g, (gr_rain_runoff_map)m);
    for (size_t c = 0; c < cells; ++c)
      if (m == GR_RAIN_RUNOFF_WET_DURATION)
        wet_err = fmax(wet_err, fabs(ma[c] - mb[c]) / fmax(ma[c], 1e-30));
      else
        differ += memcmp(&ma[c], &mb[c], sizeof(float)) != 0;
    free(ma);
    free(mb);
  }
  float *ha = get(a, &g, GR_FIELD_WATER_DEPTH), *hb = get(b, &g, GR_FIELD_WATER_DEPTH);
  differ += memcmp(ha, hb, plane) != 0;
  printf("checkpoint of version 6: %zu bytes (version 7: %zu), %d cells with wet time; 40 steps "
         "on: %ld values differ from the saved run's, wet_duration off by %.3g relative\n",
         old, bytes, spell, differ, wet_err);
  CHECK(spell > 0 && differ == 0 && wet_err <= 2.5e-7); /* two roundings of a float */
  /* Refused: version 6 at version 7's size, and versions 5 and 8. */
  memcpy(v7 + 4, &six, sizeof(six));
  CHECK(gr_rain_runoff_state_load(b, v7, bytes) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(has(gr_rain_runoff_last_error(b), "bytes"), "'%s'", gr_rain_runoff_last_error(b));
  for (uint32_t v = 5; v <= 8; v += 3) {
    memcpy(v6 + 4, &v, sizeof(v));
    CHECK(gr_rain_runoff_state_load(b, v6, old) == GR_ERR_INVALID_ARGUMENT);
    CHECK_MSG(has(gr_rain_runoff_last_error(b), "version 7 or 6"), "'%s'",
              gr_rain_runoff_last_error(b));
  }
  free(ha);
  free(hb);
  free(wet);
  free(v7);
  free(v6);
  gr_rain_runoff_destroy(a);
  gr_rain_runoff_destroy(b);
}

/* A 256 x 256 pond, deep enough that an advance takes a few hundred steps
 * (about a second on PoCL). */
static gr_rain_runoff *make_pond(const gr_grid *g) {
  float *b = alloc_field(g, 1), *d = alloc_field(g, 1);
  for (int j = 0; j < g->ny; ++j)
    for (int i = 0; i < g->nx; ++i) {
      size_t c = (size_t)j * g->nx + i;
      b[c] = (float)(0.2 * sin(i / 11.0) * cos(j / 13.0) + 0.1 * hash01(i, j, 7));
      d[c] = (float)(0.3 + 0.2 * hash01(i, j, 8));
    }
  gr_rain_runoff_params p = params_with(50.0 / 3.6e6, 5.0 / 3.6e6, GR_BOUNDARY_OPEN);
  gr_rain_runoff *s = make_sim(g, &p, b, d);
  free(b);
  free(d);
  return s;
}

/* Progress: the callback sees increasing simulated times at least every few
 * tenths of a second, and its waits change nothing (a run without it gives
 * the same bits). A nonzero return stops the advance within 0.5 s with
 * GR_ERR_ABORTED at a step boundary: the ledger balances and the state goes
 * on. */
void test_progress(void) {
  gr_grid g = {256, 256, 1.0, 1.0, 0.0, 0.0, 0, 0};
  gr_rain_runoff *a = make_pond(&g), *b = make_pond(&g);
  if (!a || !b) {
    gr_rain_runoff_destroy(a);
    gr_rain_runoff_destroy(b);
    return;
  }
  progress_log log = {0, 1, 0, 0.0, 0.0};
  gr_rain_runoff_set_progress(a, on_progress, &log);
  const double duration = 120.0;
  int sa = 0, sb = 0;
  double t0 = wall_now();
  CHECK(gr_rain_runoff_advance(a, duration, &sa) == GR_OK);
  double wall = wall_now() - t0;
  CHECK(gr_rain_runoff_advance(b, duration, &sb) == GR_OK);
  printf("progress: %d steps in %.2f s, %d calls, last at %.3f s of %.0f\n", sa, wall, log.calls,
         log.last, duration);
  CHECK(sa == sb && sa > 100);
  /* A fast device (a GPU) may finish before the first call is due. */
  CHECK(log.increasing && (log.calls == 0 || (log.last > 0.0 && log.last <= duration)));
  /* At least one call per 0.3 s of wall time after the first 0.3 s. */
  CHECK_MSG(log.calls >= (int)(wall / 0.3), "%d calls in %.2f s", log.calls, wall);
  CHECK(same_bits(a, b, &g, "with and without a progress callback"));

  /* Stop at the third call. */
  progress_log stop = {0, 1, 3, 0.0, 0.0};
  gr_rain_runoff_set_progress(a, on_progress, &stop);
  gr_rain_runoff_ledger before = ledger(a);
  int steps = 0;
  /* Advance until the third call stops it: on a fast device one advance
   * may make fewer than three calls (they come at most every 0.1 s). */
  gr_status st = GR_OK;
  double started = wall_now();
  while (st == GR_OK && stop.calls < 3 && wall_now() - started < 60.0) {
    int more = 0;
    st = gr_rain_runoff_advance(a, 10.0 * duration, &more);
    steps += more;
  }
  double honoured = wall_now() - stop.stopped_at_wall;
  CHECK_MSG(st == GR_ERR_ABORTED, "%s", gr_status_string(st));
  CHECK(stop.calls == 3 && honoured < 0.5);
  CHECK_MSG(has(gr_rain_runoff_last_error(a), "progress"), "'%s'", gr_rain_runoff_last_error(a));
  gr_rain_runoff_ledger l = ledger(a);
  double in = l.initial_volume + l.rain_volume;
  printf("abort: honoured in %.3f s at %.3f s of simulated time (%d steps), balance %.3g\n",
         honoured, l.time, steps, fabs(l.balance_error) / in);
  CHECK(l.steps == before.steps + steps && steps > 0);
  CHECK(l.time > before.time);
  /* The callback saw the time the state stopped at (to rounding). */
  CHECK_MSG(fabs(stop.last - l.time) <= 1e-9 * l.time, "%.17g vs %.17g", stop.last, l.time);
  CHECK(fabs(l.balance_error) <= 1e-7 * in);
  /* The state goes on: without the callback the advance completes. */
  gr_rain_runoff_set_progress(a, NULL, NULL);
  CHECK(gr_rain_runoff_advance(a, 5.0, NULL) == GR_OK);
  l = ledger(a);
  CHECK(fabs(l.balance_error) <= 1e-7 * (l.initial_volume + l.rain_volume));
  float *h = get(a, &g, GR_FIELD_WATER_DEPTH);
  CHECK(bad_depths(h, cells_of(&g)) == 0);
  free(h);
  gr_rain_runoff_destroy(a);
  gr_rain_runoff_destroy(b);
}

/* Two simulations on one shared context (the filters' case) that fail
 * differently keep their own sentences. */
void test_shared_context(void) {
  gr_context *shared = NULL;
  gr_status st = gr_context_acquire(NULL, &shared);
  CHECK_MSG(st == GR_OK, "acquire: %s", gr_last_error(NULL));
  if (st != GR_OK)
    return;
  gr_grid g = {12, 10, 1.0, 1.0, 0.0, 0.0, 0, 0};
  gr_rain_runoff_params p;
  gr_rain_runoff_params_init(&p);
  gr_rain_runoff *a = NULL, *b = NULL;
  CHECK(gr_rain_runoff_create(shared, &g, &p, &a) == GR_OK);
  CHECK(gr_rain_runoff_create(shared, &g, &p, &b) == GR_OK);
  if (a && b) {
    CHECK(strcmp(gr_rain_runoff_last_error(a), "") == 0);
    gr_rain_runoff_params q = p;
    q.manning_n = 2.0;
    CHECK(gr_rain_runoff_set_params(a, &q) == GR_ERR_INVALID_ARGUMENT);
    CHECK(gr_rain_runoff_step(b, -1.0, 1) == GR_ERR_INVALID_ARGUMENT);
    const char *ea = gr_rain_runoff_last_error(a), *eb = gr_rain_runoff_last_error(b);
    CHECK_MSG(has(ea, "ManningN") && !has(ea, "dt"), "a: '%s'", ea);
    CHECK_MSG(has(eb, "dt") && !has(eb, "ManningN"), "b: '%s'", eb);
    /* A success leaves the latest error; a new failure of a replaces a's only. */
    CHECK(gr_rain_runoff_step(a, 0.1, 1) == GR_OK);
    CHECK(has(gr_rain_runoff_last_error(a), "ManningN"));
    float depth[120];
    CHECK(gr_rain_runoff_get_field(a, GR_FIELD_SNOW_DEPTH, depth) == GR_ERR_INVALID_ARGUMENT);
    CHECK(has(gr_rain_runoff_last_error(a), "snow_depth"));
    CHECK(has(gr_rain_runoff_last_error(b), "dt"));
  }
  CHECK(strcmp(gr_rain_runoff_last_error(NULL), "") == 0);
  gr_rain_runoff_destroy(a);
  gr_rain_runoff_destroy(b);
  gr_context_release(shared);
}

/* The ledger's fixed point on the device is the host's (graupel/reduce.h):
 * depths from 1e-12 m to 60 m, set as the initial water, reduce on the
 * device to the very integers the host booked, so the stored volume is the
 * initial one to the bit and the balance is 0 exactly, before any step and
 * after a reset; both equal the depths' sum to 1e-15. */
void test_ledger_fixed_point(void) {
  gr_grid g = {23, 17, 1.5, 2.5, 0.0, 0.0, 0, 0};
  float *b = alloc_field(&g, 1), *d = alloc_field(&g, 1);
  double exact = 0.0; /* in double: to 1e-16 for a few hundred floats */
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      size_t c = (size_t)j * g.nx + i;
      b[c] = (float)(0.01 * i);
      d[c] = (float)(pow(10.0, -12.0 + 13.5 * hash01(i, j, 21)) * (1.0 + hash01(i, j, 22)));
      exact += d[c];
    }
  gr_rain_runoff_params p = params_with(1e-5, 1e-6, GR_BOUNDARY_OPEN);
  gr_rain_runoff *s = make_sim(&g, &p, b, d);
  if (s) {
    for (int pass = 0; pass < 2; ++pass) {
      gr_rain_runoff_ledger l = ledger(s);
      CHECK_MSG(memcmp(&l.stored_volume, &l.initial_volume, sizeof(double)) == 0 &&
                    l.balance_error == 0.0,
                "%s: stored %.17g, initial %.17g, balance %.3g", pass ? "after a reset" : "set",
                l.stored_volume, l.initial_volume, l.balance_error);
      CHECK_NEAR(l.stored_volume, exact * g.dx * g.dy, 1e-15 * exact * g.dx * g.dy);
      double dt = 0.0;
      CHECK(gr_rain_runoff_stable_dt(s, &dt) == GR_OK && dt > 0.0);
      CHECK(gr_rain_runoff_step(s, dt, 20) == GR_OK);
      l = ledger(s);
      double in = l.initial_volume + l.rain_volume;
      /* The steps' float rounding over depths 13 decades apart (2e-8 here,
       * the same before the fixed point), not the ledger's. */
      CHECK_MSG(fabs(l.balance_error) <= 1e-7 * in, "after 20 steps: balance %.3g of %.6g",
                l.balance_error, in);
      CHECK(gr_rain_runoff_reset(s) == GR_OK);
    }
  }
  gr_rain_runoff_destroy(s);
  free(b);
  free(d);
}
