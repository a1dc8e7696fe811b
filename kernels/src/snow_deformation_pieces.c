/* Snow deformation core, host side: pieces of a split domain and
 * checkpoints (snow_deformation_internal.h): the piece contract, the
 * allreduce and the halo exchange, and the state's bytes saved and loaded. */
#include "snow_deformation_internal.h"
#include "runtime_internal.h"

/* ------------------------------------------------------ pieces and halos */

/* The piece contract (graupel.h, snow_deformation.h): which sides have a
 * neighbour, and so a ring of grid.ghost points, GR_SNOW_DEFORMATION_GHOST
 * or a multiple of it up to GR_SNOW_DEFORMATION_GHOST_MAX (anything else
 * is refused, with GR_SNOW_DEFORMATION_GHOST as the width asked for). */
gr_status gr_snow_piece_rings(const gr_grid *g, int ring[4], char *msg, size_t len) {
  const int G = GR_SNOW_DEFORMATION_GHOST;
  int need = g->ghost >= G && g->ghost <= GR_SNOW_DEFORMATION_GHOST_MAX && g->ghost % G == 0
                 ? g->ghost
                 : G;
  char need_for[80];
  snprintf(need_for, sizeof(need_for), " (or a multiple of %d up to %d)", G,
           GR_SNOW_DEFORMATION_GHOST_MAX);
  return gr_grid_piece_check(g, "snow deformation", need, need_for, 1, ring, msg, len);
}

int gr_snow_has_ring(const gr_snow_deformation *s) {
  return s->ring[0] || s->ring[1] || s->ring[2] || s->ring[3];
}

/* The piece's ring width (every side with a neighbour has the same); 0 on
 * a whole grid. */
int gr_snow_ring_width(const gr_snow_deformation *s) {
  int w = 0;
  for (int q = 0; q < 4; ++q)
    w = s->ring[q] > w ? s->ring[q] : w;
  return w;
}

/* Cuts the window [*x0, *x1] x [*y0, *y1] of the local arrays to the
 * piece's own points (nothing to cut on a whole grid). */
void gr_snow_own_clip(const gr_snow_deformation *s, int *x0, int *y0, int *x1, int *y1) {
  int ax = s->ring[0], ay = s->ring[2];
  int bx = s->grid.nx - 1 - s->ring[1], by = s->grid.ny - 1 - s->ring[3];
  *x0 = *x0 > ax ? *x0 : ax;
  *y0 = *y0 > ay ? *y0 : ay;
  *x1 = *x1 < bx ? *x1 : bx;
  *y1 = *y1 < by ? *y1 : by;
}

void gr_snow_deformation_set_allreduce(gr_snow_deformation *s, gr_allreduce_fn fn, void *user) {
  if (!s)
    return;
  s->allreduce = fn;
  s->allreduce_user = fn ? user : NULL;
}

void gr_snow_deformation_set_halo_exchange(gr_snow_deformation *s, gr_halo_exchange_fn fn,
                                           void *user) {
  if (!s)
    return;
  s->halo_exchange = fn;
  s->halo_user = fn ? user : NULL;
}

gr_status gr_snow_allreduce(gr_snow_deformation *s, double *values, int n, gr_reduce_op op) {
  gr_status st = s->allreduce(s->allreduce_user, values, n, op);
  if (st != GR_OK && st != GR_ERR_ABORTED)
    return gr_set_error(s->ctx, st,
                        "The snow deformation simulation's global reduction (the allreduce "
                        "callback) failed: %s.",
                        gr_status_string(st));
  return st;
}

/* Integer sums over every piece (nothing to do without an allreduce): each
 * int64 travels as two doubles, its high and its low 32 bits, whose sums
 * are exact for fewer than 2^21 pieces, so the totals are the whole grid's
 * integers however the domain is split. */
#define GR_SNOW_ALLREDUCE_MAX 8
gr_status gr_snow_allreduce_i64(gr_snow_deformation *s, long long *v, int n) {
  if (!s->allreduce)
    return GR_OK;
  double d[2 * GR_SNOW_ALLREDUCE_MAX];
  for (int q = 0; q < n; ++q) {
    long long hi = v[q] >= 0 ? v[q] / 4294967296LL : -((-v[q] + 4294967295LL) / 4294967296LL);
    d[2 * q] = (double)hi;
    d[2 * q + 1] = (double)(v[q] - hi * 4294967296LL); /* 0 .. 2^32 - 1 */
  }
  gr_status st = gr_snow_allreduce(s, d, 2 * n, GR_REDUCE_SUM);
  for (int q = 0; st == GR_OK && q < n; ++q)
    v[q] = (long long)d[2 * q] * 4294967296LL + (long long)d[2 * q + 1];
  return st;
}

/* After a stage that used up a piece's ring (an object's press, a talus
 * launch): the caller's exchange refreshes it. Nothing on a whole grid. */
gr_status gr_snow_piece_sync(gr_snow_deformation *s) {
  if (!gr_snow_has_ring(s))
    return GR_OK;
  gr_status st = s->halo_exchange(s->halo_user);
  if (st != GR_OK)
    return gr_set_error(s->ctx, st,
                        "The snow deformation piece's halo exchange (the callback given to "
                        "gr_snow_deformation_set_halo_exchange) failed in step %lld with %s; the "
                        "piece's ring is not fresh, so restore a checkpoint before stepping on.",
                        s->steps + 1, gr_status_string(st));
  return GR_OK;
}

/* The points of a halo strip on `side`: the ring's width in columns by
 * the local arrays' rows (west, east), or their columns by the ring's
 * width in rows (south, north); 0 where the side has no neighbour. */
static size_t gr_snow_strip_cells(const gr_snow_deformation *s, int side, size_t *w, size_t *h) {
  if (side < 0 || side > 3 || !s->ring[side])
    return 0;
  *w = side < 2 ? (size_t)s->ring[side] : (size_t)s->grid.nx;
  *h = side < 2 ? (size_t)s->grid.ny : (size_t)s->ring[side];
  return *w * *h;
}

gr_status gr_snow_deformation_halo_size(const gr_snow_deformation *s, int side, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_halo_size needs a simulation and a place for the "
                        "size.");
  size_t w = 0, h = 0;
  *bytes = GR_SNOW_HALO_ARRAYS * gr_snow_strip_cells(s, side, &w, &h) * sizeof(cl_float);
  return GR_OK;
}

/* Copies the floats of points [x0, x0+w) x [y0, y0+h) of a local array
 * between the device and a packed host block; waits unless `wait` is 0
 * (then host must stay as it is until the queue is finished). */
static gr_status gr_snow_rect(gr_snow_deformation *s, cl_mem buf, size_t x0, size_t y0, size_t w,
                              size_t h, void *host, int write, int wait) {
  const size_t f = sizeof(cl_float), pitch = (size_t)s->grid.nx * f;
  size_t origin[3] = {x0 * f, y0, 0}, host_origin[3] = {0, 0, 0}, region[3] = {w * f, h, 1};
  cl_command_queue q = gr_context_queue(s->ctx);
  cl_bool block = wait ? CL_TRUE : CL_FALSE;
  cl_int err = write ? clEnqueueWriteBufferRect(q, buf, block, origin, host_origin, region, pitch,
                                                0, w * f, 0, host, 0, NULL, NULL)
                     : clEnqueueReadBufferRect(q, buf, block, origin, host_origin, region, pitch, 0,
                                               w * f, 0, host, 0, NULL, NULL);
  return gr_cl_check(s->ctx, err,
                     write ? "Writing a halo strip to the device"
                           : "Reading part of a field back from the device");
}

/* Reads the piece's own points of a local array (the whole array for a
 * grid without a ring). */
gr_status gr_snow_read_own(gr_snow_deformation *s, cl_mem buf, float *host) {
  if (!gr_snow_has_ring(s))
    return gr_buffer_read(s->ctx, buf, 0, gr_snow_cells(s) * sizeof(float), host);
  return gr_snow_rect(s, buf, (size_t)s->ring[0], (size_t)s->ring[2], (size_t)s->own_nx,
                      (size_t)s->own_ny, host, 0, 1);
}

/* Copies one side's strip between the device and the host: from the own
 * points next to the side (get: the state's depth and density), or into
 * the ring on that side (set: both buffers of each pair, so that the
 * talus' second buffer equals the state there, as it must outside a
 * launch's window). The copies are enqueued without waiting and waited for
 * once at the end. Both buffers are written from the host: a device copy
 * from one to the other waits behind another context's kernels where two
 * pieces share a GPU (an H200 at 16384^2: 35 ms of copies a step against
 * 5.8). */
static gr_status gr_snow_halo_copy(gr_snow_deformation *s, int side, void *host, size_t bytes,
                                   int set) {
  size_t w = 0, h = 0, cells = gr_snow_strip_cells(s, side, &w, &h);
  if (cells == 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow deformation piece has no neighbour on side %d (0 west, 1 east, "
                        "2 south, 3 north): only sides with a ring exchange a halo.",
                        side);
  size_t need = GR_SNOW_HALO_ARRAYS * cells * sizeof(cl_float);
  if (bytes != need)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The halo buffer has %zu bytes but side %d's strip has %zu: size it with "
                        "gr_snow_deformation_halo_size.",
                        bytes, side, need);
  const size_t g = (size_t)s->ring[side], nxl = (size_t)s->grid.nx, nyl = (size_t)s->grid.ny;
  size_t x0 = 0, y0 = 0;
  /* The talus' columns only (a strip of a piece without a west or east
   * ring: its neighbours' columns are its own), packed the same way. */
  if (side >= 2 && s->halo_cols_on && !s->ring[0] && !s->ring[1]) {
    x0 = (size_t)s->halo_cols[0];
    w = (size_t)(s->halo_cols[1] - s->halo_cols[0] + 1);
    cells = w * h;
  }
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
  unsigned char *at = host;
  gr_status st = GR_OK;
  for (int a = 0; st == GR_OK && a < GR_SNOW_HALO_ARRAYS; ++a) {
    cl_mem *pair = a ? s->density : s->depth;
    if (s->halo_reach) { /* the talus' reach mask in the depth's place (gr_snow_relax_reach) */
      if (a == 0)
        st = gr_snow_rect(s, s->weight, x0, y0, w, h, at, set, 0);
      else if (!set)
        memset(at, 0, cells * sizeof(cl_float));
      at += cells * sizeof(cl_float);
      continue;
    }
    st = gr_snow_rect(s, pair[s->cur], x0, y0, w, h, at, set, 0);
    if (st == GR_OK && set)
      st = gr_snow_rect(s, pair[1 - s->cur], x0, y0, w, h, at, set, 0);
    at += cells * sizeof(cl_float);
  }
  /* host is the caller's until every copy has finished (also after an error) */
  gr_status fin = gr_finish(s->ctx);
  return st != GR_OK ? st : fin;
}

gr_status gr_snow_deformation_halo_get(gr_snow_deformation *s, int side, void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_halo_get needs a simulation and a buffer.");
  if (!host)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_halo_get needs a simulation and a buffer."));
  return GR_SNOW_KEEP_ERROR(s, gr_snow_halo_copy(s, side, host, bytes, 0));
}

gr_status gr_snow_deformation_halo_set(gr_snow_deformation *s, int side, const void *host,
                                       size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_halo_set needs a simulation and a buffer.");
  if (!host)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_halo_set needs a simulation and a buffer."));
  /* The copy only reads host (set = 1). */
  return GR_SNOW_KEEP_ERROR(s, gr_snow_halo_copy(s, side, (void *)host, bytes, 1));
}

/* ---------------------------------------------------------- checkpoints */

typedef struct gr_snow_state_header {
  uint32_t magic, version;
  int32_t nx, ny, relax_full, relax_iterations, rest[4];
  int32_t i0, j0; /* the piece's first own point (0, 0 for a whole grid) */
  int64_t steps, initial_q, initial_m;
  double time, compressed, displaced, pending, pending_mass;
  double force[GR_SNOW_DEFORMATION_MAX_OBJECTS][3], area[GR_SNOW_DEFORMATION_MAX_OBJECTS];
  double impulse[GR_SNOW_DEFORMATION_MAX_OBJECTS][3], peak[GR_SNOW_DEFORMATION_MAX_OBJECTS];
  double impulse_time;
} gr_snow_state_header;

static size_t gr_snow_state_bytes(const gr_snow_deformation *s) {
  return sizeof(gr_snow_state_header) + GR_SNOW_STATE_ARRAYS * gr_snow_cells(s) * sizeof(float);
}

gr_status gr_snow_deformation_state_size(const gr_snow_deformation *s, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_state_size needs a simulation and a place for the "
                        "size.");
  *bytes = gr_snow_state_bytes(s);
  return GR_OK;
}

static cl_mem gr_snow_state_array(gr_snow_deformation *s, int a) {
  cl_mem arrays[GR_SNOW_STATE_ARRAYS] = {s->depth[s->cur], s->density[s->cur], s->overlap_sum,
                                         s->contact};
  return arrays[a];
}

gr_status gr_snow_deformation_state_save(gr_snow_deformation *s, void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_state_save needs a simulation.");
  size_t need = gr_snow_state_bytes(s);
  if (!host || bytes != need)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The buffer for the snow deformation state has %zu bytes but this %d x %d "
                        "simulation's state has %zu: size it with gr_snow_deformation_state_size.",
                        host ? bytes : 0, s->grid.nx, s->grid.ny, need));
  gr_snow_state_header hd;
  memset(&hd, 0, sizeof(hd));
  hd.magic = GR_SNOW_STATE_MAGIC;
  hd.version = GR_SNOW_STATE_VERSION;
  hd.nx = s->grid.nx;
  hd.ny = s->grid.ny;
  hd.relax_iterations = s->relax_iterations;
  hd.relax_full = s->relax_full;
  for (int q = 0; q < 4; ++q)
    hd.rest[q] = s->rest[q];
  hd.steps = s->steps;
  hd.time = s->time;
  hd.i0 = s->ox + s->ring[0];
  hd.j0 = s->oy + s->ring[2];
  hd.initial_q = s->initial_q;
  hd.initial_m = s->initial_m;
  hd.compressed = s->compressed;
  hd.displaced = s->displaced;
  hd.pending = s->pending;
  hd.pending_mass = s->pending_mass;
  memcpy(hd.force, s->force, sizeof(hd.force));
  memcpy(hd.impulse, s->impulse, sizeof(hd.impulse));
  memcpy(hd.peak, s->peak, sizeof(hd.peak));
  hd.impulse_time = s->impulse_time;
  memcpy(hd.area, s->area, sizeof(hd.area));
  memcpy(host, &hd, sizeof(hd));
  size_t ab = gr_snow_cells(s) * sizeof(float);
  gr_status st = GR_OK;
  for (int a = 0; st == GR_OK && a < GR_SNOW_STATE_ARRAYS; ++a)
    st = gr_buffer_read(s->ctx, gr_snow_state_array(s, a), 0, ab,
                        (char *)host + sizeof(hd) + (size_t)a * ab);
  return st == GR_OK ? GR_OK : GR_SNOW_KEEP_ERROR(s, st);
}

gr_status gr_snow_deformation_state_load(gr_snow_deformation *s, const void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_state_load needs a simulation.");
  size_t need = gr_snow_state_bytes(s);
  gr_snow_state_header hd;
  if (!host || bytes != need)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow deformation state has %zu bytes but this %d x %d simulation "
                        "needs %zu: load a state saved from a grid of the same size.",
                        host ? bytes : 0, s->grid.nx, s->grid.ny, need));
  memcpy(&hd, host, sizeof(hd));
  if (hd.magic != GR_SNOW_STATE_MAGIC || hd.version != GR_SNOW_STATE_VERSION ||
      hd.nx != s->grid.nx || hd.ny != s->grid.ny)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_FORMAT,
                        "The bytes are not a snow deformation state of a %d x %d grid (version "
                        "%u); load one saved by gr_snow_deformation_state_save.",
                        s->grid.nx, s->grid.ny, GR_SNOW_STATE_VERSION));
  if (hd.i0 != s->ox + s->ring[0] || hd.j0 != s->oy + s->ring[2])
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow deformation state is of the piece whose first point is (%d, %d) "
                        "but this simulation's piece starts at (%d, %d): load each piece's own "
                        "state.",
                        hd.i0, hd.j0, s->ox + s->ring[0], s->oy + s->ring[2]));
  size_t ab = gr_snow_cells(s) * sizeof(float);
  const char *base = (const char *)host + sizeof(hd);
  for (size_t c = 0; c < 2 * gr_snow_cells(s); ++c) {
    float v;
    memcpy(&v, base + c * sizeof(float), sizeof(v));
    if (!isfinite(v) || v < 0.0f)
      return GR_SNOW_KEEP_ERROR(
          s, gr_set_error(s->ctx, GR_ERR_FORMAT,
                          "The snow deformation state holds a depth or density of %g: it is "
                          "damaged; load an intact one.",
                          (double)v));
  }
  /* The rest of the arrays and of the header's numbers finite, the
   * talus's box within reach of the domain (its corners are grown and
   * compared as ints): checked before anything is written, so that a
   * refused state leaves the simulation as it was. */
  const int gx = s->grid.global_nx > 0 ? s->grid.global_nx : s->grid.nx;
  const int gy = s->grid.global_ny > 0 ? s->grid.global_ny : s->grid.ny;
  const int64_t words_top = INT64_C(1) << 62; /* the ledger's initial words (reduce.h) */
  int box_ok = hd.relax_iterations >= 0 && hd.initial_q >= -words_top &&
               hd.initial_q <= words_top && hd.initial_m >= -words_top && hd.initial_m <= words_top;
  for (int q = 0; q < 4; ++q)
    box_ok &= hd.rest[q] >= -(gx + gy + 2) && hd.rest[q] <= gx + gy + 2;
  if (!(hd.time >= 0.0 && hd.time < HUGE_VAL) || hd.steps < 0 || hd.steps > GR_STATE_MAX_STEPS ||
      !box_ok)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_FORMAT,
                        "The snow deformation state's header is damaged (time %g s, %lld steps): "
                        "pass the bytes gr_snow_deformation_state_save wrote.",
                        hd.time, (long long)hd.steps));
  const size_t nd =
      (offsetof(gr_snow_state_header, impulse_time) - offsetof(gr_snow_state_header, force)) /
          sizeof(double) +
      1;
  const gr_state_part parts[] = {
      {"overlap and contact", sizeof(hd) + 2 * ab, 2 * gr_snow_cells(s), 'f', -HUGE_VAL, HUGE_VAL},
      {"volumes", offsetof(gr_snow_state_header, compressed), 4, 'd', -HUGE_VAL, HUGE_VAL},
      {"forces and impulses", offsetof(gr_snow_state_header, force), nd, 'd', -HUGE_VAL, HUGE_VAL}};
  if (gr_state_check("snow deformation", "snow_deformation", host, parts, 3) != GR_OK)
    return GR_SNOW_KEEP_ERROR(s, GR_ERR_FORMAT);
  gr_status st = GR_OK;
  for (int a = 0; st == GR_OK && a < GR_SNOW_STATE_ARRAYS; ++a)
    st = gr_buffer_write(s->ctx, gr_snow_state_array(s, a), 0, ab, base + (size_t)a * ab);
  if (st != GR_OK)
    return GR_SNOW_KEEP_ERROR(s, st);
  s->relax_iterations = hd.relax_iterations;
  s->relax_full = hd.relax_full != 0;
  for (int q = 0; q < 4; ++q)
    s->rest[q] = hd.rest[q];
  s->sync_full = 1;
  s->reset_full = 1;
  s->steps = hd.steps;
  s->time = hd.time;
  s->initial_q = hd.initial_q;
  s->initial_m = hd.initial_m;
  s->compressed = hd.compressed;
  s->displaced = hd.displaced;
  s->pending = hd.pending;
  s->pending_mass = hd.pending_mass;
  memcpy(s->force, hd.force, sizeof(hd.force));
  memcpy(s->impulse, hd.impulse, sizeof(hd.impulse));
  memcpy(s->peak, hd.peak, sizeof(hd.peak));
  s->impulse_time = hd.impulse_time;
  memcpy(s->area, hd.area, sizeof(hd.area));
  return GR_OK;
}
