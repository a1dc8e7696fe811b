/* Snow deformation core (seed 000's thesis): host side of
 * snow_deformation.cl. The model, its step order and its book-keeping are
 * documented in graupel/snow_deformation.h; the constants both sides share
 * in snow_deformation_shared.h. */
#include "graupel/snow_deformation.h"
#include "graupel/cl_runtime.h"
#include "graupel/reduce.h"
#include "snow_deformation_shared.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define GR_SNOW_MAX_ELEVATION 1.0e6
#define GR_SNOW_MAX_DEPTH 1.0e4
#define GR_SNOW_MIN_DT 1.0e-9
#define GR_SNOW_MAX_DT 3600.0
/* Checkpoints: "GSD1". */
#define GR_SNOW_STATE_MAGIC 0x31445347u
#define GR_SNOW_STATE_VERSION                                                                      \
  5u /* 5: the impulses since the last output; 4: the piece's i0,                                  \
         j0, the ledger's start in fixed point, the relaxation's rest box */
/* Per-point arrays of a checkpoint: depth, density, overlap sum, contact. */
#define GR_SNOW_STATE_ARRAYS 4
/* Per point of a halo strip: depth and density. */
#define GR_SNOW_HALO_ARRAYS 2

enum {
  GR_SNOW_P_INITIAL_DEPTH,
  GR_SNOW_P_INITIAL_DENSITY,
  GR_SNOW_P_MIN_DENSITY,
  GR_SNOW_P_MAX_DENSITY,
  GR_SNOW_P_COMPRESSION,
  GR_SNOW_P_MAX_SLOPE,
  GR_SNOW_P_FALLOFF,
  GR_SNOW_P_ITERATIONS,
  GR_SNOW_P_TOLERANCE,
  GR_SNOW_P_SLUMP,
  GR_SNOW_P_COUNT
};

/* The one place each range is written. Densities: Table 3.1 of the thesis
 * spans 30 (new snow) to 900 (ice) kg/m^3; sand reaches about 2000. */
static const gr_param_bound gr_snow_bounds[GR_SNOW_P_COUNT] = {
    {"InitialSnowDepth", "m", 0.0, 100.0, 0.5, 1.0, 0, 0},
    {"InitialDensity", "kg/m^3", 1.0, 3000.0, 150.0, 1.0, 0, 0},
    {"MinDensity", "kg/m^3", 1.0, 3000.0, 100.0, 1.0, 0, 0},
    {"MaxDensity", "kg/m^3", 1.0, 3000.0, 400.0, 1.0, 0, 0},
    {"CompressionModel", "", 0.0, 1.0, 0.0, 1.0, 0, 1},
    {"MaxSlope", "m/m", 0.0, 100.0, 0.6, 1.0, 1, 0},
    {"DirectionFalloff", "", 1.0, 1000.0, 8.0, 1.0, 0, 0},
    {"MaxRelaxIterations", "", 0.0, 100000.0, 200.0, 1.0, 0, 1},
    {"RelaxTolerance", "m", 0.0, 1.0, 1e-4, 1.0, 1, 0},
    /* The front of a collapsing granular pile H high moves at about
     * sqrt(g H) (Lube et al. 2004, Lajeunesse et al. 2004): 2.2 m/s for the
     * default 0.5 m cover. 0: instant (every step relaxes to the end). */
    {"SlumpSpeed", "m/s", 0.0, 1000.0, 2.0, 1.0, 0, 0},
};

typedef struct gr_snow_object {
  int first, count;       /* triangles in the world-triangle array */
  int bi0, bi1, bj0, bj1; /* the box of points it may cover; bi0 > bi1: none */
  double v[3];
} gr_snow_object;

struct gr_snow_deformation {
  gr_context *ctx;
  /* The local arrays' grid: for a piece of a split domain its points and
   * its ring (nx, ny count both; see "Pieces" below), whose point (0, 0)
   * is the domain's (ox, oy); for a whole grid the grid as given. */
  gr_grid grid;
  int ring[4];               /* ring width per side: west, east, south, north */
  int ox, oy;                /* the domain's index of local point (0, 0) */
  int gnx, gny;              /* the whole domain's points */
  int own_nx, own_ny;        /* the piece's own points */
  gr_allreduce_fn allreduce; /* NULL: this simulation is the whole domain */
  void *allreduce_user;
  gr_halo_exchange_fn halo_exchange; /* a piece with a ring steps only with one */
  void *halo_user;
  gr_snow_deformation_params params;
  cl_kernel raster, raster_clear, overlap_k, contour, obj_reduce, apply, relax_rate, relax_move,
      relax_block, relax_group, check_reduce, ledger_reduce, surface, reset, ring_reduce, quantize,
      reach_rows, reach_cols, reach_seed, reach_ceiling;
  cl_mem depth[2], density[2]; /* [cur] is the state */
  int cur;
  cl_mem ground, depth0, density0, under, overlap, weight, overlap_sum, contact, under_min, rate,
      rate_in, movable, scratch;
  size_t block[2]; /* the blocked talus launch's work-group: its tile of points */
  int blocked;     /* the talus in blocked launches (GPUs) or one launch per iteration */
  int group;       /* the talus' tail in one work-group (snow_relax_group) */
  size_t group_size;
  int group_area;      /* the largest window the tail's group computes */
  cl_mem group_result; /* snow_relax_group's iterations, end and window */
  cl_mem tri;          /* world triangles, 9 floats each */
  size_t tri_cap;
  gr_reduction red_check[GR_SNOW_CHECK_LAG + 1];
  gr_reduction_i64 red_obj, red_ledger, red_ring;
  gr_snow_object objects[GR_SNOW_DEFORMATION_MAX_OBJECTS];
  gr_mesh_memo memo[GR_SNOW_DEFORMATION_MAX_OBJECTS]; /* each object's mesh as last checked */
  int nobjects;
  double force[GR_SNOW_DEFORMATION_MAX_OBJECTS][3], area[GR_SNOW_DEFORMATION_MAX_OBJECTS];
  /* Since the last clear_impulses: each object's impulse (N s), its largest
   * step force (N) and the time the steps took (s). */
  double impulse[GR_SNOW_DEFORMATION_MAX_OBJECTS][3], peak[GR_SNOW_DEFORMATION_MAX_OBJECTS];
  double impulse_time;
  double time, compressed, displaced;
  /* The snow at the start over the piece's own points: quanta, and
   * 2^-24 kg/m^2 (snow_ledger_reduce's fixed point). */
  long long initial_q, initial_m;
  /* Displaced snow not yet deposited (the rounding to whole quanta), per
   * unit cell area, and its mass. */
  double pending, pending_mass;
  long long steps;
  int relax_iterations;
  int relax_full; /* the next relaxation covers the whole grid */
  /* x0 y0 x1 y1: the box where the last relaxation stopped at its cap with
   * snow still able to move (x0 > x1: nowhere); the next one starts there
   * too, so that no window ever leaves out a point that can move. */
  int rest[4];
  int sync_full; /* the state's other buffer may differ anywhere */
  /* The talus' reach this step (gr_snow_relax_reach): on, its box (x0 y0
   * x1 y1, local) cut to the local arrays and whole (the domain's box, the
   * same on every piece), the mask in `weight`, the ceilings in `scratch`;
   * halo_reach: the exchange carries the mask. */
  int reach_on, reach_box[4], reach_all[4], halo_reach;
  int dirty[4];   /* x0 y0 x1 y1: where the last step's objects wrote */
  int reset_full; /* the next step clears the per-step arrays everywhere */
  gr_progress_fn progress;
  void *progress_user;
  int aborted;
  int timing; /* per-stage timing on: wait after each stage */
  double t_mark;
  gr_snow_deformation_timing tm;
  char error[1024];
};

#define GR_SNOW_KEEP_ERROR(s, st) gr_error_keep((s)->error, sizeof((s)->error), (st))
#define GR_SNOW_ARG(s, k, name, var) gr_kernel_arg((s)->ctx, (k), (name), sizeof(var), &(var))

const gr_param_bound *gr_snow_deformation_param_bounds(int *count) {
  if (count)
    *count = GR_SNOW_P_COUNT;
  return gr_snow_bounds;
}

const char *gr_snow_deformation_last_error(const gr_snow_deformation *s) {
  return s ? s->error : "";
}

void gr_snow_deformation_params_init(gr_snow_deformation_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  const gr_param_bound *t = gr_snow_bounds;
  p->initial_snow_depth = t[GR_SNOW_P_INITIAL_DEPTH].default_value;
  p->initial_density = t[GR_SNOW_P_INITIAL_DENSITY].default_value;
  p->min_density = t[GR_SNOW_P_MIN_DENSITY].default_value;
  p->max_density = t[GR_SNOW_P_MAX_DENSITY].default_value;
  p->compression_model = (int)t[GR_SNOW_P_COMPRESSION].default_value;
  p->max_slope = t[GR_SNOW_P_MAX_SLOPE].default_value;
  p->direction_falloff = t[GR_SNOW_P_FALLOFF].default_value;
  p->max_relax_iterations = (int)t[GR_SNOW_P_ITERATIONS].default_value;
  p->relax_tolerance = t[GR_SNOW_P_TOLERANCE].default_value;
  p->slump_speed = t[GR_SNOW_P_SLUMP].default_value;
}

static double gr_snow_param_value(const gr_snow_deformation_params *p, int row) {
  switch (row) {
  case GR_SNOW_P_INITIAL_DEPTH:
    return p->initial_snow_depth;
  case GR_SNOW_P_INITIAL_DENSITY:
    return p->initial_density;
  case GR_SNOW_P_MIN_DENSITY:
    return p->min_density;
  case GR_SNOW_P_MAX_DENSITY:
    return p->max_density;
  case GR_SNOW_P_COMPRESSION:
    return (double)p->compression_model;
  case GR_SNOW_P_MAX_SLOPE:
    return p->max_slope;
  case GR_SNOW_P_FALLOFF:
    return p->direction_falloff;
  case GR_SNOW_P_ITERATIONS:
    return (double)p->max_relax_iterations;
  case GR_SNOW_P_SLUMP:
    return p->slump_speed;
  default:
    return p->relax_tolerance;
  }
}

gr_status gr_snow_deformation_params_validate(const gr_snow_deformation_params *p, char *msg,
                                              size_t msg_len) {
  if (!p) {
    if (msg && msg_len)
      snprintf(msg, msg_len, "Invalid snow deformation parameters: no parameters were given.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  for (int row = 0; row < GR_SNOW_P_COUNT; ++row) {
    const gr_param_bound *r = &gr_snow_bounds[row];
    double v = gr_snow_param_value(p, row);
    if (gr_param_accepts(r, v))
      continue;
    gr_param_explain(r, v, "Invalid snow deformation parameters", msg, msg_len);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (p->min_density > p->max_density) {
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "Invalid snow deformation parameters: MinDensity (%g kg/m^3) must not exceed "
               "MaxDensity (%g kg/m^3); swap the two ends of DensityRange.",
               p->min_density, p->max_density);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (p->initial_density < p->min_density || p->initial_density > p->max_density) {
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "Invalid snow deformation parameters: InitialDensity must lie within DensityRange "
               "%g to %g kg/m^3 (got %g kg/m^3).",
               p->min_density, p->max_density, p->initial_density);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

static double gr_snow_now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* With timing on: waits for the stage just enqueued and charges its time. */
static gr_status gr_snow_mark(gr_snow_deformation *s, double *acc) {
  if (!s->timing)
    return GR_OK;
  gr_status st = gr_finish(s->ctx);
  double t = gr_snow_now_ms();
  *acc += t - s->t_mark;
  s->t_mark = t;
  return st;
}

void gr_snow_deformation_set_blocked(gr_snow_deformation *s, int on) {
  if (s)
    s->blocked = on != 0;
}

void gr_snow_deformation_set_group(gr_snow_deformation *s, int on) {
  if (s)
    s->group = on != 0;
}

void gr_snow_deformation_set_timing(gr_snow_deformation *s, int on) {
  if (!s)
    return;
  s->timing = on != 0;
  memset(&s->tm, 0, sizeof(s->tm));
}

gr_status gr_snow_deformation_timing_get(const gr_snow_deformation *s,
                                         gr_snow_deformation_timing *out) {
  if (!s || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_timing_get needs a simulation and a place for the "
                        "times.");
  *out = s->tm;
  return GR_OK;
}

static size_t gr_snow_cells(const gr_snow_deformation *s) {
  return (size_t)s->grid.nx * (size_t)s->grid.ny;
}

static gr_status gr_snow_fill(gr_snow_deformation *s, cl_mem buf, float value) {
  return gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), buf, &value, sizeof(value), 0,
                                         gr_snow_cells(s) * sizeof(float), 0, NULL, NULL),
                     "Filling a device buffer");
}

static gr_status gr_snow_copy(gr_snow_deformation *s, cl_mem from, cl_mem to) {
  return gr_cl_check(s->ctx,
                     clEnqueueCopyBuffer(gr_context_queue(s->ctx), from, to, 0, 0,
                                         gr_snow_cells(s) * sizeof(float), 0, NULL, NULL),
                     "Copying a device buffer");
}

/* Depths to whole quanta (snow_deformation_shared.h). */
static gr_status gr_snow_quantize(gr_snow_deformation *s, cl_mem depth) {
  cl_int n = (cl_int)gr_snow_cells(s);
  gr_status st = GR_SNOW_ARG(s, s->quantize, "n", n);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->quantize, "depth", depth);
  if (st == GR_OK)
    st = gr_enqueue_1d(s->ctx, s->quantize, (size_t)n);
  return st;
}

/* The state (depth and density) of points [x0, x1] x [y0, y1] from the
 * current buffer of the pair to the other one. */
static gr_status gr_snow_sync_rect(gr_snow_deformation *s, int x0, int y0, int x1, int y1) {
  if (x0 > x1 || y0 > y1)
    return GR_OK;
  size_t origin[3] = {(size_t)x0 * sizeof(float), (size_t)y0, 0};
  size_t region[3] = {(size_t)(x1 - x0 + 1) * sizeof(float), (size_t)(y1 - y0 + 1), 1};
  size_t pitch = (size_t)s->grid.nx * sizeof(float);
  cl_int err = CL_SUCCESS;
  for (int q = 0; q < 2 && err == CL_SUCCESS; ++q) {
    cl_mem *pair = q ? s->density : s->depth;
    err = clEnqueueCopyBufferRect(gr_context_queue(s->ctx), pair[s->cur], pair[1 - s->cur], origin,
                                  origin, region, pitch, 0, pitch, 0, 0, NULL, NULL);
  }
  return gr_cl_check(s->ctx, err, "Copying a window of the snow state");
}

/* sum S (quanta) and sum S rho (2^-24 kg/m^2) over the piece's own points
 * (every point of a whole grid). */
static gr_status gr_snow_ledger_sums(gr_snow_deformation *s, long long *vol, long long *mass) {
  cl_int nx = s->grid.nx, x0 = s->ring[0], y0 = s->ring[2], w = s->own_nx, n = w * s->own_ny;
  const cl_kernel k = s->ledger_reduce;
  gr_status st = GR_SNOW_ARG(s, k, "depth", s->depth[s->cur]);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "density", s->density[s->cur]);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "nx", nx);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "x0", x0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "y0", y0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "w", w);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "n", n);
  long long sums[GR_SNOW_LEDGER_SUMS];
  if (st == GR_OK)
    st = gr_reduction_i64_run(s->ctx, &s->red_ledger, k, sums);
  if (st == GR_OK) {
    *vol = sums[0];
    *mass = sums[1];
  }
  return st;
}

static gr_status gr_snow_initial_state(gr_snow_deformation *s) {
  s->cur = 0;
  gr_status st = gr_snow_copy(s, s->depth0, s->depth[0]);
  if (st == GR_OK)
    st = gr_snow_copy(s, s->density0, s->density[0]);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->overlap_sum, 0.0f);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->contact, 0.0f);
  s->time = s->compressed = s->displaced = s->pending = s->pending_mass = 0.0;
  s->steps = 0;
  s->relax_iterations = 0;
  s->relax_full = 1;
  s->rest[0] = s->rest[1] = 0;
  s->rest[2] = s->rest[3] = -1;
  s->sync_full = 1;
  s->reset_full = 1;
  s->aborted = 0;
  memset(s->force, 0, sizeof(s->force));
  memset(s->area, 0, sizeof(s->area));
  gr_snow_deformation_clear_impulses(s);
  if (st == GR_OK)
    st = gr_snow_ledger_sums(s, &s->initial_q, &s->initial_m);
  return st;
}

/* ------------------------------------------------------ pieces and halos */

/* The piece contract (graupel.h, snow_deformation.h): which sides have a
 * neighbour, and so a ring of GR_SNOW_DEFORMATION_GHOST points. */
static gr_status gr_snow_piece_rings(const gr_grid *g, int ring[4], char *msg, size_t len) {
  long long gnx = g->global_nx > 0 ? g->global_nx : g->nx;
  long long gny = g->global_ny > 0 ? g->global_ny : g->ny;
  int whole_x = g->global_nx <= 0, whole_y = g->global_ny <= 0;
  const int G = GR_SNOW_DEFORMATION_GHOST;
  memset(ring, 0, 4 * sizeof(int));
  if (g->global_nx < 0 || g->global_ny < 0 || g->ghost < 0 || g->i0 < 0 || g->j0 < 0) {
    snprintf(msg, len,
             "Invalid grid: i0, j0, global_nx, global_ny and ghost must be 0 or more (got %d, "
             "%d, %d, %d, %d).",
             g->i0, g->j0, g->global_nx, g->global_ny, g->ghost);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if ((whole_x && g->i0 != 0) || (whole_y && g->j0 != 0) ||
      (!whole_x && (long long)g->i0 + g->nx > gnx) ||
      (!whole_y && (long long)g->j0 + g->ny > gny)) {
    snprintf(msg, len,
             "Invalid grid: the piece of %d x %d points at (%d, %d) reaches beyond the domain of "
             "%lld x %lld points; give global_nx and global_ny of the whole domain.",
             g->nx, g->ny, g->i0, g->j0, gnx, gny);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (!whole_x) {
    ring[0] = g->i0 > 0 ? G : 0;
    ring[1] = (long long)g->i0 + g->nx < gnx ? G : 0;
  }
  if (!whole_y) {
    ring[2] = g->j0 > 0 ? G : 0;
    ring[3] = (long long)g->j0 + g->ny < gny ? G : 0;
  }
  int any = ring[0] || ring[1] || ring[2] || ring[3];
  if (any && g->ghost != G) {
    snprintf(msg, len,
             "Invalid grid: a snow deformation piece with neighbours needs a ghost ring of %d "
             "points (got ghost = %d); set grid.ghost to %d.",
             G, g->ghost, G);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (((ring[0] || ring[1]) && g->nx < G) || ((ring[2] || ring[3]) && g->ny < G)) {
    snprintf(msg, len,
             "Invalid grid: a snow deformation piece of %d x %d points is narrower than its "
             "ghost ring of %d toward a neighbour; split the domain into fewer pieces.",
             g->nx, g->ny, G);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

static int gr_snow_has_ring(const gr_snow_deformation *s) {
  return s->ring[0] || s->ring[1] || s->ring[2] || s->ring[3];
}

/* Cuts the window [*x0, *x1] x [*y0, *y1] of the local arrays to the
 * piece's own points (nothing to cut on a whole grid). */
static void gr_snow_own_clip(const gr_snow_deformation *s, int *x0, int *y0, int *x1, int *y1) {
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

static gr_status gr_snow_allreduce(gr_snow_deformation *s, double *values, int n, gr_reduce_op op) {
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
static gr_status gr_snow_allreduce_i64(gr_snow_deformation *s, long long *v, int n) {
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
static gr_status gr_snow_piece_sync(gr_snow_deformation *s) {
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

/* The points of a halo strip on `side`: GR_SNOW_DEFORMATION_GHOST columns
 * by the local arrays' rows (west, east), or their columns by
 * GR_SNOW_DEFORMATION_GHOST rows (south, north); 0 where the side has no
 * neighbour. */
static size_t gr_snow_strip_cells(const gr_snow_deformation *s, int side, size_t *w, size_t *h) {
  if (side < 0 || side > 3 || !s->ring[side])
    return 0;
  *w = side < 2 ? (size_t)GR_SNOW_DEFORMATION_GHOST : (size_t)s->grid.nx;
  *h = side < 2 ? (size_t)s->grid.ny : (size_t)GR_SNOW_DEFORMATION_GHOST;
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
 * between the device and a packed host block; waits. */
static gr_status gr_snow_rect(gr_snow_deformation *s, cl_mem buf, size_t x0, size_t y0, size_t w,
                              size_t h, void *host, int write) {
  const size_t f = sizeof(cl_float), pitch = (size_t)s->grid.nx * f;
  size_t origin[3] = {x0 * f, y0, 0}, host_origin[3] = {0, 0, 0}, region[3] = {w * f, h, 1};
  cl_command_queue q = gr_context_queue(s->ctx);
  cl_int err = write ? clEnqueueWriteBufferRect(q, buf, CL_TRUE, origin, host_origin, region, pitch,
                                                0, w * f, 0, host, 0, NULL, NULL)
                     : clEnqueueReadBufferRect(q, buf, CL_TRUE, origin, host_origin, region, pitch,
                                               0, w * f, 0, host, 0, NULL, NULL);
  return gr_cl_check(s->ctx, err,
                     write ? "Writing a halo strip to the device"
                           : "Reading part of a field back from the device");
}

/* Reads the piece's own points of a local array (the whole array for a
 * grid without a ring). */
static gr_status gr_snow_read_own(gr_snow_deformation *s, cl_mem buf, float *host) {
  if (!gr_snow_has_ring(s))
    return gr_buffer_read(s->ctx, buf, 0, gr_snow_cells(s) * sizeof(float), host);
  return gr_snow_rect(s, buf, (size_t)s->ring[0], (size_t)s->ring[2], (size_t)s->own_nx,
                      (size_t)s->own_ny, host, 0);
}

/* Copies one side's strip between the device and the host: from the own
 * points next to the side (get: the state's depth and density), or into
 * the ring on that side (set: both buffers of each pair, so that the
 * talus' second buffer equals the state there, as it must outside a
 * launch's window). */
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
  const size_t g = GR_SNOW_DEFORMATION_GHOST, nxl = (size_t)s->grid.nx, nyl = (size_t)s->grid.ny;
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
  unsigned char *at = host;
  gr_status st = GR_OK;
  for (int a = 0; st == GR_OK && a < GR_SNOW_HALO_ARRAYS; ++a) {
    cl_mem *pair = a ? s->density : s->depth;
    if (s->halo_reach) { /* the talus' reach mask in the depth's place (gr_snow_relax_reach) */
      if (a == 0)
        st = gr_snow_rect(s, s->weight, x0, y0, w, h, at, set);
      else if (!set)
        memset(at, 0, cells * sizeof(cl_float));
      at += cells * sizeof(cl_float);
      continue;
    }
    st = gr_snow_rect(s, pair[s->cur], x0, y0, w, h, at, set);
    if (st == GR_OK && set)
      st = gr_snow_rect(s, pair[1 - s->cur], x0, y0, w, h, at, set);
    at += cells * sizeof(cl_float);
  }
  return st;
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

/* The talus launch's tile: 32 x 32 points on a CPU (its halo, 2 per
 * iteration on each side, then costs about as much again), 16 x 16 on a
 * GPU, smaller where the kernel's work-group or the local memory (8
 * planes of the tile and halo) does not allow it. */
static gr_status gr_snow_block_shape(gr_snow_deformation *s) {
  cl_device_id dev = gr_context_device(s->ctx);
  cl_device_type type = 0;
  cl_ulong local_mem = 0;
  size_t wg = 0;
  cl_int err = clGetDeviceInfo(dev, CL_DEVICE_TYPE, sizeof(type), &type, NULL);
  if (err == CL_SUCCESS)
    err = clGetDeviceInfo(dev, CL_DEVICE_LOCAL_MEM_SIZE, sizeof(local_mem), &local_mem, NULL);
  if (err == CL_SUCCESS)
    err = clGetKernelWorkGroupInfo(s->relax_block, dev, CL_KERNEL_WORK_GROUP_SIZE, sizeof(wg), &wg,
                                   NULL);
  if (err != CL_SUCCESS)
    return gr_cl_check(s->ctx, err, "Querying the device for the talus kernel's work-group");
  size_t t = (type & CL_DEVICE_TYPE_GPU) ? 16 : 64;
  for (; t > 1; t /= 2) {
    size_t side = t + 4 * GR_SNOW_BLOCK_ITERATIONS;
    if (t * t <= wg && 8 * side * side * sizeof(cl_float) <= local_mem)
      break;
  }
  if (t < 4)
    return gr_set_error(s->ctx, GR_ERR_TOO_LARGE,
                        "The OpenCL device offers too little local memory (%llu bytes) or too "
                        "small work-groups (%zu) for the snow talus kernel; pick another device.",
                        (unsigned long long)local_mem, wg);
  s->block[0] = s->block[1] = t;
  s->blocked = (type & CL_DEVICE_TYPE_GPU) != 0;
  /* The tail's work-group: as large as the device allows on a GPU (one
   * group holds one multiprocessor), 256 on a CPU (one core runs it). */
  wg = 0;
  err = clGetKernelWorkGroupInfo(s->relax_group, dev, CL_KERNEL_WORK_GROUP_SIZE, sizeof(wg), &wg,
                                 NULL);
  if (err != CL_SUCCESS)
    return gr_cl_check(s->ctx, err, "Querying the device for the talus kernel's work-group");
  size_t g = (type & CL_DEVICE_TYPE_GPU) ? 1024 : 256;
  s->group_size = g < wg ? g : wg;
  s->group = s->group_size >= 32;
  s->group_area = (type & CL_DEVICE_TYPE_GPU) ? GR_SNOW_GROUP_AREA_GPU : GR_SNOW_GROUP_AREA_CPU;
  return GR_OK;
}

/* Correctly rounded division and square root where the device offers
 * them (OpenCL allows 2.5 ulp otherwise, and NVIDIA's driver takes it):
 * the talus' decisions hinge on the rates' last bits, so with them a GPU
 * ends bit for bit where PoCL does (without, 7e-5 m apart after 40 steps
 * of the devices_agree trail). */
static const char *gr_snow_build_options(gr_context *ctx) {
  cl_device_fp_config fp = 0;
  if (clGetDeviceInfo(gr_context_device(ctx), CL_DEVICE_SINGLE_FP_CONFIG, sizeof(fp), &fp, NULL) ==
          CL_SUCCESS &&
      (fp & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT))
    return "-cl-fp32-correctly-rounded-divide-sqrt";
  return "";
}

/* The planes of a point that gr_snow_deformation_create allocates. */
#define GR_SNOW_PLANES 17

gr_status gr_snow_deformation_memory(const gr_grid *grid, gr_memory_need *out) {
  if (!grid || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_memory needs a grid and a place for the answer.");
  /* A piece's ring (at most grid->ghost points each way). */
  int ring = grid->ghost > 0 ? grid->ghost : 0;
  double n = ((double)grid->nx + 2.0 * ring) * ((double)grid->ny + 2.0 * ring);
  memset(out, 0, sizeof(*out));
  out->points = (double)grid->nx * (double)grid->ny;
  out->device = sizeof(float) * GR_SNOW_PLANES * n;
  out->largest = sizeof(float) * n;
  out->state = sizeof(float) * GR_SNOW_STATE_ARRAYS * n; /* gr_snow_state_bytes */
  return GR_OK;
}

gr_status gr_snow_deformation_create(gr_context *ctx, const gr_grid *grid,
                                     const gr_snow_deformation_params *p,
                                     gr_snow_deformation **out) {
  char msg[320];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_create needs a context and a place for the "
                        "simulation.");
  *out = NULL;
  if (gr_grid_validate(grid, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (gr_snow_deformation_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  int ring[4];
  if (gr_snow_piece_rings(grid, ring, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (((double)grid->nx + 2 * GR_SNOW_DEFORMATION_GHOST) *
          ((double)grid->ny + 2 * GR_SNOW_DEFORMATION_GHOST) >
      (double)INT_MAX / 2)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The snow deformation grid of %d x %d points is too large: the kernels "
                        "address at most about 1e9 points; coarsen it.",
                        grid->nx, grid->ny);
  gr_memory_need need;
  gr_snow_deformation_memory(grid, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The snow deformation of a %d x %d grid %s: use a smaller grid or "
                        "another device.",
                        grid->nx, grid->ny, msg);
  gr_snow_deformation *s = calloc(1, sizeof(*s));
  if (!s)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  s->ctx = gr_context_retain(ctx);
  s->grid = *grid;
  memcpy(s->ring, ring, sizeof(ring));
  s->own_nx = grid->nx;
  s->own_ny = grid->ny;
  s->gnx = grid->global_nx > 0 ? grid->global_nx : grid->nx;
  s->gny = grid->global_ny > 0 ? grid->global_ny : grid->ny;
  s->ox = grid->i0 - ring[0];
  s->oy = grid->j0 - ring[2];
  s->grid.nx = grid->nx + ring[0] + ring[1];
  s->grid.ny = grid->ny + ring[2] + ring[3];
  s->params = *p;
  size_t cells = gr_snow_cells(s), bytes = cells * sizeof(float);
  cl_program prog = NULL;
  gr_status st = gr_program_get(ctx, "snow_deformation", gr_snow_build_options(ctx), &prog);
  struct {
    const char *name;
    cl_kernel *k;
  } ks[] = {{"snow_raster", &s->raster},
            {"snow_raster_clear", &s->raster_clear},
            {"snow_overlap", &s->overlap_k},
            {"snow_contour", &s->contour},
            {"snow_object_reduce", &s->obj_reduce},
            {"snow_apply", &s->apply},
            {"snow_relax_rate", &s->relax_rate},
            {"snow_relax_move", &s->relax_move},
            {"snow_relax_block", &s->relax_block},
            {"snow_relax_group", &s->relax_group},
            {"snow_check_reduce", &s->check_reduce},
            {"snow_ledger_reduce", &s->ledger_reduce},
            {"snow_surface", &s->surface},
            {"snow_reset", &s->reset},
            {"snow_ring_reduce", &s->ring_reduce},
            {"snow_quantize", &s->quantize},
            {"snow_reach_rows", &s->reach_rows},
            {"snow_reach_cols", &s->reach_cols},
            {"snow_reach_seed", &s->reach_seed},
            {"snow_reach_ceiling", &s->reach_ceiling}};
  for (size_t i = 0; st == GR_OK && i < sizeof(ks) / sizeof(ks[0]); ++i)
    st = gr_kernel_create(ctx, prog, ks[i].name, ks[i].k);
  cl_mem *bufs[] = {&s->depth[0],    &s->depth[1], &s->density[0], &s->density[1], &s->ground,
                    &s->depth0,      &s->density0, &s->under,      &s->overlap,    &s->weight,
                    &s->overlap_sum, &s->contact,  &s->under_min,  &s->rate,       &s->rate_in,
                    &s->movable,     &s->scratch};
  _Static_assert(sizeof(bufs) / sizeof(bufs[0]) == GR_SNOW_PLANES,
                 "gr_snow_deformation_memory counts every plane");
  for (size_t i = 0; st == GR_OK && i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, bufs[i]);
  if (st == GR_OK)
    st = gr_snow_block_shape(s);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, 6 * sizeof(cl_int), NULL, &s->group_result);
  if (st == GR_OK)
    st = gr_reduction_i64_init(ctx, s->obj_reduce, cells, GR_SNOW_OBJ_SUMS, &s->red_obj);
  if (st == GR_OK)
    for (int q = 0; st == GR_OK && q <= GR_SNOW_CHECK_LAG; ++q)
      st = gr_reduction_init(ctx, s->check_reduce, cells, 0, GR_SNOW_CHECK_MAXES, &s->red_check[q]);
  if (st == GR_OK)
    st = gr_reduction_i64_init(ctx, s->ledger_reduce, cells, GR_SNOW_LEDGER_SUMS, &s->red_ledger);
  if (st == GR_OK)
    st = gr_reduction_i64_init(ctx, s->ring_reduce, cells, 4, &s->red_ring);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->ground, 0.0f);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->depth0, (float)p->initial_snow_depth);
  if (st == GR_OK)
    st = gr_snow_quantize(s, s->depth0);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->density0, (float)p->initial_density);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->overlap, 0.0f);
  if (st == GR_OK)
    st = gr_snow_initial_state(s);
  if (st != GR_OK) {
    gr_snow_deformation_destroy(s);
    return st;
  }
  *out = s;
  return GR_OK;
}

void gr_snow_deformation_destroy(gr_snow_deformation *s) {
  if (!s)
    return;
  cl_kernel ks[] = {s->raster,      s->raster_clear, s->overlap_k,    s->contour,
                    s->obj_reduce,  s->apply,        s->relax_rate,   s->relax_move,
                    s->relax_block, s->relax_group,  s->check_reduce, s->ledger_reduce,
                    s->surface,     s->reset,        s->ring_reduce,  s->quantize,
                    s->reach_rows,  s->reach_cols,   s->reach_seed,   s->reach_ceiling};
  for (size_t i = 0; i < sizeof(ks) / sizeof(ks[0]); ++i)
    if (ks[i])
      clReleaseKernel(ks[i]);
  cl_mem *bufs[] = {&s->depth[0],    &s->depth[1], &s->density[0], &s->density[1],  &s->ground,
                    &s->depth0,      &s->density0, &s->under,      &s->overlap,     &s->weight,
                    &s->overlap_sum, &s->contact,  &s->under_min,  &s->rate,        &s->rate_in,
                    &s->movable,     &s->scratch,  &s->tri,        &s->group_result};
  for (size_t i = 0; i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    gr_buffer_release(bufs[i]);
  gr_reduction_i64_release(&s->red_obj);
  for (int q = 0; q <= GR_SNOW_CHECK_LAG; ++q)
    gr_reduction_release(&s->red_check[q]);
  gr_reduction_i64_release(&s->red_ledger);
  gr_reduction_i64_release(&s->red_ring);
  for (int o = 0; o < GR_SNOW_DEFORMATION_MAX_OBJECTS; ++o)
    gr_mesh_memo_free(&s->memo[o]);
  gr_context_release(s->ctx);
  free(s);
}

gr_status gr_snow_deformation_set_params(gr_snow_deformation *s,
                                         const gr_snow_deformation_params *p) {
  char msg[320];
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_set_params needs a simulation.");
  if (gr_snow_deformation_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return GR_SNOW_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg));
  s->params = *p;
  s->relax_full = 1; /* a new MaxSlope may make any slope too steep */
  return GR_OK;
}

gr_status gr_snow_deformation_field_validate(const gr_snow_deformation_params *p, gr_field f,
                                             const float *values, size_t n, size_t nx, char *msg,
                                             size_t msg_len) {
  double lo, hi;
  const char *rule;
  char rule_text[200];
  const char *name = gr_field_name(f);
  if (!name)
    name = "(unknown field)";
  switch (f) {
  case GR_FIELD_ELEVATION:
    lo = -GR_SNOW_MAX_ELEVATION;
    hi = GR_SNOW_MAX_ELEVATION;
    rule = "elevations must be finite and within +-1e6 m";
    break;
  case GR_FIELD_SNOW_DEPTH:
    lo = 0.0;
    hi = GR_SNOW_MAX_DEPTH;
    rule = "snow depths must be finite, at least 0 and at most 1e4 m";
    break;
  case GR_FIELD_SNOW_DENSITY:
    if (!p) {
      if (msg && msg_len)
        snprintf(msg, msg_len,
                 "Checking the field 'snow_density' needs the parameters (its DensityRange); "
                 "pass them.");
      return GR_ERR_INVALID_ARGUMENT;
    }
    lo = (double)(float)p->min_density;
    hi = (double)(float)p->max_density;
    snprintf(rule_text, sizeof(rule_text),
             "snow densities must lie within DensityRange, %g to %g kg/m^3", lo, hi);
    rule = rule_text;
    break;
  default:
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "The field '%s' is not an input of the snow deformation simulation; its inputs "
               "are elevation, snow_depth and snow_density.",
               name);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return gr_field_check_range(name, values, n, nx, lo, hi, rule, msg, msg_len);
}

static gr_status gr_snow_set_field_impl(gr_snow_deformation *s, gr_field f, const float *host) {
  size_t cells = gr_snow_cells(s), nx = (size_t)s->grid.nx;
  char msg[512];
  if (gr_snow_deformation_field_validate(&s->params, f, host, cells, nx, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  size_t bytes = cells * sizeof(float);
  s->relax_full = 1; /* new snow or ground may be too steep anywhere */
  s->sync_full = 1;
  if (f == GR_FIELD_ELEVATION)
    return gr_buffer_write(s->ctx, s->ground, 0, bytes, host);
  /* The new snow replaces what is there: the ledger's initial volume and
   * mass move by the change, so the balance still closes. */
  long long v0, m0, v1, m1;
  gr_status st = gr_snow_ledger_sums(s, &v0, &m0);
  cl_mem init = f == GR_FIELD_SNOW_DEPTH ? s->depth0 : s->density0;
  cl_mem now = f == GR_FIELD_SNOW_DEPTH ? s->depth[s->cur] : s->density[s->cur];
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, init, 0, bytes, host);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, now, 0, bytes, host);
  if (st == GR_OK && f == GR_FIELD_SNOW_DEPTH)
    st = gr_snow_quantize(s, init);
  if (st == GR_OK && f == GR_FIELD_SNOW_DEPTH)
    st = gr_snow_quantize(s, now);
  if (st == GR_OK)
    st = gr_snow_ledger_sums(s, &v1, &m1);
  if (st == GR_OK) {
    s->initial_q += v1 - v0;
    s->initial_m += m1 - m0;
  }
  return st;
}

gr_status gr_snow_deformation_set_field(gr_snow_deformation *s, gr_field f, const float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_set_field needs a simulation.");
  if (!host)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_set_field needs the field's values (got NULL)."));
  return GR_SNOW_KEEP_ERROR(s, gr_snow_set_field_impl(s, f, host));
}

/* The points [*lo, *hi] of a box [b0, b1] whose raster test may pass for
 * coordinates in [a, b] at spacing d (the kernel widens each triangle by one
 * spacing; one more here covers the rounding). Empty: *lo > *hi. */
static gr_status gr_snow_set_objects_impl(gr_snow_deformation *s, const gr_mesh *meshes, int n,
                                          const double *velocities) {
  char msg[320];
  if (n < 0 || n > GR_SNOW_DEFORMATION_MAX_OBJECTS || (n > 0 && !meshes))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_set_objects takes 0 to %d objects with their meshes "
                        "(got %d%s).",
                        GR_SNOW_DEFORMATION_MAX_OBJECTS, n,
                        n > 0 && !meshes ? " and no meshes" : "");
  size_t total = 0;
  for (int o = 0; o < n; ++o) {
    if (gr_mesh_check(&s->memo[o], &meshes[o], 1, msg, sizeof(msg)) != GR_OK)
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "Object %d: %s", o, msg);
    if (velocities)
      for (int a = 0; a < 3; ++a)
        if (!isfinite(velocities[3 * o + a]))
          return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                              "Object %d has a velocity that is not finite (component %d is %g); "
                              "give finite velocities in m/s.",
                              o, a, velocities[3 * o + a]);
    total += (size_t)meshes[o].ntriangles;
  }
  if (total > (size_t)INT_MAX / 9)
    return gr_set_error(s->ctx, GR_ERR_TOO_LARGE,
                        "The objects have %zu triangles, more than the core addresses; simplify "
                        "the meshes.",
                        total);
  int most_vertices = 0;
  for (int o = 0; o < n; ++o)
    most_vertices = meshes[o].nvertices > most_vertices ? meshes[o].nvertices : most_vertices;
  float *tri = total ? malloc(total * 9 * sizeof(float)) : NULL;
  double *world = most_vertices ? malloc((size_t)most_vertices * 3 * sizeof(double)) : NULL;
  if ((total && !tri) || (most_vertices && !world)) {
    free(tri);
    free(world);
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  gr_snow_object objs[GR_SNOW_DEFORMATION_MAX_OBJECTS];
  const gr_grid *g = &s->grid;
  size_t at = 0;
  for (int o = 0; o < n; ++o) {
    const gr_mesh *m = &meshes[o];
    const double *T = m->transform;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    objs[o].first = (int)at;
    objs[o].count = m->ntriangles;
    /* Each vertex once, relative to grid point (0, 0), where float keeps
     * its precision. */
    for (int q = 0; q < m->nvertices; ++q) {
      const float *v = m->vertices + 3 * q;
      double *w = world + 3 * q;
      for (int a = 0; a < 3; ++a)
        w[a] = T[a] * v[0] + T[4 + a] * v[1] + T[8 + a] * v[2] + T[12 + a];
      w[0] -= g->x0;
      w[1] -= g->y0;
    }
    for (int t = 0; t < m->ntriangles; ++t, ++at)
      for (int k = 0; k < 3; ++k) {
        const double *w = world + 3 * m->triangles[3 * t + k];
        for (int a = 0; a < 3; ++a) {
          tri[9 * at + 3 * k + a] = (float)w[a];
          lo[a] = w[a] < lo[a] ? w[a] : lo[a];
          hi[a] = w[a] > hi[a] ? w[a] : hi[a];
        }
      }
    /* The box in the whole domain's points, kept in the local arrays'
     * indices (for a piece it may lie partly or wholly beyond them: every
     * piece steps every object the domain has). */
    double fi0 = ceil(lo[0] / g->dx - 1.0), fi1 = floor(hi[0] / g->dx + 1.0);
    double fj0 = ceil(lo[1] / g->dy - 1.0), fj1 = floor(hi[1] / g->dy + 1.0);
    if (fi1 < 0 || fj1 < 0 || fi0 > s->gnx - 1 || fj0 > s->gny - 1) {
      objs[o].bi0 = objs[o].bj0 = 1;
      objs[o].bi1 = objs[o].bj1 = 0; /* wholly outside: touches nothing */
    } else {
      objs[o].bi0 = (int)fmax(0.0, fi0) - s->ox;
      objs[o].bi1 = (int)fmin(s->gnx - 1.0, fi1) - s->ox;
      objs[o].bj0 = (int)fmax(0.0, fj0) - s->oy;
      objs[o].bj1 = (int)fmin(s->gny - 1.0, fj1) - s->oy;
    }
    for (int a = 0; a < 3; ++a)
      objs[o].v[a] = velocities ? velocities[3 * o + a] : 0.0;
  }
  free(world);
  gr_status st = GR_OK;
  if (total > s->tri_cap) {
    gr_buffer_release(&s->tri);
    s->tri_cap = 0;
    st = gr_buffer_create(s->ctx, CL_MEM_READ_ONLY, total * 9 * sizeof(float), NULL, &s->tri);
    if (st == GR_OK)
      s->tri_cap = total;
  }
  if (st == GR_OK && total)
    st = gr_buffer_write(s->ctx, s->tri, 0, total * 9 * sizeof(float), tri);
  free(tri);
  if (st != GR_OK)
    return st;
  memcpy(s->objects, objs, (size_t)n * sizeof(objs[0]));
  if (n != s->nobjects) {
    memset(s->force, 0, sizeof(s->force));
    memset(s->area, 0, sizeof(s->area));
    gr_snow_deformation_clear_impulses(s);
  }
  s->nobjects = n;
  return GR_OK;
}

gr_status gr_snow_deformation_set_objects(gr_snow_deformation *s, const gr_mesh *meshes, int n,
                                          const double *velocities) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_set_objects needs a simulation.");
  return GR_SNOW_KEEP_ERROR(s, gr_snow_set_objects_impl(s, meshes, n, velocities));
}

/* A named kernel argument. */
typedef struct gr_snow_arg {
  const char *name;
  size_t size;
  const void *value;
} gr_snow_arg;

static gr_status gr_snow_args(gr_snow_deformation *s, cl_kernel k, const gr_snow_arg *args,
                              size_t n) {
  gr_status st = GR_OK;
  for (size_t q = 0; st == GR_OK && q < n; ++q)
    st = gr_kernel_arg(s->ctx, k, args[q].name, args[q].size, args[q].value);
  return st;
}

/* The press parameters both press kernels take. */
static gr_status gr_snow_press_args(gr_snow_deformation *s, cl_kernel k) {
  float rho_min = (float)s->params.min_density, rho_max = (float)s->params.max_density;
  float w_const = s->params.compression_model == GR_SNOW_COMPRESSION_CONSTANT
                      ? (float)(1.0 - GR_SNOW_DEFORMATION_CONSTANT_COMPRESSION)
                      : -1.0f;
  float gap = (float)GR_SNOW_DEFORMATION_CONTACT_GAP;
  gr_status st = GR_SNOW_ARG(s, k, "ground", s->ground);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "depth", s->depth[s->cur]);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "density", s->density[s->cur]);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "under", s->under);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "overlap", s->overlap);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "weight", s->weight);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "rho_min", rho_min);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "rho_max", rho_max);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "w_const", w_const);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "gap", gap);
  return st;
}

/* Grows the box of the points this step's objects wrote (their overlap
 * sum, contact and lowest underside), which the next step clears. */
static void gr_snow_dirty(gr_snow_deformation *s, int x0, int y0, int x1, int y1) {
  int *d = s->dirty;
  if (d[0] > d[2]) {
    d[0] = x0, d[1] = y0, d[2] = x1, d[3] = y1;
    return;
  }
  d[0] = d[0] < x0 ? d[0] : x0;
  d[1] = d[1] < y0 ? d[1] : y0;
  d[2] = d[2] > x1 ? d[2] : x1;
  d[3] = d[3] > y1 ? d[3] : y1;
}

/* The start of a step: the overlap sum and contact 0 and the lowest
 * underside +inf where the last step's objects wrote them (everywhere
 * after the state was set). */
static gr_status gr_snow_reset(gr_snow_deformation *s) {
  int nx = s->grid.nx, ny = s->grid.ny, *d = s->dirty;
  if (s->reset_full) {
    d[0] = d[1] = 0;
    d[2] = nx - 1;
    d[3] = ny - 1;
    s->reset_full = 0;
  }
  if (d[0] > d[2] || d[1] > d[3])
    return GR_OK;
  cl_kernel k = s->reset;
  cl_int x_end = d[2] + 1, y_end = d[3] + 1;
  gr_status st = GR_SNOW_ARG(s, k, "nx", nx);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "ny", ny);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "x_end", x_end);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "y_end", y_end);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "overlap_sum", s->overlap_sum);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "contact", s->contact);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "under_min", s->under_min);
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, k, (size_t)d[0], (size_t)d[1], (size_t)(d[2] - d[0] + 1),
                       (size_t)(d[3] - d[1] + 1), NULL);
  d[0] = d[1] = 0;
  d[2] = d[3] = -1; /* clean */
  return st;
}

/* The contour window of an object's step: [x0, x0 + w) x [y0, y0 + h) of
 * the local arrays (on: not empty), and the piece's own points of it for
 * the sums: from (rx0, ry0), rw wide, rn in all. */
typedef struct gr_snow_cwin {
  size_t x0, y0, w, h;
  cl_int x_end, y_end, rx0, ry0, rw, rn;
  int on;
} gr_snow_cwin;

/* Rings a deposit goes out at most (gr_snow_deposit); what is left after
 * them waits for the next press, as the rounding's rest does. */
#define GR_SNOW_DEPOSIT_RINGS 64

/* The contour weights of ring `ring` (snow_contour) on the window. */
static gr_status gr_snow_contour_ring(gr_snow_deformation *s, const gr_snow_cwin *win, cl_int ring,
                                      float vx, float vy, float rest) {
  cl_int nx = s->grid.nx, ny = s->grid.ny;
  float gap = (float)GR_SNOW_DEFORMATION_CONTACT_GAP, clearance = 2.0f * gap;
  const gr_snow_arg args[] = {{"ground", sizeof(cl_mem), &s->ground},
                              {"depth", sizeof(cl_mem), &s->depth[s->cur]},
                              {"under", sizeof(cl_mem), &s->under},
                              {"under_min", sizeof(cl_mem), &s->under_min},
                              {"overlap", sizeof(cl_mem), &s->overlap},
                              {"nx", sizeof(nx), &nx},
                              {"ny", sizeof(ny), &ny},
                              {"vx", sizeof(vx), &vx},
                              {"vy", sizeof(vy), &vy},
                              {"rest", sizeof(rest), &rest},
                              {"gap", sizeof(gap), &gap},
                              {"clearance", sizeof(clearance), &clearance},
                              {"ring", sizeof(ring), &ring},
                              {"x_end", sizeof(cl_int), &win->x_end},
                              {"y_end", sizeof(cl_int), &win->y_end},
                              {"weight", sizeof(cl_mem), &s->weight}};
  gr_status st = gr_snow_args(s, s->contour, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->contour, win->x0, win->y0, win->w, win->h, NULL);
  return st;
}

/* After a ring's deposit (and the next ring's weights), over the domain
 * (snow_ring_reduce): q[0] the quanta the ring received, q[1] its points
 * that got less than their share, q[2] the next ring's weights (units of
 * 2^-20), q[3] its points. */
static gr_status gr_snow_ring_sums(gr_snow_deformation *s, const gr_snow_cwin *win,
                                   long long q[4]) {
  cl_int nx = s->grid.nx;
  const gr_snow_arg args[] = {
      {"got", sizeof(cl_mem), &s->scratch},   {"full", sizeof(cl_mem), &s->movable},
      {"weight", sizeof(cl_mem), &s->weight}, {"nx", sizeof(nx), &nx},
      {"x0", sizeof(cl_int), &win->rx0},      {"y0", sizeof(cl_int), &win->ry0},
      {"w", sizeof(cl_int), &win->rw},        {"n", sizeof(cl_int), &win->rn}};
  gr_status st = gr_snow_args(s, s->ring_reduce, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK)
    st = gr_reduction_i64_run(s->ctx, &s->red_ring, s->ring_reduce, q);
  if (st == GR_OK)
    st = gr_snow_allreduce_i64(s, q, 4);
  return st;
}

/* snow_apply on the window: ring 0 presses (press) and deposits, a later
 * ring only deposits; each point's deposit to scratch, its lack of room to
 * movable (for gr_snow_ring_sums). */
static gr_status gr_snow_apply_ring(gr_snow_deformation *s, const gr_snow_cwin *win, cl_int ring,
                                    cl_int press, float add_depth, float add_rho) {
  cl_int nx = s->grid.nx, ny = s->grid.ny;
  float clearance = (float)(2.0 * GR_SNOW_DEFORMATION_CONTACT_GAP);
  const gr_snow_arg args[] = {{"clearance", sizeof(clearance), &clearance},
                              {"add_depth", sizeof(add_depth), &add_depth},
                              {"add_rho", sizeof(add_rho), &add_rho},
                              {"press", sizeof(press), &press},
                              {"ring", sizeof(ring), &ring},
                              {"nx", sizeof(nx), &nx},
                              {"ny", sizeof(ny), &ny},
                              {"x_end", sizeof(cl_int), &win->x_end},
                              {"y_end", sizeof(cl_int), &win->y_end},
                              {"overlap_sum", sizeof(cl_mem), &s->overlap_sum},
                              {"contact", sizeof(cl_mem), &s->contact},
                              {"under_min", sizeof(cl_mem), &s->under_min},
                              {"got", sizeof(cl_mem), &s->scratch},
                              {"full", sizeof(cl_mem), &s->movable}};
  gr_status st = gr_snow_press_args(s, s->apply);
  if (st == GR_OK)
    st = gr_snow_args(s, s->apply, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->apply, win->x0, win->y0, win->w, win->h, NULL);
  return st;
}

/* An object's press and deposit (header, steps 4 to 6): give (per unit
 * cell area: the displaced snow and what waited) goes to the contour at
 * add_depth per unit weight, each point taking at most its room under the
 * objects (snow_room: snow is never put under an object up to its
 * underside). What did not fit under an overhang goes on to the next ring
 * out, the points bordering the full ones, with the same direction
 * weights (or evenly, where none faces the motion), ring by ring until it
 * is placed: at most GR_SNOW_DEPOSIT_RINGS rings, and what is left (the
 * rounding to whole quanta, less than a quantum a point) waits for the
 * next press. One read-back a ring: its deposit and the next ring's
 * weights together. Every decision is on global integer sums: the same on
 * every split. */
static gr_status gr_snow_deposit(gr_snow_deformation *s, const gr_snow_cwin *win, cl_int press,
                                 float add_depth, float add_rho, double give, float vx, float vy,
                                 float rest) {
  const double quantum = 1.0 / GR_SNOW_QUANTUM_INV;
  long long q[4] = {0, 0, 0, 0};
  gr_status st = GR_OK;
  double left = give;
  for (cl_int ring = 0; st == GR_OK; ++ring) {
    if (win->on)
      st = gr_snow_apply_ring(s, win, ring, press, add_depth, add_rho);
    /* A piece's ring: the contour and the deposits beside its outer edge
     * lacked their neighbours; the neighbours' own points replace them. */
    if (st == GR_OK)
      st = gr_snow_piece_sync(s);
    if (st != GR_OK || add_depth <= 0.0f)
      return st; /* nothing deposited: what waits still waits */
    if (win->on)
      st = gr_snow_contour_ring(s, win, ring + 1, vx, vy, rest);
    if (st == GR_OK)
      st = gr_snow_ring_sums(s, win, q);
    if (st != GR_OK)
      break;
    left -= (double)q[0] * quantum;
    if (q[1] == 0 || ring == GR_SNOW_DEPOSIT_RINGS)
      break;                     /* all placed but the rounding's rest, or the last ring */
    if (q[3] > 0 && q[2] == 0) { /* no point of the next ring faces the motion: evenly */
      if (win->on)
        st = gr_snow_contour_ring(s, win, ring + 1, vx, vy, 1.0f);
      if (st == GR_OK)
        st = gr_snow_ring_sums(s, win, q);
    }
    if (st != GR_OK || q[2] <= 0)
      break; /* no ring left on the grid */
    double per = left / ((double)q[2] / GR_SNOW_WEIGHT_INV);
    add_depth = (float)per;
    if ((double)add_depth > per)
      add_depth = nextafterf(add_depth, 0.0f);
  }
  /* The rest waits for the next press (and counts in the ledger). */
  s->pending_mass = left > 0.0 ? left * add_rho : 0.0;
  s->pending = left > 0.0 ? left : 0.0;
  return st;
}

static gr_status gr_snow_object_step(gr_snow_deformation *s, int o, double dt) {
  const gr_snow_object *ob = &s->objects[o];
  gr_context *ctx = s->ctx;
  int nx = s->grid.nx, ny = s->grid.ny;
  float dx = (float)s->grid.dx, dy = (float)s->grid.dy;
  s->area[o] = 0.0;
  if (ob->bi0 > ob->bi1 || ob->bj0 > ob->bj1)
    return GR_OK; /* wholly off the (whole) grid: it touches nothing, on every piece */
  /* The kernels run on the object's box grown by two (W: the underside,
   * +inf beyond the box, and the overlap, 0 there) and by one (the contour
   * ring and everything that reads the contour). Outside W nothing changes,
   * and the step's reset clears W again. On a piece the windows are cut to
   * the local arrays, ring included, and may be empty there: the piece
   * still takes part in the object's global sums and halo exchange. */
  int wx0 = ob->bi0 - 2 > 0 ? ob->bi0 - 2 : 0, wy0 = ob->bj0 - 2 > 0 ? ob->bj0 - 2 : 0;
  int wx1 = ob->bi1 + 2 < nx - 1 ? ob->bi1 + 2 : nx - 1,
      wy1 = ob->bj1 + 2 < ny - 1 ? ob->bj1 + 2 : ny - 1;
  int cx0 = ob->bi0 - 1 > 0 ? ob->bi0 - 1 : 0, cy0 = ob->bj0 - 1 > 0 ? ob->bj0 - 1 : 0;
  int cx1 = ob->bi1 + 1 < nx - 1 ? ob->bi1 + 1 : nx - 1,
      cy1 = ob->bj1 + 1 < ny - 1 ? ob->bj1 + 1 : ny - 1;
  int w_on = wx0 <= wx1 && wy0 <= wy1, c_on = cx0 <= cx1 && cy0 <= cy1;
  size_t WX0 = (size_t)wx0, WY0 = (size_t)wy0, WW = (size_t)(wx1 - wx0 + 1),
         WH = (size_t)(wy1 - wy0 + 1), CX0 = (size_t)cx0, CY0 = (size_t)cy0,
         CW = (size_t)(cx1 - cx0 + 1), CH = (size_t)(cy1 - cy0 + 1);
  /* A launch is rounded up to whole work-groups: the kernels stop at the
   * window's end, as what lies beyond is another object's or step's. */
  cl_int wx_end = wx1 + 1, wy_end = wy1 + 1, cx_end = cx1 + 1, cy_end = cy1 + 1;
  /* The raster's box and loop in the domain's indices (the same floats on
   * every piece), cut to the local arrays. */
  cl_int first = ob->first, count = ob->count, ox = s->ox, oy = s->oy;
  cl_int bi0 = (ob->bi0 > 0 ? ob->bi0 : 0) + ox, bi1 = (ob->bi1 < nx - 1 ? ob->bi1 : nx - 1) + ox,
         bj0 = (ob->bj0 > 0 ? ob->bj0 : 0) + oy, bj1 = (ob->bj1 < ny - 1 ? ob->bj1 : ny - 1) + oy;
  gr_status st = GR_OK;
  if (w_on) {
    gr_snow_dirty(s, wx0, wy0, wx1, wy1);
    st = GR_SNOW_ARG(s, s->raster_clear, "nx", nx);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->raster_clear, "ny", ny);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->raster_clear, "x_end", wx_end);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->raster_clear, "y_end", wy_end);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->raster_clear, "under", s->under);
    if (st == GR_OK)
      st = gr_enqueue_2d(ctx, s->raster_clear, WX0, WY0, WW, WH, NULL);
  }
  const gr_snow_arg raster[] = {{"tri", sizeof(cl_mem), &s->tri},
                                {"first", sizeof(first), &first},
                                {"count", sizeof(count), &count},
                                {"nx", sizeof(nx), &nx},
                                {"dx", sizeof(dx), &dx},
                                {"dy", sizeof(dy), &dy},
                                {"bi0", sizeof(bi0), &bi0},
                                {"bi1", sizeof(bi1), &bi1},
                                {"bj0", sizeof(bj0), &bj0},
                                {"bj1", sizeof(bj1), &bj1},
                                {"ox", sizeof(ox), &ox},
                                {"oy", sizeof(oy), &oy},
                                {"under", sizeof(cl_mem), &s->under}};
  if (st == GR_OK && bi0 <= bi1 && bj0 <= bj1 && count > 0) {
    st = gr_snow_args(s, s->raster, raster, sizeof(raster) / sizeof(raster[0]));
    if (st == GR_OK)
      st = gr_enqueue_1d(ctx, s->raster, (size_t)count); /* one work-item per triangle */
  }
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.raster_ms);
  /* overlap */
  if (st == GR_OK && w_on) {
    st = GR_SNOW_ARG(s, s->overlap_k, "ground", s->ground);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "depth", s->depth[s->cur]);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "under", s->under);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "nx", nx);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "ny", ny);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "overlap", s->overlap);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "x_end", wx_end);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "y_end", wy_end);
    if (st == GR_OK)
      st = gr_enqueue_2d(ctx, s->overlap_k, WX0, WY0, WW, WH, NULL);
  }
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.press_ms);
  /* contour and weights */
  double vn = sqrt(ob->v[0] * ob->v[0] + ob->v[1] * ob->v[1] + ob->v[2] * ob->v[2]);
  double ux = 0.0, uy = 0.0, uz = -1.0; /* at rest: straight down, a uniform ring */
  if (vn > 0.0) {
    ux = ob->v[0] / vn;
    uy = ob->v[1] / vn;
    uz = ob->v[2] / vn;
  }
  float vx = (float)ux, vy = (float)uy, rest = (float)(uz * uz / s->params.direction_falloff);
  gr_snow_cwin win = {CX0, CY0, CW, CH, cx_end, cy_end, 0, 0, 1, 0, c_on};
  if (st == GR_OK && c_on)
    st = gr_snow_contour_ring(s, &win, 0, vx, vy, rest);
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.contour_ms);
  /* Totals over the piece's own points of the contour window (fixed point:
   * the same integers however the domain is split), then over the
   * domain. */
  long long q[GR_SNOW_OBJ_SUMS];
  int rx0 = cx0, ry0 = cy0, rx1 = cx1, ry1 = cy1;
  gr_snow_own_clip(s, &rx0, &ry0, &rx1, &ry1);
  cl_int cw = rx1 - rx0 + 1, cn = rx0 <= rx1 && ry0 <= ry1 ? cw * (ry1 - ry0 + 1) : 0;
  cw = cw > 0 ? cw : 1;
  win.rx0 = rx0, win.ry0 = ry0, win.rw = cw, win.rn = cn;
  if (st == GR_OK)
    st = gr_snow_press_args(s, s->obj_reduce);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->obj_reduce, "nx", nx);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->obj_reduce, "x0", rx0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->obj_reduce, "y0", ry0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->obj_reduce, "w", cw);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->obj_reduce, "n", cn);
  if (st == GR_OK)
    st = gr_reduction_i64_run(ctx, &s->red_obj, s->obj_reduce, q);
  if (st == GR_OK)
    st = gr_snow_allreduce_i64(s, q, GR_SNOW_OBJ_SUMS);
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.press_ms);
  if (st != GR_OK)
    return st;
  /* sums, per unit cell area: 0 e, 1 e rho, 2 weights, 3 contour points,
   * 4 D rho, 5 D - e, 6 contact points */
  const double quantum = 1.0 / GR_SNOW_QUANTUM_INV, press_mass = 1.0 / GR_SNOW_PRESS_MASS_INV;
  double sums[GR_SNOW_OBJ_SUMS] = {(double)q[0] * quantum,
                                   (double)q[1] * press_mass,
                                   (double)q[2] / GR_SNOW_WEIGHT_INV,
                                   (double)q[3],
                                   (double)q[4] * press_mass,
                                   (double)q[5] * quantum,
                                   (double)q[6]};
  double area = s->grid.dx * s->grid.dy;
  int press = sums[3] > 0.0 && sums[2] > 0.0 && sums[0] > 0.0;
  if (sums[0] <= 0.0 && sums[5] > 0.0)
    press = 1; /* all compressed, nothing to distribute */
  float add_depth = 0.0f, add_rho = (float)s->params.max_density;
  /* What the contour receives: this object's displaced snow and what the
   * rounding to whole quanta kept back before (pending), per unit weight,
   * rounded down so that the contour never receives more. */
  double give = sums[0] + s->pending;
  if (press && sums[2] > 0.0 && sums[0] > 0.0) {
    double per = give / sums[2];
    add_depth = (float)per;
    if ((double)add_depth > per)
      add_depth = nextafterf(add_depth, 0.0f);
    add_rho = (float)fmin(s->params.max_density, sums[1] / sums[0]);
  }
  if (press) {
    s->compressed += sums[5] * area;
    s->displaced += sums[0] * area;
    double m = sums[4] * area;
    for (int a = 0; a < 3; ++a)
      s->force[o][a] += -m * ob->v[a] / dt;
  }
  s->area[o] = sums[6] * area;
  if (st == GR_OK)
    st = gr_snow_deposit(s, &win, press, add_depth, add_rho, give, vx, vy, rest);
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.distribution_ms);
  return st;
}

/* RelaxTolerance, but at least GR_SNOW_MIN_MOVE (below it an iteration
 * could move nothing). */
static float gr_snow_tolerance(const gr_snow_deformation *s) {
  float tol = (float)s->params.relax_tolerance;
  return tol > GR_SNOW_MIN_MOVE ? tol : GR_SNOW_MIN_MOVE;
}

/* The check: the largest amount a point of the givers' window R can still
 * move, and the box of the points that can move more than the tolerance
 * (out[1..4]: -x0, x1, -y0, y1), in two halves so that the host need not
 * wait between them: start enqueues the reduction on r (on a piece, over
 * its own points of the window; *empty when it has none), finish reads it
 * back and, on a piece, takes the largest over every piece
 * (GR_REDUCE_MAX), the box in the domain's indices and back in the local
 * arrays': every piece goes on, and stops, with the whole grid's window. */
static gr_status gr_snow_relax_check_start(gr_snow_deformation *s, gr_reduction *r, int x0, int y0,
                                           int x1, int y1, int *empty) {
  if (gr_snow_has_ring(s))
    gr_snow_own_clip(s, &x0, &y0, &x1, &y1);
  *empty = x0 > x1 || y0 > y1;
  if (*empty)
    return GR_OK;
  cl_kernel k = s->check_reduce;
  cl_int nx = s->grid.nx, w = x1 - x0 + 1, cnt = w * (y1 - y0 + 1);
  float tol = gr_snow_tolerance(s);
  gr_status st = GR_SNOW_ARG(s, k, "movable", s->movable);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "nx", nx);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "x0", x0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "y0", y0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "w", w);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "n", cnt);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "tol", tol);
  if (st == GR_OK)
    st = gr_reduction_start(s->ctx, r, k);
  return st;
}

static gr_status gr_snow_relax_check_finish(gr_snow_deformation *s, gr_reduction *r, int empty,
                                            double out[GR_SNOW_CHECK_MAXES]) {
  gr_status st = GR_OK;
  if (!empty) {
    st = gr_reduction_finish(s->ctx, r, NULL, out);
  } else {
    out[0] = 0.0;
    for (int q = 1; q < GR_SNOW_CHECK_MAXES; ++q)
      out[q] = -1.0e9;
  }
  if (st != GR_OK || !gr_snow_has_ring(s))
    return st;
  const double shift[GR_SNOW_CHECK_MAXES] = {0.0, -(double)s->ox, (double)s->ox, -(double)s->oy,
                                             (double)s->oy};
  for (int q = 1; q < GR_SNOW_CHECK_MAXES; ++q)
    if (out[q] > -1.0e8)
      out[q] += shift[q];
  if (s->allreduce)
    st = gr_snow_allreduce(s, out, GR_SNOW_CHECK_MAXES, GR_REDUCE_MAX);
  for (int q = 1; q < GR_SNOW_CHECK_MAXES; ++q)
    if (out[q] > -1.0e8)
      out[q] -= shift[q];
  return st;
}

/* The talus thresholds: MaxSlope times the distance along x, y and the
 * diagonal. */
static void gr_snow_thresholds(const gr_snow_deformation *s, float thr[3]) {
  double slope = s->params.max_slope, dx = s->grid.dx, dy = s->grid.dy;
  thr[0] = (float)(slope * dx);
  thr[1] = (float)(slope * dy);
  thr[2] = (float)(slope * sqrt(dx * dx + dy * dy));
}

/* The arguments every talus kernel shares: the ground, the lowest
 * underside (or the reach's ceilings) and its clearance (snow_excess), the
 * grid and the thresholds. */
static gr_status gr_snow_talus_args(gr_snow_deformation *s, cl_kernel k) {
  cl_int nx = s->grid.nx, ny = s->grid.ny;
  float thr[3];
  gr_snow_thresholds(s, thr);
  float clearance = (float)(2.0 * GR_SNOW_DEFORMATION_CONTACT_GAP);
  /* Under a reach the ceilings are its plane (snow_reach_ceiling). */
  cl_mem ceiling = s->reach_on ? s->scratch : s->under_min;
  const gr_snow_arg args[] = {{"ground", sizeof(cl_mem), &s->ground},
                              {"under_min", sizeof(cl_mem), &ceiling},
                              {"clearance", sizeof(clearance), &clearance},
                              {"nx", sizeof(nx), &nx},
                              {"ny", sizeof(ny), &ny},
                              {"tx", sizeof(float), &thr[0]},
                              {"ty", sizeof(float), &thr[1]},
                              {"td", sizeof(float), &thr[2]}};
  return gr_snow_args(s, k, args, sizeof(args) / sizeof(args[0]));
}

/* snow_relax_rate over [x0, x_end) x [y0, y_end) (nothing when that is
 * empty, as a piece's cut may be): the rates of iteration t of a launch
 * whose givers' window at t = 0 is [gx0, gx_end) x [gy0, gy_end). */
static gr_status gr_snow_relax_rate(gr_snow_deformation *s, float tol, cl_int gx0, cl_int gy0,
                                    cl_int gx_end, cl_int gy_end, cl_int t, cl_int x0, cl_int y0,
                                    cl_int x_end, cl_int y_end) {
  const gr_snow_arg rate[] = {{"depth", sizeof(cl_mem), &s->depth[s->cur]},
                              {"tol", sizeof(tol), &tol},
                              {"gx0", sizeof(gx0), &gx0},
                              {"gy0", sizeof(gy0), &gy0},
                              {"gx_end", sizeof(gx_end), &gx_end},
                              {"gy_end", sizeof(gy_end), &gy_end},
                              {"t", sizeof(t), &t},
                              {"x_end", sizeof(x_end), &x_end},
                              {"y_end", sizeof(y_end), &y_end},
                              {"rate", sizeof(cl_mem), &s->rate},
                              {"rate_in", sizeof(cl_mem), &s->rate_in},
                              {"movable", sizeof(cl_mem), &s->movable}};
  gr_status st = gr_snow_talus_args(s, s->relax_rate);
  if (st == GR_OK)
    st = gr_snow_args(s, s->relax_rate, rate, sizeof(rate) / sizeof(rate[0]));
  if (st == GR_OK && x_end > x0 && y_end > y0)
    st = gr_enqueue_2d(s->ctx, s->relax_rate, (size_t)x0, (size_t)y0, (size_t)(x_end - x0),
                       (size_t)(y_end - y0), NULL);
  return st;
}

/* Iteration t of a launch whose givers' window at t = 0 is [gx0, gx_end) x
 * [gy0, gy_end), in two launches: the rates on the window grown by t + 2,
 * the moves on it grown by t + 1; the state flips buffers. */
static gr_status gr_snow_relax_once(gr_snow_deformation *s, cl_int gx0, cl_int gy0, cl_int gx_end,
                                    cl_int gy_end, cl_int t, float tol) {
  cl_int nx = s->grid.nx, ny = s->grid.ny, nxt = 1 - s->cur;
  cl_int rx0 = gx0 - t - 2 > 0 ? gx0 - t - 2 : 0, ry0 = gy0 - t - 2 > 0 ? gy0 - t - 2 : 0;
  cl_int rx_end = gx_end + t + 2 < nx ? gx_end + t + 2 : nx,
         ry_end = gy_end + t + 2 < ny ? gy_end + t + 2 : ny;
  cl_int mx0 = gx0 - t - 1 > 0 ? gx0 - t - 1 : 0, my0 = gy0 - t - 1 > 0 ? gy0 - t - 1 : 0;
  cl_int mx_end = gx_end + t + 1 < nx ? gx_end + t + 1 : nx,
         my_end = gy_end + t + 1 < ny ? gy_end + t + 1 : ny;
  gr_status st = gr_snow_relax_rate(s, tol, gx0, gy0, gx_end, gy_end, t, rx0, ry0, rx_end, ry_end);
  const gr_snow_arg move[] = {{"depth", sizeof(cl_mem), &s->depth[s->cur]},
                              {"density", sizeof(cl_mem), &s->density[s->cur]},
                              {"rate", sizeof(cl_mem), &s->rate},
                              {"rate_in", sizeof(cl_mem), &s->rate_in},
                              {"x_end", sizeof(mx_end), &mx_end},
                              {"y_end", sizeof(my_end), &my_end},
                              {"depth_out", sizeof(cl_mem), &s->depth[nxt]},
                              {"density_out", sizeof(cl_mem), &s->density[nxt]}};
  if (st == GR_OK)
    st = gr_snow_talus_args(s, s->relax_move);
  if (st == GR_OK)
    st = gr_snow_args(s, s->relax_move, move, sizeof(move) / sizeof(move[0]));
  if (st == GR_OK && mx_end > mx0 && my_end > my0)
    st = gr_enqueue_2d(s->ctx, s->relax_move, (size_t)mx0, (size_t)my0, (size_t)(mx_end - mx0),
                       (size_t)(my_end - my0), NULL);
  if (st == GR_OK)
    s->cur = nxt;
  return st;
}

/* iters iterations in one launch of snow_relax_block over the move window
 * [mx0, mx_end) x [my0, my_end); the state flips buffers. */
static gr_status gr_snow_relax_blocked(gr_snow_deformation *s, cl_int gx0, cl_int gy0,
                                       cl_int gx_end, cl_int gy_end, cl_int mx0, cl_int my0,
                                       cl_int mx_end, cl_int my_end, cl_int iters, float tol) {
  cl_int nxt = 1 - s->cur;
  size_t bw = s->block[0], bh = s->block[1];
  size_t lbytes = 8 * (bw + 4 * GR_SNOW_BLOCK_ITERATIONS) * (bh + 4 * GR_SNOW_BLOCK_ITERATIONS) *
                  sizeof(cl_float);
  const gr_snow_arg args[] = {{"depth", sizeof(cl_mem), &s->depth[s->cur]},
                              {"density", sizeof(cl_mem), &s->density[s->cur]},
                              {"tol", sizeof(tol), &tol},
                              {"gx0", sizeof(gx0), &gx0},
                              {"gy0", sizeof(gy0), &gy0},
                              {"gx_end", sizeof(gx_end), &gx_end},
                              {"gy_end", sizeof(gy_end), &gy_end},
                              {"x_end", sizeof(mx_end), &mx_end},
                              {"y_end", sizeof(my_end), &my_end},
                              {"iters", sizeof(iters), &iters},
                              {"depth_out", sizeof(cl_mem), &s->depth[nxt]},
                              {"density_out", sizeof(cl_mem), &s->density[nxt]},
                              {"movable", sizeof(cl_mem), &s->movable},
                              {"lmem", lbytes, NULL}};
  const size_t local[2] = {bw, bh};
  gr_status st = gr_snow_talus_args(s, s->relax_block);
  if (st == GR_OK)
    st = gr_snow_args(s, s->relax_block, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK && mx_end > mx0 && my_end > my0) /* a piece's cut may be empty */
    st = gr_enqueue_2d(s->ctx, s->relax_block, (size_t)mx0, (size_t)my0, (size_t)(mx_end - mx0),
                       (size_t)(my_end - my0), local);
  if (st == GR_OK)
    s->cur = nxt;
  return st;
}

/* The talus' tail in one launch of snow_relax_group from the givers'
 * window [*x0, *x1] x [*y0, *y1] (inclusive), at most cap iterations: adds
 * the iterations run to *ran, sets *done when nothing could move any more,
 * and leaves the window of the next iteration in *x0.. (waits). The count
 * is the one the checked launches would give: they check every align
 * iterations, so a relaxation that ends at iteration e counts e rounded up
 * to align, and one that would not end before the cap counts the cap. */
static gr_status gr_snow_relax_group(gr_snow_deformation *s, int *x0, int *y0, int *x1, int *y1,
                                     cl_int cap, cl_int align, float tol, int *ran, int *done) {
  cl_int nxt = 1 - s->cur;
  cl_int max_area = s->group_area;
  cl_int w[4] = {*x0, *y0, *x1, *y1}, first = *ran, left = cap - first;
  const gr_snow_arg args[] = {{"depth", sizeof(cl_mem), &s->depth[s->cur]},
                              {"density", sizeof(cl_mem), &s->density[s->cur]},
                              {"depth_tmp", sizeof(cl_mem), &s->depth[nxt]},
                              {"density_tmp", sizeof(cl_mem), &s->density[nxt]},
                              {"tol", sizeof(tol), &tol},
                              {"x0", sizeof(cl_int), &w[0]},
                              {"y0", sizeof(cl_int), &w[1]},
                              {"x1", sizeof(cl_int), &w[2]},
                              {"y1", sizeof(cl_int), &w[3]},
                              {"cap", sizeof(left), &left},
                              {"max_area", sizeof(max_area), &max_area},
                              {"first", sizeof(first), &first},
                              {"align", sizeof(align), &align},
                              {"rate", sizeof(cl_mem), &s->rate},
                              {"rate_in", sizeof(cl_mem), &s->rate_in},
                              {"result", sizeof(cl_mem), &s->group_result}};
  const size_t local[2] = {s->group_size, 1};
  cl_int res[6];
  gr_status st = gr_snow_talus_args(s, s->relax_group);
  if (st == GR_OK)
    st = gr_snow_args(s, s->relax_group, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->relax_group, 0, 0, s->group_size, 1, local);
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->group_result, 0, sizeof(res), res);
  if (st == GR_OK) {
    int end = first + res[0], counted = (end + align - 1) / align * align;
    *done = res[1] != 0 && counted < cap;
    *ran = *done ? counted : (res[1] != 0 ? cap : end);
    *x0 = res[2], *y0 = res[3], *x1 = res[4], *y1 = res[5];
  }
  return st;
}

/* The reach of a step's talus in points (8-neighbour steps): with a
 * SlumpSpeed c, ceil(c dt / d) for the finer spacing d (at least one); 0
 * (no bound) for c = 0 or where it spans the whole domain anyway. A talus
 * iteration moves snow one point, so without a bound the snow would slide
 * as far as the iterations reach (about 60 m/s at 4096 points over 20 m
 * with 200 a step): the slump's speed, and the shape of a trail, would
 * change with the resolution. The same on every piece: dt and the spacing
 * are the domain's. */
static int gr_snow_reach_hops(const gr_snow_deformation *s, double dt) {
  const gr_snow_deformation_params *p = &s->params;
  if (!(p->slump_speed > 0.0))
    return 0;
  double d = s->grid.dx < s->grid.dy ? s->grid.dx : s->grid.dy;
  double n = ceil(p->slump_speed * dt / d - 1e-9), all = s->gnx > s->gny ? s->gnx : s->gny;
  return n >= all ? 0 : (n < 1.0 ? 1 : (int)n);
}

/* One pass of the reach's max filter (snow_reach_rows, snow_reach_cols):
 * the points within h of a point of src above thr in the box src_box
 * (local, inclusive, cut to the arrays; empty: none) into `weight`, on
 * out_box. */
static gr_status gr_snow_reach_dilate(gr_snow_deformation *s, cl_mem src, float thr,
                                      const int src_box[4], const int out_box[4], cl_int h) {
  cl_int nx = s->grid.nx, ny = s->grid.ny, sx0 = src_box[0], sy0 = src_box[1], sx1 = src_box[2],
         sy1 = src_box[3];
  cl_int x_end = out_box[2] + 1, y_end = sy1 + 1;
  const gr_snow_arg rows[] = {{"src", sizeof(cl_mem), &src},
                              {"thr", sizeof(thr), &thr},
                              {"sx0", sizeof(sx0), &sx0},
                              {"sy0", sizeof(sy0), &sy0},
                              {"sx1", sizeof(sx1), &sx1},
                              {"sy1", sizeof(sy1), &sy1},
                              {"h", sizeof(h), &h},
                              {"nx", sizeof(nx), &nx},
                              {"ny", sizeof(ny), &ny},
                              {"x_end", sizeof(x_end), &x_end},
                              {"y_end", sizeof(y_end), &y_end},
                              {"out", sizeof(cl_mem), &s->scratch}};
  gr_status st = gr_snow_args(s, s->reach_rows, rows, sizeof(rows) / sizeof(rows[0]));
  if (st == GR_OK && sy0 <= sy1) /* no rows: the columns read none */
    st = gr_enqueue_2d(s->ctx, s->reach_rows, (size_t)out_box[0], (size_t)sy0,
                       (size_t)(out_box[2] - out_box[0] + 1), (size_t)(sy1 - sy0 + 1), NULL);
  cl_int y_end2 = out_box[3] + 1;
  const gr_snow_arg cols[] = {{"src", sizeof(cl_mem), &s->scratch},
                              {"sy0", sizeof(sy0), &sy0},
                              {"sy1", sizeof(sy1), &sy1},
                              {"h", sizeof(h), &h},
                              {"nx", sizeof(nx), &nx},
                              {"ny", sizeof(ny), &ny},
                              {"x_end", sizeof(x_end), &x_end},
                              {"y_end", sizeof(y_end2), &y_end2},
                              {"out", sizeof(cl_mem), &s->weight}};
  if (st == GR_OK)
    st = gr_snow_args(s, s->reach_cols, cols, sizeof(cols) / sizeof(cols[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->reach_cols, (size_t)out_box[0], (size_t)out_box[1],
                       (size_t)(out_box[2] - out_box[0] + 1), (size_t)(out_box[3] - out_box[1] + 1),
                       NULL);
  return st;
}

/* A box (x0 y0 x1 y1) cut to the local arrays; 0 when nothing is left. */
static int gr_snow_clip_box(const gr_snow_deformation *s, const int in[4], int out[4]) {
  out[0] = in[0] > 0 ? in[0] : 0;
  out[1] = in[1] > 0 ? in[1] : 0;
  out[2] = in[2] < s->grid.nx - 1 ? in[2] : s->grid.nx - 1;
  out[3] = in[3] < s->grid.ny - 1 ? in[3] : s->grid.ny - 1;
  return out[0] <= out[2] && out[1] <= out[3];
}

/* The reach of this step's talus (SlumpSpeed; header): the points within
 * hops of a seed, a point that can move more than the tolerance at the
 * step's start (a mover, found on the window [*x0, *x1] x [*y0, *y1],
 * where every point that can move lies) or one on a slope
 * (snow_reach_seed), as far as the talus can reach in the step (the cap's
 * iterations from the movers). Only those points give or receive (their
 * ceilings, snow_reach_ceiling, are -inf elsewhere), and within them the
 * snow settles: a slide spreads over flat snow at SlumpSpeed, and what an
 * object feeds becomes a heap at MaxSlope on every grid (a talus cut to a
 * number of iterations carries a flux that shrinks with the spacing, and
 * piled a wall). The mask is a max filter of the seeds in passes of at
 * most GR_SNOW_DEFORMATION_GHOST - 1 points, each exchanged on a piece (a
 * seed reads its neighbours: the ring gives 7 points), so a piece's mask is
 * the whole grid's. Leaves the movers' box in *x0.. (the givers' window)
 * and the reach's box in s->reach_box and s->reach_all; *any = 0 when
 * nothing can move. */
static gr_status gr_snow_relax_reach(gr_snow_deformation *s, int hops, float tol, int *x0, int *y0,
                                     int *x1, int *y1, int *any) {
  cl_int gx0 = *x0, gy0 = *y0, gx_end = *x1 + 1, gy_end = *y1 + 1, t = 0;
  s->reach_on = 0;
  *any = 0;
  /* The movers: snow_relax_rate's movable amounts at t = 0, everyone a giver. */
  gr_status st = gr_snow_relax_rate(s, tol, gx0, gy0, gx_end, gy_end, t, gx0, gy0, gx_end, gy_end);
  double m[GR_SNOW_CHECK_MAXES];
  int empty = 0;
  if (st == GR_OK)
    st = gr_snow_relax_check_start(s, &s->red_check[0], *x0, *y0, *x1, *y1, &empty);
  if (st == GR_OK)
    st = gr_snow_relax_check_finish(s, &s->red_check[0], empty, m);
  if (st != GR_OK || m[0] <= tol)
    return st;
  *any = 1;
  /* The boxes in the local arrays' indices, not cut: the same box of the
   * domain on every piece. The seeds: wherever this step's talus can
   * reach, snow moving a point an iteration, so within the cap of the
   * movers. */
  int movers[4] = {(int)-m[1], (int)-m[3], (int)m[2], (int)m[4]}, src[4], out[4], cut[4],
      cut_out[4];
  int far = s->params.max_relax_iterations;
  src[0] = movers[0] - far, src[1] = movers[1] - far, src[2] = movers[2] + far,
  src[3] = movers[3] + far;
  *x0 = movers[0], *y0 = movers[1], *x1 = movers[2], *y1 = movers[3];
  float t3[3];
  gr_snow_thresholds(s, t3);
  if (gr_snow_clip_box(s, src, cut)) {
    cl_int nx = s->grid.nx, ny = s->grid.ny, x_end = cut[2] + 1, y_end = cut[3] + 1;
    const gr_snow_arg args[] = {{"ground", sizeof(cl_mem), &s->ground},
                                {"depth", sizeof(cl_mem), &s->depth[s->cur]},
                                {"movable", sizeof(cl_mem), &s->movable},
                                {"tol", sizeof(tol), &tol},
                                {"ax0", sizeof(cl_int), &movers[0]},
                                {"ay0", sizeof(cl_int), &movers[1]},
                                {"ax1", sizeof(cl_int), &movers[2]},
                                {"ay1", sizeof(cl_int), &movers[3]},
                                {"tx", sizeof(float), &t3[0]},
                                {"ty", sizeof(float), &t3[1]},
                                {"td", sizeof(float), &t3[2]},
                                {"nx", sizeof(nx), &nx},
                                {"ny", sizeof(ny), &ny},
                                {"x_end", sizeof(x_end), &x_end},
                                {"y_end", sizeof(y_end), &y_end},
                                {"reach", sizeof(cl_mem), &s->weight}};
    st = gr_snow_args(s, s->reach_seed, args, sizeof(args) / sizeof(args[0]));
    if (st == GR_OK)
      st = gr_enqueue_2d(s->ctx, s->reach_seed, (size_t)cut[0], (size_t)cut[1],
                         (size_t)(cut[2] - cut[0] + 1), (size_t)(cut[3] - cut[1] + 1), NULL);
  }
  /* The max filter, hops points, in passes a piece's ring can feed. */
  for (int left = hops; st == GR_OK && left > 0;) {
    int h = left < GR_SNOW_DEFORMATION_GHOST - 1 ? left : GR_SNOW_DEFORMATION_GHOST - 1;
    out[0] = src[0] - h, out[1] = src[1] - h, out[2] = src[2] + h, out[3] = src[3] + h;
    if (!gr_snow_clip_box(s, src, cut)) /* no seeds here */
      cut[0] = cut[1] = 0, cut[2] = cut[3] = -1;
    if (gr_snow_clip_box(s, out, cut_out))
      st = gr_snow_reach_dilate(s, s->weight, 0.5f, cut, cut_out, h);
    if (st == GR_OK) {
      s->halo_reach = 1; /* pieces: the ring's mask from its own piece */
      st = gr_snow_piece_sync(s);
      s->halo_reach = 0;
    }
    memcpy(src, out, sizeof(src));
    left -= h;
  }
  memcpy(s->reach_all, src, sizeof(src));
  if (st == GR_OK && !gr_snow_clip_box(s, src, s->reach_box))
    s->reach_box[0] = s->reach_box[1] = 0, s->reach_box[2] = s->reach_box[3] = -1;
  /* The ceilings, as far as a talus launch on the reach reads: a blocked
   * launch's moves reach GR_SNOW_BLOCK_ITERATIONS beyond its givers and read
   * twice that farther. */
  const int pad = 3 * GR_SNOW_BLOCK_ITERATIONS;
  int wide[4] = {src[0] - pad, src[1] - pad, src[2] + pad, src[3] + pad};
  if (st == GR_OK && gr_snow_clip_box(s, wide, cut)) {
    cl_int nx = s->grid.nx, ny = s->grid.ny, x_end = cut[2] + 1, y_end = cut[3] + 1;
    const gr_snow_arg args[] = {{"under_min", sizeof(cl_mem), &s->under_min},
                                {"reach", sizeof(cl_mem), &s->weight},
                                {"bx0", sizeof(cl_int), &s->reach_box[0]},
                                {"by0", sizeof(cl_int), &s->reach_box[1]},
                                {"bx1", sizeof(cl_int), &s->reach_box[2]},
                                {"by1", sizeof(cl_int), &s->reach_box[3]},
                                {"nx", sizeof(nx), &nx},
                                {"ny", sizeof(ny), &ny},
                                {"x_end", sizeof(x_end), &x_end},
                                {"y_end", sizeof(y_end), &y_end},
                                {"ceiling", sizeof(cl_mem), &s->scratch}};
    st = gr_snow_args(s, s->reach_ceiling, args, sizeof(args) / sizeof(args[0]));
    if (st == GR_OK)
      st = gr_enqueue_2d(s->ctx, s->reach_ceiling, (size_t)cut[0], (size_t)cut[1],
                         (size_t)(cut[2] - cut[0] + 1), (size_t)(cut[3] - cut[1] + 1), NULL);
  }
  if (st == GR_OK)
    s->reach_on = 1;
  return st;
}

/* Talus relaxation on a window that follows the snow that can move.
 *
 * The window: the givers R (at first the objects' boxes grown by the
 * contour ring, or the whole grid after the snow or the ground was set:
 * relax_full). Snow leaves only points of R, so after an iteration only
 * points within one of R changed, and only those and their neighbours can
 * have gained an excess: R grows by one per iteration. A launch of
 * snow_relax_block runs GR_SNOW_BLOCK_ITERATIONS iterations and writes the
 * moves' window, R grown by that many. Then the check reads the first
 * iteration's largest movable amount (the end when it is at most
 * RelaxTolerance: then nothing moved in the launch) and the box of the
 * points that could move more; only those gave (a point gives only while
 * it can move more than RelaxTolerance), so R shrinks to that box grown by
 * the iterations run. The window decides what is computed, never the
 * result: a run from the whole grid ends bit for bit where a run from the
 * objects' boxes does when the rest was relaxed.
 *
 * The pair of buffers: a launch writes the other buffer on its window only,
 * so outside it the other buffer must equal the state. That holds at the
 * start of a step but where the objects pressed (synchronised first), and
 * is restored when a window does not cover the last one and at the end (the
 * last window copied across). */
static gr_status gr_snow_relax(gr_snow_deformation *s, double dt) {
  int nx = s->grid.nx, ny = s->grid.ny;
  float tol = gr_snow_tolerance(s);
  gr_status st = GR_OK;
  int it = 0, x0 = nx, x1 = -1, y0 = ny, y1 = -1;
  s->relax_iterations = 0;
  if (s->relax_full) {
    x0 = y0 = 0;
    x1 = nx - 1;
    y1 = ny - 1;
  } else {
    for (int o = 0; o < s->nobjects; ++o) {
      const gr_snow_object *ob = &s->objects[o];
      if (ob->bi0 > ob->bi1 || ob->bj0 > ob->bj1)
        continue;
      x0 = x0 < ob->bi0 - 2 ? x0 : ob->bi0 - 2;
      x1 = x1 > ob->bi1 + 2 ? x1 : ob->bi1 + 2;
      y0 = y0 < ob->bj0 - 2 ? y0 : ob->bj0 - 2;
      y1 = y1 > ob->bj1 + 2 ? y1 : ob->bj1 + 2;
    }
    if (s->rest[0] <= s->rest[2] && s->rest[1] <= s->rest[3]) {
      x0 = x0 < s->rest[0] ? x0 : s->rest[0];
      y0 = y0 < s->rest[1] ? y0 : s->rest[1];
      x1 = x1 > s->rest[2] ? x1 : s->rest[2];
      y1 = y1 > s->rest[3] ? y1 : s->rest[3];
    }
  }
  if (s->params.max_relax_iterations == 0) {
    s->sync_full |= x0 <= x1;   /* the objects changed the state alone */
    if (x0 <= x1 && y0 <= y1) { /* all of it may still move */
      s->rest[0] = x0 > 0 ? x0 : 0, s->rest[1] = y0 > 0 ? y0 : 0;
      s->rest[2] = x1 < nx - 1 ? x1 : nx - 1, s->rest[3] = y1 < ny - 1 ? y1 : ny - 1;
    }
    return GR_OK;
  }
  if (x0 > x1 || y0 > y1)
    return GR_OK; /* nothing touched the snow: it stays as relaxed as it was */
  x0 = x0 > 0 ? x0 : 0;
  y0 = y0 > 0 ? y0 : 0;
  x1 = x1 < nx - 1 ? x1 : nx - 1;
  y1 = y1 < ny - 1 ? y1 : ny - 1;
  if (s->sync_full || s->relax_full)
    st = gr_snow_sync_rect(s, 0, 0, nx - 1, ny - 1);
  else
    st = gr_snow_sync_rect(s, x0, y0, x1, y1);
  s->relax_full = s->sync_full = 0;
  /* SlumpSpeed: the talus runs on the step's reach only (the givers'
   * window from the movers on). */
  const int hops = gr_snow_reach_hops(s, dt);
  int movers[4] = {0, 0, -1, -1}; /* under a reach: the box of the points that could move */
  s->reach_on = 0;
  if (st == GR_OK && hops > 0) {
    int any = 0;
    st = gr_snow_relax_reach(s, hops, tol, &x0, &y0, &x1, &y1, &any);
    movers[0] = x0, movers[1] = y0, movers[2] = x1, movers[3] = y1;
    if (st != GR_OK || !any) {
      s->reach_on = 0;
      s->rest[0] = s->rest[1] = 0;
      s->rest[2] = s->rest[3] = -1;
      return st; /* nothing can move: the snow is as relaxed as it was */
    }
  }
  int lx0 = 0, ly0 = 0, lx1 = -1, ly1 = -1; /* the last launch's window */
  /* Launches in flight: on GPUs, where a read-back between launches costs
   * more than the launch, only every GR_SNOW_CHECK_EVERY-th launch is
   * checked and a check is read back GR_SNOW_CHECK_LAG checks later, so the
   * window of a launch is the last box read grown by every iteration
   * launched since. A launch after the
   * one whose check says nothing could move changes nothing (no point
   * gives), so the lag changes what is computed, never the result or the
   * iteration count. */
  const int lag = s->blocked ? GR_SNOW_CHECK_LAG : 0, cap = s->params.max_relax_iterations;
  const int every = s->blocked ? GR_SNOW_CHECK_EVERY : 1;
  /* per check in flight: the iterations launched before its launch, and
   * whether it is empty (a piece with none of the window) */
  int before[GR_SNOW_CHECK_LAG + 1], empty[GR_SNOW_CHECK_LAG + 1];
  int launched = 0, started = 0, read = 0, it_launched = 0, done = 0;
  while (st == GR_OK && !done) {
    if (s->reach_on) { /* no giver beyond the reach (and no read beyond its ceilings) */
      const int *b = s->reach_box;
      x0 = x0 > b[0] ? x0 : b[0], y0 = y0 > b[1] ? y0 : b[1];
      x1 = x1 < b[2] ? x1 : b[2], y1 = y1 < b[3] ? y1 : b[3];
    }
    /* The tail: once the givers' window grown by two is small, in one
     * work-group (not on a piece with a ring: it would need an exchange
     * every iteration), after every check in flight is read. */
    int gx = (x1 + 2 < nx - 1 ? x1 + 2 : nx - 1) - (x0 - 2 > 0 ? x0 - 2 : 0) + 1,
        gy = (y1 + 2 < ny - 1 ? y1 + 2 : ny - 1) - (y0 - 2 > 0 ? y0 - 2 : 0) + 1;
    int tail = s->group && !gr_snow_has_ring(s) && it_launched < cap &&
               (double)gx * gy <= (double)s->group_area;
    if (tail && read == started) {
      x0 = x0 > 0 ? x0 : 0;
      y0 = y0 > 0 ? y0 : 0;
      x1 = x1 < nx - 1 ? x1 : nx - 1;
      y1 = y1 < ny - 1 ? y1 : ny - 1;
      st = gr_snow_relax_group(s, &x0, &y0, &x1, &y1, cap, GR_SNOW_BLOCK_ITERATIONS * every, tol,
                               &it_launched, &done);
      if (st == GR_OK)
        it = it_launched;
      continue;
    }
    if (!tail && it_launched < cap && started - read <= lag) {
      int left = cap - it_launched;
      cl_int iters = left < GR_SNOW_BLOCK_ITERATIONS ? left : GR_SNOW_BLOCK_ITERATIONS;
      x0 = x0 > 0 ? x0 : 0;
      y0 = y0 > 0 ? y0 : 0;
      x1 = x1 < nx - 1 ? x1 : nx - 1;
      y1 = y1 < ny - 1 ? y1 : ny - 1;
      cl_int gx0 = x0, gy0 = y0, gx_end = x1 + 1, gy_end = y1 + 1;
      /* The launch's window: R grown by the iterations. */
      int mx0 = x0 - iters > 0 ? x0 - iters : 0, my0 = y0 - iters > 0 ? y0 - iters : 0;
      cl_int mx_end = x1 + iters + 1 < nx ? x1 + iters + 1 : nx,
             my_end = y1 + iters + 1 < ny ? y1 + iters + 1 : ny;
      /* The buffer the first write goes to lags the state on the last
       * window; it must not where that write does not reach: all of the
       * launch's window in one blocked launch, R grown by one in the first
       * of the one-launch iterations (each later one covers its
       * predecessor's). */
      int grow = s->blocked ? iters : 1;
      int fx0 = x0 - grow > 0 ? x0 - grow : 0, fy0 = y0 - grow > 0 ? y0 - grow : 0;
      int fx1 = x1 + grow < nx - 1 ? x1 + grow : nx - 1,
          fy1 = y1 + grow < ny - 1 ? y1 + grow : ny - 1;
      if (lx0 < fx0 || ly0 < fy0 || lx1 > fx1 || ly1 > fy1)
        st = gr_snow_sync_rect(s, lx0, ly0, lx1, ly1);
      if (st == GR_OK && s->blocked)
        st = gr_snow_relax_blocked(s, gx0, gy0, gx_end, gy_end, mx0, my0, mx_end, my_end, iters,
                                   tol);
      for (cl_int t = 0; st == GR_OK && !s->blocked && t < iters; ++t)
        st = gr_snow_relax_once(s, gx0, gy0, gx_end, gy_end, t, tol);
      if (st == GR_OK)
        st = gr_snow_piece_sync(s); /* pieces: the ring the launch used up */
      if (st == GR_OK)
        lx0 = mx0, ly0 = my0, lx1 = mx_end - 1, ly1 = my_end - 1;
      int slot = started % (lag + 1);
      if (st == GR_OK && launched % every == 0) {
        st = gr_snow_relax_check_start(s, &s->red_check[slot], x0, y0, x1, y1, &empty[slot]);
        before[slot] = it_launched;
        started += st == GR_OK;
      }
      if (st == GR_OK) {
        it_launched += iters;
        ++launched;
        x0 -= iters, x1 += iters, y0 -= iters, y1 += iters; /* until a box is read */
      }
      continue;
    }
    if (read == started)
      break; /* the cap, every check read */
    double m[GR_SNOW_CHECK_MAXES];
    int slot = read % (lag + 1);
    st = gr_snow_relax_check_finish(s, &s->red_check[slot], empty[slot], m);
    ++read;
    if (st == GR_OK && m[0] <= tol) {
      it = before[slot]; /* nothing could move: that launch and those after changed nothing */
      done = 1;
    } else if (st == GR_OK) {
      it = it_launched;
      int g = it_launched - before[slot]; /* iterations since that check's launch began */
      x0 = (int)-m[1] - g, x1 = (int)m[2] + g;
      y0 = (int)-m[3] - g, y1 = (int)m[4] + g;
    }
  }
  /* Checks still in flight (after the end, or an error): wait for them. */
  for (; read < started; ++read)
    if (!empty[read % (lag + 1)])
      gr_reduction_finish(s->ctx, &s->red_check[read % (lag + 1)], NULL, NULL);
  /* Stopped by the cap: the last box read, grown by the iterations since,
   * holds every point that may still move. */
  s->rest[0] = s->rest[1] = 0;
  s->rest[2] = s->rest[3] = -1;
  if (st == GR_OK && !done) {
    s->rest[0] = x0 > 0 ? x0 : 0, s->rest[1] = y0 > 0 ? y0 : 0;
    s->rest[2] = x1 < nx - 1 ? x1 : nx - 1, s->rest[3] = y1 < ny - 1 ? y1 : ny - 1;
  }
  /* Under a reach: snow moved a point an iteration from the points that
   * could move, within the reach, so only there, and next to it, may a
   * point have an excess now (the edge of the reach, where the front
   * slides on next step). Not cut to the local arrays: the domain's box,
   * so that every piece goes on with the next step's talus alike. */
  if (st == GR_OK && s->reach_on) {
    const int *b = s->reach_all, g = it_launched + 1;
    int e[4] = {movers[0] - g, movers[1] - g, movers[2] + g, movers[3] + g};
    e[0] = e[0] > b[0] - 1 ? e[0] : b[0] - 1, e[1] = e[1] > b[1] - 1 ? e[1] : b[1] - 1;
    e[2] = e[2] < b[2] + 1 ? e[2] : b[2] + 1, e[3] = e[3] < b[3] + 1 ? e[3] : b[3] + 1;
    if (s->rest[0] > s->rest[2] || s->rest[1] > s->rest[3])
      memcpy(s->rest, e, sizeof(e));
    s->rest[0] = s->rest[0] < e[0] ? s->rest[0] : e[0];
    s->rest[1] = s->rest[1] < e[1] ? s->rest[1] : e[1];
    s->rest[2] = s->rest[2] > e[2] ? s->rest[2] : e[2];
    s->rest[3] = s->rest[3] > e[3] ? s->rest[3] : e[3];
  }
  s->reach_on = 0;
  /* Both buffers equal again: the last window from the state. */
  if (st == GR_OK)
    st = gr_snow_sync_rect(s, lx0, ly0, lx1, ly1);
  s->relax_iterations = it;
  return st;
}

gr_status gr_snow_deformation_step(gr_snow_deformation *s, double dt) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_step needs a simulation.");
  if (!(dt >= GR_SNOW_MIN_DT && dt <= GR_SNOW_MAX_DT))
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow deformation time step must lie between 1e-9 and 3600 s (got "
                        "%g s).",
                        dt));
  if (s->aborted)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_ABORTED,
                        "The snow deformation was stopped by its progress callback%s; set the "
                        "callback again or reset to go on.",
                        s->allreduce ? " (of this or another piece of the domain)" : ""));
  if (gr_snow_has_ring(s) && (!s->allreduce || !s->halo_exchange))
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "A snow deformation piece with neighbours steps only with a global "
                        "reduction and a halo exchange (it has %s and %s): set them with "
                        "gr_snow_deformation_set_allreduce and "
                        "gr_snow_deformation_set_halo_exchange.",
                        s->allreduce ? "one" : "none", s->halo_exchange ? "one" : "none"));
  gr_status st = gr_snow_reset(s);
  memset(s->force, 0, sizeof(s->force));
  if (st == GR_OK && s->timing) {
    st = gr_finish(s->ctx);
    s->t_mark = gr_snow_now_ms();
  }
  for (int o = 0; st == GR_OK && o < s->nobjects; ++o)
    st = gr_snow_object_step(s, o, dt);
  if (st == GR_OK)
    st = gr_snow_relax(s, dt);
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.relax_ms);
  if (st == GR_OK && s->timing) {
    s->tm.steps++;
    s->tm.relax_iterations += s->relax_iterations;
  }
  if (st == GR_OK)
    st = gr_finish(s->ctx);
  if (st != GR_OK)
    return GR_SNOW_KEEP_ERROR(s, st);
  s->time += dt;
  s->steps++;
  /* The impulse: the force of a step acts over the step. */
  for (int o = 0; o < s->nobjects; ++o) {
    const double *f = s->force[o];
    for (int a = 0; a < 3; ++a)
      s->impulse[o][a] += f[a] * dt;
    s->peak[o] = fmax(s->peak[o], sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
  }
  s->impulse_time += dt;
  int stop = s->progress && s->progress(s->progress_user, s->time) != 0;
  /* Pieces: a stop asked on any piece stops every piece after this step
   * (every piece makes this call at every step, callback or not). */
  if (s->allreduce) {
    double flag = stop ? 1.0 : 0.0;
    st = gr_snow_allreduce(s, &flag, 1, GR_REDUCE_MAX);
    stop = flag != 0.0;
  }
  if (stop)
    s->aborted = 1;
  return st == GR_OK ? GR_OK : GR_SNOW_KEEP_ERROR(s, st);
}

gr_status gr_snow_deformation_get_field(gr_snow_deformation *s, gr_field f, float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_get_field needs a simulation.");
  if (!host)
    return GR_SNOW_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                              "gr_snow_deformation_get_field needs a place for "
                                              "the values (got NULL)."));
  cl_mem src = NULL;
  gr_status st = GR_OK;
  switch (f) {
  case GR_FIELD_SNOW_DEPTH:
    src = s->depth[s->cur];
    break;
  case GR_FIELD_SNOW_DENSITY:
    src = s->density[s->cur];
    break;
  case GR_FIELD_OVERLAP:
    src = s->overlap_sum;
    break;
  case GR_FIELD_CONTACT:
    src = s->contact;
    break;
  case GR_FIELD_ELEVATION:
    src = s->ground;
    break;
  case GR_FIELD_SNOW_SURFACE: {
    int n = (int)gr_snow_cells(s);
    st = GR_SNOW_ARG(s, s->surface, "ground", s->ground);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->surface, "depth", s->depth[s->cur]);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->surface, "n", n);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->surface, "out", s->scratch);
    if (st == GR_OK)
      st = gr_enqueue_1d(s->ctx, s->surface, (size_t)n);
    src = s->scratch;
    break;
  }
  default: {
    const char *name = gr_field_name(f);
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow deformation simulation has no output field '%s'; it gives "
                        "snow_depth, snow_surface, snow_density, overlap, contact and elevation.",
                        name ? name : "(unknown field)"));
  }
  }
  if (st == GR_OK)
    st = gr_snow_read_own(s, src, host);
  return st == GR_OK ? GR_OK : GR_SNOW_KEEP_ERROR(s, st);
}

gr_status gr_snow_deformation_ledger_get(gr_snow_deformation *s, gr_snow_deformation_ledger *out) {
  if (!s || !out)
    return s ? GR_SNOW_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                                  "gr_snow_deformation_ledger_get needs a place "
                                                  "for the ledger."))
             : gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                            "gr_snow_deformation_ledger_get needs a simulation.");
  /* Fixed point over the own points, then over every piece (collective):
   * the whole grid's integers, so its very doubles. */
  long long q[4] = {0, 0, s->initial_q, s->initial_m};
  gr_status st = gr_snow_ledger_sums(s, &q[0], &q[1]);
  if (st == GR_OK)
    st = gr_snow_allreduce_i64(s, q, 4);
  if (st != GR_OK)
    return GR_SNOW_KEEP_ERROR(s, st);
  const double a = s->grid.dx * s->grid.dy, quantum = 1.0 / GR_SNOW_QUANTUM_INV,
               mass = 1.0 / GR_SNOW_LEDGER_MASS_INV;
  double v = (double)q[0] * quantum * a, m = (double)q[1] * mass * a;
  memset(out, 0, sizeof(*out));
  out->time = s->time;
  out->steps = s->steps;
  out->initial_volume = (double)q[2] * quantum * a;
  out->initial_mass = (double)q[3] * mass * a;
  /* Displaced snow waiting for a contour is still snow. */
  v += s->pending * a;
  m += s->pending_mass * a;
  out->snow_volume = v;
  out->snow_mass = m;
  out->compressed_volume = s->compressed;
  out->displaced_volume = s->displaced;
  out->balance_error = m - out->initial_mass;
  out->volume_error = out->initial_volume - s->compressed - v;
  out->relax_iterations = s->relax_iterations;
  return GR_OK;
}

gr_status gr_snow_deformation_object_forces(gr_snow_deformation *s, double *force3, double *area,
                                            int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_object_forces needs a simulation.");
  if (n != s->nobjects)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_object_forces was asked for %d objects but %d are "
                        "set; pass the number given to set_objects.",
                        n, s->nobjects));
  for (int o = 0; o < n; ++o) {
    if (force3)
      for (int a = 0; a < 3; ++a)
        force3[3 * o + a] = s->force[o][a];
    if (area)
      area[o] = s->area[o];
  }
  return GR_OK;
}

gr_status gr_snow_deformation_object_mean_forces(gr_snow_deformation *s, double *force3,
                                                 double *peak, double *seconds, int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_object_mean_forces needs a simulation.");
  if (n != s->nobjects)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_object_mean_forces was asked for %d objects but %d "
                        "are set; pass the number given to set_objects.",
                        n, s->nobjects));
  const double span = s->impulse_time;
  for (int o = 0; o < n; ++o) {
    if (force3)
      for (int a = 0; a < 3; ++a)
        force3[3 * o + a] = span > 0.0 ? s->impulse[o][a] / span : 0.0;
    if (peak)
      peak[o] = s->peak[o];
  }
  if (seconds)
    *seconds = span;
  return GR_OK;
}

void gr_snow_deformation_clear_impulses(gr_snow_deformation *s) {
  if (!s)
    return;
  memset(s->impulse, 0, sizeof(s->impulse));
  memset(s->peak, 0, sizeof(s->peak));
  s->impulse_time = 0.0;
}

void gr_snow_deformation_set_progress(gr_snow_deformation *s, gr_progress_fn fn, void *user) {
  if (!s)
    return;
  s->progress = fn;
  s->progress_user = user;
  s->aborted = 0;
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

gr_status gr_snow_deformation_reset(gr_snow_deformation *s) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_reset needs a simulation.");
  gr_status st = gr_snow_initial_state(s);
  return st == GR_OK ? GR_OK : GR_SNOW_KEEP_ERROR(s, st);
}
