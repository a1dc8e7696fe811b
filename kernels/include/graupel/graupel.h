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
  GR_FIELD_COUNT
} gr_field;

/** Array name of a field ("elevation", "snow_depth", ...); NULL if unknown. */
GR_API const char *gr_field_name(gr_field f);
/** Field for an array name; -1 if the name is not one of gr_field_name's. */
GR_API int gr_field_from_name(const char *name);
/** Number of components (3 for velocity, 1 otherwise). */
GR_API int gr_field_components(gr_field f);

#ifdef __cplusplus
}
#endif

#endif
