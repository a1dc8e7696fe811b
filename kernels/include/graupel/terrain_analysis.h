/**
 * @file terrain_analysis.h
 * @brief Terrain analysis and cast shadows (seed 001): normals, slope,
 * aspect, hillshade, slope-based snow cover and cover classes, and a
 * ray-marched shadow mask, computed by OpenCL kernels from one height field.
 *
 * Input: a height field h (m) on a whole gr_grid (x east, y north, z up):
 * `elevation`, or any other surface such as `snow_surface`.
 *
 * Derivatives (kernel terrain_analysis_derive):
 * - gx = dh/dx, gy = dh/dy by central differences inside the grid and
 *   one-sided differences on its edges (0 along an axis with one point);
 *   a plane's gradient is therefore exact everywhere, edges included.
 * - normal = (-gx, -gy, 1) / sqrt(gx^2 + gy^2 + 1), a unit vector; a flat
 *   field gives exactly (0, 0, 1).
 * - slope = atan(sqrt(gx^2 + gy^2)), degrees, 0 (flat) .. 90.
 * - aspect = the downslope direction (-gx, -gy) as a compass bearing:
 *   degrees clockwise from north (+y), in [0, 360): a plane falling to the
 *   east has aspect 90. Flat points (gx = gy = 0) have aspect -1, the
 *   convention of ESRI's Aspect tool.
 * - hillshade = max(0, normal . sun), 0..1, with the unit vector towards the
 *   sun sun = (sin A cos E, cos A cos E, sin E) for SunAzimuth A (degrees
 *   clockwise from north) and SunElevation E (degrees above the horizon).
 *   This is the Lambert term that ESRI's Hillshade computes as
 *   cos(Z) cos(S) + sin(Z) sin(S) cos(A - aspect), Z = 90 - E, without its
 *   scaling to 0..255: a flat field gives sin E. With ModelShadows on,
 *   hillshade is multiplied by the shadow mask (ESRI's "model shadows").
 *
 * Cover (seed 001's snow/ice blend by slope; the seed gives neither the
 * exponent nor the threshold, so both are parameters):
 * - snow_cover = clamp(n_z, 0, 1)^SnowExponent (CoverMode 0, the seed's
 *   smooth snow/ice blend), or 1 where slope <= RockSlope and 0 elsewhere
 *   (CoverMode 1, the seed's hard threshold, written as a slope).
 * - cover_class, the first rule that holds:
 *   3 ice    where h < WaterLevel (frozen water and its shore: the seed puts
 *            ice where the terrain meets the water);
 *   2 rock   where slope > RockSlope (too steep for snow to stay);
 *   1 snow   where snow_cover >= SnowCoverLimit;
 *   0 ground elsewhere.
 *
 * Shadow (kernel terrain_analysis_shadow, seed 001 A.2.5's ray march): from
 * every point a ray runs towards the sun's azimuth in steps of one cell along
 * the grid axis it moves fastest along, reading h bilinearly, and keeps the
 * highest angle H above the horizon that the terrain rises to. The ray stops
 * when it leaves the grid (what lies beyond is taken as open sky) or when no
 * later sample could change the answer (the field's maximum is known).
 * - hard (PenumbraWidth 0): shadow = 1 (lit) where H < E, else 0.
 * - soft (PenumbraWidth W > 0 degrees): the sun is a band of elevations
 *   E - W/2 .. E + W/2, and shadow = clamp(0.5 + (E - H) / W, 0, 1), the
 *   part of it above the terrain's horizon. The real sun's disc is about
 *   0.53 degrees wide.
 * So a spike of height h on flat ground shades the points behind it, away
 * from the sun, up to a distance h / tan E, and no others.
 *
 * The field is whole: a piece of a split domain (gr_grid with global_nx or
 * ghost) is refused, as rays cross the whole domain.
 */
#ifndef GRAUPEL_TERRAIN_ANALYSIS_H
#define GRAUPEL_TERRAIN_ANALYSIS_H

#include "graupel/memory.h"
#include "graupel/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The outputs; each is nx*ny values (normal: 3 per point, x fastest). */
typedef enum gr_terrain_output {
  GR_TERRAIN_NORMAL = 0,  /**< `normal`, unit vector, 3 floats per point */
  GR_TERRAIN_SLOPE,       /**< `slope`, degrees */
  GR_TERRAIN_ASPECT,      /**< `aspect`, degrees clockwise from north, -1 flat */
  GR_TERRAIN_HILLSHADE,   /**< `hillshade`, 0..1 */
  GR_TERRAIN_SNOW_COVER,  /**< `snow_cover`, 0..1 */
  GR_TERRAIN_COVER_CLASS, /**< `cover_class`, bytes: 0 ground, 1 snow, 2 rock, 3 ice */
  GR_TERRAIN_SHADOW,      /**< `shadow`, 1 lit .. 0 in shadow */
  GR_TERRAIN_OUTPUT_COUNT
} gr_terrain_output;

/** The values of cover_class. */
typedef enum gr_cover_class {
  GR_COVER_GROUND = 0,
  GR_COVER_SNOW = 1,
  GR_COVER_ROCK = 2,
  GR_COVER_ICE = 3
} gr_cover_class;

/** The array name of an output ("normal", "slope", ...); NULL if unknown. */
GR_API const char *gr_terrain_output_name(gr_terrain_output o);

/**
 * The parameters. Ranges and defaults are the rows of
 * gr_terrain_analysis_param_bounds (named after the filters' properties),
 * the one place they are written.
 */
typedef struct gr_terrain_analysis_params {
  double sun_azimuth;      /**< SunAzimuth: degrees clockwise from north */
  double sun_elevation;    /**< SunElevation: degrees above the horizon, above 0 */
  double snow_exponent;    /**< SnowExponent: k of snow_cover = n_z^k, above 0 */
  int cover_mode;          /**< CoverMode: 0 smooth (n_z^k), 1 threshold at RockSlope */
  double snow_cover_limit; /**< SnowCoverLimit: snow class where snow_cover >= it */
  double rock_slope;       /**< RockSlope: degrees; steeper is rock */
  double water_level;      /**< WaterLevel: m; lower is ice */
  int model_shadows;       /**< ModelShadows: 1 multiplies hillshade by the shadow */
  double penumbra_width;   /**< PenumbraWidth: degrees of sun elevation; 0 hard */
} gr_terrain_analysis_params;

/** The table's defaults. */
GR_API void gr_terrain_analysis_params_init(gr_terrain_analysis_params *p);

/**
 * Checks every parameter against its row of the table; a sentence naming
 * the property, the value and the range goes to msg.
 */
GR_API gr_status gr_terrain_analysis_params_validate(const gr_terrain_analysis_params *p, char *msg,
                                                     size_t msg_len);

/**
 * The parameter table (SunAzimuth, SunElevation, SnowExponent, CoverMode,
 * SnowCoverLimit, RockSlope, WaterLevel, ModelShadows, PenumbraWidth);
 * *count gets the rows.
 */
GR_API const gr_param_bound *gr_terrain_analysis_param_bounds(int *count);

typedef struct gr_terrain_analysis gr_terrain_analysis;

/**
 * What an analysis of grid needs (memory.h): 37 bytes a point on the device
 * (the heights, the normal's three floats, slope, aspect, hillshade, snow
 * cover, shadow and the cover class's byte) and a byte a row on the host.
 * GR_ERR_INVALID_ARGUMENT without grid or out.
 */
GR_API gr_status gr_terrain_analysis_memory(const gr_grid *grid, gr_memory_need *out);

/**
 * An analysis of one whole grid: validates the grid and the parameters,
 * refuses one that gr_terrain_analysis_memory says does not fit
 * (GR_ERR_TOO_LARGE, before anything is allocated), builds the kernels and
 * allocates the device buffers.
 */
GR_API gr_status gr_terrain_analysis_create(gr_context *ctx, const gr_grid *grid,
                                            const gr_terrain_analysis_params *p,
                                            gr_terrain_analysis **out);

/** New parameters for the next compute (validated; kept unchanged on failure). */
GR_API gr_status gr_terrain_analysis_set_params(gr_terrain_analysis *t,
                                                const gr_terrain_analysis_params *p);

/**
 * Uploads the height field (nx*ny floats, m). Refuses a NaN or infinite
 * value with a sentence naming the point; the outputs of an earlier compute
 * are dropped.
 */
GR_API gr_status gr_terrain_analysis_set_heights(gr_terrain_analysis *t, const float *host);

/**
 * Enqueues everything the parameters ask for: the shadow when ModelShadows
 * is on, then normal, slope, aspect, hillshade, snow_cover and cover_class.
 * Does not wait.
 */
GR_API gr_status gr_terrain_analysis_compute(gr_terrain_analysis *t);

/** Enqueues the shadow of the whole grid; does not wait. */
GR_API gr_status gr_terrain_analysis_compute_shadow(gr_terrain_analysis *t);

/**
 * Enqueues the shadow of rows row0 .. row0+nrows-1 only (a caller that
 * reports progress or honours an abort computes a large grid band by band);
 * the shadow counts as computed once every row has been. Does not wait.
 */
GR_API gr_status gr_terrain_analysis_compute_shadow_rows(gr_terrain_analysis *t, int row0,
                                                         int nrows);

/**
 * Reads a float output back (waits for the device): nx*ny floats, 3*nx*ny
 * for GR_TERRAIN_NORMAL. Refuses an output that no compute has made since
 * the last set_heights, and GR_TERRAIN_COVER_CLASS (bytes: see below).
 */
GR_API gr_status gr_terrain_analysis_get_output(gr_terrain_analysis *t, gr_terrain_output o,
                                                float *host);

/** Reads cover_class back: nx*ny bytes (gr_cover_class values). */
GR_API gr_status gr_terrain_analysis_get_cover_class(gr_terrain_analysis *t, unsigned char *host);

/**
 * The latest error of a call on this analysis ("" when none). Never NULL.
 * For t == NULL, the calling thread's latest error.
 */
GR_API const char *gr_terrain_analysis_last_error(const gr_terrain_analysis *t);

/** Frees the analysis; NULL is fine. */
GR_API void gr_terrain_analysis_destroy(gr_terrain_analysis *t);

#ifdef __cplusplus
}
#endif

#endif
