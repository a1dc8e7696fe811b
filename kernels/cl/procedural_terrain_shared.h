/* Constants of the procedural terrain kernel that its host code
 * (kernels/src/procedural_terrain.c) also uses: included by both, so each
 * number is written once. Plain C that OpenCL C and C11 both read. */
#ifndef GRAUPEL_CL_PROCEDURAL_TERRAIN_SHARED_H
#define GRAUPEL_CL_PROCEDURAL_TERRAIN_SHARED_H

/* The noise kinds; the host checks that gr_noise_type has the same values. */
#define GR_PT_KIND_RIDGED 0
#define GR_PT_KIND_FBM 1
#define GR_PT_KIND_BILLOW 2

/* Per-octave tables the host fills in double and uploads as float/int:
 * table[GR_PT_TABLE_STRIDE*o ..] = (frac_x, frac_y, step_x, step_y),
 * lattice[GR_PT_LATTICE_STRIDE*o ..] = (lat_x, lat_y). */
#define GR_PT_TABLE_STRIDE 4
#define GR_PT_LATTICE_STRIDE 2

/* Octave o's lattice is shifted by (frac(0.25 + o*SX), frac(0.25 + o*SY))
 * lattice units (host side, in double). Gradient noise has no spread on its
 * lattice lines; unshifted, every octave had one on x = 0 and y = 0 and the
 * terrain dipped along both axes (28% low on average). Irrational steps keep
 * the octaves' lines apart; 0.25 puts the axes where the first octave's
 * spread is close to its average over a cell (0.5, mid-cell, lay 6% high). */
#define GR_PT_SHIFT_STEP_X 0.6180339887498949
#define GR_PT_SHIFT_STEP_Y 0.4142135623730951

#endif
