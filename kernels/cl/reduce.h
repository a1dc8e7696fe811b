/* Deterministic sums on the device, shared by every core that keeps a water
 * (or mass, or energy) ledger: Kahan sums per cell, double-float (TwoSum)
 * accumulation per work-item and a fixed-shape work-group combine. The host
 * side (graupel/reduce.h, src/reduce.c) launches the reduction and adds the
 * groups' partials in order in double, so every run gives the same bits.
 *
 * A reduction kernel is a 1-D launch of whole work-groups with the arguments
 * `__global float *partial` and `__local float *scratch` (set by
 * gr_reduction_run) and its own inputs. Each work-item sums the cells
 * gr_reduce_block gives it into nsum (hi, lo) pairs and nmax maxima, stores
 * them at gr_reduce_slots(scratch, ...) (the pairs first, then the maxima)
 * and calls gr_reduce_group. */
#ifndef GRAUPEL_CL_REDUCE_H
#define GRAUPEL_CL_REDUCE_H

/* Kahan summation into per-cell arrays: sum[c] - comp[c] carries a running
 * total to about twice float precision over 10^5 steps and more. */
/* x added to the sum s and compensation k already read from sum[c],
 * comp[c] (a caller that reads them before it knows whether it adds). */
GR_INLINE void gr_kahan_store(__global float *restrict sum, __global float *restrict comp, int c,
                              float s, float k, float x) {
  float y = x - k;
  float t = s + y;
  comp[c] = (t - s) - y;
  sum[c] = t;
}

GR_INLINE void gr_kahan_add(__global float *restrict sum, __global float *restrict comp, int c,
                            float x) {
  gr_kahan_store(sum, comp, c, sum[c], comp[c], x);
}

/* Double-float arithmetic (Knuth's TwoSum): hi + lo holds a sum to about
 * twice float precision, so that a ledger's volumes agree with the Kahan sums
 * per cell. */
GR_INLINE void gr_df_add(float *hi, float *lo, float x) {
  float s = *hi + x;
  float bb = s - *hi;
  float e = (*hi - (s - bb)) + (x - bb);
  *hi = s;
  *lo += e;
}

/* a += b for double-floats in local memory, renormalised (Fast2Sum) so that
 * lo stays small against hi. */
GR_INLINE void gr_df_merge(__local float *a, __local const float *b) {
  float hi = a[0], lo = a[1] + b[1];
  gr_df_add(&hi, &lo, b[0]);
  float s = hi + lo;
  a[1] = lo - (s - hi);
  a[0] = s;
}

/* The cells [*start, *end) of n that this work-item's group sums: one
 * contiguous block per group (cache-friendly on CPUs), its work-items
 * interleaved within it (coalesced on GPUs): a work-item takes
 * *start + lid, *start + lid + wg, ... */
GR_INLINE void gr_reduce_block(int n, int *start, int *end) {
  int groups = get_num_groups(0);
  int per_group = (n + groups - 1) / groups;
  *start = get_group_id(0) * per_group;
  *end = min(n, *start + per_group);
}

/* This work-item's 2 nsum + nmax slots in scratch. */
GR_INLINE __local float *gr_reduce_slots(__local float *scratch, int nsum, int nmax) {
  return scratch + (2 * nsum + nmax) * get_local_id(0);
}

/* Combines the work-items' slots in a fixed binary tree (the work-group size
 * is a power of two) and writes the group's 2 nsum + nmax floats to
 * partial[(2 nsum + nmax) * group ...]. Every work-item of the group must
 * call it. */
GR_INLINE void gr_reduce_group(__local float *scratch, int nsum, int nmax,
                               __global float *restrict partial) {
  int lid = get_local_id(0), wg = get_local_size(0), slots = 2 * nsum + nmax;
  __local float *mine = scratch + slots * lid;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (int span = wg / 2; span > 0; span /= 2) {
    if (lid < span) {
      __local const float *other = scratch + slots * (lid + span);
      for (int q = 0; q < nsum; ++q)
        gr_df_merge(mine + 2 * q, other + 2 * q);
      for (int q = 2 * nsum; q < slots; ++q)
        mine[q] = fmax(mine[q], other[q]);
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (lid == 0)
    for (int q = 0; q < slots; ++q)
      partial[slots * get_group_id(0) + q] = scratch[q];
}

/* Integer (fixed-point) sums, for totals that must not depend on how the
 * cells are split into work-groups or among the pieces of a domain: integer
 * addition is exact in any order. A reduction kernel of this kind has the
 * arguments `__global long *partial` and `__local long *scratch` (set by
 * gr_reduction_i64_run); each work-item stores its nsum longs at
 * gr_reduce_slots_long(scratch, nsum) and calls gr_reduce_group_long (or,
 * with maxima, gr_reduce_group_long_max). */
GR_INLINE __local long *gr_reduce_slots_long(__local long *scratch, int nsum) {
  return scratch + nsum * get_local_id(0);
}

/* Adds the work-items' slots (a binary tree; any order gives the same
 * integers), keeps the largest of the last nmax slots, and writes the
 * group's nsum + nmax longs to partial[(nsum + nmax) * group ...] (the
 * work-items store nsum + nmax longs at gr_reduce_slots_long(scratch,
 * nsum + nmax)). A maximum of non-negative floats travels as the float's
 * bits (as_int), which order as the floats do. Every work-item of the group
 * must call it. */
GR_INLINE void gr_reduce_group_long_max(__local long *scratch, int nsum, int nmax,
                                        __global long *restrict partial) {
  int lid = get_local_id(0), wg = get_local_size(0), slots = nsum + nmax;
  __local long *mine = scratch + slots * lid;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (int span = wg / 2; span > 0; span /= 2) {
    if (lid < span) {
      __local const long *other = scratch + slots * (lid + span);
      for (int q = 0; q < nsum; ++q)
        mine[q] += other[q];
      for (int q = nsum; q < slots; ++q)
        mine[q] = max(mine[q], other[q]);
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (lid == 0)
    for (int q = 0; q < slots; ++q)
      partial[slots * get_group_id(0) + q] = scratch[q];
}

/* gr_reduce_group_long_max without maxima. */
GR_INLINE void gr_reduce_group_long(__local long *scratch, int nsum,
                                    __global long *restrict partial) {
  gr_reduce_group_long_max(scratch, nsum, 0, partial);
}

/* Ledger fixed point (graupel/reduce.h's gr_fixed, which gives the same
 * integers on the host): a float x adds two integers, coarse = x cut
 * toward zero to a multiple of 2^-24, in units of 2^-24, and fine = the rest
 * (exact as a float, |rest| < 2^-24) cut toward zero to a multiple of 2^-54,
 * in units of 2^-54 (|fine| < 2^30). Sums of them are exact and order-free:
 * the same cells give the same totals however they are split among
 * work-items, work-groups, pieces or devices. |x| >= 2^-31 converts
 * exactly, smaller x to within 2^-54; coarse is clamped to +-2^62 (|x| <
 * 2^38 fits; graupel/reduce.h states the totals' bounds) and fine to +-2^30.
 * Scaling by powers of two is exact, a float cut to an integer converts
 * back exactly, and x - c 2^-24 is exact (c 2^-24 is x cut to a coarser
 * grid), so every device gives these very integers. Conversions toward
 * zero, the fine one to int: PoCL vectorises them (rint doubled the
 * reduction's time again). */
GR_INLINE void gr_fixed_add(long *coarse, long *fine, float x) {
  long c = convert_long(fmin(fmax(x * 16777216.0f, -4611686018427387904.0f), /* 2^24, 2^62 */
                             4611686018427387904.0f));
  float rest = x - convert_float(c) * 5.9604644775390625e-8f; /* 2^-24 */
  *coarse += c;
  *fine += convert_int(fmin(fmax(rest * 18014398509481984.0f, -1073741824.0f), /* 2^54, 2^30 */
                            1073741824.0f));
}

#endif
