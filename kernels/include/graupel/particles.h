/**
 * @file particles.h
 * @brief Rain (seed 004) and snowfall (seed 001) particles: every particle's
 * position, velocity, size and exposure streak at a time t, computed by an
 * OpenCL kernel as a pure function of (Seed, t, particle index).
 *
 * There is no state between calls: a request for any time, in any order,
 * gives the same bits (ParaView scrubs time freely). Random numbers come from
 * a counter-based hash of (Seed, index, respawn count, stream), never from a
 * sequence.
 *
 * The region is a box [xmin, xmax] x [ymin, ymax] x [zmin, zmax] (m, z up).
 * Every particle falls from the top of the box to its bottom at its own
 * constant speed s (m/s, downward: its fall speed minus the wind's z) with
 * its own phase, then respawns at the top (at the bottom if an updraft
 * lifts it out of the top) at a new hashed (x, y). In between it drifts with
 * the wind; x and y wrap around the box (periodic), so particles never
 * leave it. With c = phase + s t / (zmax - zmin) (phase uniform in [0, 1)),
 * the particle is in its floor(c)-th life at height
 * zmax - (c - floor(c)) (zmax - zmin), and its (x, y) is a point hashed
 * from the life plus the wind's drift (wind_x t, wind_y t), wrapped: a
 * uniform point shifted on a periodic box is uniform, so respawned
 * particles appear anywhere, and within a life every particle moves by
 * exactly the wind times the time, however slowly it falls.
 * Drops and flakes fall through terrain (as in RainCL, seed 004):
 * the box's bottom is the ground plane.
 *
 * Rain (GR_PARTICLES_RAIN), after seed 004's particles and drop physics:
 * - Drop diameters D follow Marshall and Palmer (1948),
 *   N(D) = N0 exp(-Lambda D), N0 = 8000 m^-3 mm^-1, Lambda = 4.1 R^-0.21
 *   mm^-1 for a rain rate R in mm/h, truncated to the 0.1 .. 6 mm of real
 *   drops (drops above about 5-6 mm break up), sampled
 *   by the inverse of the truncated distribution's CDF:
 *   D = 0.1 - ln(1 - u (1 - exp(-Lambda 5.9))) / Lambda, u uniform in [0, 1).
 *   Its mean is 0.1 + 1/Lambda - 5.9 e / (1 - e), e = exp(-Lambda 5.9).
 *   N0 fixes the number of drops per m^3 (N0/Lambda untruncated); Count
 *   sets how many are drawn, so it does not enter.
 * - Terminal fall speed by diameter, Gunn and Kinzer's (1949) data as fitted
 *   by Atlas, Srivastava and Sekhon (1973): v = 9.65 - 10.3 exp(-0.6 D),
 *   m/s, D in mm, clamped at 0 (the fit goes negative below 0.09 mm).
 *   The seed draws speeds at random and ignores size;
 *   here speed follows size, as its physics section says it should.
 * - velocity = (wind_x, wind_y, wind_z - v): the drops move with the wind
 *   (the seed's pos += (velocity + wind) dt).
 *
 * Snowfall (GR_PARTICLES_SNOW), after seed 001's snowfall (the seed
 * leaves the jitter open; these are the choices):
 * - fall speed uniform in [0.5, 1.5] m/s per flake (dry snowflakes,
 *   Locatelli and Hobbs 1974), size uniform in [2, 10] mm;
 * - flutter: a sideways sway a sin(2 pi f t + phi) along a hashed horizontal
 *   direction, a uniform in [FlutterAmplitude/2, FlutterAmplitude], f in
 *   [0.2, 0.8] Hz, phi in [0, 2 pi);
 * - velocity = wind + the sway's velocity + (0, 0, -fall speed).
 *
 * Outputs (per particle; 3 floats a particle for vectors):
 * - position (m);
 * - velocity (m/s) at t;
 * - size: the diameter in mm (rain: `diameter`, snow: `size`);
 * - streak (m): the motion over the exposure [t - ExposureTime, t] (the
 *   point minus where it was then, across a respawn or a wrap as if
 *   there were none), for line streaks or oriented glyphs.
 *
 * Float math: positions are float32 computed from t in float32, so they
 * are good to about s t 6e-8 m (1 mm after 20 minutes of 9 m/s rain).
 */
#ifndef GRAUPEL_PARTICLES_H
#define GRAUPEL_PARTICLES_H

#include "graupel/memory.h"
#include "graupel/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What falls. */
typedef enum gr_particles_kind {
  GR_PARTICLES_RAIN = 0, /**< drops: Marshall-Palmer sizes, Atlas fall speeds */
  GR_PARTICLES_SNOW = 1  /**< flakes: 0.5-1.5 m/s, flutter */
} gr_particles_kind;

/** The outputs. */
typedef enum gr_particles_output {
  GR_PARTICLES_POSITION = 0, /**< m, 3 floats a particle */
  GR_PARTICLES_VELOCITY,     /**< `velocity`, m/s, 3 floats a particle */
  GR_PARTICLES_SIZE,         /**< `diameter` (rain) or `size` (snow), mm */
  GR_PARTICLES_STREAK,       /**< `streak`, m, 3 floats a particle */
  GR_PARTICLES_OUTPUT_COUNT
} gr_particles_output;

/** Components of an output (3 or 1; 0 if unknown). */
GR_API int gr_particles_output_components(gr_particles_output o);

/** The array name of an output for a kind ("velocity", "diameter", ...); NULL if unknown. */
GR_API const char *gr_particles_output_name(gr_particles_kind kind, gr_particles_output o);

/** Limits of the largest wind component the core accepts, m/s. */
#define GR_PARTICLES_MAX_WIND 100.0

/**
 * The parameters. The rows of gr_particles_param_bounds (Count, RainRate,
 * ExposureTime, Seed, FlutterAmplitude) give ranges and defaults; kind,
 * wind and region are checked by gr_particles_params_validate.
 */
typedef struct gr_particles_params {
  int kind;                 /**< gr_particles_kind */
  int count;                /**< Count: particles, 2^10 .. 2^24 */
  double rain_rate;         /**< RainRate: m/s (the user's mm/h times to_core), above 0 */
  double exposure_time;     /**< ExposureTime: s, the streak's exposure */
  int seed;                 /**< Seed */
  double flutter_amplitude; /**< FlutterAmplitude: m, the largest sway (snow) */
  double wind[3];           /**< m/s, each within +-GR_PARTICLES_MAX_WIND */
  double region[6];         /**< xmin xmax ymin ymax zmin zmax, m, each max above its min */
} gr_particles_params;

/** Defaults: rain, the table's values, no wind, a 100 m box from z = 0 to 50. */
GR_API void gr_particles_params_init(gr_particles_params *p);

/**
 * Checks every parameter; one sentence naming the parameter, its value and
 * the fix goes to msg.
 */
GR_API gr_status gr_particles_params_validate(const gr_particles_params *p, char *msg,
                                              size_t msg_len);

/** The parameter table (Count, RainRate, ExposureTime, Seed, FlutterAmplitude). */
GR_API const gr_param_bound *gr_particles_param_bounds(int *count);

/** Marshall-Palmer's Lambda (mm^-1) for a rain rate in mm/h. */
GR_API double gr_particles_marshall_palmer_lambda(double rain_rate_mm_h);

/** The mean diameter (mm) of drops the core draws for a rain rate in mm/h. */
GR_API double gr_particles_mean_diameter(double rain_rate_mm_h);

/** Atlas et al.'s terminal fall speed (m/s) of a drop of diameter d (mm). */
GR_API double gr_particles_rain_fall_speed(double diameter_mm);

typedef struct gr_particles gr_particles;

/**
 * What p's Count of particles needs (memory.h): their outputs on the
 * device, 4 bytes a component (points here are particles).
 * GR_ERR_INVALID_ARGUMENT without p or out.
 */
GR_API gr_status gr_particles_memory(const gr_particles_params *p, gr_memory_need *out);

/**
 * Validates the parameters, refuses a Count that gr_particles_memory says
 * does not fit (GR_ERR_TOO_LARGE, before anything is allocated), builds the
 * kernels and allocates the outputs.
 */
GR_API gr_status gr_particles_create(gr_context *ctx, const gr_particles_params *p,
                                     gr_particles **out);

/**
 * New parameters (validated; kept unchanged on failure); a new Count
 * reallocates. The outputs of an earlier compute are dropped.
 */
GR_API gr_status gr_particles_set_params(gr_particles *s, const gr_particles_params *p);

/** The number of particles. */
GR_API int gr_particles_count(const gr_particles *s);

/** Enqueues the particles at time t (s, finite); does not wait. */
GR_API gr_status gr_particles_compute(gr_particles *s, double time);

/**
 * Reads an output back (waits): count floats, 3 * count for vectors.
 * Refuses before the first compute.
 */
GR_API gr_status gr_particles_get_output(gr_particles *s, gr_particles_output o, float *host);

/** The latest error of a call on s ("" when none); for s == NULL the thread's. */
GR_API const char *gr_particles_last_error(const gr_particles *s);

/** Frees; NULL is fine. */
GR_API void gr_particles_destroy(gr_particles *s);

#ifdef __cplusplus
}
#endif

#endif
