/* Snow deformation core, host side: what the host files share, and nothing
 * of the public API (graupel/snow_deformation.h): the limits and checkpoint
 * layout, the parameter table's rows, the handle's state, and the private
 * functions of snow_deformation.c (parameters, device arrays, life cycle),
 * snow_deformation_step.c (objects, step, outputs),
 * snow_deformation_talus.c and snow_deformation_pieces.c (halos,
 * checkpoints). */
#ifndef GRAUPEL_SNOW_DEFORMATION_INTERNAL_H
#define GRAUPEL_SNOW_DEFORMATION_INTERNAL_H

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
  /* halo_cols_on: the talus' exchange copies only the local columns
   * halo_cols[0] .. halo_cols[1] of a south or north strip (the columns its
   * launches wrote since the last exchange, the same on every piece) */
  int halo_cols_on, halo_cols[2];
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

/* A named kernel argument. */
typedef struct gr_snow_arg {
  const char *name;
  size_t size;
  const void *value;
} gr_snow_arg;

/* snow_deformation.c */
double gr_snow_now_ms(void);
gr_status gr_snow_mark(gr_snow_deformation *s, double *acc);
size_t gr_snow_cells(const gr_snow_deformation *s);
gr_status gr_snow_sync_rect(gr_snow_deformation *s, int x0, int y0, int x1, int y1);
gr_status gr_snow_ledger_sums(gr_snow_deformation *s, long long *vol, long long *mass);

/* snow_deformation_step.c */
gr_status gr_snow_args(gr_snow_deformation *s, cl_kernel k, const gr_snow_arg *args, size_t n);

/* snow_deformation_talus.c */
gr_status gr_snow_relax(gr_snow_deformation *s, double dt);

/* snow_deformation_pieces.c */
gr_status gr_snow_piece_rings(const gr_grid *g, int ring[4], char *msg, size_t len);
int gr_snow_has_ring(const gr_snow_deformation *s);
int gr_snow_ring_width(const gr_snow_deformation *s);
void gr_snow_own_clip(const gr_snow_deformation *s, int *x0, int *y0, int *x1, int *y1);
gr_status gr_snow_allreduce(gr_snow_deformation *s, double *values, int n, gr_reduce_op op);
gr_status gr_snow_allreduce_i64(gr_snow_deformation *s, long long *v, int n);
gr_status gr_snow_piece_sync(gr_snow_deformation *s);
gr_status gr_snow_read_own(gr_snow_deformation *s, cl_mem buf, float *host);

#endif
