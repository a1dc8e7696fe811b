/**
 * @file snow_melt.h
 * @brief Snowmelt by an enhanced temperature-index model with potential
 * clear-sky radiation, cast shadows, rain, liquid water holding, refreezing
 * and settling; point by point on the device, with a water ledger that
 * closes exactly.
 *
 * Model. Hock, R. (1999): A distributed temperature-index ice- and snowmelt
 * model including potential direct solar radiation, J. Glaciol. 45(149),
 * 101-111 (her model 3), with the threshold temperature T0 of Pellicciotti,
 * F. et al. (2005), J. Glaciol. 51(175), 573-587. Per point and step of dt:
 *
 * - Air temperature T (degC): T_ref + LapseRate (z - ReferenceElevation) /
 *   1000 for the point's elevation z (m; LapseRate in degC/km, -6.5 the
 *   standard atmosphere's), or, where the caller gives a per-point field
 *   (GR_SNOW_MELT_TEMPERATURE and gr_snow_melt_forcing.use_temperature_field),
 *   that field's value at the point.
 * - Melt M = (MF / 24 + a I) (T - T0) mm w.e. per hour for T > T0, else 0:
 *   MF = MeltFactor (mm w.e. degC^-1 d^-1), a = RadiationFactor (mm w.e.
 *   h^-1 degC^-1 (W m^-2)^-1; 0.0006 is Hock's snow value), T0 =
 *   ThresholdTemperature. Melt never exceeds the frozen water equivalent.
 * - I, potential clear-sky direct radiation on the slope (W m^-2), Hock
 *   1999 eq. 3: I = I0 (Rm/R)^2 Psi_a^(P / (P0 cos Z)) cos(theta), I0 = 1368
 *   W m^-2, Psi_a = Transmissivity, P / P0 = (1 - 2.25577e-5 z)^5.25588 (the
 *   standard atmosphere's pressure at z), Z the solar zenith angle and theta
 *   the angle of incidence on the slope: cos(theta) = n . s for the unit
 *   normal n = (-gx, -gy, 1) / |.| (gx, gy by central differences inside the
 *   domain and one-sided on its edges, as terrain_analysis.h) and the unit
 *   vector s towards the sun. I = 0 where cos(theta) <= 0, the sun is at or
 *   below the horizon, or the point lies in a cast shadow.
 * - Sun (Iqbal 1983, "An introduction to solar radiation", sec. 1.2-1.5):
 *   the day angle G = 2 pi (d - 1) / 365 of the day d (StartDayOfYear plus
 *   the whole days since StartHour; periodic, so it needs no wrap); the
 *   declination by Spencer (1971), delta = 0.006918 - 0.399912 cos G +
 *   0.070257 sin G - 0.006758 cos 2G + 0.000907 sin 2G - 0.002697 cos 3G +
 *   0.00148 sin 3G (rad), and the eccentricity (Rm/R)^2 = 1.000110 + 0.034221
 *   cos G + 0.001280 sin G + 0.000719 cos 2G + 0.000077 sin 2G, also Spencer's;
 *   the hour angle 15 deg (h - 12) for the local solar time h (StartHour plus
 *   the simulated time, modulo 24); with latitude phi, the sun's vector
 *   (east, north, up) = (-cos delta sin w, sin delta cos phi - cos delta sin
 *   phi cos w, sin delta sin phi + cos delta cos phi cos w): its elevation
 *   asin(up) and azimuth atan2(east, north), clockwise from north.
 * - Over a step, I is the mean over ns = ceil(dt / 900 s) equal sub-steps at
 *   their midpoints (so an hour's step takes 4 samples of the sun, never 1);
 *   the output `radiation` is the last step's mean.
 * - Cast shadows (CastShadows 1). When the terrain is set
 *   (gr_snow_melt_set_terrain), the horizon angle of every own point is
 *   found in HorizonSectors directions k 360 / HorizonSectors deg (k = 0 ..
 *   HorizonSectors - 1, clockwise from north): a ray marched one cell at a
 *   time along its faster axis over the WHOLE domain's elevation, read
 *   bilinearly (as terrain_analysis' shadow), keeps the highest angle the
 *   terrain rises to (at least 0: what lies below the horizontal never
 *   shades a sun above it); the ray ends where it leaves the domain (open
 *   sky beyond) or where no higher terrain can follow. Per sub-step, the
 *   horizon in the sun's azimuth is interpolated linearly between the two
 *   sectors around it and the point is lit where the sun's elevation exceeds
 *   it. So a step is point-local, and pieces of a split domain never exchange
 *   halos while stepping (see "Pieces" below).
 * - Precipitation P (mm/h: gr_snow_melt_forcing.precipitation, or a per-point
 *   field GR_SNOW_MELT_PRECIPITATION): the liquid fraction clamp((T - (Ts -
 *   dT / 2)) / dT, 0, 1) for RainSnowThreshold Ts and RainSnowBand dT (dT =
 *   0: all rain where T >= Ts). The solid part adds to the frozen water
 *   equivalent, the density mixed by mass with NewSnowDensity; the liquid part
 *   is rain: on snow (frozen water after the snowfall) it adds to the held
 *   liquid water and its heat melts rho_w c_w R max(T, 0) / (rho_w L_f) (R the
 *   rain's depth, c_w = 4186 J kg^-1 K^-1, L_f = 334 kJ/kg; rain at 0 degC
 *   melts nothing); on bare ground it passes straight to the release.
 * - Refreezing for T < T0: RefreezeFactor (T0 - T) mm per day, at most the
 *   held liquid water (all of it refreezes given cold time enough). The
 *   default 0.6 mm degC^-1 d^-1 is Snow-17's negative melt factor NMF, 0.15
 *   mm degC^-1 per 6 h (Anderson, E. A. (2006): Snow Accumulation and
 *   Ablation Model - SNOW-17, NOAA NWS), which Snow-17 applies to the pack's
 *   heat deficit; here it is the refreezing rate itself (no cold content).
 * - Liquid water is held up to LiquidWaterCapacity times the frozen water
 *   equivalent; the excess is released in the same step (release begins at
 *   the step in which the held water would exceed the capacity).
 * - Settling: rho -> MaxDensity - (MaxDensity - rho) exp(-dt / SettlingTime),
 *   exact in dt (n steps of dt / n give one step of dt, to rounding).
 * - depth = SWE rho_w / rho with SWE = frozen + held liquid water (m w.e.,
 *   rho_w = 1000 kg/m^3); 0 where SWE is 0.
 *
 * Order of a step, per point: temperature; the sun's sub-steps (mean I);
 * precipitation split into snow and rain; snowfall (density mixed); rain
 * (held on snow, released on bare ground); melt (temperature index plus the
 * rain's heat, at most the frozen water); refreezing (T < T0, at most the
 * liquid); release beyond the capacity; settling.
 *
 * State in fixed point. The frozen and the liquid water equivalents are
 * 64-bit integers of 2^-32 m (2.3e-10 m) a point, and every transfer
 * (snowfall, rain, melt, refreezing, release) is one such integer added to
 * one side and taken from the other: a float state would round each
 * transfer twice, differently. So the ledger's balance is exact, and its
 * sums (integers, split into 24-bit halves before adding) are the same bits
 * however the grid is split. Where this core departs from its sources: the
 * state's fixed point, the refreezing rate above, and no cold content.
 *
 * Time. The core has its own step, TimeStep (s); gr_snow_melt_advance takes
 * n = ceil(duration / TimeStep) equal steps that end exactly at the
 * duration. The forcing (gr_snow_melt_set_forcing: T_ref, precipitation, and
 * whether the per-point fields are used) is constant over an advance: a
 * caller splits its advances where the forcing changes. The core keeps the
 * simulated time (saved in checkpoints), which places the sun.
 *
 * Fields. Inputs by gr_snow_melt_set_field (each the local arrays: nx x ny
 * for a whole grid, a piece's rows and its rings otherwise): GR_FIELD_ELEVATION
 * (m, within +-1e6; flat 0 until set), GR_FIELD_SNOW_DEPTH (m, 0 to 1e4;
 * 0 until set) and GR_FIELD_SNOW_DENSITY (kg/m^3, 0 to 1000, at least 1 where
 * the depth is above 0; NewSnowDensity until set): the initial frozen water
 * depth density / 1000 (no liquid water), set only before the first step
 * (or after a reset); GR_SNOW_MELT_TEMPERATURE (degC, +-100) and
 * GR_SNOW_MELT_PRECIPITATION (mm/h, 0 to 1000). Every value finite. Outputs
 * by gr_snow_melt_get (own points, nx x ny floats): the
 * gr_snow_melt_output list.
 *
 * Pieces of a split domain (graupel.h's contract): a piece is a strip of
 * whole rows (i0 = 0, nx = global_nx) with a ring of grid.ghost = 1 row
 * toward each neighbour, which serves the slopes' central differences; the
 * core keeps its state on the own rows only. A step reads nothing beyond its
 * point, so stepping never exchanges halos (there are no halo calls); what
 * crosses the cuts is the horizon, and that comes from the whole domain's
 * elevation, which every piece is given once (gr_snow_melt_set_terrain):
 * rays cross the whole domain and the terrain is static, so one upload at
 * set-up is cheaper than any exchange per step. It costs 4 bytes a point of
 * the whole domain on the device while the horizons are computed (the
 * buffer is released after) and HorizonSectors floats a point of the piece
 * kept. The ledger is added over the pieces by the allreduce
 * (gr_snow_melt_set_allreduce; exact integers, the same bits as the whole
 * grid), and advance reduces a stop flag between its batches.
 */
#ifndef GRAUPEL_SNOW_MELT_H
#define GRAUPEL_SNOW_MELT_H

#include "graupel/memory.h"
#include "graupel/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Inputs of gr_snow_melt_set_field besides GR_FIELD_ELEVATION, _SNOW_DEPTH, _SNOW_DENSITY. */
enum {
  GR_SNOW_MELT_TEMPERATURE = 100,  /**< `air_temperature`, degC, per point */
  GR_SNOW_MELT_PRECIPITATION = 101 /**< `precipitation`, mm/h, per point */
};

/** The outputs; each nx*ny floats of the own points. */
typedef enum gr_snow_melt_output {
  GR_SNOW_MELT_SNOW_DEPTH = 0, /**< `snow_depth`, m */
  GR_SNOW_MELT_SNOW_DENSITY,   /**< `snow_density`, kg/m^3 (0 without snow) */
  GR_SNOW_MELT_SWE,            /**< `swe`: frozen + liquid, m w.e. */
  GR_SNOW_MELT_LIQUID_WATER,   /**< `liquid_water`: held liquid water, m */
  GR_SNOW_MELT_MELT_RATE,      /**< `melt_rate`, mm/h: mean since the last mark */
  GR_SNOW_MELT_WATER_RELEASE,  /**< `water_release`, mm/h: mean since the last mark */
  GR_SNOW_MELT_RADIATION,      /**< `radiation`, W/m^2: the last step's mean I */
  GR_SNOW_MELT_RELEASED,       /**< `released_depth`, m: released since the last mark */
  GR_SNOW_MELT_OUTPUT_COUNT
} gr_snow_melt_output;

/** The array name of an output ("snow_depth", ...); NULL if unknown. */
GR_API const char *gr_snow_melt_output_name(gr_snow_melt_output o);

/**
 * The parameters, in the core's units. Ranges and defaults are the rows of
 * gr_snow_melt_param_bounds (the property names in brackets), written
 * nowhere else.
 */
typedef struct gr_snow_melt_params {
  double latitude;            /**< Latitude, deg, -90 .. 90 */
  int start_day;              /**< StartDayOfYear, 1 .. 366 */
  double start_hour;          /**< StartHour, local solar time, h, 0 .. 24 */
  double time_step;           /**< TimeStep, s, 1 .. 86400 */
  double melt_factor;         /**< MeltFactor MF, mm w.e. degC^-1 d^-1 */
  double radiation_factor;    /**< RadiationFactor a, mm w.e. h^-1 degC^-1 (W m^-2)^-1 */
  double threshold;           /**< ThresholdTemperature T0, degC */
  double lapse_rate;          /**< LapseRate, degC/km */
  double reference_elevation; /**< ReferenceElevation, m: where T = T_ref */
  double transmissivity;      /**< Transmissivity Psi_a, (0, 1] */
  double rain_snow_threshold; /**< RainSnowThreshold Ts, degC */
  double rain_snow_band;      /**< RainSnowBand dT, degC */
  double new_snow_density;    /**< NewSnowDensity, kg/m^3 */
  double max_density;         /**< MaxDensity, kg/m^3, at least NewSnowDensity */
  double settling_time;       /**< SettlingTime, s (the table's unit: days) */
  double liquid_capacity;     /**< LiquidWaterCapacity, fraction of the frozen SWE */
  double refreeze_factor;     /**< RefreezeFactor, mm w.e. degC^-1 d^-1 */
  int cast_shadows;           /**< CastShadows, 0 or 1 */
  int horizon_sectors;        /**< HorizonSectors, 4 .. 360 */
} gr_snow_melt_params;

/** The table's defaults. */
GR_API void gr_snow_melt_params_init(gr_snow_melt_params *p);

/** Checks every parameter against its row, then MaxDensity >= NewSnowDensity; a sentence to msg. */
GR_API gr_status gr_snow_melt_params_validate(const gr_snow_melt_params *p, char *msg,
                                              size_t msg_len);

/** The parameter table; *count gets the rows. */
GR_API const gr_param_bound *gr_snow_melt_param_bounds(int *count);

/** The forcing of the next advances: constant over each. */
typedef struct gr_snow_melt_forcing {
  double air_temperature;      /**< T_ref, degC at ReferenceElevation, +-100 */
  double precipitation;        /**< mm/h, 0 .. 1000 */
  int use_temperature_field;   /**< 1: T is the GR_SNOW_MELT_TEMPERATURE field */
  int use_precipitation_field; /**< 1: P is the GR_SNOW_MELT_PRECIPITATION field */
} gr_snow_melt_forcing;

/**
 * The book-keeping, m^3 (cell area dx dy), over the own points (global
 * after the allreduce on pieces). balance_error = (snowfall_in +
 * snowfall_volume + rain_volume) - (stored_swe_volume + stored_liquid_volume
 * + released_volume), computed in the state's integers: exactly 0 unless a
 * transfer was booked wrongly.
 */
typedef struct gr_snow_melt_ledger {
  double time;                 /**< simulated time, s */
  long long steps;             /**< steps taken */
  double snowfall_in;          /**< the initial SWE */
  double snowfall_volume;      /**< precipitation that fell as snow */
  double rain_volume;          /**< precipitation that fell as rain */
  double melt_volume;          /**< frozen water that melted (rain's heat included) */
  double refrozen_volume;      /**< liquid water that refroze */
  double released_volume;      /**< water released (melt, rain) */
  double released_since_mark;  /**< of which since the last mark */
  double stored_swe_volume;    /**< frozen water held */
  double stored_liquid_volume; /**< liquid water held */
  double balance_error;        /**< see above */
} gr_snow_melt_ledger;

typedef struct gr_snow_melt gr_snow_melt;

/**
 * What a simulation on grid needs (memory.h) with the default sectors when
 * p is NULL: on the device 112 bytes a point plus 4 per horizon sector
 * (state, accumulators, normals, fields), plus 4 a point of the whole domain
 * while the horizons are computed; on the host 8 a point (the initial snow);
 * a checkpoint 80 bytes a point.
 */
GR_API gr_status gr_snow_melt_memory(const gr_grid *grid, const gr_snow_melt_params *p,
                                     gr_memory_need *out);

/**
 * A simulation on a whole grid or a piece (ghost 1, strips of rows), flat
 * ground at 0, no snow, forcing 0 degC and no precipitation. Refuses a grid
 * that does not fit (GR_ERR_TOO_LARGE) before allocating.
 */
GR_API gr_status gr_snow_melt_create(gr_context *ctx, const gr_grid *grid,
                                     const gr_snow_melt_params *p, gr_snow_melt **out);

/**
 * The whole domain's elevation for the horizons: global_nx x global_ny
 * floats (a whole grid: its own nx x ny), finite, within +-1e6 m. Computes
 * the horizons now (waits). Needed before stepping with CastShadows 1.
 */
GR_API gr_status gr_snow_melt_set_terrain(gr_snow_melt *s, const float *elevation);

/** Uploads an input (see "Fields"); a refused field names the point and keeps the state. */
GR_API gr_status gr_snow_melt_set_field(gr_snow_melt *s, int field, const float *host);

/** The forcing of the next advances (finite, in range; refused with one sentence). */
GR_API gr_status gr_snow_melt_set_forcing(gr_snow_melt *s, const gr_snow_melt_forcing *f);

/**
 * Advances by duration s (>= 0, finite) in ceil(duration / TimeStep) equal
 * steps. With a progress callback it may stop between batches
 * (GR_ERR_ABORTED, the state valid there). *steps_taken may be NULL.
 */
GR_API gr_status gr_snow_melt_advance(gr_snow_melt *s, double duration, int *steps_taken);

/** Progress and abort for advance; NULL removes it. */
GR_API void gr_snow_melt_set_progress(gr_snow_melt *s, gr_progress_fn fn, void *user);

/**
 * Starts a new output interval: melt_rate, water_release and released_depth
 * are from now on over the time since this call (the ledger's
 * released_since_mark too).
 */
GR_API gr_status gr_snow_melt_mark(gr_snow_melt *s);

/** Reads an output (waits): nx*ny floats of the own points. */
GR_API gr_status gr_snow_melt_get(gr_snow_melt *s, gr_snow_melt_output o, float *host);

/** The ledger now (waits; collective on pieces). */
GR_API gr_status gr_snow_melt_ledger_get(gr_snow_melt *s, gr_snow_melt_ledger *out);

/** Back to the snow set by set_field, time 0, no steps, no mark. Inputs and forcing are kept. */
GR_API gr_status gr_snow_melt_reset(gr_snow_melt *s);

/**
 * Checkpoints: the state, accumulators, time, steps and mark as bytes (a
 * piece: its own; it loads only into the same piece). Loaded into a
 * simulation of the same grid, inputs, terrain and parameters, the steps
 * that follow are bit-identical to those after the save (with the forcing
 * set again).
 */
GR_API gr_status gr_snow_melt_state_size(const gr_snow_melt *s, size_t *bytes);
GR_API gr_status gr_snow_melt_state_save(gr_snow_melt *s, void *host, size_t bytes);
GR_API gr_status gr_snow_melt_state_load(gr_snow_melt *s, const void *host, size_t bytes);

/** The ring a piece needs: 1 row (the slopes' central differences). */
#define GR_SNOW_MELT_GHOST 1

/** The global reduction over the pieces; NULL (the default) for a whole domain. */
GR_API void gr_snow_melt_set_allreduce(gr_snow_melt *s, gr_allreduce_fn fn, void *user);

/** The latest error of a call on this simulation ("" when none; never NULL). */
GR_API const char *gr_snow_melt_last_error(const gr_snow_melt *s);

/** Frees the simulation; NULL is fine. */
GR_API void gr_snow_melt_destroy(gr_snow_melt *s);

#ifdef __cplusplus
}
#endif

#endif
