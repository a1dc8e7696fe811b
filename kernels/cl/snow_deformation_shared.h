/* Constants of the snow deformation core that the host (snow_deformation.c)
 * and the device (snow_deformation.cl) must agree on. Plain preprocessor
 * definitions only, valid C11 and OpenCL C. */
#ifndef GRAUPEL_CL_SNOW_DEFORMATION_SHARED_H
#define GRAUPEL_CL_SNOW_DEFORMATION_SHARED_H

/* The talus share (thermal erosion): a point gives at most this fraction
 * of its largest excess per iteration, and a point takes at most this
 * fraction of its largest incoming excess. 1/2 would level a lone pair to
 * the threshold in one iteration; 3/4 takes it a quarter of the excess
 * below (over-relaxation), which carries an excess down a long slope at the
 * talus angle in far fewer iterations (measured: the talus column in 8
 * iterations instead of 24) and leaves the cone within 1 % of its analytic
 * top; from 0.8 on a collapse comes out visibly flatter than MaxSlope (3.5 %
 * at 0.8, 22 % at 0.9). That holds for excesses above the threshold (a
 * collapse); a smaller one, the creep of a slight excess down a slope
 * already at the talus angle, moves at GR_SNOW_TALUS_SHARE_SMALL: there a
 * slope relaxes like a diffusion of its excess, and the share is its speed
 * (the bench's sphere at 1024^2: 104 iterations a step with 3/4 throughout,
 * 90 with 0.95 for excesses under a tenth of the threshold, 52 under the
 * threshold; the talus column's top stays within 3 % of the cone's). */
#define GR_SNOW_TALUS_SHARE 0.75f
#define GR_SNOW_TALUS_SHARE_SMALL 0.95f

/* A cell gives at most this fraction of its snow in one talus iteration, so
 * that rounding never takes it below zero. */
#define GR_SNOW_KEEP 0.999999f

/* A point lies inside a triangle's xy projection when each edge function
 * is at least -GR_SNOW_EDGE_EPS times twice the area: points on a shared edge
 * then belong to both triangles whatever the rounding (the minimum does not
 * mind), so a closed mesh has no pin-holes. */
#define GR_SNOW_EDGE_EPS 1.0e-6f

/* Reductions: per object, seven double-float sums (displaced volume e,
 * displaced mass e rho, the contour weights, contour points, the moved mass
 * D rho, the compressed height D - e, contact points), per unit cell area;
 * the ledger two (depth, depth times density); the talus check five maxima
 * (the largest movable amount and the box of the points still moving). */
#define GR_SNOW_OBJ_SUMS 7
#define GR_SNOW_LEDGER_SUMS 2
#define GR_SNOW_CHECK_MAXES 5

/* The per-object and ledger sums are integers (fixed point, reduce.h's
 * gr_reduce_group_long), so that the totals that steer a step (the
 * displaced height, its mass, the contour weights) and the ledger come out
 * to the bit whatever the split among work-groups or among the pieces of a
 * domain: heights in quanta (GR_SNOW_QUANTUM), contour weights in units of
 * 2^-20 (snow_contour rounds each weight to one), the masses of a press
 * (e rho, D rho) in units of 2^-32 kg/m^2 and the ledger's mass (S rho) in
 * units of 2^-24 kg/m^2 (int64 holds 2^39 kg/m^2 of snow summed over the
 * points: 16 m of ice on 2^23 points). */
#define GR_SNOW_WEIGHT_INV 1048576.0f
#define GR_SNOW_PRESS_MASS_INV 4294967296.0f
#define GR_SNOW_LEDGER_MASS_INV 16777216.0f

/* Talus iterations per launch of snow_relax_block (temporal blocking);
 * the check (the largest movable amount, and the box of the points still
 * moving, which becomes the window) runs after every launch. */
#define GR_SNOW_BLOCK_ITERATIONS 4

/* On GPUs (blocked talus) every GR_SNOW_CHECK_EVERY-th launch is checked,
 * and a check is read back GR_SNOW_CHECK_LAG checks later, so the device
 * never idles waiting for the host; the launches after the one whose check
 * finds nothing to move change nothing. */
#ifndef GR_SNOW_CHECK_EVERY
#define GR_SNOW_CHECK_EVERY 2
#endif
#define GR_SNOW_CHECK_LAG 2

/* The talus' tail runs in one work-group (snow_relax_group) once the
 * window it computes (the givers' window grown by two) holds at most this
 * many points: on GPUs, where the group is one multiprocessor's, and on
 * CPUs, where it is one core's. Measured on the bench sphere at 1024^2, a
 * group of 256: on the H200 the talus took 0.79-0.84 ms a step with 8192,
 * 1.09-1.51 ms with 4096 or without the tail, 1.39 ms with 16384 or 32768;
 * on PoCL here 16-17 ms with 32768 or 131072, 22 ms with 8192, 24 ms
 * without. */
#define GR_SNOW_GROUP_AREA_GPU 8192
#define GR_SNOW_GROUP_AREA_CPU 32768

/* The 8 neighbours' offsets, in the order the talus adds them up:
 * row by row from (-1, -1), the point itself left out. */
#define GR_SNOW_NEIGHBOUR_DI(q) ((q) < 3 ? (q)-1 : (q) < 5 ? 2 * ((q)-3) - 1 : (q)-6)
#define GR_SNOW_NEIGHBOUR_DJ(q) ((q) < 3 ? -1 : (q) < 5 ? 0 : 1)

/* The quantum of snow depth, 2^-20 m (about 1 micrometre). Depths and
 * every amount of snow that moves (pressed, displaced, deposited, slid) are
 * whole multiples of it: below 16 m of snow (2^24 quanta, a float's
 * significand) every sum and difference of them is exact, so what leaves a
 * point arrives at another to the bit and the volume ledger closes exactly
 * over any number of steps. */
#define GR_SNOW_QUANTUM_INV 1048576.0f
#define GR_SNOW_QUANTUM (1.0f / GR_SNOW_QUANTUM_INV)

/* A point slides only while it can move more than this (and more than
 * RelaxTolerance): 16 quanta, so that its largest pair moves at least a
 * quantum and every iteration that runs makes progress. */
#define GR_SNOW_MIN_MOVE (16.0f * GR_SNOW_QUANTUM)

#endif
