/* Water surface core, host side (water_surface_internal.h): pieces of a
 * split domain (the piece contract, the allreduce and the halo exchange)
 * and checkpoints (the state's bytes saved and loaded). */
#include "water_surface_internal.h"

/* Checkpoints: "GRW1" and the layout's version. */
#define GR_WS_STATE_MAGIC 0x31575247u
#define GR_WS_STATE_VERSION 2u /* 2: a piece's j0 */

/* ------------------------------------------------------------- pieces */

/* The piece contract (graupel.h, water_surface.h): strips of whole rows, a
 * ring of grid->ghost rows toward each neighbour. */
gr_status gr_ws_piece_check(const gr_grid *g, const gr_water_surface_params *p, int *ring_s,
                            int *ring_n, char *msg, size_t len) {
  char why[96];
  snprintf(why, sizeof(why), "for DropRadius %g m on a spacing of %g m", p->drop_radius, g->dy);
  return gr_grid_strip_check(g, "water surface", "", gr_water_surface_ghost(p, g->dy), why, ring_s,
                             ring_n, msg, len);
}

void gr_water_surface_set_allreduce(gr_water_surface *s, gr_allreduce_fn fn, void *user) {
  if (!s)
    return;
  s->allreduce = fn;
  s->allreduce_user = fn ? user : NULL;
}

void gr_water_surface_set_halo_exchange(gr_water_surface *s, gr_halo_exchange_fn fn, void *user) {
  if (!s)
    return;
  s->halo_exchange = fn;
  s->halo_user = fn ? user : NULL;
}

/* The caller's allreduce. */
gr_status gr_ws_allreduce(gr_water_surface *s, double *v, int n, gr_reduce_op op) {
  gr_status st = s->allreduce(s->allreduce_user, v, n, op);
  if (st != GR_OK)
    return gr_set_error(s->ctx, st,
                        "The water surface's global reduction (the allreduce callback) failed "
                        "after step %lld with %s.",
                        s->steps, gr_status_string(st));
  return GR_OK;
}

/* The local row the strip on `side` is read from (set 0) or written to
 * (set 1): one row of h, the own row next to the neighbour or the ring row
 * next to the own rows; -1 without a neighbour there. */
static int gr_ws_strip_row(const gr_water_surface *s, int side, int set) {
  if (side == GR_WATER_SURFACE_SOUTH && s->ring_s)
    return set ? s->ring_s - 1 : s->ring_s;
  if (side == GR_WATER_SURFACE_NORTH && s->ring_n)
    return set ? s->ring_s + s->own_ny : s->ring_s + s->own_ny - 1;
  return -1;
}

gr_status gr_water_surface_halo_size(const gr_water_surface *s, int side, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_halo_size needs a simulation and a place for the size.");
  *bytes = gr_ws_strip_row(s, side, 0) < 0 ? 0 : (size_t)s->grid.nx * sizeof(float);
  return GR_OK;
}

/* The strip's wave height between the device and the host; waits. */
static gr_status gr_ws_halo_copy(gr_water_surface *s, int side, void *host, size_t bytes, int set) {
  int row = gr_ws_strip_row(s, side, set);
  if (row < 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The water surface piece has no neighbour on side %d (2 south, 3 north): "
                        "only sides with a ring exchange a halo.",
                        side);
  size_t need = (size_t)s->grid.nx * sizeof(float), at = (size_t)row * need;
  if (!host || bytes != need)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The halo buffer has %zu bytes but side %d's strip has %zu: size it with "
                        "gr_water_surface_halo_size.",
                        host ? bytes : 0, side, need);
  return set ? gr_buffer_write(s->ctx, s->h[s->cur], at, need, host)
             : gr_buffer_read(s->ctx, s->h[s->cur], at, need, host);
}

gr_status gr_water_surface_halo_get(gr_water_surface *s, int side, void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_halo_get needs a simulation.");
  return GR_WS_KEEP(s, gr_ws_halo_copy(s, side, host, bytes, 0));
}

gr_status gr_water_surface_halo_set(gr_water_surface *s, int side, const void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_halo_set needs a simulation.");
  /* The copy only reads host (set = 1). */
  return GR_WS_KEEP(s, gr_ws_halo_copy(s, side, (void *)host, bytes, 1));
}

/* ------------------------------------------------------------ checkpoints */

typedef struct gr_ws_state_header {
  uint32_t magic, version;
  int32_t nx, ny;
  int64_t steps;
  int32_t initial_known, j0;
  double time, initial_sum, last_dt;
} gr_ws_state_header;

size_t gr_ws_state_bytes(const gr_water_surface *s) {
  return sizeof(gr_ws_state_header) + 2 * gr_ws_points(s) * sizeof(float);
}

gr_status gr_water_surface_state_size(const gr_water_surface *s, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_state_size needs a simulation and a place for the "
                        "size.");
  *bytes = gr_ws_state_bytes(s);
  return GR_OK;
}

static gr_status gr_ws_save_impl(gr_water_surface *s, void *host, size_t bytes) {
  size_t need = gr_ws_state_bytes(s), fb = gr_ws_points(s) * sizeof(float);
  if (bytes != need)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The buffer for the water surface state has %zu bytes but this state has "
                        "%zu: size it with gr_water_surface_state_size.",
                        bytes, need);
  gr_ws_state_header hd;
  memset(&hd, 0, sizeof(hd));
  hd.magic = GR_WS_STATE_MAGIC;
  hd.version = GR_WS_STATE_VERSION;
  hd.nx = s->grid.nx;
  hd.ny = s->grid.ny;
  hd.steps = s->steps;
  hd.initial_known = s->initial_known;
  hd.j0 = s->grid.j0;
  hd.time = s->time;
  hd.initial_sum = s->initial_sum;
  hd.last_dt = s->last_dt;
  unsigned char *at = host;
  memcpy(at, &hd, sizeof(hd));
  gr_status st = gr_buffer_read(s->ctx, s->h[s->cur], 0, fb, at + sizeof(hd));
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->v, 0, fb, at + sizeof(hd) + fb);
  return st;
}

gr_status gr_water_surface_state_save(gr_water_surface *s, void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_state_save needs a simulation and a buffer.");
  if (!host)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_water_surface_state_save needs a simulation and a "
                                      "buffer."));
  return GR_WS_KEEP(s, gr_ws_save_impl(s, host, bytes));
}

static gr_status gr_ws_load_impl(gr_water_surface *s, const void *host, size_t bytes) {
  size_t need = gr_ws_state_bytes(s), fb = gr_ws_points(s) * sizeof(float);
  gr_ws_state_header hd;
  if (bytes < sizeof(hd))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The water surface state has %zu bytes, fewer than its header: pass the "
                        "bytes gr_water_surface_state_save wrote.",
                        bytes);
  memcpy(&hd, host, sizeof(hd));
  if (hd.magic != GR_WS_STATE_MAGIC || hd.version != GR_WS_STATE_VERSION)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The bytes given are not a water surface state of this version: pass the "
                        "bytes gr_water_surface_state_save wrote.");
  if (hd.nx != s->grid.nx || hd.ny != s->grid.ny || hd.j0 != s->grid.j0 || bytes != need)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The water surface state is of a %d x %d grid at row %d (%zu bytes) but "
                        "this simulation's grid is %d x %d at row %d (%zu bytes): load it into a "
                        "simulation of the grid (or piece) it was saved from.",
                        (int)hd.nx, (int)hd.ny, (int)hd.j0, bytes, s->grid.nx, s->grid.ny,
                        s->grid.j0, need);
  if (!(hd.time >= 0.0 && hd.time < HUGE_VAL) || hd.steps < 0 || hd.steps > GR_STATE_MAX_STEPS ||
      !isfinite(hd.initial_sum))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The water surface state's header is damaged (time %g s, %lld steps): "
                        "pass the bytes gr_water_surface_state_save wrote.",
                        hd.time, (long long)hd.steps);
  /* The wave within set_wave's bounds and its velocity finite, checked
   * before anything is written, so that a refused state leaves the
   * simulation as it was. */
  const gr_state_part parts[] = {
      {"wave height", sizeof(hd), gr_ws_points(s), 'f', -GR_WS_MAX_WAVE, GR_WS_MAX_WAVE},
      {"wave velocity", sizeof(hd) + fb, gr_ws_points(s), 'f', -HUGE_VAL, HUGE_VAL}};
  gr_status st = gr_state_check("water surface", "water_surface", host, parts, 2);
  if (st != GR_OK)
    return st;
  const unsigned char *at = (const unsigned char *)host + sizeof(hd);
  st = gr_buffer_write(s->ctx, s->h[s->cur], 0, fb, at);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->v, 0, fb, at + fb);
  if (st != GR_OK)
    return st;
  s->steps = hd.steps;
  s->time = hd.time;
  s->initial_known = hd.initial_known != 0;
  s->initial_sum = hd.initial_sum;
  s->last_dt = isfinite(hd.last_dt) && hd.last_dt > 0.0 ? hd.last_dt : 0.0;
  return GR_OK;
}

gr_status gr_water_surface_state_load(gr_water_surface *s, const void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_state_load needs a simulation and the saved bytes.");
  if (!host)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_water_surface_state_load needs a simulation and the "
                                      "saved bytes."));
  return GR_WS_KEEP(s, gr_ws_load_impl(s, host, bytes));
}
