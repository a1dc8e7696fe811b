/* Host half of the deterministic device reductions (graupel/reduce.h; the
 * device half is cl/reduce.h). */
#include "graupel/reduce.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Work-groups of a reduction: enough to fill a GPU, few enough that the
 * host's final sum is instant. */
#define GR_REDUCE_GROUPS 256
#define GR_REDUCE_LOCAL 64
/* The launch of a reduction whose result does not depend on how the cells
 * are grouped (integer sums, maxima) on a GPU: 256 groups of 64 items are
 * 16384 items, a few percent of what an H200 runs at once, and such a
 * reduction over 4096^2 cells took 1.5-2 ms (a stream of that size: 0.07
 * ms); 1024 groups of 256 fill it. Float sums keep the fixed shape above,
 * which their bits depend on (CPUs and GPUs agree). */
#define GR_REDUCE_GROUPS_WIDE 1024
#define GR_REDUCE_LOCAL_WIDE 256

/* The work-group size and count of a reduction of `items` cells by kernel
 * k with `slot_bytes` of scratch per item; wide: the result is order-free,
 * so a GPU may take the wide shape. */
static gr_status gr_reduce_shape(gr_context *ctx, cl_kernel k, size_t items, size_t slot_bytes,
                                 int wide, size_t *local, size_t *groups) {
  cl_device_id dev = gr_context_device(ctx);
  size_t kmax = 0;
  cl_device_type type = 0;
  cl_ulong lmem = 0;
  cl_int err =
      clGetKernelWorkGroupInfo(k, dev, CL_KERNEL_WORK_GROUP_SIZE, sizeof(kmax), &kmax, NULL);
  if (err == CL_SUCCESS)
    err = clGetDeviceInfo(dev, CL_DEVICE_TYPE, sizeof(type), &type, NULL);
  if (err == CL_SUCCESS)
    err = clGetDeviceInfo(dev, CL_DEVICE_LOCAL_MEM_SIZE, sizeof(lmem), &lmem, NULL);
  gr_status st = gr_cl_check(ctx, err, "Querying a reduction's work-group size");
  if (st != GR_OK)
    return st;
  wide = wide && (type & CL_DEVICE_TYPE_GPU);
  size_t cap = wide ? GR_REDUCE_LOCAL_WIDE : GR_REDUCE_LOCAL,
         most = wide ? GR_REDUCE_GROUPS_WIDE : GR_REDUCE_GROUPS;
  *local = 1;
  while (*local * 2 <= cap && *local * 2 <= kmax &&
         (!wide || *local * 2 * slot_bytes <= (size_t)lmem / 2))
    *local *= 2;
  *groups = (items + *local - 1) / *local;
  if (*groups > most)
    *groups = most;
  if (*groups < 1)
    *groups = 1;
  return GR_OK;
}

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
  /* maxima alone are order-free; float sums are not */
  gr_status st = gr_reduce_shape(ctx, k, items, (size_t)(2 * nsum + nmax) * sizeof(cl_float),
                                 nsum == 0, &r->local, &r->groups);
  if (st != GR_OK)
    return st;
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

/* a + b modulo 2^64, as the devices' integer sums wrap: within the bounds
 * reduce.h gives it is a + b; beyond them (a damaged or hostile state's
 * values) the total is wrong but defined, where a signed overflow would
 * not be. */
static long long gr_i64_add(long long a, long long b) {
  return (long long)((unsigned long long)a + (unsigned long long)b);
}

gr_status gr_reduction_i64_init(gr_context *ctx, cl_kernel k, size_t items, int nsum,
                                gr_reduction_i64 *r) {
  return gr_reduction_i64_init_max(ctx, k, items, nsum, 0, r);
}

gr_status gr_reduction_i64_init_max(gr_context *ctx, cl_kernel k, size_t items, int nsum, int nmax,
                                    gr_reduction_i64 *r) {
  if (!ctx || !k || !r || nsum < 0 || nmax < 0 || nsum + nmax < 1 ||
      nsum + nmax > GR_REDUCTION_MAX_SLOTS)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_reduction_i64_init needs a context, a kernel, a reduction and 1 to %d "
                        "slots (got %d sums and %d maxima).",
                        GR_REDUCTION_MAX_SLOTS, nsum, nmax);
  memset(r, 0, sizeof(*r));
  r->nsum = nsum;
  r->nmax = nmax;
  const int slots = nsum + nmax;
  gr_status st =
      gr_reduce_shape(ctx, k, items, (size_t)slots * sizeof(cl_long), 1, &r->local, &r->groups);
  if (st != GR_OK)
    return st;
  size_t bytes = r->groups * (size_t)slots * sizeof(cl_long);
  st = gr_buffer_create(ctx, CL_MEM_WRITE_ONLY, bytes, NULL, &r->partial);
  if (st == GR_OK) {
    r->host = malloc(r->groups * (size_t)slots * sizeof(long long));
    if (!r->host)
      st = gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  if (st != GR_OK)
    gr_reduction_i64_release(r);
  return st;
}

gr_status gr_reduction_i64_run(gr_context *ctx, gr_reduction_i64 *r, cl_kernel k, long long *sums) {
  return gr_reduction_i64_run_max(ctx, r, k, sums, NULL);
}

gr_status gr_reduction_i64_run_max(gr_context *ctx, gr_reduction_i64 *r, cl_kernel k,
                                   long long *sums, long long *maxes) {
  if (!ctx || !r || !r->partial || !k || (r->nsum > 0 && !sums) || (r->nmax > 0 && !maxes))
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_reduction_i64_run needs a context, an initialised reduction, its "
                        "kernel and room for the sums and maxima.");
  const int slots = r->nsum + r->nmax;
  gr_status st = gr_kernel_arg(ctx, k, "partial", sizeof(cl_mem), &r->partial);
  if (st == GR_OK)
    st = gr_kernel_arg(ctx, k, "scratch", r->local * (size_t)slots * sizeof(cl_long), NULL);
  size_t global = r->groups * r->local;
  if (st == GR_OK)
    st = gr_cl_check(ctx,
                     clEnqueueNDRangeKernel(gr_context_queue(ctx), k, 1, NULL, &global, &r->local,
                                            0, NULL, NULL),
                     "Enqueueing a reduction");
  if (st == GR_OK)
    st = gr_buffer_read(ctx, r->partial, 0, r->groups * (size_t)slots * sizeof(cl_long), r->host);
  if (st != GR_OK)
    return st;
  for (int q = 0; q < r->nsum; ++q)
    sums[q] = 0;
  for (int q = 0; q < r->nmax; ++q)
    maxes[q] = LLONG_MIN;
  for (size_t grp = 0; grp < r->groups; ++grp) {
    const long long *p = r->host + (size_t)slots * grp;
    for (int q = 0; q < r->nsum; ++q)
      sums[q] = gr_i64_add(sums[q], p[q]);
    for (int q = 0; q < r->nmax; ++q)
      maxes[q] = p[r->nsum + q] > maxes[q] ? p[r->nsum + q] : maxes[q];
  }
  return GR_OK;
}

void gr_reduction_i64_release(gr_reduction_i64 *r) {
  if (!r)
    return;
  gr_buffer_release(&r->partial);
  free(r->host);
  r->host = NULL;
}

/* ---------------------------------------------------------- fixed point */

gr_fixed gr_fixed_from_float(float x) {
  /* cl/reduce.h's gr_fixed_add, step for step: C's conversions cut toward
   * zero as OpenCL's convert_long and convert_int do, and fmaxf / fminf
   * take the number over a NaN as fmax / fmin do. */
  gr_fixed f;
  f.coarse =
      (long long)fminf(fmaxf(x * 16777216.0f, -4611686018427387904.0f), 4611686018427387904.0f);
  float rest = x - (float)f.coarse * 5.9604644775390625e-8f;
  f.fine = (int)fminf(fmaxf(rest * 18014398509481984.0f, -1073741824.0f), 1073741824.0f);
  return f;
}

void gr_fixed_add(gr_fixed *sum, gr_fixed x) {
  sum->coarse = gr_i64_add(sum->coarse, x.coarse);
  sum->fine = gr_i64_add(sum->fine, x.fine);
}

static gr_wide gr_wide_of(long long v) {
  gr_wide w;
  w.lo = (unsigned long long)v;
  w.hi = v < 0 ? -1 : 0;
  return w;
}

void gr_wide_add(gr_wide *sum, gr_wide x) {
  unsigned long long lo = sum->lo + x.lo;
  sum->hi = (long long)((unsigned long long)sum->hi + (unsigned long long)x.hi + (lo < x.lo));
  sum->lo = lo;
}

static gr_wide gr_wide_neg(gr_wide x) {
  gr_wide r;
  r.lo = ~x.lo + 1u;
  r.hi = (long long)(~(unsigned long long)x.hi + (r.lo == 0u));
  return r;
}

/* x 2^32, modulo 2^128. */
static gr_wide gr_wide_shift32(gr_wide x) {
  gr_wide r;
  r.hi = (long long)(((unsigned long long)x.hi << 32) | (x.lo >> 32));
  r.lo = x.lo << 32;
  return r;
}

/* a b for unsigned 64-bit a, b: the high and low words. */
static void gr_umul(unsigned long long a, unsigned long long b, unsigned long long *hi,
                    unsigned long long *lo) {
  const unsigned long long m = 0xffffffffull;
  unsigned long long a0 = a & m, a1 = a >> 32, b0 = b & m, b1 = b >> 32;
  unsigned long long p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
  unsigned long long mid = (p00 >> 32) + (p01 & m) + (p10 & m);
  *lo = (mid << 32) | (p00 & m);
  *hi = p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32);
}

static unsigned long long gr_magnitude(long long v) {
  return v < 0 ? 0ull - (unsigned long long)v : (unsigned long long)v;
}

gr_wide gr_wide_mul(long long a, long long b) {
  gr_wide r;
  unsigned long long hi;
  gr_umul(gr_magnitude(a), gr_magnitude(b), &hi, &r.lo);
  r.hi = (long long)hi;
  return (a < 0) != (b < 0) ? gr_wide_neg(r) : r;
}

gr_wide gr_wide_scale(gr_wide x, long long m) {
  int negative = (x.hi < 0) != (m < 0);
  gr_wide mag = x.hi < 0 ? gr_wide_neg(x) : x;
  unsigned long long um = gr_magnitude(m), hi;
  gr_wide r;
  gr_umul(mag.lo, um, &hi, &r.lo);
  r.hi = (long long)(hi + (unsigned long long)mag.hi * um);
  return negative ? gr_wide_neg(r) : r;
}

double gr_wide_value(gr_wide x, int frac_bits) {
  int negative = x.hi < 0;
  gr_wide mag = negative ? gr_wide_neg(x) : x;
  unsigned long long hi = (unsigned long long)mag.hi, lo = mag.lo;
  double v;
  if (hi == 0u) {
    v = (double)lo;
  } else {
    /* The top 64 bits, the ones below folded into the last (sticky) bit,
     * so that the one conversion to double rounds as the exact value would. */
    int s = 0;
    while (s < 64 && (hi >> s) != 0u)
      ++s;
    unsigned long long top = s == 64 ? hi : (hi << (64 - s)) | (lo >> s);
    unsigned long long below = s == 64 ? lo : lo & ((1ull << s) - 1u);
    v = ldexp((double)(top | (below != 0u)), s);
  }
  v = ldexp(v, -frac_bits);
  return negative ? -v : v;
}

double gr_fixed_value(gr_fixed x) {
  gr_wide w = gr_wide_mul(x.coarse, 1ll << (GR_FIXED_FINE_BITS - GR_FIXED_COARSE_BITS));
  gr_wide_add(&w, gr_wide_of(x.fine));
  return gr_wide_value(w, GR_FIXED_FINE_BITS);
}

/* The 32-bit chunks of an integer, as doubles: the low ones 0 .. 2^32 - 1,
 * the top one signed. */
static double gr_chunk_low(unsigned long long bits) {
  return (double)(bits & 0xffffffffull);
}
static double gr_chunk_top(unsigned long long bits) {
  long long top = (long long)(bits >> 32);
  return (double)(top >= 2147483648ll ? top - 4294967296ll : top);
}

void gr_fixed_pack(const long long *v, int nv, const gr_wide *w, int nw, double *packed) {
  for (int q = 0; q < nv; ++q) {
    unsigned long long u = (unsigned long long)v[q];
    *packed++ = gr_chunk_top(u);
    *packed++ = gr_chunk_low(u);
  }
  for (int q = 0; q < nw; ++q) {
    unsigned long long hi = (unsigned long long)w[q].hi;
    *packed++ = gr_chunk_top(hi);
    *packed++ = gr_chunk_low(hi);
    *packed++ = gr_chunk_low(w[q].lo >> 32);
    *packed++ = gr_chunk_low(w[q].lo);
  }
}

void gr_fixed_unpack(const double *packed, long long *v, int nv, gr_wide *w, int nw) {
  /* Each chunk's sum is an exact integer below 2^53; the totals follow
   * modulo 2^64 (2^128), which gives the true ones when they fit. */
  for (int q = 0; q < nv; ++q, packed += 2) {
    unsigned long long u =
        ((unsigned long long)(long long)packed[0] << 32) + (unsigned long long)(long long)packed[1];
    v[q] = (long long)u;
  }
  for (int q = 0; q < nw; ++q, packed += 4) {
    gr_wide r = gr_wide_of((long long)packed[0]);
    for (int c = 1; c < 4; ++c) {
      r = gr_wide_shift32(r);
      gr_wide_add(&r, gr_wide_of((long long)packed[c]));
    }
    w[q] = r;
  }
}
