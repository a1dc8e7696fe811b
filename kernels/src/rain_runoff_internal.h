/* Rain runoff core, host side: what the host files share, and nothing of
 * the public API (graupel/rain_runoff.h): the limits and checkpoint layout,
 * the parameter table's rows, the handle's state, and the private functions
 * of rain_runoff.c (parameters, life cycle), rain_runoff_program.c (device
 * arrays, kernels' arguments, program and tiles), rain_runoff_inputs.c,
 * rain_runoff_step.c, rain_runoff_advance.c (stable step, advance),
 * rain_runoff_outputs.c and rain_runoff_pieces.c (halos, checkpoints). */
#ifndef GRAUPEL_RAIN_RUNOFF_INTERNAL_H
#define GRAUPEL_RAIN_RUNOFF_INTERNAL_H

#include "graupel/rain_runoff.h"
#include "graupel/cl_runtime.h"
#include "graupel/reduce.h"
#include "rain_runoff_shared.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Kernels index cells and faces with int: (nx+1)*(ny+1), with room to
 * spare, must stay below INT_MAX. */
#define GR_RAIN_RUNOFF_MAX_FACES ((double)INT_MAX - 1048576.0)
/* Physical sanity bounds set_field adds to field_validate's (finite, and in
 * the parameters' ranges): beyond them float differences overflow. */
#define GR_RAIN_RUNOFF_MAX_ELEVATION 1.0e6
#define GR_RAIN_RUNOFF_MAX_DEPTH 1.0e4
#define GR_RAIN_RUNOFF_MIN_DT 1.0e-30
/* The fused shallow-water stages are bound by their instructions and by
 * how many work-groups an NVIDIA GPU keeps in flight: capped at 32
 * registers (from 45 and 48) the H200's step at 4096^2 took 1.65 ms
 * against 1.87 (24: 1.77, 28: 1.69, 40: 1.73, 64: 1.94); the local
 * inertial step is the same either way (1.06 ms). Register allocation
 * changes no arithmetic: the same bits. NVIDIA's compiler applies the cap
 * only to kernels without reqd_work_group_size: since the fused stages
 * are built for their tile (GR_SW_TILE_ATTR) it bounds their registers by
 * itself (on the H200 32 for the interior's tiles, 47 for the rim's), so
 * the cap now binds the separate launches and the local inertial kernels
 * (RESULTS.md, "2026-12-01, fourth session"). A local inertial program is
 * built without it: its update, its loads all issued before its stores,
 * took 0.58 ms at 4096^2 uncapped against 0.67 capped (RESULTS.md,
 * "2026-12-02"). */
#define GR_RAIN_RUNOFF_NV_REGISTERS 32
/* The local inertial kernels' work-group on GPUs: 32 x 4 cells, a warp a
 * row (the runtime's 16 x 16 gives a warp two half rows: the H200's step
 * at 4096^2 took 1.04 ms with it, 0.70 with 32 x 4 and the update's loads
 * first). */
#define GR_RAIN_RUNOFF_LI_GROUP_X 32
#define GR_RAIN_RUNOFF_LI_GROUP_Y 4
/* advance re-reads the stable step after 1 to 64 steps (see
 * gr_rain_runoff_advance_impl). */
#define GR_RAIN_RUNOFF_CHUNK_MIN 1
#define GR_RAIN_RUNOFF_CHUNK_MAX 64
/* gr_rain_runoff_step waits after every this many steps: an OpenCL queue
 * holding thousands of launches grows the runtime's own pools for good
 * (PoCL here: 16-22 MB more resident after 1000-step calls than after
 * 100-step ones, measured by the soak), and a wait per 64 steps costs the
 * device nothing it would not idle anyway. */
#define GR_RAIN_RUNOFF_IN_FLIGHT 64
/* With a progress callback, advance waits on the queue after a batch of
 * steps that takes about this long (s), and calls the callback when at least
 * GR_RAIN_RUNOFF_PROGRESS_EVERY has passed since the last call. */
#define GR_RAIN_RUNOFF_BATCH_S 0.08
#define GR_RAIN_RUNOFF_PROGRESS_EVERY 0.1
/* Checkpoints: "GRR1" and the layout's version. */
#define GR_RAIN_RUNOFF_STATE_MAGIC 0x31525247u
/* 2: the piece's i0, j0; 3: qu, qv; 4: the maps; 5: the inflow; 6: the
 * ledger's initial water and rain in fixed point; 7: the wet duration by
 * its spells (ended spells and the start of the one under way, double-float
 * pairs) instead of a Kahan sum of every wet step's dt (version 6 is still
 * read: gr_rain_runoff_state_load) */
#define GR_RAIN_RUNOFF_STATE_VERSION 7u
/* The rain ledger's steps: dt in units of 2^-32 s (graupel/reduce.h's fixed
 * point for the rates; see gr_rain_runoff_rain_book). */
#define GR_RAIN_RUNOFF_STEP_BITS 32
/* Per-cell arrays of a checkpoint: h, h_c, k, inf, inf_c, out, out_c, qu, qv,
 * the flood maps' max_depth, max_speed, arrival, wet, wet_lo, max_hazard, the
 * inflow and its compensation, then the maps' wet_since and wet_since_lo
 * (version 6: the first 17, wet and wet_lo a Kahan sum and its
 * compensation). */
/* Per halo cell: h, k, west and south faces (local inertial); h, qu, qv and
 * h_c (shallow water). */
#define GR_RAIN_RUNOFF_HALO_ARRAYS 4
#define GR_RAIN_RUNOFF_STATE_CELL_ARRAYS 19
#define GR_RAIN_RUNOFF_STATE_CELL_ARRAYS_6 17
#define GR_RAIN_RUNOFF_MAP_ARRAYS 8
/* The local inertial model's smallest Manning n (shallow water allows 0). */
#define GR_RAIN_RUNOFF_LI_MIN_N 0.005

/* The parameter table's rows, in gr_rain_runoff_param_bounds' order. */
enum {
  GR_RAIN_RUNOFF_P_RAIN_RATE,
  GR_RAIN_RUNOFF_P_PERMEABILITY,
  GR_RAIN_RUNOFF_P_MANNING_N,
  GR_RAIN_RUNOFF_P_MAX_DT,
  GR_RAIN_RUNOFF_P_CFL,
  GR_RAIN_RUNOFF_P_BOUNDARY,                              /* four rows: west, east, south, north */
  GR_RAIN_RUNOFF_P_LEVEL = GR_RAIN_RUNOFF_P_BOUNDARY + 4, /* four rows, likewise */
  GR_RAIN_RUNOFF_P_FLOW_MODEL = GR_RAIN_RUNOFF_P_LEVEL + 4,
  GR_RAIN_RUNOFF_P_WETTING_DEPTH,
  GR_RAIN_RUNOFF_P_DEBRIS_FACTOR,
  GR_RAIN_RUNOFF_P_NO_DATA,
  GR_RAIN_RUNOFF_P_COUNT
};

struct gr_rain_runoff {
  gr_context *ctx;
  gr_grid grid;
  /* The local arrays: the piece's own nx x ny cells and its ring, ring[side]
   * cells wide on each side that has a neighbour (0 at the domain's edges;
   * both 0 for a whole grid). Every device array is nxl x nyl cells. */
  int nxl, nyl;
  int ring[4]; /* gr_rain_runoff_side order: west, east, south, north */
  gr_rain_runoff_params params;
  cl_kernel flux, flux_edges, limit, update, reduce, derive, sw_speed, maps, source;
  cl_kernel li_speed; /* the local inertial model's kinematic rate (the stable step) */
  /* The local inertial step in one launch (rain_runoff_li_step; fused: it
   * is used), its work-group (li_local; the tile is 3 smaller each way),
   * and the depth and limiter it writes, swapped with h and k after every
   * such step (h_alt, k_alt: made on first use). */
  cl_kernel li_step;
  int fused;
  size_t li_local[2];
  cl_mem h_alt, k_alt;
  /* The limiter and the update in one launch (rain_runoff_limit_update;
   * merged: the three launches take it in place of rain_runoff_limit and
   * rain_runoff_update, GPUs by default), reading h and writing h_alt,
   * swapped after every such step. */
  cl_kernel limit_update;
  int merged;
  /* The indices of the arguments that change every step, looked up once:
   * li_step's (h, h_out, limit, limit_out, qx_old, qy_old, qx, qy,
   * map_time), flux_edges' (h, limit, qx_old, qy_old, qx, qy), flux's
   * (qx_old, qy_old, qx, qy, h), limit's and update's (qx, qy; map_time),
   * limit_update's (qx, qy, map_time, h, h_out). */
  cl_uint ix_step[9], ix_edges[6], ix_flux[5], ix_limit[2], ix_update[3], ix_lu[5];
  /* rain_uniform of flux_edges, li_step, flux, limit, update, limit_update */
  cl_uint ix_rain[6];
  /* Shallow water's step: the points of stage 1, then per stage the faces
   * and the cells' update. */
  cl_kernel sw_prep, sw_faces[2], sw_update[2], sw_edges;
  /* The rim's faces of each stage (rain_runoff_sw_rim1, 2; sw_faces takes
   * the interior's), sw_rim_faces work-items. */
  cl_kernel sw_rim_faces[2];
  /* Or each stage in two launches, when sw_fused, in work-groups of
   * sw_local cells (the tile; sw_tile_bytes of local memory,
   * gr_rain_runoff_sw_shape): the interior's tiles (sw_inner:
   * rain_runoff_sw_inner1, 2; tile columns sw_tiles[0] .. sw_tiles[1] - 1,
   * rows sw_tiles[2] .. sw_tiles[3] - 1), then the sw_rim others (sw_stage:
   * rain_runoff_sw_stage1, 2). */
  cl_kernel sw_stage[2], sw_inner[2];
  int sw_fused;
  size_t sw_local[2], sw_tile_bytes, sw_rim;
  cl_int sw_tiles[4];
  /* The tile the program's fused stages were built for (GPUs: its size a
   * constant of the kernels, gr_rain_runoff_specialise); 0 x 0: any. */
  size_t sw_built[2];
  /* Every kernel comes from the program built for `inputs`: the optional
   * inputs' GR_RAIN_RUNOFF_IN_* bits, and GR_RAIN_RUNOFF_IN_ALL + 1 where it
   * has the shallow-water model's kernels (-1 before the first build;
   * gr_rain_runoff_specialise). specialise 0 keeps them general (every
   * input and both models, a program without options), which
   * gr_rain_runoff_set_specialised sets for tests and the bench. */
  int inputs, specialise;
  /* The device takes NVIDIA's compiler options (cl_nv_compiler_options):
   * the program is built with at most GR_RAIN_RUNOFF_NV_REGISTERS
   * registers a work-item. */
  int nv_registers;
  /* The device is a GPU: the program is built with -DGR_RAIN_RUNOFF_GPU=1
   * (the forms of a few expressions SIMT devices run without branches,
   * the same floats). */
  int gpu;
  cl_mem h, h_c, b, k, inf, inf_c, out, out_c;
  cl_mem in, in_c; /* inflow (edges and sources), per cell (m), and its compensation */
  /* Sources (m/s of depth): the point inflows' field (pts, once set) and
   * the field the steps read (src: pts plus the edges' hydrographs, made by
   * rain_runoff_source before every step while a hydrograph is set). */
  cl_mem pts, src;
  int has_pts;
  double pts_max; /* the largest point-inflow rate, m/s */
  /* The inflow hydrographs per edge (west, east, south, north): n rows of
   * time (s) and discharge (m^3/s); n 0 where there is none. */
  int edge_n[4];
  double *edge_t[4], *edge_q[4];
  /* The Manning map as n^2 per cell (once set; has_n2), and its smallest n. */
  cl_mem n2map;
  int has_n2;
  double n_min;
  /* No-data cells (NaN elevations): per cell of the local array 0 (of the
   * domain), 1 (a wall) or 2 (an outfall), on the device (nodata, once
   * there are some: has_nodata) and on the host (mask); the owned cells of
   * the domain (active_own), for the uniform rain. */
  cl_mem nodata;
  int has_nodata;
  unsigned char *mask;
  double active_own;
  /* The hyetograph: hy_n rows of time (s) and rain rate (m/s); 0: none. */
  int hy_n;
  double *hy_t, *hy_r;
  cl_mem qu, qv, h1, qu1, qv1, dh1; /* shallow water: discharges and Heun's stage */
  /* Shallow water within a step: stage 1's points (the depth after rain and
   * infiltration, velocities), stage 2's velocities, and the faces' fluxes
   * (4 floats per face). */
  cl_mem wh, wu, wv, u1, v1, fx, fy;
  cl_mem qu0, qv0;     /* initial discharges, once VELOCITY was set */
  cl_mem qx[2], qy[2]; /* discharges; [cur] is the latest, the other the next */
  /* The flood maps, in gr_rain_runoff_map order but for the class (read
   * from the rating), then the wet duration's low word and the start of the
   * cell's wet spell under way (hi, lo; -1: dry): GR_RAIN_RUNOFF_MAP_ARGS. */
  cl_mem map[GR_RAIN_RUNOFF_MAP_ARRAYS];
  int cur;
  cl_mem h0;      /* initial depth, once WATER_DEPTH was set */
  cl_mem rain;    /* rain-rate field, once set */
  cl_mem perm;    /* permeability field, once set */
  cl_mem scratch; /* derived fields on read (3 floats per cell), on first use */
  cl_mem dummy;   /* bound in place of a field that was not set */
  int has_rain, has_perm;
  gr_fixed rain_field_sum; /* the rain-rate field's floats summed in fixed point, m/s */
  double rain_field_max;   /* its largest value, m/s (the local array's, ring included) */
  /* g max(|db/dx| / dx + |db/dy| / dy) over the local array, 1/s^2: the
   * fastest the bed's slope can speed water up, per cell crossed. */
  double slope_rate;
  /* The lowest ground along each of the domain's edges (west, east, south,
   * north; 0 on a side with a neighbour): a level edge's depth over it is
   * water the stable step must see. */
  double edge_bed[4];
  /* The ledger's own cells' water in fixed point (graupel/reduce.h), so
   * that its sums over the pieces are the whole grid's to the bit: the
   * initial depth's floats (m), the initial water (m: that sum, and each
   * WATER_DEPTH set later replacing the water there), and the rain as exact
   * products of fixed-point rates (m/s) and steps in units of
   * 2^-GR_RAIN_RUNOFF_STEP_BITS s: rain_book[0] of the rates' coarse
   * words, rain_book[1] of their fine ones. */
  gr_fixed initial_sum, initial;
  gr_wide rain_book[2];
  double time;
  long long steps;
  gr_reduction_i64 ledger; /* the reduction behind the ledger and the stable step */
  gr_reduction speed;      /* shallow water's stable step: deepest cell, fastest wave rate */
  gr_reduction film;       /* the local inertial model's: the fastest film (li_speed) */
  /* The step kernels' arguments other than the alternating face arrays are
   * set again only when they change: the parameters, the input fields or
   * dt (steps_dt). */
  int args_set;
  cl_float args_dt;
  cl_mem args_h, args_k; /* the depth and limiter the step kernels were bound to */
  int maps_bound;        /* the maps kernel's arguments that change only with the parameters */
  gr_progress_fn progress;
  double progress_last; /* wall clock of the callback's last call, across advances (0: none) */
  void *progress_user;
  gr_allreduce_fn allreduce; /* NULL: this simulation is the whole domain's only piece */
  void *allreduce_user;
  gr_halo_exchange_fn halo_exchange; /* NULL: the caller exchanges between one-step calls */
  void *halo_user;
  char error[1024]; /* this handle's latest error (gr_error_keep) */
};

/* Every failing public entry point with a handle ends here. */
#define GR_RAIN_RUNOFF_KEEP_ERROR(s, st) gr_error_keep((s)->error, sizeof((s)->error), (st))

/* One kernel argument by its name in the kernel's source. */
typedef struct gr_rain_runoff_arg {
  const char *name;
  size_t size;
  const void *value;
} gr_rain_runoff_arg;

#define GR_RAIN_RUNOFF_ARGS(s, k, args)                                                            \
  gr_rain_runoff_args((s), (k), (args), sizeof(args) / sizeof((args)[0]))

/* advance's watch over the queue for its progress callback: it waits on the
 * queue after every `batch` steps, sized so a batch takes about
 * GR_RAIN_RUNOFF_BATCH_S, and calls the callback when enough wall time has
 * passed. Waiting changes when the host blocks, never what is computed. */
typedef struct gr_rain_runoff_watch {
  double last_call, last_wait;
  int batch, since;
  int global; /* a piece with an allreduce: the stop flag is reduced after every step */
} gr_rain_runoff_watch;

/* rain_runoff.c: the parameter table (the one place each range is written)
 * and its rows' ranges in the core's units. */
extern const gr_param_bound gr_rain_runoff_bounds[GR_RAIN_RUNOFF_P_COUNT];
double gr_rain_runoff_core_max(int row);
const char *gr_rain_runoff_field_label(gr_field f);
gr_status gr_rain_runoff_field_check(gr_field f, const float *values, size_t n, size_t nx,
                                     int strict, char *msg, size_t msg_len);

/* rain_runoff_program.c */
gr_status gr_rain_runoff_args(gr_rain_runoff *s, cl_kernel k, const gr_rain_runoff_arg *args,
                              size_t n);
size_t gr_rain_runoff_cells(const gr_rain_runoff *s);
size_t gr_rain_runoff_own_cells(const gr_rain_runoff *s);
int gr_rain_runoff_has_ring(const gr_rain_runoff *s);
gr_fixed gr_rain_runoff_own_sum(const gr_rain_runoff *s, const float *host);
gr_status gr_rain_runoff_arg_at(gr_rain_runoff *s, cl_kernel k, cl_uint index, size_t size,
                                const void *value);
gr_status gr_rain_runoff_fill(gr_rain_runoff *s, cl_mem buf, float value, size_t bytes);
gr_status gr_rain_runoff_clear_flow(gr_rain_runoff *s);
gr_status gr_rain_runoff_rect(gr_rain_runoff *s, cl_mem buf, size_t pitch, size_t comps, size_t x0,
                              size_t y0, size_t w, size_t h, void *host, int write);
gr_status gr_rain_runoff_read_own(gr_rain_runoff *s, cl_mem buf, size_t comps, float *host);
gr_status gr_rain_runoff_reduce_fixed(gr_rain_runoff *s, gr_fixed sums[GR_RAIN_RUNOFF_SUMS],
                                      double *max_depth);
gr_status gr_rain_runoff_deepest(gr_rain_runoff *s, double *max_depth);
gr_status gr_rain_runoff_sw_shape(gr_rain_runoff *s, size_t tx, size_t ty, int set_default);
gr_status gr_rain_runoff_reductions(gr_rain_runoff *s);
gr_status gr_rain_runoff_specialise(gr_rain_runoff *s);
gr_status gr_rain_runoff_inputs_changed(gr_rain_runoff *s, gr_status st);

/* rain_runoff_inputs.c */
double gr_rain_runoff_edge_depth(const gr_rain_runoff *s);
gr_status gr_rain_runoff_set_elevation(gr_rain_runoff *s, const float *host);
void gr_rain_runoff_blank(const gr_rain_runoff *s, float *host, size_t comps);
int gr_rain_runoff_has_edge_inflow(const gr_rain_runoff *s);
int gr_rain_runoff_has_sources(const gr_rain_runoff *s);
gr_status gr_rain_runoff_sources_update(gr_rain_runoff *s, double t0, double t1);
double gr_rain_runoff_source_max(const gr_rain_runoff *s);
void gr_rain_runoff_rain_book(gr_rain_runoff *s, const gr_fixed *hyetograph, cl_float dtf,
                              int done);
gr_status gr_rain_runoff_hyetograph_step(gr_rain_runoff *s, double t0, double t1, gr_fixed *sum);
double gr_rain_runoff_rain_max(const gr_rain_runoff *s);
double gr_rain_runoff_min_n(const gr_rain_runoff *s);

/* rain_runoff_step.c */
gr_status gr_rain_runoff_enqueue(gr_rain_runoff *s, double dt, int nsteps, gr_rain_runoff_watch *w,
                                 int *done_out, int *stop);

/* rain_runoff_advance.c */
gr_status gr_rain_runoff_watch_step(gr_rain_runoff *s, gr_rain_runoff_watch *w, double time,
                                    int *stop);

/* rain_runoff_outputs.c */
gr_status gr_rain_runoff_map_args(gr_rain_runoff *s, cl_kernel k);
cl_float4 gr_rain_runoff_map_time(double t0, double t1);
gr_status gr_rain_runoff_maps_update(gr_rain_runoff *s, double time);
gr_status gr_rain_runoff_maps_restart(gr_rain_runoff *s);

/* rain_runoff_pieces.c */
gr_status gr_rain_runoff_piece(const gr_grid *g, gr_flow_model model, int ring[4], char *msg,
                               size_t len);
gr_status gr_rain_runoff_allreduce(gr_rain_runoff *s, double *values, int n, gr_reduce_op op);
gr_status gr_rain_runoff_exchange(gr_rain_runoff *s, long long step);

#endif
