/* Constants of the sky kernels (sky.cl) that their host code
 * (kernels/src/sky.c) also uses: included by both, so each number is written
 * once. Plain C that OpenCL C and C11 both read. */
#ifndef GRAUPEL_CL_SKY_SHARED_H
#define GRAUPEL_CL_SKY_SHARED_H

/* The cloud noise: libnoise's fBm defaults (seed 001 names libnoise and
 * gives no octaves, persistence or lacunarity). */
#define GR_SKY_OCTAVES 6
#define GR_SKY_LACUNARITY 2.0
#define GR_SKY_PERSISTENCE 0.5

/* Per-octave tables the host fills in double and uploads as float/int, as
 * the terrain does: table[GR_SKY_TABLE_STRIDE*o ..] = (frac_x, frac_y,
 * step_x, step_y), lattice[GR_SKY_LATTICE_STRIDE*o ..] = (lat_x, lat_y). */
#define GR_SKY_TABLE_STRIDE 4
#define GR_SKY_LATTICE_STRIDE 2

/* The Seed's noise distribution is measured on GR_SKY_SAMPLE_SIDE^2 points
 * GR_SKY_SAMPLE_STEP first-octave wavelengths apart (an irrational step, so
 * no octave's samples fall on its lattice, where gradient noise is 0). */
#define GR_SKY_SAMPLE_SIDE 256
#define GR_SKY_SAMPLE_STEP 1.41421356237

/* Colours of sky_rgb, 0..1: the zenith blue, the lit cloud and the
 * thickest cloud's grey. */
#define GR_SKY_BLUE_R 0.29f
#define GR_SKY_BLUE_G 0.50f
#define GR_SKY_BLUE_B 0.84f
#define GR_SKY_WHITE 0.97f
#define GR_SKY_GREY 0.60f

#endif
