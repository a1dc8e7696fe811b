/* What graupel-bench needs from a core: each core's bench/bench_<core>.c
 * defines gr_bench_<core>() (the one name the registry in graupel_cores.h
 * gives it), returning how to set the core up on an n by n grid, step it and
 * tear it down. The driver (graupel_bench.c) times the steps. */
#ifndef GRAUPEL_BENCH_H
#define GRAUPEL_BENCH_H

#include "graupel/cl_runtime.h"
#include "graupel_cores.h"

#include <time.h>

/* The callbacks that tie one piece of a split domain to the others (see
 * gr_allreduce_fn, gr_halo_exchange_fn): bench_split.c's host exchange. */
typedef struct gr_bench_link {
  gr_allreduce_fn allreduce;
  void *allreduce_user;
  gr_halo_exchange_fn exchange;
  void *exchange_user;
} gr_bench_link;

/* Sides of a strip for the halo calls: every core's side enum numbers them
 * so (west 0, east 1, south 2, north 3). */
enum { GR_BENCH_SOUTH = 2, GR_BENCH_NORTH = 3 };

/* What graupel-bench --devices K needs from a core that runs as pieces of
 * a split domain: the grid cut into K strips along y, one host thread and
 * one context per piece (bench_split.c). The piece's state is the core's
 * own: step, teardown and report of gr_bench_core apply to it. */
typedef struct gr_bench_split {
  /* Rows j0 .. j0 + ny - 1 of setup's n by n set-up, with the ring the core
   * needs toward each neighbour; j0 = 0, ny = n is the whole grid (no ring,
   * link unused: the reference of --verify). Collective: every piece calls
   * it, since set-up may read a global value (the stable step). */
  gr_status (*setup)(gr_context *ctx, int n, int j0, int ny, const gr_bench_link *link,
                     void **state);
  /* Ring rows toward a neighbour, for the set-up setup will make. */
  int (*ring)(void);
  /* The core's halo calls on the piece (sides: GR_BENCH_SOUTH, _NORTH). */
  gr_status (*halo_size)(void *state, int side, size_t *bytes);
  gr_status (*halo_get)(void *state, int side, void *host, size_t bytes);
  gr_status (*halo_set)(void *state, int side, const void *host, size_t bytes);
  /* The outputs --verify compares, count of them: output i's name, floats
   * per cell, and (host not NULL) the owned cells (row-major, components
   * innermost); with host NULL, state may be NULL. */
  int outputs;
  gr_status (*output)(void *state, int i, const char **name, int *components, float *host);
  /* Optional, collective: one line on the state after the run (a ledger:
   * global through the allreduce); the first piece's is printed. */
  gr_status (*summary)(void *state, char *line, size_t len);
  /* The piece's latest error ("" if none). */
  const char *(*last_error)(void *state);
  /* Optional, collective: a few more steps with the core's per-stage timing
   * on, one line of the piece's stages (ms a step); printed per piece. */
  gr_status (*stages)(void *state, char *line, size_t len);
} gr_bench_split;

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
  /* Optional: how the core runs as pieces (--devices); NULL: it does not. */
  const gr_bench_split *split;
} gr_bench_core;

#define GR_BENCH_DECLARE(core) const gr_bench_core *gr_bench_##core(void);
GRAUPEL_CORE_LIST(GR_BENCH_DECLARE)
#undef GR_BENCH_DECLARE

/* The float4 copy rate of ctx's device, bytes per second (the practical
 * limit the bandwidth fraction is of); buffers of at least min_bytes. */
gr_status gr_bench_copy_bandwidth(gr_context *ctx, size_t min_bytes, double *bytes_per_s);

/* ms per pass of a plain 5-point stencil on an nx x ny grid of ctx's device,
 * the yardstick a core's step is counted in (issues 8 and 10: timed in the
 * same run as the steps, so that a busy machine slows both). */
gr_status gr_bench_stencil_ms(gr_context *ctx, int nx, int ny, double *ms);

/* graupel-bench --devices K (bench_split.c): the core's set-up split into K
 * strips over the devices `device` names (every GPU, ...); prints the
 * figures and, with verify, compares with one whole grid. Returns the exit
 * status. */
int gr_bench_split_run(const char *name, const gr_bench_core *core, int n, int steps,
                       const char *device, int k, int verify);

/* Seconds on a monotonic clock. */
static inline double gr_bench_now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#endif
