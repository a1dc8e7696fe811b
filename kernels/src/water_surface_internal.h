/* Water surface core, host side, private to its files: water_surface.c
 * (parameters, the handle, creation, inputs and the water found from them),
 * water_surface_step.c (stepping, outputs, the ledger) and
 * water_surface_pieces.c (pieces of a split domain, halos, checkpoints). */
#ifndef GRAUPEL_WATER_SURFACE_INTERNAL_H
#define GRAUPEL_WATER_SURFACE_INTERNAL_H

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
  cl_kernel step, reduce, derive;
  size_t tile[2]; /* the step's work-group (its reqd_work_group_size) */
  cl_mem h[2];    /* wave height; [cur] is the latest */
  int cur;
  cl_mem v;                 /* vertical velocity h_t, at half steps */
  cl_mem wet;               /* uchar per point */
  cl_mem base;              /* the still surface, m */
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

/* set_wave's bound on the wave height, which a checkpoint's wave keeps too. */
#define GR_WS_MAX_WAVE 1.0e4

#define GR_WS_KEEP(s, st) gr_error_keep((s)->error, sizeof((s)->error), (st))

/* The local arrays' points (a piece: own rows and rings). */
static inline size_t gr_ws_points(const gr_water_surface *s) {
  return (size_t)s->grid.nx * (size_t)s->grid.ny;
}

/* The own points and the first own point's index in the local arrays. */
static inline size_t gr_ws_own_points(const gr_water_surface *s) {
  return (size_t)s->grid.nx * (size_t)s->own_ny;
}
static inline size_t gr_ws_own_first(const gr_water_surface *s) {
  return (size_t)s->grid.nx * (size_t)s->ring_s;
}

static inline int gr_ws_pieced(const gr_water_surface *s) {
  return s->ring_s > 0 || s->ring_n > 0;
}

/* Rows of the drop Gaussians' reach: 4 DropRadius, at most
 * GR_WATER_SURFACE_MAX_REACH. */
static inline int gr_ws_reach(double radius, double d) {
  return (int)fmin(ceil(GR_WATER_SURFACE_REACH_SIGMAS * radius / d), GR_WATER_SURFACE_MAX_REACH);
}

/* One kernel argument by its name in the kernel's source. */
typedef struct gr_ws_arg {
  const char *name;
  size_t size;
  const void *value;
} gr_ws_arg;

/* Sets each of args on k by its name (GR_WS_ARGS: a whole array of them). */
gr_status gr_ws_args(gr_water_surface *s, cl_kernel k, const gr_ws_arg *args, size_t n);
#define GR_WS_ARGS(s, k, args) gr_ws_args((s), (k), (args), sizeof(args) / sizeof((args)[0]))

/* Fills bytes of buf with value, enqueued. */
gr_status gr_ws_fill(gr_water_surface *s, cl_mem buf, float value, size_t bytes);

/* The lake's mode: a lake when asked for, else the depth when given. */
int gr_ws_lake(const gr_water_surface *s);

/* Finds the wet points and the still surface from the inputs and the
 * parameters, and uploads them; refuses no water with a sentence. */
gr_status gr_ws_prepare(gr_water_surface *s);

/* The ledger's device sums (wave, energy per area, wet count) and max |h|
 * over the own points, the same bits for the whole grid and any split. */
gr_status gr_ws_reduce(gr_water_surface *s, double sums[3], double *max_wave);

/* Records the wave's sum at time 0 when it is not known yet. */
gr_status gr_ws_know_initial(gr_water_surface *s);

/* The piece contract: the ring toward each side, or a sentence in msg. */
gr_status gr_ws_piece_check(const gr_grid *g, const gr_water_surface_params *p, int *ring_s,
                            int *ring_n, char *msg, size_t len);

/* The caller's allreduce. */
gr_status gr_ws_allreduce(gr_water_surface *s, double *v, int n, gr_reduce_op op);

/* Bytes of a checkpoint of s. */
size_t gr_ws_state_bytes(const gr_water_surface *s);

#endif
