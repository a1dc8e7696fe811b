/**
 * @file sky.h
 * @brief The sky of seed 001 (its clouds and lightning): branching
 * lightning bolts as polylines, and a drifting cloud cover image.
 *
 * Lightning (gr_lightning_*, host C, no device). A bolt is a few hundred
 * points at most, and its main strand is a random walk (each point follows
 * from the one before): inherently sequential and far too small to pay for
 * a kernel launch and a read-back, so it is computed on the host. It is
 * still a pure function of its parameters: every random number is a hash of
 * (Seed, Variant, strand, point, purpose), never a generator's state.
 * - The seed's method (a:L181): points along the segment from Start to End
 *   with random lateral offsets, the ends fixed, several strands per strike;
 *   50 control points. The seed does not say how the offsets are drawn
 *   (notes C): here they are a Brownian bridge, so that neighbouring points
 *   are correlated (a jagged line, not noise) and both ends are exact.
 * - Main strand (strand 0): ControlPoints points P_k = Start + t_k (End -
 *   Start) + Jitter L (B_k.x v + B_k.y w), t_k = k / (ControlPoints - 1),
 *   L = |End - Start|, (v, w) unit vectors across the bolt, B the bridge
 *   W_k - t_k W_last of a 2-D Gaussian random walk W with steps of variance
 *   1 / (ControlPoints - 1) per axis: the lateral offset's standard
 *   deviation is Jitter L sqrt(t (1 - t)) per axis, Jitter L / 2 at the
 *   middle. P_0 = Start and P_last = End exactly.
 * - Branches (strands 1 .. Strands; the seed's "several polylines per
 *   strike", here grown from the main strand so that they read as one
 *   bolt): each starts exactly at a main-strand point k (0 <= k <= 0.8 of
 *   the strand, never its last point), leaves the main strand's direction by
 *   20 to 45 degrees, is 0.15 to 0.4 of the main strand's remaining length
 *   long and has gr_lightning_branch_points(ControlPoints) = max(2,
 *   ControlPoints / 2) points: its own free random walk with the same
 *   relative Jitter (its tip is free, as a branch ends in the air).
 * - Point layout: the main strand's ControlPoints points, then each
 *   branch's points in order; total ControlPoints + Strands *
 *   gr_lightning_branch_points(ControlPoints).
 * - intensity: 1 on the main strand; on a branch 0.5 at its root fading
 *   linearly to 0.15 at its tip (the seed draws white lines; intensity is
 *   for colouring, glow width or opacity). strand: 0 main, s for branch s.
 * - Timing (a:L185: a bolt is shown briefly and reshaped a few times):
 *   the shape is Variant + floor(Time * FlickerRate) (gr_lightning_shape),
 *   each shape another bolt of the same Seed; FlickerRate 0 keeps one shape
 *   at every time. When a bolt is shown (the seed's random intervals) is
 *   left to the caller: an animation shows or hides the source.
 *
 * Cloud cover (gr_cloud_cover_*, OpenCL kernels sky_cloud_noise and
 * sky_cloud_shade). After Hugo Elias's "Cloud Cover" as the seed uses it
 * (A.2.6), on a Resolution x Resolution image Size metres wide, centred on
 * (0, 0), pixel centres at -Size/2 + (i + 1/2) Size / Resolution:
 * - n(x, y, t) = fBm of 2-D gradient noise (kernels/cl/noise.h, the
 *   terrain's) at (x - u t, y - v t) / Scale, 6 octaves, lacunarity 2,
 *   persistence 0.5 (libnoise's defaults, notes A.2.1; the seed gives none),
 *   normalised to [0, 1]: Scale is the first octave's wavelength in metres.
 *   (u, v) = WindSpeed (sin D, cos D) for WindDirection D, the compass
 *   bearing the clouds move towards (90: east). The whole field moves with
 *   the wind, so cloud(x, y, t + dt) = cloud(x - u dt, y - v dt, t) exactly.
 *   (The seed averages layers moving in different directions; one velocity
 *   keeps the drift a plain shift that a user and a test can reason about.)
 * - Cover is the fraction of the sky clouded: the threshold T is the
 *   (1 - Cover) quantile of n for this Seed, measured once per Seed on 65536
 *   points spread over 360 x 360 first-octave wavelengths (the noise's own
 *   distribution, independent of the image), so that over an image many
 *   times Scale wide the clouded fraction (cloud > 0) is Cover to within
 *   sampling error; Cover 0 is a clear sky, Cover 1 an overcast one. T falls
 *   as Cover rises, so the clouded set and every pixel's cloud only grow.
 * - cloud = 1 - Sharpness^(255 (n - T)) where n > T, else 0 (Elias's
 *   density curve with n on his 0..255 scale): 0..1. Lower Sharpness gives
 *   denser, harder-edged clouds.
 * - sky_rgb (3 bytes): the zenith blue mixed towards white by cloud, the
 *   thickest cloud greyed (a background picture, not a radiative model).
 */
#ifndef GRAUPEL_SKY_H
#define GRAUPEL_SKY_H

#include "graupel/memory.h"
#include "graupel/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------- lightning */

/** A bolt's parameters; Seed is shared with the cloud cover's row. */
typedef struct gr_lightning_params {
  int control_points;  /**< ControlPoints: points of the main strand, at least 2 */
  int strands;         /**< Strands: branches besides the main strand */
  double jitter;       /**< Jitter: lateral displacement relative to the length */
  int seed;            /**< Seed: any integer */
  int variant;         /**< the first shape of the Seed's bolt (not a table row) */
  double flicker_rate; /**< FlickerRate: reshapes per second, 0 still */
  double time;         /**< s: with flicker_rate, picks the shape (not a table row) */
  double start[3];     /**< where the bolt leaves the cloud, m */
  double end[3];       /**< where it strikes, m; must differ from start */
} gr_lightning_params;

/** The table's defaults, Variant 0, Start (0, 0, 1000) and End (0, 0, 0). */
GR_API void gr_lightning_params_init(gr_lightning_params *p);

/**
 * Checks the table's lightning rows, Start and End (finite, apart) and the
 * time (finite); a sentence naming the property, the value and the fix goes
 * to msg.
 */
GR_API gr_status gr_lightning_params_validate(const gr_lightning_params *p, char *msg,
                                              size_t msg_len);

/**
 * The shape drawn: variant + floor(time * flicker_rate), saturating at the
 * int range; variant when flicker_rate is 0.
 */
GR_API int gr_lightning_shape(const gr_lightning_params *p);

/** Points of each branch: max(2, control_points / 2). */
GR_API int gr_lightning_branch_points(int control_points);

/** Points of the whole bolt (main strand and branches); 0 when p is invalid. */
GR_API long gr_lightning_point_count(const gr_lightning_params *p);

/**
 * Writes the bolt: xyz (3 doubles a point), intensity and strand (one a
 * point; either may be NULL), gr_lightning_point_count(p) points in the
 * layout above. Validates p first (a sentence to msg on failure).
 */
GR_API gr_status gr_lightning_generate(const gr_lightning_params *p, double *xyz, float *intensity,
                                       int *strand, char *msg, size_t msg_len);

/**
 * A strike on a terrain: the index (0 .. npoints-1) of the point that the
 * bolt of (seed, shape) hits, a hash of them (shape: gr_lightning_shape).
 * -1 when npoints < 1.
 */
GR_API long gr_lightning_strike_index(int seed, int shape, long npoints);

/**
 * The start of a strike at end over a terrain of bounds (xmin, xmax, ymin,
 * ymax, zmin, zmax): half the terrain's larger horizontal extent (at least
 * 100 m) above its highest point, offset sideways by up to a third of that
 * height in a hashed direction, so bolts lean.
 */
GR_API void gr_lightning_start_over(int seed, int shape, const double bounds[6],
                                    const double end[3], double start[3]);

/* ----------------------------------------------------------- cloud cover */

/** The cloud image's parameters. */
typedef struct gr_cloud_cover_params {
  double cover;          /**< Cover: fraction of the sky clouded, 0..1 */
  double scale;          /**< Scale: first octave's wavelength, m */
  double sharpness;      /**< Sharpness: Elias's CloudSharpness */
  double wind_speed;     /**< WindSpeed: m/s */
  double wind_direction; /**< WindDirection: degrees clockwise from north, moving towards */
  int resolution;        /**< Resolution: pixels per side */
  double size;           /**< Size: the image's width, m */
  int seed;              /**< Seed: any integer */
} gr_cloud_cover_params;

/** The table's defaults. */
GR_API void gr_cloud_cover_params_init(gr_cloud_cover_params *p);

/** Checks the table's cloud rows; a sentence to msg on failure. */
GR_API gr_status gr_cloud_cover_params_validate(const gr_cloud_cover_params *p, char *msg,
                                                size_t msg_len);

/**
 * The image's grid: Resolution x Resolution points at the pixel centres,
 * spacing Size / Resolution, centred on (0, 0).
 */
GR_API void gr_cloud_cover_grid(const gr_cloud_cover_params *p, gr_grid *out);

/**
 * The parameter table of the sky core (Lightning: ControlPoints, Strands,
 * Jitter, Seed, FlickerRate; Cloud Cover: Cover, Scale, Sharpness, WindSpeed,
 * WindDirection, Resolution, Size, and Seed, the one row both share);
 * *count gets the rows.
 */
GR_API const gr_param_bound *gr_sky_param_bounds(int *count);

typedef struct gr_cloud_cover gr_cloud_cover;

/**
 * What a cloud image of p's Resolution needs (memory.h): 11 bytes a pixel
 * on the device (the noise and the cloud's floats, the colour's three
 * bytes) and the Seed's noise sample on both sides. GR_ERR_INVALID_ARGUMENT
 * without p or out.
 */
GR_API gr_status gr_cloud_cover_memory(const gr_cloud_cover_params *p, gr_memory_need *out);

/**
 * A cloud image: validates the parameters and the grid against the device
 * and its memory (gr_cloud_cover_memory; GR_ERR_TOO_LARGE before anything
 * is allocated), builds the kernels, allocates the buffers and measures the
 * Seed's noise distribution (one small launch, waited for).
 */
GR_API gr_status gr_cloud_cover_create(gr_context *ctx, const gr_cloud_cover_params *p,
                                       gr_cloud_cover **out);

/**
 * New parameters (validated; kept unchanged on failure). A new Resolution
 * reallocates, a new Seed measures the distribution again.
 */
GR_API gr_status gr_cloud_cover_set_params(gr_cloud_cover *c, const gr_cloud_cover_params *p);

/** Enqueues the image at time t (s) over the whole grid; does not wait. */
GR_API gr_status gr_cloud_cover_compute(gr_cloud_cover *c, double t);

/**
 * Enqueues rows row0 .. row0+nrows-1 of the image at time t only (progress
 * and abort between bands); does not wait.
 */
GR_API gr_status gr_cloud_cover_compute_rows(gr_cloud_cover *c, double t, int row0, int nrows);

/** The threshold T of the current Cover on n's 0..1 scale. */
GR_API double gr_cloud_cover_threshold(const gr_cloud_cover *c);

/**
 * Reads the image back (waits): cloud (Resolution^2 floats) and sky_rgb
 * (3 Resolution^2 bytes); either may be NULL. Refuses before a compute.
 */
GR_API gr_status gr_cloud_cover_get(gr_cloud_cover *c, float *cloud, unsigned char *sky_rgb);

/** The latest error of a call on c ("" when none); for NULL, the thread's. */
GR_API const char *gr_cloud_cover_last_error(const gr_cloud_cover *c);

/** Frees the image; NULL is fine. */
GR_API void gr_cloud_cover_destroy(gr_cloud_cover *c);

#ifdef __cplusplus
}
#endif

#endif
