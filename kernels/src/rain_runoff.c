/* Rain runoff core (seed 004's water simulation): host side of
 * rain_runoff.cl. The model, the step order and the book-keeping are
 * documented in graupel/rain_runoff.h; the kernels' data layout in
 * rain_runoff.cl; the constants both sides share in rain_runoff_shared.h. */
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
 * (RESULTS.md, "2026-12-01, fourth session"). */
#define GR_RAIN_RUNOFF_NV_REGISTERS 32
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
 * ledger's initial water and rain in fixed point */
#define GR_RAIN_RUNOFF_STATE_VERSION 6u
/* The rain ledger's steps: dt in units of 2^-32 s (graupel/reduce.h's fixed
 * point for the rates; see gr_rain_runoff_rain_book). */
#define GR_RAIN_RUNOFF_STEP_BITS 32
/* Per-cell arrays of a checkpoint: h, h_c, k, inf, inf_c, out, out_c, qu, qv,
 * the flood maps' max_depth, max_speed, arrival, wet, wet_c, max_hazard, and
 * the inflow and its compensation. */
/* Per halo cell: h, k, west and south faces (local inertial); h, qu, qv and
 * h_c (shallow water). */
#define GR_RAIN_RUNOFF_HALO_ARRAYS 4
#define GR_RAIN_RUNOFF_STATE_CELL_ARRAYS 17
#define GR_RAIN_RUNOFF_MAP_ARRAYS 6
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

/* The one place each range is written: the validator, the field checks, the
 * filter's clamps, the XML domains and the README follow it. */
static const gr_param_bound gr_rain_runoff_bounds[GR_RAIN_RUNOFF_P_COUNT] = {
    {"RainRate", "mm/h", 0.0, 3600.0, 100.0, 1.0 / 3.6e6, 0, 0},
    {"Permeability", "mm/h", 0.0, 36000.0, 0.0, 1.0 / 3.6e6, 0, 0},
    {"ManningN", "s/m^(1/3)", 0.0, 1.0, 0.03, 1.0, 0, 0},
    {"MaxTimeStep", "s", 0.0, 3600.0, 3600.0, 1.0, 1, 0},
    {"CourantNumber", "", 0.0, 1.0, 0.7, 1.0, 1, 0},
    {"BoundaryWest", "", 0.0, 3.0, 0.0, 1.0, 0, 1},
    {"BoundaryEast", "", 0.0, 3.0, 0.0, 1.0, 0, 1},
    {"BoundarySouth", "", 0.0, 3.0, 0.0, 1.0, 0, 1},
    {"BoundaryNorth", "", 0.0, 3.0, 0.0, 1.0, 0, 1},
    {"LevelWest", "m", -1.0e6, 1.0e6, 0.0, 1.0, 0, 0},
    {"LevelEast", "m", -1.0e6, 1.0e6, 0.0, 1.0, 0, 0},
    {"LevelSouth", "m", -1.0e6, 1.0e6, 0.0, 1.0, 0, 0},
    {"LevelNorth", "m", -1.0e6, 1.0e6, 0.0, 1.0, 0, 0},
    {"FlowModel", "", 0.0, 1.0, 0.0, 1.0, 0, 1},
    {"WettingDepth", "m", 0.0, 10.0, 0.01, 1.0, 1, 0},
    {"DebrisFactor", "", 0.0, 1.0, 0.0, 1.0, 0, 0},
    {"NoDataBoundary", "", 0.0, 1.0, 1.0, 1.0, 0, 1},
};

/* A row's range in the core's unit: exactly the products a caller gets from
 * the user's bounds times to_core, so the user's own bounds are accepted. */
static double gr_rain_runoff_core_min(int row) {
  return gr_rain_runoff_bounds[row].min * gr_rain_runoff_bounds[row].to_core;
}
static double gr_rain_runoff_core_max(int row) {
  return gr_rain_runoff_bounds[row].max * gr_rain_runoff_bounds[row].to_core;
}

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
  /* The indices of the arguments that change every step, looked up once:
   * li_step's (h, h_out, limit, limit_out, qx_old, qy_old, qx, qy,
   * map_time), flux_edges' (h, limit, qx_old, qy_old, qx, qy), flux's
   * (qx_old, qy_old, qx, qy), limit's and update's (qx, qy; map_time). */
  cl_uint ix_step[9], ix_edges[6], ix_flux[4], ix_limit[2], ix_update[3];
  cl_uint ix_rain[5]; /* rain_uniform of flux_edges, li_step, flux, limit, update */
  /* Shallow water's step: the points of stage 1, then per stage the faces
   * and the cells' update. */
  cl_kernel sw_prep, sw_faces[2], sw_update[2], sw_edges;
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
   * from the rating) and with the wet duration's Kahan compensation last. */
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

static int gr_rain_runoff_has_sources(const gr_rain_runoff *s);
static int gr_rain_runoff_has_edge_inflow(const gr_rain_runoff *s);
static gr_status gr_rain_runoff_sources_update(gr_rain_runoff *s, double t0, double t1);
static gr_status gr_rain_runoff_set_elevation(gr_rain_runoff *s, const float *host);

/* Every failing public entry point with a handle ends here. */
#define GR_RAIN_RUNOFF_KEEP_ERROR(s, st) gr_error_keep((s)->error, sizeof((s)->error), (st))

const gr_param_bound *gr_rain_runoff_param_bounds(int *count) {
  if (count)
    *count = GR_RAIN_RUNOFF_P_COUNT;
  return gr_rain_runoff_bounds;
}

const char *gr_rain_runoff_last_error(const gr_rain_runoff *s) {
  return s ? s->error : "";
}

void gr_rain_runoff_params_init(gr_rain_runoff_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  const gr_param_bound *t = gr_rain_runoff_bounds;
  p->rain_rate =
      t[GR_RAIN_RUNOFF_P_RAIN_RATE].default_value * t[GR_RAIN_RUNOFF_P_RAIN_RATE].to_core;
  p->permeability =
      t[GR_RAIN_RUNOFF_P_PERMEABILITY].default_value * t[GR_RAIN_RUNOFF_P_PERMEABILITY].to_core;
  p->manning_n = t[GR_RAIN_RUNOFF_P_MANNING_N].default_value;
  p->max_dt = t[GR_RAIN_RUNOFF_P_MAX_DT].default_value;
  p->cfl = t[GR_RAIN_RUNOFF_P_CFL].default_value;
  for (int e = 0; e < 4; ++e) {
    p->boundary[e] = (gr_boundary)(int)t[GR_RAIN_RUNOFF_P_BOUNDARY + e].default_value;
    p->boundary_level[e] = t[GR_RAIN_RUNOFF_P_LEVEL + e].default_value;
  }
  p->flow_model = (gr_flow_model)(int)t[GR_RAIN_RUNOFF_P_FLOW_MODEL].default_value;
  p->wetting_depth = t[GR_RAIN_RUNOFF_P_WETTING_DEPTH].default_value;
  p->debris_factor = t[GR_RAIN_RUNOFF_P_DEBRIS_FACTOR].default_value;
  p->no_data = (gr_boundary)(int)t[GR_RAIN_RUNOFF_P_NO_DATA].default_value;
}

/* The core's value of row `row` in p. */
static double gr_rain_runoff_param_value(const gr_rain_runoff_params *p, int row) {
  switch (row) {
  case GR_RAIN_RUNOFF_P_RAIN_RATE:
    return p->rain_rate;
  case GR_RAIN_RUNOFF_P_PERMEABILITY:
    return p->permeability;
  case GR_RAIN_RUNOFF_P_MANNING_N:
    return p->manning_n;
  case GR_RAIN_RUNOFF_P_MAX_DT:
    return p->max_dt;
  case GR_RAIN_RUNOFF_P_CFL:
    return p->cfl;
  case GR_RAIN_RUNOFF_P_WETTING_DEPTH:
    return p->wetting_depth;
  case GR_RAIN_RUNOFF_P_DEBRIS_FACTOR:
    return p->debris_factor;
  case GR_RAIN_RUNOFF_P_NO_DATA: {
    int k; /* any bit pattern the enum may hold */
    memcpy(&k, &p->no_data, sizeof(k));
    return (double)k;
  }
  case GR_RAIN_RUNOFF_P_FLOW_MODEL: {
    int m; /* any bit pattern the enum may hold */
    memcpy(&m, &p->flow_model, sizeof(m));
    return (double)m;
  }
  default:
    if (row >= GR_RAIN_RUNOFF_P_LEVEL)
      return p->boundary_level[row - GR_RAIN_RUNOFF_P_LEVEL];
    else {
      int b; /* any bit pattern the enum may hold */
      memcpy(&b, &p->boundary[row - GR_RAIN_RUNOFF_P_BOUNDARY], sizeof(b));
      return (double)b;
    }
  }
}

gr_status gr_rain_runoff_params_validate(const gr_rain_runoff_params *p, char *msg,
                                         size_t msg_len) {
  if (!p) {
    if (msg && msg_len)
      snprintf(msg, msg_len, "Invalid rain runoff parameters: no parameters were given.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  for (int row = 0; row < GR_RAIN_RUNOFF_P_COUNT; ++row) {
    const gr_param_bound *r = &gr_rain_runoff_bounds[row];
    double v = gr_rain_runoff_param_value(p, row);
    if (gr_param_accepts(r, v))
      continue;
    gr_param_explain(r, v, "Invalid rain runoff parameters", msg, msg_len);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (p->flow_model == GR_FLOW_LOCAL_INERTIAL && p->manning_n < GR_RAIN_RUNOFF_LI_MIN_N) {
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "Invalid rain runoff parameters: ManningN must be at least %g s/m^(1/3) for "
               "FlowModel 1 (local inertial) (got %g); raise it, or take FlowModel 0 (shallow "
               "water), which allows 0.",
               GR_RAIN_RUNOFF_LI_MIN_N, p->manning_n);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

static const char *gr_rain_runoff_field_label(gr_field f) {
  const char *name = gr_field_name(f);
  return name ? name : "(unknown field)";
}

/* field_validate's checks; with nx > 0 the bad value is named by its cell
 * (i, j), otherwise by its index. strict adds set_field's sanity bounds. */
static gr_status gr_rain_runoff_field_check(gr_field f, const float *values, size_t n, size_t nx,
                                            int strict, char *msg, size_t msg_len) {
  const char *rule = NULL;
  char rule_text[160];
  double lo = -HUGE_VAL, hi = HUGE_VAL;
  size_t comps = 1;
  int nan_ok = 0;
  switch (f) {
  case GR_FIELD_ELEVATION:
    /* NaN marks a no-data cell (outside the domain); infinities are refused. */
    nan_ok = 1;
    rule = strict ? "elevations must be within +-1e6 m, or NaN for a no-data cell"
                  : "elevations must be finite, or NaN for a no-data cell";
    if (strict) {
      lo = -GR_RAIN_RUNOFF_MAX_ELEVATION;
      hi = GR_RAIN_RUNOFF_MAX_ELEVATION;
    }
    break;
  case GR_FIELD_WATER_SURFACE:
    rule = strict ? "water surfaces must be finite and within +-1e6 m"
                  : "water surfaces must be finite";
    if (strict) {
      lo = -GR_RAIN_RUNOFF_MAX_ELEVATION;
      hi = GR_RAIN_RUNOFF_MAX_ELEVATION;
    }
    break;
  case GR_FIELD_VELOCITY:
    rule = "velocities must be finite and within +-1000 m/s";
    lo = -1000.0;
    hi = 1000.0;
    comps = 3;
    break;
  case GR_FIELD_WATER_DEPTH:
    rule = strict ? "depths must be finite, at least 0 and at most 1e4 m"
                  : "depths must be finite and at least 0 m";
    lo = 0.0;
    if (strict)
      hi = GR_RAIN_RUNOFF_MAX_DEPTH;
    break;
  case GR_FIELD_PERMEABILITY:
  case GR_FIELD_RAIN_RATE: {
    /* The maps replace the uniform parameters: the same range, in m/s. */
    int row = f == GR_FIELD_RAIN_RATE ? GR_RAIN_RUNOFF_P_RAIN_RATE : GR_RAIN_RUNOFF_P_PERMEABILITY;
    lo = gr_rain_runoff_core_min(row);
    hi = gr_rain_runoff_core_max(row);
    snprintf(rule_text, sizeof(rule_text),
             "%s must lie between %g and %g m/s (%g to %g %s), like %s",
             f == GR_FIELD_RAIN_RATE ? "rain rates" : "permeabilities", lo, hi,
             gr_rain_runoff_bounds[row].min, gr_rain_runoff_bounds[row].max,
             gr_rain_runoff_bounds[row].unit, gr_rain_runoff_bounds[row].property);
    rule = rule_text;
    break;
  }
  default:
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "The field '%s' is not an input of the rain runoff simulation; its inputs are "
               "elevation, water_depth, water_surface, velocity, permeability and rain_rate.",
               gr_rain_runoff_field_label(f));
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (!values) {
    if (msg && msg_len)
      snprintf(msg, msg_len, "No values were given for the field '%s'.",
               gr_rain_runoff_field_label(f));
    return GR_ERR_INVALID_ARGUMENT;
  }
  for (size_t c = 0; c < n; ++c) {
    double v = values[c];
    if ((isfinite(v) && v >= lo && v <= hi) || (nan_ok && isnan(v)))
      continue;
    if (msg && msg_len) {
      if (nx > 0)
        snprintf(msg, msg_len, "The field '%s' has the value %g at cell (%zu, %zu): %s.",
                 gr_rain_runoff_field_label(f), v, c / comps % nx, c / comps / nx, rule);
      else
        snprintf(msg, msg_len,
                 "The field '%s' has the value %g at index %zu (row-major, x fastest): %s.",
                 gr_rain_runoff_field_label(f), v, c, rule);
    }
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

gr_status gr_rain_runoff_field_validate(gr_field f, const float *values, size_t n, char *msg,
                                        size_t msg_len) {
  return gr_rain_runoff_field_check(f, values, n, 0, 0, msg, msg_len);
}

/* ----------------------------------------------------------- device state */

/* Cells of the local arrays (the piece and its ring). */
static size_t gr_rain_runoff_cells(const gr_rain_runoff *s) {
  return (size_t)s->nxl * (size_t)s->nyl;
}

/* Cells the piece owns: those of the ledger and of get_field. */
static size_t gr_rain_runoff_own_cells(const gr_rain_runoff *s) {
  return (size_t)s->grid.nx * (size_t)s->grid.ny;
}

static int gr_rain_runoff_has_ring(const gr_rain_runoff *s) {
  return s->ring[0] || s->ring[1] || s->ring[2] || s->ring[3];
}

/* The sum of a local-array field's floats over the owned cells in fixed
 * point: the same integers as the device's reduction of the same floats,
 * whatever the split. */
static gr_fixed gr_rain_runoff_own_sum(const gr_rain_runoff *s, const float *host) {
  gr_fixed sum = {0, 0};
  for (int j = s->ring[2]; j < s->nyl - s->ring[3]; ++j)
    for (int i = s->ring[0]; i < s->nxl - s->ring[1]; ++i) {
      size_t c = (size_t)j * (size_t)s->nxl + (size_t)i;
      if (!s->has_nodata || !s->mask[c]) /* nothing falls on, or stays in, no-data cells */
        gr_fixed_add(&sum, gr_fixed_from_float(host[c]));
    }
  return sum;
}

/* One kernel argument by its name in the kernel's source. */
typedef struct gr_rain_runoff_arg {
  const char *name;
  size_t size;
  const void *value;
} gr_rain_runoff_arg;

/* Sets the arguments in `args` of kernel k by name; the first failure names
 * the kernel and the argument. */
static gr_status gr_rain_runoff_args(gr_rain_runoff *s, cl_kernel k, const gr_rain_runoff_arg *args,
                                     size_t n) {
  gr_status st = GR_OK;
  for (size_t i = 0; st == GR_OK && i < n; ++i)
    st = gr_kernel_arg(s->ctx, k, args[i].name, args[i].size, args[i].value);
  return st;
}
#define GR_RAIN_RUNOFF_ARGS(s, k, args)                                                            \
  gr_rain_runoff_args((s), (k), (args), sizeof(args) / sizeof((args)[0]))

/* The indices of kernel k's arguments called names[0..n) (the programs
 * carry argument names, gr_program_get): the step loops set the arguments
 * that change every step by index, without gr_kernel_arg's look-up (a
 * mutex and a query per argument), which shows on small grids. */
static gr_status gr_rain_runoff_arg_indices(gr_rain_runoff *s, cl_kernel k,
                                            const char *const *names, int n, cl_uint *out) {
  cl_uint nargs = 0;
  cl_int err = clGetKernelInfo(k, CL_KERNEL_NUM_ARGS, sizeof(nargs), &nargs, NULL);
  for (int a = 0; err == CL_SUCCESS && a < n; ++a) {
    out[a] = nargs;
    for (cl_uint i = 0; err == CL_SUCCESS && i < nargs && out[a] == nargs; ++i) {
      char name[64] = "";
      err = clGetKernelArgInfo(k, i, CL_KERNEL_ARG_NAME, sizeof(name), name, NULL);
      if (err == CL_SUCCESS && strcmp(name, names[a]) == 0)
        out[a] = i;
    }
    if (err == CL_SUCCESS && out[a] == nargs)
      return gr_set_error(s->ctx, GR_ERR_OPENCL,
                          "A rain runoff step kernel has no argument '%s': the kernels' source "
                          "and rain_runoff.c disagree; rebuild Graupel.",
                          names[a]);
  }
  return gr_cl_check(s->ctx, err, "Reading the rain runoff step kernels' argument names");
}

/* Sets argument `index` of kernel k (see gr_rain_runoff_arg_indices). */
static gr_status gr_rain_runoff_arg_at(gr_rain_runoff *s, cl_kernel k, cl_uint index, size_t size,
                                       const void *value) {
  return gr_cl_check(s->ctx, clSetKernelArg(k, index, size, value),
                     "Setting a rain runoff step kernel's argument");
}

/* Looks up the indices of the step kernels' changing arguments. */
static gr_status gr_rain_runoff_step_indices(gr_rain_runoff *s) {
  static const char *const step[] = {"h",      "h_out", "limit", "limit_out", "qx_old",
                                     "qy_old", "qx",    "qy",    "map_time"};
  static const char *const edges[] = {"h", "limit", "qx_old", "qy_old", "qx", "qy"};
  static const char *const update[] = {"qx", "qy", "map_time"};
  gr_status st = gr_rain_runoff_arg_indices(s, s->li_step, step, 9, s->ix_step);
  if (st == GR_OK)
    st = gr_rain_runoff_arg_indices(s, s->flux_edges, edges, 6, s->ix_edges);
  if (st == GR_OK)
    st = gr_rain_runoff_arg_indices(s, s->flux, edges + 2, 4, s->ix_flux);
  if (st == GR_OK)
    st = gr_rain_runoff_arg_indices(s, s->limit, update, 2, s->ix_limit);
  if (st == GR_OK)
    st = gr_rain_runoff_arg_indices(s, s->update, update, 3, s->ix_update);
  static const char *const rain[] = {"rain_uniform"};
  cl_kernel li[5] = {s->flux_edges, s->li_step, s->flux, s->limit, s->update};
  for (int k = 0; st == GR_OK && k < 5; ++k)
    st = gr_rain_runoff_arg_indices(s, li[k], rain, 1, &s->ix_rain[k]);
  return st;
}

/* The device's largest work-group and its local memory (bytes). */
static cl_int gr_rain_runoff_group_limits(const gr_rain_runoff *s, size_t *most,
                                          cl_ulong *local_mem) {
  cl_device_id dev = gr_context_device(s->ctx);
  cl_int err = clGetDeviceInfo(dev, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof(*most), most, NULL);
  if (err == CL_SUCCESS)
    err = clGetDeviceInfo(dev, CL_DEVICE_LOCAL_MEM_SIZE, sizeof(*local_mem), local_mem, NULL);
  return err;
}

/* The fused local inertial step's work-group (rain_runoff_li_step: a tile
 * 3 cells smaller each way, whose faces it computes again for the ring
 * around the tile) and whether it is the default. A GPU: the largest of 32
 * x 16, 16 x 16, 16 x 8 and 8 x 8 that the kernel's registers and the local
 * memory allow (a tile of 29 x 13 computes 1.36 times the faces of its
 * cells, 13 x 13 1.5 times; the redundant reads hit the caches); one launch
 * by default, the step's traffic in one pass. A CPU: 64 x 16 (61 x 13), three launches by default:
 * with PoCL on this project's 2-core machine the one launch took about 1.5 times the CPU time of
 * the three at 256^2 to 1024^2 (its ring's faces again, every cell's limiter five times, and LLVM's
 * code for its two regions), where the caches hide most of what the three launches read again. */
static gr_status gr_rain_runoff_li_shape(gr_rain_runoff *s) {
  cl_ulong local_mem = 0;
  size_t most = 0, wg = 0;
  cl_int err = gr_rain_runoff_group_limits(s, &most, &local_mem);
  if (err == CL_SUCCESS)
    err = clGetKernelWorkGroupInfo(s->li_step, gr_context_device(s->ctx), CL_KERNEL_WORK_GROUP_SIZE,
                                   sizeof(wg), &wg, NULL);
  if (err != CL_SUCCESS)
    return gr_cl_check(s->ctx, err, "Querying the device for the local inertial step's work-group");
  static const size_t gpu_shapes[][2] = {{32, 16}, {16, 16}, {16, 8}, {8, 8}, {8, 8}};
  static const size_t cpu_shapes[][2] = {{64, 16}, {32, 16}, {16, 16}, {16, 8}, {8, 8}};
  const size_t(*shapes)[2] = s->gpu ? gpu_shapes : cpu_shapes;
  int fits = 0;
  for (int k = 0; k < 5 && !fits; ++k) {
    s->li_local[0] = shapes[k][0];
    s->li_local[1] = shapes[k][1];
    size_t items = shapes[k][0] * shapes[k][1];
    fits = items <= wg && 3 * items * sizeof(cl_float) <= local_mem;
  }
  /* Where not even 8 x 8 fits (a tile of 5 x 5), the three launches only. */
  if (!fits)
    s->li_local[0] = s->li_local[1] = 0;
  /* Not the default anywhere (gr_rain_runoff_create): the fused step
   * recomputes the ring's faces and each cell's limiter five times, and
   * measured slower on both kinds of device (the H200 at 4096^2: 1.34 ms a
   * step against 1.14; PoCL here about 1.5x). gr_rain_runoff_set_fused
   * picks it, where the device allows its work-group. */
  s->fused = s->fused && s->li_local[0] > 0;
  return GR_OK;
}

static gr_status gr_rain_runoff_fill(gr_rain_runoff *s, cl_mem buf, float value, size_t bytes) {
  return gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), buf, &value, sizeof(value), 0,
                                         bytes, 0, NULL, NULL),
                     "Filling a device buffer");
}

/* Discharges none, limiters 1 (nothing was limited). */
static gr_status gr_rain_runoff_clear_flow(gr_rain_runoff *s) {
  size_t nx = (size_t)s->nxl, ny = (size_t)s->nyl;
  gr_status st = GR_OK;
  for (int a = 0; a < 2 && st == GR_OK; ++a) {
    st = gr_rain_runoff_fill(s, s->qx[a], 0.0f, (nx + 1) * ny * sizeof(float));
    if (st == GR_OK)
      st = gr_rain_runoff_fill(s, s->qy[a], 0.0f, nx * (ny + 1) * sizeof(float));
  }
  if (st == GR_OK)
    st = gr_rain_runoff_fill(s, s->k, 1.0f, nx * ny * sizeof(float));
  if (st == GR_OK)
    st = gr_rain_runoff_fill(s, s->qu, 0.0f, nx * ny * sizeof(float));
  if (st == GR_OK)
    st = gr_rain_runoff_fill(s, s->qv, 0.0f, nx * ny * sizeof(float));
  return st;
}

/* Copies the floats of cells [x0, x0+w) x [y0, y0+h) of a local array with
 * `comps` floats per cell and rows of `pitch` cells between the device and
 * a packed host block (w * comps floats per row); waits. */
static gr_status gr_rain_runoff_rect(gr_rain_runoff *s, cl_mem buf, size_t pitch, size_t comps,
                                     size_t x0, size_t y0, size_t w, size_t h, void *host,
                                     int write) {
  const size_t f = sizeof(cl_float) * comps;
  size_t origin[3] = {x0 * f, y0, 0}, host_origin[3] = {0, 0, 0}, region[3] = {w * f, h, 1};
  cl_command_queue q = gr_context_queue(s->ctx);
  cl_int err = write ? clEnqueueWriteBufferRect(q, buf, CL_TRUE, origin, host_origin, region,
                                                pitch * f, 0, w * f, 0, host, 0, NULL, NULL)
                     : clEnqueueReadBufferRect(q, buf, CL_TRUE, origin, host_origin, region,
                                               pitch * f, 0, w * f, 0, host, 0, NULL, NULL);
  return gr_cl_check(s->ctx, err,
                     write ? "Writing a halo strip to the device"
                           : "Reading part of a field back from the device");
}

/* Reads the owned cells of a local array (comps floats per cell): the whole
 * array for a grid without a ring. */
static gr_status gr_rain_runoff_read_own(gr_rain_runoff *s, cl_mem buf, size_t comps, float *host) {
  if (!gr_rain_runoff_has_ring(s))
    return gr_buffer_read(s->ctx, buf, 0, gr_rain_runoff_cells(s) * comps * sizeof(cl_float), host);
  return gr_rain_runoff_rect(s, buf, (size_t)s->nxl, comps, (size_t)s->ring[0], (size_t)s->ring[2],
                             (size_t)s->grid.nx, (size_t)s->grid.ny, host, 0);
}

/* Sums the stored, infiltrated, outflow and inflow depths over the owned
 * cells in fixed point (m, so times dx dy for m^3; sums NULL: none) and
 * finds the deepest cell. */
static gr_status gr_rain_runoff_reduce_fixed(gr_rain_runoff *s, gr_fixed sums[GR_RAIN_RUNOFF_SUMS],
                                             double *max_depth) {
  cl_int n = (cl_int)gr_rain_runoff_cells(s);
  /* The owned cells of the local arrays (masked only where there is a ring). */
  cl_int row = s->nxl, own_x0 = s->ring[0], own_x1 = s->nxl - s->ring[1];
  cl_int own_y0 = s->ring[2], own_y1 = s->nyl - s->ring[3];
  cl_int masked = gr_rain_runoff_has_ring(s), with_sums = sums != NULL;
  const gr_rain_runoff_arg args[] = {
      {"with_sums", sizeof(with_sums), &with_sums},
      {"h", sizeof(cl_mem), &s->h},
      {"h_comp", sizeof(cl_mem), &s->h_c},
      {"infiltrated", sizeof(cl_mem), &s->inf},
      {"infiltrated_comp", sizeof(cl_mem), &s->inf_c},
      {"outflow", sizeof(cl_mem), &s->out},
      {"outflow_comp", sizeof(cl_mem), &s->out_c},
      {"inflow", sizeof(cl_mem), &s->in},
      {"inflow_comp", sizeof(cl_mem), &s->in_c},
      {"n", sizeof(n), &n},
      {"row", sizeof(row), &row},
      {"own_x0", sizeof(own_x0), &own_x0},
      {"own_x1", sizeof(own_x1), &own_x1},
      {"own_y0", sizeof(own_y0), &own_y0},
      {"own_y1", sizeof(own_y1), &own_y1},
      {"masked", sizeof(masked), &masked},
  };
  long long words[2 * GR_RAIN_RUNOFF_SUMS], maxes[GR_RAIN_RUNOFF_MAXES];
  gr_status st = GR_RAIN_RUNOFF_ARGS(s, s->reduce, args);
  if (st == GR_OK)
    st = gr_reduction_i64_run_max(s->ctx, &s->ledger, s->reduce, words, maxes);
  if (st != GR_OK)
    return st;
  for (int q = 0; sums && q < GR_RAIN_RUNOFF_SUMS; ++q) {
    sums[q].coarse = words[2 * q];
    sums[q].fine = words[2 * q + 1];
  }
  if (max_depth) {
    /* The deepest cell's float, by its bits (a depth is never below 0). */
    int32_t bits = (int32_t)maxes[0];
    float deepest;
    memcpy(&deepest, &bits, sizeof(deepest));
    *max_depth = deepest;
  }
  return GR_OK;
}

/* The deepest owned cell only (the stable step): the ledger's reduction
 * reading the depth alone. */
static gr_status gr_rain_runoff_deepest(gr_rain_runoff *s, double *max_depth) {
  return gr_rain_runoff_reduce_fixed(s, NULL, max_depth);
}

/* ------------------------------------------------------------ flood maps */

/* Folds the state now into the flood maps (rain_runoff_maps): `time` is the
 * state's time (s), dt the step that led to it (0: count no time). */
static gr_status gr_rain_runoff_maps_update(gr_rain_runoff *s, double time, double dt) {
  const size_t m = sizeof(cl_mem);
  gr_status st = GR_OK;
  if (!s->maps_bound) {
    cl_int nx = s->nxl, ny = s->nyl, sw = s->params.flow_model == GR_FLOW_SHALLOW_WATER;
    cl_float wd = (cl_float)s->params.wetting_depth, df = (cl_float)s->params.debris_factor;
    const gr_rain_runoff_arg args[] = {
        {"qu", m, &s->qu},
        {"qv", m, &s->qv},
        {"max_depth", m, &s->map[0]},
        {"max_speed", m, &s->map[1]},
        {"arrival", m, &s->map[2]},
        {"wet_time", m, &s->map[3]},
        {"max_hazard", m, &s->map[4]},
        {"wet_time_comp", m, &s->map[5]},
        {"nx", sizeof(nx), &nx},
        {"ny", sizeof(ny), &ny},
        {"sw", sizeof(sw), &sw},
        {"wetting_depth", sizeof(wd), &wd},
        {"debris_factor", sizeof(df), &df},
    };
    st = GR_RAIN_RUNOFF_ARGS(s, s->maps, args);
    s->maps_bound = st == GR_OK;
  }
  cl_float t = (cl_float)time, dtf = (cl_float)dt;
  /* The depth and limiter alternate with the fused local inertial step. */
  const gr_rain_runoff_arg step[] = {
      {"h", m, &s->h},           {"limit", m, &s->k},     {"qx", m, &s->qx[s->cur]},
      {"qy", m, &s->qy[s->cur]}, {"time", sizeof(t), &t}, {"dt", sizeof(dtf), &dtf},
  };
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->maps, step);
  /* Read-modify-write per cell: the kernel takes (i, j) and leaves the
   * padding of the rounded-up launch alone, so each cell runs once. */
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->maps, 0, 0, (size_t)s->nxl, (size_t)s->nyl, NULL);
  return st;
}

/* The maps of the water there now only (create, reset): nothing yet, never
 * wet (arrival -1), then the present state folded in at the present time. */
static gr_status gr_rain_runoff_maps_restart(gr_rain_runoff *s) {
  size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
  gr_status st = GR_OK;
  for (int a = 0; st == GR_OK && a < GR_RAIN_RUNOFF_MAP_ARRAYS; ++a)
    st = gr_rain_runoff_fill(s, s->map[a], a == 2 ? -1.0f : 0.0f, bytes);
  if (st == GR_OK)
    st = gr_rain_runoff_maps_update(s, s->time, 0.0);
  return st;
}

/* ------------------------------------------------------------- life cycle */

/* The piece contract (graupel.h, rain_runoff.h): which sides have a
 * neighbour, and so a ring of GR_RAIN_RUNOFF_GHOST cells. */
static gr_status gr_rain_runoff_piece(const gr_grid *g, gr_flow_model model, int ring[4], char *msg,
                                      size_t len) {
  const int G = model == GR_FLOW_SHALLOW_WATER ? GR_RAIN_RUNOFF_GHOST_SW : GR_RAIN_RUNOFF_GHOST;
  long long gnx = g->global_nx > 0 ? g->global_nx : g->nx;
  long long gny = g->global_ny > 0 ? g->global_ny : g->ny;
  int whole_x = g->global_nx <= 0, whole_y = g->global_ny <= 0;
  memset(ring, 0, 4 * sizeof(int));
  if (g->global_nx < 0 || g->global_ny < 0 || g->ghost < 0) {
    snprintf(msg, len,
             "Invalid grid: global_nx, global_ny and ghost must be 0 or more (got %d, %d, %d).",
             g->global_nx, g->global_ny, g->ghost);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if ((!whole_x && (long long)g->i0 + g->nx > gnx) ||
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
             "Invalid grid: a rain runoff piece with neighbours needs a ghost ring of %d points "
             "for FlowModel %d (got ghost = %d); set grid.ghost to %d.",
             G, (int)model, g->ghost, G);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (((ring[0] || ring[1]) && g->nx < G) || ((ring[2] || ring[3]) && g->ny < G)) {
    snprintf(msg, len,
             "Invalid grid: a rain runoff piece of %d x %d points is narrower than its ghost ring "
             "of %d toward a neighbour; split the domain into fewer pieces.",
             g->nx, g->ny, G);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

/* The local memory of a fused shallow-water stage's tile of tx x ty cells
 * (gr_sw_fused): its points with two cells either side (a float4 each),
 * six planes of x-faces and six of y-faces. */
static size_t gr_rain_runoff_sw_tile_bytes(size_t tx, size_t ty) {
  return sizeof(cl_float) * (4 * (tx + 4) * (ty + 4) + 6 * ((tx + 1) * ty + tx * (ty + 1)));
}

/* The default tile of a device whose work-groups take at most `most`
 * work-items and local_mem bytes: 32 x 8, halved until it fits. Measured
 * on the H200 at 4096^2 (ms a step): 32 x 8 1.51, 64 x 4 1.59, 32 x 4 1.63
 * (and before the interior's kernel and the register cap, 16 x 8 2.48,
 * 16 x 16 2.50 against 32 x 8 2.16); with the tile's size built into the
 * kernels, 32 x 8 1.12, 16 x 16 1.76. */
static void gr_rain_runoff_sw_default_tile(size_t most, cl_ulong local_mem, size_t *tx,
                                           size_t *ty) {
  *tx = 32;
  *ty = 8;
  while (*ty > 1 && (*tx * *ty > most || gr_rain_runoff_sw_tile_bytes(*tx, *ty) > local_mem))
    *ty /= 2;
  while (*tx > 1 && (*tx * *ty > most || gr_rain_runoff_sw_tile_bytes(*tx, *ty) > local_mem))
    *tx /= 2;
}

/* The fused shallow-water stages' work-group (rain_runoff_sw_stage1, 2): a
 * tile of tx x ty cells (0 x 0: the device's default), refused where the
 * device's work-groups or local memory are too small for it; with
 * set_default also whether the fused path is the default. A GPU: fused by
 * default (a step moves the state twice instead of storing and reading
 * every face and point, see gr_sw_fused; the H200 at 4096^2: 2.16 ms a step
 * against 2.65). A CPU: not fused by default: with PoCL
 * on this project's 2-core machine a fused step took 4-7x the separate
 * launches' time (512^2: 32-35 ms against 7.7-8.5; 1024^2: 160-250 ms
 * against 36), where the caches hide most of what the separate launches
 * store and read again. */
static gr_status gr_rain_runoff_sw_shape(gr_rain_runoff *s, size_t tx, size_t ty, int set_default) {
  cl_device_id dev = gr_context_device(s->ctx);
  cl_ulong local_mem = 0;
  size_t most = 0;
  cl_int err = gr_rain_runoff_group_limits(s, &most, &local_mem);
  /* The smallest work-group any of the four kernels takes. A local
   * inertial program has no stages: the device's largest work-group until
   * the model changes, when the tile is checked again
   * (gr_rain_runoff_specialise). */
  cl_kernel stages[4] = {s->sw_stage[0], s->sw_stage[1], s->sw_inner[0], s->sw_inner[1]};
  for (int k = 0; err == CL_SUCCESS && k < 4; ++k) {
    size_t wg = most;
    if (stages[k])
      err = clGetKernelWorkGroupInfo(stages[k], dev, CL_KERNEL_WORK_GROUP_SIZE, sizeof(wg), &wg,
                                     NULL);
    most = wg < most ? wg : most;
  }
  if (err != CL_SUCCESS)
    return gr_cl_check(s->ctx, err, "Querying the device for the shallow-water stages' work-group");
  if (tx == 0 && ty == 0)
    gr_rain_runoff_sw_default_tile(most, local_mem, &tx, &ty);
  size_t bytes = gr_rain_runoff_sw_tile_bytes(tx, ty);
  if (tx == 0 || ty == 0 || tx * ty > most || bytes > local_mem)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The shallow-water tile of %zu x %zu cells does not fit the device: it "
                        "takes at most %zu work-items and %llu bytes of local memory (the tile "
                        "needs %zu); take a smaller tile, or 0 x 0 for the device's default.",
                        tx, ty, most, (unsigned long long)local_mem, bytes);
  s->sw_local[0] = tx;
  s->sw_local[1] = ty;
  s->sw_tile_bytes = bytes;
  /* The interior's tiles: those whose faces all lie two cells or more
   * inside the local array (i0 >= 2, i0 + tx + 2 <= nx, and so along y);
   * with none, every tile is the rim's (rows 0 .. ntj - 1 below an empty
   * interior). */
  size_t nti = ((size_t)s->nxl + tx - 1) / tx, ntj = ((size_t)s->nyl + ty - 1) / ty;
  size_t ilo = (2 + tx - 1) / tx, ihi = s->nxl >= 2 ? ((size_t)s->nxl - 2) / tx : 0;
  size_t jlo = (2 + ty - 1) / ty, jhi = s->nyl >= 2 ? ((size_t)s->nyl - 2) / ty : 0;
  if (ihi <= ilo || jhi <= jlo) {
    ilo = ihi = 0;
    jlo = jhi = ntj;
  }
  s->sw_tiles[0] = (cl_int)ilo;
  s->sw_tiles[1] = (cl_int)ihi;
  s->sw_tiles[2] = (cl_int)jlo;
  s->sw_tiles[3] = (cl_int)jhi;
  s->sw_rim = nti * ntj - (ihi - ilo) * (jhi - jlo);
  if (set_default)
    s->sw_fused = s->gpu;
  s->args_set = 0;
  return GR_OK;
}

/* The ledger's and the stable steps' reductions, (re)made for their
 * kernels' work-groups. */
static gr_status gr_rain_runoff_reductions(gr_rain_runoff *s) {
  size_t cells = (size_t)s->nxl * (size_t)s->nyl;
  gr_reduction_i64_release(&s->ledger);
  gr_reduction_release(&s->speed);
  gr_reduction_release(&s->film);
  gr_status st = gr_reduction_i64_init_max(s->ctx, s->reduce, cells, 2 * GR_RAIN_RUNOFF_SUMS,
                                           GR_RAIN_RUNOFF_MAXES, &s->ledger);
  if (st == GR_OK && s->sw_speed) /* a shallow-water program's */
    st = gr_reduction_init(s->ctx, s->sw_speed, cells, 0, 2, &s->speed);
  if (st == GR_OK)
    st = gr_reduction_init(s->ctx, s->li_speed, cells, 0, 1, &s->film);
  return st;
}

/* The optional inputs in use, GR_RAIN_RUNOFF_IN_* bits. */
static int gr_rain_runoff_inputs_used(const gr_rain_runoff *s) {
  return (s->has_rain ? GR_RAIN_RUNOFF_IN_RAIN : 0) | (s->has_perm ? GR_RAIN_RUNOFF_IN_PERM : 0) |
         (gr_rain_runoff_has_sources(s) ? GR_RAIN_RUNOFF_IN_SRC : 0) |
         (s->has_nodata ? GR_RAIN_RUNOFF_IN_NODATA : 0) | (s->has_n2 ? GR_RAIN_RUNOFF_IN_N2 : 0);
}

/* Takes every kernel from the program built for the inputs in use (every
 * input where specialise is 0) when they are not already from it: the
 * program is found or built (gr_program_get: once per context and
 * options), the kernels made, and only then the old ones released; the
 * argument indices, the fused work-groups, the reductions and the
 * arguments follow. Called at creation, by the setters of inputs
 * (gr_rain_runoff_inputs_changed), and before every batch of steps and
 * every local inertial stable step (a switch of specialise, or a build
 * that failed before). */
static gr_status gr_rain_runoff_specialise(gr_rain_runoff *s) {
  /* The inputs' bits, and the shallow-water kernels above them: a local
   * inertial simulation's program leaves those out. */
  int sw = !s->specialise || s->params.flow_model == GR_FLOW_SHALLOW_WATER;
  int inputs = s->specialise ? gr_rain_runoff_inputs_used(s) : GR_RAIN_RUNOFF_IN_ALL;
  int want = inputs | (sw ? GR_RAIN_RUNOFF_IN_ALL + 1 : 0);
  /* A GPU's shallow-water program is built for its tile (GR_SW_TILE_X, Y:
   * the one set, or before one is the device's default): the fused stages
   * then take only that work-group. */
  size_t tile[2] = {0, 0};
  if (s->gpu && sw) {
    tile[0] = s->sw_local[0];
    tile[1] = s->sw_local[1];
    cl_ulong local_mem = 0;
    size_t most = 0;
    if (tile[0] == 0 && gr_rain_runoff_group_limits(s, &most, &local_mem) == CL_SUCCESS)
      gr_rain_runoff_sw_default_tile(most, local_mem, &tile[0], &tile[1]);
  }
  if (want == s->inputs && tile[0] == s->sw_built[0] && tile[1] == s->sw_built[1])
    return GR_OK;
  static const char *const names[] = {
      "rain_runoff_flux",       "rain_runoff_flux_edges", "rain_runoff_limit",
      "rain_runoff_update",     "rain_runoff_li_step",    "rain_runoff_sw_prep",
      "rain_runoff_sw_faces1",  "rain_runoff_sw_faces2",  "rain_runoff_sw_update1",
      "rain_runoff_sw_update2", "rain_runoff_sw_edges",   "rain_runoff_sw_stage1",
      "rain_runoff_sw_stage2",  "rain_runoff_reduce",     "rain_runoff_derive",
      "rain_runoff_sw_speed",   "rain_runoff_li_speed",   "rain_runoff_maps",
      "rain_runoff_source",     "rain_runoff_sw_inner1",  "rain_runoff_sw_inner2"};
  enum { GR_RR_KERNELS = sizeof(names) / sizeof(names[0]) };
  /* The shallow-water model's kernels (none in a local inertial program). */
  static const unsigned char sw_only[GR_RR_KERNELS] = {0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1,
                                                       1, 1, 0, 0, 1, 0, 0, 0, 1, 1};
  cl_kernel *slots[GR_RR_KERNELS] = {
      &s->flux,       &s->flux_edges,  &s->limit,       &s->update,       &s->li_step,
      &s->sw_prep,    &s->sw_faces[0], &s->sw_faces[1], &s->sw_update[0], &s->sw_update[1],
      &s->sw_edges,   &s->sw_stage[0], &s->sw_stage[1], &s->reduce,       &s->derive,
      &s->sw_speed,   &s->li_speed,    &s->maps,        &s->source,       &s->sw_inner[0],
      &s->sw_inner[1]};
  char opt[224] = "";
  int len = 0;
  if (s->specialise)
    len = snprintf(opt, sizeof(opt), "-DGR_RAIN_RUNOFF_INPUTS=%d -DGR_RAIN_RUNOFF_SW=%d ", inputs,
                   sw);
  if (s->gpu)
    len += snprintf(opt + len, sizeof(opt) - (size_t)len, "-DGR_RAIN_RUNOFF_GPU=1 ");
  if (tile[0] > 0)
    len += snprintf(opt + len, sizeof(opt) - (size_t)len, "-DGR_SW_TILE_X=%zu -DGR_SW_TILE_Y=%zu ",
                    tile[0], tile[1]);
  if (s->nv_registers)
    snprintf(opt + len, sizeof(opt) - (size_t)len, "-cl-nv-maxrregcount=%d",
             GR_RAIN_RUNOFF_NV_REGISTERS);
  cl_program prog = NULL;
  gr_status st = gr_program_get(s->ctx, "rain_runoff", opt[0] ? opt : NULL, &prog);
  cl_kernel made[GR_RR_KERNELS] = {NULL};
  for (int k = 0; st == GR_OK && k < GR_RR_KERNELS; ++k)
    if (sw || !sw_only[k])
      st = gr_kernel_create(s->ctx, prog, names[k], &made[k]);
  if (st != GR_OK) {
    for (int k = 0; k < GR_RR_KERNELS; ++k)
      if (made[k])
        clReleaseKernel(made[k]);
    return st;
  }
  int first = s->inputs < 0;
  for (int k = 0; k < GR_RR_KERNELS; ++k) {
    if (*slots[k])
      clReleaseKernel(*slots[k]);
    *slots[k] = made[k];
  }
  /* Until all that follows holds, the next call builds them again. */
  s->inputs = -1;
  s->sw_built[0] = tile[0];
  s->sw_built[1] = tile[1];
  s->args_set = 0;
  s->maps_bound = 0;
  st = gr_rain_runoff_step_indices(s);
  if (st == GR_OK)
    st = gr_rain_runoff_li_shape(s);
  /* The shallow-water tile, checked against the new kernels (at creation
   * the caller picks the default); one that no longer fits becomes it. */
  if (st == GR_OK && !first && gr_rain_runoff_sw_shape(s, s->sw_local[0], s->sw_local[1], 0))
    st = gr_rain_runoff_sw_shape(s, 0, 0, 0);
  /* The reductions' work-groups, from their new kernels (at creation the
   * caller makes them). */
  if (st == GR_OK && !first)
    st = gr_rain_runoff_reductions(s);
  if (st == GR_OK)
    s->inputs = want;
  /* A tile that had to change (it no longer fitted): built for the new one. */
  if (st == GR_OK && !first && tile[0] > 0 &&
      (s->sw_local[0] != tile[0] || s->sw_local[1] != tile[1]))
    st = gr_rain_runoff_specialise(s);
  return st;
}

/* After a setter (its status st) that may have changed the inputs in use:
 * the kernels follow at once. Kernels built for more inputs than are in use
 * are right too; where a build fails (out of memory), the kernels that read
 * inputs (the steps' and the local inertial stable step's) are made again
 * before they next run: gr_rain_runoff_enqueue and
 * gr_rain_runoff_stable_dt_impl call gr_rain_runoff_specialise first. The
 * other kernels read no optional input. */
static gr_status gr_rain_runoff_inputs_changed(gr_rain_runoff *s, gr_status st) {
  return st == GR_OK ? gr_rain_runoff_specialise(s) : st;
}

void gr_rain_runoff_set_specialised(gr_rain_runoff *s, int on) {
  if (s)
    s->specialise = on != 0;
}

/* The public bits are the kernels' (rain_runoff_shared.h). */
_Static_assert(GR_RAIN_RUNOFF_INPUT_RAIN == GR_RAIN_RUNOFF_IN_RAIN &&
                   GR_RAIN_RUNOFF_INPUT_PERMEABILITY == GR_RAIN_RUNOFF_IN_PERM &&
                   GR_RAIN_RUNOFF_INPUT_INFLOWS == GR_RAIN_RUNOFF_IN_SRC &&
                   GR_RAIN_RUNOFF_INPUT_NO_DATA == GR_RAIN_RUNOFF_IN_NODATA &&
                   GR_RAIN_RUNOFF_INPUT_MANNING == GR_RAIN_RUNOFF_IN_N2 &&
                   GR_RAIN_RUNOFF_INPUT_ALL == GR_RAIN_RUNOFF_IN_ALL,
               "the optional inputs' bits");

int gr_rain_runoff_specialised_for(const gr_rain_runoff *s) {
  return s && s->inputs >= 0 ? s->inputs & GR_RAIN_RUNOFF_IN_ALL : -1;
}

gr_status gr_rain_runoff_memory(const gr_context *ctx, const gr_grid *grid,
                                const gr_rain_runoff_params *p, int inputs, gr_memory_need *out) {
  if (!grid || !p || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_memory needs a grid, parameters and a place for the "
                        "answer.");
  /* A piece's ring (at most grid->ghost cells each way). */
  int ring = grid->ghost > 0 ? grid->ghost : 0;
  double nx = (double)grid->nx + 2.0 * ring, ny = (double)grid->ny + 2.0 * ring, cells = nx * ny;
  double faces = (nx + 1.0) * ny + nx * (ny + 1.0);
  /* gr_rain_runoff_create's per_cell (21) and flood maps, the derive
   * kernel's scratch (3), the initial water h0 (1). */
  double planes = 21.0 + GR_RAIN_RUNOFF_MAP_ARRAYS + 3.0 + 1.0;
  planes += (inputs & GR_RAIN_RUNOFF_INPUT_RAIN) ? 1.0 : 0.0;
  planes += (inputs & GR_RAIN_RUNOFF_INPUT_PERMEABILITY) ? 1.0 : 0.0;
  planes += (inputs & GR_RAIN_RUNOFF_INPUT_INFLOWS) ? 2.0 : 0.0; /* src, pts */
  planes += (inputs & GR_RAIN_RUNOFF_INPUT_NO_DATA) ? 1.0 : 0.0;
  planes += (inputs & GR_RAIN_RUNOFF_INPUT_MANNING) ? 1.0 : 0.0;
  double face_planes = 2.0; /* qx[2] and qy[2]: two sets of x- and y-faces */
  /* The separate shallow-water launches' x- and y-face arrays
   * (gr_rain_runoff_face_arrays): where the stages are not fused. */
  int separate = p->flow_model == GR_FLOW_SHALLOW_WATER && !(ctx && gr_context_is_gpu(ctx));
  face_planes += separate ? 6.0 : 0.0;
  memset(out, 0, sizeof(*out));
  out->points = (double)grid->nx * (double)grid->ny;
  out->device = sizeof(cl_float) * (planes * cells + face_planes * faces);
  out->largest = sizeof(cl_float) * (separate ? 6.0 * (nx + 1.0) * ny : 3.0 * cells);
  out->host = ((inputs & GR_RAIN_RUNOFF_INPUT_NO_DATA) ? 1.0 : 0.0) * cells + 8.0 * cells;
  /* gr_rain_runoff_state_bytes, the header aside */
  out->state = sizeof(float) * (GR_RAIN_RUNOFF_STATE_CELL_ARRAYS * cells + faces);
  return GR_OK;
}

gr_status gr_rain_runoff_create(gr_context *ctx, const gr_grid *grid,
                                const gr_rain_runoff_params *p, gr_rain_runoff **out) {
  char msg[256];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_create needs a context and a place for the simulation.");
  *out = NULL;
  if (gr_grid_validate(grid, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (gr_rain_runoff_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  int ring[4];
  if (gr_rain_runoff_piece(grid, p->flow_model, ring, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);

  size_t nx = (size_t)grid->nx + (size_t)ring[0] + (size_t)ring[1];
  size_t ny = (size_t)grid->ny + (size_t)ring[2] + (size_t)ring[3], cells = nx * ny;
  if (((double)nx + 1.0) * ((double)ny + 1.0) > GR_RAIN_RUNOFF_MAX_FACES)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The rain runoff grid of %zu x %zu points is too large: the kernels "
                        "address at most about 2.1e9 faces; split the domain or coarsen it.",
                        nx, ny);
  gr_memory_need need;
  gr_rain_runoff_memory(ctx, grid, p, 0, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The rain runoff state of a %zu x %zu grid %s: use a smaller grid or "
                        "another device.",
                        nx, ny, msg);
  gr_status st = GR_OK;
  gr_rain_runoff *s = calloc(1, sizeof(*s));
  if (!s)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  s->ctx = gr_context_retain(ctx);
  s->grid = *grid;
  s->nxl = (int)nx;
  s->nyl = (int)ny;
  memcpy(s->ring, ring, sizeof(ring));
  s->params = *p;
  size_t bytes = cells * sizeof(cl_float);
  /* The kernels: for the inputs in use (none yet), made again when they
   * change (gr_rain_runoff_specialise). */
  s->inputs = -1;
  s->specialise = 1;
  size_t ext_len = 0;
  char *ext = NULL;
  if (clGetDeviceInfo(gr_context_device(ctx), CL_DEVICE_EXTENSIONS, 0, NULL, &ext_len) ==
          CL_SUCCESS &&
      (ext = calloc(ext_len + 1, 1)) != NULL &&
      clGetDeviceInfo(gr_context_device(ctx), CL_DEVICE_EXTENSIONS, ext_len, ext, NULL) ==
          CL_SUCCESS)
    s->nv_registers = strstr(ext, "cl_nv_compiler_options") != NULL;
  free(ext);
  cl_device_type type = 0;
  if (clGetDeviceInfo(gr_context_device(ctx), CL_DEVICE_TYPE, sizeof(type), &type, NULL) ==
      CL_SUCCESS)
    s->gpu = (type & CL_DEVICE_TYPE_GPU) != 0;
  st = gr_rain_runoff_specialise(s);
  if (st == GR_OK)
    st = gr_rain_runoff_sw_shape(s, 0, 0, 1);
  /* The fused local inertial step is not the default (see li_shape). */
  s->fused = 0;
  for (int a = 0; st == GR_OK && a < GR_RAIN_RUNOFF_MAP_ARRAYS; ++a)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, &s->map[a]);
  cl_mem *per_cell[] = {&s->h,     &s->h_c, &s->b,    &s->k,  &s->inf, &s->inf_c, &s->out,
                        &s->out_c, &s->in,  &s->in_c, &s->qu, &s->qv,  &s->h1,    &s->qu1,
                        &s->qv1,   &s->dh1, &s->wh,   &s->wu, &s->wv,  &s->u1,    &s->v1};
  for (size_t i = 0; st == GR_OK && i < sizeof(per_cell) / sizeof(per_cell[0]); ++i)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, per_cell[i]);
  for (int a = 0; a < 2 && st == GR_OK; ++a) {
    st =
        gr_buffer_create(ctx, CL_MEM_READ_WRITE, (nx + 1) * ny * sizeof(cl_float), NULL, &s->qx[a]);
    if (st == GR_OK)
      st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, nx * (ny + 1) * sizeof(cl_float), NULL,
                            &s->qy[a]);
  }
  /* Bound where an input is absent, and for the face arrays before they
   * exist (gr_rain_runoff_face_arrays, arguments the kernels may write):
   * read-write, though nothing reads or writes it. */
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, sizeof(cl_float), NULL, &s->dummy);
  if (st == GR_OK)
    st = gr_rain_runoff_reductions(s);
  /* Dry, flat ground; nothing infiltrated or gone. */
  cl_mem *zeroed[] = {&s->h,  &s->h_c,  &s->b,  &s->inf, &s->inf_c, &s->out, &s->out_c,
                      &s->in, &s->in_c, &s->h1, &s->qu1, &s->qv1,   &s->dh1, &s->dummy};
  for (size_t i = 0; st == GR_OK && i < sizeof(zeroed) / sizeof(zeroed[0]); ++i)
    st =
        gr_rain_runoff_fill(s, *zeroed[i], 0.0f, *zeroed[i] == s->dummy ? sizeof(cl_float) : bytes);
  if (st == GR_OK)
    st = gr_rain_runoff_clear_flow(s);
  if (st == GR_OK)
    st = gr_rain_runoff_maps_restart(s);
  if (st == GR_OK)
    st = gr_finish(ctx);
  if (st != GR_OK) {
    gr_rain_runoff_destroy(s);
    return st;
  }
  *out = s;
  return GR_OK;
}

void gr_rain_runoff_destroy(gr_rain_runoff *s) {
  if (!s)
    return;
  cl_kernel kernels[] = {
      s->flux,        s->limit,       s->update,       s->reduce,       s->derive,   s->sw_prep,
      s->sw_faces[0], s->sw_faces[1], s->sw_update[0], s->sw_update[1], s->sw_speed, s->maps,
      s->source,      s->flux_edges,  s->sw_edges,     s->li_speed,     s->li_step};
  for (size_t i = 0; i < sizeof(kernels) / sizeof(kernels[0]); ++i)
    if (kernels[i])
      clReleaseKernel(kernels[i]);
  cl_mem *bufs[] = {&s->h,    &s->h_c,     &s->b,      &s->qx[0], &s->qy[0], &s->qx[1], &s->qy[1],
                    &s->k,    &s->inf,     &s->inf_c,  &s->out,   &s->out_c, &s->h0,    &s->rain,
                    &s->perm, &s->scratch, &s->dummy,  &s->qu,    &s->qv,    &s->h1,    &s->qu1,
                    &s->qv1,  &s->qu0,     &s->qv0,    &s->dh1,   &s->in,    &s->in_c,  &s->pts,
                    &s->src,  &s->n2map,   &s->nodata, &s->wh,    &s->wu,    &s->wv,    &s->u1,
                    &s->v1,   &s->fx,      &s->fy,     &s->h_alt, &s->k_alt};
  for (size_t i = 0; i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    gr_buffer_release(bufs[i]);
  for (int a = 0; a < GR_RAIN_RUNOFF_MAP_ARRAYS; ++a)
    gr_buffer_release(&s->map[a]);
  for (int k = 0; k < 2; ++k) {
    if (s->sw_stage[k])
      clReleaseKernel(s->sw_stage[k]);
    if (s->sw_inner[k])
      clReleaseKernel(s->sw_inner[k]);
  }
  gr_reduction_i64_release(&s->ledger);
  gr_reduction_release(&s->speed);
  gr_reduction_release(&s->film);
  for (int e = 0; e < 4; ++e) {
    free(s->edge_t[e]);
    free(s->edge_q[e]);
  }
  free(s->hy_t);
  free(s->hy_r);
  free(s->mask);
  gr_context_release(s->ctx);
  free(s);
}

gr_status gr_rain_runoff_set_params(gr_rain_runoff *s, const gr_rain_runoff_params *p) {
  char msg[256];
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_params needs a simulation.");
  if (gr_rain_runoff_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg));
  if (p->flow_model == GR_FLOW_LOCAL_INERTIAL && s->has_n2 && s->n_min < GR_RAIN_RUNOFF_LI_MIN_N)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The Manning map's smallest n is %g s/m^(1/3), below the %g that FlowModel "
                        "1 (local inertial) needs; raise the map's values, or keep FlowModel 0 "
                        "(shallow water).",
                        s->n_min, GR_RAIN_RUNOFF_LI_MIN_N));
  if (p->flow_model != s->params.flow_model) {
    /* The models keep their discharges in different places: the water
     * stays and starts from rest. A piece's ring width is its model's. */
    if (gr_rain_runoff_has_ring(s))
      return GR_RAIN_RUNOFF_KEEP_ERROR(
          s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "A rain runoff piece with neighbours cannot change its FlowModel (from "
                          "%d to %d): its ghost ring is the model's; create the pieces anew.",
                          (int)s->params.flow_model, (int)p->flow_model));
    gr_status st = gr_rain_runoff_clear_flow(s);
    if (st != GR_OK)
      return GR_RAIN_RUNOFF_KEEP_ERROR(s, st);
  }
  int rebuild = s->has_nodata && p->no_data != s->params.no_data;
  s->params = *p;
  s->args_set = 0;
  s->maps_bound = 0;
  if (rebuild) {
    /* The no-data cells turn from walls to outfalls or back: their bed and
     * kind, from the elevation on the device and the mask. */
    size_t cells = gr_rain_runoff_cells(s);
    float *b = malloc(cells * sizeof(float));
    if (!b)
      return GR_RAIN_RUNOFF_KEEP_ERROR(
          s, gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory."));
    gr_status st = gr_buffer_read(s->ctx, s->b, 0, cells * sizeof(cl_float), b);
    for (size_t c = 0; c < cells; ++c)
      if (s->mask[c])
        b[c] = NAN;
    if (st == GR_OK)
      st = gr_rain_runoff_set_elevation(s, b);
    free(b);
    return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_inputs_changed(s, st));
  }
  /* A new FlowModel takes its program. */
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_inputs_changed(s, GR_OK));
}

/* Uploads into *buf, allocating it on first use. */
static gr_status gr_rain_runoff_upload(gr_rain_runoff *s, cl_mem *buf, const float *host) {
  size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
  if (!*buf)
    return gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bytes, host, buf);
  return gr_buffer_write(s->ctx, *buf, 0, bytes, host);
}

/* The lowest ground along each of the domain's edges in the local array
 * `z` (s->edge_bed; 0 on a side with a neighbour). */
static void gr_rain_runoff_edge_beds(gr_rain_runoff *s, const float *z) {
  const int nx = s->nxl, ny = s->nyl;
  for (int e = 0; e < 4; ++e) {
    double low = HUGE_VAL;
    int n = e < 2 ? ny : nx;
    for (int k = 0; !s->ring[e] && k < n; ++k) {
      int i = e == 0 ? 0 : (e == 1 ? nx - 1 : k), j = e < 2 ? k : (e == 2 ? 0 : ny - 1);
      double v = z[(size_t)j * (size_t)nx + (size_t)i];
      low = v < low ? v : low;
    }
    s->edge_bed[e] = s->ring[e] ? 0.0 : low;
  }
}

/* The deepest water a level edge holds over its edge's lowest ground (m; 0
 * without level edges): the stable step counts it as water in the grid. */
static double gr_rain_runoff_edge_depth(const gr_rain_runoff *s) {
  double deepest = 0.0;
  for (int e = 0; e < 4; ++e) {
    if (s->ring[e] || s->params.boundary[e] != GR_BOUNDARY_LEVEL)
      continue;
    double d = s->params.boundary_level[e] - s->edge_bed[e];
    deepest = d > deepest ? d : deepest;
  }
  return deepest;
}

static gr_status gr_rain_runoff_rain_sum(gr_rain_runoff *s);

/* The bed the kernels see in a no-data cell: a wall far above any ground
 * and water (elevations lie within +-1e6 m), or an outfall's cliff far
 * below it, over which water pours out (the hydrostatic reconstruction and
 * the local inertial faces then pass what the cell above it sends, and the
 * cell drains every step). Fixed heights: every piece sees the same. */
#define GR_RAIN_RUNOFF_NODATA_WALL 2.0e6f
#define GR_RAIN_RUNOFF_NODATA_CLIFF -2.0e6f

/* Uploads the elevation (NaN: no-data cells, as the params' kind makes
 * them), the no-data map when there are no-data cells, and the owned
 * domain cells' count; the rain field's sum follows the new mask. */
static gr_status gr_rain_runoff_set_elevation(gr_rain_runoff *s, const float *host) {
  size_t cells = gr_rain_runoff_cells(s);
  int any = 0;
  for (size_t c = 0; c < cells && !any; ++c)
    any = isnan(host[c]);
  if (!any) {
    free(s->mask);
    s->mask = NULL;
    s->has_nodata = 0;
    s->args_set = 0;
    gr_status st = gr_buffer_write(s->ctx, s->b, 0, cells * sizeof(cl_float), host);
    if (st == GR_OK && s->has_rain)
      st = gr_rain_runoff_rain_sum(s);
    return st;
  }
  unsigned char *mask = malloc(cells);
  float *b = malloc(cells * sizeof(float)), *kind = malloc(cells * sizeof(float));
  if (!mask || !b || !kind) {
    free(mask);
    free(b);
    free(kind);
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  int outfall = s->params.no_data == GR_BOUNDARY_OPEN;
  double active = 0.0;
  for (size_t c = 0; c < cells; ++c) {
    mask[c] = isnan(host[c]) ? 1 : 0;
    b[c] = mask[c] ? (outfall ? GR_RAIN_RUNOFF_NODATA_CLIFF : GR_RAIN_RUNOFF_NODATA_WALL) : host[c];
    kind[c] = mask[c] ? (outfall ? 2.0f : 1.0f) : 0.0f;
  }
  for (int j = s->ring[2]; j < s->nyl - s->ring[3]; ++j)
    for (int i = s->ring[0]; i < s->nxl - s->ring[1]; ++i)
      active += !mask[(size_t)j * (size_t)s->nxl + (size_t)i];
  gr_status st = gr_buffer_write(s->ctx, s->b, 0, cells * sizeof(cl_float), b);
  if (st == GR_OK)
    st = gr_rain_runoff_upload(s, &s->nodata, kind);
  free(b);
  free(kind);
  if (st != GR_OK) {
    free(mask);
    return st;
  }
  free(s->mask);
  s->mask = mask;
  s->has_nodata = 1;
  s->active_own = active;
  s->args_set = 0;
  return s->has_rain ? gr_rain_runoff_rain_sum(s) : GR_OK;
}

/* The rain field's sum over the owned domain cells and its largest value,
 * read back from the device (after the no-data cells changed). */
static gr_status gr_rain_runoff_rain_sum(gr_rain_runoff *s) {
  size_t cells = gr_rain_runoff_cells(s);
  float *r = malloc(cells * sizeof(float));
  if (!r)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  gr_status st = gr_buffer_read(s->ctx, s->rain, 0, cells * sizeof(cl_float), r);
  if (st == GR_OK) {
    s->rain_field_sum = gr_rain_runoff_own_sum(s, r);
    s->rain_field_max = 0.0;
    for (size_t c = 0; c < cells; ++c)
      if ((!s->has_nodata || !s->mask[c]) && r[c] > s->rain_field_max)
        s->rain_field_max = r[c];
  }
  free(r);
  return st;
}

/* After a read of the owned cells (comps floats each): NaN in no-data cells. */
static void gr_rain_runoff_blank(const gr_rain_runoff *s, float *host, size_t comps) {
  if (!s->has_nodata)
    return;
  size_t k = 0;
  for (int j = s->ring[2]; j < s->nyl - s->ring[3]; ++j)
    for (int i = s->ring[0]; i < s->nxl - s->ring[1]; ++i, ++k)
      if (s->mask[(size_t)j * (size_t)s->nxl + (size_t)i])
        for (size_t q = 0; q < comps; ++q)
          host[k * comps + q] = NAN;
}

static gr_status gr_rain_runoff_set_field_impl(gr_rain_runoff *s, gr_field f, const float *host) {
  char msg[320];
  size_t cells = gr_rain_runoff_cells(s);
  size_t values = f == GR_FIELD_VELOCITY ? 3 * cells : cells;
  if (gr_rain_runoff_field_check(f, host, values, (size_t)s->nxl, 1, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (f == GR_FIELD_VELOCITY && s->params.flow_model != GR_FLOW_SHALLOW_WATER)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The field 'velocity' is an input of FlowModel 0 (shallow water) only, and "
                        "this simulation runs FlowModel %d (local inertial), which starts from "
                        "rest: leave it out, or take FlowModel 0.",
                        (int)s->params.flow_model);
  if (f == GR_FIELD_WATER_SURFACE) {
    /* The depth under the surface, as WATER_DEPTH sets it. */
    float *d = malloc(cells * sizeof(float));
    if (!d)
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    gr_status st = gr_buffer_read(s->ctx, s->b, 0, cells * sizeof(cl_float), d);
    for (size_t c = 0; st == GR_OK && c < cells; ++c) {
      float depth = host[c] - d[c];
      d[c] = depth > 0.0f ? depth : 0.0f;
    }
    if (st == GR_OK)
      st = gr_rain_runoff_set_field_impl(s, GR_FIELD_WATER_DEPTH, d);
    free(d);
    return st;
  }
  if (f == GR_FIELD_VELOCITY) {
    /* The discharges h (u, v) of the water there now; they are also the
     * initial ones that reset returns to. */
    float *q = malloc(3 * cells * sizeof(float));
    if (!q)
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    float *qx = q + cells, *qy = q + 2 * cells;
    gr_status st = gr_buffer_read(s->ctx, s->h, 0, cells * sizeof(cl_float), q);
    for (size_t c = 0; st == GR_OK && c < cells; ++c) {
      qx[c] = q[c] * host[3 * c];
      qy[c] = q[c] * host[3 * c + 1];
    }
    if (st == GR_OK)
      st = gr_rain_runoff_upload(s, &s->qu0, qx);
    if (st == GR_OK)
      st = gr_rain_runoff_upload(s, &s->qv0, qy);
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, s->qu, 0, cells * sizeof(cl_float), qx);
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, s->qv, 0, cells * sizeof(cl_float), qy);
    /* The maps see the new speeds from now on. */
    if (st == GR_OK)
      st = gr_rain_runoff_maps_update(s, s->time, 0.0);
    free(q);
    return st;
  }
  gr_status st = GR_OK;
  s->args_set = 0; /* a field allocated now is bound at the next step */
  switch (f) {
  case GR_FIELD_ELEVATION: {
    st = gr_rain_runoff_set_elevation(s, host);
    double worst = 0.0;
    const int nx = s->nxl, ny = s->nyl;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const float *z = host + (size_t)j * nx + i;
        double sx = 0.0, sy = 0.0;
        if (i > 0)
          sx = fabs((double)z[0] - z[-1]);
        if (i < nx - 1)
          sx = fmax(sx, fabs((double)z[1] - z[0]));
        if (j > 0)
          sy = fabs((double)z[0] - z[-nx]);
        if (j < ny - 1)
          sy = fmax(sy, fabs((double)z[nx] - z[0]));
        double rate = sx / (s->grid.dx * s->grid.dx) + sy / (s->grid.dy * s->grid.dy);
        worst = rate > worst ? rate : worst;
      }
    if (st == GR_OK) {
      s->slope_rate = GR_GRAVITY * worst;
      gr_rain_runoff_edge_beds(s, host);
    }
    break;
  }
  case GR_FIELD_PERMEABILITY:
    st = gr_rain_runoff_upload(s, &s->perm, host);
    if (st == GR_OK)
      s->has_perm = 1;
    break;
  case GR_FIELD_RAIN_RATE: {
    gr_fixed sum = gr_rain_runoff_own_sum(s, host);
    st = gr_rain_runoff_upload(s, &s->rain, host);
    if (st == GR_OK) {
      s->has_rain = 1;
      s->rain_field_sum = sum;
      s->rain_field_max = 0.0;
      for (size_t c = 0; c < cells; ++c)
        if (!s->has_nodata || !s->mask[c])
          s->rain_field_max = host[c] > s->rain_field_max ? host[c] : s->rain_field_max;
    }
    break;
  }
  case GR_FIELD_WATER_DEPTH: {
    /* The new water replaces what is there now: the ledger counts the
     * difference as initial water, so the balance still closes. No-data
     * cells hold none. */
    float *dry = NULL;
    if (s->has_nodata) {
      dry = malloc(cells * sizeof(float));
      if (!dry)
        return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
      for (size_t c = 0; c < cells; ++c)
        dry[c] = s->mask[c] ? 0.0f : host[c];
      host = dry;
    }
    gr_fixed now[GR_RAIN_RUNOFF_SUMS], sum = gr_rain_runoff_own_sum(s, host);
    st = gr_rain_runoff_reduce_fixed(s, now, NULL);
    if (st == GR_OK)
      st = gr_rain_runoff_upload(s, &s->h0, host);
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, s->h, 0, cells * sizeof(cl_float), host);
    if (st == GR_OK)
      st = gr_rain_runoff_fill(s, s->h_c, 0.0f, cells * sizeof(cl_float));
    if (st == GR_OK)
      st = gr_rain_runoff_clear_flow(s);
    /* No discharge: the initial velocity, if any, was of other water. */
    gr_buffer_release(&s->qu0);
    gr_buffer_release(&s->qv0);
    if (st == GR_OK) { /* exact: the device's sum of the old water is in the same units */
      s->initial_sum = sum;
      s->initial.coarse += sum.coarse - now[0].coarse;
      s->initial.fine += sum.fine - now[0].fine;
    }
    /* The maps count the new water from the time it is set. */
    if (st == GR_OK)
      st = gr_rain_runoff_maps_update(s, s->time, 0.0);
    free(dry);
    break;
  }
  default:
    break; /* refused by gr_rain_runoff_field_check */
  }
  return st;
}

gr_status gr_rain_runoff_set_field(gr_rain_runoff *s, gr_field f, const float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_field needs a simulation and the field's values.");
  if (!host)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_field needs a simulation and the field's values."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(
      s, gr_rain_runoff_inputs_changed(s, gr_rain_runoff_set_field_impl(s, f, host)));
}

/* ------------------------------------------------------------- inflows */

#define GR_RAIN_RUNOFF_MAX_DISCHARGE 1.0e6
#define GR_RAIN_RUNOFF_MAX_ROWS 1000000

static const char *const gr_rain_runoff_side_names[4] = {"west", "east", "south", "north"};

/* (Re)allocates the source field the steps read, and fills it for the
 * sources now when no hydrograph rewrites it before every step. */
/* Keeps a copy of a validated table of n rows (times t, values v) in
 * *keep_t, *keep_v, freeing the one before; n = 0 keeps none. */
static gr_status gr_rain_runoff_table_keep(gr_rain_runoff *s, const double *t, const double *v,
                                           int n, double **keep_t, double **keep_v) {
  double *nt = NULL, *nv = NULL;
  if (n > 0) {
    nt = malloc((size_t)n * sizeof(double));
    nv = malloc((size_t)n * sizeof(double));
    if (!nt || !nv) {
      free(nt);
      free(nv);
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    }
    memcpy(nt, t, (size_t)n * sizeof(double));
    memcpy(nv, v, (size_t)n * sizeof(double));
  }
  free(*keep_t);
  free(*keep_v);
  *keep_t = nt;
  *keep_v = nv;
  return GR_OK;
}

static gr_status gr_rain_runoff_sources_changed(gr_rain_runoff *s) {
  size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
  gr_status st = GR_OK;
  if (gr_rain_runoff_has_sources(s) && !s->src)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bytes, NULL, &s->src);
  if (st == GR_OK && gr_rain_runoff_has_sources(s) && !gr_rain_runoff_has_edge_inflow(s))
    st = gr_rain_runoff_sources_update(s, s->time, s->time);
  s->args_set = 0; /* use_src and the buffer are bound at the next step */
  return st;
}

static gr_status gr_rain_runoff_set_point_inflows_impl(gr_rain_runoff *s, const int *ij,
                                                       const double *q, int n) {
  if (n < 0 || n > GR_RAIN_RUNOFF_MAX_ROWS || (n > 0 && (!ij || !q)))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The point inflows must be 0 to %d cells with a discharge each (got %d%s).",
                        GR_RAIN_RUNOFF_MAX_ROWS, n, n > 0 && (!ij || !q) ? " and no values" : "");
  int gnx = s->grid.global_nx > 0 ? s->grid.global_nx : s->grid.nx;
  int gny = s->grid.global_ny > 0 ? s->grid.global_ny : s->grid.ny;
  for (int k = 0; k < n; ++k) {
    if (!(q[k] >= 0.0 && q[k] <= GR_RAIN_RUNOFF_MAX_DISCHARGE))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "Point inflow %d has the discharge %g m^3/s: discharges must lie between "
                          "0 and %g m^3/s; give it a discharge in that range.",
                          k, q[k], GR_RAIN_RUNOFF_MAX_DISCHARGE);
    if (ij[2 * k] < 0 || ij[2 * k] >= gnx || ij[2 * k + 1] < 0 || ij[2 * k + 1] >= gny)
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "Point inflow %d is the cell (%d, %d), outside the domain of %d x %d "
                          "cells: give cells from (0, 0) to (%d, %d).",
                          k, ij[2 * k], ij[2 * k + 1], gnx, gny, gnx - 1, gny - 1);
  }
  size_t cells = gr_rain_runoff_cells(s);
  gr_status st = GR_OK;
  if (n == 0) {
    s->has_pts = 0;
    s->pts_max = 0.0;
  } else {
    /* Summed in double in the order given, one float per cell: the same
     * floats in every piece that holds the cell (owned or in its ring). */
    double *sum = calloc(cells, sizeof(double));
    float *f = malloc(cells * sizeof(float));
    if (!sum || !f) {
      free(sum);
      free(f);
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    }
    const int x0 = s->grid.i0 - s->ring[0], y0 = s->grid.j0 - s->ring[2];
    for (int k = 0; k < n; ++k) {
      int i = ij[2 * k] - x0, j = ij[2 * k + 1] - y0;
      if (i >= 0 && i < s->nxl && j >= 0 && j < s->nyl)
        sum[(size_t)j * (size_t)s->nxl + (size_t)i] += q[k];
    }
    double area = s->grid.dx * s->grid.dy, top = 0.0;
    for (size_t c = 0; c < cells; ++c) {
      f[c] = (float)(sum[c] / area);
      top = f[c] > top ? f[c] : top;
    }
    st = gr_rain_runoff_upload(s, &s->pts, f);
    free(sum);
    free(f);
    if (st != GR_OK)
      return st;
    s->has_pts = 1;
    s->pts_max = top;
  }
  return gr_rain_runoff_sources_changed(s);
}

gr_status gr_rain_runoff_set_point_inflows(gr_rain_runoff *s, const int *ij,
                                           const double *discharge, int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_point_inflows needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(
      s,
      gr_rain_runoff_inputs_changed(s, gr_rain_runoff_set_point_inflows_impl(s, ij, discharge, n)));
}

static gr_status gr_rain_runoff_set_edge_inflow_impl(gr_rain_runoff *s, int side, const double *t,
                                                     const double *q, int n) {
  if (side < 0 || side > 3)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The edge of an inflow hydrograph must be 0 west, 1 east, 2 south or 3 "
                        "north (got %d).",
                        side);
  const char *name = gr_rain_runoff_side_names[side];
  if (n < 0 || n > GR_RAIN_RUNOFF_MAX_ROWS || (n > 0 && (!t || !q)))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The %s edge's inflow hydrograph must have 0 to %d rows of time and "
                        "discharge (got %d%s).",
                        name, GR_RAIN_RUNOFF_MAX_ROWS, n,
                        n > 0 && (!t || !q) ? " and no values" : "");
  for (int k = 0; k < n; ++k) {
    if (!(t[k] >= -1e12 && t[k] <= 1e12))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The %s edge's inflow hydrograph has the time %g s in row %d: times must "
                          "be finite numbers of seconds; correct that row.",
                          name, t[k], k);
    if (k > 0 && !(t[k] > t[k - 1]))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The %s edge's inflow hydrograph's times must increase from row to row, "
                          "but row %d has %g s after %g s; sort the rows and drop repeated times.",
                          name, k, t[k], t[k - 1]);
    if (!(q[k] >= 0.0 && q[k] <= GR_RAIN_RUNOFF_MAX_DISCHARGE))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The %s edge's inflow hydrograph has the discharge %g m^3/s in row %d: "
                          "discharges must lie between 0 and %g m^3/s; correct that row.",
                          name, q[k], k, GR_RAIN_RUNOFF_MAX_DISCHARGE);
  }
  gr_status st = gr_rain_runoff_table_keep(s, t, q, n, &s->edge_t[side], &s->edge_q[side]);
  if (st != GR_OK)
    return st;
  s->edge_n[side] = n;
  return gr_rain_runoff_sources_changed(s);
}

gr_status gr_rain_runoff_set_edge_inflow(gr_rain_runoff *s, int side, const double *times,
                                         const double *discharge, int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_edge_inflow needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(
      s, gr_rain_runoff_inputs_changed(
             s, gr_rain_runoff_set_edge_inflow_impl(s, side, times, discharge, n)));
}

/* ------------------------------------------------ rain and roughness maps */

static gr_status gr_rain_runoff_set_manning_map_impl(gr_rain_runoff *s, const double *n) {
  size_t cells = gr_rain_runoff_cells(s);
  if (!n) {
    s->has_n2 = 0;
    s->args_set = 0;
    return GR_OK;
  }
  const gr_param_bound *row = &gr_rain_runoff_bounds[GR_RAIN_RUNOFF_P_MANNING_N];
  int li = s->params.flow_model == GR_FLOW_LOCAL_INERTIAL;
  double lo = li ? GR_RAIN_RUNOFF_LI_MIN_N : row->min, low = HUGE_VAL;
  for (size_t c = 0; c < cells; ++c) {
    if (!(n[c] >= lo && n[c] <= row->max))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The Manning map has the value %g s/m^(1/3) at cell (%zu, %zu): values "
                          "must lie between %g and %g%s, like ManningN; correct the map.",
                          n[c], c % (size_t)s->nxl, c / (size_t)s->nxl, lo, row->max,
                          li ? " for FlowModel 1 (local inertial)" : "");
    low = n[c] < low ? n[c] : low;
  }
  float *n2 = malloc(cells * sizeof(float));
  if (!n2)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  /* n^2 as the uniform ManningN's: in double, then one float (the same
   * float for the same n, so a map of ManningN everywhere is that run). */
  for (size_t c = 0; c < cells; ++c)
    n2[c] = (float)(n[c] * n[c]);
  gr_status st = gr_rain_runoff_upload(s, &s->n2map, n2);
  free(n2);
  if (st != GR_OK)
    return st;
  s->has_n2 = 1;
  s->n_min = low;
  s->args_set = 0;
  return GR_OK;
}

gr_status gr_rain_runoff_set_manning_map(gr_rain_runoff *s, const double *n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_manning_map needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(
      s, gr_rain_runoff_inputs_changed(s, gr_rain_runoff_set_manning_map_impl(s, n)));
}

static gr_status gr_rain_runoff_set_hyetograph_impl(gr_rain_runoff *s, const double *t,
                                                    const double *r, int n) {
  const gr_param_bound *row = &gr_rain_runoff_bounds[GR_RAIN_RUNOFF_P_RAIN_RATE];
  const double hi = gr_rain_runoff_core_max(GR_RAIN_RUNOFF_P_RAIN_RATE);
  if (n < 0 || n > GR_RAIN_RUNOFF_MAX_ROWS || (n > 0 && (!t || !r)))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The hyetograph must have 0 to %d rows of time and rain rate (got %d%s).",
                        GR_RAIN_RUNOFF_MAX_ROWS, n, n > 0 && (!t || !r) ? " and no values" : "");
  for (int k = 0; k < n; ++k) {
    if (!(t[k] >= -1e12 && t[k] <= 1e12))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The hyetograph has the time %g s in row %d: times must be finite "
                          "numbers of seconds; correct that row.",
                          t[k], k);
    if (k > 0 && !(t[k] > t[k - 1]))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The hyetograph's times must increase from row to row, but row %d has "
                          "%g s after %g s; sort the rows and drop repeated times.",
                          k, t[k], t[k - 1]);
    if (!(r[k] >= 0.0 && r[k] <= hi))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The hyetograph has the rain rate %g %s in row %d: rates must lie "
                          "between %g and %g %s, like RainRate; correct that row.",
                          r[k] / row->to_core, row->unit, k, row->min, row->max, row->unit);
  }
  gr_status st = gr_rain_runoff_table_keep(s, t, r, n, &s->hy_t, &s->hy_r);
  if (st != GR_OK)
    return st;
  s->hy_n = n;
  s->args_set = 0; /* RainRate again at the next bind when it is removed */
  return GR_OK;
}

gr_status gr_rain_runoff_set_hyetograph(gr_rain_runoff *s, const double *times, const double *rates,
                                        int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_hyetograph needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_set_hyetograph_impl(s, times, rates, n));
}

/* ------------------------------------------------------ pieces and halos */

void gr_rain_runoff_set_allreduce(gr_rain_runoff *s, gr_allreduce_fn fn, void *user) {
  if (!s)
    return;
  s->allreduce = fn;
  s->allreduce_user = fn ? user : NULL;
}

static gr_status gr_rain_runoff_allreduce(gr_rain_runoff *s, double *values, int n,
                                          gr_reduce_op op) {
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

void gr_rain_runoff_set_sw_fused(gr_rain_runoff *s, int on) {
  if (s)
    s->sw_fused = on != 0;
}

gr_status gr_rain_runoff_set_sw_tile(gr_rain_runoff *s, int tx, int ty) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_sw_tile needs a simulation.");
  if (tx < 0 || ty < 0 || (tx == 0) != (ty == 0))
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The shallow-water tile of %d x %d cells is not a tile: give two positive "
                        "sizes, or 0 x 0 for the device's default.",
                        tx, ty));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_sw_shape(s, (size_t)tx, (size_t)ty, 0));
}

void gr_rain_runoff_set_fused(gr_rain_runoff *s, int on) {
  if (!s)
    return;
  s->fused = on != 0 && s->li_local[0] > 0; /* the device allows its work-group */
  s->args_set = 0;
}

/* After a step of a piece with a ring: the caller's exchange refreshes it. */
static gr_status gr_rain_runoff_exchange(gr_rain_runoff *s, long long step) {
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

/* --------------------------------------------------------------- stepping */

static double gr_rain_runoff_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* advance's watch over the queue for its progress callback: it waits on the
 * queue after every `batch` steps, sized so a batch takes about
 * GR_RAIN_RUNOFF_BATCH_S, and calls the callback when enough wall time has
 * passed. Waiting changes when the host blocks, never what is computed. */
typedef struct gr_rain_runoff_watch {
  double last_call, last_wait;
  int batch, since;
  int global; /* a piece with an allreduce: the stop flag is reduced after every step */
} gr_rain_runoff_watch;

/* A piece's watch: its own progress callback (if any) only raises a flag,
 * and the flags of every piece are reduced after every step, so all pieces
 * stop after the same step whichever asked; every piece makes this call at
 * every step, callback or not, so the allreduce calls match. One 8-byte
 * reduction per step costs little next to the step's halo exchange. */
static gr_status gr_rain_runoff_watch_global(gr_rain_runoff *s, gr_rain_runoff_watch *w,
                                             double time, int *stop) {
  double flag = 0.0;
  gr_status st = GR_OK;
  if (s->progress) {
    /* The exchange has usually waited already; this makes the time the
     * device's for a piece without a ring too. */
    st = gr_finish(s->ctx);
    double now = gr_rain_runoff_now();
    if (st == GR_OK && now - w->last_call >= GR_RAIN_RUNOFF_PROGRESS_EVERY) {
      w->last_call = now;
      if (s->progress(s->progress_user, time) != 0)
        flag = 1.0;
    }
  }
  /* Reached even when the wait failed: a piece that skipped the collective
   * would leave the others waiting in it. */
  gr_status sr = gr_rain_runoff_allreduce(s, &flag, 1, GR_REDUCE_MAX);
  if (st == GR_OK)
    st = sr;
  if (st == GR_OK && flag != 0.0)
    *stop = 1;
  return st;
}

/* Called after each enqueued step; `time` is the simulated time it reaches.
 * *stop becomes 1 when the callback asks to stop. */
static gr_status gr_rain_runoff_watch_step(gr_rain_runoff *s, gr_rain_runoff_watch *w, double time,
                                           int *stop) {
  if (w->global)
    return gr_rain_runoff_watch_global(s, w, time, stop);
  if (++w->since < w->batch)
    return GR_OK;
  gr_status st = gr_finish(s->ctx);
  if (st != GR_OK)
    return st;
  double now = gr_rain_runoff_now(), span = now - w->last_wait;
  if (span < 0.5 * GR_RAIN_RUNOFF_BATCH_S && w->batch < (1 << 20))
    w->batch *= 2;
  else if (span > GR_RAIN_RUNOFF_BATCH_S && w->batch > 1)
    w->batch /= 2;
  w->since = 0;
  w->last_wait = now;
  if (now - w->last_call >= GR_RAIN_RUNOFF_PROGRESS_EVERY) {
    w->last_call = now;
    if (s->progress(s->progress_user, time) != 0)
      *stop = 1;
  }
  return GR_OK;
}

/* ---------------------------------------------------------------- sources */

static int gr_rain_runoff_has_edge_inflow(const gr_rain_runoff *s) {
  return s->edge_n[0] || s->edge_n[1] || s->edge_n[2] || s->edge_n[3];
}

static int gr_rain_runoff_has_sources(const gr_rain_runoff *s) {
  return s->has_pts || gr_rain_runoff_has_edge_inflow(s);
}

/* The integral over [a, b] of the piecewise-linear function through (t[k],
 * v[k]), k < n, held at v[0] before t[0] and at v[n-1] after t[n-1]. */
static double gr_rain_runoff_table_integral(const double *t, const double *v, int n, double a,
                                            double b) {
  double sum = 0.0;
  if (a < t[0])
    sum += v[0] * ((b < t[0] ? b : t[0]) - a);
  if (b > t[n - 1])
    sum += v[n - 1] * (b - (a > t[n - 1] ? a : t[n - 1]));
  for (int k = 0; k + 1 < n; ++k) {
    double lo = a > t[k] ? a : t[k], hi = b < t[k + 1] ? b : t[k + 1];
    if (hi <= lo)
      continue;
    double slope = (v[k + 1] - v[k]) / (t[k + 1] - t[k]);
    double vlo = v[k] + slope * (lo - t[k]), vhi = v[k] + slope * (hi - t[k]);
    sum += 0.5 * (vlo + vhi) * (hi - lo);
  }
  return sum;
}

/* The cells along each domain edge of the whole domain (a piece's edge is
 * part of it): the hydrograph's discharge is spread over all of them. */
static double gr_rain_runoff_edge_cells(const gr_rain_runoff *s, int side) {
  int gnx = s->grid.global_nx > 0 ? s->grid.global_nx : s->grid.nx;
  int gny = s->grid.global_ny > 0 ? s->grid.global_ny : s->grid.ny;
  return side < 2 ? (double)gny : (double)gnx;
}

/* Writes the sources of the step [t0, t1] into s->src: the point inflows
 * and each edge's mean discharge over the step (the exact integral of its
 * table, over t1 - t0), spread over the edge's cells, as m/s of depth. */
static gr_status gr_rain_runoff_sources_update(gr_rain_runoff *s, double t0, double t1) {
  cl_float edge[4];
  for (int e = 0; e < 4; ++e) {
    double rate = 0.0;
    if (s->edge_n[e] && !s->ring[e] && t1 > t0)
      rate = gr_rain_runoff_table_integral(s->edge_t[e], s->edge_q[e], s->edge_n[e], t0, t1) /
             (t1 - t0) / (gr_rain_runoff_edge_cells(s, e) * s->grid.dx * s->grid.dy);
    edge[e] = (cl_float)rate;
  }
  cl_int nx = s->nxl, ny = s->nyl, use_pts = s->has_pts;
  cl_mem pts = s->has_pts ? s->pts : s->dummy;
  const size_t m = sizeof(cl_mem);
  const gr_rain_runoff_arg args[] = {
      {"pts", m, &pts},
      {"use_pts", sizeof(use_pts), &use_pts},
      {"src", m, &s->src},
      {"nx", sizeof(nx), &nx},
      {"ny", sizeof(ny), &ny},
      {"edge_w", sizeof(cl_float), &edge[0]},
      {"edge_e", sizeof(cl_float), &edge[1]},
      {"edge_s", sizeof(cl_float), &edge[2]},
      {"edge_n", sizeof(cl_float), &edge[3]},
  };
  gr_status st = GR_RAIN_RUNOFF_ARGS(s, s->source, args);
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->source, 0, 0, (size_t)s->nxl, (size_t)s->nyl, NULL);
  return st;
}

/* The largest source rate the sources may reach (m/s of depth): the point
 * inflows' and every edge's largest discharge over its cells. */
static double gr_rain_runoff_source_max(const gr_rain_runoff *s) {
  double edge = 0.0;
  for (int e = 0; e < 4; ++e) {
    if (!s->edge_n[e] || s->ring[e])
      continue;
    double q = 0.0;
    for (int k = 0; k < s->edge_n[e]; ++k)
      q = s->edge_q[e][k] > q ? s->edge_q[e][k] : q;
    q /= gr_rain_runoff_edge_cells(s, e) * s->grid.dx * s->grid.dy;
    edge += q; /* a corner cell gets two edges' */
  }
  return (s->has_pts ? s->pts_max : 0.0) + edge;
}

/* The ledger's rain for `done` steps of the float dtf: the owned cells'
 * rates (the rain field's, RainRate's, or with a hyetograph the sum of the
 * rates the steps took) in fixed point, times the steps in units of
 * 2^-GR_RAIN_RUNOFF_STEP_BITS s, as exact integer products. dtf >= 2^-9 s
 * is exact in those units (smaller steps round to them); every piece books
 * the same step integers, so the pieces' rain adds up to the whole grid's,
 * bit for bit. Bounds: rates up to RainRate's 3600 mm/h (coarse words up to
 * 2^14 a cell), steps up to MaxTimeStep's 3600 s (2^44 units) and simulated
 * time below 2^31 s keep rain_book[0] below 2^109 and rain_book[1] below 2^125 on a
 * 65536^2 grid. */
static void gr_rain_runoff_rain_book(gr_rain_runoff *s, const gr_fixed *hyetograph, cl_float dtf,
                                     int done) {
  long long step = llrint(ldexp((double)dtf, GR_RAIN_RUNOFF_STEP_BITS));
  /* The owned cells of the domain: no rain falls on no-data cells. */
  long long active =
      s->has_nodata ? (long long)s->active_own : (long long)gr_rain_runoff_own_cells(s);
  gr_fixed rate;
  long long times;
  if (s->has_rain) {
    rate = s->rain_field_sum;
    times = 1;
  } else if (s->hy_n) { /* each step its own rate, as the device took it */
    rate = *hyetograph;
    times = active;
    done = 1;
  } else {
    rate = gr_fixed_from_float((cl_float)s->params.rain_rate);
    times = active;
  }
  gr_wide coarse = gr_wide_scale(gr_wide_mul(rate.coarse, times), step * done);
  gr_wide fine = gr_wide_scale(gr_wide_mul(rate.fine, times), step * done);
  gr_wide_add(&s->rain_book[0], coarse);
  gr_wide_add(&s->rain_book[1], fine);
}

/* The hyetograph's rain for the step [t0, t1]: the table's exact mean over
 * it, as the float the kernels take in place of RainRate (a rain_rate field
 * still wins); *sum adds that float (in fixed point) for the ledger. */
static gr_status gr_rain_runoff_hyetograph_step(gr_rain_runoff *s, double t0, double t1,
                                                gr_fixed *sum) {
  cl_float rf =
      (cl_float)(gr_rain_runoff_table_integral(s->hy_t, s->hy_r, s->hy_n, t0, t1) / (t1 - t0));
  int sw = s->params.flow_model == GR_FLOW_SHALLOW_WATER;
  cl_kernel li[5] = {s->flux_edges, s->li_step, s->flux, s->limit, s->update};
  cl_kernel swk[5] = {s->sw_prep, s->sw_faces[0], s->sw_update[0], s->sw_faces[1], s->sw_update[1]};
  gr_status st = GR_OK;
  for (int k = 0; st == GR_OK && k < (sw ? 5 : (s->fused ? 2 : 5)); ++k)
    st = sw ? gr_kernel_arg(s->ctx, swk[k], "rain_uniform", sizeof(rf), &rf)
            : gr_rain_runoff_arg_at(s, li[k], s->ix_rain[k], sizeof(rf), &rf);
  for (int k = 0; st == GR_OK && sw && k < 4; ++k)
    st = gr_kernel_arg(s->ctx, k < 2 ? s->sw_stage[k] : s->sw_inner[k - 2], "rain_uniform",
                       sizeof(rf), &rf);
  if (st == GR_OK)
    gr_fixed_add(sum, gr_fixed_from_float(rf));
  return st;
}

/* The largest uniform rain rate (m/s): the hyetograph's, or RainRate. */
static double gr_rain_runoff_rain_max(const gr_rain_runoff *s) {
  double top = s->hy_n ? 0.0 : s->params.rain_rate;
  for (int k = 0; k < s->hy_n; ++k)
    top = s->hy_r[k] > top ? s->hy_r[k] : top;
  return top;
}

/* The smallest Manning n the friction takes: the map's, or ManningN. */
static double gr_rain_runoff_min_n(const gr_rain_runoff *s) {
  return s->has_n2 ? s->n_min : s->params.manning_n;
}

/* Binds every step-kernel argument but the alternating face arrays, when
 * something they hold has changed since the last step. */
static gr_status gr_rain_runoff_bind(gr_rain_runoff *s, cl_float dt) {
  /* The fused step sets the depth and limiter every step (they alternate);
   * the other kernels keep those they were bound to. */
  int fused = s->fused && s->params.flow_model == GR_FLOW_LOCAL_INERTIAL;
  if (s->args_set && s->args_dt == dt && (fused || (s->args_h == s->h && s->args_k == s->k)))
    return GR_OK;
  s->args_h = s->h;
  s->args_k = s->k;
  const gr_rain_runoff_params *p = &s->params;
  const gr_grid *gd = &s->grid;
  cl_int nx = s->nxl, ny = s->nyl;
  cl_float inv_dx = (cl_float)(1.0 / gd->dx), inv_dy = (cl_float)(1.0 / gd->dy);
  cl_float g = (cl_float)GR_GRAVITY;
  cl_float n2 = (cl_float)(p->manning_n * p->manning_n);
  cl_int use_rain = s->has_rain, use_perm = s->has_perm;
  cl_float rain_uniform = (cl_float)p->rain_rate, perm_uniform = (cl_float)p->permeability;
  /* The domain's edges' kinds and levels; a side with a neighbour is open
   * (its ring is refreshed from the neighbour after every step). */
  cl_int bnd[4];
  cl_float lvl[4];
  for (int e = 0; e < 4; ++e) {
    int kind; /* any bit pattern the enum may hold: validated as a whole number 0-3 */
    memcpy(&kind, &p->boundary[e], sizeof(kind));
    bnd[e] = s->ring[e] ? GR_RAIN_RUNOFF_B_OPEN : kind;
    lvl[e] = (cl_float)p->boundary_level[e];
  }
  cl_mem rain = s->has_rain ? s->rain : s->dummy, perm = s->has_perm ? s->perm : s->dummy;
  cl_int use_src = gr_rain_runoff_has_sources(s);
  cl_mem src = use_src ? s->src : s->dummy;
  cl_int use_n2 = s->has_n2;
  cl_mem n2map = use_n2 ? s->n2map : s->dummy;
  cl_int use_nodata = s->has_nodata;
  cl_mem nodata = use_nodata ? s->nodata : s->dummy;
  cl_float theta = (cl_float)GR_RAIN_RUNOFF_THETA;
  cl_float wd = (cl_float)p->wetting_depth, df = (cl_float)p->debris_factor, t0 = 0.0f;
  const size_t m = sizeof(cl_mem);
  /* The flood maps, which the last kernel of a step folds its state into
   * (map_time is set before every launch). */
  const gr_rain_runoff_arg maps[] = {
      {"max_depth", m, &s->map[0]},       {"max_speed", m, &s->map[1]},
      {"arrival", m, &s->map[2]},         {"wet_time", m, &s->map[3]},
      {"max_hazard", m, &s->map[4]},      {"wet_time_comp", m, &s->map[5]},
      {"wetting_depth", sizeof(wd), &wd}, {"debris_factor", sizeof(df), &df},
      {"map_time", sizeof(t0), &t0},
  };
  /* Arguments the three step kernels share (each takes those it has). */
  const gr_rain_runoff_arg common[] = {
      {"h", m, &s->h},
      {"rain", m, &rain},
      {"perm", m, &perm},
      {"src", m, &src},
      {"use_src", sizeof(use_src), &use_src},
      {"nodata", m, &nodata},
      {"use_nodata", sizeof(use_nodata), &use_nodata},
      {"limit", m, &s->k},
      {"nx", sizeof(nx), &nx},
      {"ny", sizeof(ny), &ny},
      {"dt", sizeof(dt), &dt},
      {"inv_dx", sizeof(inv_dx), &inv_dx},
      {"inv_dy", sizeof(inv_dy), &inv_dy},
      {"use_rain", sizeof(use_rain), &use_rain},
      {"rain_uniform", sizeof(rain_uniform), &rain_uniform},
      {"use_perm", sizeof(use_perm), &use_perm},
      {"perm_uniform", sizeof(perm_uniform), &perm_uniform},
  };
  const gr_rain_runoff_arg flux[] = {
      {"b", m, &s->b},
      {"g", sizeof(g), &g},
      {"n2", sizeof(n2), &n2},
      {"n2map", m, &n2map},
      {"use_n2", sizeof(use_n2), &use_n2},
  };
  const gr_rain_runoff_arg edges[] = {
      {"bnd_w", sizeof(cl_int), &bnd[0]},   {"bnd_e", sizeof(cl_int), &bnd[1]},
      {"bnd_s", sizeof(cl_int), &bnd[2]},   {"bnd_n", sizeof(cl_int), &bnd[3]},
      {"lvl_w", sizeof(cl_float), &lvl[0]}, {"lvl_e", sizeof(cl_float), &lvl[1]},
      {"lvl_s", sizeof(cl_float), &lvl[2]}, {"lvl_n", sizeof(cl_float), &lvl[3]},
  };
  const gr_rain_runoff_arg update[] = {
      {"h_comp", m, &s->h_c},
      {"infiltrated", m, &s->inf},
      {"infiltrated_comp", m, &s->inf_c},
      {"outflow", m, &s->out},
      {"outflow_comp", m, &s->out_c},
      {"inflow", m, &s->in},
      {"inflow_comp", m, &s->in_c},
  };
  if (p->flow_model == GR_FLOW_SHALLOW_WATER) {
    /* The face arrays, or the one-float dummy until a step takes the
     * separate launches (gr_rain_runoff_face_arrays). */
    cl_mem fx = s->fx ? s->fx : s->dummy, fy = s->fy ? s->fy : s->dummy;
    const gr_rain_runoff_arg sw[] = {
        {"h", m, &s->h},
        {"qu", m, &s->qu},
        {"qv", m, &s->qv},
        {"h1", m, &s->h1},
        {"wh", m, &s->wh},
        {"wu", m, &s->wu},
        {"wv", m, &s->wv},
        {"u1", m, &s->u1},
        {"v1", m, &s->v1},
        {"fx", m, &fx},
        {"fy", m, &fy},
        {"h_comp", m, &s->h_c},
        {"dh1", m, &s->dh1},
        {"qu1", m, &s->qu1},
        {"qv1", m, &s->qv1},
        {"b", m, &s->b},
        {"rain", m, &rain},
        {"perm", m, &perm},
        {"src", m, &src},
        {"use_src", sizeof(use_src), &use_src},
        {"nodata", m, &nodata},
        {"use_nodata", sizeof(use_nodata), &use_nodata},
        {"infiltrated", m, &s->inf},
        {"infiltrated_comp", m, &s->inf_c},
        {"outflow", m, &s->out},
        {"outflow_comp", m, &s->out_c},
        {"nx", sizeof(nx), &nx},
        {"ny", sizeof(ny), &ny},
        {"dt", sizeof(dt), &dt},
        {"inv_dx", sizeof(inv_dx), &inv_dx},
        {"inv_dy", sizeof(inv_dy), &inv_dy},
        {"g", sizeof(g), &g},
        {"n2", sizeof(n2), &n2},
        {"n2map", m, &n2map},
        {"use_n2", sizeof(use_n2), &use_n2},
        {"use_rain", sizeof(use_rain), &use_rain},
        {"rain_uniform", sizeof(rain_uniform), &rain_uniform},
        {"use_perm", sizeof(use_perm), &use_perm},
        {"perm_uniform", sizeof(perm_uniform), &perm_uniform},
        {"inflow", m, &s->in},
        {"inflow_comp", m, &s->in_c},
        {"bnd_w", sizeof(cl_int), &bnd[0]},
        {"bnd_e", sizeof(cl_int), &bnd[1]},
        {"bnd_s", sizeof(cl_int), &bnd[2]},
        {"bnd_n", sizeof(cl_int), &bnd[3]},
        {"lvl_w", sizeof(cl_float), &lvl[0]},
        {"lvl_e", sizeof(cl_float), &lvl[1]},
        {"lvl_s", sizeof(cl_float), &lvl[2]},
        {"lvl_n", sizeof(cl_float), &lvl[3]},
    };
    cl_kernel swk[6] = {s->sw_prep,     s->sw_faces[0],  s->sw_update[0],
                        s->sw_faces[1], s->sw_update[1], s->sw_edges};
    gr_status st = GR_OK;
    for (int k = 0; st == GR_OK && k < 6; ++k)
      st = GR_RAIN_RUNOFF_ARGS(s, swk[k], sw);
    for (int k = 0; st == GR_OK && k < 6; ++k)
      st = GR_RAIN_RUNOFF_ARGS(s, swk[k], maps);
    /* The fused stages take the same arguments, the interior's tiles and
     * their tile's local memory. */
    cl_kernel fused[4] = {s->sw_stage[0], s->sw_stage[1], s->sw_inner[0], s->sw_inner[1]};
    for (int k = 0; st == GR_OK && k < 4; ++k)
      st = GR_RAIN_RUNOFF_ARGS(s, fused[k], sw);
    for (int k = 0; st == GR_OK && k < 4; ++k)
      st = GR_RAIN_RUNOFF_ARGS(s, fused[k], maps);
    for (int k = 0; st == GR_OK && k < 4; ++k)
      st = gr_kernel_arg(s->ctx, fused[k], "tiles", sizeof(s->sw_tiles), s->sw_tiles);
    for (int k = 0; st == GR_OK && k < 4; ++k)
      st = gr_kernel_arg(s->ctx, fused[k], "tile", s->sw_tile_bytes, NULL);
    s->args_set = st == GR_OK;
    s->args_dt = dt;
    return st;
  }
  cl_kernel kernels[] = {s->flux, s->flux_edges, s->limit, s->update, s->li_step};
  gr_status st = GR_OK;
  for (int i = 0; st == GR_OK && i < 5; ++i)
    st = GR_RAIN_RUNOFF_ARGS(s, kernels[i], common);
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->flux, flux);
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->flux_edges, flux);
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->li_step, flux);
  if (st == GR_OK)
    st = gr_kernel_arg(s->ctx, s->flux, "theta", sizeof(theta), &theta);
  if (st == GR_OK)
    st = gr_kernel_arg(s->ctx, s->li_step, "theta", sizeof(theta), &theta);
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->flux_edges, edges);
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->update, update);
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->update, maps);
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->li_step, update);
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->li_step, maps);
  /* The edges rain_runoff_flux_edges writes, which the fused step reads. */
  cl_int fixed = 0;
  for (int e = 0; e < 4; ++e)
    fixed |= bnd[e] != GR_RAIN_RUNOFF_B_OPEN ? 1 << e : 0;
  if (st == GR_OK)
    st = gr_kernel_arg(s->ctx, s->li_step, "fixed", sizeof(fixed), &fixed);
  if (st == GR_OK && s->li_local[0] > 0)
    st = gr_kernel_arg(s->ctx, s->li_step, "lmem",
                       3 * s->li_local[0] * s->li_local[1] * sizeof(cl_float), NULL);
  s->args_set = st == GR_OK;
  s->args_dt = dt;
  return st;
}

/* The separate shallow-water launches' face arrays (six planes of x-faces
 * and of y-faces, gr_sw_line_face), made the first time a step takes that
 * path: the fused stages, the default on GPUs, keep their faces in local
 * memory, and the arrays would take 805 MB at 4096^2 (12.9 GB at 16384^2)
 * for nothing. Until then the kernels get the one-float dummy for them. */
static gr_status gr_rain_runoff_face_arrays(gr_rain_runoff *s) {
  if (s->fx)
    return GR_OK;
  size_t nx = (size_t)s->nxl, ny = (size_t)s->nyl;
  gr_status st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, (nx + 1) * ny * 6 * sizeof(cl_float),
                                  NULL, &s->fx);
  if (st == GR_OK)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, nx * (ny + 1) * 6 * sizeof(cl_float), NULL,
                          &s->fy);
  if (st != GR_OK) {
    gr_buffer_release(&s->fx);
    gr_buffer_release(&s->fy);
  }
  s->args_set = 0;
  return st;
}

/* Enqueues up to nsteps steps of dt; *done gets the steps enqueued. With a
 * watch (advance with a progress callback) it may stop early at a step
 * boundary: *stop becomes 1. */
static gr_status gr_rain_runoff_enqueue(gr_rain_runoff *s, double dt, int nsteps,
                                        gr_rain_runoff_watch *w, int *done_out, int *stop) {
  cl_float dtf = (cl_float)dt;
  const size_t m = sizeof(cl_mem);
  gr_status st = gr_rain_runoff_specialise(s);
  if (st == GR_OK && s->params.flow_model == GR_FLOW_SHALLOW_WATER && !s->sw_fused)
    st = gr_rain_runoff_face_arrays(s);
  if (st == GR_OK)
    st = gr_rain_runoff_bind(s, dtf);
  int done = 0, exchange = s->halo_exchange && gr_rain_runoff_has_ring(s);
  int sw = s->params.flow_model == GR_FLOW_SHALLOW_WATER;
  /* The end time of each step, summed as s->time is below (the flood maps'
   * arrival times). */
  double t_end = s->time;
  int per_step = gr_rain_runoff_has_edge_inflow(s);
  /* Any of the domain's edges not open: rain_runoff_flux_edges rewrites it. */
  int edges = 0;
  for (int e = 0; e < 4; ++e)
    edges |= !s->ring[e] && s->params.boundary[e] != GR_BOUNDARY_OPEN;
  gr_fixed rate_sum = {0, 0}; /* the hyetograph's rates the steps took (m/s, floats) */
  while (sw && st == GR_OK && done < nsteps && !*stop) {
    if (per_step)
      st = gr_rain_runoff_sources_update(s, t_end, t_end + dt);
    if (st == GR_OK && s->hy_n)
      st = gr_rain_runoff_hyetograph_step(s, t_end, t_end + dt, &rate_sum);
    /* Stage 2's update folds the new state into the flood maps at the
     * step's end. */
    cl_float map_time = (cl_float)(t_end += dt);
    /* Fused: each of Heun's stages in two launches, the interior's tiles
     * and the rim's, their faces in local memory (rain_runoff_sw_inner1, 2
     * and rain_runoff_sw_stage1, 2). */
    if (st == GR_OK && s->sw_fused)
      st = gr_kernel_arg(s->ctx, s->sw_stage[1], "map_time", sizeof(map_time), &map_time);
    if (st == GR_OK && s->sw_fused)
      st = gr_kernel_arg(s->ctx, s->sw_inner[1], "map_time", sizeof(map_time), &map_time);
    for (int stage = 0; st == GR_OK && s->sw_fused && stage < 2; ++stage) {
      const cl_int *t = s->sw_tiles;
      if (t[1] > t[0] && t[3] > t[2])
        st = gr_enqueue_2d(s->ctx, s->sw_inner[stage], 0, 0, (size_t)(t[1] - t[0]) * s->sw_local[0],
                           (size_t)(t[3] - t[2]) * s->sw_local[1], s->sw_local);
      if (st == GR_OK && s->sw_rim)
        st = gr_enqueue_2d(s->ctx, s->sw_stage[stage], 0, 0, s->sw_rim * s->sw_local[0],
                           s->sw_local[1], s->sw_local);
    }
    /* Or stage 1's points, then Heun's two stages: every face once, then
     * every cell from its four faces. */
    if (st == GR_OK && !s->sw_fused)
      st = gr_enqueue_2d(s->ctx, s->sw_prep, 0, 0, (size_t)s->nxl, (size_t)s->nyl, NULL);
    if (st == GR_OK && !s->sw_fused)
      st = gr_kernel_arg(s->ctx, s->sw_update[1], "map_time", sizeof(map_time), &map_time);
    for (int stage = 0; st == GR_OK && !s->sw_fused && stage < 2; ++stage) {
      st = gr_enqueue_2d(s->ctx, s->sw_faces[stage], 0, 0, (size_t)s->nxl + 1, (size_t)s->nyl + 1,
                         NULL);
      if (st == GR_OK)
        st = gr_enqueue_2d(s->ctx, s->sw_update[stage], 0, 0, (size_t)s->nxl, (size_t)s->nyl, NULL);
      /* The rim's cells book the stage's edge flows (after their update). */
      if (st == GR_OK)
        st = gr_enqueue_1d(s->ctx, s->sw_edges, 2 * ((size_t)s->nxl + (size_t)s->nyl));
    }
    if (st == GR_OK)
      ++done;
    if (st == GR_OK && exchange)
      st = gr_rain_runoff_exchange(s, s->steps + done);
    if (st == GR_OK && w)
      st = gr_rain_runoff_watch_step(s, w, s->time + dt * (double)done, stop);
  }
  int fused = !sw && s->fused;
  if (st == GR_OK && fused && !s->h_alt) {
    size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bytes, NULL, &s->h_alt);
    if (st == GR_OK)
      st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bytes, NULL, &s->k_alt);
  }
  /* The fused step's work-groups: tiles of li_local - 3 cells each way. */
  size_t tx = fused ? s->li_local[0] - 3 : 1, ty = fused ? s->li_local[1] - 3 : 1;
  size_t gx = ((size_t)s->nxl + tx - 1) / tx * s->li_local[0];
  size_t gy = ((size_t)s->nyl + ty - 1) / ty * s->li_local[1];
  while (!sw && st == GR_OK && done < nsteps && !*stop) {
    int old = s->cur, now = 1 - s->cur;
    if (per_step)
      st = gr_rain_runoff_sources_update(s, t_end, t_end + dt);
    if (st == GR_OK && s->hy_n)
      st = gr_rain_runoff_hyetograph_step(s, t_end, t_end + dt, &rate_sum);
    /* The update folds the new state into the flood maps at the step's end. */
    cl_float map_time = (cl_float)(t_end += dt);
    /* The edges that are not open, from the step's start: the fused step
     * reads them, the three launches' flux kernel writes them open first. */
    const cl_mem *eargs[6] = {&s->h, &s->k, &s->qx[old], &s->qy[old], &s->qx[now], &s->qy[now]};
    for (int a = 0; st == GR_OK && edges && a < (fused ? 6 : 4); ++a)
      st = gr_rain_runoff_arg_at(s, s->flux_edges, s->ix_edges[fused ? a : a + 2], m,
                                 eargs[fused ? a : a + 2]);
    if (fused) {
      const cl_mem *sargs[8] = {&s->h,       &s->h_alt,   &s->k,       &s->k_alt,
                                &s->qx[old], &s->qy[old], &s->qx[now], &s->qy[now]};
      for (int a = 0; st == GR_OK && a < 8; ++a)
        st = gr_rain_runoff_arg_at(s, s->li_step, s->ix_step[a], m, sargs[a]);
      if (st == GR_OK)
        st = gr_rain_runoff_arg_at(s, s->li_step, s->ix_step[8], sizeof(map_time), &map_time);
      if (st == GR_OK && edges)
        st = gr_enqueue_1d(s->ctx, s->flux_edges, 2 * ((size_t)s->nxl + (size_t)s->nyl));
      if (st == GR_OK)
        st = gr_enqueue_2d(s->ctx, s->li_step, 0, 0, gx, gy, s->li_local);
      if (st == GR_OK) {
        /* The new faces, depth and limiters are current. */
        cl_mem t = s->h;
        s->h = s->h_alt;
        s->h_alt = t;
        t = s->k;
        s->k = s->k_alt;
        s->k_alt = t;
        s->cur = now;
      }
    } else {
      for (int a = 0; st == GR_OK && a < 4; ++a)
        st = gr_rain_runoff_arg_at(s, s->flux, s->ix_flux[a], m, eargs[a + 2]);
      for (int a = 0; st == GR_OK && a < 2; ++a)
        st = gr_rain_runoff_arg_at(s, s->limit, s->ix_limit[a], m, eargs[a + 4]);
      for (int a = 0; st == GR_OK && a < 2; ++a)
        st = gr_rain_runoff_arg_at(s, s->update, s->ix_update[a], m, eargs[a + 4]);
      if (st == GR_OK)
        st = gr_rain_runoff_arg_at(s, s->update, s->ix_update[2], sizeof(map_time), &map_time);
      if (st == GR_OK)
        st = gr_enqueue_2d(s->ctx, s->flux, 0, 0, (size_t)s->nxl + 1, (size_t)s->nyl + 1, NULL);
      /* The edges that are not open, after the flux kernel wrote them so. */
      if (st == GR_OK && edges)
        st = gr_enqueue_1d(s->ctx, s->flux_edges, 2 * ((size_t)s->nxl + (size_t)s->nyl));
      if (st == GR_OK)
        s->cur = now; /* the flux kernel is enqueued: the new faces are current */
      if (st == GR_OK)
        st = gr_enqueue_2d(s->ctx, s->limit, 0, 0, (size_t)s->nxl, (size_t)s->nyl, NULL);
      if (st == GR_OK)
        st = gr_enqueue_2d(s->ctx, s->update, 0, 0, (size_t)s->nxl, (size_t)s->nyl, NULL);
    }
    if (st == GR_OK)
      ++done;
    if (st == GR_OK && exchange)
      st = gr_rain_runoff_exchange(s, s->steps + done);
    if (st == GR_OK && w)
      st = gr_rain_runoff_watch_step(s, w, s->time + dt * (double)done, stop);
  }
  /* The ledger counts the steps whose launches were all enqueued, with the
   * rain the device added: the float dt it was given. */
  gr_rain_runoff_rain_book(s, &rate_sum, dtf, done);
  /* Step by step, not dt * done: a piece that steps one step per call (to
   * exchange its halo) then keeps the same time, to the bit, as the whole
   * grid stepping many per call. */
  for (int k = 0; k < done; ++k)
    s->time += dt;
  s->steps += done;
  *done_out = done;
  return st;
}

static gr_status gr_rain_runoff_step_impl(gr_rain_runoff *s, double dt, int nsteps) {
  double max_dt = gr_rain_runoff_core_max(GR_RAIN_RUNOFF_P_MAX_DT);
  if (!(dt >= GR_RAIN_RUNOFF_MIN_DT && dt <= max_dt))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The time step dt must lie between %g and %g s (got %g s).",
                        GR_RAIN_RUNOFF_MIN_DT, max_dt, dt);
  if (nsteps < 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The number of steps must be 0 or more (got %d).", nsteps);
  if (nsteps == 0)
    return GR_OK;
  if (nsteps > 1 && gr_rain_runoff_has_ring(s) && !s->halo_exchange)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "A rain runoff piece with neighbours and no halo exchange takes one step "
                        "per call (got %d): exchange its halo between steps, or give it an "
                        "exchange with gr_rain_runoff_set_halo_exchange.",
                        nsteps);
  gr_status st = GR_OK;
  for (int left = nsteps; st == GR_OK && left > 0;) {
    int k = left < GR_RAIN_RUNOFF_IN_FLIGHT ? left : GR_RAIN_RUNOFF_IN_FLIGHT, done = 0, stop = 0;
    if (left < nsteps) /* after the first batch: wait for the one before */
      st = gr_finish(s->ctx);
    if (st == GR_OK)
      st = gr_rain_runoff_enqueue(s, dt, k, NULL, &done, &stop);
    left -= k;
  }
  return st;
}

gr_status gr_rain_runoff_step(gr_rain_runoff *s, double dt, int nsteps) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_rain_runoff_step needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_step_impl(s, dt, nsteps));
}

/* The longest step dt whose gravity wave, in the water that rain and
 * inflows arriving at `rate` (m/s of depth) make on dry (or still) ground
 * within the step, r dt deep, crosses no more than `reach` metres:
 *   sqrt(g r dt) dt <= reach,   dt = (reach / sqrt(g r))^(2/3).
 * Both models' stable steps take it, each with its own reach: a step
 * computed from the water there is before the step's rain lands is
 * unbounded on dry ground (MaxTimeStep long), and the rain of that step,
 * which the step's own faces already see, makes water whose waves it
 * outruns. HUGE_VAL with no water arriving. */
static double gr_rain_runoff_rain_dt(double rate, double reach) {
  return rate > 0.0 ? pow(reach / sqrt(GR_GRAVITY * rate), 2.0 / 3.0) : HUGE_VAL;
}

/* Shallow water: the Courant condition of the explicit finite volumes on the
 * fastest waves of any cell, |u| + sqrt(g h) along x and |v| + sqrt(g h)
 * along y:  dt max(ax / dx + ay / dy) <= cfl / 2,
 * the half keeping the hydrostatic reconstruction's depths positive with the
 * second-order reconstruction (Audusse et al. 2004). */
static gr_status gr_rain_runoff_sw_stable_dt(gr_rain_runoff *s, double *dt) {
  cl_int n = (cl_int)gr_rain_runoff_cells(s);
  cl_int row = s->nxl, own_x0 = s->ring[0], own_x1 = s->nxl - s->ring[1];
  cl_int own_y0 = s->ring[2], own_y1 = s->nyl - s->ring[3];
  cl_int masked = gr_rain_runoff_has_ring(s);
  cl_float g = (cl_float)GR_GRAVITY;
  cl_float inv_dx = (cl_float)(1.0 / s->grid.dx), inv_dy = (cl_float)(1.0 / s->grid.dy);
  const gr_rain_runoff_arg args[] = {
      {"inv_dx", sizeof(inv_dx), &inv_dx},
      {"inv_dy", sizeof(inv_dy), &inv_dy},
      {"h", sizeof(cl_mem), &s->h},
      {"qu", sizeof(cl_mem), &s->qu},
      {"qv", sizeof(cl_mem), &s->qv},
      {"n", sizeof(n), &n},
      {"row", sizeof(row), &row},
      {"own_x0", sizeof(own_x0), &own_x0},
      {"own_x1", sizeof(own_x1), &own_x1},
      {"own_y0", sizeof(own_y0), &own_y0},
      {"own_y1", sizeof(own_y1), &own_y1},
      {"masked", sizeof(masked), &masked},
      {"g", sizeof(g), &g},
  };
  /* The deepest cell, the fastest rate, the heaviest rain (m/s), the
   * steepest bed (slope_rate). */
  double maxes[4] = {0.0, 0.0,
                     (s->has_rain ? s->rain_field_max : gr_rain_runoff_rain_max(s)) +
                         gr_rain_runoff_source_max(s),
                     s->slope_rate};
  gr_status st = GR_RAIN_RUNOFF_ARGS(s, s->sw_speed, args);
  if (st == GR_OK)
    st = gr_reduction_run(s->ctx, &s->speed, s->sw_speed, NULL, maxes);
  /* A level edge's water enters at up to twice its wave speed (a dry
   * front's, HLL's). */
  double edge = gr_rain_runoff_edge_depth(s);
  if (edge > 0.0) {
    double c2 = 2.0 * sqrt(GR_GRAVITY * edge) * (1.0 / s->grid.dx + 1.0 / s->grid.dy);
    maxes[0] = edge > maxes[0] ? edge : maxes[0];
    maxes[1] = c2 > maxes[1] ? c2 : maxes[1];
  }
  if (st == GR_OK && s->allreduce)
    st = gr_rain_runoff_allreduce(s, maxes, 4, GR_REDUCE_MAX);
  if (st != GR_OK)
    return st;
  double rate = maxes[1];
  double stable = rate > 0.0 ? 0.5 * s->params.cfl / rate : s->params.max_dt;
  /* Rain on dry (or still) ground: the step must not outrun the waves of
   * the water it adds, r dt deep: dt sqrt(g r dt) (1/dx + 1/dy) <= cfl / 2.
   * Without it a dry grid's first step is MaxTimeStep long. */
  double r = maxes[2];
  if (r > 0.0) {
    double wet =
        gr_rain_runoff_rain_dt(r, 0.5 * s->params.cfl / (1.0 / s->grid.dx + 1.0 / s->grid.dy));
    stable = wet < stable ? wet : stable;
  }
  /* Frictionless water on a slope gains g S dt of speed within the step,
   * before the second stage moves it: a film on a steep bed that starts
   * still (which the speeds above cannot see) would cross cells in that
   * stage. So, with ManningN 0, also
   *   dt^2 g max(|db/dx| / dx + |db/dy| / dy) <= cfl / 8,
   * a quarter of the budget above (both together: 1.25 cfl / 2 at worst,
   * below the 1/2 that keeps depths positive), each bound a function of
   * one maximum, so that pieces taking the smallest of their steps take
   * the whole grid's. With friction, taken in each stage, a film gains no
   * more than its Manning speed, and no bound is needed. (sw_thin_films
   * shows both: frictionless rain on slopes up to 3, with MaxTimeStep 1 s,
   * emptied cells beyond their water without it.) */
  double accel = maxes[3];
  if (accel > 0.0 && gr_rain_runoff_min_n(s) == 0.0 && (maxes[0] > 0.0 || r > 0.0)) {
    double steep = sqrt(0.125 * s->params.cfl / accel);
    stable = steep < stable ? steep : stable;
  }
  *dt = stable < s->params.max_dt ? stable : s->params.max_dt;
  return GR_OK;
}

/* The local inertial model's kinematic rate (1/s): rain_runoff_li_speed
 * reduced over the owned cells. */
static gr_status gr_rain_runoff_film_rate(gr_rain_runoff *s, double *rate) {
  cl_int n = (cl_int)gr_rain_runoff_cells(s);
  cl_int row = s->nxl, rows = s->nyl, own_x0 = s->ring[0], own_x1 = s->nxl - s->ring[1];
  cl_int own_y0 = s->ring[2], own_y1 = s->nyl - s->ring[3];
  cl_int use_nodata = s->has_nodata, use_n2 = s->has_n2;
  cl_float n2 = (cl_float)(s->params.manning_n * s->params.manning_n);
  cl_float inv_dx = (cl_float)(1.0 / s->grid.dx), inv_dy = (cl_float)(1.0 / s->grid.dy);
  cl_float g = (cl_float)GR_GRAVITY, cfl = (cl_float)s->params.cfl;
  const gr_rain_runoff_arg args[] = {
      {"h", sizeof(cl_mem), &s->h},
      {"b", sizeof(cl_mem), &s->b},
      {"nodata", sizeof(cl_mem), s->has_nodata ? &s->nodata : &s->dummy},
      {"use_nodata", sizeof(use_nodata), &use_nodata},
      {"n2map", sizeof(cl_mem), s->has_n2 ? &s->n2map : &s->dummy},
      {"use_n2", sizeof(use_n2), &use_n2},
      {"n2", sizeof(n2), &n2},
      {"n", sizeof(n), &n},
      {"row", sizeof(row), &row},
      {"rows", sizeof(rows), &rows},
      {"own_x0", sizeof(own_x0), &own_x0},
      {"own_x1", sizeof(own_x1), &own_x1},
      {"own_y0", sizeof(own_y0), &own_y0},
      {"own_y1", sizeof(own_y1), &own_y1},
      {"inv_dx", sizeof(inv_dx), &inv_dx},
      {"inv_dy", sizeof(inv_dy), &inv_dy},
      {"g", sizeof(g), &g},
      {"cfl", sizeof(cfl), &cfl},
  };
  gr_status st = GR_RAIN_RUNOFF_ARGS(s, s->li_speed, args);
  if (st == GR_OK)
    st = gr_reduction_run(s->ctx, &s->film, s->li_speed, NULL, rate);
  return st;
}

static gr_status gr_rain_runoff_stable_dt_impl(gr_rain_runoff *s, double *dt) {
  if (s->params.flow_model == GR_FLOW_SHALLOW_WATER)
    return gr_rain_runoff_sw_stable_dt(s, dt);
  /* li_speed reads the no-data cells and the Manning map. */
  gr_status st = gr_rain_runoff_specialise(s);
  if (st != GR_OK)
    return st;
  /* The deepest cell and the fastest that water arrives (m/s): the
   * heaviest rain and the strongest inflow. */
  double maxes[3] = {0.0, 0.0, 0.0};
  st = gr_rain_runoff_deepest(s, &maxes[0]);
  if (st == GR_OK)
    st = gr_rain_runoff_film_rate(s, &maxes[2]);
  maxes[1] =
      (s->has_rain ? s->rain_field_max : gr_rain_runoff_rain_max(s)) + gr_rain_runoff_source_max(s);
  /* A level edge's water counts as the grid's. */
  double edge = gr_rain_runoff_edge_depth(s);
  maxes[0] = edge > maxes[0] ? edge : maxes[0];
  /* The whole domain's: every piece takes the same step. */
  if (st == GR_OK && s->allreduce)
    st = gr_rain_runoff_allreduce(s, maxes, 3, GR_REDUCE_MAX);
  if (st != GR_OK)
    return st;
  /* The scheme's stability limit in 2-D for gravity waves, c = sqrt(g h)
   * at the deepest cell: a checkerboard mode of the staggered grid, damped
   * by the smoothing to 2 theta - 1 per step, grows unless
   *   c dt sqrt(1/dx^2 + 1/dy^2) <= sqrt(theta).
   * (Bates et al. 2010's cfl dx / sqrt(g h) is the 1-D limit; in 2-D it
   * allows steps sqrt(2 / theta) times too long.) cfl is the fraction of the
   * limit taken. The flow speed |u| is left out on purpose: the local
   * inertial equations have no advection term, and q / h of a cell that a
   * step has just drained would shrink the step for nothing.
   *   The rain and inflow of the step add to that: the step's faces see
   * each cell's depth after them, h + r dt. On dry ground, where h_max
   * alone allowed any step up to MaxTimeStep, the step also keeps the
   * waves of r dt within the limit (gr_rain_runoff_rain_dt). Each bound is
   * a function of one maximum, as shallow water's are, so that pieces taking
   * the smallest of their steps take the whole grid's; where both bind, h +
   * r dt is at most twice the depth either allows, a wave sqrt(2) faster:
   * within the limit while cfl <= 1 / sqrt(2) (the default is 0.7).
   *   Friction adds a bound of its own on thin films on steep slopes.
   * It is implicit (Bates et al. 2010):
   *   q' (1 + kf |q'|) = q~ - g h dt S,   kf = g dt n^2 / h^(7/3),
   * so a long step tends to the Manning discharge h^(5/3) sqrt|S| / n and
   * never beyond it, and q's response to the surface slope, dq'/dS =
   * -g h dt / (1 + 2 kf |q'|), is at most the frictionless g h dt: as a
   * diffusion of the surface its explicit limit lies within the gravity-wave
   * limit above. Its response to the depth is not bounded so. With
   * kf q'^2 = g h dt |S| - q' (for q~ = 0),
   *   dq'/dh = g dt |S| (10/3 - (7/3) q' / (g h dt |S|)) / (1 + 2 kf |q'|),
   * the celerity of the film's kinematic wave: 5/3 of the Manning speed
   * u = h^(2/3) sqrt|S| / n on a long step, at most (10/3) g |S| dt on a
   * short one. That wave moves upwind and explicitly, monotone only while it
   * crosses at most a cell a step, dt dq'/dh / dx <= 1, and u / sqrt(g h)
   * (the Froude number, h^(1/6) sqrt|S| / (n sqrt g): 2.7 for 1 cm on a
   * slope of 0.3 with n 0.03, 8 with n 0.01) is not bounded: a
   * supercritical film takes gravity-limited steps in which it would leave
   * its cell several times over. The limiter then lets each cell empty once
   * a step, the water moves a cell a step, slower than the film, and piles
   * up: with no cap, tilted_plane_uncapped's plane of slope 0.3 with n 0.01
   * stood two to three times too deep. So also dt <= cfl / rate, the rate
   * the fastest face's of rain_runoff_li_speed: min(5/3 u / d, sqrt(cfl
   * (10/3) g |S| / d)) per face, each direction's Courant condition on its
   * own faces (as the faces of the two directions are computed apart). It
   * takes each face's Manning speed from its depth and surface slope, not
   * q / h, which a cell just drained makes large for nothing; a lake at
   * rest has none. */
  double inv = sqrt(1.0 / (s->grid.dx * s->grid.dx) + 1.0 / (s->grid.dy * s->grid.dy));
  double c = sqrt(GR_GRAVITY * maxes[0]);
  double stable =
      c > 0.0 ? s->params.cfl * sqrt(GR_RAIN_RUNOFF_THETA) / (c * inv) : s->params.max_dt;
  double wet = gr_rain_runoff_rain_dt(maxes[1], s->params.cfl * sqrt(GR_RAIN_RUNOFF_THETA) / inv);
  stable = wet < stable ? wet : stable;
  double film = maxes[2] > 0.0 ? s->params.cfl / maxes[2] : HUGE_VAL;
  stable = film < stable ? film : stable;
  *dt = stable < s->params.max_dt ? stable : s->params.max_dt;
  return GR_OK;
}

gr_status gr_rain_runoff_stable_dt(gr_rain_runoff *s, double *dt) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_stable_dt needs a simulation and a place for dt.");
  if (!dt)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_stable_dt needs a simulation and a place for dt."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_stable_dt_impl(s, dt));
}

static gr_status gr_rain_runoff_advance_impl(gr_rain_runoff *s, double duration,
                                             long long *taken_out) {
  if (!(duration >= 0.0 && duration < HUGE_VAL))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The duration to advance must be a finite number of seconds, 0 or more "
                        "(got %g).",
                        duration);
  if (gr_rain_runoff_has_ring(s) && (!s->allreduce || !s->halo_exchange))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "A rain runoff piece with neighbours advances only with a global "
                        "reduction and a halo exchange (it has %s and %s): set them with "
                        "gr_rain_runoff_set_allreduce and gr_rain_runoff_set_halo_exchange, or "
                        "step it with gr_rain_runoff_step, exchanging its halo between steps.",
                        s->allreduce ? "one" : "none", s->halo_exchange ? "one" : "none");
  /* The stable step is read back again after a few steps, not once: rain
   * filling a dry bowl deepens it, and a step that was stable at the start
   * of a long advance is not by its end. The stretch between reads starts
   * at one step (GR_RAIN_RUNOFF_CHUNK_MIN) and doubles (to
   * GR_RAIN_RUNOFF_CHUNK_MAX) while the stable step holds, back to one
   * when it shrinks by more than 5 %; the last stretch is split into equal
   * steps that end exactly at the duration. One step, not four, at the
   * start: on dry ground the first stable step sees still water only rain
   * deep, and the water's own speed and depth shrink it by half and more
   * within a few steps (advance_dry_start: four steps of the first took the
   * shallow-water model past its Courant limit, where cut negative depths
   * made water). All of it depends on the state only, so the same state and
   * duration give the same steps; the progress watch only adds waits. */
  double left = duration, last_dt = 0.0;
  int chunk = GR_RAIN_RUNOFF_CHUNK_MIN, stop = 0;
  gr_rain_runoff_watch watch = {0.0, 0.0, 1, 0, s->allreduce != NULL};
  watch.last_call = watch.last_wait = gr_rain_runoff_now();
  /* The callback's cadence runs on across advances: a caller advancing in
   * parts shorter than GR_RAIN_RUNOFF_PROGRESS_EVERY (a GPU's 1000 s may
   * take 80 ms) still hears from it. */
  if (s->progress_last > 0.0)
    watch.last_call = s->progress_last;
  gr_rain_runoff_watch *w = s->progress || watch.global ? &watch : NULL;
  gr_status st = GR_OK;
  while (st == GR_OK && left > 0.0 && !stop) {
    double dt = 0.0;
    st = gr_rain_runoff_stable_dt_impl(s, &dt);
    if (st != GR_OK)
      break;
    if (last_dt > 0.0)
      chunk = dt >= 0.95 * last_dt
                  ? (chunk * 2 < GR_RAIN_RUNOFF_CHUNK_MAX ? chunk * 2 : GR_RAIN_RUNOFF_CHUNK_MAX)
                  : GR_RAIN_RUNOFF_CHUNK_MIN;
    last_dt = dt;
    double n = ceil(left / dt);
    if (n < 1.0)
      n = 1.0;
    if ((double)*taken_out + n > (double)INT_MAX) {
      st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "Advancing by %g s takes more than %d steps (the stable step is %g s "
                        "with %g s left): advance in parts.",
                        duration, INT_MAX, dt, left);
      break;
    }
    int done = 0;
    if (n <= chunk) {
      st = gr_rain_runoff_enqueue(s, left / n, (int)n, w, &done, &stop);
      *taken_out += done;
      break;
    }
    st = gr_rain_runoff_enqueue(s, dt, chunk, w, &done, &stop);
    *taken_out += done;
    if (st == GR_OK)
      left -= chunk * dt;
  }
  if (s->progress)
    s->progress_last = watch.last_call;
  if (st == GR_OK && stop)
    st = gr_set_error(s->ctx, GR_ERR_ABORTED,
                      "The rain runoff advance was stopped by %s at %g s of simulated time; the "
                      "state is valid there and may be advanced further.",
                      watch.global ? "the progress callback of this or another piece of the domain"
                                   : "its progress callback",
                      s->time);
  return st;
}

gr_status gr_rain_runoff_advance(gr_rain_runoff *s, double duration, int *steps_taken) {
  if (steps_taken)
    *steps_taken = 0;
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_advance needs a simulation.");
  long long taken = 0;
  gr_status st = gr_rain_runoff_advance_impl(s, duration, &taken);
  if (steps_taken)
    *steps_taken = (int)taken;
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, st);
}

void gr_rain_runoff_set_progress(gr_rain_runoff *s, gr_progress_fn fn, void *user) {
  if (!s)
    return;
  s->progress = fn;
  s->progress_user = fn ? user : NULL;
  s->progress_last = 0.0;
}

/* ---------------------------------------------------------------- reading */

/* Runs the derive kernel (what: 0 surface, 1 velocity, 2 discharge, 3
 * infiltrated) into the scratch buffer. */
static gr_status gr_rain_runoff_derive_run(gr_rain_runoff *s, cl_int what) {
  size_t cells = gr_rain_runoff_cells(s);
  gr_status st = GR_OK;
  if (!s->scratch)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, 3 * cells * sizeof(cl_float), NULL,
                          &s->scratch);
  cl_int nx = s->nxl, ny = s->nyl, sw = s->params.flow_model == GR_FLOW_SHALLOW_WATER;
  const size_t m = sizeof(cl_mem);
  const gr_rain_runoff_arg args[] = {
      {"h", m, &s->h},
      {"b", m, &s->b},
      {"qu", m, &s->qu},
      {"qv", m, &s->qv},
      {"sw", sizeof(sw), &sw},
      {"qx", m, &s->qx[s->cur]},
      {"qy", m, &s->qy[s->cur]},
      {"limit", m, &s->k},
      {"infiltrated", m, &s->inf},
      {"infiltrated_comp", m, &s->inf_c},
      {"out", m, &s->scratch},
      {"nx", sizeof(nx), &nx},
      {"ny", sizeof(ny), &ny},
      {"what", sizeof(what), &what},
  };
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->derive, args);
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->derive, 0, 0, (size_t)nx, (size_t)ny, NULL);
  return st;
}

/* derive_run, then the owned cells' `comps` floats each back. */
static gr_status gr_rain_runoff_derive(gr_rain_runoff *s, cl_int what, size_t comps, float *host) {
  gr_status st = gr_rain_runoff_derive_run(s, what);
  if (st == GR_OK)
    st = gr_rain_runoff_read_own(s, s->scratch, comps, host);
  return st;
}

static gr_status gr_rain_runoff_sample_impl(gr_rain_runoff *s, const int *ij, int n,
                                            float *values) {
  if (n < 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The number of points to sample must be 0 or more (got %d).", n);
  for (int k = 0; k < n; ++k)
    if (ij[2 * k] < 0 || ij[2 * k] >= s->grid.nx || ij[2 * k + 1] < 0 ||
        ij[2 * k + 1] >= s->grid.ny)
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "Sample point %d is the cell (%d, %d), outside the %d x %d grid: give "
                          "cells from (0, 0) to (%d, %d).",
                          k, ij[2 * k], ij[2 * k + 1], s->grid.nx, s->grid.ny, s->grid.nx - 1,
                          s->grid.ny - 1);
  if (n == 0)
    return GR_OK;
  gr_status st = gr_rain_runoff_derive_run(s, 2);
  for (int k = 0; st == GR_OK && k < n; ++k) {
    /* The cell in the local array (past the ring). */
    size_t c = ((size_t)ij[2 * k + 1] + (size_t)s->ring[2]) * (size_t)s->nxl + (size_t)ij[2 * k] +
               (size_t)s->ring[0];
    float h = 0.0f, b = 0.0f, q = 0.0f;
    st = gr_buffer_read(s->ctx, s->h, c * sizeof(float), sizeof(float), &h);
    if (st == GR_OK)
      st = gr_buffer_read(s->ctx, s->b, c * sizeof(float), sizeof(float), &b);
    if (st == GR_OK)
      st = gr_buffer_read(s->ctx, s->scratch, c * sizeof(float), sizeof(float), &q);
    /* The surface as WATER_SURFACE gives it: the float sum b + h. */
    int off = s->has_nodata && s->mask[c];
    values[3 * k] = off ? NAN : h;
    values[3 * k + 1] = off ? NAN : b + h;
    values[3 * k + 2] = off ? NAN : q;
  }
  return st;
}

gr_status gr_rain_runoff_sample(gr_rain_runoff *s, const int *ij, int n, float *values) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_sample needs a simulation, the cells and room for values.");
  if (n > 0 && (!ij || !values))
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s,
        gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                     "gr_rain_runoff_sample needs a simulation, the cells and room for values."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_sample_impl(s, ij, n, values));
}

static gr_status gr_rain_runoff_get_field_raw(gr_rain_runoff *s, gr_field f, float *host);

static gr_status gr_rain_runoff_get_field_impl(gr_rain_runoff *s, gr_field f, float *host) {
  gr_status st = gr_rain_runoff_get_field_raw(s, f, host);
  if (st == GR_OK)
    gr_rain_runoff_blank(s, host, f == GR_FIELD_VELOCITY ? 3 : 1);
  return st;
}

static gr_status gr_rain_runoff_get_field_raw(gr_rain_runoff *s, gr_field f, float *host) {
  size_t cells = gr_rain_runoff_own_cells(s);
  switch (f) {
  case GR_FIELD_WATER_DEPTH:
    return gr_rain_runoff_read_own(s, s->h, 1, host);
  case GR_FIELD_ELEVATION:
    return gr_rain_runoff_read_own(s, s->b, 1, host);
  case GR_FIELD_PERMEABILITY:
  case GR_FIELD_RAIN_RATE: {
    int field = f == GR_FIELD_RAIN_RATE ? s->has_rain : s->has_perm;
    if (field)
      return gr_rain_runoff_read_own(s, f == GR_FIELD_RAIN_RATE ? s->rain : s->perm, 1, host);
    float v = (float)(f == GR_FIELD_RAIN_RATE ? s->params.rain_rate : s->params.permeability);
    for (size_t c = 0; c < cells; ++c)
      host[c] = v;
    return GR_OK;
  }
  case GR_FIELD_WATER_SURFACE:
    return gr_rain_runoff_derive(s, 0, 1, host);
  case GR_FIELD_VELOCITY:
    return gr_rain_runoff_derive(s, 1, 3, host);
  case GR_FIELD_DISCHARGE:
    return gr_rain_runoff_derive(s, 2, 1, host);
  case GR_FIELD_INFILTRATED:
    return gr_rain_runoff_derive(s, 3, 1, host);
  default:
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff simulation has no field '%s'; it has elevation, "
                        "water_depth, water_surface, velocity, discharge, infiltrated, "
                        "permeability and rain_rate.",
                        gr_rain_runoff_field_label(f));
  }
}

gr_status gr_rain_runoff_get_field(gr_rain_runoff *s, gr_field f, float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_get_field needs a simulation and room for the field.");
  if (!host)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_get_field needs a simulation and room for the field."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_get_field_impl(s, f, host));
}

gr_status gr_rain_runoff_ledger_get(gr_rain_runoff *s, gr_rain_runoff_ledger *out) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_ledger_get needs a simulation and a ledger to fill.");
  if (!out)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_ledger_get needs a simulation and a ledger to fill."));
  gr_fixed sums[GR_RAIN_RUNOFF_SUMS + 1];
  double hmax = 0.0;
  gr_status st = gr_rain_runoff_reduce_fixed(s, sums, &hmax);
  sums[GR_RAIN_RUNOFF_SUMS] = s->initial;
  /* Over every piece of the domain, as integers: the device's sums, the
   * initial water and the rain, exact in any order, so every split gives
   * the whole grid's bits. */
  long long words[2 * (GR_RAIN_RUNOFF_SUMS + 1)];
  gr_wide rain[2] = {s->rain_book[0], s->rain_book[1]};
  for (int q = 0; q <= GR_RAIN_RUNOFF_SUMS; ++q) {
    words[2 * q] = sums[q].coarse;
    words[2 * q + 1] = sums[q].fine;
  }
  if (st == GR_OK && s->allreduce) {
    double packed[GR_FIXED_PACKED(2 * (GR_RAIN_RUNOFF_SUMS + 1), 2)];
    gr_fixed_pack(words, 2 * (GR_RAIN_RUNOFF_SUMS + 1), rain, 2, packed);
    st = gr_rain_runoff_allreduce(s, packed, (int)(sizeof(packed) / sizeof(packed[0])),
                                  GR_REDUCE_SUM);
    gr_fixed_unpack(packed, words, 2 * (GR_RAIN_RUNOFF_SUMS + 1), rain, 2);
  }
  if (st == GR_OK && s->allreduce)
    st = gr_rain_runoff_allreduce(s, &hmax, 1, GR_REDUCE_MAX);
  if (st != GR_OK)
    return GR_RAIN_RUNOFF_KEEP_ERROR(s, st);
  double area = s->grid.dx * s->grid.dy, depth[GR_RAIN_RUNOFF_SUMS + 1];
  for (int q = 0; q <= GR_RAIN_RUNOFF_SUMS; ++q)
    depth[q] = gr_fixed_value((gr_fixed){words[2 * q], words[2 * q + 1]});
  memset(out, 0, sizeof(*out));
  out->time = s->time;
  out->steps = s->steps;
  out->initial_volume = depth[GR_RAIN_RUNOFF_SUMS] * area;
  out->rain_volume = (gr_wide_value(rain[0], GR_FIXED_COARSE_BITS + GR_RAIN_RUNOFF_STEP_BITS) +
                      gr_wide_value(rain[1], GR_FIXED_FINE_BITS + GR_RAIN_RUNOFF_STEP_BITS)) *
                     area;
  out->stored_volume = depth[0] * area;
  out->infiltrated_volume = depth[1] * area;
  out->outflow_volume = depth[2] * area;
  out->inflow_volume = depth[3] * area;
  out->balance_error = out->initial_volume + out->rain_volume + out->inflow_volume -
                       out->infiltrated_volume - out->outflow_volume - out->stored_volume;
  out->max_depth = hmax;
  return GR_OK;
}

static gr_status gr_rain_runoff_reset_impl(gr_rain_runoff *s) {
  size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
  gr_status st;
  if (s->h0)
    st = gr_cl_check(
        s->ctx,
        clEnqueueCopyBuffer(gr_context_queue(s->ctx), s->h0, s->h, 0, 0, bytes, 0, NULL, NULL),
        "Copying the initial water depth");
  else
    st = gr_rain_runoff_fill(s, s->h, 0.0f, bytes);
  cl_mem zeroed[] = {s->h_c, s->inf, s->inf_c, s->out, s->out_c, s->in, s->in_c};
  for (size_t i = 0; st == GR_OK && i < sizeof(zeroed) / sizeof(zeroed[0]); ++i)
    st = gr_rain_runoff_fill(s, zeroed[i], 0.0f, bytes);
  if (st == GR_OK)
    st = gr_rain_runoff_clear_flow(s);
  for (int a = 0; st == GR_OK && s->qu0 && a < 2; ++a)
    st = gr_cl_check(s->ctx,
                     clEnqueueCopyBuffer(gr_context_queue(s->ctx), a ? s->qv0 : s->qu0,
                                         a ? s->qv : s->qu, 0, 0, bytes, 0, NULL, NULL),
                     "Copying the initial discharges");
  if (st != GR_OK)
    return st;
  s->time = 0.0;
  s->steps = 0;
  memset(s->rain_book, 0, sizeof(s->rain_book));
  s->initial = s->initial_sum;
  return gr_rain_runoff_maps_restart(s);
}

gr_status gr_rain_runoff_reset(gr_rain_runoff *s) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_rain_runoff_reset needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_reset_impl(s));
}

/* ------------------------------------------------------------ flood maps */

static const char *const gr_rain_runoff_map_names[GR_RAIN_RUNOFF_MAP_COUNT] = {
    "max_depth", "max_speed", "arrival_time", "wet_duration", "hazard_rating", "hazard_class"};

const char *gr_rain_runoff_map_name(gr_rain_runoff_map map) {
  int m; /* any bit pattern the enum may hold */
  memcpy(&m, &map, sizeof(m));
  return m >= 0 && m < GR_RAIN_RUNOFF_MAP_COUNT ? gr_rain_runoff_map_names[m] : NULL;
}

int gr_rain_runoff_hazard_class(double rating) {
  /* FD2321/TR2 Table 13.1: the upper ends of "low" and "moderate" belong to
   * the class above; 2.0 itself is still "significant". */
  if (rating > 2.0)
    return 3;
  if (rating >= 1.25)
    return 2;
  if (rating >= 0.75)
    return 1;
  return 0;
}

static gr_status gr_rain_runoff_get_map_impl(gr_rain_runoff *s, gr_rain_runoff_map map,
                                             float *host) {
  size_t cells = gr_rain_runoff_own_cells(s);
  const char *name = gr_rain_runoff_map_name(map);
  if (!name)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff simulation has no flood map %d; its maps are 0 "
                        "max_depth to %d hazard_class (gr_rain_runoff_map).",
                        (int)map, GR_RAIN_RUNOFF_MAP_COUNT - 1);
  int buf = map == GR_RAIN_RUNOFF_HAZARD_CLASS ? 4 : (int)map;
  gr_status st = gr_rain_runoff_read_own(s, s->map[buf], 1, host);
  if (st != GR_OK)
    return st;
  if (map == GR_RAIN_RUNOFF_WET_DURATION) {
    /* The Kahan sum with its compensation taken off. */
    float *comp = malloc(cells * sizeof(float));
    if (!comp)
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    st = gr_rain_runoff_read_own(s, s->map[5], 1, comp);
    for (size_t c = 0; st == GR_OK && c < cells; ++c)
      host[c] -= comp[c];
    free(comp);
  } else if (map == GR_RAIN_RUNOFF_ARRIVAL_TIME) {
    for (size_t c = 0; c < cells; ++c)
      host[c] = host[c] < 0.0f ? NAN : host[c];
  } else if (map == GR_RAIN_RUNOFF_HAZARD_CLASS) {
    for (size_t c = 0; c < cells; ++c)
      host[c] = (float)gr_rain_runoff_hazard_class(host[c]);
  }
  if (st == GR_OK)
    gr_rain_runoff_blank(s, host, 1);
  return st;
}

gr_status gr_rain_runoff_get_map(gr_rain_runoff *s, gr_rain_runoff_map map, float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_get_map needs a simulation and room for the map.");
  if (!host)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_get_map needs a simulation and room for the map."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_get_map_impl(s, map, host));
}

/* ------------------------------------------------------------ checkpoints */

/* The checkpoint's header; the arrays follow it: the per-cell h, h_c, k,
 * inf, inf_c, out, out_c, then the current x- and y-faces (the other face
 * set is rewritten whole by the next step before it is read). */
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

static size_t gr_rain_runoff_state_bytes(const gr_rain_runoff *s) {
  return sizeof(gr_rain_runoff_state_header) +
         sizeof(float) * (GR_RAIN_RUNOFF_STATE_CELL_ARRAYS * gr_rain_runoff_cells(s) +
                          gr_rain_runoff_xfaces(s) + gr_rain_runoff_yfaces(s));
}

gr_status gr_rain_runoff_state_size(const gr_rain_runoff *s, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_state_size needs a simulation and a place for the size.");
  *bytes = gr_rain_runoff_state_bytes(s);
  return GR_OK;
}

/* The state's device arrays in checkpoint order, with their sizes. */
static int gr_rain_runoff_state_arrays(gr_rain_runoff *s, int cur, cl_mem *bufs, size_t *sizes) {
  cl_mem cells[GR_RAIN_RUNOFF_STATE_CELL_ARRAYS] = {
      s->h,      s->h_c,    s->k,      s->inf,    s->inf_c,  s->out,    s->out_c, s->qu,  s->qv,
      s->map[0], s->map[1], s->map[2], s->map[3], s->map[4], s->map[5], s->in,    s->in_c};
  int n = 0;
  for (int i = 0; i < GR_RAIN_RUNOFF_STATE_CELL_ARRAYS; ++i, ++n) {
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
  int n = gr_rain_runoff_state_arrays(s, s->cur, bufs, sizes);
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

static gr_status gr_rain_runoff_state_load_impl(gr_rain_runoff *s, const void *host, size_t bytes) {
  size_t need = gr_rain_runoff_state_bytes(s);
  gr_rain_runoff_state_header hd;
  if (bytes < sizeof(hd))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff state has %zu bytes, fewer than its header: pass the "
                        "bytes gr_rain_runoff_state_save wrote.",
                        bytes);
  memcpy(&hd, host, sizeof(hd));
  if (hd.magic != GR_RAIN_RUNOFF_STATE_MAGIC || hd.version != GR_RAIN_RUNOFF_STATE_VERSION)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The bytes given are not a rain runoff state of this version (magic "
                        "0x%08x, version %u; expected 0x%08x, version %u): pass the bytes "
                        "gr_rain_runoff_state_save wrote.",
                        (unsigned)hd.magic, (unsigned)hd.version, GR_RAIN_RUNOFF_STATE_MAGIC,
                        GR_RAIN_RUNOFF_STATE_VERSION);
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
  /* The rain's sums stay below 2^109 and 2^125 (gr_rain_runoff_rain_book). */
  const int64_t rain_top = INT64_C(1) << 61;
  if (!(hd.time >= 0.0 && hd.time < HUGE_VAL) || hd.steps < 0 || hd.rain_hi[0] < 0 ||
      hd.rain_hi[0] > rain_top || hd.rain_hi[1] < -rain_top || hd.rain_hi[1] > rain_top)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff state's header is damaged (time %g s, %lld steps): "
                        "pass the bytes gr_rain_runoff_state_save wrote.",
                        hd.time, (long long)hd.steps);
  /* Into face set 0, which becomes current. */
  const unsigned char *at = (const unsigned char *)host + sizeof(hd);
  cl_mem bufs[GR_RAIN_RUNOFF_STATE_CELL_ARRAYS + 2];
  size_t sizes[GR_RAIN_RUNOFF_STATE_CELL_ARRAYS + 2];
  int n = gr_rain_runoff_state_arrays(s, 0, bufs, sizes);
  gr_status st = GR_OK;
  for (int i = 0; st == GR_OK && i < n; ++i) {
    st = gr_buffer_write(s->ctx, bufs[i], 0, sizes[i], at);
    at += sizes[i];
  }
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
  return GR_OK;
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
