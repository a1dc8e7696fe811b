/* graupel-bench: speed of every Graupel core on one device.
 *
 *   graupel-bench --core NAME [--size N] [--steps K] [--device SPEC] [--list]
 *                 [--devices D [--verify]]
 *
 * Prints ms per step, million cells per second, and the effective bandwidth
 * as a fraction of a float4 copy kernel measured on the same device in the
 * same run (the practical limit), then one machine-readable line:
 *   core=NAME size=N steps=K ms_per_step=X mcells_per_s=Y bw_fraction=Z device="..."
 * The state stays on the device: steps are enqueued back to back and the
 * clock stops after one clFinish. The cores come from the registry
 * (graupel_cores.h, written from kernels/cores.cmake); each core's set-up and
 * step live in its own bench/bench_<core>.c (see bench.h).
 *
 * --devices D splits the grid into D strips along y, one per OpenCL device
 * (the D devices SPEC or GRAUPEL_DEVICE matches, every GPU by default;
 * pieces share devices where fewer exist), one host thread each, the halo
 * exchange and the allreduce on the host (bench_split.c); --verify then
 * compares every output with one whole grid's after the same steps and
 * fails on any bit of difference. */
#include "bench.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ copy probe */

/* ms per pass of the plain 5-point stencil (bench.cl's bench_stencil5) on
 * an nx x ny grid: the mean of 30 passes after a warm-up one. */
gr_status gr_bench_stencil_ms(gr_context *ctx, int nx, int ny, double *ms) {
  cl_program prog = NULL;
  cl_kernel k = NULL;
  cl_mem buf[2] = {NULL, NULL};
  size_t bytes = (size_t)nx * (size_t)ny * sizeof(float);
  gr_status st = gr_program_get(ctx, "bench", NULL, &prog);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "bench_stencil5", &k);
  for (int a = 0; st == GR_OK && a < 2; ++a)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, &buf[a]);
  float zero = 0.0f;
  for (int a = 0; st == GR_OK && a < 2; ++a)
    st = gr_cl_check(ctx,
                     clEnqueueFillBuffer(gr_context_queue(ctx), buf[a], &zero, sizeof(zero), 0,
                                         bytes, 0, NULL, NULL),
                     "Filling the stencil buffer");
  double t0 = 0.0;
  const int passes = 30;
  for (int p = -1; st == GR_OK && p < passes; ++p) {
    if (p == 0) {
      st = gr_finish(ctx);
      t0 = gr_bench_now_s();
    }
    if (st == GR_OK)
      st = gr_kernel_args(ctx, k, sizeof(cl_mem), &buf[(p + 1) & 1], sizeof(int), &nx, sizeof(int),
                          &ny, sizeof(cl_mem), &buf[p & 1], (size_t)0);
    if (st == GR_OK)
      st = gr_enqueue_2d(ctx, k, 0, 0, (size_t)nx, (size_t)ny, NULL);
  }
  if (st == GR_OK)
    st = gr_finish(ctx);
  if (st == GR_OK)
    *ms = 1e3 * (gr_bench_now_s() - t0) / passes;
  for (int a = 0; a < 2; ++a)
    gr_buffer_release(&buf[a]);
  if (k)
    clReleaseKernel(k);
  return st;
}

/* Bytes per second of a device-to-device float4 copy of at least 64 MiB
 * (or the grid's size if larger), the best of several timed rounds. */
gr_status gr_bench_copy_bandwidth(gr_context *ctx, size_t min_bytes, double *bytes_per_s) {
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
    double t0 = gr_bench_now_s();
    for (int r = 0; st == GR_OK && r < reps; ++r)
      st =
          gr_cl_check(ctx,
                      clEnqueueNDRangeKernel(gr_context_queue(ctx), k, 1, NULL, &global,
                                             gr_context_is_gpu(ctx) ? &local : NULL, 0, NULL, NULL),
                      "Enqueueing the copy kernel");
    if (st == GR_OK)
      st = gr_finish(ctx);
    double dt = gr_bench_now_s() - t0;
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

/* -------------------------------------------------------------- registry */

/* Every core in kernels/cores.cmake, in its order; each brings its own
 * bench/bench_<core>.c. */
typedef struct bench_entry {
  const char *name;
  const gr_bench_core *(*get)(void);
} bench_entry;

#define GR_BENCH_ENTRY(core) {#core, gr_bench_##core},
static const bench_entry cores[] = {GRAUPEL_CORE_LIST(GR_BENCH_ENTRY)};
#undef GR_BENCH_ENTRY
static const int ncores = (int)(sizeof(cores) / sizeof(cores[0]));

static void usage(FILE *f) {
  fprintf(f, "usage: graupel-bench --core NAME [--size N] [--steps K] "
             "[--device gpu|cpu|NAME[:N]] [--list]\n"
             "                     [--devices D [--verify]]   (cores marked *: the grid in D "
             "strips over D devices)\ncores:\n");
  for (int i = 0; i < ncores; ++i)
    fprintf(f, "  %-16s %s%s\n", cores[i].name, cores[i].get()->split ? "* " : "",
            cores[i].get()->about);
}

/* The command line. */
typedef struct bench_args {
  const char *core_name, *device;
  int size, steps, list, devices, verify;
} bench_args;

/* Reads argv into a. Returns -1 to go on, else main's exit status: 0 after
 * --help, 2 after an unknown argument (with the usage on stderr). */
static int parse_args(int argc, char **argv, bench_args *a) {
  a->core_name = a->device = NULL;
  a->size = 1024;
  a->steps = 50;
  a->list = a->devices = a->verify = 0;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--core") == 0 && i + 1 < argc)
      a->core_name = argv[++i];
    else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc)
      a->size = atoi(argv[++i]);
    else if (strcmp(argv[i], "--steps") == 0 && i + 1 < argc)
      a->steps = atoi(argv[++i]);
    else if (strcmp(argv[i], "--device") == 0 && i + 1 < argc)
      a->device = argv[++i];
    else if (strcmp(argv[i], "--devices") == 0 && i + 1 < argc)
      a->devices = atoi(argv[++i]);
    else if (strcmp(argv[i], "--verify") == 0)
      a->verify = 1;
    else if (strcmp(argv[i], "--list") == 0)
      a->list = 1;
    else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
      usage(stdout);
      return 0;
    } else {
      fprintf(stderr, "graupel-bench: unknown argument '%s'.\n", argv[i]);
      usage(stderr);
      return 2;
    }
  }
  return -1;
}

/* --list: every OpenCL device, one a line. */
static int list_devices(void) {
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

/* The core --core names, into *entry and *core, and the other options
 * checked. Returns -1 to go on, else main's exit status (2, the message
 * printed). */
static int check_args(const bench_args *a, const bench_entry **entry, const gr_bench_core **core) {
  *entry = NULL;
  for (int i = 0; a->core_name && i < ncores; ++i)
    if (strcmp(cores[i].name, a->core_name) == 0)
      *entry = &cores[i];
  *core = *entry ? (*entry)->get() : NULL;
  if (!*core || a->size < 1 || a->steps < 1) {
    fprintf(stderr, "graupel-bench: %s.\n",
            !*core ? "name a core with --core" : "--size and --steps must be positive");
    usage(stderr);
    return 2;
  }
  if (a->devices < 0 || a->devices > 64 || (a->verify && a->devices == 0)) {
    fprintf(stderr, "graupel-bench: %s.\n",
            a->verify && a->devices == 0 ? "--verify compares --devices D with one whole grid: "
                                           "add --devices D"
                                         : "--devices takes 1 to 64");
    return 2;
  }
  return -1;
}

/* The copy probe, the core's set-up, two warm-up steps and the timed ones:
 * *elapsed the seconds the timed steps took. */
static gr_status time_steps(gr_context *ctx, const gr_bench_core *core, int size, int steps,
                            double *copy_bps, void **state, double *elapsed) {
  double cells = (double)size * (double)size;
  gr_status st = gr_bench_copy_bandwidth(ctx, (size_t)(cells * 4.0), copy_bps);
  if (st == GR_OK)
    st = core->setup(ctx, size, state);
  /* Warm-up: first launches pay for compilation and first touch. */
  for (int i = 0; st == GR_OK && i < 2; ++i)
    st = core->step(*state);
  if (st == GR_OK)
    st = gr_finish(ctx);
  if (st == GR_OK) {
    double t0 = gr_bench_now_s();
    for (int i = 0; st == GR_OK && i < steps; ++i)
      st = core->step(*state);
    if (st == GR_OK)
      st = gr_finish(ctx);
    *elapsed = gr_bench_now_s() - t0;
  }
  return st;
}

/* The whole grid on one device (no --devices). */
static int run_one_device(const bench_entry *entry, const gr_bench_core *core, int size, int steps,
                          const char *device) {
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
  double copy_bps = 0.0, elapsed = 0.0;
  void *state = NULL;
  gr_status st = time_steps(ctx, core, size, steps, &copy_bps, &state, &elapsed);
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
         entry->name, size, size, steps, ms, mcells, bw / 1e9, frac);
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
         entry->name, size, steps, ms, mcells, frac, dev);
  core->teardown(state);
  gr_context_release(ctx);
  return 0;
}

int main(int argc, char **argv) {
  bench_args a;
  int rc = parse_args(argc, argv, &a);
  if (rc >= 0)
    return rc;
  if (a.list)
    return list_devices();
  const bench_entry *entry = NULL;
  const gr_bench_core *core = NULL;
  rc = check_args(&a, &entry, &core);
  if (rc >= 0)
    return rc;
  if (a.devices > 0)
    return gr_bench_split_run(entry->name, core, a.size, a.steps, a.device, a.devices, a.verify);
  return run_one_device(entry, core, a.size, a.steps, a.device);
}
