/* Constants of the terrain analysis kernels that their host code
 * (kernels/src/terrain_analysis.c) also uses: included by both, so each
 * number is written once. Plain C that OpenCL C and C11 both read. */
#ifndef GRAUPEL_CL_TERRAIN_ANALYSIS_SHARED_H
#define GRAUPEL_CL_TERRAIN_ANALYSIS_SHARED_H

/* cover_class values; the host checks that gr_cover_class agrees. */
#define GR_TA_CLASS_GROUND 0
#define GR_TA_CLASS_SNOW 1
#define GR_TA_CLASS_ROCK 2
#define GR_TA_CLASS_ICE 3

/* CoverMode values. */
#define GR_TA_COVER_SMOOTH 0
#define GR_TA_COVER_THRESHOLD 1

/* The aspect of a flat point (ESRI's convention). */
#define GR_TA_ASPECT_FLAT (-1.0f)

#endif
