/* Snow accumulation core, host side: pieces of a split domain and
 * checkpoints (snow_accumulation_internal.h): the piece contract, the
 * allreduce, the rows and sums across pieces, the halo exchange, and the
 * state's bytes saved and loaded. */
#include "snow_accumulation_internal.h"
#include "runtime_internal.h"

/* ------------------------------------------------------ pieces and rows */

int gr_snow_accumulation_ghost(const gr_snow_accumulation_params *p) {
  return p ? p->blur_radius + 2 : 0;
}

/* The piece contract (graupel.h, snow_accumulation.h): strips of whole rows,
 * a ring of grid->ghost rows toward each neighbour. */
gr_status gr_snac_piece_check(const gr_grid *g, const gr_snow_accumulation_params *p, int *ring_s,
                              int *ring_n, char *msg, size_t len) {
  char why[48];
  snprintf(why, sizeof(why), "for BlurRadius %d", p->blur_radius);
  return gr_grid_strip_check(g, "snow accumulation", " (its ledger adds whole rows)",
                             gr_snow_accumulation_ghost(p), why, ring_s, ring_n, msg, len);
}

int gr_snac_pieced(const gr_snow_accumulation *s) {
  return s->ring_s > 0 || s->ring_n > 0;
}

void gr_snow_accumulation_set_allreduce(gr_snow_accumulation *s, gr_allreduce_fn fn, void *user) {
  if (!s)
    return;
  s->allreduce = fn;
  s->allreduce_user = fn ? user : NULL;
}

void gr_snow_accumulation_set_halo_exchange(gr_snow_accumulation *s, gr_halo_exchange_fn fn,
                                            void *user) {
  if (!s)
    return;
  s->halo_exchange = fn;
  s->halo_user = fn ? user : NULL;
}

/* The caller's allreduce over n values, in calls of at most
 * GR_SNOW_ACCUMULATION_REDUCE_CHUNK. */
gr_status gr_snac_allreduce(gr_snow_accumulation *s, double *v, size_t n, gr_reduce_op op) {
  for (size_t at = 0; at < n; at += GR_SNOW_ACCUMULATION_REDUCE_CHUNK) {
    size_t m =
        n - at < GR_SNOW_ACCUMULATION_REDUCE_CHUNK ? n - at : GR_SNOW_ACCUMULATION_REDUCE_CHUNK;
    gr_status st = s->allreduce(s->allreduce_user, v + at, (int)m, op);
    if (st != GR_OK)
      return gr_set_error(s->ctx, st,
                          "The snow accumulation simulation's global reduction (the allreduce "
                          "callback) failed in step %lld with %s.",
                          s->steps + 1, gr_status_string(st));
  }
  return GR_OK;
}

/* Per own row: stored, fallen and shed snow (m, per unit area), 3 doubles
 * a row, each a row's sum in order along it (snow_accumulation_row_sums). */
gr_status gr_snac_rows(gr_snow_accumulation *s, double *out) {
  cl_int nx = s->grid.nx, first = s->ring_s, rows = s->own_ny;
  const gr_snac_arg args[] = {GR_SNAC_MEM("depth", s->arr[0]), GR_SNAC_MEM("depth_lo", s->arr[1]),
                              GR_SNAC_MEM("fall", s->arr[2]),  GR_SNAC_MEM("fall_lo", s->arr[3]),
                              GR_SNAC_MEM("shed", s->arr[4]),  GR_SNAC_MEM("shed_lo", s->arr[5]),
                              GR_SNAC_VAL("nx", nx),           GR_SNAC_VAL("first", first),
                              GR_SNAC_VAL("rows", rows),       GR_SNAC_MEM("out", s->rows_buf)};
  size_t n = (size_t)rows * 2 * GR_SNAC_SUMS;
  float *f = malloc(n * sizeof(float));
  if (!f)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  gr_status st = gr_snac_args(s, s->row_sums, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK)
    st = gr_enqueue_1d(s->ctx, s->row_sums, (size_t)rows);
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->rows_buf, 0, n * sizeof(float), f);
  for (size_t r = 0; st == GR_OK && r < (size_t)rows; ++r)
    for (int q = 0; q < GR_SNAC_SUMS; ++q)
      out[GR_SNAC_SUMS * r + (size_t)q] = (double)f[2 * GR_SNAC_SUMS * r + 2 * (size_t)q] +
                                          (double)f[2 * GR_SNAC_SUMS * r + 2 * (size_t)q + 1];
  free(f);
  return st;
}

/* The grid's ledger sums, m per unit area: stored, fallen, shed and
 * initial snow. Each piece puts its rows' sums at their rows of the domain
 * (-inf elsewhere), a GR_REDUCE_MAX makes every row's the same on every
 * piece (one value and -infs: exact in any order and with any reduction
 * scheme, unlike a sum), and the rows are added in the domain's order: the
 * same bits however the domain is split. A piece without an allreduce
 * adds its own rows. */
gr_status gr_snac_grid_sums(gr_snow_accumulation *s, double sums[4]) {
  int global = gr_snac_pieced(s) && s->allreduce;
  size_t R = global ? (size_t)s->gny : (size_t)s->own_ny;
  size_t base = global ? (size_t)(s->row0 + s->ring_s) : 0;
  double *rows = malloc(4 * R * sizeof(double));
  double *own = malloc((size_t)s->own_ny * GR_SNAC_SUMS * sizeof(double));
  gr_status st =
      rows && own ? GR_OK : gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK)
    st = gr_snac_rows(s, own);
  for (size_t k = 0; st == GR_OK && k < 4 * R; ++k)
    rows[k] = -HUGE_VAL;
  for (size_t r = 0; st == GR_OK && r < (size_t)s->own_ny; ++r) {
    for (int q = 0; q < GR_SNAC_SUMS; ++q)
      rows[4 * (base + r) + (size_t)q] = own[GR_SNAC_SUMS * r + (size_t)q];
    rows[4 * (base + r) + 3] = s->init_rows[r];
  }
  if (st == GR_OK && global)
    st = gr_snac_allreduce(s, rows, 4 * R, GR_REDUCE_MAX);
  for (int q = 0; q < 4; ++q)
    sums[q] = 0.0;
  for (size_t r = 0; st == GR_OK && r < R; ++r)
    for (int q = 0; q < 4; ++q)
      sums[q] += rows[4 * r + (size_t)q];
  free(rows), free(own);
  return st;
}

/* The strip on `side`: rows of the local arrays and how many. */
static int gr_snac_strip(const gr_snow_accumulation *s, int side, int set, size_t *row0) {
  int G = s->grid.ghost;
  if (side == GR_SNOW_ACCUMULATION_SOUTH && s->ring_s) {
    *row0 = set ? 0 : (size_t)s->ring_s;
    return G;
  }
  if (side == GR_SNOW_ACCUMULATION_NORTH && s->ring_n) {
    *row0 = set ? (size_t)(s->grid.ny - G) : (size_t)(s->grid.ny - s->ring_n - G);
    return G;
  }
  return 0;
}

gr_status gr_snow_accumulation_halo_size(const gr_snow_accumulation *s, int side, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_halo_size needs a simulation and a place for the "
                        "size.");
  size_t row0 = 0;
  *bytes = (size_t)gr_snac_strip(s, side, 0, &row0) * (size_t)s->grid.nx * sizeof(float);
  return GR_OK;
}

/* The strip's snow depth between the device and the host; waits. */
static gr_status gr_snac_halo_copy(gr_snow_accumulation *s, int side, void *host, size_t bytes,
                                   int set) {
  size_t row0 = 0;
  size_t rows = (size_t)gr_snac_strip(s, side, set, &row0);
  if (rows == 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow accumulation piece has no neighbour on side %d (2 south, 3 "
                        "north): only sides with a ring exchange a halo.",
                        side);
  size_t row = (size_t)s->grid.nx * sizeof(float), need = rows * row;
  if (!host || bytes != need)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The halo buffer has %zu bytes but side %d's strip has %zu: size it with "
                        "gr_snow_accumulation_halo_size.",
                        host ? bytes : 0, side, need);
  return set ? gr_buffer_write(s->ctx, s->arr[0], row0 * row, need, host)
             : gr_buffer_read(s->ctx, s->arr[0], row0 * row, need, host);
}

gr_status gr_snow_accumulation_halo_get(gr_snow_accumulation *s, int side, void *host,
                                        size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_halo_get needs a simulation.");
  gr_status st = gr_snac_halo_copy(s, side, host, bytes, 0);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_halo_set(gr_snow_accumulation *s, int side, const void *host,
                                        size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_halo_set needs a simulation.");
  /* The copy only reads host (set = 1). */
  gr_status st = gr_snac_halo_copy(s, side, (void *)host, bytes, 1);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

/* ---------------------------------------------------------- checkpoints */

typedef struct gr_snac_state_header {
  uint32_t magic, version;
  int32_t nx, ny, nobjects, nv, ns, j0, ntri, pad;
  int64_t steps;
  double time, initial_objects, retired_fall, retired_shed, dropped, snow_bound;
} gr_snac_state_header;

static size_t gr_snac_state_bytes(const gr_snow_accumulation *s) {
  return sizeof(gr_snac_state_header) +
         GR_SNAC_ARRAYS * (gr_snac_cells(s) + (size_t)s->ntri + (size_t)s->ns) * sizeof(float) +
         (size_t)s->own_ny * sizeof(double);
}

gr_status gr_snow_accumulation_state_size(const gr_snow_accumulation *s, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_state_size needs a simulation and a place for the "
                        "size.");
  *bytes = gr_snac_state_bytes(s);
  return GR_OK;
}

gr_status gr_snow_accumulation_state_save(gr_snow_accumulation *s, void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_state_save needs a simulation.");
  size_t need = gr_snac_state_bytes(s);
  if (!host || bytes != need)
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The buffer for the snow accumulation state has %zu bytes but this "
                        "simulation's state has %zu: size it with "
                        "gr_snow_accumulation_state_size.",
                        host ? bytes : 0, need));
  gr_snac_state_header hd;
  memset(&hd, 0, sizeof(hd));
  hd.magic = GR_SNAC_STATE_MAGIC;
  hd.version = GR_SNAC_STATE_VERSION;
  hd.nx = s->grid.nx, hd.ny = s->grid.ny, hd.nobjects = s->nobjects, hd.nv = s->nv;
  hd.ns = s->ns;
  hd.j0 = s->grid.j0;
  hd.ntri = s->ntri;
  hd.steps = s->steps;
  hd.time = s->time;
  hd.initial_objects = s->initial_objects;
  hd.retired_fall = s->retired_fall;
  hd.retired_shed = s->retired_shed;
  hd.dropped = s->dropped;
  hd.snow_bound = s->snow_bound;
  memcpy(host, &hd, sizeof(hd));
  char *at = (char *)host + sizeof(hd);
  size_t gb = gr_snac_cells(s) * sizeof(float), ob = (size_t)s->ntri * sizeof(float);
  size_t tb = (size_t)s->ns * sizeof(float);
  gr_status st = GR_OK;
  for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a, at += gb)
    st = gr_buffer_read(s->ctx, s->arr[a], 0, gb, at);
  /* Per array the faces, then the textures' samples. */
  for (int a = 0; st == GR_OK && ob + tb > 0 && a < GR_SNAC_ARRAYS; ++a, at += ob + tb) {
    if (ob > 0)
      st = gr_buffer_read(s->ctx, s->o_arr[a], 0, ob, at);
    if (st == GR_OK && tb > 0)
      st = gr_buffer_read(s->ctx, s->t_arr[a], 0, tb, at + ob);
  }
  /* The initial snow per own row, last. */
  if (st == GR_OK)
    memcpy(at, s->init_rows, (size_t)s->own_ny * sizeof(double));
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_state_load(gr_snow_accumulation *s, const void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_state_load needs a simulation.");
  size_t need = gr_snac_state_bytes(s);
  gr_snac_state_header hd;
  if (!host || bytes != need)
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow accumulation state has %zu bytes but this simulation (%d x %d "
                        "points, %d mesh points) needs %zu: load a state saved with the same grid "
                        "and objects.",
                        host ? bytes : 0, s->grid.nx, s->grid.ny, s->nv, need));
  memcpy(&hd, host, sizeof(hd));
  if (hd.magic != GR_SNAC_STATE_MAGIC || hd.version != GR_SNAC_STATE_VERSION ||
      hd.nx != s->grid.nx || hd.ny != s->grid.ny || hd.nobjects != s->nobjects || hd.nv != s->nv ||
      hd.ns != s->ns || hd.j0 != s->grid.j0 || hd.ntri != s->ntri)
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_FORMAT,
                        "The bytes are not a snow accumulation state of a %d x %d grid (a piece "
                        "from row %d) with %d objects (version %u); load one saved by "
                        "gr_snow_accumulation_state_save on the same piece with the same objects "
                        "set.",
                        s->grid.nx, s->grid.ny, s->grid.j0, s->nobjects, GR_SNAC_STATE_VERSION));
  const char *base = (const char *)host + sizeof(hd);
  size_t gcells = gr_snac_cells(s), gb = gcells * sizeof(float),
         ob = (size_t)s->ntri * sizeof(float);
  size_t tb = (size_t)s->ns * sizeof(float);
  /* Depths (the hi parts) must be finite and not negative. */
  for (int part = 0; part < 2; ++part) {
    const char *p = part ? base + GR_SNAC_ARRAYS * gb : base;
    size_t n = part ? (size_t)s->ntri + (size_t)s->ns : gcells;
    for (size_t c = 0; c < n; ++c) {
      float v;
      memcpy(&v, p + c * sizeof(float), sizeof(v));
      if (!isfinite(v) || v < -1e-6f)
        return GR_SNAC_KEEP_ERROR(
            s, gr_set_error(s->ctx, GR_ERR_FORMAT,
                            "The snow accumulation state holds a snow depth of %g: it is "
                            "damaged; load an intact one.",
                            (double)v));
    }
  }
  /* Every other number finite (the bound of the snow and the time not
   * negative): checked before anything is written, so that a refused state
   * leaves the simulation as it was. */
  if (!(hd.time >= 0.0 && hd.time < HUGE_VAL) || hd.steps < 0 || hd.steps > GR_STATE_MAX_STEPS ||
      !(hd.snow_bound >= 0.0 && hd.snow_bound < HUGE_VAL) || !isfinite(hd.initial_objects) ||
      !isfinite(hd.retired_fall) || !isfinite(hd.retired_shed) || !isfinite(hd.dropped))
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_FORMAT,
                        "The snow accumulation state's header is damaged (time %g s, %lld "
                        "steps): pass the bytes gr_snow_accumulation_state_save wrote.",
                        hd.time, (long long)hd.steps));
  const size_t off = sizeof(hd), faces = (size_t)s->ntri + (size_t)s->ns;
  const gr_state_part parts[] = {
      {"grid arrays", off, GR_SNAC_ARRAYS * gcells, 'f', -HUGE_VAL, HUGE_VAL},
      {"object arrays", off + GR_SNAC_ARRAYS * gb, GR_SNAC_ARRAYS * faces, 'f', -HUGE_VAL,
       HUGE_VAL},
      {"initial snow per row", off + GR_SNAC_ARRAYS * (gb + ob + tb), (size_t)s->own_ny, 'd',
       -HUGE_VAL, HUGE_VAL}};
  gr_status st = gr_state_check("snow accumulation", "snow_accumulation", host, parts, 3);
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  const char *at = base;
  for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a, at += gb)
    st = gr_buffer_write(s->ctx, s->arr[a], 0, gb, at);
  for (int a = 0; st == GR_OK && ob + tb > 0 && a < GR_SNAC_ARRAYS; ++a, at += ob + tb) {
    if (ob > 0)
      st = gr_buffer_write(s->ctx, s->o_arr[a], 0, ob, at);
    if (st == GR_OK && tb > 0)
      st = gr_buffer_write(s->ctx, s->t_arr[a], 0, tb, at + ob);
  }
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  memcpy(s->init_rows, at, (size_t)s->own_ny * sizeof(double));
  s->steps = hd.steps;
  s->time = hd.time;
  s->initial_objects = hd.initial_objects;
  s->retired_fall = hd.retired_fall;
  s->retired_shed = hd.retired_shed;
  s->dropped = hd.dropped;
  s->snow_bound = hd.snow_bound;
  s->aborted = 0;
  return GR_OK;
}
