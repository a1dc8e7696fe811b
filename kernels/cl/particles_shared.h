/* Constants of the particle kernels that their host code
 * (kernels/src/particles.c) also uses: included by both, so each number is
 * written once. Plain C that OpenCL C and C11 both read. */
#ifndef GRAUPEL_CL_PARTICLES_SHARED_H
#define GRAUPEL_CL_PARTICLES_SHARED_H

/* Drop diameters, mm: real drops span about 0.1 to 6 mm (seed 004's drop
 * physics), so Marshall-Palmer's exponential is truncated there. */
#define GR_PA_DROP_MIN_MM 0.1
#define GR_PA_DROP_MAX_MM 6.0

/* Marshall-Palmer: Lambda = GR_PA_MP_A R^GR_PA_MP_B mm^-1, R in mm/h. */
#define GR_PA_MP_A 4.1
#define GR_PA_MP_B (-0.21)

/* Atlas et al. (1973): v = A - B exp(-C D), m/s, D in mm. */
#define GR_PA_ATLAS_A 9.65
#define GR_PA_ATLAS_B 10.3
#define GR_PA_ATLAS_C 0.6

/* Snowflakes: fall speed, m/s; size, mm; flutter frequency, Hz. */
#define GR_PA_SNOW_SPEED_MIN 0.5
#define GR_PA_SNOW_SPEED_MAX 1.5
#define GR_PA_SNOW_SIZE_MIN 2.0
#define GR_PA_SNOW_SIZE_MAX 10.0
#define GR_PA_FLUTTER_FREQ_MIN 0.2
#define GR_PA_FLUTTER_FREQ_MAX 0.8

/* A constant above as a float literal (9.65 -> 9.65f) for the kernels, so
 * that no double reaches a device without fp64; the host reads the
 * decimals as doubles. */
#define GR_PA_FLOAT_(x) x##f
#define GR_PA_FLOAT(x) GR_PA_FLOAT_(x)

/* Hash streams: one per random quantity, so that none correlates. */
#define GR_PA_STREAM_PHASE 1u
#define GR_PA_STREAM_SIZE 2u
#define GR_PA_STREAM_X 3u
#define GR_PA_STREAM_Y 4u
#define GR_PA_STREAM_SPEED 5u
#define GR_PA_STREAM_FLUTTER_A 6u
#define GR_PA_STREAM_FLUTTER_F 7u
#define GR_PA_STREAM_FLUTTER_PHI 8u
#define GR_PA_STREAM_FLUTTER_DIR 9u

#endif
