/**
 * @file procedural_terrain.h
 * @brief Procedural terrain (seed 001): ridged multifractal, fBm and billow
 * noise computed by an OpenCL kernel.
 *
 * The noise is a function of world position, so a grid that is shifted by k
 * cells gives the same values shifted by k cells (tiles of a larger terrain
 * join seamlessly, and an MPI split needs no exchange).
 *
 * Normalisation (so that 0 <= elevation <= height_scale holds exactly):
 * - the gradient noise g is scaled to [-1, 1] (2-D Perlin's bound is
 *   sqrt(2)/2; g is multiplied by sqrt(2) and clamped against rounding);
 * - fBm: n = (sum_o p^o g_o / sum_o p^o + 1) / 2;
 * - billow: as fBm with g_o replaced by 2|g_o| - 1;
 * - ridged multifractal (libnoise's recurrence):
 *   s_o = (offset - |g_o|)^2 * w_o,  w_0 = 1,  w_{o+1} = clamp(s_o*gain, 0, 1),
 *   r = sum_o s_o lambda^(-o H) / sum_o offset^2 lambda^(-o H)  in [0, 1];
 *   inverted (seed 001's choice: rounded hills and river valleys instead of
 *   sharp crests) n = 1 - r, else n = r.
 * elevation = height_scale * n, in metres.
 * Octave o samples g_o at (x, y) * f * lacunarity^o + (frac(0.25 + 0.618034 o),
 * frac(0.25 + 0.414214 o)) lattice units (f the frequency in cycles per metre):
 * unshifted, every octave's lattice had lines on x = 0 and y = 0, where
 * gradient noise has half its spread, and the terrain dipped along both axes.
 */
#ifndef GRAUPEL_PROCEDURAL_TERRAIN_H
#define GRAUPEL_PROCEDURAL_TERRAIN_H

#include "graupel/memory.h"
#include "graupel/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum gr_noise_type {
  GR_NOISE_RIDGED = 0, /**< ridged multifractal (inverted by default) */
  GR_NOISE_FBM = 1,    /**< fractional Brownian motion (Perlin sum) */
  GR_NOISE_BILLOW = 2  /**< sum of |noise| octaves: puffy hills */
} gr_noise_type;

#define GR_PROCEDURAL_TERRAIN_OCTAVES_MIN 1
#define GR_PROCEDURAL_TERRAIN_OCTAVES_MAX 16

/**
 * The noise parameters. Ranges and defaults are the rows of
 * gr_procedural_terrain_param_bounds (named after the filter's properties),
 * the one place they are written; the docs pages, the XML domains and the VTK
 * clamps follow that table.
 */
typedef struct gr_procedural_terrain_params {
  int seed;            /**< Seed: any integer; equal seeds give equal fields */
  gr_noise_type type;  /**< NoiseType */
  int octaves;         /**< Octaves (GR_PROCEDURAL_TERRAIN_OCTAVES_MIN..MAX) */
  double frequency;    /**< Frequency: base-octave cycles per km, above 0 */
  double lacunarity;   /**< Lacunarity: frequency ratio of octaves */
  double persistence;  /**< Persistence: amplitude ratio (fBm, billow) */
  double offset;       /**< Offset: ridged offset, above 0 for every type */
  double gain;         /**< Gain: ridged weight gain */
  double h;            /**< SpectralExponent: ridged spectral exponent H */
  int invert;          /**< Invert: ridged only, 1 flips the ridges */
  double height_scale; /**< HeightScale: metres */
} gr_procedural_terrain_params;

/** The table's defaults. */
GR_API void gr_procedural_terrain_params_init(gr_procedural_terrain_params *p);

/**
 * Checks every parameter against its row of the table (min_open rows exclude
 * their min); a sentence naming the property, the value and the range goes
 * to msg.
 */
GR_API gr_status gr_procedural_terrain_params_validate(const gr_procedural_terrain_params *p,
                                                       char *msg, size_t msg_len);

typedef struct gr_procedural_terrain gr_procedural_terrain;

/**
 * What a generator for grid needs (memory.h): its elevation buffer, 4 bytes
 * a point, and the octave tables. GR_ERR_INVALID_ARGUMENT without grid or out.
 */
GR_API gr_status gr_procedural_terrain_memory(const gr_grid *grid, gr_memory_need *out);

/**
 * A terrain generator for one grid: validates the grid and the parameters,
 * checks gr_procedural_terrain_memory against what there is (a grid that
 * does not fit is GR_ERR_TOO_LARGE, before anything is allocated), builds
 * the kernel and allocates the elevation buffer on the device.
 */
GR_API gr_status gr_procedural_terrain_create(gr_context *ctx, const gr_grid *grid,
                                              const gr_procedural_terrain_params *p,
                                              gr_procedural_terrain **out);

/**
 * New parameters for the next compute (validated). A new Octaves or
 * NoiseType builds (or reuses) that kernel variant; on any failure the
 * generator keeps its previous parameters.
 */
GR_API gr_status gr_procedural_terrain_set_params(gr_procedural_terrain *t,
                                                  const gr_procedural_terrain_params *p);

/** Enqueues the noise kernel over the whole grid; does not wait. */
GR_API gr_status gr_procedural_terrain_compute(gr_procedural_terrain *t);

/**
 * Enqueues the rows row0 .. row0+nrows-1 only; does not wait. A caller that
 * reports progress or honours an abort computes a large grid band by band.
 */
GR_API gr_status gr_procedural_terrain_compute_rows(gr_procedural_terrain *t, int row0, int nrows);

/**
 * Reads a field back (waits for the device). Only GR_FIELD_ELEVATION exists;
 * host must hold nx*ny floats.
 */
GR_API gr_status gr_procedural_terrain_get_field(gr_procedural_terrain *t, gr_field f, float *host);

/**
 * The latest error of a call on this generator ("" when none), its own and
 * never another generator's on the same shared context. Never NULL. For
 * t == NULL (a create that failed has no generator), the calling thread's
 * latest error.
 */
GR_API const char *gr_procedural_terrain_last_error(const gr_procedural_terrain *t);

/**
 * The parameter table (Seed, NoiseType, Octaves, Frequency, Lacunarity,
 * Persistence, Offset, Gain, SpectralExponent, Invert, HeightScale) that
 * gr_procedural_terrain_params_validate follows; *count gets the rows.
 */
GR_API const gr_param_bound *gr_procedural_terrain_param_bounds(int *count);

/** Frees the generator; NULL is fine. */
GR_API void gr_procedural_terrain_destroy(gr_procedural_terrain *t);

/** One call: create, compute, read elevation into host (nx*ny floats), free. */
GR_API gr_status gr_procedural_terrain_generate(gr_context *ctx, const gr_grid *grid,
                                                const gr_procedural_terrain_params *p, float *host);

#ifdef __cplusplus
}
#endif

#endif
