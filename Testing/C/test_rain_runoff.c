/* Rain runoff tests (graupel/rain_runoff.h; seed 004, RainCL, its water
 * height map with its flow made conservative). This file: the helpers every
 * theme uses, the subtests' table and main; the subtests live by theme in
 * test_rain_runoff_*.c (test_rain_runoff.h lists them): the local inertial
 * model's physics (_li), the shallow-water model's (_sw), the interface
 * (_api: errors, parameters, checkpoints, progress, devices), the flood
 * maps (_maps), split domains (_pieces), boundaries (_boundaries), the
 * optional inputs (_inputs) and the launch paths (_paths).
 *
 *   test_rain_runoff             every test but long_run and memcheck
 *   test_rain_runoff memcheck    the host-code paths only, on tiny grids (for
 *                                valgrind, where each kernel run is slow);
 *                                --memcheck is the old spelling
 *   test_rain_runoff NAME...     the named tests (--list names them) */
#include "test_rain_runoff.h"

/* The counters of every file's CHECKs (gr_test.h, GR_TEST_SHARED_COUNTERS). */
int gr_test_failures = 0;
int gr_test_checks = 0;

gr_context *ctx;

/* ---------------------------------------------------------------- helpers */

/* A deterministic value in [0, 1) per cell and seed. */
double hash01(int i, int j, uint32_t seed) {
  uint32_t x = (uint32_t)i * 0x9e3779b1U ^ ((uint32_t)j * 0x85ebca77U + seed * 0xc2b2ae3dU);
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return (double)x / 4294967296.0;
}

size_t cells_of(const gr_grid *g) {
  return (size_t)g->nx * (size_t)g->ny;
}

float *alloc_field(const gr_grid *g, int components) {
  return calloc(cells_of(g) * (size_t)components, sizeof(float));
}

/* Every edge of the domain the same kind. */
void set_edges(gr_rain_runoff_params *p, gr_boundary kind) {
  for (int e = 0; e < 4; ++e)
    p->boundary[e] = kind;
}

/* Parameters of the local inertial model (FlowModel 1), which the tests
 * before the shallow-water section check. */
gr_rain_runoff_params params_with(double rain, double perm, gr_boundary boundary) {
  gr_rain_runoff_params p;
  gr_rain_runoff_params_init(&p);
  p.rain_rate = rain;
  p.permeability = perm;
  set_edges(&p, boundary);
  p.flow_model = GR_FLOW_LOCAL_INERTIAL;
  return p;
}

/* A simulation on g with elevation b (NULL: flat at 0) and, when given, an
 * initial depth. */
gr_rain_runoff *make_sim(const gr_grid *g, const gr_rain_runoff_params *p, const float *b,
                         const float *depth) {
  gr_rain_runoff *s = NULL;
  gr_status st = gr_rain_runoff_create(ctx, g, p, &s);
  if (st == GR_OK && b)
    st = gr_rain_runoff_set_field(s, GR_FIELD_ELEVATION, b);
  if (st == GR_OK && depth)
    st = gr_rain_runoff_set_field(s, GR_FIELD_WATER_DEPTH, depth);
  CHECK_MSG(st == GR_OK, "set-up: %s", gr_last_error(ctx));
  if (st != GR_OK) {
    gr_rain_runoff_destroy(s);
    return NULL;
  }
  return s;
}

float *get(gr_rain_runoff *s, const gr_grid *g, gr_field f) {
  float *v = alloc_field(g, gr_field_components(f));
  gr_status st = gr_rain_runoff_get_field(s, f, v);
  CHECK_MSG(st == GR_OK, "get %s: %s", gr_field_name(f), gr_last_error(ctx));
  return v;
}

gr_rain_runoff_ledger ledger(gr_rain_runoff *s) {
  gr_rain_runoff_ledger l;
  memset(&l, 0, sizeof(l));
  gr_status st = gr_rain_runoff_ledger_get(s, &l);
  CHECK_MSG(st == GR_OK, "ledger: %s", gr_last_error(ctx));
  return l;
}

/* Steps in chunks of `chunk` at the stable step, `chunks` times. */
void run_stable(gr_rain_runoff *s, int chunks, int chunk) {
  for (int c = 0; c < chunks; ++c) {
    double dt = 0.0;
    gr_status st = gr_rain_runoff_stable_dt(s, &dt);
    if (st == GR_OK)
      st = gr_rain_runoff_step(s, dt, chunk);
    CHECK_MSG(st == GR_OK, "stepping: %s", gr_last_error(ctx));
    if (st != GR_OK)
      return;
  }
}

/* Counts depths that are negative, NaN or infinite. */
/* The flow models by gr_flow_model. */
const char *const model_names[2] = {"shallow water", "local inertial"};

int bad_depths(const float *h, size_t n) {
  int bad = 0;
  for (size_t c = 0; c < n; ++c)
    bad += !(h[c] >= 0.0f && h[c] < 1e30f);
  return bad;
}

int bad_values(const float *v, size_t n) {
  int bad = 0;
  for (size_t c = 0; c < n; ++c)
    bad += !(v[c] > -1e30f && v[c] < 1e30f);
  return bad;
}

double sum_of(const float *v, size_t n) {
  double s = 0.0;
  for (size_t c = 0; c < n; ++c)
    s += v[c];
  return s;
}

static const gr_subtest tests[] = {
    {"rain_gain", test_rain_gain, 0},
    {"infiltration", test_infiltration, 0},
    {"conservation", test_conservation, 0},
    {"bowl", test_bowl, 0},
    {"tilted_plane", test_tilted_plane, 0},
    {"tilted_plane_uncapped", test_tilted_plane_uncapped, 0},
    {"symmetry", test_symmetry, 0},
    {"determinism", test_determinism, 0},
    {"lake_at_rest", test_lake_at_rest, 0},
    {"column", test_column, 0},
    {"advance", test_advance, 0},
    {"advance_dry_start", test_advance_dry_start, 0},
    {"reset", test_reset, 0},
    {"long_run", test_long_run_default, 1},
    {"devices_agree", test_devices_agree, 0},
    {"errors", test_errors, 0},
    {"param_table", test_param_table, 0},
    {"checkpoint", test_checkpoint, 0},
    {"checkpoint_v6", test_checkpoint_v6, 0},
    {"progress", test_progress, 0},
    {"shared_context", test_shared_context, 0},
    {"ledger_fixed_point", test_ledger_fixed_point, 0},
    {"pieces_x", test_pieces_x, 0},
    {"pieces_y", test_pieces_y, 0},
    {"advance_pieces_x", test_advance_pieces_x, 0},
    {"advance_pieces_y", test_advance_pieces_y, 0},
    {"advance_pieces_abort", test_advance_pieces_abort, 0},
    {"piece_checkpoint", test_piece_checkpoint, 0},
    {"pieces_wet_spells", test_pieces_wet_spells, 0},
    {"memcheck", test_memcheck_subset, 1},
    {"sw_ritter", test_sw_ritter, 0},
    {"sw_stoker", test_sw_stoker, 0},
    {"sw_lake_at_rest", test_sw_lake_at_rest, 0},
    {"sw_conservation", test_sw_conservation, 0},
    {"sw_determinism", test_sw_determinism, 0},
    {"sw_thacker", test_sw_thacker, 0},
    {"sw_bump", test_sw_bump, 0},
    {"sw_tilted_plane", test_sw_tilted_plane, 0},
    {"sw_inputs", test_sw_inputs, 0},
    {"sw_thin_films", test_sw_thin_films, 0},
    {"sw_devices_agree", test_sw_devices_agree, 0},
    {"sw_pieces_x", test_sw_pieces_x, 0},
    {"sw_pieces_y", test_sw_pieces_y, 0},
    {"sw_advance_pieces_x", test_sw_advance_pieces_x, 0},
    {"sw_advance_pieces_y", test_sw_advance_pieces_y, 0},
    {"sw_piece_checkpoint", test_sw_piece_checkpoint, 0},
    {"maps_every_step", test_maps_every_step, 0},
    {"maps_arrival", test_maps_arrival, 0},
    {"maps_hazard", test_maps_hazard, 0},
    {"maps_reset", test_maps_reset, 0},
    {"maps_wet_spells", test_maps_wet_spells, 0},
    {"gauges", test_gauges, 0},
    {"edges_wall", test_edges_wall, 0},
    {"edges_level", test_edges_level, 0},
    {"edges_transmissive", test_edges_transmissive, 0},
    {"edges_mirror", test_edges_mirror, 0},
    {"pieces_edges_x", test_pieces_edges_x, 0},
    {"pieces_edges_y", test_pieces_edges_y, 0},
    {"advance_pieces_edges_y", test_advance_pieces_edges_y, 0},
    {"sw_pieces_edges_x", test_sw_pieces_edges_x, 0},
    {"sw_pieces_edges_y", test_sw_pieces_edges_y, 0},
    {"sw_advance_pieces_edges_x", test_sw_advance_pieces_edges_x, 0},
    {"sw_fused", test_sw_fused, 0},
    {"sw_pieces_paths", test_sw_pieces_paths, 0},
    {"inflow_point", test_inflow_point, 0},
    {"inflow_edge", test_inflow_edge, 0},
    {"inflow_errors", test_inflow_errors, 0},
    {"hyetograph", test_hyetograph, 0},
    {"manning_map", test_manning_map, 0},
    {"no_data", test_no_data, 0},
    {"li_fused", test_li_fused, 0},
    {"specialised", test_specialised, 0},
    {"device_forms", test_device_forms, 0},
    {"pieces_paths", test_pieces_paths, 0},
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
  /* --memcheck: the old spelling of the subtest memcheck. */
  static char memcheck[] = "memcheck";
  for (int a = 1; a < argc; ++a)
    if (strcmp(argv[a], "--memcheck") == 0)
      argv[a] = memcheck;
  return gr_test_main(argc, argv, tests, (int)(sizeof(tests) / sizeof(tests[0])), setup, teardown);
}
