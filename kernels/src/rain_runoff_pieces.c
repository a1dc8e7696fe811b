/* Rain runoff core, host side: pieces of a split domain and checkpoints
 * (rain_runoff_internal.h): the piece contract, the allreduce and the halo
 * exchange, and the state's bytes saved and loaded. */
#include "rain_runoff_internal.h"
#include "runtime_internal.h"

/* ------------------------------------------------------ pieces and halos */

/* The piece contract (graupel.h, rain_runoff.h): which sides have a
 * neighbour, and so a ring of GR_RAIN_RUNOFF_GHOST cells. */
gr_status gr_rain_runoff_piece(const gr_grid *g, gr_flow_model model, int ring[4], char *msg,
                               size_t len) {
  const int G = model == GR_FLOW_SHALLOW_WATER ? GR_RAIN_RUNOFF_GHOST_SW : GR_RAIN_RUNOFF_GHOST;
  char need_for[40];
  snprintf(need_for, sizeof(need_for), " for FlowModel %d", (int)model);
  return gr_grid_piece_check(g, "rain runoff", G, need_for, 0, ring, msg, len);
}

void gr_rain_runoff_set_allreduce(gr_rain_runoff *s, gr_allreduce_fn fn, void *user) {
  if (!s)
    return;
  s->allreduce = fn;
  s->allreduce_user = fn ? user : NULL;
}

gr_status gr_rain_runoff_allreduce(gr_rain_runoff *s, double *values, int n, gr_reduce_op op) {
  gr_status st = s->allreduce(s->allreduce_user, values, n, op);
  if (st != GR_OK && st != GR_ERR_ABORTED)
    return gr_set_error(s->ctx, st,
                        "The rain runoff simulation's global reduction (the allreduce callback) "
                        "failed: %s.",
                        gr_status_string(st));
  return st;
}

void gr_rain_runoff_set_halo_exchange(gr_rain_runoff *s, gr_halo_exchange_fn fn, void *user) {
  if (!s)
    return;
  s->halo_exchange = fn;
  s->halo_user = fn ? user : NULL;
}

/* After a step of a piece with a ring: the caller's exchange refreshes it. */
gr_status gr_rain_runoff_exchange(gr_rain_runoff *s, long long step) {
  gr_status st = s->halo_exchange(s->halo_user);
  if (st != GR_OK)
    return gr_set_error(s->ctx, st,
                        "The rain runoff piece's halo exchange (the callback given to "
                        "gr_rain_runoff_set_halo_exchange) failed after step %lld with %s; the "
                        "piece's ring is not fresh, so restore a checkpoint before stepping on.",
                        step, gr_status_string(st));
  return GR_OK;
}

/* The cells of a halo strip on `side`: GR_RAIN_RUNOFF_GHOST columns by the
 * local array's rows (west, east), or its columns by GR_RAIN_RUNOFF_GHOST
 * rows (south, north); 0 where the side has no neighbour. */
static size_t gr_rain_runoff_strip_cells(const gr_rain_runoff *s, int side, size_t *w, size_t *h) {
  if (side < 0 || side > 3 || !s->ring[side])
    return 0;
  *w = side < 2 ? (size_t)s->ring[side] : (size_t)s->nxl;
  *h = side < 2 ? (size_t)s->nyl : (size_t)s->ring[side];
  return *w * *h;
}

gr_status gr_rain_runoff_halo_size(const gr_rain_runoff *s, int side, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_halo_size needs a simulation and a place for the size.");
  size_t w = 0, h = 0;
  *bytes =
      GR_RAIN_RUNOFF_HALO_ARRAYS * gr_rain_runoff_strip_cells(s, side, &w, &h) * sizeof(cl_float);
  return GR_OK;
}

/* Copies one side's strip between the device and host: from the owned
 * cells next to the side (get), or into the ring on that side (set). */
static gr_status gr_rain_runoff_halo_copy(gr_rain_runoff *s, int side, void *host, size_t bytes,
                                          int set) {
  size_t w = 0, h = 0, cells = gr_rain_runoff_strip_cells(s, side, &w, &h);
  if (cells == 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff piece has no neighbour on side %d (0 west, 1 east, 2 "
                        "south, 3 north): only sides with a ring exchange a halo.",
                        side);
  size_t need = GR_RAIN_RUNOFF_HALO_ARRAYS * cells * sizeof(cl_float);
  if (bytes != need)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The halo buffer has %zu bytes but side %d's strip has %zu: size it with "
                        "gr_rain_runoff_halo_size.",
                        bytes, side, need);
  const size_t g = (size_t)s->ring[side], nxl = (size_t)s->nxl, nyl = (size_t)s->nyl;
  size_t x0 = 0, y0 = 0;
  switch (side) {
  case 0:
    x0 = set ? 0 : g;
    break;
  case 1:
    x0 = set ? nxl - g : nxl - 2 * g;
    break;
  case 2:
    y0 = set ? 0 : g;
    break;
  default:
    y0 = set ? nyl - g : nyl - 2 * g;
    break;
  }
  /* Per cell: depth, limiter, its west x-face and its south y-face (the
   * faces are numbered from the cell's corner: x-face rows are nxl + 1
   * wide, y-faces like cells). */
  int sw = s->params.flow_model == GR_FLOW_SHALLOW_WATER;
  const cl_mem li_bufs[GR_RAIN_RUNOFF_HALO_ARRAYS] = {s->h, s->k, s->qx[s->cur], s->qy[s->cur]};
  const cl_mem sw_bufs[GR_RAIN_RUNOFF_HALO_ARRAYS] = {s->h, s->qu, s->qv, s->h_c};
  const cl_mem *bufs = sw ? sw_bufs : li_bufs;
  const size_t pitch[GR_RAIN_RUNOFF_HALO_ARRAYS] = {nxl, nxl, sw ? nxl : nxl + 1, nxl};
  unsigned char *at = host;
  gr_status st = GR_OK;
  for (int a = 0; st == GR_OK && a < GR_RAIN_RUNOFF_HALO_ARRAYS; ++a) {
    st = gr_rain_runoff_rect(s, bufs[a], pitch[a], 1, x0, y0, w, h, at, set);
    at += cells * sizeof(cl_float);
  }
  return st;
}

gr_status gr_rain_runoff_halo_get(gr_rain_runoff *s, int side, void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_halo_get needs a simulation and a buffer.");
  if (!host)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_halo_get needs a simulation and a buffer."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_halo_copy(s, side, host, bytes, 0));
}

gr_status gr_rain_runoff_halo_set(gr_rain_runoff *s, int side, const void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_halo_set needs a simulation and a buffer.");
  if (!host)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_halo_set needs a simulation and a buffer."));
  /* The copy only reads host (write = 1). */
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_halo_copy(s, side, (void *)host, bytes, 1));
}

/* ------------------------------------------------------------ checkpoints */

/* The checkpoint's header; the arrays follow it: the per-cell arrays
 * (GR_RAIN_RUNOFF_STATE_CELL_ARRAYS), then the current x- and y-faces (the
 * other face set is rewritten whole by the next step before it is read). */
typedef struct gr_rain_runoff_state_header {
  uint32_t magic, version;
  int32_t nx, ny; /* the local arrays' */
  int32_t i0, j0; /* the piece's first owned point (0, 0 for a whole grid) */
  int64_t steps;
  double time;
  /* The ledger's fixed point: the initial water's words, the rain's two
   * 128-bit sums (lo, hi each). */
  int64_t initial[2];
  uint64_t rain_lo[2];
  int64_t rain_hi[2];
} gr_rain_runoff_state_header;

static size_t gr_rain_runoff_xfaces(const gr_rain_runoff *s) {
  return ((size_t)s->nxl + 1) * (size_t)s->nyl;
}
static size_t gr_rain_runoff_yfaces(const gr_rain_runoff *s) {
  return (size_t)s->nxl * ((size_t)s->nyl + 1);
}

/* The state's bytes with `arrays` per-cell arrays (version 7's, or 6's). */
static size_t gr_rain_runoff_state_bytes_of(const gr_rain_runoff *s, int arrays) {
  return sizeof(gr_rain_runoff_state_header) +
         sizeof(float) * ((size_t)arrays * gr_rain_runoff_cells(s) + gr_rain_runoff_xfaces(s) +
                          gr_rain_runoff_yfaces(s));
}

static size_t gr_rain_runoff_state_bytes(const gr_rain_runoff *s) {
  return gr_rain_runoff_state_bytes_of(s, GR_RAIN_RUNOFF_STATE_CELL_ARRAYS);
}

gr_status gr_rain_runoff_state_size(const gr_rain_runoff *s, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_state_size needs a simulation and a place for the size.");
  *bytes = gr_rain_runoff_state_bytes(s);
  return GR_OK;
}

/* The state's device arrays in checkpoint order, with their sizes: the
 * first `arrays` per-cell ones (version 7's, or 6's), then the faces. */
static int gr_rain_runoff_state_arrays(gr_rain_runoff *s, int cur, int arrays, cl_mem *bufs,
                                       size_t *sizes) {
  cl_mem cells[GR_RAIN_RUNOFF_STATE_CELL_ARRAYS] = {
      s->h,      s->h_c, s->k,      s->inf,    s->inf_c,  s->out,    s->out_c,
      s->qu,     s->qv,  s->map[0], s->map[1], s->map[2], s->map[3], s->map[4],
      s->map[5], s->in,  s->in_c,   s->map[6], s->map[7]};
  int n = 0;
  for (int i = 0; i < arrays; ++i, ++n) {
    bufs[n] = cells[i];
    sizes[n] = gr_rain_runoff_cells(s) * sizeof(float);
  }
  bufs[n] = s->qx[cur];
  sizes[n++] = gr_rain_runoff_xfaces(s) * sizeof(float);
  bufs[n] = s->qy[cur];
  sizes[n++] = gr_rain_runoff_yfaces(s) * sizeof(float);
  return n;
}

static gr_status gr_rain_runoff_state_save_impl(gr_rain_runoff *s, void *host, size_t bytes) {
  size_t need = gr_rain_runoff_state_bytes(s);
  if (bytes != need)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The buffer for the rain runoff state has %zu bytes but this %d x %d "
                        "simulation's state has %zu: size it with gr_rain_runoff_state_size.",
                        bytes, s->nxl, s->nyl, need);
  gr_rain_runoff_state_header hd;
  memset(&hd, 0, sizeof(hd));
  hd.magic = GR_RAIN_RUNOFF_STATE_MAGIC;
  hd.version = GR_RAIN_RUNOFF_STATE_VERSION;
  hd.nx = s->nxl;
  hd.ny = s->nyl;
  hd.i0 = s->grid.i0;
  hd.j0 = s->grid.j0;
  hd.steps = s->steps;
  hd.time = s->time;
  hd.initial[0] = s->initial.coarse;
  hd.initial[1] = s->initial.fine;
  for (int q = 0; q < 2; ++q) {
    hd.rain_lo[q] = s->rain_book[q].lo;
    hd.rain_hi[q] = s->rain_book[q].hi;
  }
  unsigned char *at = host;
  memcpy(at, &hd, sizeof(hd));
  at += sizeof(hd);
  cl_mem bufs[GR_RAIN_RUNOFF_STATE_CELL_ARRAYS + 2];
  size_t sizes[GR_RAIN_RUNOFF_STATE_CELL_ARRAYS + 2];
  int n = gr_rain_runoff_state_arrays(s, s->cur, GR_RAIN_RUNOFF_STATE_CELL_ARRAYS, bufs, sizes);
  gr_status st = GR_OK;
  for (int i = 0; st == GR_OK && i < n; ++i) {
    st = gr_buffer_read(s->ctx, bufs[i], 0, sizes[i], at);
    at += sizes[i];
  }
  return st;
}

gr_status gr_rain_runoff_state_save(gr_rain_runoff *s, void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_state_save needs a simulation and a buffer.");
  if (!host)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_state_save needs a simulation and a buffer."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_state_save_impl(s, host, bytes));
}

/* Version 6's wet duration, a Kahan sum (wet, its compensation comp) of
 * every wet step's dt, into version 7's ended spells (wet, comp become the
 * double-float pair hi, lo of the same value): the spells under way start
 * at the checkpoint's time (gr_rain_runoff_maps_update after the load, with
 * wet_since -1 everywhere), where the sum stopped. */
static gr_status gr_rain_runoff_state_wet_6(gr_rain_runoff *s, const unsigned char *wet,
                                            const unsigned char *comp) {
  size_t cells = gr_rain_runoff_cells(s), bytes = cells * sizeof(float);
  float *pair = malloc(2 * bytes);
  if (!pair)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  float *lo = pair + cells;
  for (size_t c = 0; c < cells; ++c) {
    float w, k;
    memcpy(&w, wet + c * sizeof(float), sizeof(float));
    memcpy(&k, comp + c * sizeof(float), sizeof(float));
    double v = (double)w - (double)k; /* exact: k is within w's last bits */
    pair[c] = (float)v;
    lo[c] = (float)(v - (double)pair[c]);
  }
  gr_status st = gr_buffer_write(s->ctx, s->map[3], 0, bytes, pair);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->map[5], 0, bytes, lo);
  if (st == GR_OK)
    st = gr_rain_runoff_fill(s, s->map[6], -1.0f, bytes);
  if (st == GR_OK)
    st = gr_rain_runoff_fill(s, s->map[7], 0.0f, bytes);
  free(pair);
  return st;
}

static gr_status gr_rain_runoff_state_load_impl(gr_rain_runoff *s, const void *host, size_t bytes) {
  gr_rain_runoff_state_header hd;
  if (bytes < sizeof(hd))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff state has %zu bytes, fewer than its header: pass the "
                        "bytes gr_rain_runoff_state_save wrote.",
                        bytes);
  memcpy(&hd, host, sizeof(hd));
  /* Version 6 differs in the wet duration only (gr_rain_runoff_state_wet_6). */
  int v6 = hd.version == 6u;
  if (hd.magic != GR_RAIN_RUNOFF_STATE_MAGIC || (hd.version != GR_RAIN_RUNOFF_STATE_VERSION && !v6))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The bytes given are not a rain runoff state of this version (magic "
                        "0x%08x, version %u; expected 0x%08x, version %u or 6): pass the bytes "
                        "gr_rain_runoff_state_save wrote.",
                        (unsigned)hd.magic, (unsigned)hd.version, GR_RAIN_RUNOFF_STATE_MAGIC,
                        GR_RAIN_RUNOFF_STATE_VERSION);
  const int arrays = v6 ? GR_RAIN_RUNOFF_STATE_CELL_ARRAYS_6 : GR_RAIN_RUNOFF_STATE_CELL_ARRAYS;
  size_t need = gr_rain_runoff_state_bytes_of(s, arrays);
  if (hd.nx != s->nxl || hd.ny != s->nyl)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff state is of a %d x %d grid but this simulation's grid "
                        "is %d x %d: load it into a simulation of the grid it was saved from.",
                        (int)hd.nx, (int)hd.ny, s->nxl, s->nyl);
  if (hd.i0 != s->grid.i0 || hd.j0 != s->grid.j0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff state is of the piece whose first point is (%d, %d) but "
                        "this simulation's piece starts at (%d, %d): load each piece's own "
                        "checkpoint.",
                        (int)hd.i0, (int)hd.j0, s->grid.i0, s->grid.j0);
  if (bytes != need)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff state has %zu bytes but a %d x %d simulation's state "
                        "has %zu: pass the whole buffer gr_rain_runoff_state_save filled.",
                        bytes, s->nxl, s->nyl, need);
  /* The rain's sums stay below 2^109 and 2^125 (gr_rain_runoff_rain_book);
   * the initial water's words below 2^62 (graupel/reduce.h's bounds). */
  const int64_t rain_top = INT64_C(1) << 61, initial_top = INT64_C(1) << 62;
  if (!(hd.time >= 0.0 && hd.time < HUGE_VAL) || hd.steps < 0 || hd.steps > GR_STATE_MAX_STEPS ||
      hd.rain_hi[0] < 0 || hd.rain_hi[0] > rain_top || hd.rain_hi[1] < -rain_top ||
      hd.rain_hi[1] > rain_top || hd.initial[0] < -initial_top || hd.initial[0] > initial_top ||
      hd.initial[1] < -initial_top || hd.initial[1] > initial_top)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff state's header is damaged (time %g s, %lld steps): "
                        "pass the bytes gr_rain_runoff_state_save wrote.",
                        hd.time, (long long)hd.steps);
  /* Every float finite, checked before anything is written, so that a
   * refused state leaves the simulation as it was. */
  const size_t cells = gr_rain_runoff_cells(s);
  const gr_state_part parts[] = {{"water depth", sizeof(hd), cells, 'f', -HUGE_VAL, HUGE_VAL},
                                 {"per-cell arrays", sizeof(hd) + 4 * cells,
                                  (size_t)(arrays - 1) * cells, 'f', -HUGE_VAL, HUGE_VAL},
                                 {"face discharges", sizeof(hd) + 4 * (size_t)arrays * cells,
                                  gr_rain_runoff_xfaces(s) + gr_rain_runoff_yfaces(s), 'f',
                                  -HUGE_VAL, HUGE_VAL}};
  gr_status st = gr_state_check("rain runoff", "rain_runoff", host, parts, 3);
  if (st != GR_OK)
    return st;
  /* Into face set 0, which becomes current. */
  const unsigned char *at = (const unsigned char *)host + sizeof(hd);
  cl_mem bufs[GR_RAIN_RUNOFF_STATE_CELL_ARRAYS + 2];
  size_t sizes[GR_RAIN_RUNOFF_STATE_CELL_ARRAYS + 2];
  int n = gr_rain_runoff_state_arrays(s, 0, arrays, bufs, sizes);
  for (int i = 0; st == GR_OK && i < n; ++i) {
    st = gr_buffer_write(s->ctx, bufs[i], 0, sizes[i], at);
    at += sizes[i];
  }
  /* Version 6: the wet duration's arrays 12 and 14 (map[3], map[5]). */
  const unsigned char *cells_at = (const unsigned char *)host + sizeof(hd);
  if (st == GR_OK && v6)
    st = gr_rain_runoff_state_wet_6(s, cells_at + 12 * cells * sizeof(float),
                                    cells_at + 14 * cells * sizeof(float));
  if (st != GR_OK)
    return st;
  s->cur = 0;
  s->steps = hd.steps;
  s->time = hd.time;
  s->initial.coarse = hd.initial[0];
  s->initial.fine = hd.initial[1];
  for (int q = 0; q < 2; ++q) {
    s->rain_book[q].lo = hd.rain_lo[q];
    s->rain_book[q].hi = hd.rain_hi[q];
  }
  /* The maps' wet spells from the depth loaded and this simulation's
   * wetting depth: the spells under way of a version 6 state, or of a state
   * saved under another wetting depth (the step kernels take a cell's wet
   * state from its depth). A state saved under this wetting depth is left
   * as it was: its maps already hold what the fold would add. */
  return gr_rain_runoff_maps_update(s, s->time);
}

gr_status gr_rain_runoff_state_load(gr_rain_runoff *s, const void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_state_load needs a simulation and the saved bytes.");
  if (!host)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_state_load needs a simulation and the saved bytes."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_state_load_impl(s, host, bytes));
}
