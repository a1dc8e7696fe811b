/**
 * @file snow_accumulation.h
 * @brief Snowfall from a direction onto terrain and objects (seed 002: the
 * occlusion-based accumulation of Reynolds, Laycock & Day as a CTU thesis
 * implements it), as a deterministic, volume-keeping model on
 * the device.
 *
 * State: snow depth S per grid point over a ground B (the snow surface is
 * H = B + S), and snow depth per face (triangle) of every object (it lives
 * in the object's own frame, so it moves with the object; the mesh points
 * show it, see Objects below).
 *
 * One step of dt seconds (gr_snow_accumulation_step), with d the unit snow
 * direction (SnowDirection, turned by up to Flutter at random each step,
 * seeded by Seed and the step's number):
 *  1. exposure view: an orthographic depth view along d of the snow surface
 *     H (two triangles per grid cell) and of every object triangle at its
 *     pose, at ExposureResolution texels across. Rays along d are named by
 *     where they cross z = 0 (an oblique projection, which orders and
 *     separates points exactly as an orthographic view along d does); a
 *     texel keeps the highest crossing of its centre's ray, by an integer
 *     atomic_max on the float's ordered bits: order-independent, so reruns
 *     are bit-identical (no float atomics).
 *  2. exposure: a grid point, or an object face's centroid (or a texture
 *     sample) moved half a texel along the face's normal, is exposed (1) when nothing in the view
 * lies above it on its ray by more than a depth bias (a quarter texel plus the surface's slope in
 * the view times 0.75 texel: a surface does not shadow itself), else 0. Binary, like the thesis'
 * occlusion render.
 *  3. growth: g = SnowfallRate x exposure x max(0, n . -d) x (1 + A N) x dt,
 *     n the ground's normal (grid) or the face's own normal (objects: each
 *     triangle faces the snow as it is, not as its points' averaged
 *     normals would), N a seeded value noise in [-1, 1] of the position
 *     (world xy on the terrain, the face's centroid in the object's own
 *     frame on objects) with a lattice of
 *     NoiseScale metres, A = NoiseAmplitude. SnowfallRate is the fall per
 *     area across the snow direction: what an exposed surface facing the
 *     snow receives (a horizontal one, for vertical snow).
 *  4. on the grid only: the growth is blurred (a separable binomial kernel
 *     of radius r = BlurRadius points, weights C(2r + 4, r + 2 + k); r = 4
 *     is the thesis' 9-tap kernel; near the grid's edge
 *     the weights are renormalised) and, with Dilation, replaced by its
 *     maximum over the 3 x 3 neighbourhood (the thesis' dilation).
 *  5. increment and stability, integrated together over the step: with
 *     the capacity c = MaxDepth x max(0, n . up) and k = -ln(1 - f),
 *     f = StabilityFactor (so that an excess alone keeps (1 - f)^t after t
 *     seconds: f is the fraction of the excess shed per second), the depth
 *     follows dS/dt = r - k max(0, S - c) through the step, the growth g
 *     arriving at the constant rate r = g / dt. Its exact solution: from
 *     an excess x0 = S - c >= 0, x(t) = r / k + (x0 - r / k) e^-kt, so
 *       x1 = x0 e^-k dt + g phi(k dt),  phi(z) = (1 - e^-z) / z;
 *     from below capacity, S grows freely until it reaches c at
 *     t* = (c - S) / r, and relaxes the remaining tau = dt - t* =
 *     dt E / g (E = S + g - c, the excess had nothing been shed):
 *       x1 = E phi(k dt E / g)   (S + g when E <= 0: never reaches c).
 *     The snow shed is what fell and is no longer stored, S + g - (c + x1),
 *     taken from the depth's double-float pair as it is added to the shed
 *     pair. A constant rate then gives the same snow in 10 steps as in 100
 *     (and as the continuous solution) to float rounding, whatever f; f = 1
 *     (k infinite) keeps S at c, f = 0 never sheds. Shed snow leaves the
 *     simulation and is counted (shed_volume). (Before, the step added g
 *     and then shed 1 - (1 - f)^dt of the excess: a step of dt shed the
 *     whole step's growth as if it had all come at its start, and
 *     StabilityFactor 0.001/s stored 7.6 % less in 10 steps than in 100.)
 *
 * Deviations from the thesis, on purpose: its
 * stability branch sets every point below capacity to 0 (flat surfaces
 * could never hold snow): here snow below capacity stays. Its growth is a
 * noise value per frame: here it is a rate times dt, and the noise is a
 * fixed pattern in space (not re-drawn per step), so the same simulated
 * time gives the same snow whether it is taken in 10 steps or 100 (to
 * float rounding for any f while the exposure does not change, step 5).
 * Its "5x5" blur is the 9-tap kernel above. Its per-object UV textures are
 * here per-face depths (no UV unwrap needed) and, for objects given
 * texture coordinates, an accumulation texture whose texels are samples
 * like the faces (gr_snow_accumulation_set_object_texture): both from the
 * faces, as the thesis' texels lie on one face each.
 *
 * Book-keeping: every grid point and object face keeps its depth, the snow
 * that fell on it and the snow it shed as double-float pairs, so
 *   stored = initial + snowfall - shed - dropped
 * holds to about 1e-12 over any number of steps (dropped: the snow of
 * objects that set_objects removed). Volumes: grid points count dx dy each;
 * a face its area (in the object's own frame: poses are rigid), so an
 * exposed object below capacity under vertical snow holds rate x t times
 * the area its snow-facing faces cover seen from above, as the ground does.
 *
 * Fields (gr_field): set ELEVATION (required, m; within +-1e6 m, finite)
 * and optionally SNOW_DEPTH (m, 0 to 1e4, the initial snow). Read
 * SNOW_DEPTH, SNOW_SURFACE, SNOW_DENSITY (SnowDensity everywhere, for Snow
 * Deformation), EXPOSURE (0 or 1, the last step's) and ELEVATION.
 *
 * Objects: triangle meshes (gr_mesh; open surfaces such as a roof plane
 * are fine, triangles wound counter-clockwise seen from the side that
 * receives snow), at the pose of their transform; set them before each
 * step that moves them. The snow lives on the faces (steps 2, 3 and 5 per
 * triangle, with its own normal and capacity). A mesh point shows the mean
 * of its faces' snow weighted by the area each turns to the sky, A max(0,
 * n . up) (the plain area where all its faces face sideways or down): so a
 * cone's base ring and apex carry what its sloped sides do (not the flat
 * ground's snow at the apex and none on the ring, as the averaged point
 * normals gave), a roof's ridge what its planes do, the top corners of a
 * box what its top does, and a flat-shaded mesh (its own points per face)
 * the same as a smooth one.
 *
 * Pieces of a split domain: see "Pieces of a split domain" below; a piece
 * computes bit for bit what the whole grid computes at its points, its
 * objects' snow and the ledger included.
 */
#ifndef GRAUPEL_SNOW_ACCUMULATION_H
#define GRAUPEL_SNOW_ACCUMULATION_H

#include "graupel/memory.h"
#include "graupel/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Most objects one simulation takes. */
#define GR_SNOW_ACCUMULATION_MAX_OBJECTS 256

/** The largest angle of SnowDirection from straight down, degrees. */
#define GR_SNOW_ACCUMULATION_MAX_TILT 75.0

/**
 * The parameters, in the core's units (SI; Flutter in radians). Ranges and
 * defaults are the rows of gr_snow_accumulation_param_bounds, written
 * nowhere else, but for direction (a vector: finite, not zero, at most
 * GR_SNOW_ACCUMULATION_MAX_TILT degrees from straight down; default 0 0 -1).
 */
typedef struct gr_snow_accumulation_params {
  double direction[3];     /**< SnowDirection, any length (normalised) */
  double flutter;          /**< rad, the largest random turn per step (row Flutter) */
  double snowfall_rate;    /**< m/s (row SnowfallRate, cm/h) */
  double noise_amplitude;  /**< A (row NoiseAmplitude) */
  double noise_scale;      /**< m, the noise lattice (row NoiseScale) */
  int seed;                /**< row Seed */
  int exposure_resolution; /**< texels across the view (row ExposureResolution) */
  int blur_radius;         /**< grid points (row BlurRadius) */
  int dilation;            /**< 0 or 1 (row Dilation) */
  double max_depth;        /**< m, the capacity of a horizontal surface (row MaxDepth) */
  double stability_factor; /**< f, per second (row StabilityFactor) */
  double snow_density;     /**< kg/m^3 of the fresh snow (row SnowDensity) */
  /** Texels across an accumulation texture, 0: none (row AccumulationTextureSize): the
   *  size callers pass to set_object_texture; validated with the rest. */
  int texture_size;
} gr_snow_accumulation_params;

/** The table's defaults, direction 0 0 -1. */
GR_API void gr_snow_accumulation_params_init(gr_snow_accumulation_params *p);

/**
 * Checks every parameter against its row of the table and the direction;
 * the sentence in msg names the property, its value and the fix.
 */
GR_API gr_status gr_snow_accumulation_params_validate(const gr_snow_accumulation_params *p,
                                                      char *msg, size_t msg_len);

/**
 * The parameter table (Flutter deg, SnowfallRate cm/h, NoiseAmplitude,
 * NoiseScale m, Seed, ExposureResolution, BlurRadius, Dilation, MaxDepth m,
 * StabilityFactor 1/s, SnowDensity kg/m^3, AccumulationTextureSize);
 * *count gets the number of rows.
 */
GR_API const gr_param_bound *gr_snow_accumulation_param_bounds(int *count);

/**
 * The check set_field applies, on the host: f must be ELEVATION (finite,
 * within +-1e6 m) or SNOW_DEPTH (finite, 0 to 1e4 m); n values in rows of
 * nx (0: one row). The sentence names the field, the point (i, j) and the
 * value. values may be NULL only when n is 0.
 */
GR_API gr_status gr_snow_accumulation_field_validate(gr_field f, const float *values, size_t n,
                                                     size_t nx, char *msg, size_t msg_len);

/** Book-keeping; volumes m^3, cumulative since create or reset. */
typedef struct gr_snow_accumulation_ledger {
  double time;                  /**< simulated time, s */
  long long steps;              /**< steps taken */
  double initial_volume;        /**< snow set with SNOW_DEPTH and set_object_snow */
  double snowfall_volume;       /**< all that fell (the growth after blur and dilation) */
  double stored_volume;         /**< terrain + objects now */
  double stored_volume_terrain; /**< sum S dx dy */
  double stored_volume_objects; /**< sum over the objects' faces of depth x area */
  double shed_volume;           /**< removed by the stability cap */
  double dropped_volume;        /**< on objects that set_objects removed */
  /** initial + snowfall - shed - dropped - stored: rounding only */
  double balance_error;
} gr_snow_accumulation_ledger;

typedef struct gr_snow_accumulation gr_snow_accumulation;

/**
 * What a simulation on grid with p's ExposureResolution needs (memory.h),
 * its ring included and its objects not (they add their faces' arrays):
 * 48 bytes a point on the device (ground, initial depth, growth, scratch,
 * noise and the seven snow arrays), the exposure view's int a texel, and 8
 * bytes a row on the host. GR_ERR_INVALID_ARGUMENT without
 * grid, p or out.
 */
GR_API gr_status gr_snow_accumulation_memory(const gr_grid *grid,
                                             const gr_snow_accumulation_params *p,
                                             gr_memory_need *out);

/**
 * A simulation on a whole grid or a piece of one (see "Pieces of a split
 * domain" below): validates grid and parameters, checks
 * that the exposure view fits the device (no wider than its largest 2-D
 * image where it has images, and within its largest buffer:
 * GR_ERR_TOO_LARGE with a sentence otherwise) and that the grid fits in
 * memory (gr_snow_accumulation_memory; GR_ERR_TOO_LARGE before anything is
 * allocated), builds the kernels, and starts with flat ground at 0, no
 * snow and no objects.
 */
GR_API gr_status gr_snow_accumulation_create(gr_context *ctx, const gr_grid *grid,
                                             const gr_snow_accumulation_params *p,
                                             gr_snow_accumulation **out);

/** New parameters from the next step on (validated like create; the state is kept). */
GR_API gr_status gr_snow_accumulation_set_params(gr_snow_accumulation *s,
                                                 const gr_snow_accumulation_params *p);

/**
 * Uploads ELEVATION or SNOW_DEPTH (nx*ny floats, a piece's local array with
 * its rings; see field_validate); a
 * refused field leaves the state as it was. SNOW_DEPTH replaces the snow
 * on the grid and becomes what reset returns to; the ledger's initial
 * volume moves by the change.
 */
GR_API gr_status gr_snow_accumulation_set_field(gr_snow_accumulation *s, gr_field f,
                                                const float *host);

/**
 * The objects for the next steps (copied; 0 to
 * GR_SNOW_ACCUMULATION_MAX_OBJECTS), each passing gr_mesh_validate(mesh, 0)
 * (open surfaces allowed), at the pose of its transform. Object o keeps its
 * snow when the previous call had an object o with as many vertices and
 * triangles (the same mesh at a new pose: its snow moves with it); otherwise its snow
 * starts at 0 and the snow of an object that is gone counts as dropped. A
 * refusal names the object and keeps the objects set before.
 */
GR_API gr_status gr_snow_accumulation_set_objects(gr_snow_accumulation *s, const gr_mesh *meshes,
                                                  int n);

/**
 * Object o's snow per mesh point (n must be its vertex count), from its
 * faces (see Objects above): SNOW_DEPTH (m, along the faces' normals) or
 * EXPOSURE (0 to 1, the last step's: the sky-weighted share of the point's
 * faces that were exposed).
 */
GR_API gr_status gr_snow_accumulation_get_object_field(gr_snow_accumulation *s, int o, gr_field f,
                                                       float *host, int n);

/**
 * Object o's snow cap as offsets: 3 floats per mesh point, the point's
 * SNOW_DEPTH (m) along the unit mean of its faces' world normals, weighted
 * as the depth is (a cone's base ring moves up and out with its sides).
 */
GR_API gr_status gr_snow_accumulation_get_object_offsets(gr_snow_accumulation *s, int o, float *xyz,
                                                         int n);

/**
 * Sets object o's snow per mesh point (m, 0 to 1e4): each face gets the
 * mean of its three points' depths; the initial volume moves by the change.
 */
GR_API gr_status gr_snow_accumulation_set_object_snow(gr_snow_accumulation *s, int o,
                                                      const float *depth, int n);

/**
 * Gives object o an accumulation texture of size x size texels (the thesis'
 * per-object texture; size 0 removes it; the row
 * AccumulationTextureSize bounds it), uv holding 2 texture coordinates per
 * mesh point. Every texel whose centre falls in the UV triangle of one of
 * the object's triangles becomes a sample on that triangle (barycentric;
 * the first triangle in mesh order wins where UV triangles overlap) with
 * the triangle's own normal, and goes through the same exposure, growth,
 * noise (the object's frame) and stability as the faces each step,
 * moving with the object. Texels on no triangle stay 0. The samples are a
 * finer picture of the same snow, not more of it: they stay out of the
 * ledger (the faces carry the object's volume), set_object_snow and
 * reset leave them at / bring them to 0, checkpoints include them. The
 * same size and coordinates again keep the texture's snow; set_objects
 * keeps a kept object's texture (its samples move with it) and drops the
 * texture of an object it replaces.
 */
GR_API gr_status gr_snow_accumulation_set_object_texture(gr_snow_accumulation *s, int o,
                                                         const float *uv, int size);

/**
 * Object o's accumulation texture: size x size floats (size its texture's
 * size), snow depth in m, row-major with u along a row (texel (i, j) at
 * j x size + i, centre ((i + 0.5) / size, (j + 0.5) / size)).
 */
GR_API gr_status gr_snow_accumulation_get_object_texture(gr_snow_accumulation *s, int o,
                                                         float *texels, int size);

/**
 * One step of dt seconds (finite, 1e-6 to 86400); enqueues and does not
 * wait. A piece with neighbours waits for its exchange and reductions, and
 * steps only with an allreduce and a halo exchange set (collective).
 */
GR_API gr_status gr_snow_accumulation_step(gr_snow_accumulation *s, double dt);

/**
 * Reads a grid field back (waits): SNOW_DEPTH, SNOW_SURFACE, SNOW_DENSITY,
 * EXPOSURE, ELEVATION; nx*ny floats (a piece: its own rows).
 */
GR_API gr_status gr_snow_accumulation_get_field(gr_snow_accumulation *s, gr_field f, float *host);

/**
 * The ledger now (waits; reduces on the device). A piece with an allreduce
 * gives the whole domain's ledger (a collective call); one without, its own
 * rows' and the objects'.
 */
GR_API gr_status gr_snow_accumulation_ledger_get(gr_snow_accumulation *s,
                                                 gr_snow_accumulation_ledger *out);

/**
 * Progress (gr_progress_fn): called after each step with the time reached;
 * a non-zero return makes the next step refuse with GR_ERR_ABORTED until
 * set_progress or reset is called. NULL removes it.
 */
GR_API void gr_snow_accumulation_set_progress(gr_snow_accumulation *s, gr_progress_fn fn,
                                              void *user);

/**
 * Checkpoints: the grid's and the objects' snow, fallen and shed snow,
 * exposures, time, steps and ledger as bytes. Loading into a simulation of
 * the same grid with the same objects set (as many, with as many mesh
 * points and triangles) makes every later step bit-identical. Elevation, parameters and
 * object poses are not part of it. A piece's state holds its local arrays,
 * rings included, and its j0; it loads only into the same piece.
 */
GR_API gr_status gr_snow_accumulation_state_size(const gr_snow_accumulation *s, size_t *bytes);
GR_API gr_status gr_snow_accumulation_state_save(gr_snow_accumulation *s, void *host, size_t bytes);
GR_API gr_status gr_snow_accumulation_state_load(gr_snow_accumulation *s, const void *host,
                                                 size_t bytes);

/**
 * Back to the initial snow (the last SNOW_DEPTH set, none on objects),
 * ledger zeroed; elevation and objects kept.
 */
GR_API gr_status gr_snow_accumulation_reset(gr_snow_accumulation *s);

/**
 * @name Pieces of a split domain
 *
 * A simulation may hold one strip of a domain split along y (the gr_grid
 * piece fields: j0, global_ny, ghost; a piece spans whole rows: i0 = 0 and
 * nx = global_nx or 0, because the ledger sums whole rows, see below). On
 * each side where the strip has a neighbour (south: j0 > 0, north:
 * j0 + ny < global_ny) it keeps a ring of grid.ghost rows, copies of the
 * neighbour's rows; grid.ghost must be at least
 * gr_snow_accumulation_ghost(params) and the strip at least grid.ghost rows
 * high. The local arrays are the strip and its rings: nx x (ny + rings)
 * floats for set_field and checkpoints; get_field gives the own nx x ny.
 *
 * What is local and what is not. The growth of an own point reads the
 * snow surface one row away (its normal), the blur reads BlurRadius rows of
 * growth on each side and the dilation one more: so the ring is BlurRadius +
 * 2 rows, refreshed once per step (the snow depth, after the increment,
 * through the caller's exchange), and every own point then computes the
 * whole grid's bits. The exposure view is not local: a ray along a tilted
 * snow direction crosses terrain any distance away, so no ring bounds it
 * (the reach is the relief times the tilt's tangent, up to 3.7 times the
 * relief). A ring holding the whole terrain would make each piece hold the
 * whole grid, and a terrain-only march would change the model (snow hides
 * ground too). Instead each piece rasterizes the surface cells of its
 * local arrays into a view of the whole domain's extent (the same texels on
 * every piece: the view's box comes from the elevation's and the snow's
 * range reduced with GR_REDUCE_MAX), and the views are combined with
 * GR_REDUCE_MAX, texel by texel: the view keeps the highest crossing of
 * each texel, so the maximum over the pieces' views is the whole grid's
 * view, bit for bit, whatever the split. Only the texels that can differ
 * and are read are combined. A piece's cells, and its grid points' rays,
 * fall in a band of view rows that its rows and the view box's heights
 * bound, and it draws the objects into that band only (the first piece
 * from the view's first row on, the last up to its last row: every row has
 * the objects in some piece's view); elsewhere its view holds objects
 * alone. So the pieces agree (a GR_REDUCE_MAX of 2 values per view row:
 * the highest and lowest piece whose band covers it) on the rows two or
 * more bands cover, a band about as wide as the ring plus the relief times
 * the snow's slope along y, and combine those rows alone (in calls of at
 * most GR_SNOW_ACCUMULATION_REDUCE_CHUNK values); every other row a piece
 * reads is already the maximum. The objects' points read rows anywhere:
 * their exposure (a point is exposed when every piece's view leaves it
 * exposed) is combined per face and sample, GR_REDUCE_MAX of minus
 * the exposure, or, where that is more values, the view rows under the
 * objects are combined too; the rows and the points go in one allreduce
 * (one read-back and one write) a step. At 1024^2 with ExposureResolution 1024 and two
 * pieces, graupel-bench's scene reduces about 0.37 MB a step per piece
 * instead of the whole view's 8 MB. This happens in the steps where the
 * terrain is drawn at all: where the surface rises slower than the snow
 * falls (snow straight down always) the view holds the objects alone,
 * which every piece draws the same, and nothing is reduced.
 *
 * Objects: every piece keeps every object and its snow (faces and
 * textures are small beside the grid), takes the same steps on them from
 * the same view, and so holds the same bits. The one grid value an object
 * reads is the snow surface under a face's centroid (whether it is buried, in
 * the steps without terrain in the view): the piece that owns the grid
 * cell under the point gives it, the others -inf, reduced with
 * GR_REDUCE_MAX (a value per face). An object across the cut thus
 * sees both pieces' snow. The objects' volumes are the same on every piece
 * and enter the ledger once.
 *
 * The ledger: the grid's stored, fallen and shed snow and its initial
 * snow are summed per row (in a fixed order along the row), and the rows
 * are added in the order of the domain's rows: each piece places its rows'
 * sums in an array of the domain's rows, -inf elsewhere, GR_REDUCE_MAX
 * makes it every piece's (one value and -infs: exact in any order), and
 * the host adds the rows in order. So the ledger is the same bits for 1, 2
 * or any number of pieces, and the same as the whole grid's. Every
 * reduction this core asks for is a GR_REDUCE_MAX, so its bits never depend
 * on how the allreduce orders a sum.
 *
 * Stepping on pieces is collective: every piece sets the same parameters
 * and objects and calls step with the same dt, and each step makes the
 * same sequence of allreduce and exchange calls on every piece; ledger_get
 * is collective too. A stop asked by one piece's progress callback is
 * reduced after every step (GR_REDUCE_MAX), so every piece stops after the
 * same step. An error on one piece returns on that piece only: the others
 * wait in their next collective call, which the caller's callbacks must end.
 * @{
 */

/** Values per allreduce call, at most (longer reductions are cut into calls of this many). */
#define GR_SNOW_ACCUMULATION_REDUCE_CHUNK 65536

/** Sides of a piece, for the halo calls (as every core numbers them; x sides never have one). */
typedef enum gr_snow_accumulation_side {
  GR_SNOW_ACCUMULATION_SOUTH = 2, /**< toward j0 - 1 */
  GR_SNOW_ACCUMULATION_NORTH = 3  /**< toward j0 + ny */
} gr_snow_accumulation_side;

/** The ring a piece needs for these parameters, rows: BlurRadius + 2 (0 for NULL). */
GR_API int gr_snow_accumulation_ghost(const gr_snow_accumulation_params *p);

/**
 * The global reduction over the pieces (see gr_allreduce_fn); NULL (the
 * default) for a simulation that is the whole domain. A piece with a
 * neighbour steps only with one and a halo exchange set.
 */
GR_API void gr_snow_accumulation_set_allreduce(gr_snow_accumulation *s, gr_allreduce_fn fn,
                                               void *user);

/** The halo exchange (see gr_halo_exchange_fn), called once per step; NULL removes it. */
GR_API void gr_snow_accumulation_set_halo_exchange(gr_snow_accumulation *s, gr_halo_exchange_fn fn,
                                                   void *user);

/** Bytes of the halo strip on `side` (south 2, north 3): ghost rows of snow depth; 0 for none. */
GR_API gr_status gr_snow_accumulation_halo_size(const gr_snow_accumulation *s, int side,
                                                size_t *bytes);

/** Copies the own rows next to `side` out (for the neighbour on that side); waits. */
GR_API gr_status gr_snow_accumulation_halo_get(gr_snow_accumulation *s, int side, void *host,
                                               size_t bytes);

/** Copies the neighbour's rows into the ring on `side`; waits. */
GR_API gr_status gr_snow_accumulation_halo_set(gr_snow_accumulation *s, int side, const void *host,
                                               size_t bytes);
/** @} */

/** The latest error of a call on this simulation ("" when none). Never NULL. */
GR_API const char *gr_snow_accumulation_last_error(const gr_snow_accumulation *s);

/**
 * Per-stage wall times for graupel-bench, cumulative since timing was
 * switched on (ms); while on, each step waits after every stage.
 */
typedef struct gr_snow_accumulation_timing {
  long long steps;    /**< steps timed */
  double view_ms;     /**< clearing the view and rasterising terrain and objects */
  double exposure_ms; /**< exposure and growth of the grid points */
  double blur_ms;     /**< blur and dilation */
  double apply_ms;    /**< increment and stability on the grid */
  double objects_ms;  /**< exposure, growth and stability of the faces and samples */
  double host_ms;     /**< the view's extent and the direction, on the host */
  double combine_ms;  /**< a piece's share with the others: its view's shared rows, the
                           objects' values and the halo exchange (0 on a whole grid) */
} gr_snow_accumulation_timing;

/** Switches per-stage timing on (non-zero; the sums restart) or off. */
GR_API void gr_snow_accumulation_set_timing(gr_snow_accumulation *s, int on);

/** The sums since timing was switched on. */
GR_API gr_status gr_snow_accumulation_timing_get(const gr_snow_accumulation *s,
                                                 gr_snow_accumulation_timing *out);

/**
 * The largest ExposureResolution this simulation's device takes (its 2-D
 * image width where it has images, and the view within its largest
 * buffer), for error messages and the filter's domain.
 */
GR_API gr_status gr_snow_accumulation_max_resolution(gr_context *ctx, int *out);

/** Frees the simulation; NULL is fine. */
GR_API void gr_snow_accumulation_destroy(gr_snow_accumulation *s);

#ifdef __cplusplus
}
#endif

#endif
