/**
 * @file graupel.h
 * @brief Graupel core: version, export macro, status codes, grids and field names.
 *
 * Every public header of the core includes this one. The core is C11 and knows
 * nothing of VTK; VTK filters, graupel-bench and the C tests all drive it the
 * same way.
 */
#ifndef GRAUPEL_GRAUPEL_H
#define GRAUPEL_GRAUPEL_H

#include <stddef.h>

#define GRAUPEL_VERSION_MAJOR 0
#define GRAUPEL_VERSION_MINOR 1
#define GRAUPEL_VERSION_PATCH 0
#define GRAUPEL_VERSION_NUMBER                                                                     \
  (GRAUPEL_VERSION_MAJOR * 10000 + GRAUPEL_VERSION_MINOR * 100 + GRAUPEL_VERSION_PATCH)

#if defined(_WIN32)
#define GR_API __declspec(dllexport)
#elif defined(__GNUC__)
#define GR_API __attribute__((visibility("default")))
#else
#define GR_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Result of every fallible call. 0 is success; errors are negative and their
 * values are pinned (they never change meaning between versions).
 */
typedef enum gr_status {
  GR_OK = 0,
  GR_ERR_INVALID_ARGUMENT = -1, /**< a parameter or field is out of its domain */
  GR_ERR_NO_PLATFORM = -2,      /**< no OpenCL platform is installed */
  GR_ERR_NO_DEVICE = -3,        /**< no device matches the request */
  GR_ERR_OPENCL = -4,           /**< an OpenCL call failed */
  GR_ERR_BUILD = -5,            /**< a kernel program failed to build */
  GR_ERR_OUT_OF_MEMORY = -6,    /**< host or device allocation failed */
  GR_ERR_TOO_LARGE = -7,        /**< a grid or buffer exceeds a device limit */
  GR_ERR_IO = -8,               /**< a file could not be read or written */
  GR_ERR_FORMAT = -9,           /**< a file is not what it claims to be */
  GR_ERR_ABORTED = -10,         /**< the caller asked to stop */
} gr_status;

/** Stable name of a status code, e.g. "GR_ERR_BUILD". Never NULL. */
GR_API const char *gr_status_string(gr_status st);

/** Library version as "MAJOR.MINOR.PATCH". */
GR_API const char *gr_version_string(void);

/**
 * A regular 2-D grid of nx by ny points, x east, y north, z up: a whole
 * domain, or one piece of it (an MPI rank's sub-extent).
 * Point (i, j) lies at (x0 + (i0 + i)*dx, y0 + (j0 + j)*dy); fields are
 * row-major with i fastest: value(i, j) = field[j*nx + i]. For a piece,
 * (x0, y0) stays the whole domain's origin and (i0, j0) is the index of the
 * piece's first point, so that pieces compute bit for bit what the whole
 * grid computes at the same points. Zero-initialise what you don't set.
 */
typedef struct gr_grid {
  int nx, ny;
  double dx, dy; /**< spacing, m, > 0 */
  double x0, y0; /**< origin of the whole domain, m */
  int i0, j0;    /**< global index of this grid's first point (0 for a whole grid) */
  /**
   * The piece contract (all 0 for a whole grid). global_nx, global_ny: the
   * whole domain's points (0 means nx, ny: this grid is the whole domain);
   * the piece's points are i0 .. i0+nx-1 by j0 .. j0+ny-1 of it, and only
   * the domain's own edges are boundaries. ghost: the width of the ring of
   * points around the piece that a core keeps as copies of its neighbours'
   * points (its halo), filled by the core's halo calls; the core's own
   * header says how wide a ring it needs.
   */
  int global_nx, global_ny;
  int ghost;
} gr_grid;

/** Checks dimensions and spacing; a sentence goes to msg when not valid. */
GR_API gr_status gr_grid_validate(const gr_grid *g, char *msg, size_t msg_len);

/**
 * The fields every core speaks of. The names (gr_field_name) are the same
 * in VTK arrays and EXR channels.
 */
typedef enum gr_field {
  GR_FIELD_ELEVATION = 0,
  GR_FIELD_SNOW_DEPTH,
  GR_FIELD_SNOW_DENSITY,
  GR_FIELD_SNOW_SURFACE,
  GR_FIELD_OVERLAP,
  GR_FIELD_EXPOSURE,
  GR_FIELD_WATER_DEPTH,
  GR_FIELD_WATER_SURFACE,
  GR_FIELD_VELOCITY,
  GR_FIELD_DISCHARGE,
  GR_FIELD_INFILTRATED,
  GR_FIELD_PERMEABILITY,
  GR_FIELD_RAIN_RATE,
  GR_FIELD_CONTACT, /**< 1 where an object touches the snow, else 0 */
  GR_FIELD_COUNT
} gr_field;

/** Array name of a field ("elevation", "snow_depth", ...); NULL if unknown. */
GR_API const char *gr_field_name(gr_field f);
/** Field for an array name; -1 if the name is not one of gr_field_name's. */
GR_API int gr_field_from_name(const char *name);
/** Number of components (3 for velocity, 1 otherwise; 0 if unknown). */
GR_API int gr_field_components(gr_field f);
/** SI unit of a field ("m", "kg/m^3", "m/s", "m^2/s", "1"); NULL if unknown. */
GR_API const char *gr_field_unit(gr_field f);

/**
 * Progress of a long core call (an advance over many steps): called between
 * steps with the simulated time reached, in seconds, at least every few
 * tenths of a second of wall time. Return 0 to go on; anything else stops
 * the call at a step boundary with GR_ERR_ABORTED and a valid state.
 */
typedef int (*gr_progress_fn)(void *user, double time);

/** Operations of a global reduction over the pieces of a split domain. */
typedef enum gr_reduce_op { GR_REDUCE_SUM = 0, GR_REDUCE_MAX = 1, GR_REDUCE_MIN = 2 } gr_reduce_op;

/**
 * A global reduction, in place: values[0..n-1] become the reduction over
 * every piece of the domain (an MPI_Allreduce; in one process, the identity).
 * Must combine in a fixed order so reruns match bit for bit.
 */
typedef gr_status (*gr_allreduce_fn)(void *user, double *values, int n, gr_reduce_op op);

/**
 * Refreshes the ring (halo) of one piece of a split domain from its
 * neighbours: the core's halo_get on each neighbour, its halo_set on this
 * piece (across processes, a send and a receive per side). A grid core calls
 * it after every step it takes on a piece with a ring, so a piece can take
 * many steps per call; every piece calls it equally often and at the same
 * steps, so it may be collective. Anything but GR_OK stops the core's call
 * with that status.
 */
typedef gr_status (*gr_halo_exchange_fn)(void *user);

/**
 * One row of a core's parameter table: the single source of a parameter's
 * range that the core's validator, the filter's clamp, the XML domain and the
 * docs pages all follow (a ctest checks that they agree). Values are in the
 * user's unit; the core's value is the user's times to_core.
 */
typedef struct gr_param_bound {
  const char *property; /**< the filter property, e.g. "RainRate" */
  const char *unit;     /**< the user's unit, e.g. "mm/h"; "" when none */
  double min, max;      /**< the range, in the user's unit */
  double default_value; /**< in the user's unit */
  double to_core;       /**< core value = user value * to_core */
  int min_open;         /**< 1: min itself is excluded, (min, max] */
  int integer;          /**< 1 for whole-number properties */
} gr_param_bound;

/** The row of table (count rows) for a property name; NULL when there is none. */
GR_API const gr_param_bound *gr_param_find(const gr_param_bound *table, int count,
                                           const char *property);

/**
 * 1 when a core value lies in the row's range: from min * to_core (excluded
 * when min_open) to max * to_core, a whole number for integer rows; 0 for NaN.
 * The products are the ones a filter sends for the user's own bounds, so a
 * user value at a bound is always accepted.
 */
GR_API int gr_param_accepts(const gr_param_bound *b, double core_value);

/**
 * A user value moved into [min, max] (a filter's clamp). An open min is kept
 * as the excluded end, which gr_param_accepts then refuses with a sentence;
 * NaN stays NaN for the same reason.
 */
GR_API double gr_param_clamp(const gr_param_bound *b, double user_value);

/**
 * The sentence for a core value that row b refuses, in the user's unit:
 * "<what>: RainRate must lie between 0 and 3600 mm/h (got 7200 mm/h)." (or
 * "must be above .. and at most ..", or "must be a whole number from .. to
 * .."), written to msg.
 */
GR_API void gr_param_explain(const gr_param_bound *b, double core_value, const char *what,
                             char *msg, size_t msg_len);

/**
 * A closed triangle mesh (an object: a wheel, a boot, a rock), as views of
 * the caller's arrays. Vertices in the object's own frame, metres;
 * triangles wound counter-clockwise seen from outside; transform maps the
 * object's frame to the world (column-major 4x4, GLM's layout, z up).
 */
typedef struct gr_mesh {
  const float *vertices; /**< 3 per vertex */
  int nvertices;
  const int *triangles; /**< 3 vertex indices per triangle */
  int ntriangles;
  double transform[16];
} gr_mesh;

/**
 * Checks a mesh: at least one triangle, indices in range, finite vertices,
 * no degenerate (zero-area) triangle, a finite invertible transform, and,
 * when closed is 1, every edge shared by exactly two triangles of opposite
 * direction (a watertight, consistently wound surface). A sentence naming
 * the first fault goes to msg.
 */
GR_API gr_status gr_mesh_validate(const gr_mesh *m, int closed, char *msg, size_t msg_len);

/** A named per-point array of a gr_points. */
typedef struct gr_points_array {
  const char *name;    /**< e.g. "diameter", "velocity" */
  int components;      /**< 1 to 9 */
  const float *values; /**< components per point */
} gr_points_array;

/**
 * Points (rain drops, snowflakes) as views of the caller's arrays:
 * positions in the world, metres, and named per-point arrays.
 */
typedef struct gr_points {
  const float *positions; /**< 3 per point */
  long long npoints;
  const gr_points_array *arrays;
  int narrays;
} gr_points;

/** Checks points: finite positions, arrays named, distinct, 1..9 components, values finite. */
GR_API gr_status gr_points_validate(const gr_points *p, char *msg, size_t msg_len);

#ifdef __cplusplus
}
#endif

#endif
