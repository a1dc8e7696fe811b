/**
 * @file rain_runoff.h
 * @brief Rain on terrain (seed 004's water simulation): rain gain,
 * infiltration through a permeability map, runoff and pooling, as a
 * conservative, deterministic height-field flow on the device.
 *
 * Per step of length dt, in this order (seed 004's per-frame order):
 *  1. rain gain:     h += r dt                       (r: rain rate, m/s)
 *  2. infiltration:  i = min(k dt, h),  h -= i        (k: permeability, m/s)
 *  3. flow: face discharges q (m^2/s) by the local inertial approximation of
 *     the shallow water equations (Bates, Horritt & Fewtrell 2010, the
 *     LISFLOOD-FP scheme), on a staggered grid:
 *        h_f   = max(eta_L, eta_R) - max(b_L, b_R)       (flow depth at the face)
 *        m     = q~ - g h_f dt (eta_R - eta_L)/dx
 *        q'    = m / (1 + g dt n^2 |q'| / h_f^(7/3))
 *     Two refinements of Bates et al.: q~ = theta q + (1 - theta)(q_before
 *     + q_after)/2 smooths the previous discharge with its two neighbours
 *     in line (de Almeida et al. 2012, theta = 0.8, as LISFLOOD-FP does,
 *     falling back like it to q~ = q where the smoothed result would flow
 *     against the surface slope; it damps ripples a few cells long that
 *     deep, smooth water otherwise keeps forever); and the friction takes
 *     the new |q'| instead of the old |q| (solved exactly: q' = 2m / (1 +
 *     sqrt(1 + 4 g dt n^2 |m| / h_f^(7/3)))), which keeps thin films on
 *     steep slopes at their Manning velocity where the old |q| made the
 *     discharge flip between large and nothing. Faces shallower than 1e-6 m
 *     carry nothing. Then every cell's outflow is
 *     scaled so that it never sends more water than it holds (no negative
 *     depth), and
 *        h    += dt (sum of inflows - sum of outflows) / (dx dy).
 *
 * Deviation from the seed, on purpose: the
 * seed's tangential flow and its Algorithm 1 "distribution" create and
 * destroy water (and its released code races); here every face discharge is
 * computed once from both sides' identical inputs, so what leaves one cell
 * arrives in the next, bit for bit the same number, and
 *   stored(t) = stored(0) + rain - infiltrated - outflow
 * holds to float rounding (the depth, the infiltrated and the outflow per
 * cell are Kahan sums, so 10^5 steps and more stay balanced to about 1e-8).
 * The flow is gathered, never scattered, so two runs give bit-identical
 * fields, and a terrain symmetric under a mirror gives a mirrored flow.
 *
 * Boundaries, one per edge of the domain (params.boundary[side], in
 * gr_rain_runoff_side order: west, east, south, north), for either model:
 *  - GR_BOUNDARY_CLOSED: a wall, no flow through the edge;
 *  - GR_BOUNDARY_OPEN: a free outfall into a dry cell at the edge cell's
 *    ground height; water leaves (outflow), nothing enters;
 *  - GR_BOUNDARY_TRANSMISSIVE: zero gradient, the edge's water depth and
 *    velocity continue beyond it over a bed whose slope continues (the edge
 *    cell's bed minus the step to its inner neighbour): uniform flow on a
 *    slope leaves at its normal depth, without reflection; nothing enters
 *    (a zero-gradient inflow would grow with the edge cell's depth and feed
 *    a pit at the edge without end);
 *  - GR_BOUNDARY_LEVEL: the water surface beyond the edge stands at
 *    params.boundary_level[side] (m, as the elevations) over the edge
 *    cell's ground (with the edge's velocity for shallow water): the edge
 *    fills or drains the domain toward that level; a level below the ground
 *    is a free outfall.
 * What leaves through an edge is outflow, what enters is inflow, both in
 * the ledger.
 *
 * No-data cells: a NaN elevation (as real DEMs mark missing ground) puts its
 * cell outside the domain, for either model: nothing rains, enters or is
 * counted there, and get_field, get_map and sample give NaN there. By
 * params.no_data it is a wall (GR_BOUNDARY_CLOSED, the default: its bed far
 * above any ground, so no face to it carries water) or an outfall
 * (GR_BOUNDARY_OPEN: its bed far below, so water pours over the brink as over
 * a cliff, and what reaches the cell leaves the domain at the end of the step
 * as outflow). Infinite elevations are still refused. The stable step counts the levels' depths
 * over the edges' lowest ground as water in the grid.
 *
 * Fields (gr_field): set ELEVATION (required, m), optionally PERMEABILITY
 * (m/s, replaces params.permeability), RAIN_RATE (m/s, replaces
 * params.rain_rate) and WATER_DEPTH (the initial depth, m). Read back
 * WATER_DEPTH, WATER_SURFACE (= elevation + depth), VELOCITY (3 components,
 * m/s, z = 0: the cell-centred mean of the face discharges over the depth;
 * 0 where the cell holds less than 0.1 mm, as a cell that a step has just
 * drained holds a film whose depth says nothing of the flow through it),
 * DISCHARGE (|q| of the cell-centred mean, m^2/s), INFILTRATED (cumulative,
 * m) and the inputs (PERMEABILITY and RAIN_RATE as uniform fields of the
 * parameters when none was set).
 */
/*
 * Shallow-water model (FlowModel 0, the default): the same steps 1 and 2
 * (rain, infiltration, as above), then the 2-D shallow-water equations with
 * advection for the depth h and the discharges (qu, qv) = h (u, v), cell-
 * centred, by conservative finite volumes:
 *  - fluxes: HLL on the hydrostatic reconstruction of Audusse, Bouchut,
 *    Bristeau, Klein & Perthame (2004): at each face the depths are cut to
 *    the higher of the two sides' beds, and the pressure of what was cut
 *    goes to the cell it came from, which keeps a lake at rest exactly at
 *    rest (well-balanced) and no depth negative at wet/dry fronts (at a
 *    Courant number of at most 1/2, which the stable step keeps);
 *  - second order in space: minmod-limited slopes of the depth, the water
 *    surface and the velocities (the surface as bed differences plus depth
 *    differences, so that large elevations lose nothing to rounding), with
 *    the matching centred bed source term. A surface whose rise between two
 *    cells is within the depths' own rounding, 2 FLT_EPSILON (h1 + h2), is
 *    flat: a lake given as depths level - elevation, or as its level
 *    (WATER_SURFACE), has its depths rounded, and stays exactly at rest;
 *  - second order in time: Heun's method (SSP-RK2), two launches a step;
 *  - Manning friction in each stage, implicit in the new discharge:
 *    |q'| (1 + g dt n^2 |q'| / h^(7/3)) = |q| (solved exactly, as the local
 *    inertial model does), so thin films on steep slopes stay at their
 *    Manning velocity whatever the step; ManningN = 0 is frictionless.
 * Velocities are desingularised below 1e-5 m of depth (Kurganov & Petrova
 * 2007). Edges: a wall mirrors the edge cell; an open edge leads into a dry
 * cell at the edge's bed and passes outflow only. The ledger, determinism
 * (gathers: each face is computed once per stage and read by the two cells
 * that share it), the
 * checkpoints and the pieces work as for the local inertial model; the
 * stable step is c / 2 / max((|u| + sqrt(g h)) / dx + (|v| + sqrt(g h))
 * / dy) over the cells, c = min(1, 9 cfl / 7) (0.9 at the default cfl 0.7;
 * 1/2 is the bound that keeps depths positive; one reduction, as the local
 * inertial model's), and
 * a piece's ring is GR_RAIN_RUNOFF_GHOST_SW cells (each stage reads two
 * cells away: one exchange per step covers both stages; the halo strip holds
 * per cell the depth, qu, qv and the depth's Kahan compensation).
 * VELOCITY (3 components, z ignored; after WATER_DEPTH, which clears the
 * flow) sets the initial discharges h (u, v), and WATER_SURFACE (after
 * ELEVATION) sets the depth max(0, surface - elevation) as WATER_DEPTH
 * does (for either model); VELOCITY is an input of this model only.
 */
#ifndef GRAUPEL_RAIN_RUNOFF_H
#define GRAUPEL_RAIN_RUNOFF_H

#include "graupel/memory.h"
#include "graupel/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The flow model (row FlowModel). */
typedef enum gr_flow_model {
  /** The 2-D shallow-water equations with advection (the default): see
   *  "Shallow-water model" below. */
  GR_FLOW_SHALLOW_WATER = 0,
  /** The local inertial scheme described above (Bates et al. 2010), kept
   *  bit for bit: cheaper per step, without advection. */
  GR_FLOW_LOCAL_INERTIAL = 1
} gr_flow_model;

/** The kind of an edge (rows BoundaryWest, BoundaryEast, BoundarySouth,
 *  BoundaryNorth); see "Boundaries" above. */
typedef enum gr_boundary {
  GR_BOUNDARY_OPEN = 0,         /**< free outfall: water may leave through the edge */
  GR_BOUNDARY_CLOSED = 1,       /**< the edge is a wall */
  GR_BOUNDARY_TRANSMISSIVE = 2, /**< zero gradient: depth, velocity and bed slope continue */
  GR_BOUNDARY_LEVEL = 3         /**< the water surface beyond the edge is boundary_level */
} gr_boundary;

/** Sides of the domain (boundaries) and of a piece (the halo calls). */
typedef enum gr_rain_runoff_side {
  GR_RAIN_RUNOFF_WEST = 0,  /**< toward i0 - 1 */
  GR_RAIN_RUNOFF_EAST = 1,  /**< toward i0 + nx */
  GR_RAIN_RUNOFF_SOUTH = 2, /**< toward j0 - 1 */
  GR_RAIN_RUNOFF_NORTH = 3  /**< toward j0 + ny */
} gr_rain_runoff_side;

/** Standard gravity, m/s^2. */
#define GR_GRAVITY 9.80665

/**
 * The parameters, in the core's units. Their ranges and defaults are the
 * rows of gr_rain_runoff_param_bounds (in the user's units, with the factor
 * to these), written nowhere else.
 */
typedef struct gr_rain_runoff_params {
  double rain_rate;    /**< m/s (row RainRate, mm/h) */
  double permeability; /**< infiltration capacity, m/s (row Permeability, mm/h) */
  double manning_n;    /**< Manning roughness, s/m^(1/3) (row ManningN) */
  double cfl;          /**< Courant number of the adaptive step (row CourantNumber) */
  double max_dt;       /**< longest step, s (row MaxTimeStep) */
  /** rows BoundaryWest, BoundaryEast, BoundarySouth, BoundaryNorth, by
   *  gr_rain_runoff_side: 0 open, 1 closed, 2 transmissive, 3 level */
  gr_boundary boundary[4];
  /** rows LevelWest, LevelEast, LevelSouth, LevelNorth, m: the water
   *  surface beyond an edge of kind GR_BOUNDARY_LEVEL (unused otherwise) */
  double boundary_level[4];
  /** row FlowModel: 0 shallow water (the default), 1 local inertial. The
   *  local inertial model needs manning_n >= 0.005; shallow water allows 0
   *  (frictionless). */
  gr_flow_model flow_model;
  /** row WettingDepth, m (default 0.01): a cell deeper than this is wet for
   *  the flood maps' arrival_time and wet_duration. Above 0. */
  double wetting_depth;
  /** row DebrisFactor (default 0): FD2321's DF, added to the hazard rating
   *  where the depth exceeds 0.25 m. 0 to 1. */
  double debris_factor;
  /** row NoDataBoundary (default 1): what no-data cells (NaN elevations) are,
   *  GR_BOUNDARY_CLOSED a wall or GR_BOUNDARY_OPEN an outfall; see "No-data
   *  cells". */
  gr_boundary no_data;
} gr_rain_runoff_params;

/** The table's defaults. */
GR_API void gr_rain_runoff_params_init(gr_rain_runoff_params *p);

/**
 * Checks every parameter against its row of gr_rain_runoff_param_bounds
 * (the user's bounds times to_core); the sentence in msg speaks the user's
 * unit: "RainRate must lie between 0 and 3600 mm/h (got 7200 mm/h)".
 */
GR_API gr_status gr_rain_runoff_params_validate(const gr_rain_runoff_params *p, char *msg,
                                                size_t msg_len);

/**
 * Checks one input field before it is uploaded: every value finite, and
 * for WATER_DEPTH, PERMEABILITY and RAIN_RATE not negative (and within the
 * ranges of the matching parameters). n values; a sentence naming the field,
 * the first bad value (by its row-major index: this call has no grid) and
 * the value goes to msg. Fields that are not inputs and NULL values give
 * GR_ERR_INVALID_ARGUMENT.
 */
GR_API gr_status gr_rain_runoff_field_validate(gr_field f, const float *values, size_t n, char *msg,
                                               size_t msg_len);

/**
 * Water book-keeping, volumes in m^3. Every volume is a sum of integers
 * (graupel/reduce.h's ledger fixed point: each cell's float to 2^-54 m,
 * exact in any order), turned into a double once when the ledger is read,
 * so a domain split into pieces gives the whole grid's ledger bit for bit.
 * The rain is booked on the host (the owned cells' rain-rate floats times
 * each step's dt as the float the device used, an exact integer product);
 * the other volumes are reduced on the device when the ledger is read (each
 * cell's Kahan sum, value and compensation).
 */
typedef struct gr_rain_runoff_ledger {
  double time;               /**< simulated time since the start (or reset), s */
  long long steps;           /**< steps taken */
  double initial_volume;     /**< water present at the start */
  double rain_volume;        /**< rain that fell on the grid */
  double infiltrated_volume; /**< water that went into the ground */
  double outflow_volume;     /**< water that left through the boundary */
  double inflow_volume;      /**< water that came in: level edges, inflows (see "Inflows") */
  double stored_volume;      /**< water on the grid now */
  /** initial + rain + inflow - infiltrated - outflow - stored: float rounding only */
  double balance_error;
  double max_depth; /**< deepest cell now, m */
} gr_rain_runoff_ledger;

typedef struct gr_rain_runoff gr_rain_runoff;

/**
 * What a simulation on grid needs on ctx's device (memory.h), its ring
 * included, with the optional inputs of `inputs` (GR_RAIN_RUNOFF_INPUT_*
 * bits, below; GR_RAIN_RUNOFF_INPUT_ALL for the most): on the device 27
 * floats a cell of state and flood maps, the two sets of face discharges,
 * the derived fields' three floats, the initial water, a float a cell per
 * input (two for inflows), and on a device that runs the shallow-water
 * stages as separate launches (not a GPU; ctx NULL counts them) their six
 * planes of x- and y-faces, about 48 bytes a cell; on the host the no-data
 * mask's byte and the copies made while inputs are set (8 bytes a cell).
 * Initial velocities (2 floats a cell) and the fused local inertial step's
 * two planes (gr_rain_runoff_set_li_fused) are not counted.
 * GR_ERR_INVALID_ARGUMENT without grid, p or out.
 */
GR_API gr_status gr_rain_runoff_memory(const gr_context *ctx, const gr_grid *grid,
                                       const gr_rain_runoff_params *p, int inputs,
                                       gr_memory_need *out);

/**
 * A simulation on one grid: validates grid and parameters, refuses a grid
 * whose state (gr_rain_runoff_memory without optional inputs) does not fit
 * (GR_ERR_TOO_LARGE, before anything is allocated), builds the
 * kernels and allocates the device state (dry, flat ground until
 * ELEVATION is set).
 */
GR_API gr_status gr_rain_runoff_create(gr_context *ctx, const gr_grid *grid,
                                       const gr_rain_runoff_params *p, gr_rain_runoff **out);

/** New parameters from the next step on (validated; the state is kept). */
GR_API gr_status gr_rain_runoff_set_params(gr_rain_runoff *s, const gr_rain_runoff_params *p);

/**
 * Uploads an input field (nx*ny floats; for a piece with neighbours its
 * local array, ring included: see "Pieces of a split domain") after
 * gr_rain_runoff_field_validate
 * (whose sentence then names the bad cell as (i, j)), which set_field
 * tightens with two bounds beyond which float differences overflow:
 * elevations within +-1e6 m and depths up to 1e4 m. A refused field leaves
 * the state as it was. Setting WATER_DEPTH replaces the water now (with no
 * discharge) and makes it the initial state that reset returns to; the
 * ledger's initial_volume grows by the water added, so the balance still
 * closes when it is set after steps.
 */
GR_API gr_status gr_rain_runoff_set_field(gr_rain_runoff *s, gr_field f, const float *host);

/**
 * Enqueues nsteps (>= 0) steps of length dt (s, 1e-30 to 3600); does not
 * wait (a piece with a ring and a halo exchange waits for each exchange;
 * one without an exchange takes nsteps = 1 only). The caller keeps dt
 * stable (see gr_rain_runoff_stable_dt); advance does it for you.
 */
GR_API gr_status gr_rain_runoff_step(gr_rain_runoff *s, double dt, int nsteps);

/**
 * The longest stable step for the current state: the fraction cfl of the
 * scheme's 2-D limit for gravity waves,
 *   cfl * sqrt(theta) / (sqrt(g * max_depth) * sqrt(1/dx^2 + 1/dy^2)),
 * theta = 0.8 (for dx = dy: cfl * 0.632 * dx / sqrt(g h); Bates et al.'s
 * cfl * dx / sqrt(g h) is the 1-D limit and unstable in 2-D above cfl =
 * 0.63), capped at params.max_dt. Reads one reduction back. (The
 * shallow-water model's: see "Shallow-water model" above.)
 */
GR_API gr_status gr_rain_runoff_stable_dt(gr_rain_runoff *s, double *dt);

/**
 * Advances by duration seconds (>= 0; 0 takes no step) in stable steps: the
 * stable step is read back at the start and again after every 4 to 64 steps
 * (4 while it shrinks, doubling while it holds), since rain that fills a dry
 * bowl makes a step that was stable at the start unstable by the end; the
 * last stretch is n = ceil(left / stable_dt) equal steps that end exactly at
 * the duration. The same state and duration always give the same steps.
 * *steps_taken may be NULL. More than INT_MAX steps are refused. A piece
 * with a ring advances with an allreduce and a halo exchange set (see
 * "Pieces of a split domain").
 */
GR_API gr_status gr_rain_runoff_advance(gr_rain_runoff *s, double duration, int *steps_taken);

/** Reads a field back (waits): nx*ny floats, 3*nx*ny for VELOCITY (a piece: its own cells). */
GR_API gr_status gr_rain_runoff_get_field(gr_rain_runoff *s, gr_field f, float *host);

/**
 * Gauges: the state at n owned cells, given as (i, j) pairs in ij (2n ints;
 * for a piece, its own cells from (0, 0)); values gets 3 floats per cell:
 * the depth (m), the water surface (m) and the discharge |q| (m^2/s), the
 * very floats get_field's WATER_DEPTH, WATER_SURFACE and DISCHARGE hold
 * there. Reads a few floats only (waits), so it can follow every output of
 * a large grid. A cell outside the grid is refused with a sentence.
 */
GR_API gr_status gr_rain_runoff_sample(gr_rain_runoff *s, const int *ij, int n, float *values);

/**
 * @name Inflows
 *
 * Water let in as sources (m/s of depth added to cells, like rain, before
 * infiltration and flow), counted as the ledger's inflow_volume: per cell
 * the very float the depth gained, in a Kahan sum, so the ledger closes to
 * float rounding. Both are inputs, not state: a checkpoint does not hold
 * them, and reset keeps them. The stable step (shallow water) counts them
 * as rain.
 * @{
 */

/**
 * Point inflows (a river, a culvert): n sources at the domain's cells
 * ij[2k], ij[2k+1] (the whole domain's indices, also for a piece, which
 * keeps those in its local array, ring included), discharge[k] m^3/s each
 * (0 to 1e6), constant in time. Sources in one cell add up (in double, in
 * the order given). They replace the previous ones; n = 0 removes them. A
 * refused list (a sentence names the source and its value) leaves the
 * sources as they were.
 */
GR_API gr_status gr_rain_runoff_set_point_inflows(gr_rain_runoff *s, const int *ij,
                                                  const double *discharge, int n);

/**
 * An inflow hydrograph along the domain edge `side` (a gr_rain_runoff_side):
 * n rows of times[k] (s, finite, strictly increasing) and discharge[k]
 * (m^3/s, 0 to 1e6), linear in between, the first discharge before the
 * first time and the last after the last time. Each step of [t, t + dt]
 * takes the table's exact mean over the step (its integral over dt) and
 * spreads it evenly over the edge's cells (Q / (n_edge dx dy) per cell, m/s
 * of depth, n_edge the whole domain's cells along the edge), whatever the
 * edge's kind; a piece applies the edges it shares with the domain. n = 0
 * removes it. A refused table (times not increasing, a negative discharge:
 * a sentence names the row) leaves the edge's hydrograph as it was.
 */
GR_API gr_status gr_rain_runoff_set_edge_inflow(gr_rain_runoff *s, int side, const double *times,
                                                const double *discharge, int n);
/** @} */

/**
 * @name Rain over time and roughness by place
 * @{
 */

/**
 * A hyetograph: n rows of times[k] (s, finite, strictly increasing) and
 * rates[k] (m/s, within RainRate's range), linear in between, the first rate
 * before the first time and the last after the last time. Each step of [t,
 * t + dt] rains the table's exact mean over the step, uniformly, in place of
 * params.rain_rate (a RAIN_RATE field still wins); the ledger's rain is the
 * sum of those floats times the area and dt. n = 0 removes it (RainRate
 * again). An input, not state; a refused table leaves the one before.
 */
GR_API gr_status gr_rain_runoff_set_hyetograph(gr_rain_runoff *s, const double *times,
                                               const double *rates, int n);

/**
 * A Manning roughness map: one n per cell of the local array (nx * ny
 * doubles, ring included for a piece), s/m^(1/3), within ManningN's range
 * (0.005 and more for the local inertial model), used in place of
 * params.manning_n: shallow water takes each cell's n, the local inertial
 * model a face's mean of its two cells' n^2. n^2 is computed in double and
 * rounded once, as for the uniform ManningN, so a map of ManningN everywhere
 * gives that run bit for bit. NULL removes it. A refused map (a sentence
 * names the cell and the value) leaves the one before; set_params refuses
 * FlowModel 1 while the map holds an n below 0.005.
 */
GR_API gr_status gr_rain_runoff_set_manning_map(gr_rain_runoff *s, const double *n);
/** @} */

/** The ledger now (waits; reduces the volumes on the device). */
GR_API gr_status gr_rain_runoff_ledger_get(gr_rain_runoff *s, gr_rain_runoff_ledger *out);

/**
 * @name Flood maps
 *
 * What a flood analyst reads off a run: per cell, cumulative since the
 * start (or the last reset), for either flow model, in the checkpointed
 * state (so a run restored from a checkpoint, or requested in any order
 * through the framework, gives the same maps bit for bit). After every
 * step a small kernel folds the step's end state in (one launch per step,
 * per cell, in place: deterministic, no atomics); the initial water counts
 * too (at time 0, or at the time WATER_DEPTH, WATER_SURFACE or VELOCITY is
 * set). With h the depth and v the speed |VELOCITY| (as get_field reads
 * them, so 0 below 0.1 mm of water):
 *  - MAX_DEPTH (m): the largest h at the end of any step;
 *  - MAX_SPEED (m/s): the largest v where h > wetting_depth (the films a
 *    front leaves behind have speeds q / h of hundreds of m/s that say
 *    nothing of the flow);
 *  - ARRIVAL_TIME (s): the end time of the first step after which
 *    h > wetting_depth (0 for water there at the start, the time it is
 *    set for a wetting_depth changed by set_params); NaN if never;
 *  - WET_DURATION (s): the sum of the dt of the steps after which h >
 *    wetting_depth, kept by wet spells: a spell counts from the start of
 *    its first wet step to the start of the step after which the cell is
 *    dry again (or to the time now while it lasts), in twice float
 *    precision from the steps' times, so a cell that stays wet has
 *    WET_DURATION + ARRIVAL_TIME = the time now + its first wet step (a
 *    wetting_depth changed by set_params starts or ends spells at the time
 *    it is set);
 *  - HAZARD_RATING: the largest flood-hazard rating
 *      HR = h (v + 0.5) + DF,  DF = debris_factor where h > 0.25 m, else 0,
 *    of the UK Defra / Environment Agency method (HR Wallingford, "Flood
 *    Risks to People, Phase 2", R&D Technical Report FD2321/TR2, 2006, eq.
 *    3.1 and Table 3.1 for DF: 0 up to 0.25 m for every land use, 0 / 0.5
 *    / 1 above it for pasture / woodland / urban); the default DF 0 is the
 *    plain h (v + 0.5), and 0.5 or 1 give the report's rule for woodland or
 *    urban ground (its pasture value 0.5 applies above 0.75 m only);
 *  - HAZARD_CLASS: the class of HAZARD_RATING by FD2321/TR2 Table 13.1
 *    (and the Defra/EA supplementary note on flood hazard ratings, 2008):
 *    0 low (HR < 0.75, "caution"), 1 moderate (0.75 <= HR < 1.25, "danger
 *    for some"), 2 significant (1.25 <= HR <= 2.0, "danger for most"), 3
 *    extreme (HR > 2.0, "danger for all"); see gr_rain_runoff_hazard_class.
 * Each step's last launch folds the state it leaves into the maps (the
 * velocity as VELOCITY reads it) and writes only the cells whose values
 * change: no launch of its own, no second read of the depth and the
 * discharges; the arrival time and the wet duration are read and written
 * only where a cell turns wet or dry (its wet state before the step is its
 * depth then).
 * @{
 */
typedef enum gr_rain_runoff_map {
  GR_RAIN_RUNOFF_MAX_DEPTH = 0, /**< "max_depth", m */
  GR_RAIN_RUNOFF_MAX_SPEED,     /**< "max_speed", m/s */
  GR_RAIN_RUNOFF_ARRIVAL_TIME,  /**< "arrival_time", s (NaN: never wet) */
  GR_RAIN_RUNOFF_WET_DURATION,  /**< "wet_duration", s */
  GR_RAIN_RUNOFF_HAZARD_RATING, /**< "hazard_rating", FD2321's HR (its maximum over time) */
  GR_RAIN_RUNOFF_HAZARD_CLASS,  /**< "hazard_class", 0 to 3 */
  GR_RAIN_RUNOFF_MAP_COUNT
} gr_rain_runoff_map;

/** The map's array name ("max_depth", ...); NULL for a value that is no map. */
GR_API const char *gr_rain_runoff_map_name(gr_rain_runoff_map map);

/** FD2321's class of a hazard rating: 0 below 0.75, 1 below 1.25, 2 up to 2.0, 3 above (NaN: 0). */
GR_API int gr_rain_runoff_hazard_class(double rating);

/** Reads a map back (waits): nx*ny floats of the owned cells. */
GR_API gr_status gr_rain_runoff_get_map(gr_rain_runoff *s, gr_rain_runoff_map map, float *host);
/** @} */

/**
 * Back to the initial state: the initial water depth (0 unless set),
 * no discharge, nothing infiltrated, ledger zeroed, the flood maps those of
 * the initial water. Inputs are kept.
 */
GR_API gr_status gr_rain_runoff_reset(gr_rain_runoff *s);

/**
 * Progress and abort for gr_rain_runoff_advance (see gr_progress_fn); NULL
 * removes it. After GR_ERR_ABORTED the state is valid at a step boundary
 * inside the advance (the ledger's time says where). On a piece with an
 * allreduce the abort is global: see "Pieces of a split domain".
 */
GR_API void gr_rain_runoff_set_progress(gr_rain_runoff *s, gr_progress_fn fn, void *user);

/**
 * Checkpoints: the whole evolving state (depths, discharges, limiter,
 * cumulative fields, their compensations, time, steps, ledger) as bytes on
 * the host. Loading a saved state into a simulation of the same grid and
 * inputs makes every later step bit-identical to the steps that followed
 * the save. Inputs (elevation, maps) and parameters are not part of it.
 * States saved before WET_DURATION was kept by wet spells (version 6 of
 * the layout, a sum of every wet step's dt) still load, their spells under
 * way starting at the saved time; the bytes of other versions are refused
 * with a sentence.
 */
GR_API gr_status gr_rain_runoff_state_size(const gr_rain_runoff *s, size_t *bytes);
GR_API gr_status gr_rain_runoff_state_save(gr_rain_runoff *s, void *host, size_t bytes);
GR_API gr_status gr_rain_runoff_state_load(gr_rain_runoff *s, const void *host, size_t bytes);

/**
 * @name Pieces of a split domain
 *
 * A simulation may hold one piece of a domain split among processes (the
 * gr_grid piece fields: i0, j0, global_nx, global_ny, ghost). Only the
 * domain's own edges are boundaries. On every side where the piece has a
 * neighbour it keeps a ring of GR_RAIN_RUNOFF_GHOST cells, copies of the
 * neighbour's cells; grid.ghost must then be GR_RAIN_RUNOFF_GHOST, and the
 * piece at least that many cells wide toward the neighbour. At the domain's
 * edges there is no ring.
 *
 * Why 3: a step reads up to 2 cells away in three launches (a face's
 * smoothing reads the limiter 2 cells away and the neighbouring faces'
 * discharges; the limiter reads a cell's faces; the update reads the
 * neighbours' limiters), so every kernel runs over the whole local array,
 * ring included, and with a ring of 3 every owned cell's new depth, limiter
 * and faces are computed from valid values only, the very floats the whole
 * grid computes. So the halo is exchanged once per step, after it:
 *   per ring cell the depth, the limiter, its west x-face and its south
 *   y-face (gr_rain_runoff_halo_get on the sending piece, the owned cells
 *   next to the side; gr_rain_runoff_halo_set on the receiving one);
 *   x sides (west, east) first, then y sides (south, north): an x strip spans
 *   the local array's rows and a y strip its columns, ring included, so
 *   corner cells travel through the x neighbour.
 * The exchange is the caller's (gr_rain_runoff_set_halo_exchange): with
 * one set, the core calls it after every step it takes on a piece with a
 * ring, so gr_rain_runoff_step with nsteps > 1 and gr_rain_runoff_advance
 * work on a piece; without one a piece with a ring takes one step per
 * gr_rain_runoff_step call (the caller exchanges between calls) and does not
 * advance (both refused with a sentence). The stable step and the ledger are
 * global through the allreduce callback (the deepest cell by GR_REDUCE_MAX;
 * the stored, infiltrated, outflow, inflow, rain and initial volumes by
 * GR_REDUCE_SUM of their fixed-point integers, 32 bits to a double:
 * gr_fixed_pack), so every piece takes the same dt and the same steps as the
 * whole grid, which makes every owned cell bit-identical to the whole
 * grid's, and the global ledger is the whole grid's to the bit, however the
 * domain is cut; advance on a piece with a ring needs both callbacks.
 *
 * Advance on pieces is collective: every piece calls gr_rain_runoff_advance
 * with the same duration, and each call makes the same sequence of
 * allreduce and exchange calls (every piece's advance re-reads the global
 * stable step at the same steps). Abort: a piece's progress callback (each
 * piece may have its own, or none) only raises a flag; after every step of
 * an advance with an allreduce the flags are reduced by GR_REDUCE_MAX, so an
 * abort asked for on any one piece stops every piece after the same step,
 * with GR_ERR_ABORTED and the same time and steps in every ledger. An
 * error on one piece (a failed launch, a failed exchange) returns on that
 * piece only: the others wait in their next collective call, which the
 * caller's callbacks must end (MPI_Abort, or a status that is not GR_OK).
 *
 * Input fields (set_field) of a piece cover its local array, ring included:
 * (nx + rings) x (ny + rings) floats, row-major; get_field returns the owned
 * nx x ny cells. A checkpoint of a piece holds its local arrays, ring
 * included, and its i0, j0: loading needs no exchange (the ring is as fresh
 * as when it was saved: save after a step's exchange, as the core's own
 * steps leave it), and is refused into another piece. Every piece must load
 * its checkpoint of the same step (their time and steps say which).
 * @{
 */

/** Ring width of a piece toward each neighbour, cells (local inertial). */
#define GR_RAIN_RUNOFF_GHOST 3
/** Ring width for the shallow-water model: its two stages read 2 cells away
 *  each, so 4 cells make one exchange per step enough. A piece's model
 *  cannot change (the ring would). */
#define GR_RAIN_RUNOFF_GHOST_SW 4

/**
 * The global reduction over the pieces (see gr_allreduce_fn); NULL (the
 * default) for a simulation that is the whole domain or the only piece.
 */
GR_API void gr_rain_runoff_set_allreduce(gr_rain_runoff *s, gr_allreduce_fn fn, void *user);

/**
 * The halo exchange (see gr_halo_exchange_fn and above), called with user
 * after every step the core takes on this piece; NULL (the default) removes
 * it. Never called for a simulation without a ring (a whole grid).
 */
GR_API void gr_rain_runoff_set_halo_exchange(gr_rain_runoff *s, gr_halo_exchange_fn fn, void *user);

/** Bytes of the halo strip on `side` (a gr_rain_runoff_side); 0 where there is no neighbour. */
GR_API gr_status gr_rain_runoff_halo_size(const gr_rain_runoff *s, int side, size_t *bytes);

/** Copies the owned cells next to `side` out (for the neighbour on that side); waits. */
GR_API gr_status gr_rain_runoff_halo_get(gr_rain_runoff *s, int side, void *host, size_t bytes);

/** Copies the neighbour's strip into the ring on `side`; waits. */
GR_API gr_status gr_rain_runoff_halo_set(gr_rain_runoff *s, int side, const void *host,
                                         size_t bytes);
/** @} */

/**
 * How a shallow-water step (FlowModel 0) is launched: each of Heun's two
 * stages in two launches (the interior's tiles, then the rim's), each
 * work-group computing its tile's faces in local memory from the tile and
 * two cells either side of it (non-zero), or in
 * the stages' separate launches (points, faces, cells, edge flows) through
 * global memory (0). Both give the same bits; only the speed differs, and a
 * simulation may switch between steps. The default is the device's faster
 * one (see the implementation: fused on GPUs).
 */
GR_API void gr_rain_runoff_set_sw_fused(gr_rain_runoff *s, int on);

/**
 * The fused shallow-water stages' tile, tx x ty cells (a work-group of as
 * many work-items); 0 x 0: the device's default. A tuning knob: the bits do
 * not depend on it. Refused (GR_ERR_INVALID_ARGUMENT, the tile kept) where
 * the device's work-groups or local memory are too small for it. On GPUs
 * the shallow-water program is built for its tile (its size a constant of
 * the kernels), so a new tile builds it again before the next step.
 */
GR_API gr_status gr_rain_runoff_set_sw_tile(gr_rain_runoff *s, int tx, int ty);

/**
 * The latest error of a call on this simulation ("" when there was none):
 * its own, never another handle's on the same context. Never NULL.
 */
GR_API const char *gr_rain_runoff_last_error(const gr_rain_runoff *s);

/**
 * The parameter table (RainRate mm/h, Permeability mm/h, ManningN,
 * MaxTimeStep s, CourantNumber, BoundaryWest/East/South/North, LevelWest/East/South/North m,
 * FlowModel, WettingDepth m, DebrisFactor) that
 * gr_rain_runoff_params_validate
 * follows; *count gets the number of rows.
 */
GR_API const gr_param_bound *gr_rain_runoff_param_bounds(int *count);

/**
 * How a local inertial step (FlowModel 1) is launched: in one launch, each
 * work-group computing its tile's faces, limiters and depths in local
 * memory from the tile and a ring of two cells (non-zero), or as three
 * launches, faces, limiters and depths, each through global memory (0).
 * Edges of other kinds than open add one launch either way. Both give the
 * same bits; only the speed differs. The default is the device's faster
 * one (see the implementation).
 */
GR_API void gr_rain_runoff_set_fused(gr_rain_runoff *s, int on);

/**
 * Whether the kernels are compiled for the optional inputs in use
 * (non-zero, the default) or for every input possible (0). An input map
 * (rain, permeability, Manning n), inflows and no-data cells each cost the
 * step loads and tests; compiled without those that are absent, the local
 * inertial step on a CPU is two to three times faster. The call that sets
 * or clears such an input takes the matching program (built once per
 * context and set of inputs; OpenCL drivers also cache the binaries);
 * this switch takes effect at the next step. Both give the same bits; only
 * the speed differs.
 */
GR_API void gr_rain_runoff_set_specialised(gr_rain_runoff *s, int on);

/** The optional inputs, a bit each, as gr_rain_runoff_specialised_for reports them. */
enum {
  GR_RAIN_RUNOFF_INPUT_RAIN = 1,         /**< a rain-rate field */
  GR_RAIN_RUNOFF_INPUT_PERMEABILITY = 2, /**< a permeability field */
  GR_RAIN_RUNOFF_INPUT_INFLOWS = 4,      /**< point inflows or an edge hydrograph */
  GR_RAIN_RUNOFF_INPUT_NO_DATA = 8,      /**< no-data (NaN) elevations */
  GR_RAIN_RUNOFF_INPUT_MANNING = 16,     /**< a Manning map */
  GR_RAIN_RUNOFF_INPUT_ALL = 31
};

/**
 * The optional inputs the step kernels are compiled for now: the inputs in
 * use at the latest step (or at creation), GR_RAIN_RUNOFF_INPUT_ALL when
 * not specialised; -1 for no simulation.
 */
GR_API int gr_rain_runoff_specialised_for(const gr_rain_runoff *s);

/** Frees the simulation; NULL is fine. */
GR_API void gr_rain_runoff_destroy(gr_rain_runoff *s);

#ifdef __cplusplus
}
#endif

#endif
