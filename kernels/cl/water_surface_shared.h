/* Constants of the water surface core that the host (water_surface.c) and the
 * device (water_surface.cl) must agree on: written once here, included by
 * both. Plain preprocessor definitions only, valid C11 and OpenCL C. */
#ifndef GRAUPEL_CL_WATER_SURFACE_SHARED_H
#define GRAUPEL_CL_WATER_SURFACE_SHARED_H

/* The ledger's reduction (reduce.h, integer): five int64 words per
 * work-group (the wave height over the wet points and the wave energy, each
 * a fixed-point coarse and fine word, and the wet points) and one maximum
 * (the largest |wave height|, its float's bits). */
#define GR_WATER_SURFACE_WORDS 5
#define GR_WATER_SURFACE_MAXES 1

/* A raindrop's Gaussian is summed over a window of this many spacings per
 * DropRadius on each side of the point (exp(-8) = 3e-4 of the peak at its
 * edge), and never wider than GR_WATER_SURFACE_MAX_REACH points: a larger
 * DropRadius on a fine grid is cut there (the dimple stays volume-neutral,
 * see water_surface.h). */
#define GR_WATER_SURFACE_REACH_SIGMAS 4.0
#define GR_WATER_SURFACE_MAX_REACH 12

/* What the derive kernel writes (3 floats per point for the normal). */
#define GR_WATER_SURFACE_DERIVE_SURFACE 0
#define GR_WATER_SURFACE_DERIVE_NORMAL 1
#define GR_WATER_SURFACE_DERIVE_WET 2
#define GR_WATER_SURFACE_DERIVE_WAVE 3

#endif
