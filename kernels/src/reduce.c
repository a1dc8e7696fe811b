/* Host half of the deterministic device reductions (graupel/reduce.h; the
 * device half is cl/reduce.h). */
#include "graupel/reduce.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Work-groups of a reduction: enough to fill a GPU, few enough that the
 * host's final sum is instant. */
#define GR_REDUCE_GROUPS 256
#define GR_REDUCE_LOCAL 64

gr_status gr_reduction_init(gr_context *ctx, cl_kernel k, size_t items, int nsum, int nmax,
                            gr_reduction *r) {
  if (!ctx || !k || !r || nsum < 0 || nmax < 0 || 2 * nsum + nmax < 1 ||
      2 * nsum + nmax > GR_REDUCTION_MAX_SLOTS)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_reduction_init needs a context, a kernel, a reduction and 1 to %d "
                        "slots (got %d sums and %d maxima).",
                        GR_REDUCTION_MAX_SLOTS, nsum, nmax);
  memset(r, 0, sizeof(*r));
  r->nsum = nsum;
  r->nmax = nmax;
  size_t kmax = 0;
  gr_status st =
      gr_cl_check(ctx,
                  clGetKernelWorkGroupInfo(k, gr_context_device(ctx), CL_KERNEL_WORK_GROUP_SIZE,
                                           sizeof(kmax), &kmax, NULL),
                  "Querying a reduction's work-group size");
  if (st != GR_OK)
    return st;
  r->local = 1;
  while (r->local * 2 <= GR_REDUCE_LOCAL && r->local * 2 <= kmax)
    r->local *= 2;
  r->groups = (items + r->local - 1) / r->local;
  if (r->groups > GR_REDUCE_GROUPS)
    r->groups = GR_REDUCE_GROUPS;
  if (r->groups < 1)
    r->groups = 1;
  size_t bytes = r->groups * (size_t)(2 * nsum + nmax) * sizeof(cl_float);
  st = gr_buffer_create(ctx, CL_MEM_WRITE_ONLY, bytes, NULL, &r->partial);
  if (st == GR_OK) {
    r->host = malloc(bytes);
    if (!r->host)
      st = gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  if (st != GR_OK)
    gr_reduction_release(r);
  return st;
}

gr_status gr_reduction_start(gr_context *ctx, gr_reduction *r, cl_kernel k) {
  if (!ctx || !r || !r->partial || !k || r->pending)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_reduction_start needs a context, an initialised reduction that is not "
                        "already started, and its kernel.");
  const int slots = 2 * r->nsum + r->nmax;
  gr_status st = gr_kernel_arg(ctx, k, "partial", sizeof(cl_mem), &r->partial);
  if (st == GR_OK)
    st = gr_kernel_arg(ctx, k, "scratch", r->local * (size_t)slots * sizeof(cl_float), NULL);
  size_t global = r->groups * r->local;
  cl_command_queue q = gr_context_queue(ctx);
  if (st == GR_OK)
    st = gr_cl_check(ctx, clEnqueueNDRangeKernel(q, k, 1, NULL, &global, &r->local, 0, NULL, NULL),
                     "Enqueueing a reduction");
  if (st == GR_OK)
    st = gr_cl_check(ctx,
                     clEnqueueReadBuffer(q, r->partial, CL_FALSE, 0,
                                         r->groups * (size_t)slots * sizeof(cl_float), r->host, 0,
                                         NULL, &r->pending),
                     "Reading a reduction's partials back");
  if (st == GR_OK)
    st = gr_cl_check(ctx, clFlush(q), "Flushing the queue after a reduction");
  return st;
}

gr_status gr_reduction_finish(gr_context *ctx, gr_reduction *r, double *sums, double *maxes) {
  if (!ctx || !r || !r->pending)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_reduction_finish needs a context and a started reduction.");
  gr_status st =
      gr_cl_check(ctx, clWaitForEvents(1, &r->pending), "Waiting for a reduction's partials");
  clReleaseEvent(r->pending);
  r->pending = NULL;
  if (st != GR_OK || (!sums && !maxes))
    return st;
  if ((r->nsum > 0 && !sums) || (r->nmax > 0 && !maxes))
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_reduction_finish needs room for the results.");
  /* In group order, in double: the same partials give the same bits. The
   * maxima start at -inf, below every group's own start value. */
  const int slots = 2 * r->nsum + r->nmax;
  for (int q = 0; q < r->nsum; ++q)
    sums[q] = 0.0;
  for (int q = 0; q < r->nmax; ++q)
    maxes[q] = -HUGE_VAL;
  for (size_t grp = 0; grp < r->groups; ++grp) {
    const float *p = r->host + (size_t)slots * grp;
    for (int q = 0; q < r->nsum; ++q)
      sums[q] += (double)p[2 * q] + (double)p[2 * q + 1];
    for (int q = 0; q < r->nmax; ++q)
      maxes[q] = p[2 * r->nsum + q] > maxes[q] ? p[2 * r->nsum + q] : maxes[q];
  }
  return GR_OK;
}

gr_status gr_reduction_run(gr_context *ctx, gr_reduction *r, cl_kernel k, double *sums,
                           double *maxes) {
  if (!ctx || !r || !r->partial || !k || (r->nsum > 0 && !sums) || (r->nmax > 0 && !maxes))
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_reduction_run needs a context, an initialised reduction, its kernel "
                        "and room for the results.");
  gr_status st = gr_reduction_start(ctx, r, k);
  if (st != GR_OK) {
    if (r->pending)
      gr_reduction_finish(ctx, r, NULL, NULL);
    return st;
  }
  return gr_reduction_finish(ctx, r, sums, maxes);
}

void gr_reduction_release(gr_reduction *r) {
  if (!r)
    return;
  if (r->pending) {
    clWaitForEvents(1, &r->pending);
    clReleaseEvent(r->pending);
    r->pending = NULL;
  }
  gr_buffer_release(&r->partial);
  free(r->host);
  r->host = NULL;
}

/* ------------------------------------------------------ integer reductions */

gr_status gr_reduction_i64_init(gr_context *ctx, cl_kernel k, size_t items, int nsum,
                                gr_reduction_i64 *r) {
  if (!ctx || !k || !r || nsum < 1 || nsum > GR_REDUCTION_MAX_SLOTS)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_reduction_i64_init needs a context, a kernel, a reduction and 1 to %d "
                        "sums (got %d).",
                        GR_REDUCTION_MAX_SLOTS, nsum);
  memset(r, 0, sizeof(*r));
  r->nsum = nsum;
  size_t kmax = 0;
  gr_status st =
      gr_cl_check(ctx,
                  clGetKernelWorkGroupInfo(k, gr_context_device(ctx), CL_KERNEL_WORK_GROUP_SIZE,
                                           sizeof(kmax), &kmax, NULL),
                  "Querying a reduction's work-group size");
  if (st != GR_OK)
    return st;
  r->local = 1;
  while (r->local * 2 <= GR_REDUCE_LOCAL && r->local * 2 <= kmax)
    r->local *= 2;
  r->groups = (items + r->local - 1) / r->local;
  if (r->groups > GR_REDUCE_GROUPS)
    r->groups = GR_REDUCE_GROUPS;
  if (r->groups < 1)
    r->groups = 1;
  size_t bytes = r->groups * (size_t)nsum * sizeof(cl_long);
  st = gr_buffer_create(ctx, CL_MEM_WRITE_ONLY, bytes, NULL, &r->partial);
  if (st == GR_OK) {
    r->host = malloc(r->groups * (size_t)nsum * sizeof(long long));
    if (!r->host)
      st = gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  if (st != GR_OK)
    gr_reduction_i64_release(r);
  return st;
}

gr_status gr_reduction_i64_run(gr_context *ctx, gr_reduction_i64 *r, cl_kernel k, long long *sums) {
  if (!ctx || !r || !r->partial || !k || !sums)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_reduction_i64_run needs a context, an initialised reduction, its "
                        "kernel and room for the sums.");
  gr_status st = gr_kernel_arg(ctx, k, "partial", sizeof(cl_mem), &r->partial);
  if (st == GR_OK)
    st = gr_kernel_arg(ctx, k, "scratch", r->local * (size_t)r->nsum * sizeof(cl_long), NULL);
  size_t global = r->groups * r->local;
  if (st == GR_OK)
    st = gr_cl_check(ctx,
                     clEnqueueNDRangeKernel(gr_context_queue(ctx), k, 1, NULL, &global, &r->local,
                                            0, NULL, NULL),
                     "Enqueueing a reduction");
  if (st == GR_OK)
    st = gr_buffer_read(ctx, r->partial, 0, r->groups * (size_t)r->nsum * sizeof(cl_long), r->host);
  if (st != GR_OK)
    return st;
  for (int q = 0; q < r->nsum; ++q)
    sums[q] = 0;
  for (size_t grp = 0; grp < r->groups; ++grp)
    for (int q = 0; q < r->nsum; ++q)
      sums[q] += r->host[(size_t)r->nsum * grp + q];
  return GR_OK;
}

void gr_reduction_i64_release(gr_reduction_i64 *r) {
  if (!r)
    return;
  gr_buffer_release(&r->partial);
  free(r->host);
  r->host = NULL;
}
