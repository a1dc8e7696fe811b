/* Rain runoff tests of split domains (test_rain_runoff.c has main):
 * pieces along x and y, stepped and advanced, by threads with a halo
 * exchange and an allreduce, checkpoints of pieces, and both again with
 * the shallow-water model and with every kind of edge: every owned cell
 * bit for bit the whole grid's. */
#include "test_rain_runoff.h"

/* ------------------------------------------------------------- pieces */

/* Every entry of a ledger, for the bit-for-bit comparisons of split and
 * whole domains. */
static const struct {
  const char *name;
  size_t offset;
} ledger_entries[] = {
    {"time", offsetof(gr_rain_runoff_ledger, time)},
    {"initial_volume", offsetof(gr_rain_runoff_ledger, initial_volume)},
    {"rain_volume", offsetof(gr_rain_runoff_ledger, rain_volume)},
    {"infiltrated_volume", offsetof(gr_rain_runoff_ledger, infiltrated_volume)},
    {"outflow_volume", offsetof(gr_rain_runoff_ledger, outflow_volume)},
    {"inflow_volume", offsetof(gr_rain_runoff_ledger, inflow_volume)},
    {"stored_volume", offsetof(gr_rain_runoff_ledger, stored_volume)},
    {"balance_error", offsetof(gr_rain_runoff_ledger, balance_error)},
    {"max_depth", offsetof(gr_rain_runoff_ledger, max_depth)},
};

/* Checks that a piece's global ledger is the whole grid's, bit for bit in
 * every entry (the volumes too: the core sums them in fixed point, which no
 * split can change); says which entries differ and by how much. Returns the
 * number of entries that differ. */
static int ledger_same_bits(const gr_rain_runoff_ledger *piece, const gr_rain_runoff_ledger *whole,
                            const char *what, int k) {
  int differ = piece->steps != whole->steps;
  CHECK_MSG(piece->steps == whole->steps, "%s: piece %d: %lld steps, the whole grid %lld", what, k,
            piece->steps, whole->steps);
  for (size_t e = 0; e < sizeof(ledger_entries) / sizeof(ledger_entries[0]); ++e) {
    double a, b;
    memcpy(&a, (const char *)piece + ledger_entries[e].offset, sizeof(a));
    memcpy(&b, (const char *)whole + ledger_entries[e].offset, sizeof(b));
    int same = memcmp(&a, &b, sizeof(a)) == 0;
    CHECK_MSG(same,
              "%s: piece %d: the global ledger's %s is %.17g, the whole grid's %.17g (%.3g apart): "
              "not the same bits",
              what, k, ledger_entries[e].name, a, b, a - b);
    differ += !same;
  }
  return differ;
}

/* The flow model the pieces tests run: local inertial, and again shallow
 * water (the *_sw tests), whose ring is GR_RAIN_RUNOFF_GHOST_SW. */
static gr_flow_model piece_model = GR_FLOW_LOCAL_INERTIAL;
/* 1: the pieces tests with every kind of edge (the *_edges tests): a level
 * edge west (above the ground there), a transmissive one east, a wall south
 * and an outfall north, inflows (piece_inflows) and two no-data holes
 * across the splits, outfalls; 0: every edge an outfall. */
static int piece_edges = 0;
/* The shallow-water step's launch path in the pieces tests
 * (gr_rain_runoff_set_sw_fused): -1 the device's default, 0 the stages'
 * separate launches, 1 one launch a stage (sw_pieces_paths). */
int piece_sw_fused = -1;
/* The local inertial step's launches in the pieces tests (set_fused): -1
 * the device's default, 0 three launches, 1 one (the *_fused tests). */
int piece_fused = -1;

static gr_rain_runoff_params piece_params(void) {
  gr_rain_runoff_params p = params_with(0.0, 0.0, GR_BOUNDARY_OPEN);
  p.flow_model = piece_model;
  if (piece_edges) {
    p.boundary[GR_RAIN_RUNOFF_WEST] = GR_BOUNDARY_LEVEL;
    p.boundary_level[GR_RAIN_RUNOFF_WEST] = 0.7;
    p.boundary[GR_RAIN_RUNOFF_EAST] = GR_BOUNDARY_TRANSMISSIVE;
    p.boundary[GR_RAIN_RUNOFF_SOUTH] = GR_BOUNDARY_CLOSED;
    p.no_data = GR_BOUNDARY_OPEN; /* the no-data holes of make_domain drain */
  }
  return p;
}

static int piece_ghost(void) {
  return piece_model == GR_FLOW_SHALLOW_WATER ? GR_RAIN_RUNOFF_GHOST_SW : GR_RAIN_RUNOFF_GHOST;
}

/* The whole domain's inputs for the split tests: a bumpy, tilted terrain
 * with rain and infiltration maps and some water. */
typedef struct domain {
  gr_grid g;
  float *b, *r, *k, *d;
} domain;

static domain make_domain(int nx, int ny) {
  domain dm;
  gr_grid g = {nx, ny, 2.0, 1.5, 0.0, 0.0, 0, 0};
  dm.g = g;
  dm.b = alloc_field(&g, 1);
  dm.r = alloc_field(&g, 1);
  dm.k = alloc_field(&g, 1);
  dm.d = alloc_field(&g, 1);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      size_t c = (size_t)j * nx + i;
      double x = i * g.dx, y = j * g.dy;
      dm.b[c] =
          (float)(0.04 * x + 0.02 * y + 0.4 * sin(x / 7.0) * cos(y / 5.0) + 0.2 * hash01(i, j, 11));
      dm.r[c] = (float)(3e-5 * hash01(i, j, 12));
      dm.k[c] = hash01(i, j, 13) < 0.5 ? 0.0f : (float)(4e-6 * hash01(i, j, 14));
      dm.d[c] = (float)(0.05 * hash01(i, j, 15));
      /* With every kind of edge, no-data holes too, across the splits. */
      int hole_a = i >= nx / 2 - 2 && i < nx / 2 + 2 && j >= ny / 3 && j < ny / 3 + 3;
      int hole_b = i >= 3 && i < 6 && j >= ny / 2 - 2 && j < ny / 2 + 2;
      if (piece_edges && (hole_a || hole_b))
        dm.b[c] = NAN;
    }
  return dm;
}

static void free_domain(domain *dm) {
  free(dm->b);
  free(dm->r);
  free(dm->k);
  free(dm->d);
}

/* One piece of a domain: its grid, its rings (the core's rule: a ring of
 * GR_RAIN_RUNOFF_GHOST toward every neighbour) and its simulation. */
typedef struct piece {
  gr_grid g;
  int ring[4], nxl, nyl;
  gr_rain_runoff *s;
} piece;

static void team_ledger(piece *pc, gr_rain_runoff_ledger *out);

static float *cut(const float *global, int gnx, int x0, int y0, int w, int h) {
  float *out = malloc((size_t)w * (size_t)h * sizeof(float));
  for (int j = 0; j < h; ++j)
    memcpy(out + (size_t)j * w, global + (size_t)(y0 + j) * gnx + x0, (size_t)w * sizeof(float));
  return out;
}

/* With piece_edges, the inflows too: a hydrograph along the south edge (a
 * wall there) and two point inflows, one next to the split in x (in the
 * west half's ring) and one in the north-west. */
static void piece_inflows(gr_rain_runoff *s) {
  if (!piece_edges || !s)
    return;
  const double t[3] = {0.0, 20.0, 60.0}, q[3] = {0.0, 0.4, 0.1};
  const int ij[4] = {19, 5, 4, 19};
  const double pq[2] = {0.05, 0.02};
  CHECK(gr_rain_runoff_set_edge_inflow(s, GR_RAIN_RUNOFF_SOUTH, t, q, 3) == GR_OK);
  CHECK(gr_rain_runoff_set_point_inflows(s, ij, pq, 2) == GR_OK);
}

static int make_piece(piece *p, const domain *dm, const gr_rain_runoff_params *prm, int i0, int j0,
                      int nx, int ny) {
  const int G = piece_ghost();
  memset(p, 0, sizeof(*p));
  p->g = dm->g;
  p->g.nx = nx;
  p->g.ny = ny;
  p->g.i0 = i0;
  p->g.j0 = j0;
  p->g.global_nx = dm->g.nx;
  p->g.global_ny = dm->g.ny;
  p->g.ghost = G;
  p->ring[0] = i0 > 0 ? G : 0;
  p->ring[1] = i0 + nx < dm->g.nx ? G : 0;
  p->ring[2] = j0 > 0 ? G : 0;
  p->ring[3] = j0 + ny < dm->g.ny ? G : 0;
  p->nxl = nx + p->ring[0] + p->ring[1];
  p->nyl = ny + p->ring[2] + p->ring[3];
  gr_status st = gr_rain_runoff_create(ctx, &p->g, prm, &p->s);
  CHECK_MSG(st == GR_OK, "piece: %s", gr_last_error(ctx));
  if (st == GR_OK && piece_fused >= 0)
    gr_rain_runoff_set_fused(p->s, piece_fused);
  const float *fields[] = {dm->b, dm->r, dm->k, dm->d};
  const gr_field names[] = {GR_FIELD_ELEVATION, GR_FIELD_RAIN_RATE, GR_FIELD_PERMEABILITY,
                            GR_FIELD_WATER_DEPTH};
  for (int f = 0; st == GR_OK && f < 4; ++f) {
    float *local = cut(fields[f], dm->g.nx, i0 - p->ring[0], j0 - p->ring[2], p->nxl, p->nyl);
    st = gr_rain_runoff_set_field(p->s, names[f], local);
    CHECK_MSG(st == GR_OK, "piece field: %s", gr_rain_runoff_last_error(p->s));
    free(local);
  }
  if (st == GR_OK)
    piece_inflows(p->s);
  if (st == GR_OK && piece_sw_fused >= 0)
    gr_rain_runoff_set_sw_fused(p->s, piece_sw_fused);
  return st == GR_OK;
}

static gr_rain_runoff *make_whole(const domain *dm, const gr_rain_runoff_params *prm) {
  gr_rain_runoff *s = make_sim(&dm->g, prm, dm->b, dm->d);
  if (s && piece_fused >= 0)
    gr_rain_runoff_set_fused(s, piece_fused);
  piece_inflows(s);
  if (s) {
    CHECK(gr_rain_runoff_set_field(s, GR_FIELD_RAIN_RATE, dm->r) == GR_OK);
    CHECK(gr_rain_runoff_set_field(s, GR_FIELD_PERMEABILITY, dm->k) == GR_OK);
    if (piece_sw_fused >= 0)
      gr_rain_runoff_set_sw_fused(s, piece_sw_fused);
  }
  return s;
}

/* Passes p's strip on side `side` to q's ring on the opposite side. */
static void pass_halo(piece *p, piece *q, int side) {
  size_t bytes = 0, other = 0;
  CHECK(gr_rain_runoff_halo_size(p->s, side, &bytes) == GR_OK);
  CHECK(gr_rain_runoff_halo_size(q->s, side ^ 1, &other) == GR_OK);
  CHECK(bytes > 0 && bytes == other);
  void *buf = malloc(bytes);
  CHECK(gr_rain_runoff_halo_get(p->s, side, buf, bytes) == GR_OK);
  CHECK(gr_rain_runoff_halo_set(q->s, side ^ 1, buf, bytes) == GR_OK);
  free(buf);
}

/* Counts the owned cells of piece p whose field f differs in any bit from
 * the whole grid's. */
static long piece_diff(piece *p, gr_rain_runoff *whole, const domain *dm, gr_field f) {
  int comps = gr_field_components(f);
  float *w = get(whole, &dm->g, f), *v = get(p->s, &p->g, f);
  long diff = 0;
  for (int j = 0; j < p->g.ny; ++j)
    for (int i = 0; i < p->g.nx; ++i)
      for (int q = 0; q < comps; ++q)
        diff += memcmp(&v[((size_t)j * p->g.nx + i) * comps + q],
                       &w[((size_t)(p->g.j0 + j) * dm->g.nx + p->g.i0 + i) * comps + q],
                       sizeof(float)) != 0;
  free(w);
  free(v);
  return diff;
}

/* The same for flood map m. */
static long piece_map_diff(piece *p, gr_rain_runoff *whole, const domain *dm,
                           gr_rain_runoff_map m) {
  float *w = get_map(whole, &dm->g, m), *v = get_map(p->s, &p->g, m);
  long diff = 0;
  for (int j = 0; j < p->g.ny; ++j)
    for (int i = 0; i < p->g.nx; ++i)
      diff += memcmp(&v[(size_t)j * p->g.nx + i],
                     &w[(size_t)(p->g.j0 + j) * dm->g.nx + p->g.i0 + i], sizeof(float)) != 0;
  free(w);
  free(v);
  return diff;
}

static void check_pieces(piece *pc, int n, gr_rain_runoff *whole, const domain *dm,
                         const char *what) {
  const gr_field fields[] = {GR_FIELD_WATER_DEPTH, GR_FIELD_VELOCITY, GR_FIELD_DISCHARGE,
                             GR_FIELD_INFILTRATED, GR_FIELD_WATER_SURFACE};
  long total = 0;
  for (int k = 0; k < n; ++k)
    for (size_t f = 0; f < sizeof(fields) / sizeof(fields[0]); ++f) {
      long d = piece_diff(&pc[k], whole, dm, fields[f]);
      CHECK_MSG(d == 0, "%s: piece %d: %ld cells of %s differ from the whole grid", what, k, d,
                gr_field_name(fields[f]));
      total += d;
    }
  /* The flood maps too: each piece folds in its own cells' steps. */
  for (int k = 0; k < n; ++k)
    for (int m = 0; m < GR_RAIN_RUNOFF_MAP_COUNT; ++m) {
      long d = piece_map_diff(&pc[k], whole, dm, (gr_rain_runoff_map)m);
      CHECK_MSG(d == 0, "%s: piece %d: %ld cells of the map %s differ from the whole grid", what, k,
                d, gr_rain_runoff_map_name((gr_rain_runoff_map)m));
      total += d;
    }
  printf("%s: %ld cells (fields and flood maps) differ from the whole grid in any bit\n", what,
         total);
}

/* Two halves split in x, stepped by one driver that exchanges the halo
 * after every step and takes the smaller of the halves' stable steps (the
 * stable step falls with the depth, so that is the whole grid's): every
 * owned cell of every field is the whole grid's bit for bit. */
void test_pieces_x(void) {
  domain dm = make_domain(37, 23);
  gr_rain_runoff_params prm = piece_params();
  gr_rain_runoff *whole = make_whole(&dm, &prm);
  piece pc[2];
  int ok =
      make_piece(&pc[0], &dm, &prm, 0, 0, 18, 23) && make_piece(&pc[1], &dm, &prm, 18, 0, 19, 23);
  CHECK(pc[0].nxl == 18 + piece_ghost() && pc[1].nxl == 19 + piece_ghost() && pc[0].nyl == 23);
  int steps = 0, same_dt = 1;
  for (; ok && whole && steps < 150; ++steps) {
    double dw = 0.0, d0 = 0.0, d1 = 0.0;
    CHECK(gr_rain_runoff_stable_dt(whole, &dw) == GR_OK);
    CHECK(gr_rain_runoff_stable_dt(pc[0].s, &d0) == GR_OK);
    CHECK(gr_rain_runoff_stable_dt(pc[1].s, &d1) == GR_OK);
    double dt = d0 < d1 ? d0 : d1;
    same_dt &= dt == dw;
    CHECK(gr_rain_runoff_step(whole, dw, 1) == GR_OK);
    CHECK(gr_rain_runoff_step(pc[0].s, dt, 1) == GR_OK);
    CHECK(gr_rain_runoff_step(pc[1].s, dt, 1) == GR_OK);
    pass_halo(&pc[0], &pc[1], GR_RAIN_RUNOFF_EAST);
    pass_halo(&pc[1], &pc[0], GR_RAIN_RUNOFF_WEST);
  }
  CHECK(same_dt);
  if (ok && whole) {
    check_pieces(pc, 2, whole, &dm, "split in x, 150 steps");
    /* The halves' own ledgers add up to the whole's (summed in another order). */
    gr_rain_runoff_ledger lw = ledger(whole), l0 = ledger(pc[0].s), l1 = ledger(pc[1].s);
    double in = lw.initial_volume + lw.rain_volume + lw.inflow_volume;
    CHECK_NEAR(l0.stored_volume + l1.stored_volume, lw.stored_volume, 1e-9 * in);
    CHECK_NEAR(l0.outflow_volume + l1.outflow_volume, lw.outflow_volume, 1e-9 * in);
    CHECK_NEAR(l0.inflow_volume + l1.inflow_volume, lw.inflow_volume, 1e-9 * in);
    CHECK(piece_edges ? lw.inflow_volume > 0.0 : lw.inflow_volume == 0.0);
    CHECK_NEAR(l0.infiltrated_volume + l1.infiltrated_volume, lw.infiltrated_volume, 1e-9 * in);
    CHECK_NEAR(l0.rain_volume + l1.rain_volume, lw.rain_volume, 1e-9 * in);
    CHECK_NEAR(l0.initial_volume + l1.initial_volume, lw.initial_volume, 1e-9 * in);
    CHECK(lw.outflow_volume > 0.0 && l0.outflow_volume > 0.0 && l1.outflow_volume > 0.0);
    /* Reduced over both (the allreduce of gr_rain_runoff_ledger_get): the
     * whole grid's ledger, bit for bit. */
    gr_rain_runoff_ledger lt[2];
    team_ledger(pc, lt);
    int differ = ledger_same_bits(&lt[0], &lw, "split in x", 0) +
                 ledger_same_bits(&lt[1], &lw, "split in x", 1);
    printf("split in x: %d ledger entries differ from the whole grid's in any bit (balance %.3g "
           "of the water in)\n",
           differ, fabs(lw.balance_error) / in);
    /* A piece with neighbours steps one step at a time and does not advance. */
    CHECK(gr_rain_runoff_step(pc[0].s, 0.01, 2) == GR_ERR_INVALID_ARGUMENT);
    CHECK(has(gr_rain_runoff_last_error(pc[0].s), "halo"));
    CHECK(gr_rain_runoff_advance(pc[0].s, 1.0, NULL) == GR_ERR_INVALID_ARGUMENT);
    size_t bytes = 0;
    CHECK(gr_rain_runoff_halo_size(pc[0].s, GR_RAIN_RUNOFF_WEST, &bytes) == GR_OK && bytes == 0);
    float strip[4];
    CHECK(gr_rain_runoff_halo_get(pc[0].s, GR_RAIN_RUNOFF_WEST, strip, sizeof(strip)) ==
          GR_ERR_INVALID_ARGUMENT);
    CHECK(gr_rain_runoff_halo_get(pc[0].s, GR_RAIN_RUNOFF_EAST, strip, sizeof(strip)) ==
          GR_ERR_INVALID_ARGUMENT);
    CHECK(has(gr_rain_runoff_last_error(pc[0].s), "gr_rain_runoff_halo_size"));
  }
  /* Pieces the core refuses: the wrong ring, beyond the domain, too narrow. */
  gr_grid bad = pc[0].g;
  gr_rain_runoff *s = NULL;
  bad.ghost = 2;
  CHECK(gr_rain_runoff_create(ctx, &bad, &prm, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  CHECK(has(gr_last_error(ctx), "ghost"));
  bad = pc[1].g;
  bad.nx = 20;
  CHECK(gr_rain_runoff_create(ctx, &bad, &prm, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  CHECK(has(gr_last_error(ctx), "beyond the domain"));
  bad = pc[1].g;
  bad.i0 = 35;
  bad.nx = 2;
  CHECK(gr_rain_runoff_create(ctx, &bad, &prm, &s) == GR_ERR_INVALID_ARGUMENT && !s);
  for (int k = 0; k < 2; ++k)
    gr_rain_runoff_destroy(pc[k].s);
  gr_rain_runoff_destroy(whole);
  free_domain(&dm);
}

/* Two threads, one piece each (split in y), with a barrier-based allreduce
 * and a mailbox for the halo: the allreduce gives both the whole domain's
 * stable step and ledger. */
typedef struct member {
  gr_test_team *t;
  int rank, steps;
  piece *p;
  gr_status st;
  gr_rain_runoff_ledger l;
} member;

static gr_status team_halo(void *s, int side, void *host, size_t bytes, int set) {
  return set ? gr_rain_runoff_halo_set(s, side, host, bytes)
             : gr_rain_runoff_halo_get(s, side, host, bytes);
}

static gr_status team_allreduce(void *user, double *values, int n, gr_reduce_op op) {
  member *m = user;
  return gr_test_team_allreduce(m->t, m->rank, values, n, op);
}

static void *member_run(void *arg) {
  member *m = arg;
  gr_status st = GR_OK;
  for (int k = 0; k < m->steps; ++k) {
    double dt = 0.0;
    gr_status s1 = gr_rain_runoff_stable_dt(m->p->s, &dt); /* both reach the allreduce */
    if (s1 == GR_OK)
      s1 = gr_rain_runoff_step(m->p->s, dt, 1);
    if (s1 == GR_OK)
      s1 = gr_test_team_exchange(m->t, m->rank, m->p->s, team_halo);
    else
      gr_test_team_pass(m->t);
    if (st == GR_OK)
      st = s1;
  }
  gr_status s2 = gr_rain_runoff_ledger_get(m->p->s, &m->l);
  m->st = st == GR_OK ? s2 : st;
  return NULL;
}

static void *member_ledger(void *arg) {
  member *m = arg;
  m->st = gr_rain_runoff_ledger_get(m->p->s, &m->l);
  return NULL;
}

/* The global ledger of two pieces: gr_rain_runoff_ledger_get (collective)
 * on two threads with the team's allreduce, which is removed again. */
static void team_ledger(piece *pc, gr_rain_runoff_ledger *out) {
  gr_test_team t;
  gr_test_team_init(&t, 2, 32);
  member m[2];
  for (int k = 0; k < 2; ++k) {
    m[k] = (member){&t, k, 0, &pc[k], GR_OK, {0}};
    gr_rain_runoff_set_allreduce(pc[k].s, team_allreduce, &m[k]);
  }
  gr_test_team_run(2, member_ledger, m, sizeof(m[0]));
  for (int k = 0; k < 2; ++k) {
    CHECK_MSG(m[k].st == GR_OK, "ledger of piece %d: %s", k, gr_rain_runoff_last_error(pc[k].s));
    gr_rain_runoff_set_allreduce(pc[k].s, NULL, NULL);
    out[k] = m[k].l;
  }
  gr_test_team_destroy(&t);
}

void test_pieces_y(void) {
  domain dm = make_domain(29, 41);
  gr_rain_runoff_params prm = piece_params();
  gr_rain_runoff *whole = make_whole(&dm, &prm);
  piece pc[2];
  int ok =
      make_piece(&pc[0], &dm, &prm, 0, 0, 29, 20) && make_piece(&pc[1], &dm, &prm, 0, 20, 29, 21);
  const int steps = 150;
  if (ok && whole) {
    gr_test_team t;
    gr_test_team_init(&t, 2, 32);
    member m[2];
    for (int k = 0; k < 2; ++k) {
      int side = k == 0 ? GR_RAIN_RUNOFF_NORTH : GR_RAIN_RUNOFF_SOUTH;
      size_t bytes = 0;
      CHECK(gr_rain_runoff_halo_size(pc[k].s, side, &bytes) == GR_OK);
      gr_test_team_mail(&t, k, side, bytes);
      m[k] = (member){&t, k, steps, &pc[k], GR_OK, {0}};
      gr_rain_runoff_set_allreduce(pc[k].s, team_allreduce, &m[k]);
    }
    gr_test_team_run(2, member_run, m, sizeof(m[0]));
    for (int k = 0; k < 2; ++k) {
      CHECK_MSG(m[k].st == GR_OK, "member %d: %s", k, gr_rain_runoff_last_error(pc[k].s));
      gr_rain_runoff_set_allreduce(pc[k].s, NULL, NULL);
    }
    gr_test_team_destroy(&t);
    for (int k = 0; k < steps; ++k) {
      double dt = 0.0;
      CHECK(gr_rain_runoff_stable_dt(whole, &dt) == GR_OK);
      CHECK(gr_rain_runoff_step(whole, dt, 1) == GR_OK);
    }
    check_pieces(pc, 2, whole, &dm, "split in y on two threads, 150 steps");
    gr_rain_runoff_ledger lw = ledger(whole);
    double in = lw.initial_volume + lw.rain_volume + lw.inflow_volume;
    int differ = 0;
    for (int k = 0; k < 2; ++k) {
      differ += ledger_same_bits(&m[k].l, &lw, "split in y on two threads", k);
      CHECK(fabs(m[k].l.balance_error) <= 1e-7 * in);
    }
    printf("split in y on two threads: %d ledger entries differ from the whole grid's in any bit "
           "(balance %.3g of the water in)\n",
           differ, fabs(lw.balance_error) / in);
  }
  for (int k = 0; k < 2; ++k)
    gr_rain_runoff_destroy(pc[k].s);
  gr_rain_runoff_destroy(whole);
  free_domain(&dm);
}

/* Pieces that advance on their own: each of two threads advances its piece
 * with the team's allreduce and a halo exchange through the mailbox, which
 * the core calls after every step. */
typedef struct advancer {
  member m; /* the allreduce's user: team and rank */
  int mode; /* 0: advance by duration; 1: stable_dt, then nsteps steps */
  double duration;
  int nsteps, steps, exchanges;
  progress_log *log; /* this piece's progress callback, or NULL */
  gr_status st;
  gr_rain_runoff_ledger l;
} advancer;

static gr_status team_exchange(void *user) {
  advancer *a = user;
  ++a->exchanges;
  return gr_test_team_exchange(a->m.t, a->m.rank, a->m.p->s, team_halo);
}

static void *advancer_run(void *arg) {
  advancer *a = arg;
  gr_rain_runoff *s = a->m.p->s;
  if (a->mode == 0) {
    a->st = gr_rain_runoff_advance(s, a->duration, &a->steps);
  } else {
    double dt = 0.0;
    a->st = gr_rain_runoff_stable_dt(s, &dt);
    if (a->st == GR_OK)
      a->st = gr_rain_runoff_step(s, dt, a->nsteps);
    a->steps = a->st == GR_OK ? a->nsteps : 0;
  }
  /* The ledger is collective too: both pieces reach it whatever happened. */
  gr_status s2 = gr_rain_runoff_ledger_get(s, &a->l);
  if (a->st == GR_OK)
    a->st = s2;
  return NULL;
}

/* Runs both pieces on two threads (mode, duration, nsteps as in advancer)
 * with the team's callbacks, which are removed again afterwards; logs[k]
 * becomes piece k's progress callback. Returns the wall time. */
static double run_team(piece pc[2], int side0, int mode, double duration, int nsteps,
                       progress_log *logs[2], advancer a[2]) {
  gr_test_team t;
  gr_test_team_init(&t, 2, 32);
  for (int k = 0; k < 2; ++k) {
    int side = k == 0 ? side0 : side0 ^ 1;
    size_t bytes = 0;
    CHECK(gr_rain_runoff_halo_size(pc[k].s, side, &bytes) == GR_OK);
    gr_test_team_mail(&t, k, side, bytes);
    memset(&a[k], 0, sizeof(a[k]));
    a[k].m = (member){&t, k, 0, &pc[k], GR_OK, {0}};
    a[k].mode = mode;
    a[k].duration = duration;
    a[k].nsteps = nsteps;
    a[k].log = logs ? logs[k] : NULL;
    gr_rain_runoff_set_allreduce(pc[k].s, team_allreduce, &a[k].m);
    gr_rain_runoff_set_halo_exchange(pc[k].s, team_exchange, &a[k]);
    if (a[k].log)
      gr_rain_runoff_set_progress(pc[k].s, on_progress, a[k].log);
  }
  double t0 = wall_now();
  gr_test_team_run(2, advancer_run, a, sizeof(a[0]));
  double wall = wall_now() - t0;
  for (int k = 0; k < 2; ++k) {
    gr_rain_runoff_set_allreduce(pc[k].s, NULL, NULL);
    gr_rain_runoff_set_halo_exchange(pc[k].s, NULL, NULL);
    gr_rain_runoff_set_progress(pc[k].s, NULL, NULL);
  }
  gr_test_team_destroy(&t);
  return wall;
}

/* The pieces' advance against the whole grid's over the same duration: the
 * same steps, the same time, every owned cell of every field the same bits;
 * then 7 steps in one gr_rain_runoff_step call each, the same again. */
static void check_advance_split(domain *dm, piece pc[2], int side0, const char *what) {
  gr_rain_runoff_params prm = piece_params();
  gr_rain_runoff *whole = make_whole(dm, &prm);
  if (!whole)
    return;
  const double duration = 90.0;
  advancer a[2];
  run_team(pc, side0, 0, duration, 0, NULL, a);
  int sw = 0;
  CHECK(gr_rain_runoff_advance(whole, duration, &sw) == GR_OK);
  gr_rain_runoff_ledger lw = ledger(whole);
  double in = lw.initial_volume + lw.rain_volume + lw.inflow_volume;
  for (int k = 0; k < 2; ++k) {
    CHECK_MSG(a[k].st == GR_OK, "%s: piece %d: %s", what, k, gr_rain_runoff_last_error(pc[k].s));
    CHECK_MSG(a[k].steps == sw && a[k].exchanges == sw,
              "%s: piece %d: %d steps, %d exchanges; "
              "the whole grid %d steps",
              what, k, a[k].steps, a[k].exchanges, sw);
    /* The same time as the whole grid, to the bit; the duration to rounding
     * (the last stretch is equal steps of left / n). */
    CHECK_MSG(a[k].l.time == lw.time && fabs(a[k].l.time - duration) <= 1e-9 * duration &&
                  a[k].l.steps == lw.steps,
              "%s: piece %d: time %.17g, whole %.17g, steps %lld vs %lld", what, k, a[k].l.time,
              lw.time, a[k].l.steps, lw.steps);
    ledger_same_bits(&a[k].l, &lw, what, k);
    CHECK(fabs(a[k].l.balance_error) <= 1e-7 * in);
  }
  CHECK(lw.outflow_volume > 0.0 && sw > 20);
  printf("%s: advance by %.0f s, %d steps on both pieces and the whole grid\n", what, duration, sw);
  check_pieces(pc, 2, whole, dm, what);
  /* Several steps per call on a piece. */
  double dt = 0.0;
  run_team(pc, side0, 1, 0.0, 7, NULL, a);
  CHECK(gr_rain_runoff_stable_dt(whole, &dt) == GR_OK);
  CHECK(gr_rain_runoff_step(whole, dt, 7) == GR_OK);
  for (int k = 0; k < 2; ++k)
    CHECK_MSG(a[k].st == GR_OK && a[k].exchanges == 7, "%s: piece %d: %s, %d exchanges", what, k,
              gr_rain_runoff_last_error(pc[k].s), a[k].exchanges);
  check_pieces(pc, 2, whole, dm, "... then 7 steps in one call");
  lw = ledger(whole);
  for (int k = 0; k < 2; ++k)
    ledger_same_bits(&a[k].l, &lw, "... then 7 steps in one call", k);
  gr_rain_runoff_destroy(whole);
}

void test_advance_pieces_x(void) {
  domain dm = make_domain(37, 23);
  gr_rain_runoff_params prm = piece_params();
  piece pc[2] = {{0}, {0}};
  if (make_piece(&pc[0], &dm, &prm, 0, 0, 18, 23) && make_piece(&pc[1], &dm, &prm, 18, 0, 19, 23))
    check_advance_split(&dm, pc, GR_RAIN_RUNOFF_EAST, "advance split in x on two threads");
  /* Without both callbacks a piece with a ring still refuses to advance,
   * and without an exchange it takes one step per call. */
  if (pc[0].s) {
    gr_rain_runoff_set_halo_exchange(pc[0].s, team_exchange, NULL);
    CHECK(gr_rain_runoff_advance(pc[0].s, 1.0, NULL) == GR_ERR_INVALID_ARGUMENT);
    CHECK_MSG(has(gr_rain_runoff_last_error(pc[0].s), "gr_rain_runoff_set_allreduce"), "'%s'",
              gr_rain_runoff_last_error(pc[0].s));
    gr_rain_runoff_set_halo_exchange(pc[0].s, NULL, NULL);
    CHECK(gr_rain_runoff_step(pc[0].s, 0.01, 2) == GR_ERR_INVALID_ARGUMENT);
    CHECK(has(gr_rain_runoff_last_error(pc[0].s), "gr_rain_runoff_set_halo_exchange"));
  }
  for (int k = 0; k < 2; ++k)
    gr_rain_runoff_destroy(pc[k].s);
  free_domain(&dm);
}

void test_advance_pieces_y(void) {
  domain dm = make_domain(29, 41);
  gr_rain_runoff_params prm = piece_params();
  piece pc[2] = {{0}, {0}};
  if (make_piece(&pc[0], &dm, &prm, 0, 0, 29, 20) && make_piece(&pc[1], &dm, &prm, 0, 20, 29, 21))
    check_advance_split(&dm, pc, GR_RAIN_RUNOFF_NORTH, "advance split in y on two threads");
  for (int k = 0; k < 2; ++k)
    gr_rain_runoff_destroy(pc[k].s);
  free_domain(&dm);
}

/* A failing exchange stops the step with its status and a sentence. */
static gr_status failing_exchange(void *user) {
  (void)user;
  return GR_ERR_IO;
}

/* An abort asked for by one piece's progress callback (the other piece has
 * none) stops both after the same step, within half a second; both go on
 * from there together. */
void test_advance_pieces_abort(void) {
  domain dm = make_domain(36, 23);
  gr_rain_runoff_params prm = piece_params();
  prm.max_dt = 0.002; /* a long advance: 5e6 steps unless stopped */
  piece pc[2] = {{0}, {0}};
  if (make_piece(&pc[0], &dm, &prm, 0, 0, 18, 23) && make_piece(&pc[1], &dm, &prm, 18, 0, 18, 23)) {
    progress_log stop = {0, 1, 2, 0.0, 0.0};
    progress_log *logs[2] = {&stop, NULL};
    advancer a[2];
    const double duration = 1e4;
    run_team(pc, GR_RAIN_RUNOFF_EAST, 0, duration, 0, logs, a);
    double honoured = wall_now() - stop.stopped_at_wall;
    printf("abort on piece 0: both stopped after %d and %d steps at %.4f and %.4f s, honoured in "
           "%.3f s\n",
           a[0].steps, a[1].steps, a[0].l.time, a[1].l.time, honoured);
    for (int k = 0; k < 2; ++k) {
      CHECK_MSG(a[k].st == GR_ERR_ABORTED, "piece %d: %s", k, gr_status_string(a[k].st));
      CHECK_MSG(has(gr_rain_runoff_last_error(pc[k].s), "progress callback"), "'%s'",
                gr_rain_runoff_last_error(pc[k].s));
    }
    CHECK(has(gr_rain_runoff_last_error(pc[1].s), "another piece"));
    CHECK(stop.calls == 2 && honoured < 0.5);
    CHECK(a[0].steps == a[1].steps && a[0].steps > 0 && a[0].exchanges == a[0].steps);
    CHECK(a[0].l.time == a[1].l.time && a[0].l.steps == a[1].l.steps);
    CHECK(a[0].l.time > 0.0 && a[0].l.time < duration);
    double in = a[0].l.initial_volume + a[0].l.rain_volume;
    CHECK(fabs(a[0].l.balance_error) <= 1e-7 * in);
    /* Both go on from the same step. */
    run_team(pc, GR_RAIN_RUNOFF_EAST, 0, 0.05, 0, NULL, a);
    CHECK(a[0].st == GR_OK && a[1].st == GR_OK && a[0].steps == a[1].steps);
    CHECK(a[0].l.time == a[1].l.time && a[0].l.steps == a[1].l.steps);
    /* A failing exchange. */
    gr_rain_runoff_set_halo_exchange(pc[0].s, failing_exchange, NULL);
    CHECK(gr_rain_runoff_step(pc[0].s, 0.001, 3) == GR_ERR_IO);
    CHECK_MSG(has(gr_rain_runoff_last_error(pc[0].s), "halo exchange"), "'%s'",
              gr_rain_runoff_last_error(pc[0].s));
    gr_rain_runoff_set_halo_exchange(pc[0].s, NULL, NULL);
  }
  for (int k = 0; k < 2; ++k)
    gr_rain_runoff_destroy(pc[k].s);
  free_domain(&dm);
}

/* A piece's checkpoint holds its ring: pieces advanced to t1 and saved,
 * then loaded into fresh pieces (no exchange), advance to t2 bit for bit
 * like the originals and the whole grid; a piece's checkpoint is refused
 * by the other piece of the same size. */
void test_piece_checkpoint(void) {
  domain dm = make_domain(36, 23);
  gr_rain_runoff_params prm = piece_params();
  gr_rain_runoff *whole = make_whole(&dm, &prm);
  piece pc[2] = {{0}, {0}}, fresh[2] = {{0}, {0}};
  int ok = whole && make_piece(&pc[0], &dm, &prm, 0, 0, 18, 23) &&
           make_piece(&pc[1], &dm, &prm, 18, 0, 18, 23) &&
           make_piece(&fresh[0], &dm, &prm, 0, 0, 18, 23) &&
           make_piece(&fresh[1], &dm, &prm, 18, 0, 18, 23);
  void *saved[2] = {NULL, NULL};
  size_t bytes[2] = {0, 0};
  if (ok) {
    advancer a[2];
    run_team(pc, GR_RAIN_RUNOFF_EAST, 0, 40.0, 0, NULL, a);
    for (int k = 0; k < 2; ++k) {
      CHECK(a[k].st == GR_OK);
      CHECK(gr_rain_runoff_state_size(pc[k].s, &bytes[k]) == GR_OK);
      saved[k] = malloc(bytes[k]);
      CHECK(gr_rain_runoff_state_save(pc[k].s, saved[k], bytes[k]) == GR_OK);
    }
    /* The ring is in it: 21 x 23 local cells (22 x 23 with the
     * shallow-water model's ring). */
    size_t nxl = 18 + (size_t)piece_ghost(), cells = nxl * 23, faces = (nxl + 1) * 23 + nxl * 24;
    CHECK_MSG(bytes[0] == bytes[1] && bytes[0] > (19 * cells + faces) * sizeof(float) &&
                  bytes[0] < (19 * cells + faces) * sizeof(float) + 128,
              "%zu bytes", bytes[0]);
    run_team(pc, GR_RAIN_RUNOFF_EAST, 0, 30.0, 0, NULL, a);
    CHECK(gr_rain_runoff_advance(whole, 40.0, NULL) == GR_OK);
    CHECK(gr_rain_runoff_advance(whole, 30.0, NULL) == GR_OK);
    check_pieces(pc, 2, whole, &dm, "pieces advanced 40 s + 30 s");
    for (int k = 0; k < 2; ++k)
      CHECK(gr_rain_runoff_state_load(fresh[k].s, saved[k], bytes[k]) == GR_OK);
    advancer b[2];
    run_team(fresh, GR_RAIN_RUNOFF_EAST, 0, 30.0, 0, NULL, b);
    for (int k = 0; k < 2; ++k)
      CHECK(b[k].st == GR_OK && b[k].steps == a[k].steps && b[k].l.time == a[k].l.time &&
            b[k].l.steps == a[k].l.steps && b[k].l.stored_volume == a[k].l.stored_volume);
    check_pieces(fresh, 2, whole, &dm, "fresh pieces loaded at 40 s, advanced 30 s");
    printf("piece checkpoint: %zu bytes per piece; %d steps after the load\n", bytes[0],
           b[0].steps);
    /* Piece 0's checkpoint into piece 1: the same size, another place. */
    CHECK(gr_rain_runoff_state_load(pc[1].s, saved[0], bytes[0]) == GR_ERR_INVALID_ARGUMENT);
    CHECK_MSG(has(gr_rain_runoff_last_error(pc[1].s), "own checkpoint") &&
                  has(gr_rain_runoff_last_error(pc[1].s), "(18, 0)"),
              "'%s'", gr_rain_runoff_last_error(pc[1].s));
  }
  for (int k = 0; k < 2; ++k) {
    free(saved[k]);
    gr_rain_runoff_destroy(pc[k].s);
    gr_rain_runoff_destroy(fresh[k].s);
  }
  gr_rain_runoff_destroy(whole);
  free_domain(&dm);
}

/* For valgrind: the piece entry points on two tiny pieces on two threads. */
static void test_memcheck_pieces(void) {
  domain dm = make_domain(8, 5);
  gr_rain_runoff_params prm = params_with(1e-5, 0.0, GR_BOUNDARY_OPEN);
  piece pc[2] = {{0}, {0}};
  if (make_piece(&pc[0], &dm, &prm, 0, 0, 4, 5) && make_piece(&pc[1], &dm, &prm, 4, 0, 4, 5)) {
    progress_log log = {0, 1, 0, 0.0, 0.0};
    progress_log *logs[2] = {&log, NULL};
    advancer a[2];
    run_team(pc, GR_RAIN_RUNOFF_EAST, 0, 2.0, 0, logs, a);
    CHECK(a[0].st == GR_OK && a[1].st == GR_OK && a[0].steps >= 2 && a[0].steps == a[1].steps);
    run_team(pc, GR_RAIN_RUNOFF_EAST, 1, 0.0, 2, NULL, a);
    CHECK(a[0].st == GR_OK && a[1].st == GR_OK && a[0].exchanges == 2);
    size_t bytes = 0;
    CHECK(gr_rain_runoff_state_size(pc[0].s, &bytes) == GR_OK);
    void *saved = malloc(bytes);
    CHECK(saved && gr_rain_runoff_state_save(pc[0].s, saved, bytes) == GR_OK);
    CHECK(saved && gr_rain_runoff_state_load(pc[0].s, saved, bytes) == GR_OK);
    free(saved);
    CHECK(gr_rain_runoff_advance(pc[0].s, 1.0, NULL) == GR_ERR_INVALID_ARGUMENT);
    gr_rain_runoff_set_halo_exchange(pc[0].s, failing_exchange, NULL);
    CHECK(gr_rain_runoff_step(pc[0].s, 0.01, 2) == GR_ERR_IO);
  }
  gr_rain_runoff_set_halo_exchange(NULL, failing_exchange, NULL);
  for (int k = 0; k < 2; ++k)
    gr_rain_runoff_destroy(pc[k].s);
  free_domain(&dm);
}

/* What valgrind runs: every entry point and error path once, on tiny grids. */
void test_memcheck_subset(void) {
  test_memcheck();
  test_errors();
  test_param_table();
  test_shared_context();
  test_memcheck_pieces();
}

/* The pieces tests again with the shallow-water model (ring
 * GR_RAIN_RUNOFF_GHOST_SW, one exchange per step): every owned cell of every
 * field bit for bit the whole grid's. */
static void run_with_sw_pieces(void (*test)(void)) {
  piece_model = GR_FLOW_SHALLOW_WATER;
  test();
  piece_model = GR_FLOW_LOCAL_INERTIAL;
}
void test_sw_pieces_x(void) {
  run_with_sw_pieces(test_pieces_x);
}
void test_sw_pieces_y(void) {
  run_with_sw_pieces(test_pieces_y);
}
void test_sw_advance_pieces_x(void) {
  run_with_sw_pieces(test_advance_pieces_x);
}
void test_sw_advance_pieces_y(void) {
  run_with_sw_pieces(test_advance_pieces_y);
}
void test_sw_piece_checkpoint(void) {
  run_with_sw_pieces(test_piece_checkpoint);
}

/* The pieces tests with every kind of edge (piece_edges): only the domain's
 * own edges are boundaries, and every owned cell is still the whole grid's
 * bit for bit, in both models. */
void run_with_edges(void (*test)(void)) {
  piece_edges = 1;
  test();
  piece_edges = 0;
}
void test_pieces_edges_x(void) {
  run_with_edges(test_pieces_x);
}
void test_pieces_edges_y(void) {
  run_with_edges(test_pieces_y);
}
void test_advance_pieces_edges_y(void) {
  run_with_edges(test_advance_pieces_y);
}
void test_sw_pieces_edges_x(void) {
  run_with_edges(test_sw_pieces_x);
}
void test_sw_pieces_edges_y(void) {
  run_with_edges(test_sw_pieces_y);
}
void test_sw_advance_pieces_edges_x(void) {
  run_with_edges(test_sw_advance_pieces_x);
}

/* Sets the rain-rate field r (the whole domain's) on the whole grid and on
 * each piece (its cut, ring included). */
static void set_rain_all(gr_rain_runoff *whole, piece *pc, int n, const domain *dm,
                         const float *r) {
  CHECK(gr_rain_runoff_set_field(whole, GR_FIELD_RAIN_RATE, r) == GR_OK);
  for (int k = 0; k < n; ++k) {
    float *local = cut(r, dm->g.nx, pc[k].g.i0 - pc[k].ring[0], pc[k].g.j0 - pc[k].ring[2],
                       pc[k].nxl, pc[k].nyl);
    CHECK(gr_rain_runoff_set_field(pc[k].s, GR_FIELD_RAIN_RATE, local) == GR_OK);
    free(local);
  }
}

/* Wet spells across a split in x: a wetting depth of 3 cm, which the split
 * domain's water crosses both ways, and its rain stopped from step 60 to
 * 120 of 200, so that cells dry and wet again (on either side of the split
 * and in the rings). The wet duration, kept by its spells' starts and ends
 * (the ring cells' too, whose depth the exchange sets), and every other
 * field and map of the pieces are the whole grid's bit for bit; the whole
 * grid's wet duration is the sum of the dt of the steps after which the
 * depth (read back after every step) was above the wetting depth, to a
 * float's rounding. Both flow models. */
void test_pieces_wet_spells(void) {
  for (int model = 0; model < 2; ++model) {
    piece_model = model ? GR_FLOW_SHALLOW_WATER : GR_FLOW_LOCAL_INERTIAL;
    domain dm = make_domain(37, 23);
    gr_rain_runoff_params prm = piece_params();
    prm.wetting_depth = 0.03;
    gr_rain_runoff *whole = make_whole(&dm, &prm);
    piece pc[2];
    int ok = whole && make_piece(&pc[0], &dm, &prm, 0, 0, 18, 23) &&
             make_piece(&pc[1], &dm, &prm, 18, 0, 19, 23);
    size_t n = cells_of(&dm.g);
    float *dry = alloc_field(&dm.g, 1);
    double *wet = calloc(n, sizeof(double));
    int *state = calloc(n, sizeof(int)), *ended = calloc(n, sizeof(int));
    double t = 0.0;
    for (int steps = 0; ok && steps < 200; ++steps) {
      if (steps == 60 || steps == 120)
        set_rain_all(whole, pc, 2, &dm, steps == 60 ? dry : dm.r);
      double dw = 0.0, d0 = 0.0, d1 = 0.0;
      CHECK(gr_rain_runoff_stable_dt(whole, &dw) == GR_OK);
      CHECK(gr_rain_runoff_stable_dt(pc[0].s, &d0) == GR_OK);
      CHECK(gr_rain_runoff_stable_dt(pc[1].s, &d1) == GR_OK);
      double dt = fmin(dw, fmin(d0, d1));
      CHECK(gr_rain_runoff_step(whole, dt, 1) == GR_OK);
      CHECK(gr_rain_runoff_step(pc[0].s, dt, 1) == GR_OK);
      CHECK(gr_rain_runoff_step(pc[1].s, dt, 1) == GR_OK);
      pass_halo(&pc[0], &pc[1], GR_RAIN_RUNOFF_EAST);
      pass_halo(&pc[1], &pc[0], GR_RAIN_RUNOFF_WEST);
      t += dt;
      float *h = get(whole, &dm.g, GR_FIELD_WATER_DEPTH);
      for (size_t c = 0; c < n; ++c) {
        int now = h[c] > (float)prm.wetting_depth;
        ended[c] += state[c] && !now;
        wet[c] += now ? dt : 0.0;
        state[c] = now;
      }
      free(h);
    }
    if (ok) {
      check_pieces(pc, 2, whole, &dm, model ? "wet spells, shallow water" : "wet spells");
      float *wd = get_map(whole, &dm.g, GR_RAIN_RUNOFF_WET_DURATION);
      double err = 0.0;
      int spells = 0, again = 0;
      for (size_t c = 0; c < n; ++c) {
        err = fmax(err, fabs(wd[c] - wet[c]) / fmax(wet[c], 1e-30));
        spells += ended[c] > 0;
        again += ended[c] > 0 && wet[c] > 0.0 && state[c];
      }
      printf("wet spells, FlowModel %d, %.2f s: %d cells dried after a spell (%d wet again at the "
             "end); wet_duration off the sum of dt by %.3g relative\n",
             (int)piece_model, t, spells, again, err);
      CHECK_MSG(err <= 1.2e-7, "wet_duration off by %g relative", err);
      CHECK(spells > 0 && again > 0);
      free(wd);
    }
    for (int k = 0; ok && k < 2; ++k)
      gr_rain_runoff_destroy(pc[k].s);
    gr_rain_runoff_destroy(whole);
    free(dry);
    free(wet);
    free(state);
    free(ended);
    free_domain(&dm);
  }
  piece_model = GR_FLOW_LOCAL_INERTIAL;
}
