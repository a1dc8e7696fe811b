/* graupel-bench: speed of every Graupel core on one device.
 *
 *   graupel-bench --core NAME [--size N] [--steps K] [--device SPEC] [--list]
 *
 * Prints ms per step, million cells per second, and the effective bandwidth
 * as a fraction of a float4 copy kernel measured on the same device in the
 * same run (the practical limit), then one machine-readable line:
 *   core=NAME size=N steps=K ms_per_step=X mcells_per_s=Y bw_fraction=Z device="..."
 * The state stays on the device: steps are enqueued back to back and the
 * clock stops after one clFinish. */
#include "graupel/cl_runtime.h"
#include "graupel/rain_runoff.h"
#include "graupel/procedural_terrain.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ------------------------------------------------------------ copy probe */

/* Bytes per second of a device-to-device float4 copy of at least 64 MiB
 * (or the grid's size if larger), the best of several timed rounds. */
static gr_status copy_bandwidth(gr_context *ctx, size_t min_bytes, double *bytes_per_s) {
  size_t bytes = (size_t)64 << 20;
  if (min_bytes > bytes)
    bytes = min_bytes;
  gr_device_info info;
  gr_context_device_info(ctx, &info);
  while (bytes > info.max_alloc_bytes / 2 && bytes > ((size_t)1 << 20))
    bytes /= 2;
  bytes &= ~(size_t)15;
  cl_mem src = NULL, dst = NULL;
  cl_kernel k = NULL;
  cl_program prog = NULL;
  gr_status st = gr_program_get(ctx, "bench", NULL, &prog);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "bench_copy", &k);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, &src);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, &dst);
  cl_int n4 = (cl_int)(bytes / 16);
  if (st == GR_OK) {
    const cl_float zero = 0.0f;
    st = gr_cl_check(ctx,
                     clEnqueueFillBuffer(gr_context_queue(ctx), src, &zero, sizeof(zero), 0, bytes,
                                         0, NULL, NULL),
                     "Filling the copy buffer");
  }
  if (st == GR_OK)
    st = gr_kernel_args(ctx, k, sizeof(cl_mem), &src, sizeof(cl_mem), &dst, sizeof(cl_int), &n4,
                        (size_t)0);
  double best = 0.0;
  size_t local = 256;
  size_t global = ((size_t)n4 + local - 1) / local * local;
  for (int round = 0; st == GR_OK && round < 6; ++round) {
    int reps = 10;
    st = gr_finish(ctx);
    double t0 = now_s();
    for (int r = 0; st == GR_OK && r < reps; ++r)
      st =
          gr_cl_check(ctx,
                      clEnqueueNDRangeKernel(gr_context_queue(ctx), k, 1, NULL, &global,
                                             gr_context_is_gpu(ctx) ? &local : NULL, 0, NULL, NULL),
                      "Enqueueing the copy kernel");
    if (st == GR_OK)
      st = gr_finish(ctx);
    double dt = now_s() - t0;
    double bw = 2.0 * (double)bytes * reps / dt; /* one read, one write */
    if (round > 0 && bw > best)                  /* round 0 warms up */
      best = bw;
  }
  if (k)
    clReleaseKernel(k);
  gr_buffer_release(&src);
  gr_buffer_release(&dst);
  *bytes_per_s = best;
  return st;
}

/* ----------------------------------------------------------------- cores */

typedef struct bench_core {
  const char *name;
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
} bench_core;

static gr_status terrain_setup(gr_context *ctx, int n, void **state) {
  gr_grid g = {n, n, 2.0, 2.0, 0.0, 0.0};
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  return gr_procedural_terrain_create(ctx, &g, &p, (gr_procedural_terrain **)state);
}
static gr_status terrain_step(void *state) {
  return gr_procedural_terrain_compute(state);
}
static void terrain_teardown(void *state) {
  gr_procedural_terrain_destroy(state);
}

/* Rain runoff: a bowl tilted towards x = 0 (5 m deep over the grid's
 * half-width, 1 % slope), 5 cm of water everywhere so that every face
 * flows from the first step, 50 mm/h of rain, 5 mm/h of infiltration, an
 * open boundary; a fixed stable step taken once at set-up. */
typedef struct rain_runoff_bench {
  gr_rain_runoff *sim;
  double dt;
} rain_runoff_bench;

static void rain_runoff_teardown(void *state) {
  rain_runoff_bench *r = state;
  if (r)
    gr_rain_runoff_destroy(r->sim);
  free(r);
}

static gr_status rain_runoff_setup(gr_context *ctx, int n, void **state) {
  gr_grid g = {n, n, 2.0, 2.0, 0.0, 0.0, 0, 0};
  gr_rain_runoff_params p;
  gr_rain_runoff_params_init(&p);
  p.rain_rate = 50.0 / 3.6e6;
  p.permeability = 5.0 / 3.6e6;
  p.max_dt = 0.25; /* stays stable while the bowl fills during the run */
  rain_runoff_bench *r = calloc(1, sizeof(*r));
  size_t cells = (size_t)n * (size_t)n;
  float *b = malloc(cells * sizeof(float)), *d = malloc(cells * sizeof(float));
  if (!r || !b || !d) {
    free(r);
    free(b);
    free(d);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  double half = 0.5 * (n - 1);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double x = (i - half) / (half > 0.0 ? half : 1.0), y = (j - half) / (half > 0.0 ? half : 1.0);
      b[(size_t)j * n + i] = (float)(5.0 * (x * x + y * y) + 0.01 * i * g.dx);
      d[(size_t)j * n + i] = 0.05f;
    }
  gr_status st = gr_rain_runoff_create(ctx, &g, &p, &r->sim);
  if (st == GR_OK)
    st = gr_rain_runoff_set_field(r->sim, GR_FIELD_ELEVATION, b);
  if (st == GR_OK)
    st = gr_rain_runoff_set_field(r->sim, GR_FIELD_WATER_DEPTH, d);
  if (st == GR_OK)
    st = gr_rain_runoff_stable_dt(r->sim, &r->dt);
  free(b);
  free(d);
  if (st != GR_OK) {
    rain_runoff_teardown(r);
    return st;
  }
  *state = r;
  return GR_OK;
}

static gr_status rain_runoff_step(void *state) {
  rain_runoff_bench *r = state;
  return gr_rain_runoff_step(r->sim, r->dt, 1);
}

/* What a caller pays besides the steps: the ledger (one reduction and its
 * read-back) and the stable step (the same reduction). */
static gr_status rain_runoff_report(void *state, gr_context *ctx) {
  rain_runoff_bench *r = state;
  gr_rain_runoff_ledger l;
  gr_status st = gr_rain_runoff_ledger_get(r->sim, &l); /* warm-up */
  const int reps = 10;
  double t0 = now_s();
  for (int i = 0; st == GR_OK && i < reps; ++i)
    st = gr_rain_runoff_ledger_get(r->sim, &l);
  double t1 = now_s();
  if (st == GR_OK)
    printf("rain_runoff: ledger (reduction and read-back) %.4f ms; dt %.4g s; after the run "
           "%.4g m^3 stored, %.4g m^3 out, balance %.3g of the water in\n",
           1e3 * (t1 - t0) / reps, r->dt, l.stored_volume, l.outflow_volume,
           fabs(l.balance_error) / (l.initial_volume + l.rain_volume));
  (void)ctx;
  return st;
}

static const bench_core cores[] = {
    {"procedural_terrain", "procedural terrain, 6-octave inverted ridged multifractal (seed 001)",
     terrain_setup, terrain_step, terrain_teardown, 4.0, NULL},
    /* Per cell and step, each array once per launch (neighbours come from
     * cache): flux reads depth, elevation, the old discharges and the
     * limiter and writes the new discharges (28 B); limit reads depth and
     * discharges and writes the limiter (16 B); update reads depth and its
     * compensation, discharges, limiter, infiltrated and its compensation
     * and writes depth, infiltrated and their compensations (44 B). */
    {"rain_runoff",
     "rain on a tilted bowl: local inertial runoff, infiltration, open boundary (seed 004)",
     rain_runoff_setup, rain_runoff_step, rain_runoff_teardown, 88.0, rain_runoff_report},
};
static const int ncores = (int)(sizeof(cores) / sizeof(cores[0]));

static void usage(FILE *f) {
  fprintf(f, "usage: graupel-bench --core NAME [--size N] [--steps K] "
             "[--device gpu|cpu|NAME] [--list]\ncores:\n");
  for (int i = 0; i < ncores; ++i)
    fprintf(f, "  %-16s %s\n", cores[i].name, cores[i].about);
}

int main(int argc, char **argv) {
  const char *core_name = NULL, *device = NULL;
  int size = 1024, steps = 50, list = 0;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--core") == 0 && i + 1 < argc)
      core_name = argv[++i];
    else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc)
      size = atoi(argv[++i]);
    else if (strcmp(argv[i], "--steps") == 0 && i + 1 < argc)
      steps = atoi(argv[++i]);
    else if (strcmp(argv[i], "--device") == 0 && i + 1 < argc)
      device = argv[++i];
    else if (strcmp(argv[i], "--list") == 0)
      list = 1;
    else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
      usage(stdout);
      return 0;
    } else {
      fprintf(stderr, "graupel-bench: unknown argument '%s'.\n", argv[i]);
      usage(stderr);
      return 2;
    }
  }
  if (list) {
    int count = 0;
    gr_device_info infos[16];
    if (gr_device_list(infos, 16, &count) != GR_OK) {
      fprintf(stderr, "graupel-bench: %s\n", gr_last_error(NULL));
      return 1;
    }
    for (int i = 0; i < count && i < 16; ++i)
      printf("%d: %s | %s | %s | %d CUs | %.0f MiB\n", i, infos[i].name, infos[i].platform,
             infos[i].is_gpu ? "GPU" : "CPU", infos[i].compute_units,
             (double)infos[i].global_mem_bytes / 1048576.0);
    return 0;
  }
  const bench_core *core = NULL;
  for (int i = 0; core_name && i < ncores; ++i)
    if (strcmp(cores[i].name, core_name) == 0)
      core = &cores[i];
  if (!core || size < 1 || steps < 1) {
    fprintf(stderr, "graupel-bench: %s.\n",
            !core ? "name a core with --core" : "--size and --steps must be positive");
    usage(stderr);
    return 2;
  }

  gr_context_options opt;
  gr_context_options_init(&opt);
  opt.device = device;
  gr_context *ctx = NULL;
  if (gr_context_create(&opt, &ctx) != GR_OK) {
    fprintf(stderr, "graupel-bench: %s\n", gr_last_error(NULL));
    return 1;
  }
  const char *dev = gr_context_device_name(ctx);
  double cells = (double)size * (double)size;
  double copy_bps = 0.0;
  void *state = NULL;
  gr_status st = copy_bandwidth(ctx, (size_t)(cells * 4.0), &copy_bps);
  if (st == GR_OK)
    st = core->setup(ctx, size, &state);
  /* Warm-up: first launches pay for compilation and first touch. */
  for (int i = 0; st == GR_OK && i < 2; ++i)
    st = core->step(state);
  if (st == GR_OK)
    st = gr_finish(ctx);
  double elapsed = 0.0;
  if (st == GR_OK) {
    double t0 = now_s();
    for (int i = 0; st == GR_OK && i < steps; ++i)
      st = core->step(state);
    if (st == GR_OK)
      st = gr_finish(ctx);
    elapsed = now_s() - t0;
  }
  if (st != GR_OK) {
    fprintf(stderr, "graupel-bench: %s\n", gr_last_error(ctx));
    if (state)
      core->teardown(state);
    gr_context_release(ctx);
    return 1;
  }
  double ms = 1e3 * elapsed / steps;
  double mcells = cells / (elapsed / steps) / 1e6;
  double bw = core->bytes_per_cell * cells / (elapsed / steps);
  double frac = copy_bps > 0.0 ? bw / copy_bps : 0.0;
  printf("device: %s (%s)\n", dev, gr_context_platform_name(ctx));
  printf("copy probe: %.1f GB/s\n", copy_bps / 1e9);
  printf("%s: %d x %d, %d steps: %.4f ms/step, %.1f Mcells/s, %.2f GB/s "
         "(%.3f of copy)\n",
         core->name, size, size, steps, ms, mcells, bw / 1e9, frac);
  if (core->report) {
    st = core->report(state, ctx);
    if (st != GR_OK) {
      fprintf(stderr, "graupel-bench: %s\n", gr_last_error(ctx));
      core->teardown(state);
      gr_context_release(ctx);
      return 1;
    }
  }
  printf("core=%s size=%d steps=%d ms_per_step=%.6g mcells_per_s=%.6g "
         "bw_fraction=%.4g device=\"%s\"\n",
         core->name, size, steps, ms, mcells, frac, dev);
  core->teardown(state);
  gr_context_release(ctx);
  return 0;
}
