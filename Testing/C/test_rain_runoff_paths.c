/* Rain runoff tests of the launch paths (test_rain_runoff.c has main):
 * fused and separate launches of both models, programs specialised for
 * the inputs in use or not, the device forms of a few expressions, and
 * pieces on every path: the same bits every way. */
#include "test_rain_runoff.h"

/* The inputs of the launch-path tests (sw_fused, li_fused, specialised) on
 * g: a bumpy, tilted bed b with two no-data holes (NaN; the first hole_w x
 * hole_h cells from (58, 11), the second 3 x 3 from (20, 30)), a rain field
 * r (m/s), a permeability map k with dry patches, an initial depth d and a
 * Manning map nmap, all from hashes of the cell. */
static void paths_fields(const gr_grid *g, float *b, float *r, float *k, float *d, double *nmap,
                         int hole_w, int hole_h) {
  for (int j = 0; j < g->ny; ++j)
    for (int i = 0; i < g->nx; ++i) {
      size_t c = (size_t)j * g->nx + i;
      double x = i * g->dx, y = j * g->dy;
      b[c] =
          (float)(0.03 * x + 0.02 * y + 0.4 * sin(x / 7.0) * cos(y / 5.0) + 0.2 * hash01(i, j, 71));
      r[c] = (float)(4e-5 * hash01(i, j, 72));
      k[c] = hash01(i, j, 73) < 0.5 ? 0.0f : (float)(4e-6 * hash01(i, j, 74));
      d[c] = (float)(0.08 * hash01(i, j, 75));
      nmap[c] = 0.02 + 0.05 * hash01(i, j, 76);
      int hole_a = i >= 58 && i < 58 + hole_w && j >= 11 && j < 11 + hole_h;
      int hole_b = i >= 20 && i < 23 && j >= 30 && j < 33;
      if (hole_a || hole_b)
        b[c] = NAN;
    }
}

/* The launch-path tests' 75 x 41 grid and its inputs (paths_fields, the
 * first hole hole_w x hole_h cells). */
typedef struct paths_in {
  gr_grid g;
  float *b, *r, *k, *d;
  double *nmap;
} paths_in;

static paths_in paths_make(int hole_w, int hole_h) {
  paths_in in = {{75, 41, 2.0, 1.5, 0.0, 0.0, 0, 0}, NULL, NULL, NULL, NULL, NULL};
  in.b = alloc_field(&in.g, 1);
  in.r = alloc_field(&in.g, 1);
  in.k = alloc_field(&in.g, 1);
  in.d = alloc_field(&in.g, 1);
  in.nmap = malloc(cells_of(&in.g) * sizeof(double));
  paths_fields(&in.g, in.b, in.r, in.k, in.d, in.nmap, hole_w, hole_h);
  return in;
}

static void paths_free(paths_in *in) {
  free(in->b);
  free(in->r);
  free(in->k);
  free(in->d);
  free(in->nmap);
}

/* The 4-byte words in which the saved states of a and b differ (-1 where
 * either cannot be saved); *words gets the state's length in words. */
static long state_words_differ(gr_rain_runoff *a, gr_rain_runoff *b, size_t *words) {
  size_t bytes = 0;
  *words = 0;
  CHECK(gr_rain_runoff_state_size(a, &bytes) == GR_OK && bytes > 0);
  unsigned char *st[2] = {calloc(bytes ? bytes : 1, 1), calloc(bytes ? bytes : 1, 1)};
  long diff = -1;
  if (st[0] && st[1] && gr_rain_runoff_state_save(a, st[0], bytes) == GR_OK &&
      gr_rain_runoff_state_save(b, st[1], bytes) == GR_OK) {
    diff = 0;
    for (size_t q = 0; q + 4 <= bytes; q += 4)
      diff += memcmp(st[0] + q, st[1] + q, 4) != 0;
  }
  CHECK_MSG(diff >= 0, "saving the states of %zu bytes failed", bytes);
  free(st[0]);
  free(st[1]);
  *words = bytes / 4;
  return diff;
}

/* Whether two simulations' ledgers are the same to the bit. */
static int ledgers_same(gr_rain_runoff *a, gr_rain_runoff *b) {
  gr_rain_runoff_ledger la = ledger(a), lb = ledger(b);
  return memcmp(&la, &lb, sizeof(la)) == 0;
}

/* The launch-path tests' run: 300 steps of sim[0..2] in stretches of 30,
 * sim[2] switched between the paths every stretch (set_path(sim, on), on
 * in the even ones); then every word of the state and the ledger of the two
 * others against sim[ref] (the path `ref_path`: diff[0] the other fixed
 * path, diff[1] the switching run). Returns sim[ref]'s fastest max_speed
 * (m/s) and *l its ledger, for the test's check that water flowed. */
static double paths_run(gr_rain_runoff *sim[3], int ref, void (*set_path)(gr_rain_runoff *, int),
                        const gr_grid *g, int config, const char *ref_path,
                        gr_rain_runoff_ledger *l, long diff[2], size_t *words) {
  for (int chunk = 0; chunk < 10; ++chunk) {
    set_path(sim[2], chunk % 2 == 0);
    for (int v = 0; v < 3; ++v)
      run_stable(sim[v], 1, 30);
  }
  int other = 1 - ref;
  diff[0] = state_words_differ(sim[ref], sim[other], words);
  diff[1] = state_words_differ(sim[ref], sim[2], words);
  gr_rain_runoff_ledger lr = ledger(sim[ref]);
  int same_ledger = ledgers_same(sim[ref], sim[other]) && ledgers_same(sim[ref], sim[2]);
  CHECK_MSG(diff[0] == 0 && diff[1] == 0 && same_ledger,
            "config %d: %ld (fused) and %ld (switching) words of the state of %zu differ from "
            "the %s'; ledgers %s",
            config, diff[0], diff[1], *words, ref_path, same_ledger ? "agree" : "differ");
  float *speed = get_map(sim[ref], g, GR_RAIN_RUNOFF_MAX_SPEED);
  double vmax = 0.0;
  for (size_t c = 0; c < cells_of(g); ++c)
    vmax = isnan(speed[c]) ? vmax : fmax(vmax, speed[c]);
  free(speed);
  *l = lr;
  return vmax;
}

/* The shallow-water pieces tests with each launch path forced (the fused
 * stages read the ring through their tiles' halos), with every kind of edge
 * and without: every owned cell of every field and the ledger bit for bit
 * the whole grid's. */
void test_sw_pieces_paths(void) {
  for (int f = 0; f < 2; ++f) {
    piece_sw_fused = f;
    printf("%s:\n", f ? "one launch a stage" : "separate launches");
    test_sw_pieces_x();
    run_with_edges(test_sw_pieces_y);
    run_with_edges(test_sw_advance_pieces_x);
  }
  piece_sw_fused = -1;
}

/* The shallow-water step with each stage in one launch
 * (gr_rain_runoff_set_sw_fused) gives the separate launches' bits: on a
 * 75 x 41 grid (no multiple of any tile: partial tiles at the far edges),
 * bumpy and tilted, (0) with a rain field, a permeability map, a Manning
 * map, point inflows, no-data holes (outfalls, one across tile borders) and
 * a level, a transmissive, a wall and an open edge with a hydrograph on the
 * wall; (1) every edge open, a hyetograph and uniform inputs; (2)
 * frictionless, walls, a transmissive north edge and no-data walls. After
 * 300 steps the whole state (depth and its compensation, discharges,
 * infiltration, outflow, inflow, flood maps) and the ledger are the same to
 * the bit for the fused path with the device's tile, and for a run that
 * switches between the paths every 30 steps with a tile of 8 x 4. Both
 * tiles leave interior tiles (the faces' expression without the edges'
 * cases, rain_runoff_sw_inner*) and rim tiles (32 x 8: 1 x 3 of 3 x 6;
 * 8 x 4: 8 x 8 of 10 x 11). A tile that is no tile, or larger than the
 * device takes, is refused. */
void test_sw_fused(void) {
  paths_in in = paths_make(8, 7); /* the first hole across tiles' corners */
  gr_grid g = in.g;
  size_t n = cells_of(&g);
  float *b = in.b, *r = in.r, *k = in.k, *d = in.d;
  double *nmap = in.nmap;
  const double ht[3] = {0.0, 30.0, 90.0}, hq[3] = {0.0, 0.5, 0.1};
  const double hyt[3] = {0.0, 40.0, 200.0}, hyr[3] = {1e-5, 6e-5, 2e-5};
  const int ij[4] = {37, 20, 5, 38};
  const double pq[2] = {0.05, 0.02};
  for (int config = 0; config < 3; ++config) {
    gr_rain_runoff_params p = params_with(0.0, 0.0, GR_BOUNDARY_OPEN);
    p.flow_model = GR_FLOW_SHALLOW_WATER;
    if (config == 0) {
      p.boundary[GR_RAIN_RUNOFF_WEST] = GR_BOUNDARY_LEVEL;
      p.boundary_level[GR_RAIN_RUNOFF_WEST] = 0.5;
      p.boundary[GR_RAIN_RUNOFF_EAST] = GR_BOUNDARY_TRANSMISSIVE;
      p.boundary[GR_RAIN_RUNOFF_SOUTH] = GR_BOUNDARY_CLOSED;
      p.no_data = GR_BOUNDARY_OPEN;
    } else if (config == 1) {
      p.permeability = 2e-6;
    } else {
      set_edges(&p, GR_BOUNDARY_CLOSED);
      p.boundary[GR_RAIN_RUNOFF_NORTH] = GR_BOUNDARY_TRANSMISSIVE;
      p.no_data = GR_BOUNDARY_CLOSED;
      p.manning_n = 0.0;
    }
    gr_rain_runoff *sim[3] = {NULL, NULL, NULL};
    for (int v = 0; v < 3; ++v) {
      sim[v] = make_sim(&g, &p, b, d);
      if (!sim[v])
        continue;
      gr_rain_runoff_set_sw_fused(sim[v], v != 0);
      if (v == 2)
        CHECK_MSG(gr_rain_runoff_set_sw_tile(sim[v], 8, 4) == GR_OK, "tile 8 x 4: %s",
                  gr_rain_runoff_last_error(sim[v]));
      if (config != 1) {
        CHECK(gr_rain_runoff_set_field(sim[v], GR_FIELD_RAIN_RATE, r) == GR_OK);
        CHECK(gr_rain_runoff_set_field(sim[v], GR_FIELD_PERMEABILITY, k) == GR_OK);
        CHECK(gr_rain_runoff_set_point_inflows(sim[v], ij, pq, 2) == GR_OK);
      }
      if (config == 0) {
        CHECK(gr_rain_runoff_set_manning_map(sim[v], nmap) == GR_OK);
        CHECK(gr_rain_runoff_set_edge_inflow(sim[v], GR_RAIN_RUNOFF_SOUTH, ht, hq, 3) == GR_OK);
      }
      if (config == 1)
        CHECK(gr_rain_runoff_set_hyetograph(sim[v], hyt, hyr, 3) == GR_OK);
    }
    if (!sim[0] || !sim[1] || !sim[2]) {
      for (int v = 0; v < 3; ++v)
        gr_rain_runoff_destroy(sim[v]);
      continue;
    }
    size_t words = 0;
    long diff[2];
    gr_rain_runoff_ledger l0;
    double vmax = paths_run(sim, 0, gr_rain_runoff_set_sw_fused, &g, config, "separate launches",
                            &l0, diff, &words);
    /* Water moved and left (or, walled in, came in through the north edge
     * or from the inflows): the comparison is of a flow, not of still water. */
    CHECK_MSG(l0.steps == 300 && l0.outflow_volume + l0.inflow_volume > 1.0 && vmax > 0.05,
              "config %d: %lld steps, outflow %g m^3, inflow %g m^3, fastest %g m/s", config,
              l0.steps, l0.outflow_volume, l0.inflow_volume, vmax);
    CHECK(fabs(l0.balance_error) < 1e-6 * (l0.rain_volume + l0.inflow_volume + l0.initial_volume));
    printf("config %d: after %lld steps %ld words of %zu differ (fused), %ld (switching, tile 8 x "
           "4); outflow %.4f m^3, inflow %.4f m^3, fastest %.3f m/s\n",
           config, l0.steps, diff[0], words, diff[1], l0.outflow_volume, l0.inflow_volume, vmax);
    if (config == 0) {
      /* Tiles that are none, or too large for any device, are refused and
       * the tile kept (the run above is unchanged by the attempt). */
      const int bad[3][2] = {{0, 4}, {-8, 8}, {4096, 4096}};
      for (int t = 0; t < 3; ++t) {
        gr_status e = gr_rain_runoff_set_sw_tile(sim[1], bad[t][0], bad[t][1]);
        const char *msg = gr_rain_runoff_last_error(sim[1]);
        CHECK_MSG(e == GR_ERR_INVALID_ARGUMENT && strstr(msg, "tile") != NULL,
                  "tile %d x %d: status %d, '%s'", bad[t][0], bad[t][1], (int)e, msg);
      }
      run_stable(sim[1], 1, 2);
      run_stable(sim[0], 1, 2);
      CHECK(state_words_differ(sim[0], sim[1], &words) == 0);
    }
    for (int v = 0; v < 3; ++v)
      gr_rain_runoff_destroy(sim[v]);
  }
  paths_free(&in);
}

/* The local inertial pieces tests with each of the step's launch paths
 * forced (the fused one reads its ring two cells deep every step), with
 * every kind of edge and without. */
void test_pieces_paths(void) {
  for (int f = 0; f < 2; ++f) {
    piece_fused = f;
    printf("%s:\n", f ? "one launch a step" : "three launches a step");
    test_pieces_x();
    run_with_edges(test_pieces_y);
    run_with_edges(test_advance_pieces_y);
  }
  piece_fused = -1;
}

/* The local inertial step in one launch (gr_rain_runoff_set_fused) gives
 * the three launches' bits: on a 75 x 41 grid (no multiple of any tile, so
 * partial tiles at the far edges), bumpy and tilted, with a rain field, a
 * permeability map, a Manning map, point inflows, no-data holes (outfalls,
 * one across tile borders) and a level, a transmissive, a wall and an open
 * edge with a hydrograph on the wall; and with every edge open, a
 * hyetograph and uniform inputs (no edge launch). After 300 steps the whole
 * state (depth and its compensation, limiters, discharges, infiltration,
 * outflow, inflow, flood maps, ledger) is the same to the bit, also for a
 * run that switches between the paths every 30 steps. */
void test_li_fused(void) {
  paths_in in = paths_make(6, 5); /* the first hole across a tile's corner */
  gr_grid g = in.g;
  size_t n = cells_of(&g);
  float *b = in.b, *r = in.r, *k = in.k, *d = in.d;
  double *nmap = in.nmap;
  const double ht[3] = {0.0, 30.0, 90.0}, hq[3] = {0.0, 0.5, 0.1};
  const double hyt[3] = {0.0, 40.0, 200.0}, hyr[3] = {1e-5, 6e-5, 2e-5};
  const int ij[4] = {37, 20, 5, 38};
  const double pq[2] = {0.05, 0.02};
  for (int config = 0; config < 2; ++config) {
    gr_rain_runoff_params p = params_with(0.0, 0.0, GR_BOUNDARY_OPEN);
    if (config == 0) {
      p.boundary[GR_RAIN_RUNOFF_WEST] = GR_BOUNDARY_LEVEL;
      p.boundary_level[GR_RAIN_RUNOFF_WEST] = 0.5;
      p.boundary[GR_RAIN_RUNOFF_EAST] = GR_BOUNDARY_TRANSMISSIVE;
      p.boundary[GR_RAIN_RUNOFF_SOUTH] = GR_BOUNDARY_CLOSED;
      p.no_data = GR_BOUNDARY_OPEN;
    } else {
      p.permeability = 2e-6;
    }
    gr_rain_runoff *sim[3] = {NULL, NULL, NULL};
    for (int v = 0; v < 3; ++v) {
      sim[v] = make_sim(&g, &p, b, d);
      if (!sim[v])
        continue;
      gr_rain_runoff_set_fused(sim[v], v != 1);
      if (config == 0) {
        CHECK(gr_rain_runoff_set_field(sim[v], GR_FIELD_RAIN_RATE, r) == GR_OK);
        CHECK(gr_rain_runoff_set_field(sim[v], GR_FIELD_PERMEABILITY, k) == GR_OK);
        CHECK(gr_rain_runoff_set_manning_map(sim[v], nmap) == GR_OK);
        CHECK(gr_rain_runoff_set_point_inflows(sim[v], ij, pq, 2) == GR_OK);
        CHECK(gr_rain_runoff_set_edge_inflow(sim[v], GR_RAIN_RUNOFF_SOUTH, ht, hq, 3) == GR_OK);
      } else {
        CHECK(gr_rain_runoff_set_hyetograph(sim[v], hyt, hyr, 3) == GR_OK);
      }
    }
    if (!sim[0] || !sim[1] || !sim[2]) {
      for (int v = 0; v < 3; ++v)
        gr_rain_runoff_destroy(sim[v]);
      continue;
    }
    size_t words = 0;
    long diff[2];
    gr_rain_runoff_ledger l1;
    double vmax = paths_run(sim, 1, gr_rain_runoff_set_fused, &g, config, "three launches", &l1,
                            diff, &words);
    /* Water moved and left through the edges, the holes filled in part:
     * the comparison is of a flow, not of still water. */
    CHECK_MSG(l1.steps == 300 && l1.outflow_volume > 0.0 && vmax > 0.05,
              "config %d: %lld steps, outflow %g m^3, fastest %g m/s", config, l1.steps,
              l1.outflow_volume, vmax);
    CHECK(fabs(l1.balance_error) < 1e-6 * (l1.rain_volume + l1.inflow_volume + l1.initial_volume));
    printf("config %d: after %lld steps %ld words of %zu differ (one launch), %ld (switching); "
           "outflow %.4f m^3, inflow %.4f m^3, fastest %.3f m/s\n",
           config, l1.steps, diff[0], words, diff[1], l1.outflow_volume, l1.inflow_volume, vmax);
    for (int v = 0; v < 3; ++v)
      gr_rain_runoff_destroy(sim[v]);
  }
  paths_free(&in);
}

/* Gives sim the optional inputs of `bits` (GR_RAIN_RUNOFF_INPUT_*) from the
 * paths_fields inputs; the no-data holes come with the elevation (make_sim). */
static void give_inputs(gr_rain_runoff *sim, int bits, const float *r, const float *k,
                        const double *nmap) {
  const int ij[4] = {37, 20, 5, 38};
  const double pq[2] = {0.05, 0.02};
  if (bits & GR_RAIN_RUNOFF_INPUT_RAIN)
    CHECK(gr_rain_runoff_set_field(sim, GR_FIELD_RAIN_RATE, r) == GR_OK);
  if (bits & GR_RAIN_RUNOFF_INPUT_PERMEABILITY)
    CHECK(gr_rain_runoff_set_field(sim, GR_FIELD_PERMEABILITY, k) == GR_OK);
  if (bits & GR_RAIN_RUNOFF_INPUT_INFLOWS)
    CHECK(gr_rain_runoff_set_point_inflows(sim, ij, pq, 2) == GR_OK);
  if (bits & GR_RAIN_RUNOFF_INPUT_MANNING)
    CHECK(gr_rain_runoff_set_manning_map(sim, nmap) == GR_OK);
}

/* The two forms of the expressions written apart for GPUs and CPUs
 * (-DGR_RAIN_RUNOFF_GPU=1 or 0: the host picks by the device's type; see
 * gr_sw_minmod) give the same bits. Each form is forced through
 * GRAUPEL_CL_OPTIONS (read at each program build, the last -D winning), so
 * both run on whatever device the test has: the shallow-water model on the
 * 75 x 41 bumpy grid of the launch-path tests with every optional input, a
 * wall, a transmissive, a level and an open edge, in each launch path;
 * after 120 steps the whole state and the ledger are the same to the bit.
 * A third run takes the GPUs' form with the fused stages built for their
 * tile (-DGR_SW_TILE_X, Y, as the host builds them on GPUs: every index of
 * the tile a constant), a tile of 8 x 4 that has interior and rim tiles on
 * this grid; it too gives the CPUs' form's bits. */
void test_device_forms(void) {
  paths_in in = paths_make(6, 5);
  gr_grid g = in.g;
  size_t n = cells_of(&g);
  float *b = in.b, *r = in.r, *k = in.k, *d = in.d;
  double *nmap = in.nmap;
  gr_rain_runoff_params p = params_with(2e-5, 1e-6, GR_BOUNDARY_OPEN);
  p.flow_model = GR_FLOW_SHALLOW_WATER;
  p.no_data = GR_BOUNDARY_OPEN;
  p.boundary[GR_RAIN_RUNOFF_WEST] = GR_BOUNDARY_LEVEL;
  p.boundary_level[GR_RAIN_RUNOFF_WEST] = 0.5;
  p.boundary[GR_RAIN_RUNOFF_EAST] = GR_BOUNDARY_TRANSMISSIVE;
  p.boundary[GR_RAIN_RUNOFF_SOUTH] = GR_BOUNDARY_CLOSED;
  const char *before = getenv("GRAUPEL_CL_OPTIONS");
  char *kept = before ? strdup(before) : NULL;
  for (int fused = 0; fused < 2; ++fused) {
    /* the CPUs' form, the GPUs', the GPUs' built for an 8 x 4 tile */
    gr_rain_runoff *sim[3] = {NULL, NULL, NULL};
    for (int v = 0; v < 3; ++v) {
      char opt[512];
      snprintf(opt, sizeof(opt), "%s -DGR_RAIN_RUNOFF_GPU=%d%s", kept ? kept : "", v > 0,
               v == 2 ? " -DGR_SW_TILE_X=8 -DGR_SW_TILE_Y=4" : "");
      setenv("GRAUPEL_CL_OPTIONS", opt, 1);
      sim[v] = make_sim(&g, &p, b, d);
      if (sim[v]) {
        if (v == 2)
          CHECK(gr_rain_runoff_set_sw_tile(sim[v], 8, 4) == GR_OK);
        gr_rain_runoff_set_sw_fused(sim[v], fused);
        give_inputs(sim[v], GR_RAIN_RUNOFF_INPUT_ALL, r, k, nmap);
        run_stable(sim[v], 4, 30); /* builds the program under this form */
      }
    }
    if (kept)
      setenv("GRAUPEL_CL_OPTIONS", kept, 1);
    else
      unsetenv("GRAUPEL_CL_OPTIONS");
    for (int v = 1; v < 3; ++v) {
      if (!sim[0] || !sim[v])
        continue;
      size_t words = 0;
      long diff = state_words_differ(sim[0], sim[v], &words);
      gr_rain_runoff_ledger l0 = ledger(sim[0]);
      int same_ledger = ledgers_same(sim[0], sim[v]);
      const char *what = v == 2 ? "the GPUs' form built for its tile" : "the GPUs' form";
      CHECK_MSG(diff == 0 && same_ledger,
                "%s, %s: %ld words of the state of %zu differ from the CPUs' form; ledgers %s",
                fused ? "fused" : "separate launches", what, diff, words,
                same_ledger ? "agree" : "differ");
      CHECK_MSG(l0.steps == 120 && l0.outflow_volume > 0.0 && l0.infiltrated_volume > 0.0,
                "%lld steps, outflow %g m^3, infiltrated %g m^3", l0.steps, l0.outflow_volume,
                l0.infiltrated_volume);
      printf("%s, %s: %ld words of %zu differ from the CPUs' form; outflow %.4f m^3\n",
             fused ? "fused" : "separate launches", what, diff, words, l0.outflow_volume);
    }
    for (int v = 0; v < 3; ++v)
      gr_rain_runoff_destroy(sim[v]);
  }
  free(kept);
  paths_free(&in);
}

/* The step kernels compiled for the optional inputs in use
 * (gr_rain_runoff_set_specialised, the default) give the general kernels'
 * bits. Both models on the 75 x 41 bumpy grid of the launch-path tests,
 * with no optional input, each of the five alone (a rain field, a
 * permeability map, point inflows, no-data holes, a Manning map) and all of
 * them; and a run that gains them on the way (none for 40 steps, then the
 * rain and permeability maps, then the Manning map and the inflows after 80
 * steps), whose kernels follow the inputs at each step
 * (gr_rain_runoff_specialised_for), against a general run given the same.
 * After 120 steps the whole state (depth and its compensation, limiters or
 * discharges, infiltration, outflow, inflow, flood maps) and the ledger are
 * the same to the bit; also after switching the model between steps. */
void test_specialised(void) {
  paths_in in = paths_make(6, 5);
  gr_grid g = in.g;
  size_t n = cells_of(&g);
  float *b = in.b, *r = in.r, *k = in.k, *d = in.d;
  double *nmap = in.nmap;
  float *solid = alloc_field(&g, 1);
  for (size_t c = 0; c < n; ++c) /* the same bed without holes */
    solid[c] = isnan(b[c]) ? 0.5f : b[c];
  const int sets[] = {0,
                      GR_RAIN_RUNOFF_INPUT_RAIN,
                      GR_RAIN_RUNOFF_INPUT_PERMEABILITY,
                      GR_RAIN_RUNOFF_INPUT_INFLOWS,
                      GR_RAIN_RUNOFF_INPUT_NO_DATA,
                      GR_RAIN_RUNOFF_INPUT_MANNING,
                      GR_RAIN_RUNOFF_INPUT_ALL,
                      -1 /* gained on the way */};
  const int nsets = (int)(sizeof(sets) / sizeof(sets[0]));
  for (int m = 0; m < 2; ++m)
    for (int t = 0; t < nsets; ++t) {
      int bits = sets[t], staged = bits < 0;
      gr_rain_runoff_params p = params_with(2e-5, 1e-6, GR_BOUNDARY_OPEN);
      p.flow_model = m ? GR_FLOW_LOCAL_INERTIAL : GR_FLOW_SHALLOW_WATER; /* model_names' order */
      p.no_data = GR_BOUNDARY_OPEN;
      int holes = !staged && (bits & GR_RAIN_RUNOFF_INPUT_NO_DATA);
      gr_rain_runoff *sim[2] = {NULL, NULL}; /* general, specialised */
      for (int v = 0; v < 2; ++v) {
        sim[v] = make_sim(&g, &p, holes ? b : solid, d);
        if (!sim[v])
          continue;
        gr_rain_runoff_set_specialised(sim[v], v);
        give_inputs(sim[v], staged ? 0 : bits, r, k, nmap);
      }
      if (!sim[0] || !sim[1]) {
        gr_rain_runoff_destroy(sim[0]);
        gr_rain_runoff_destroy(sim[1]);
        continue;
      }
      const int gained[3] = {0, GR_RAIN_RUNOFF_INPUT_RAIN | GR_RAIN_RUNOFF_INPUT_PERMEABILITY,
                             GR_RAIN_RUNOFF_INPUT_MANNING | GR_RAIN_RUNOFF_INPUT_INFLOWS};
      int have = staged ? 0 : bits, follows = 1;
      for (int part = 0; part < 3; ++part) {
        if (staged && part > 0) {
          for (int v = 0; v < 2; ++v)
            give_inputs(sim[v], gained[part], r, k, nmap);
          have |= gained[part];
        }
        for (int v = 0; v < 2; ++v)
          run_stable(sim[v], 4, 10);
        follows &= gr_rain_runoff_specialised_for(sim[1]) == have &&
                   gr_rain_runoff_specialised_for(sim[0]) == GR_RAIN_RUNOFF_INPUT_ALL;
      }
      size_t words = 0;
      long diff = state_words_differ(sim[0], sim[1], &words);
      gr_rain_runoff_ledger l0 = ledger(sim[0]);
      int same_ledger = ledgers_same(sim[0], sim[1]);
      CHECK_MSG(follows, "%s, inputs %d: the kernels are built for %d, not the inputs in use (%d)",
                model_names[m], bits, gr_rain_runoff_specialised_for(sim[1]), have);
      CHECK_MSG(diff == 0 && same_ledger,
                "%s, inputs %d: %ld words of the state of %zu differ from the general "
                "kernels'; ledgers %s",
                model_names[m], bits, diff, words, same_ledger ? "agree" : "differ");
      /* A flow: water left through the edges and infiltrated. */
      CHECK_MSG(l0.steps == 120 && l0.outflow_volume > 0.0 && l0.infiltrated_volume > 0.0,
                "%s, inputs %d: %lld steps, outflow %g m^3, infiltrated %g m^3", model_names[m],
                bits, l0.steps, l0.outflow_volume, l0.infiltrated_volume);
      printf("%s, inputs %2d: kernels for %2d, %ld words of %zu differ; outflow %.4f m^3\n",
             model_names[m], bits, gr_rain_runoff_specialised_for(sim[1]), diff, words,
             l0.outflow_volume);
      for (int v = 0; v < 2; ++v)
        gr_rain_runoff_destroy(sim[v]);
    }
  /* The model switched between steps (gr_rain_runoff_set_params): a local
   * inertial program has no shallow-water kernels, so the switch takes the
   * shallow-water program, and back; against a general run switched alike. */
  gr_rain_runoff *sim[2] = {NULL, NULL};
  gr_rain_runoff_params p = params_with(2e-5, 1e-6, GR_BOUNDARY_OPEN);
  for (int v = 0; v < 2; ++v) {
    sim[v] = make_sim(&g, &p, solid, d);
    if (sim[v]) {
      gr_rain_runoff_set_specialised(sim[v], v);
      give_inputs(sim[v], GR_RAIN_RUNOFF_INPUT_RAIN, r, k, nmap);
    }
  }
  for (int part = 0; sim[0] && sim[1] && part < 3; ++part) {
    p.flow_model = part == 1 ? GR_FLOW_SHALLOW_WATER : GR_FLOW_LOCAL_INERTIAL;
    for (int v = 0; v < 2; ++v) {
      CHECK(gr_rain_runoff_set_params(sim[v], &p) == GR_OK);
      run_stable(sim[v], 4, 10);
    }
    size_t words = 0;
    long diff = state_words_differ(sim[0], sim[1], &words);
    gr_rain_runoff_ledger l0 = ledger(sim[0]);
    CHECK_MSG(diff == 0 && ledgers_same(sim[0], sim[1]) &&
                  gr_rain_runoff_specialised_for(sim[1]) == GR_RAIN_RUNOFF_INPUT_RAIN,
              "switched to %s: %ld words of %zu differ, kernels for %d", model_names[p.flow_model],
              diff, words, gr_rain_runoff_specialised_for(sim[1]));
    printf("switched to %s: %ld words of %zu differ; outflow %.4f m^3\n", model_names[p.flow_model],
           diff, words, l0.outflow_volume);
  }
  gr_rain_runoff_destroy(sim[0]);
  gr_rain_runoff_destroy(sim[1]);
  free(solid);
  paths_free(&in);
}
