/**
 * @file reduce.h
 * @brief Deterministic device reductions for the cores that keep a ledger.
 *
 * The device half is kernels/cl/reduce.h: a reduction kernel sums its cells
 * into nsum double-float (hi, lo) pairs and nmax maxima per work-group. This
 * half picks the launch, runs it and adds the groups' partials in group order
 * in double, so the same state gives the same sums on every run.
 */
#ifndef GRAUPEL_REDUCE_H
#define GRAUPEL_REDUCE_H

#include "graupel/cl_runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Most sums and maxima one reduction returns. */
#define GR_REDUCTION_MAX_SLOTS 32

/** One reduction's launch and buffers (zero-initialise before init). */
typedef struct gr_reduction {
  int nsum, nmax;       /**< double-float sums and maxima per group */
  size_t local, groups; /**< work-group size (a power of two) and count */
  cl_mem partial;       /**< (2 nsum + nmax) floats per group */
  float *host;          /**< the partials, read back */
  cl_event pending;     /**< the read-back of a started reduction, until it is finished */
} gr_reduction;

/**
 * Chooses the launch of kernel k over `items` cells (a power-of-two group
 * size of at most 64 that k allows, at most 256 groups: float sums depend
 * on that shape, so every device keeps it; maxima alone, order-free, take
 * up to 1024 groups of 256 on a GPU) and allocates the partials. 2 nsum +
 * nmax must be 1 to GR_REDUCTION_MAX_SLOTS.
 */
GR_API gr_status gr_reduction_init(gr_context *ctx, cl_kernel k, size_t items, int nsum, int nmax,
                                   gr_reduction *r);

/**
 * Runs k (its own arguments already set; this sets `partial` and `scratch`
 * by name), waits, and returns sums[0..nsum-1] (hi + lo of every group, added
 * in group order in double) and maxes[0..nmax-1] (NULL when nmax is 0).
 */
GR_API gr_status gr_reduction_run(gr_context *ctx, gr_reduction *r, cl_kernel k, double *sums,
                                  double *maxes);

/**
 * gr_reduction_run in two halves, so that the host need not wait for the
 * device between them: start enqueues k and the read-back of its partials
 * (and flushes the queue); finish waits for that read and returns what run
 * returns. A started reduction must be finished (or released) before it is
 * started again. finish with sums and maxes NULL only waits.
 */
GR_API gr_status gr_reduction_start(gr_context *ctx, gr_reduction *r, cl_kernel k);
GR_API gr_status gr_reduction_finish(gr_context *ctx, gr_reduction *r, double *sums, double *maxes);

/** Frees the buffers (waiting for a started read first); a zeroed or
 * released reduction is fine. */
GR_API void gr_reduction_release(gr_reduction *r);

/**
 * An integer reduction (cl/reduce.h's gr_reduce_group_long): nsum int64
 * sums per work-group, added on the host in int64. Fixed-point totals that
 * must come out the same however the cells are split (among work-groups, or
 * among the pieces of a domain) use it: integer addition is exact in any
 * order. Zero-initialise before init.
 */
typedef struct gr_reduction_i64 {
  int nsum;             /**< int64 sums per group */
  size_t local, groups; /**< work-group size (a power of two) and count */
  cl_mem partial;       /**< nsum + nmax longs per group */
  long long *host;      /**< the partials, read back */
  int nmax;             /**< int64 maxima per group (gr_reduce_group_long_max) */
} gr_reduction_i64;

/** As gr_reduction_init, for nsum (1 to GR_REDUCTION_MAX_SLOTS) integer sums (order-free: up
 * to 1024 groups of 256 on a GPU). */
GR_API gr_status gr_reduction_i64_init(gr_context *ctx, cl_kernel k, size_t items, int nsum,
                                       gr_reduction_i64 *r);

/**
 * As gr_reduction_i64_init, with nmax integer maxima after the sums (the
 * kernel ends with gr_reduce_group_long_max); nsum + nmax is 1 to
 * GR_REDUCTION_MAX_SLOTS.
 */
GR_API gr_status gr_reduction_i64_init_max(gr_context *ctx, cl_kernel k, size_t items, int nsum,
                                           int nmax, gr_reduction_i64 *r);

/**
 * Runs k (its own arguments already set; this sets `partial` and `scratch`
 * by name), waits, and returns the nsum totals (summed modulo 2^64, as the
 * device sums: beyond the bounds below a total wraps, never overflows).
 */
GR_API gr_status gr_reduction_i64_run(gr_context *ctx, gr_reduction_i64 *r, cl_kernel k,
                                      long long *sums);

/** gr_reduction_i64_run that also returns the nmax maxima (maxes may be NULL when nmax is 0). */
GR_API gr_status gr_reduction_i64_run_max(gr_context *ctx, gr_reduction_i64 *r, cl_kernel k,
                                          long long *sums, long long *maxes);

/** Frees the buffers; a zeroed or released reduction is fine. */
GR_API void gr_reduction_i64_release(gr_reduction_i64 *r);

/**
 * @name Ledger fixed point
 *
 * Totals that must be the same bits however a domain is split (among
 * work-groups, the pieces of an MPI run, or devices) are sums of integers:
 * integer addition is exact in any order. A value x (a float per cell: a
 * depth in m, a rate in m/s) becomes two int64 words, coarse = x cut toward
 * zero to a multiple of 2^-24 (in units of 2^-24) and fine = the rest cut
 * toward zero to a multiple of 2^-54 (in units of 2^-54; |fine| < 2^30), the
 * device's cl/reduce.h gr_fixed_add and gr_fixed_from_float here giving the
 * same integers. So |x| >= 2^-31 is exact and smaller x is within 2^-54 m
 * (5.6e-17): a ledger closes as well as the double-float sums it replaced.
 * Each word is summed on its own.
 *
 * Bounds (int64 totals): the coarse words of n cells stay below 2^63 while
 * sum |x| < 2^39 (5.5e11) units x cells, and the fine words while n <= 2^32
 * (two floats per cell, a value and its Kahan compensation, under 2^31 a
 * cell). For a 65536^2 grid (2^32 cells) that is a mean of 128 m per cell
 * for a depth ledger (stored, infiltrated, outflow, inflow: each on its
 * own); a single cell holds up to 2^38 m.
 *
 * Products (the rain: a rate sum times a step, both exact integers) use
 * gr_wide, a 128-bit integer; gr_fixed_pack / gr_fixed_unpack carry int64s
 * and gr_wides through a gr_allreduce_fn as doubles of 32 bits each, whose
 * sums are exact for fewer than 2^21 pieces.
 * @{
 */

/** The fixed point's two words: value = coarse 2^-24 + fine 2^-54. */
#define GR_FIXED_COARSE_BITS 24
#define GR_FIXED_FINE_BITS 54

/** A fixed-point value or sum (zero-initialise for 0). */
typedef struct gr_fixed {
  long long coarse; /**< units of 2^-GR_FIXED_COARSE_BITS */
  long long fine;   /**< units of 2^-GR_FIXED_FINE_BITS */
} gr_fixed;

/** A signed 128-bit integer, two's complement: hi 2^64 + lo. */
typedef struct gr_wide {
  unsigned long long lo;
  long long hi;
} gr_wide;

/** x as cl/reduce.h's gr_fixed_add adds it on a device (the same integers). */
GR_API gr_fixed gr_fixed_from_float(float x);

/** *sum += x, word by word (exact within the bounds above; modulo 2^64 beyond them). */
GR_API void gr_fixed_add(gr_fixed *sum, gr_fixed x);

/** The value of x (coarse 2^30 + fine, exactly, then rounded once to double). */
GR_API double gr_fixed_value(gr_fixed x);

/** a b exactly. */
GR_API gr_wide gr_wide_mul(long long a, long long b);

/** x m, exact while it fits in 127 bits and a sign. */
GR_API gr_wide gr_wide_scale(gr_wide x, long long m);

/** *sum += x (exact while it fits). */
GR_API void gr_wide_add(gr_wide *sum, gr_wide x);

/** x 2^-frac_bits, rounded once to the nearest double. */
GR_API double gr_wide_value(gr_wide x, int frac_bits);

/** Doubles that gr_fixed_pack writes for nv int64s and nw gr_wides. */
#define GR_FIXED_PACKED(nv, nw) (2 * (nv) + 4 * (nw))

/**
 * Writes v[0..nv-1] and w[0..nw-1] as GR_FIXED_PACKED(nv, nw) doubles, each
 * holding 32 bits (exact integers), for a gr_allreduce_fn with
 * GR_REDUCE_SUM; gr_fixed_unpack turns the summed doubles back into the
 * exact int64 and 128-bit totals (exact for fewer than 2^21 pieces).
 */
GR_API void gr_fixed_pack(const long long *v, int nv, const gr_wide *w, int nw, double *packed);
GR_API void gr_fixed_unpack(const double *packed, long long *v, int nv, gr_wide *w, int nw);
/** @} */

#ifdef __cplusplus
}
#endif

#endif
