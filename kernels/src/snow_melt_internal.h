/* Snow melt core, host side, private to its files: snow_melt.c (parameters,
 * the handle, creation, inputs, the terrain's horizons) and snow_melt_step.c
 * (the sun, stepping, outputs, the ledger, reset, checkpoints). */
#ifndef GRAUPEL_SNOW_MELT_INTERNAL_H
#define GRAUPEL_SNOW_MELT_INTERNAL_H

#include "graupel/snow_melt.h"
#include "graupel/cl_runtime.h"
#include "graupel/reduce.h"
#include "runtime_internal.h"
#include "snow_melt_shared.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

struct gr_snow_melt {
  gr_context *ctx;
  /* The local arrays (set_field's) are nx x (own_ny + rings); the device
   * holds the own rows only (a step reads nothing beyond its point). */
  gr_grid grid;
  int gnx, gny, own_ny, ring_s, ring_n;
  size_t n; /* own points */
  gr_allreduce_fn allreduce;
  void *allreduce_user;
  gr_snow_melt_params params;
  gr_snow_melt_forcing forcing;
  cl_kernel horizon_k, step_k, reduce_k, derive_k;
  cl_mem frozen, liquid, density, radiation, acc; /* the state and its accumulators */
  cl_mem elevation, normal, horizon, temperature, precipitation, table, scratch;
  int has_terrain, has_temperature, has_precipitation;
  /* The initial snow (own points), as set; state_ready: the device holds a
   * state (set from it at the first step after a change or reset, or loaded). */
  float *depth, *snow_density;
  int state_ready;
  gr_wide initial; /* the initial frozen water's integers */
  double time, mark_time;
  long long steps;
  float *records; /* a batch of the sun's records, on the host */
  gr_reduction_i64 ledger;
  gr_progress_fn progress;
  void *progress_user;
  char error[1024];
};

#define GR_SM_KEEP(s, st) gr_error_keep((s)->error, sizeof((s)->error), (st))

/* One kernel argument by its name in the kernel's source. */
typedef struct gr_sm_arg {
  const char *name;
  size_t size;
  const void *value;
} gr_sm_arg;

gr_status gr_sm_args(gr_snow_melt *s, cl_kernel k, const gr_sm_arg *args, size_t n);
#define GR_SM_ARGS(s, k, args) gr_sm_args((s), (k), (args), sizeof(args) / sizeof((args)[0]))

/* Enqueues a 1-D kernel over the n own points. */
gr_status gr_sm_enqueue(gr_snow_melt *s, cl_kernel k);

/* Fills bytes of buf with zeros, enqueued. */
gr_status gr_sm_zero(gr_snow_melt *s, cl_mem buf, size_t bytes);

/* Uploads the initial snow as the state (liquid 0, accumulators 0) when the
 * device holds none. */
gr_status gr_sm_prepare(gr_snow_melt *s);

/* The caller's allreduce, its failure a sentence. */
gr_status gr_sm_allreduce(gr_snow_melt *s, double *v, int n, gr_reduce_op op);

#endif
