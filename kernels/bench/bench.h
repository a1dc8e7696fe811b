/* What graupel-bench needs from a core: each core's bench/bench_<core>.c
 * defines gr_bench_<core>() (the one name the registry in graupel_cores.h
 * gives it), returning how to set the core up on an n by n grid, step it and
 * tear it down. The driver (graupel_bench.c) times the steps. */
#ifndef GRAUPEL_BENCH_H
#define GRAUPEL_BENCH_H

#include "graupel/cl_runtime.h"
#include "graupel_cores.h"

#include <time.h>

typedef struct gr_bench_core {
  /* One line for the usage text: the set-up measured. */
  const char *about;
  /* Sets the core up on an n by n grid; returns the state. */
  gr_status (*setup)(gr_context *ctx, int n, void **state);
  /* Enqueues one step; must not wait for the device. */
  gr_status (*step)(void *state);
  void (*teardown)(void *state);
  /* Bytes a step must move per cell at minimum (reads + writes). */
  double bytes_per_cell;
  /* Optional: further figures, printed after the timed steps. */
  gr_status (*report)(void *state, gr_context *ctx);
} gr_bench_core;

#define GR_BENCH_DECLARE(core) const gr_bench_core *gr_bench_##core(void);
GRAUPEL_CORE_LIST(GR_BENCH_DECLARE)
#undef GR_BENCH_DECLARE

/* Seconds on a monotonic clock. */
static inline double gr_bench_now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#endif
