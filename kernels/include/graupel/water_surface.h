/**
 * @file water_surface.h
 * @brief Waves on standing water (seed 003's height-field water surface,
 * seed 004's raindrop ripples): the damped linear wave equation on the wet
 * points of a grid, stepped on the device, with reflecting shores and
 * raindrop impacts, and the fields a renderer needs (wave height, water
 * surface, normals, wet mask).
 *
 * Water. The still water is given either by a depth (WATER_DEPTH, e.g. Rain
 * Runoff's output): a point is wet where its depth exceeds WetDepth (1 cm by
 * default: thinner films do not carry visible waves), and the still surface
 * is elevation + depth; or, with UseLakeLevel, by a lake: a point is wet
 * where its elevation lies below LakeLevel, the still surface is LakeLevel
 * and the depth LakeLevel - elevation (a lake replaces any depth given).
 * Without either there is no water, and stepping is refused with a
 * sentence. Water with no wet point is not refused (runoff early in a
 * storm is dry): nothing moves then; the ledger's wet_points says so.
 *
 * Model (seed 003 leaves its solver to Klein's thesis, which is not
 * at hand; this is the Gomez / Kass-Miller wave-equation height field in
 * its place). The wave height h (m, above the still
 * surface) obeys
 *    h_tt = c^2 (h_xx + h_yy) - gamma h_t
 * with c = WaveSpeed (m/s) and gamma = Damping (1/s), each grid point a
 * cell of dx by dy. In time: symplectic Euler, which is the leapfrog
 * scheme with the vertical velocity v = h_t at half steps,
 *    v' = (v + dt c^2 L(h)) exp(-gamma dt),   h' = h + dt v',
 * where L sums (h_nb - h) / d^2 over the 4 neighbours that are wet: a face
 * to a dry point or beyond the grid's edge carries nothing (Neumann: a
 * reflecting shore, the wall half a spacing beyond the last wet point, so a
 * basin of n wet points is n dx long). Dry points hold h = v = 0 always.
 * Consequences the tests pin: every face's difference is the exact negative
 * of its neighbour's, so the sum of h over the wet points (the mean level)
 * stays at its initial value to float rounding with or without damping;
 * without damping the energy
 *    E = sum (1/2 v^2 + 1/2 c^2 |grad h|^2 + 1/2 dt c^2 v L(h)) dx dy
 * (m^4/s^2; |grad h|^2 per wet-wet face; the last term, of the last step's
 * dt, is symplectic Euler's correction for v being half a step ahead of h,
 * which makes E the scheme's invariant) is conserved to rounding; with
 * damping it decays as exp(-gamma t) (each mode's amplitude as
 * exp(-gamma t / 2)), for gamma well below the mode's frequency; a mode cos(m pi x / L) cos(n pi y
 * / L) of a square basin of side L oscillates with the period 2 L / (c sqrt(m^2 + n^2)) (to 1e-3
 * for 16 points per half wavelength: the scheme's dispersion).
 *
 * Stability (the explicit scheme's CFL limit): c dt sqrt(1/dx^2 + 1/dy^2)
 * <= 1, i.e. c dt / dx <= 1/sqrt(2) for dx = dy. The stable step is
 * CourantNumber times it; gr_water_surface_step refuses a longer dt, and
 * gr_water_surface_advance takes n = ceil(duration / stable step) equal
 * steps that end exactly at the duration.
 *
 * Default wave speed: a fixed 1 m/s (the shallow-water speed sqrt(g d) of
 * 10 cm of water), not the mean depth's sqrt(g d): runoff films of a few
 * centimetres would give ripples too slow to see, and lakes of tens of
 * metres a step too short to be worth taking. Set sqrt(9.81 d) for depth d
 * where the physical speed matters.
 *
 * Raindrops (seed 004's ripples): a drop falls on wet
 * point (a, b) during step k with the chance p = DropRate dx dy dt (at most
 * one per point per step: p is capped at 1), decided by a hash of (Seed, k,
 * a, b), at a position hashed uniformly within the point's cell. So drops
 * are a pure function of the seed and the step: reruns, checkpoints and
 * times requested in any order give the same drops. A drop adds
 * (A s^2 / 2) L(G) to h, where G is the unit Gaussian exp(-r^2 / (2 s^2))
 * around it (A = DropAmplitude, s = DropRadius, summed within 4 s but at
 * most 12 points) and L the masked Laplacian above: for a drop well inside
 * the water a dimple of depth A at its centre with a low ring at 2 s (the
 * Laplacian of a Gaussian), and, being a sum of face differences, volume
 * neutral: drops never raise or lower the mean level. A DropRadius below
 * the spacing is not resolved: its dimple is one point deep and shallower
 * than DropAmplitude (about A s^2 (1/dx^2 + 1/dy^2)).
 *
 * Fields. Inputs by gr_water_surface_set_field: GR_FIELD_ELEVATION (m;
 * flat ground at 0 until set) and GR_FIELD_WATER_DEPTH (m, >= 0), each
 * nx*ny floats, finite; and an initial wave (gr_water_surface_set_wave).
 * Outputs by gr_water_surface_get: the gr_water_surface_output list below.
 *
 * A simulation holds a whole grid or one strip of a split domain: see
 * "Pieces of a split domain" below.
 */
#ifndef GRAUPEL_WATER_SURFACE_H
#define GRAUPEL_WATER_SURFACE_H

#include "graupel/memory.h"
#include "graupel/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The outputs; each is nx*ny floats (normal: 3 per point, x fastest). */
typedef enum gr_water_surface_output {
  GR_WATER_WAVE_HEIGHT = 0, /**< `wave_height`: h, m above the still surface (0 dry) */
  GR_WATER_NORMAL,          /**< `normal`: unit normal of water_surface ((0,0,1) dry) */
  GR_WATER_SURFACE,         /**< `water_surface`: elevation + depth + h, m (dry: + depth) */
  GR_WATER_WET,             /**< `wet`: 1 on wet points, 0 on dry ones */
  GR_WATER_ELEVATION,       /**< `elevation`: the ground, m */
  GR_WATER_DEPTH,           /**< `water_depth`: the still water's depth, m */
  GR_WATER_OUTPUT_COUNT
} gr_water_surface_output;

/** The array name of an output ("wave_height", ...); NULL if unknown. */
GR_API const char *gr_water_surface_output_name(gr_water_surface_output o);
/** Components of an output (3 for the normal, else 1; 0 if unknown). */
GR_API int gr_water_surface_output_components(gr_water_surface_output o);

/**
 * The parameters, in the core's units (SI). Ranges and defaults are the
 * rows of gr_water_surface_param_bounds, written nowhere else.
 */
typedef struct gr_water_surface_params {
  double wave_speed;     /**< WaveSpeed: c, m/s, above 0 */
  double damping;        /**< Damping: gamma, 1/s */
  double wet_depth;      /**< WetDepth: m; deeper points are wet (depth input) */
  int use_lake_level;    /**< UseLakeLevel: 1 makes a lake at LakeLevel */
  double lake_level;     /**< LakeLevel: m */
  double drop_rate;      /**< DropRate: drops per m^2 per s */
  double drop_amplitude; /**< DropAmplitude: m, a dimple's depth */
  double drop_radius;    /**< DropRadius: m, the Gaussian's sigma, above 0 */
  int seed;              /**< Seed: of the drops */
  double cfl;            /**< CourantNumber: fraction of the stable step, above 0 */
} gr_water_surface_params;

/** The table's defaults. */
GR_API void gr_water_surface_params_init(gr_water_surface_params *p);

/** Checks every parameter against its row of the table; a sentence goes to msg. */
GR_API gr_status gr_water_surface_params_validate(const gr_water_surface_params *p, char *msg,
                                                  size_t msg_len);

/**
 * The parameter table (WaveSpeed m/s, Damping 1/s, WetDepth m, UseLakeLevel,
 * LakeLevel m, DropRate 1/(m^2 s), DropAmplitude m, DropRadius m, Seed,
 * CourantNumber); *count gets the rows.
 */
GR_API const gr_param_bound *gr_water_surface_param_bounds(int *count);

/**
 * The book-keeping: sums over the wet points, each cell's float added in
 * the fixed point of graupel/reduce.h (integer sums: exact, the same bits
 * however the grid is split), then turned into a double once.
 */
typedef struct gr_water_surface_ledger {
  double time;           /**< simulated time since the start (or reset), s */
  long long steps;       /**< steps taken */
  long long wet_points;  /**< points that are wet */
  double wave_volume;    /**< sum of h dx dy, m^3: constant (drops included) */
  double initial_volume; /**< the same at time 0 */
  double energy;         /**< the scheme's energy E (see above), m^4/s^2 */
  double max_wave;       /**< largest |h|, m */
} gr_water_surface_ledger;

typedef struct gr_water_surface gr_water_surface;

/**
 * What a simulation on grid needs (memory.h), its ring included: 33 bytes a
 * point on the device (h twice, v, base, the initial h and the derived
 * fields' three floats, the wet mask's byte) and 13 on the host
 * (the elevation, the depth, and the wet mask and still surface made when
 * the water is prepared). GR_ERR_INVALID_ARGUMENT without grid or out.
 */
GR_API gr_status gr_water_surface_memory(const gr_grid *grid, gr_memory_need *out);

/**
 * A simulation on a whole grid or a piece of one (see "Pieces of a split
 * domain"), at rest, with flat ground at 0 and no water yet. A grid that
 * gr_water_surface_memory says does not fit is GR_ERR_TOO_LARGE, before
 * anything is allocated.
 */
GR_API gr_status gr_water_surface_create(gr_context *ctx, const gr_grid *grid,
                                         const gr_water_surface_params *p, gr_water_surface **out);

/**
 * New parameters from the next step on (validated; kept on failure). The
 * wave is kept; the water is found again (a point that becomes dry loses
 * its wave at the next step).
 */
GR_API gr_status gr_water_surface_set_params(gr_water_surface *s, const gr_water_surface_params *p);

/**
 * Uploads GR_FIELD_ELEVATION or GR_FIELD_WATER_DEPTH (nx*ny floats; a piece:
 * its local arrays, rings included): every
 * value finite, elevations within +-1e6 m, depths 0 to 1e4 m; a refused
 * field names the point (i, j) and leaves the state as it was.
 */
GR_API gr_status gr_water_surface_set_field(gr_water_surface *s, gr_field f, const float *host);

/**
 * Sets the wave height h (nx*ny floats, a piece's local arrays; m, finite,
 * |h| <= 1e4) with v = 0,
 * as the state now and the state reset returns to; it is zeroed on dry
 * points at the next step.
 */
GR_API gr_status gr_water_surface_set_wave(gr_water_surface *s, const float *host);

/** The longest step taken: CourantNumber times the CFL limit, s. */
GR_API gr_status gr_water_surface_stable_dt(gr_water_surface *s, double *dt);

/**
 * Enqueues nsteps (>= 0) steps of dt (above 0, at most the CFL limit
 * c dt sqrt(1/dx^2 + 1/dy^2) <= 1); does not wait. Refused while there is
 * no water (see above).
 */
GR_API gr_status gr_water_surface_step(gr_water_surface *s, double dt, int nsteps);

/**
 * Advances by duration s (>= 0, finite) in n = ceil(duration / stable_dt)
 * equal steps. With a progress callback it waits now and then and may stop
 * at a step boundary (GR_ERR_ABORTED, the state valid there). *steps_taken
 * may be NULL.
 */
GR_API gr_status gr_water_surface_advance(gr_water_surface *s, double duration, int *steps_taken);

/** Progress and abort for advance (see gr_progress_fn); NULL removes it. */
GR_API void gr_water_surface_set_progress(gr_water_surface *s, gr_progress_fn fn, void *user);

/**
 * Reads an output back (waits): nx*ny floats, 3*nx*ny for the normal (a
 * piece: its own rows).
 * Refused while there is no water.
 */
GR_API gr_status gr_water_surface_get(gr_water_surface *s, gr_water_surface_output o, float *host);

/** The ledger now (waits; reduces on the device; collective on pieces). */
GR_API gr_status gr_water_surface_ledger_get(gr_water_surface *s, gr_water_surface_ledger *out);

/** Back to the initial wave (set_wave's, else rest), time 0, step 0. Inputs are kept. */
GR_API gr_status gr_water_surface_reset(gr_water_surface *s);

/**
 * Checkpoints: h, v, time and steps as bytes (a piece: its local arrays
 * and its j0; it loads only into the same piece). Loaded into a simulation
 * of the same grid, inputs and parameters, every later step is bit-identical
 * to those that followed the save (the drops included: they follow the
 * step count).
 */
GR_API gr_status gr_water_surface_state_size(const gr_water_surface *s, size_t *bytes);
GR_API gr_status gr_water_surface_state_save(gr_water_surface *s, void *host, size_t bytes);
GR_API gr_status gr_water_surface_state_load(gr_water_surface *s, const void *host, size_t bytes);

/**
 * @name Pieces of a split domain
 *
 * A simulation may hold one strip of a domain split along y (the gr_grid
 * piece fields: j0, global_ny, ghost; a piece spans whole rows: i0 = 0 and
 * nx = global_nx or 0). On each side where the strip has a neighbour
 * (south: j0 > 0, north: j0 + ny < global_ny) it keeps a ring of grid.ghost
 * rows, copies of the neighbour's points; grid.ghost must be at least
 * gr_water_surface_ghost(params, dy) and the strip at least grid.ghost rows
 * high. The local arrays are the strip and its rings: nx x (ny + rings)
 * floats for set_field, set_wave and checkpoints; get gives the own nx x ny.
 *
 * What the ring holds. The wave stencil reaches one row: a step of an own
 * point reads h and the drops' Gaussians g one row away, and the ledger's
 * energy and the normals read h one row away. So one row of h is exchanged
 * per step (the halo calls: the own row next to the cut goes to the
 * neighbour's first ring row, after every step, through the caller's
 * exchange). The rest of the ring serves the drops: g at a point sums the
 * drops within reach (4 DropRadius, at most 12 rows) that fall on wet
 * points, and whether a point is wet follows from the inputs alone, which
 * the ring holds (set_field's local arrays). So the ring is 1 + that reach
 * in rows, and g is computed on the own rows and the first ring row from
 * the ring's inputs, never exchanged. Raindrops are a hash of the domain's
 * point index (i, j0 + local row), the seed and the step, so every piece
 * makes the whole grid's drops and the whole grid's bits.
 *
 * The ledger is a fixed-point integer sum per piece (see the ledger),
 * added over the pieces by the allreduce (GR_REDUCE_SUM of gr_fixed_pack's
 * exact 32-bit parts) and the largest |h| by GR_REDUCE_MAX: the same bits
 * for the whole grid and any split, whatever order the allreduce adds in.
 *
 * Stepping on pieces is collective: every piece sets the same parameters
 * and calls step or advance with the same arguments; each step makes one
 * exchange call, and ledger_get (and the first step after the wave is set,
 * which records the initial volume) one allreduce of 10 values and one of 1.
 * advance reduces a stop flag after every step but the last (GR_REDUCE_MAX),
 * so a stop asked by one piece's progress callback stops every piece after
 * the same step. An error on one piece returns on that piece only: the
 * others wait in their next collective call, which the caller's callbacks
 * must end.
 * @{
 */

/** Sides of a piece, for the halo calls (as every core numbers them; x sides never have one). */
typedef enum gr_water_surface_side {
  GR_WATER_SURFACE_SOUTH = 2, /**< toward j0 - 1 */
  GR_WATER_SURFACE_NORTH = 3  /**< toward j0 + ny */
} gr_water_surface_side;

/**
 * The ring a piece needs for these parameters on rows dy apart: 1 +
 * min(ceil(4 DropRadius / dy), 12) rows (0 for NULL or dy not above 0).
 */
GR_API int gr_water_surface_ghost(const gr_water_surface_params *p, double dy);

/**
 * The global reduction over the pieces (see gr_allreduce_fn); NULL (the
 * default) for a simulation that is the whole domain. A piece with a
 * neighbour steps only with one and a halo exchange set.
 */
GR_API void gr_water_surface_set_allreduce(gr_water_surface *s, gr_allreduce_fn fn, void *user);

/** The halo exchange (see gr_halo_exchange_fn), called once per step; NULL removes it. */
GR_API void gr_water_surface_set_halo_exchange(gr_water_surface *s, gr_halo_exchange_fn fn,
                                               void *user);

/** Bytes of the halo strip on `side` (south 2, north 3): one row of h, nx floats; 0 for none. */
GR_API gr_status gr_water_surface_halo_size(const gr_water_surface *s, int side, size_t *bytes);

/** Copies the own row next to `side` out (for the neighbour on that side); waits. */
GR_API gr_status gr_water_surface_halo_get(gr_water_surface *s, int side, void *host, size_t bytes);

/** Copies the neighbour's row into the ring's first row on `side`; waits. */
GR_API gr_status gr_water_surface_halo_set(gr_water_surface *s, int side, const void *host,
                                           size_t bytes);
/** @} */

/**
 * The latest error of a call on this simulation ("" when none); for s ==
 * NULL, "" as well. Never NULL.
 */
GR_API const char *gr_water_surface_last_error(const gr_water_surface *s);

/** Frees the simulation; NULL is fine. */
GR_API void gr_water_surface_destroy(gr_water_surface *s);

#ifdef __cplusplus
}
#endif

#endif
