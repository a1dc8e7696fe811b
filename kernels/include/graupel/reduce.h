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
 * size of at most 64 that k allows, at most 256 groups) and allocates the
 * partials. 2 nsum + nmax must be 1 to GR_REDUCTION_MAX_SLOTS.
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
  cl_mem partial;       /**< nsum longs per group */
  long long *host;      /**< the partials, read back */
} gr_reduction_i64;

/** As gr_reduction_init, for nsum (1 to GR_REDUCTION_MAX_SLOTS) integer sums. */
GR_API gr_status gr_reduction_i64_init(gr_context *ctx, cl_kernel k, size_t items, int nsum,
                                       gr_reduction_i64 *r);

/**
 * Runs k (its own arguments already set; this sets `partial` and `scratch`
 * by name), waits, and returns the nsum totals.
 */
GR_API gr_status gr_reduction_i64_run(gr_context *ctx, gr_reduction_i64 *r, cl_kernel k,
                                      long long *sums);

/** Frees the buffers; a zeroed or released reduction is fine. */
GR_API void gr_reduction_i64_release(gr_reduction_i64 *r);

#ifdef __cplusplus
}
#endif

#endif
