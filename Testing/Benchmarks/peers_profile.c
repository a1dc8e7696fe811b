/* Where Rain Runoff's time goes on the real DEM (peers.py --profile builds and
 * runs it against the core library of a Graupel build).
 *
 *   peers_profile DEM.f32 NX NY DX DY HOURS RAIN_MM_H MANNING FLOW_MODEL MAX_DT [PLAIN]
 *
 * DEM.f32: NX * NY floats, row 0 south. It times the context, the set-up
 * (gr_rain_runoff_create: the program build) and the first step, then
 * advances HOURS the way gr_rain_runoff_advance does (the stable step read
 * back, then 1 to 64 steps, doubling while it holds), but with the stretches
 * apart: each stretch of steps is waited for (a one-point sample), so
 * "stepping" is the steps' own time and "read-backs" the stable step's
 * reduction and read on an idle queue. It also counts how often the step
 * was MaxTimeStep (the cap) rather than the Courant limit, and finishes
 * with gr_rain_runoff_advance over the same time from the start for the
 * plain figure (PLAIN 0 leaves it out). */
#define _POSIX_C_SOURCE 199309L
#include <graupel/rain_runoff.h>
#include <graupel/runtime.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double clock_s(clockid_t id) {
  struct timespec ts;
  clock_gettime(id, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static double now(void) {
  return clock_s(CLOCK_MONOTONIC);
}
/* The process's CPU time, PoCL's worker threads included: on a shared
 * machine it moves less with the load than the wall clock. */
static double cpu(void) {
  return clock_s(CLOCK_PROCESS_CPUTIME_ID);
}

#define CHECK(call)                                                                                \
  do {                                                                                             \
    gr_status st_ = (call);                                                                        \
    if (st_ != GR_OK) {                                                                            \
      fprintf(stderr, "%s: %s\n", #call, sim ? gr_rain_runoff_last_error(sim) : "failed");         \
      return 1;                                                                                    \
    }                                                                                              \
  } while (0)

int main(int argc, char **argv) {
  if (argc != 11 && argc != 12) {
    fprintf(stderr,
            "usage: %s DEM.f32 NX NY DX DY HOURS RAIN_MM_H MANNING FLOW_MODEL MAX_DT [PLAIN]\n",
            argv[0]);
    return 2;
  }
  int nx = atoi(argv[2]), ny = atoi(argv[3]), model = atoi(argv[9]);
  double dx = atof(argv[4]), dy = atof(argv[5]), duration = atof(argv[6]) * 3600.0;
  size_t n = (size_t)nx * (size_t)ny;
  float *z = malloc(n * sizeof(float));
  FILE *fp = fopen(argv[1], "rb");
  if (!z || !fp || fread(z, sizeof(float), n, fp) != n) {
    fprintf(stderr, "cannot read %zu floats from %s\n", n, argv[1]);
    return 1;
  }
  fclose(fp);
  gr_rain_runoff *sim = NULL;
  double t0 = now();
  gr_context_options opt;
  gr_context_options_init(&opt);
  gr_context *ctx = NULL;
  CHECK(gr_context_create(&opt, &ctx));
  double t_context = now() - t0;
  gr_grid g = {.nx = nx, .ny = ny, .dx = dx, .dy = dy};
  gr_rain_runoff_params p;
  gr_rain_runoff_params_init(&p);
  p.rain_rate = atof(argv[7]) / 3.6e6;
  p.manning_n = atof(argv[8]);
  p.flow_model = model ? GR_FLOW_LOCAL_INERTIAL : GR_FLOW_SHALLOW_WATER;
  p.max_dt = atof(argv[10]);
  t0 = now();
  CHECK(gr_rain_runoff_create(ctx, &g, &p, &sim));
  double t_create = now() - t0;
  t0 = now();
  CHECK(gr_rain_runoff_set_field(sim, GR_FIELD_ELEVATION, z));
  double t_upload = now() - t0;

  int ij[2] = {nx / 2, ny / 2};
  float probe[4];
  /* The first step and a read-back, twice: PoCL builds each kernel's
   * work-group function at its first launch of a size. */
  double dt = 0.0;
  t0 = now();
  CHECK(gr_rain_runoff_stable_dt(sim, &dt));
  double t_first_read = now() - t0;
  t0 = now();
  CHECK(gr_rain_runoff_step(sim, dt, 1));
  CHECK(gr_rain_runoff_sample(sim, ij, 1, probe));
  double t_first_step = now() - t0;
  t0 = now();
  CHECK(gr_rain_runoff_step(sim, dt, 1));
  CHECK(gr_rain_runoff_sample(sim, ij, 1, probe));
  double t_second_step = now() - t0;
  CHECK(gr_rain_runoff_reset(sim));

  /* advance's loop, each part timed. */
  double left = duration, last_dt = 0.0, t_steps = 0.0, t_reads = 0.0, dt_min = HUGE_VAL;
  long long steps = 0, reads = 0, capped = 0;
  int chunk = 1;
  double c0 = cpu(), w0 = now();
  while (left > 0.0) {
    t0 = now();
    CHECK(gr_rain_runoff_stable_dt(sim, &dt));
    t_reads += now() - t0;
    ++reads;
    if (last_dt > 0.0)
      chunk = dt >= 0.95 * last_dt ? (chunk * 2 < 64 ? chunk * 2 : 64) : 1;
    last_dt = dt;
    int k = chunk;
    double h = dt, nn = ceil(left / dt);
    if (nn <= chunk) {
      k = (int)(nn < 1.0 ? 1.0 : nn);
      h = left / k;
    }
    if (dt >= p.max_dt)
      capped += k;
    dt_min = dt < dt_min ? dt : dt_min;
    t0 = now();
    CHECK(gr_rain_runoff_step(sim, h, k));
    CHECK(gr_rain_runoff_sample(sim, ij, 1, probe));
    t_steps += now() - t0;
    steps += k;
    left -= k == chunk ? chunk * dt : left;
  }
  double cpu_run = cpu() - c0, wall_run = now() - w0;
  /* One sample alone: the wait's own cost, to take off the stretches. */
  t0 = now();
  for (int i = 0; i < 20; ++i)
    CHECK(gr_rain_runoff_sample(sim, ij, 1, probe));
  double t_sample = (now() - t0) / 20.0;
  gr_rain_runoff_ledger led;
  CHECK(gr_rain_runoff_ledger_get(sim, &led));

  int taken = 0;
  double t_advance = 0.0, cpu_advance = 0.0;
  if (argc < 12 || atoi(argv[11])) {
    CHECK(gr_rain_runoff_reset(sim));
    c0 = cpu();
    t0 = now();
    CHECK(gr_rain_runoff_advance(sim, duration, &taken));
    CHECK(gr_rain_runoff_sample(sim, ij, 1, probe));
    t_advance = now() - t0;
    cpu_advance = cpu() - c0;
  }

  printf("{\"model\": %d, \"max_dt\": %g, \"t_context\": %.4f, \"t_create\": %.4f, "
         "\"t_upload\": %.4f, \"t_first_read\": %.4f, \"t_first_step\": %.4f, "
         "\"t_second_step\": %.4f, \"steps\": %lld, \"reads\": %lld, \"capped_steps\": %lld, "
         "\"dt_min\": %.4f, \"t_steps\": %.3f, \"t_reads\": %.3f, \"t_sample\": %.6f, "
         "\"wall_run\": %.3f, \"cpu_run\": %.3f, \"t_advance\": %.3f, \"cpu_advance\": %.3f, "
         "\"advance_steps\": %d, \"stored_volume\": %.6g, "
         "\"outflow_volume\": %.6g, \"max_depth\": %.4f, \"device\": \"%s\"}\n",
         model, p.max_dt, t_context, t_create, t_upload, t_first_read, t_first_step, t_second_step,
         steps, reads, capped, dt_min, t_steps, t_reads, t_sample, wall_run, cpu_run, t_advance,
         cpu_advance, taken, led.stored_volume, led.outflow_volume, led.max_depth,
         gr_context_device_name(ctx));
  gr_rain_runoff_destroy(sim);
  gr_context_release(ctx);
  free(z);
  return 0;
}
