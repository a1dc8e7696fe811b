/**
 * @file snow_deformation.h
 * @brief Objects pressing into and ploughing through snow (seed 000's
 * thesis), as a mass-conserving, deterministic height-field
 * model on the device.
 *
 * State per grid point: snow depth S (m) over a rigid ground B (m) and the
 * snow's density rho (kg/m^3); the snow surface is H = B + S.
 *
 * One step (gr_snow_deformation_step) takes the objects at the poses last
 * given to gr_snow_deformation_set_objects (the core never moves them: the
 * caller, e.g. the filter, sets each step's poses) and, object by object in
 * the order given:
 *  1. raster: the underside U(i, j) = the lowest height at which the
 *     object's surface crosses the vertical line through grid point (i, j):
 *     the exact minimum over every triangle whose xy projection contains the
 *     point (edges included), of the triangle's plane at the point; +inf
 *     where no triangle covers it (not a bounding box). A scatter, one
 *     work-item per triangle, into an integer atomic minimum of the heights'
 *     order-preserving bits: the exact minimum whatever the order.
 *  2. overlap: D = min(S, max(0, H - U)) (the ground is rigid: snow never
 *     goes below it, so an object below the ground presses at most S).
 *  3. compression vs displacement (Eqs. 3.9-3.11 made mass-consistent):
 *     the displaced height is e = max(W D, S - (S - D) rho_max / rho), at
 *     most D, with W = (rho - rho_min) / (rho_max - rho_min) clamped to
 *     [0, 1] (CompressionModel 0, density-driven; W = 1 when rho_min =
 *     rho_max) or W = 1 - 0.15 (CompressionModel 1, the thesis code's
 *     constant compressed fraction). The column keeps the mass (S - e) rho
 *     in the height S - D: rho' = (S - e) rho / (S - D), never above
 *     rho_max (the second term of e: snow that cannot be compressed further
 *     is displaced; a column pressed to the ground is displaced whole). The
 *     compressed volume is D - e. Thesis errata fixed: Eq. 3.11 lowers the
 *     column by D Q only, the code by D without changing rho (mass lost).
 *  4. imprint: S' = S - D, so the surface meets the underside (or the ground).
 *  5. contour: the points with D = 0 that have an 8-neighbour with D > 0,
 *     but for those the object already touches (their surface within
 *     GR_SNOW_DEFORMATION_CONTACT_GAP of the underside: pressed before),
 *     which lie under it: snow is never put under an object;
 *     outward direction w = -sum over overlapped 8-neighbours of their offset
 *     (the unit-weight filter of Alg. 4.8 on the overlap mask), normalised (0
 *     when the offsets cancel).
 *  6. distribution: the displaced volume V = sum e dx dy and its mass M = sum
 *     e rho dx dy go to the contour, each contour point c receiving the
 *     fraction s_w(c) / sum s_w, s_w = max(0, v^ . (w_x, w_y, 0)) + r / K,
 *     v^ the object's unit velocity (3-D), r = v^_z^2 (the code form of Eq.
 *     3.19, notes section 2.8; zero velocity counts as straight down: a uniform
 *     ring), K = DirectionFalloff, but never more than its room: up to its
 *     ceiling, the lowest underside above it (this object's, or an earlier
 *     one's this step) less twice GR_SNOW_DEFORMATION_CONTACT_GAP, so snow
 *     is never put under an object up to it. What the room under an
 *     overhang (a sphere's, a wheel's) does not hold goes on outward, ring
 *     by ring: the next ring is the points with room that border a full one
 *     (overlapped, touched, or filled by the ring before), weighted the
 *     same way (w from their full neighbours; evenly where no point faces
 *     the motion), until all is placed or 64 rings are filled (the rest
 *     waits, as the rounding's does). (A contour that took its share
 *     whatever the room put snow up to 11 mm inside a sphere pressed into
 *     dense snow, where neither contact nor overlap showed it.) The point's
 *     volume grows by its share of V and its mass by its share of M (rho
 *     mixes), so both are conserved. The totals are device reductions
 *     (reduce.h): no atomics, no append buffers. An object whose overlap
 *     leaves no contour point on the grid (it covers the whole grid) or
 *     whose weights sum to 0 (none ahead, the rest off the grid) deforms
 *     nothing that step.
 * Then, after all objects, talus relaxation (Eqs. 3.29-3.33, with Alg.
 * 4.11's loss fixed): Jacobi iterations with gather (each point computes
 * what it gives and what it receives from the same floats, so volume and
 * mass are conserved and reruns are bit-identical). Point a gives to each
 * 8-neighbour b the excess x_ab = max(0, H_a - H_b - MaxSlope d_ab), d_ab
 * the pair's distance (dx, dy or the diagonal: the slope is a true slope,
 * unlike the thesis' per-cell constant), but never more than the room under
 * b's ceiling C_b - H_b (C_b: the lowest underside above b less a clearance
 * of twice GR_SNOW_DEFORMATION_CONTACT_GAP; +inf where no object covers b),
 * times min(k_a, k_in_b), the thermal-erosion limits on both sides of the
 * pair: a gives at most 3/4 of its largest excess in all (and no more than
 * S_a), b takes at most 3/4 of its largest incoming excess: a lone pair with
 * excess x ends at the threshold minus x/2, an over-relaxation that settles
 * long slopes in a third of the iterations of exact levelling (see
 * GR_SNOW_TALUS_SHARE; a pair overshoots past level only where x exceeds
 * twice the threshold, and the next iteration sends the overshoot back).
 * Excesses no larger than the threshold (the creep of a slight excess down a
 * slope already at the talus angle) move at 0.95 instead of 3/4: there a
 * slope relaxes like a diffusion of its excess, and the share is its speed.
 * The room: snow slides in under an object (the gap behind a ploughing
 * sphere fills as the trench walls collapse) but never rises to touch it,
 * so the imprint holds and talus never makes contact. (the seed's rule,
 * never into a cell an object occupies, would leave the space under any
 * overhang empty; a bare "not where U_b <= H_a", this core's first rule,
 * hid an excess whole until a small change revealed it, and trench walls
 * under a ploughing sphere crept for hundreds of iterations.) Moved snow
 * carries its density
 * (mass mixes). Only a point that can move more than RelaxTolerance gives
 * (min(S_a, largest x_ab)), and the relaxation stops when none can (read
 * every 4 iterations, with the box of those points, which bounds the next
 * iterations' window) or after MaxRelaxIterations (the rest goes on in the
 * next steps). With a SlumpSpeed c the talus of a step runs on its reach
 * only: the points within n = ceil(c dt / d) points (8-neighbour steps, d
 * the finer spacing) of a point that can move at the step's start or of a
 * point on a slope (one standing at least half its threshold above a
 * neighbour: moving snow runs down a slope, or a heap's face, as far as
 * it goes); the other points neither give nor receive. Within its reach
 * the snow settles; the front into flat snow advances n points a step. So
 * a pile collapses, and the heap an object feeds spreads, at c on every
 * grid, steeper than MaxSlope only within about c dt of where snow arrived
 * that step (a talus cut to n iterations a step instead carries a flux that
 * shrinks with the spacing: a box pushed through snow built a wall one
 * point thick ahead of it, 1.3 m over the snow at 2.5 cm spacing, taller on
 * finer grids). c = 0 (or a reach that spans the domain) relaxes each step
 * to the end. A RelaxTolerance below 16 quanta (1.5e-5 m) acts as 16
 * quanta, so that an iteration always moves something.
 *
 * Exact volume: depths and every amount that moves (D rounded down, e to
 * the nearest, each contour point's deposit and each talus transfer rounded
 * down) are whole quanta of 2^-20 m. Below 16 m of snow every sum and
 * difference of such floats is exact, so what leaves one point arrives at
 * another to the bit, and the volume closes to the ledger's own rounding
 * over any number of steps. What the rounding of the deposits keeps back
 * (less than a quantum per contour point and ring) waits for the next press
 * and counts in the ledger meanwhile. The mass is depth times a float density:
 * it closes to the densities' rounding (about 6e-7 of the mass after 10^4
 * steps of the constant compression model, the worst case tested).
 *
 * Resistance per object (Eqs. 3.6-3.8 made dimensionally sensible): the
 * snow the object moved this step has the mass m = sum D rho dx dy (Eq. 3.6
 * with the cell area the thesis left out); the object brings it to its own
 * velocity within the step, so the force on the object is the momentum flux
 *   F = -m v / dt   (N),
 * opposite to the motion. For steady ploughing D per step is the frontal
 * area A times v dt, so F = rho A |v| v: the familiar drag form, growing with
 * speed and density, and zero without contact or motion. contact_area =
 * dx dy times the number of points whose snow surface reaches to within
 * GR_SNOW_DEFORMATION_CONTACT_GAP of the underside (or above it) before the
 * imprint.
 *
 * Fields (gr_field): set ELEVATION (required, m), optionally SNOW_DEPTH (m;
 * default params.initial_snow_depth) and SNOW_DENSITY (kg/m^3, within
 * [min_density, max_density]; default params.initial_density). Read
 * SNOW_DEPTH, SNOW_SURFACE (= elevation + depth), SNOW_DENSITY, OVERLAP (sum
 * over the objects of D in the last step, m), CONTACT (1 where some object
 * touched the snow in the last step, else 0) and ELEVATION.
 *
 * Pieces of a split domain: see "Pieces of a split domain" below; a piece
 * computes bit for bit what the whole grid computes at its points.
 */
#ifndef GRAUPEL_SNOW_DEFORMATION_H
#define GRAUPEL_SNOW_DEFORMATION_H

#include "graupel/memory.h"
#include "graupel/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The thesis code's constant compressed fraction (CompressionModel 1). */
#define GR_SNOW_DEFORMATION_CONSTANT_COMPRESSION 0.15

/** An underside within this of the snow surface counts as contact, m. */
#define GR_SNOW_DEFORMATION_CONTACT_GAP 1e-3

/** Most objects one simulation takes at once. */
#define GR_SNOW_DEFORMATION_MAX_OBJECTS 64

/** CompressionModel values. */
typedef enum gr_snow_compression {
  GR_SNOW_COMPRESSION_DENSITY = 0, /**< Eqs. 3.9-3.11, mass-consistent (default) */
  GR_SNOW_COMPRESSION_CONSTANT = 1 /**< a constant compressed fraction, 0.15 */
} gr_snow_compression;

/**
 * The parameters, in the core's units (SI). Ranges and defaults are the rows
 * of gr_snow_deformation_param_bounds, written nowhere else.
 */
typedef struct gr_snow_deformation_params {
  double initial_snow_depth; /**< m, when no SNOW_DEPTH is set (row InitialSnowDepth) */
  double initial_density;    /**< kg/m^3, when no SNOW_DENSITY is set (row InitialDensity) */
  double min_density;        /**< rho_min, kg/m^3 (row MinDensity; DensityRange[0]) */
  double max_density;        /**< rho_max, kg/m^3 (row MaxDensity; DensityRange[1]) */
  int compression_model;     /**< gr_snow_compression (row CompressionModel) */
  double max_slope;          /**< talus slope, m/m (row MaxSlope) */
  double direction_falloff;  /**< K of s_w (row DirectionFalloff) */
  int max_relax_iterations;  /**< talus iteration cap per step (row MaxRelaxIterations) */
  double relax_tolerance;    /**< m (row RelaxTolerance) */
  double slump_speed;        /**< m/s, the talus front's speed; 0: instant (row SlumpSpeed) */
} gr_snow_deformation_params;

/** The table's defaults. */
GR_API void gr_snow_deformation_params_init(gr_snow_deformation_params *p);

/**
 * Checks every parameter against its row of the table, and that
 * min_density <= initial_density <= max_density; the sentence in msg names
 * the property, its value and the range.
 */
GR_API gr_status gr_snow_deformation_params_validate(const gr_snow_deformation_params *p, char *msg,
                                                     size_t msg_len);

/**
 * The parameter table (InitialSnowDepth m, InitialDensity kg/m^3,
 * MinDensity kg/m^3, MaxDensity kg/m^3, CompressionModel, MaxSlope m/m,
 * DirectionFalloff, MaxRelaxIterations, RelaxTolerance m, SlumpSpeed m/s); *count gets the
 * number of rows.
 */
GR_API const gr_param_bound *gr_snow_deformation_param_bounds(int *count);

/**
 * The check set_field applies to an input field, on the host (no device):
 * f must be ELEVATION, SNOW_DEPTH or SNOW_DENSITY; n values, rows of nx
 * points (nx 0: one row, for naming the point); every value finite,
 * elevations within +-1e6 m, depths 0 to 1e4 m, densities within
 * [p->min_density, p->max_density] (as floats). The sentence names the field,
 * the point (i, j) and the value. values may be NULL only when n is 0.
 */
GR_API gr_status gr_snow_deformation_field_validate(const gr_snow_deformation_params *p, gr_field f,
                                                    const float *values, size_t n, size_t nx,
                                                    char *msg, size_t msg_len);

/** Book-keeping; volumes m^3, masses kg, cumulative since create or reset. */
typedef struct gr_snow_deformation_ledger {
  double time;              /**< simulated time, s (the sum of the steps' dt) */
  long long steps;          /**< steps taken */
  double initial_volume;    /**< snow volume at the start (grows with set_field) */
  double initial_mass;      /**< snow mass at the start (grows with set_field) */
  double snow_volume;       /**< snow volume now, sum S dx dy */
  double snow_mass;         /**< snow mass now, sum S rho dx dy */
  double compressed_volume; /**< volume lost to compression, cumulative */
  double displaced_volume;  /**< volume moved to contours, cumulative */
  /** snow_mass - initial_mass (kg): the float densities' rounding only */
  double balance_error;
  /** initial_volume - compressed_volume - snow_volume (m^3): the ledger's
   * own double rounding only (amounts move in whole quanta) */
  double volume_error;
  int relax_iterations; /**< talus iterations of the last step */
} gr_snow_deformation_ledger;

typedef struct gr_snow_deformation gr_snow_deformation;

/**
 * What a simulation on grid needs (memory.h), its ring included and its
 * objects not (they add 36 bytes a triangle): 68 bytes a point on the
 * device (depth and density twice, ground, the initial depth and density,
 * the underside, overlap, weight, overlap sum, contact, underside minimum,
 * the talus rates in and out, the movable snow and a scratch plane).
 * GR_ERR_INVALID_ARGUMENT without grid or out.
 */
GR_API gr_status gr_snow_deformation_memory(const gr_grid *grid, gr_memory_need *out);

/**
 * A simulation on a whole grid or a piece of one (see "Pieces of a split
 * domain" below): validates grid and
 * parameters, refuses a grid that gr_snow_deformation_memory says does not
 * fit (GR_ERR_TOO_LARGE, before anything is allocated), builds the kernels,
 * allocates the state: flat ground at 0,
 * snow of initial_snow_depth and initial_density, no objects.
 */
GR_API gr_status gr_snow_deformation_create(gr_context *ctx, const gr_grid *grid,
                                            const gr_snow_deformation_params *p,
                                            gr_snow_deformation **out);

/**
 * New parameters from the next step on (validated; the state is kept;
 * initial_snow_depth and initial_density only matter to create).
 */
GR_API gr_status gr_snow_deformation_set_params(gr_snow_deformation *s,
                                                const gr_snow_deformation_params *p);

/**
 * Uploads ELEVATION, SNOW_DEPTH or SNOW_DENSITY (nx*ny floats, row-major;
 * for a piece with neighbours its local array, ring included):
 * every value finite, elevations within +-1e6 m, depths 0 to 1e4 m,
 * densities within [min_density, max_density]; a refused field (a sentence
 * naming the field, the point (i, j) and the value) leaves the state as it
 * was. SNOW_DEPTH and SNOW_DENSITY replace the snow now and become the state
 * reset returns to; the ledger's initial volume and mass move by the change.
 */
GR_API gr_status gr_snow_deformation_set_field(gr_snow_deformation *s, gr_field f,
                                               const float *host);

/**
 * The objects for the next steps (copied; n from 0 to
 * GR_SNOW_DEFORMATION_MAX_OBJECTS): each mesh must pass
 * gr_mesh_validate(mesh, 1, ...) (closed), its pose is its transform (world,
 * z up). velocities: 3 per object, m/s, world (for the direction weights and
 * the resistance); NULL means all at rest. An object wholly outside the grid
 * is accepted and touches nothing. A refusal names the object and keeps the
 * objects set before.
 */
GR_API gr_status gr_snow_deformation_set_objects(gr_snow_deformation *s, const gr_mesh *meshes,
                                                 int n, const double *velocities);

/**
 * One step of dt seconds (finite, 1e-9 to 3600); waits. A piece with
 * neighbours steps only with an allreduce and a halo exchange set, and
 * every piece of the domain steps together (the calls are collective).
 */
GR_API gr_status gr_snow_deformation_step(gr_snow_deformation *s, double dt);

/**
 * Reads a field back (waits): SNOW_DEPTH, SNOW_SURFACE, SNOW_DENSITY,
 * OVERLAP, CONTACT or ELEVATION, nx*ny floats (a piece: its own points).
 */
GR_API gr_status gr_snow_deformation_get_field(gr_snow_deformation *s, gr_field f, float *host);

/**
 * The ledger now (waits; reduces volume and mass on the device, in fixed
 * point). A piece with an allreduce gives the whole domain's ledger (a
 * collective call); one without, its own points' volumes and masses.
 */
GR_API gr_status gr_snow_deformation_ledger_get(gr_snow_deformation *s,
                                                gr_snow_deformation_ledger *out);

/**
 * The resistance of the last step per object (see above): force3 gets 3
 * doubles per object (N, world), area one per object (m^2); either may be
 * NULL. n must equal the number of objects set. Zeros before the first step.
 */
GR_API gr_status gr_snow_deformation_object_forces(gr_snow_deformation *s, double *force3,
                                                   double *area, int n);

/**
 * The mean resistance since the last gr_snow_deformation_clear_impulses (or
 * set-up, reset, a new number of objects): each object's impulse, the sum
 * of its step forces times their steps, over the time those steps took (N,
 * world: force3 gets 3 doubles per object), the largest step force's
 * magnitude (N, peak one per object) and that time (s, *seconds); any may
 * be NULL. Zeros before a step. The force of one step aliases with the
 * step (a step that moves no snow reports 0, the next one twice the mean):
 * a caller that clears at each output reports the interval's force,
 * the same for any step short enough. The impulses are part of the
 * checkpoint state.
 */
GR_API gr_status gr_snow_deformation_object_mean_forces(gr_snow_deformation *s, double *force3,
                                                        double *peak, double *seconds, int n);

/** Starts the impulses of gr_snow_deformation_object_mean_forces anew. NULL is fine. */
GR_API void gr_snow_deformation_clear_impulses(gr_snow_deformation *s);

/**
 * Progress (see gr_progress_fn): called after each step with the time
 * reached; a non-zero return makes the next gr_snow_deformation_step
 * refuse with GR_ERR_ABORTED until set_progress or reset is called. NULL
 * removes it. On a piece with an allreduce the stop is global: see "Pieces
 * of a split domain".
 */
GR_API void gr_snow_deformation_set_progress(gr_snow_deformation *s, gr_progress_fn fn, void *user);

/**
 * Checkpoints: depth, density, overlap, contact, the last forces, time,
 * steps and ledger as bytes. Loading into a simulation of the same grid,
 * inputs and objects makes every later step bit-identical. Inputs
 * (elevation), parameters and objects are not part of it. A piece's state
 * holds its local arrays, ring included, and its i0, j0; it loads only into
 * the same piece, with no exchange (the ring is as fresh as when saved).
 */
GR_API gr_status gr_snow_deformation_state_size(const gr_snow_deformation *s, size_t *bytes);
GR_API gr_status gr_snow_deformation_state_save(gr_snow_deformation *s, void *host, size_t bytes);
GR_API gr_status gr_snow_deformation_state_load(gr_snow_deformation *s, const void *host,
                                                size_t bytes);

/** Back to the initial snow (the last SNOW_DEPTH/SNOW_DENSITY set, or the params'), ledger zeroed;
 * elevation and objects kept. */
GR_API gr_status gr_snow_deformation_reset(gr_snow_deformation *s);

/**
 * @name Pieces of a split domain
 *
 * A simulation may hold one piece of a domain split among processes (the
 * gr_grid piece fields: i0, j0, global_nx, global_ny, ghost). Only the
 * domain's own edges are boundaries. On every side where the piece has a
 * neighbour it keeps a ring of grid.ghost points, copies of the
 * neighbour's points; grid.ghost must then be GR_SNOW_DEFORMATION_GHOST, or
 * a multiple of it up to GR_SNOW_DEFORMATION_GHOST_MAX (a wider ring, see
 * below), and the piece at least that many points wide toward the
 * neighbour. The local arrays are the piece and its ring: (nx + rings) x
 * (ny + rings) floats for set_field and checkpoints; get_field gives the
 * own nx x ny.
 *
 * Why 8: a talus iteration reads points two away (a point's move reads its
 * neighbours' rates, a rate its neighbours' heights), and the talus runs
 * GR_SNOW_BLOCK_ITERATIONS (4) iterations per launch (or per group of
 * one-launch iterations) on the local arrays, ring included: after a launch
 * the outer 2 x 4 points of the ring are stale, every own point is the
 * whole grid's. So the ring is refreshed after every launch, after each
 * object's press and each further ring of its deposit (whose contour reads
 * one point away), and after each pass of the talus' reach (its mask, a
 * max filter of at most 7 points a pass, travels in the strips' depth
 * slot: a point's mover status reads its neighbours, so a ring of 8 feeds
 * 7 points).
 *
 * A wider ring, m x GR_SNOW_DEFORMATION_GHOST points (grid.ghost), trades
 * memory and bytes per exchange (about the same bytes per step) for fewer
 * exchanges (temporal blocking across the cut): the talus runs m launches
 * between exchanges (each makes 8 more of the ring's points stale, from
 * its outer edge in) and the reach's mask grows by up to grid.ghost - 1
 * points a pass; the other stages exchange as with the narrow ring. The
 * same bits as the whole grid's at every width.
 *
 * The exchange is the caller's (gr_snow_deformation_set_halo_exchange),
 * called by the core at those stages, so a step makes several: per ring
 * point the state's depth and density (gr_snow_deformation_halo_get on the
 * sending piece, the own points next to the side;
 * gr_snow_deformation_halo_set on the receiving one); x sides (west, east)
 * first, then y sides (south, north): an x strip spans the local arrays'
 * rows and a y strip their columns, ring included, so corner points travel
 * through the x neighbour.
 *
 * Every piece rasterizes every object over its local arrays (the
 * coordinates of a point are the domain's, the same floats as on the whole
 * grid). What steers a step is global through the allreduce callback and
 * the same integers on every split: each object's displaced height, its
 * mass, the contour weights and the deposits (fixed point, summed as
 * int64 over the piece's own points, then GR_REDUCE_SUM over the pieces,
 * each int64 as two doubles of 32 bits: exact), the talus check (the
 * largest movable amount and the box of the points still moving, in the
 * domain's indices, GR_REDUCE_MAX), so every piece takes the same decisions
 * as the whole grid, and every own point, the resistance and the contact
 * area are the whole grid's bit for bit. The ledger is global the same way.
 *
 * Stepping on pieces is collective: every piece sets the same objects and
 * calls gr_snow_deformation_step with the same dt, and each step makes the
 * same sequence of allreduce and exchange calls on every piece. Stop: a
 * piece's progress callback (each piece may have its own, or none) only
 * raises a flag, reduced by GR_REDUCE_MAX after every step, so a stop asked
 * for on any one piece stops every piece after the same step (their next
 * step refuses with GR_ERR_ABORTED). An error on one piece (a failed
 * launch, a failed exchange) returns on that piece only: the others wait
 * in their next collective call, which the caller's callbacks must end
 * (MPI_Abort, or a status that is not GR_OK).
 * @{
 */

/** Ring width of a piece toward each neighbour, points (2 per talus iteration x 4). */
#define GR_SNOW_DEFORMATION_GHOST 8
/** The widest ring a piece may ask for (grid.ghost, a multiple of GR_SNOW_DEFORMATION_GHOST):
 * 8 talus launches between exchanges. */
#define GR_SNOW_DEFORMATION_GHOST_MAX 64

/** Sides of a piece, for the halo calls. */
typedef enum gr_snow_deformation_side {
  GR_SNOW_DEFORMATION_WEST = 0,  /**< toward i0 - 1 */
  GR_SNOW_DEFORMATION_EAST = 1,  /**< toward i0 + nx */
  GR_SNOW_DEFORMATION_SOUTH = 2, /**< toward j0 - 1 */
  GR_SNOW_DEFORMATION_NORTH = 3  /**< toward j0 + ny */
} gr_snow_deformation_side;

/**
 * The global reduction over the pieces (see gr_allreduce_fn); NULL (the
 * default) for a simulation that is the whole domain. Values per call: at
 * most 16.
 */
GR_API void gr_snow_deformation_set_allreduce(gr_snow_deformation *s, gr_allreduce_fn fn,
                                              void *user);

/**
 * The halo exchange (see gr_halo_exchange_fn and above), called with user
 * at every stage of a step that uses up the ring; NULL (the default)
 * removes it. Never called for a simulation without a ring.
 */
GR_API void gr_snow_deformation_set_halo_exchange(gr_snow_deformation *s, gr_halo_exchange_fn fn,
                                                  void *user);

/** Bytes of the halo strip on `side` (a gr_snow_deformation_side); 0 where there is no neighbour.
 */
GR_API gr_status gr_snow_deformation_halo_size(const gr_snow_deformation *s, int side,
                                               size_t *bytes);

/** Copies the own points next to `side` out (for the neighbour on that side); waits. */
GR_API gr_status gr_snow_deformation_halo_get(gr_snow_deformation *s, int side, void *host,
                                              size_t bytes);

/** Copies the neighbour's strip into the ring on `side`; waits. */
GR_API gr_status gr_snow_deformation_halo_set(gr_snow_deformation *s, int side, const void *host,
                                              size_t bytes);
/** @} */

/** The latest error of a call on this simulation ("" when none). Never NULL. */
GR_API const char *gr_snow_deformation_last_error(const gr_snow_deformation *s);

/**
 * Per-stage wall times, for graupel-bench: cumulative since timing was last
 * switched on (ms). While on, each step waits for the device after every
 * stage (slower: for profiling only).
 */
typedef struct gr_snow_deformation_timing {
  long long steps;            /**< steps timed */
  double raster_ms;           /**< underside raster, all objects */
  double press_ms;            /**< overlap, compression totals (reduction) */
  double contour_ms;          /**< contour cells and weights */
  double distribution_ms;     /**< imprint and deposit on the contour */
  double relax_ms;            /**< talus relaxation */
  long long relax_iterations; /**< talus iterations, summed over the steps */
} gr_snow_deformation_timing;

/** Switches per-stage timing on (non-zero; the sums restart) or off. */
GR_API void gr_snow_deformation_set_timing(gr_snow_deformation *s, int on);

/**
 * How the talus iterations are launched: in blocks of 4 iterations per
 * launch, a work-group iterating its tile in local memory (non-zero; the
 * default on a GPU, where a launch costs more than its work), or two
 * launches per iteration (0; the default on a CPU, where the blocks' halos
 * cost more than the launches). Both give the same bits; only the speed
 * differs.
 */
GR_API void gr_snow_deformation_set_blocked(gr_snow_deformation *s, int on);

/**
 * Whether the talus' last iterations, once the snow still moving fits in a
 * small window, run in one work-group that iterates and checks by itself
 * (non-zero, the default but on a piece with neighbours) or as the other
 * iterations do (0). Both give the same bits; only the speed differs.
 */
GR_API void gr_snow_deformation_set_group(gr_snow_deformation *s, int on);

/** The sums since timing was switched on (zeros when it never was). */
GR_API gr_status gr_snow_deformation_timing_get(const gr_snow_deformation *s,
                                                gr_snow_deformation_timing *out);

/** Frees the simulation; NULL is fine. */
GR_API void gr_snow_deformation_destroy(gr_snow_deformation *s);

#ifdef __cplusplus
}
#endif

#endif
