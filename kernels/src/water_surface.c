/* Water surface core (seed 003's height-field water, seed 004's ripples):
 * host side of water_surface.cl. The model is documented in
 * graupel/water_surface.h; the constants both sides share in
 * water_surface_shared.h. */
#include "graupel/water_surface.h"
#include "graupel/cl_runtime.h"
#include "graupel/reduce.h"
#include "water_surface_shared.h"
#include "runtime_internal.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* set_field's sanity bounds: beyond them float differences overflow. */
#define GR_WS_MAX_ELEVATION 1.0e6
#define GR_WS_MAX_DEPTH 1.0e4
#define GR_WS_MAX_WAVE 1.0e4
/* With a progress callback, advance waits after a batch of steps that takes
 * about this long (s) and calls the callback at most this often (s). */
#define GR_WS_BATCH_S 0.08
#define GR_WS_PROGRESS_EVERY 0.1
/* Checkpoints: "GRW1" and the layout's version. */
#define GR_WS_STATE_MAGIC 0x31575247u
#define GR_WS_STATE_VERSION 2u /* 2: a piece's j0 */

/* The parameter table's rows, in gr_water_surface_param_bounds' order. */
enum {
  GR_WS_P_WAVE_SPEED,
  GR_WS_P_DAMPING,
  GR_WS_P_WET_DEPTH,
  GR_WS_P_USE_LAKE,
  GR_WS_P_LAKE_LEVEL,
  GR_WS_P_DROP_RATE,
  GR_WS_P_DROP_AMPLITUDE,
  GR_WS_P_DROP_RADIUS,
  GR_WS_P_SEED,
  GR_WS_P_CFL,
  GR_WS_P_COUNT
};

/* The one place each range is written. WaveSpeed 1 m/s is sqrt(g d) of 10 cm
 * of water (see the header for why it is fixed); Damping 0.1 /s halves a
 * ripple's energy in 7 s; WetDepth 1 cm, the wetting depth below which
 * runoff films carry no visible waves; the drops: about one per 10 m^2 a
 * second, 5 mm deep and 0.5 m wide, ripples that read at terrain scale.
 * LakeLevel spans the deepest ocean to above any terrain Procedural Terrain
 * makes; the Courant fraction 0.5 keeps the wave speed's dispersion error
 * below 1 % for waves of 8 points per wavelength. */
static const gr_param_bound gr_ws_bounds[GR_WS_P_COUNT] = {
    {"WaveSpeed", "m/s", 0.0, 300.0, 1.0, 1.0, 1, 0},
    {"Damping", "1/s", 0.0, 100.0, 0.1, 1.0, 0, 0},
    {"WetDepth", "m", 0.0, 100.0, 0.01, 1.0, 0, 0},
    {"UseLakeLevel", "", 0.0, 1.0, 0.0, 1.0, 0, 1},
    {"LakeLevel", "m", -1.1e4, 1e5, 0.0, 1.0, 0, 0},
    {"DropRate", "1/(m^2 s)", 0.0, 1000.0, 0.1, 1.0, 0, 0},
    {"DropAmplitude", "m", 0.0, 10.0, 0.005, 1.0, 0, 0},
    {"DropRadius", "m", 0.0, 1000.0, 0.5, 1.0, 1, 0},
    {"Seed", "", 0.0, 2147483647.0, 1.0, 1.0, 0, 1},
    {"CourantNumber", "", 0.0, 1.0, 0.5, 1.0, 1, 0},
};

static const char *const gr_ws_names[GR_WATER_OUTPUT_COUNT] = {
    "wave_height", "normal", "water_surface", "wet", "elevation", "water_depth"};

const char *gr_water_surface_output_name(gr_water_surface_output o) {
  return (int)o >= 0 && o < GR_WATER_OUTPUT_COUNT ? gr_ws_names[o] : NULL;
}

int gr_water_surface_output_components(gr_water_surface_output o) {
  if ((int)o < 0 || o >= GR_WATER_OUTPUT_COUNT)
    return 0;
  return o == GR_WATER_NORMAL ? 3 : 1;
}

const gr_param_bound *gr_water_surface_param_bounds(int *count) {
  if (count)
    *count = GR_WS_P_COUNT;
  return gr_ws_bounds;
}

void gr_water_surface_params_init(gr_water_surface_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  const gr_param_bound *b = gr_ws_bounds;
  p->wave_speed = b[GR_WS_P_WAVE_SPEED].default_value;
  p->damping = b[GR_WS_P_DAMPING].default_value;
  p->wet_depth = b[GR_WS_P_WET_DEPTH].default_value;
  p->use_lake_level = (int)b[GR_WS_P_USE_LAKE].default_value;
  p->lake_level = b[GR_WS_P_LAKE_LEVEL].default_value;
  p->drop_rate = b[GR_WS_P_DROP_RATE].default_value;
  p->drop_amplitude = b[GR_WS_P_DROP_AMPLITUDE].default_value;
  p->drop_radius = b[GR_WS_P_DROP_RADIUS].default_value;
  p->seed = (int)b[GR_WS_P_SEED].default_value;
  p->cfl = b[GR_WS_P_CFL].default_value;
}

static double gr_ws_param_value(const gr_water_surface_params *p, int row) {
  switch (row) {
  case GR_WS_P_WAVE_SPEED:
    return p->wave_speed;
  case GR_WS_P_DAMPING:
    return p->damping;
  case GR_WS_P_WET_DEPTH:
    return p->wet_depth;
  case GR_WS_P_USE_LAKE:
    return p->use_lake_level;
  case GR_WS_P_LAKE_LEVEL:
    return p->lake_level;
  case GR_WS_P_DROP_RATE:
    return p->drop_rate;
  case GR_WS_P_DROP_AMPLITUDE:
    return p->drop_amplitude;
  case GR_WS_P_DROP_RADIUS:
    return p->drop_radius;
  case GR_WS_P_SEED:
    return p->seed;
  default:
    return p->cfl;
  }
}

gr_status gr_water_surface_params_validate(const gr_water_surface_params *p, char *msg,
                                           size_t msg_len) {
  const char *what = "Invalid water surface parameters";
  if (!p)
    return gr_params_missing(what, msg, msg_len);
  double values[GR_WS_P_COUNT];
  for (int row = 0; row < GR_WS_P_COUNT; ++row)
    values[row] = gr_ws_param_value(p, row);
  return gr_params_check_table(gr_ws_bounds, NULL, GR_WS_P_COUNT, values, what, NULL,
                               GR_PARAM_SAY_GOT, msg, msg_len);
}

/* ------------------------------------------------------------- the handle */

struct gr_water_surface {
  gr_context *ctx;
  /* A piece (graupel.h's contract, water_surface.h's "Pieces of a split
   * domain"): grid.ny counts the local rows (own rows and rings); local row
   * 0 is the domain's row row0, the own rows are ring_s .. ring_s + own_ny
   * - 1. A whole grid: no rings, row0 0. */
  gr_grid grid;
  int gny, row0, own_ny, ring_s, ring_n;
  gr_allreduce_fn allreduce; /* NULL: this simulation is the whole domain */
  void *allreduce_user;
  gr_halo_exchange_fn halo_exchange;
  void *halo_user;
  gr_water_surface_params params;
  cl_kernel drops, step, reduce, derive;
  cl_mem h[2]; /* wave height; [cur] is the latest */
  int cur;
  cl_mem v;                 /* vertical velocity h_t, at half steps */
  cl_mem wet;               /* uchar per point */
  cl_mem base;              /* the still surface, m */
  cl_mem g;                 /* this step's drop Gaussians, on first use */
  cl_mem h0;                /* the initial wave, once set_wave was called */
  cl_mem scratch;           /* derived outputs, 3 floats per point, on first use */
  float *elevation, *depth; /* host copies of the inputs (depth once set) */
  int has_depth;
  /* The water (wet, base) is found from the inputs and parameters when first
   * needed after they change. */
  int water_ready;
  long long wet_points;
  /* The wave's sum at time 0, known once reduced (or loaded). */
  int initial_known;
  double initial_sum;
  double time;
  long long steps;
  double last_dt; /* the last step's, for the ledger's energy (0 before any) */
  gr_reduction_i64 ledger;
  gr_progress_fn progress;
  void *progress_user;
  char error[1024];
};

#define GR_WS_KEEP(s, st) gr_error_keep((s)->error, sizeof((s)->error), (st))

const char *gr_water_surface_last_error(const gr_water_surface *s) {
  return s ? s->error : "";
}

/* The local arrays' points (a piece: own rows and rings). */
static size_t gr_ws_points(const gr_water_surface *s) {
  return (size_t)s->grid.nx * (size_t)s->grid.ny;
}

/* The own points and the first own point's index in the local arrays. */
static size_t gr_ws_own_points(const gr_water_surface *s) {
  return (size_t)s->grid.nx * (size_t)s->own_ny;
}
static size_t gr_ws_own_first(const gr_water_surface *s) {
  return (size_t)s->grid.nx * (size_t)s->ring_s;
}

static int gr_ws_pieced(const gr_water_surface *s) {
  return s->ring_s > 0 || s->ring_n > 0;
}

/* Rows of the drop Gaussians' reach: 4 DropRadius, at most
 * GR_WATER_SURFACE_MAX_REACH. */
static int gr_ws_reach(double radius, double d) {
  return (int)fmin(ceil(GR_WATER_SURFACE_REACH_SIGMAS * radius / d), GR_WATER_SURFACE_MAX_REACH);
}

int gr_water_surface_ghost(const gr_water_surface_params *p, double dy) {
  if (!p || !(dy > 0.0) || !(p->drop_radius > 0.0))
    return 0;
  return 1 + gr_ws_reach(p->drop_radius, dy);
}

/* One kernel argument by its name in the kernel's source. */
typedef struct gr_ws_arg {
  const char *name;
  size_t size;
  const void *value;
} gr_ws_arg;

static gr_status gr_ws_args(gr_water_surface *s, cl_kernel k, const gr_ws_arg *args, size_t n) {
  gr_status st = GR_OK;
  for (size_t i = 0; st == GR_OK && i < n; ++i)
    st = gr_kernel_arg(s->ctx, k, args[i].name, args[i].size, args[i].value);
  return st;
}
#define GR_WS_ARGS(s, k, args) gr_ws_args((s), (k), (args), sizeof(args) / sizeof((args)[0]))

static gr_status gr_ws_fill(gr_water_surface *s, cl_mem buf, float value, size_t bytes) {
  return gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), buf, &value, sizeof(value), 0,
                                         bytes, 0, NULL, NULL),
                     "Filling a device buffer");
}

void gr_water_surface_destroy(gr_water_surface *s) {
  if (!s)
    return;
  cl_kernel kernels[] = {s->drops, s->step, s->reduce, s->derive};
  for (size_t i = 0; i < sizeof(kernels) / sizeof(kernels[0]); ++i)
    if (kernels[i])
      clReleaseKernel(kernels[i]);
  cl_mem *bufs[] = {&s->h[0], &s->h[1], &s->v, &s->wet, &s->base, &s->g, &s->h0, &s->scratch};
  for (size_t i = 0; i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    gr_buffer_release(bufs[i]);
  gr_reduction_i64_release(&s->ledger);
  free(s->elevation);
  free(s->depth);
  gr_context_release(s->ctx);
  free(s);
}

/* ------------------------------------------------------------- pieces */

/* The piece contract (graupel.h, water_surface.h): strips of whole rows, a
 * ring of grid->ghost rows toward each neighbour. */
static gr_status gr_ws_piece_check(const gr_grid *g, const gr_water_surface_params *p, int *ring_s,
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
static gr_status gr_ws_allreduce(gr_water_surface *s, double *v, int n, gr_reduce_op op) {
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

gr_status gr_water_surface_memory(const gr_grid *grid, gr_memory_need *out) {
  if (!grid || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_memory needs a grid and a place for the answer.");
  /* A piece's ring (at most grid->ghost rows each way). */
  double n = (double)grid->nx * ((double)grid->ny + 2.0 * (grid->ghost > 0 ? grid->ghost : 0));
  memset(out, 0, sizeof(*out));
  out->points = (double)grid->nx * (double)grid->ny;
  /* h twice, v, base, g, h0 and the scratch's 3: 9 floats and a byte a point. */
  out->device = (9.0 * 4.0 + 1.0) * n;
  out->largest = 3.0 * 4.0 * n; /* the scratch */
  out->host = (4.0 + 4.0 + 4.0 + 1.0) * n;
  out->state = 2.0 * sizeof(float) * n; /* gr_ws_state_bytes */
  return GR_OK;
}

gr_status gr_water_surface_create(gr_context *ctx, const gr_grid *grid,
                                  const gr_water_surface_params *p, gr_water_surface **out) {
  char msg[256];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_create needs a context and a place for the simulation.");
  *out = NULL;
  if (gr_grid_validate(grid, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (gr_water_surface_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  int ring_s = 0, ring_n = 0;
  if (gr_ws_piece_check(grid, p, &ring_s, &ring_n, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  size_t n = (size_t)grid->nx * ((size_t)grid->ny + (size_t)ring_s + (size_t)ring_n);
  if ((double)n > (double)INT_MAX - 1048576.0)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The water surface grid of %d x %d points is too large: the kernels "
                        "address at most about 2.1e9 points; coarsen it.",
                        grid->nx, grid->ny);
  gr_memory_need need;
  gr_water_surface_memory(grid, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The water surface of a %d x %d grid %s: use a smaller grid or another "
                        "device.",
                        grid->nx, grid->ny, msg);
  gr_water_surface *s = calloc(1, sizeof(*s));
  if (!s)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  s->ctx = gr_context_retain(ctx);
  s->grid = *grid;
  s->gny = grid->global_ny > 0 ? grid->global_ny : grid->ny;
  s->own_ny = grid->ny;
  s->ring_s = ring_s, s->ring_n = ring_n;
  s->row0 = grid->j0 - ring_s;
  s->grid.ny = grid->ny + ring_s + ring_n;
  s->params = *p;
  s->elevation = calloc(n, sizeof(float));
  if (!s->elevation) {
    gr_water_surface_destroy(s);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  size_t fb = n * sizeof(cl_float);
  cl_program prog = NULL;
  gr_status st = gr_program_get(ctx, "water_surface", NULL, &prog);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "water_surface_drops", &s->drops);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "water_surface_step", &s->step);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "water_surface_reduce", &s->reduce);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "water_surface_derive", &s->derive);
  cl_mem *floats[] = {&s->h[0], &s->h[1], &s->v, &s->base};
  for (size_t i = 0; st == GR_OK && i < sizeof(floats) / sizeof(floats[0]); ++i)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, fb, NULL, floats[i]);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, n, NULL, &s->wet);
  if (st == GR_OK)
    st = gr_reduction_i64_init_max(ctx, s->reduce, n, GR_WATER_SURFACE_WORDS,
                                   GR_WATER_SURFACE_MAXES, &s->ledger);
  for (size_t i = 0; st == GR_OK && i < sizeof(floats) / sizeof(floats[0]); ++i)
    st = gr_ws_fill(s, *floats[i], 0.0f, fb);
  if (st == GR_OK)
    st = gr_finish(ctx);
  if (st != GR_OK) {
    gr_water_surface_destroy(s);
    return st;
  }
  *out = s;
  return GR_OK;
}

gr_status gr_water_surface_set_params(gr_water_surface *s, const gr_water_surface_params *p) {
  char msg[256];
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_set_params needs a simulation.");
  if (gr_water_surface_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg));
  int need = gr_water_surface_ghost(p, s->grid.dy);
  if (gr_ws_pieced(s) && need > s->grid.ghost)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "Invalid water surface parameters: DropRadius %g m needs a "
                                      "ghost ring of %d rows but this piece has %d; keep "
                                      "DropRadius smaller or make the piece again with a wider "
                                      "ring.",
                                      p->drop_radius, need, s->grid.ghost));
  s->params = *p;
  s->water_ready = 0;
  s->initial_known = s->initial_known && s->steps > 0;
  return GR_OK;
}

/* Checks an input's floats: finite and within [lo, hi]; names the point. */
static gr_status gr_ws_check(gr_water_surface *s, const char *what, const float *host, double lo,
                             double hi, const char *rule) {
  const int nx = s->grid.nx;
  size_t n = gr_ws_points(s);
  for (size_t c = 0; c < n; ++c) {
    double v = host[c];
    if (isfinite(v) && v >= lo && v <= hi)
      continue;
    return gr_set_error(
        s->ctx, GR_ERR_INVALID_ARGUMENT, "The water surface's %s has %s at point (%zu, %zu): %s.",
        what, isnan(v) ? "NaN" : (isinf(v) ? "an infinite value" : "a value out of range"),
        c % (size_t)nx, c / (size_t)nx + (size_t)s->row0, rule);
  }
  return GR_OK;
}

static gr_status gr_ws_set_field_impl(gr_water_surface *s, gr_field f, const float *host) {
  size_t n = gr_ws_points(s);
  gr_status st;
  switch (f) {
  case GR_FIELD_ELEVATION:
    st = gr_ws_check(s, "elevation", host, -GR_WS_MAX_ELEVATION, GR_WS_MAX_ELEVATION,
                     "every elevation must be a finite number of metres within +-1e6 m");
    if (st == GR_OK)
      memcpy(s->elevation, host, n * sizeof(float));
    break;
  case GR_FIELD_WATER_DEPTH:
    st = gr_ws_check(s, "water_depth", host, 0.0, GR_WS_MAX_DEPTH,
                     "every depth must be a finite number of metres from 0 to 1e4 m");
    if (st == GR_OK && !s->depth && !(s->depth = malloc(n * sizeof(float))))
      st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    if (st == GR_OK) {
      memcpy(s->depth, host, n * sizeof(float));
      s->has_depth = 1;
    }
    break;
  default:
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The field '%s' is not an input of the water surface; its inputs are "
                        "elevation and water_depth.",
                        gr_field_name(f) ? gr_field_name(f) : "(unknown field)");
  }
  if (st == GR_OK)
    s->water_ready = 0;
  return st;
}

gr_status gr_water_surface_set_field(gr_water_surface *s, gr_field f, const float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_set_field needs a simulation and the field's values.");
  if (!host)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_water_surface_set_field needs a simulation and the "
                                      "field's values."));
  return GR_WS_KEEP(s, gr_ws_set_field_impl(s, f, host));
}

/* The lake's mode: a lake when asked for, else the depth when given. */
static int gr_ws_lake(const gr_water_surface *s) {
  return s->params.use_lake_level != 0;
}

/* Finds the wet points and the still surface from the inputs and the
 * parameters, and uploads them; refuses no water with a sentence. Water
 * with no wet point is not refused: runoff that has not gathered yet is
 * dry, and nothing moves. */
static gr_status gr_ws_prepare(gr_water_surface *s) {
  if (s->water_ready)
    return GR_OK;
  const gr_water_surface_params *p = &s->params;
  int lake = gr_ws_lake(s);
  if (!lake && !s->has_depth)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The water surface has no water: give it a water depth (water_depth, "
                        "e.g. Rain Runoff's output) or turn UseLakeLevel on with a LakeLevel "
                        "above the ground.");
  size_t n = gr_ws_points(s);
  unsigned char *wet = malloc(n);
  float *base = malloc(n * sizeof(float));
  if (!wet || !base) {
    free(wet);
    free(base);
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  float level = (float)p->lake_level, threshold = (float)p->wet_depth;
  long long count = 0;
  for (size_t c = 0; c < n; ++c) {
    float b = s->elevation[c];
    int w;
    if (lake) {
      w = b < level;
      base[c] = w ? level : b;
    } else {
      float d = s->depth[c];
      w = d > threshold;
      base[c] = b + d;
    }
    wet[c] = (unsigned char)w;
    count += w && c >= gr_ws_own_first(s) && c < gr_ws_own_first(s) + gr_ws_own_points(s);
  }
  gr_status st = GR_OK;
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->wet, 0, n, wet);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->base, 0, n * sizeof(float), base);
  free(wet);
  free(base);
  if (st == GR_OK) {
    s->water_ready = 1;
    s->wet_points = count;
  }
  return st;
}

/* The ledger's device sums (wave, energy per area, wet count) and max |h|
 * over the own points. The sums are fixed-point integers (reduce.h), and a
 * piece adds the other pieces' through the allreduce as exact 32-bit parts
 * (gr_fixed_pack): the same bits for the whole grid and any split. */
static gr_status gr_ws_reduce(gr_water_surface *s, double sums[3], double *max_wave) {
  const gr_grid *g = &s->grid;
  cl_int n = (cl_int)gr_ws_points(s), nx = g->nx, ny = g->ny;
  cl_int own_y0 = s->ring_s, own_y1 = s->ring_s + s->own_ny;
  cl_float c2 = (cl_float)(s->params.wave_speed * s->params.wave_speed);
  cl_float half_dt_c2 = (cl_float)(0.5 * s->last_dt * s->params.wave_speed * s->params.wave_speed);
  cl_float inv_dx2 = (cl_float)(1.0 / (g->dx * g->dx)), inv_dy2 = (cl_float)(1.0 / (g->dy * g->dy));
  const size_t m = sizeof(cl_mem);
  const gr_ws_arg args[] = {
      {"h", m, &s->h[s->cur]},
      {"v", m, &s->v},
      {"wet", m, &s->wet},
      {"n", sizeof(n), &n},
      {"nx", sizeof(nx), &nx},
      {"ny", sizeof(ny), &ny},
      {"own_y0", sizeof(own_y0), &own_y0},
      {"own_y1", sizeof(own_y1), &own_y1},
      {"c2", sizeof(c2), &c2},
      {"half_dt_c2", sizeof(half_dt_c2), &half_dt_c2},
      {"inv_dx2", sizeof(inv_dx2), &inv_dx2},
      {"inv_dy2", sizeof(inv_dy2), &inv_dy2},
  };
  long long words[GR_WATER_SURFACE_WORDS], maxes[GR_WATER_SURFACE_MAXES];
  gr_status st = GR_WS_ARGS(s, s->reduce, args);
  if (st == GR_OK)
    st = gr_reduction_i64_run_max(s->ctx, &s->ledger, s->reduce, words, maxes);
  if (st != GR_OK)
    return st;
  /* The largest |h|, by its float's bits (never below +0). */
  int32_t bits = (int32_t)maxes[0];
  float largest;
  memcpy(&largest, &bits, sizeof(largest));
  double hmax = largest;
  if (gr_ws_pieced(s) && s->allreduce) {
    double packed[GR_FIXED_PACKED(GR_WATER_SURFACE_WORDS, 0)];
    gr_fixed_pack(words, GR_WATER_SURFACE_WORDS, NULL, 0, packed);
    st = gr_ws_allreduce(s, packed, GR_FIXED_PACKED(GR_WATER_SURFACE_WORDS, 0), GR_REDUCE_SUM);
    if (st == GR_OK)
      st = gr_ws_allreduce(s, &hmax, 1, GR_REDUCE_MAX);
    if (st != GR_OK)
      return st;
    gr_fixed_unpack(packed, words, GR_WATER_SURFACE_WORDS, NULL, 0);
  }
  gr_fixed wave = {words[0], words[1]}, energy = {words[2], words[3]};
  sums[0] = gr_fixed_value(wave);
  sums[1] = gr_fixed_value(energy);
  sums[2] = (double)words[4];
  if (max_wave)
    *max_wave = hmax;
  return GR_OK;
}

/* Records the wave's sum at time 0 when it is not known yet. */
static gr_status gr_ws_know_initial(gr_water_surface *s) {
  if (s->initial_known || s->steps > 0)
    return GR_OK;
  double sums[3];
  gr_status st = gr_ws_reduce(s, sums, NULL);
  if (st == GR_OK) {
    s->initial_sum = sums[0];
    s->initial_known = 1;
  }
  return st;
}

static gr_status gr_ws_set_wave_impl(gr_water_surface *s, const float *host) {
  size_t bytes = gr_ws_points(s) * sizeof(float);
  gr_status st = gr_ws_check(s, "wave height", host, -GR_WS_MAX_WAVE, GR_WS_MAX_WAVE,
                             "every wave height must be a finite number of metres within +-1e4 m");
  if (st == GR_OK)
    st = s->h0 ? gr_buffer_write(s->ctx, s->h0, 0, bytes, host)
               : gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bytes, (void *)host, &s->h0);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->h[s->cur], 0, bytes, host);
  if (st == GR_OK)
    st = gr_ws_fill(s, s->v, 0.0f, bytes);
  if (st == GR_OK)
    s->initial_known = 0;
  return st;
}

gr_status gr_water_surface_set_wave(gr_water_surface *s, const float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_set_wave needs a simulation and the wave heights.");
  if (!host)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_water_surface_set_wave needs a simulation and the wave "
                                      "heights."));
  return GR_WS_KEEP(s, gr_ws_set_wave_impl(s, host));
}

/* --------------------------------------------------------------- stepping */

/* The CFL limit of the step: c dt sqrt(1/dx^2 + 1/dy^2) <= 1. */
static double gr_ws_limit(const gr_water_surface *s) {
  const gr_grid *g = &s->grid;
  return 1.0 / (s->params.wave_speed * sqrt(1.0 / (g->dx * g->dx) + 1.0 / (g->dy * g->dy)));
}

gr_status gr_water_surface_stable_dt(gr_water_surface *s, double *dt) {
  if (!s || !dt)
    return s ? GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                          "gr_water_surface_stable_dt needs a place for dt."))
             : gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                            "gr_water_surface_stable_dt needs a simulation.");
  *dt = s->params.cfl * gr_ws_limit(s);
  return GR_OK;
}

/* Enqueues one step of dt: this step's drops, then the wave update. */
static gr_status gr_ws_enqueue_one(gr_water_surface *s, double dt) {
  const gr_water_surface_params *p = &s->params;
  const gr_grid *gd = &s->grid;
  const size_t m = sizeof(cl_mem);
  cl_int nx = gd->nx, ny = gd->ny;
  double chance = p->drop_rate * gd->dx * gd->dy * dt;
  cl_uint threshold = chance >= 1.0 ? (cl_uint)16777216u : (cl_uint)floor(chance * 16777216.0);
  cl_int drops = p->drop_amplitude > 0.0 && threshold > 0;
  gr_status st = GR_OK;
  if (drops && !s->g)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, gr_ws_points(s) * sizeof(cl_float), NULL,
                          &s->g);
  if (st == GR_OK && drops) {
    double sigma = p->drop_radius;
    cl_int rx = gr_ws_reach(sigma, gd->dx), ry = gr_ws_reach(sigma, gd->dy);
    /* The own rows and the ring row next to them (the step reads its g). */
    cl_int j_lo = s->ring_s ? s->ring_s - 1 : 0;
    cl_int j_hi = s->ring_n ? s->ring_s + s->own_ny + 1 : ny, gj0 = s->row0;
    cl_float dx = (cl_float)gd->dx, dy = (cl_float)gd->dy;
    cl_float inv_2sig2 = (cl_float)(1.0 / (2.0 * sigma * sigma));
    cl_uint seed = (cl_uint)p->seed;
    uint64_t k = (uint64_t)s->steps;
    cl_uint step_lo = (cl_uint)(k & 0xffffffffu), step_hi = (cl_uint)(k >> 32);
    const gr_ws_arg args[] = {
        {"wet", m, &s->wet},
        {"g", m, &s->g},
        {"nx", sizeof(nx), &nx},
        {"ny", sizeof(ny), &ny},
        {"dx", sizeof(dx), &dx},
        {"dy", sizeof(dy), &dy},
        {"inv_2sig2", sizeof(inv_2sig2), &inv_2sig2},
        {"reach_x", sizeof(rx), &rx},
        {"reach_y", sizeof(ry), &ry},
        {"threshold", sizeof(threshold), &threshold},
        {"seed", sizeof(seed), &seed},
        {"step_lo", sizeof(step_lo), &step_lo},
        {"step_hi", sizeof(step_hi), &step_hi},
        {"j_lo", sizeof(j_lo), &j_lo},
        {"j_hi", sizeof(j_hi), &j_hi},
        {"gj0", sizeof(gj0), &gj0},
    };
    st = GR_WS_ARGS(s, s->drops, args);
    if (st == GR_OK)
      st =
          gr_enqueue_2d(s->ctx, s->drops, 0, (size_t)j_lo, (size_t)nx, (size_t)(j_hi - j_lo), NULL);
  }
  if (st != GR_OK)
    return st;
  cl_float inv_dx2 = (cl_float)(1.0 / (gd->dx * gd->dx));
  cl_float inv_dy2 = (cl_float)(1.0 / (gd->dy * gd->dy));
  cl_float c2dt = (cl_float)(p->wave_speed * p->wave_speed * dt), dtf = (cl_float)dt;
  cl_float damp = (cl_float)exp(-p->damping * dt);
  cl_float drop_coef = (cl_float)(0.5 * p->drop_amplitude * p->drop_radius * p->drop_radius);
  cl_mem g = s->g ? s->g : s->base; /* bound but not read without drops */
  int now = 1 - s->cur;
  cl_int j_lo = s->ring_s, j_hi = s->ring_s + s->own_ny;
  const gr_ws_arg args[] = {
      {"h_in", m, &s->h[s->cur]},
      {"h_out", m, &s->h[now]},
      {"v", m, &s->v},
      {"wet", m, &s->wet},
      {"g", m, &g},
      {"nx", sizeof(nx), &nx},
      {"ny", sizeof(ny), &ny},
      {"inv_dx2", sizeof(inv_dx2), &inv_dx2},
      {"inv_dy2", sizeof(inv_dy2), &inv_dy2},
      {"c2dt", sizeof(c2dt), &c2dt},
      {"dt", sizeof(dtf), &dtf},
      {"damp", sizeof(damp), &damp},
      {"drops", sizeof(drops), &drops},
      {"drop_coef", sizeof(drop_coef), &drop_coef},
      {"j_lo", sizeof(j_lo), &j_lo},
      {"j_hi", sizeof(j_hi), &j_hi},
  };
  st = GR_WS_ARGS(s, s->step, args);
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->step, 0, (size_t)j_lo, (size_t)nx, (size_t)(j_hi - j_lo), NULL);
  if (st != GR_OK)
    return st;
  s->cur = now;
  s->steps += 1;
  s->time += dt;
  s->last_dt = dt;
  /* A piece's ring row of h: the neighbour's new row, for the next step
   * (and the ledger's and the normals' differences across the cut). */
  if (gr_ws_pieced(s)) {
    st = s->halo_exchange(s->halo_user);
    if (st != GR_OK)
      return gr_set_error(s->ctx, st,
                          "The water surface piece's halo exchange (the callback given to "
                          "gr_water_surface_set_halo_exchange) failed in step %lld with %s; the "
                          "piece's ring is not fresh, so restore a checkpoint before stepping on.",
                          s->steps, gr_status_string(st));
  }
  return GR_OK;
}

/* What every stepping call checks first: water, and the wave's time-0 sum. */
static gr_status gr_ws_ready(gr_water_surface *s) {
  if (gr_ws_pieced(s) && (!s->allreduce || !s->halo_exchange))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "A water surface piece with neighbours steps only with an allreduce and "
                        "a halo exchange set (gr_water_surface_set_allreduce, "
                        "gr_water_surface_set_halo_exchange).");
  gr_status st = gr_ws_prepare(s);
  return st == GR_OK ? gr_ws_know_initial(s) : st;
}

static gr_status gr_ws_step_impl(gr_water_surface *s, double dt, int nsteps) {
  double limit = gr_ws_limit(s);
  if (!(dt > 0.0 && dt <= limit * (1.0 + 1e-12)))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The water surface's time step must be above 0 and at most the CFL "
                        "limit %g s for WaveSpeed %g m/s on this grid (got %g s): take shorter "
                        "steps.",
                        limit, s->params.wave_speed, dt);
  if (nsteps < 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The number of steps must be 0 or more (got %d).", nsteps);
  gr_status st = gr_ws_ready(s);
  for (int k = 0; st == GR_OK && k < nsteps; ++k)
    st = gr_ws_enqueue_one(s, dt);
  return st;
}

gr_status gr_water_surface_step(gr_water_surface *s, double dt, int nsteps) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_water_surface_step needs a simulation.");
  return GR_WS_KEEP(s, gr_ws_step_impl(s, dt, nsteps));
}

static double gr_ws_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static gr_status gr_ws_advance_impl(gr_water_surface *s, double duration, int *taken) {
  if (!(duration >= 0.0 && duration < HUGE_VAL))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The duration to advance must be a finite number of seconds, 0 or more "
                        "(got %g).",
                        duration);
  gr_status st = gr_ws_ready(s);
  if (st != GR_OK || duration == 0.0)
    return st;
  double stable = s->params.cfl * gr_ws_limit(s), n = ceil(duration / stable);
  if (n < 1.0)
    n = 1.0;
  if (n > (double)INT_MAX)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "Advancing the water surface by %g s takes more than %d steps of %g s: "
                        "advance in parts.",
                        duration, INT_MAX, stable);
  /* Equal steps ending exactly at the duration; the progress watch only adds
   * waits, so what is computed never depends on it. */
  double dt = duration / n, last_call = gr_ws_now(), last_wait = last_call;
  int total = (int)n, batch = 1, since = 0, stop = 0;
  for (int k = 0; st == GR_OK && k < total; ++k) {
    st = gr_ws_enqueue_one(s, dt);
    if (st != GR_OK)
      break;
    ++*taken;
    if (s->progress && ++since >= batch && k + 1 < total) {
      st = gr_finish(s->ctx);
      double now = gr_ws_now(), span = now - last_wait;
      if (span < 0.5 * GR_WS_BATCH_S && batch < (1 << 20))
        batch *= 2;
      else if (span > GR_WS_BATCH_S && batch > 1)
        batch /= 2;
      since = 0;
      last_wait = now;
      if (st == GR_OK && now - last_call >= GR_WS_PROGRESS_EVERY) {
        last_call = now;
        stop = s->progress(s->progress_user, s->time) != 0;
      }
    }
    /* The pieces' callbacks run at their own wall times: a stop asked on
     * any piece stops every piece after this same step. */
    if (st == GR_OK && gr_ws_pieced(s) && k + 1 < total) {
      double flag = stop;
      st = gr_ws_allreduce(s, &flag, 1, GR_REDUCE_MAX);
      stop = flag > 0.0;
    }
    if (st == GR_OK && stop)
      return gr_set_error(s->ctx, GR_ERR_ABORTED,
                          "The water surface advance was stopped by its progress callback at %g s "
                          "of simulated time; the state is valid there.",
                          s->time);
  }
  return st;
}

gr_status gr_water_surface_advance(gr_water_surface *s, double duration, int *steps_taken) {
  if (steps_taken)
    *steps_taken = 0;
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_advance needs a simulation.");
  int taken = 0;
  gr_status st = gr_ws_advance_impl(s, duration, &taken);
  if (steps_taken)
    *steps_taken = taken;
  return GR_WS_KEEP(s, st);
}

void gr_water_surface_set_progress(gr_water_surface *s, gr_progress_fn fn, void *user) {
  if (!s)
    return;
  s->progress = fn;
  s->progress_user = fn ? user : NULL;
}

/* ---------------------------------------------------------------- reading */

static gr_status gr_ws_derive(gr_water_surface *s, cl_int what, size_t comps, float *host) {
  size_t n = gr_ws_points(s);
  gr_status st = GR_OK;
  if (!s->scratch)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, 3 * n * sizeof(cl_float), NULL, &s->scratch);
  cl_int nx = s->grid.nx, ny = s->grid.ny;
  cl_float inv_dx = (cl_float)(1.0 / s->grid.dx), inv_dy = (cl_float)(1.0 / s->grid.dy);
  const size_t m = sizeof(cl_mem);
  const gr_ws_arg args[] = {
      {"h", m, &s->h[s->cur]},
      {"base", m, &s->base},
      {"wet", m, &s->wet},
      {"out", m, &s->scratch},
      {"nx", sizeof(nx), &nx},
      {"ny", sizeof(ny), &ny},
      {"inv_dx", sizeof(inv_dx), &inv_dx},
      {"inv_dy", sizeof(inv_dy), &inv_dy},
      {"what", sizeof(what), &what},
  };
  if (st == GR_OK)
    st = GR_WS_ARGS(s, s->derive, args);
  if (st == GR_OK)
    st =
        gr_enqueue_2d(s->ctx, s->derive, 0, (size_t)s->ring_s, (size_t)nx, (size_t)s->own_ny, NULL);
  /* The own rows (a piece's local arrays hold its rings around them). */
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->scratch, comps * gr_ws_own_first(s) * sizeof(cl_float),
                        comps * gr_ws_own_points(s) * sizeof(cl_float), host);
  return st;
}

static gr_status gr_ws_get_impl(gr_water_surface *s, gr_water_surface_output o, float *host) {
  if ((int)o < 0 || o >= GR_WATER_OUTPUT_COUNT)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The water surface has no output %d; its outputs are wave_height, "
                        "normal, water_surface, wet, elevation and water_depth.",
                        (int)o);
  size_t n = gr_ws_own_points(s), first = gr_ws_own_first(s);
  if (o == GR_WATER_ELEVATION) {
    memcpy(host, s->elevation + first, n * sizeof(float));
    return GR_OK;
  }
  gr_status st = gr_ws_prepare(s);
  if (st != GR_OK)
    return st;
  switch (o) {
  case GR_WATER_WAVE_HEIGHT:
    return gr_ws_derive(s, GR_WATER_SURFACE_DERIVE_WAVE, 1, host);
  case GR_WATER_NORMAL:
    return gr_ws_derive(s, GR_WATER_SURFACE_DERIVE_NORMAL, 3, host);
  case GR_WATER_SURFACE:
    return gr_ws_derive(s, GR_WATER_SURFACE_DERIVE_SURFACE, 1, host);
  case GR_WATER_WET:
    return gr_ws_derive(s, GR_WATER_SURFACE_DERIVE_WET, 1, host);
  default: {
    /* water_depth: the input, or the lake's depth over its wet points. */
    float level = (float)s->params.lake_level;
    for (size_t c = 0; c < n; ++c) {
      float b = s->elevation[first + c];
      if (!gr_ws_lake(s))
        host[c] = s->depth[first + c];
      else
        host[c] = b < level ? level - b : 0.0f;
    }
    return GR_OK;
  }
  }
}

gr_status gr_water_surface_get(gr_water_surface *s, gr_water_surface_output o, float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_get needs a simulation and room for the output.");
  if (!host)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_water_surface_get needs a simulation and room for the "
                                      "output."));
  return GR_WS_KEEP(s, gr_ws_get_impl(s, o, host));
}

static gr_status gr_ws_ledger_impl(gr_water_surface *s, gr_water_surface_ledger *out) {
  double sums[3], hmax = 0.0;
  gr_status st = gr_ws_ready(s);
  if (st == GR_OK)
    st = gr_ws_reduce(s, sums, &hmax);
  if (st != GR_OK)
    return st;
  double area = s->grid.dx * s->grid.dy;
  memset(out, 0, sizeof(*out));
  out->time = s->time;
  out->steps = s->steps;
  out->wet_points = (long long)sums[2];
  out->wave_volume = sums[0] * area;
  out->initial_volume = s->initial_sum * area;
  out->energy = sums[1] * area;
  out->max_wave = hmax;
  return GR_OK;
}

gr_status gr_water_surface_ledger_get(gr_water_surface *s, gr_water_surface_ledger *out) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_ledger_get needs a simulation and a ledger to fill.");
  if (!out)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_water_surface_ledger_get needs a simulation and a "
                                      "ledger to fill."));
  return GR_WS_KEEP(s, gr_ws_ledger_impl(s, out));
}

static gr_status gr_ws_reset_impl(gr_water_surface *s) {
  size_t bytes = gr_ws_points(s) * sizeof(cl_float);
  gr_status st;
  if (s->h0)
    st = gr_cl_check(s->ctx,
                     clEnqueueCopyBuffer(gr_context_queue(s->ctx), s->h0, s->h[s->cur], 0, 0, bytes,
                                         0, NULL, NULL),
                     "Copying the initial wave");
  else
    st = gr_ws_fill(s, s->h[s->cur], 0.0f, bytes);
  if (st == GR_OK)
    st = gr_ws_fill(s, s->v, 0.0f, bytes);
  if (st == GR_OK) {
    s->time = 0.0;
    s->steps = 0;
    s->last_dt = 0.0;
    s->initial_known = 0;
  }
  return st;
}

gr_status gr_water_surface_reset(gr_water_surface *s) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_reset needs a simulation.");
  return GR_WS_KEEP(s, gr_ws_reset_impl(s));
}

/* ------------------------------------------------------------ checkpoints */

typedef struct gr_ws_state_header {
  uint32_t magic, version;
  int32_t nx, ny;
  int64_t steps;
  int32_t initial_known, j0;
  double time, initial_sum, last_dt;
} gr_ws_state_header;

static size_t gr_ws_state_bytes(const gr_water_surface *s) {
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
  if (!(hd.time >= 0.0 && hd.time < HUGE_VAL) || hd.steps < 0 || !isfinite(hd.initial_sum))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The water surface state's header is damaged (time %g s, %lld steps): "
                        "pass the bytes gr_water_surface_state_save wrote.",
                        hd.time, (long long)hd.steps);
  const unsigned char *at = (const unsigned char *)host + sizeof(hd);
  gr_status st = gr_buffer_write(s->ctx, s->h[s->cur], 0, fb, at);
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
