/* Constants of the snow accumulation core that the host (snow_accumulation.c)
 * and the device (snow_accumulation.cl) must agree on. Plain preprocessor
 * definitions only, valid C11 and OpenCL C. */
#ifndef GRAUPEL_CL_SNOW_ACCUMULATION_SHARED_H
#define GRAUPEL_CL_SNOW_ACCUMULATION_SHARED_H

/* The ledger reductions: three double-float sums each (stored, fallen and
 * shed snow), per unit cell area on the grid and per unit depth x area on
 * the objects. */
#define GR_SNAC_SUMS 3

/* The exposure view has this many texels of margin on each side, so that a
 * point on the extent's edge still finds its texel. */
#define GR_SNAC_VIEW_MARGIN 1

/* An empty texel (nothing on its ray): below every float's ordered key. */
#define GR_SNAC_EMPTY (-2147483647 - 1)

/* The depth bias, in texels: a constant part and the part per unit of the
 * surface's slope in the view (the largest distance from a point's
 * projection to its texel's centre is 0.71 texel). The slope is taken at
 * most GR_SNAC_MAX_VIEW_SLOPE: steeper surfaces barely face the snow. */
#define GR_SNAC_BIAS_TEXELS 0.25f
#define GR_SNAC_BIAS_SLOPE 0.75f
#define GR_SNAC_MAX_VIEW_SLOPE 20.0f

/* Mesh points are tested half a texel out along their normal. */
#define GR_SNAC_NORMAL_OFFSET 0.5f

/* Largest BlurRadius: the kernel's weights are C(2r + 4, r + 2 + k). */
#define GR_SNAC_MAX_BLUR 16

/* The noise lattice repeats after this many cells in each direction. */
#define GR_SNAC_NOISE_PERIOD 65536.0

/* The terrain is left out of the exposure view when its steepest surface
 * triangle, with this relative margin, rises slower than the snow falls
 * (rise over run of the direction): then no surface point can hide
 * another. */
#define GR_SNAC_SLOPE_MARGIN 0.01

#endif
