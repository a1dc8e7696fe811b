/* Soak: many cycles of what exists, with resident memory flat.
 *
 *   test_soak runtime N      N cycles of context, program, kernel and buffer
 *                            creation, use and release (private and shared)
 *   test_soak procedural_terrain N DIR  N terrain generations (random valid parameters)
 *                            and EXR round trips of the result through DIR
 *   test_soak rain_runoff N         one rain runoff simulation stepped N times on a
 *                            small random terrain, its parameters drawn anew
 *                            every 5000 steps; every 1000 steps the depth and
 *                            velocity must be finite (depth >= 0) and the
 *                            water balance within 1e-4 of the water that came
 *                            in; a second simulation is created, stepped and
 *                            freed every 10^4 steps
 *   test_soak snow_accumulation N   tilted, fluttering snow on a small rough
 *                            field with a box circling over it, stepped N
 *                            times; every 1000 steps the depths must be
 *                            finite, 0 to MaxDepth, and the ledger closed
 *                            (1e-9 of the snowfall); a checkpoint goes into
 *                            a second simulation, freed again, every 10^4
 *                            steps
 *   test_soak snow_melt N    hills with snow under weather drawn anew every
 *                            50 hourly steps (snowfall, rain, warm, cold),
 *                            N steps; every 1000 steps the fields must be
 *                            finite and in range and the ledger exact
 *                            (balance 0, in = stored + released to 1e-9);
 *                            a checkpoint goes into a second simulation,
 *                            freed again, every 10^4 steps
 *   test_soak snow_deformation N    a box moving in circles over a small snow
 *                            field, stepped N times; every 1000 steps the
 *                            depth and density must be finite and in range
 *                            and the ledger closed (mass and volume within
 *                            1e-5 relative); a checkpoint goes into a second
 *                            simulation, freed again, every 10^4 steps
 *
 * Memory is "flat" when the resident set after the last cycle exceeds the one
 * after the first tenth of the cycles by less than a small allowance (the
 * allocator and the OpenCL runtime settle in during that first tenth). Every
 * generated field is checked for NaN, infinity and its documented bounds. */
#include "graupel/cl_runtime.h"
#include "graupel/exr_io.h"
#include "graupel/rain_runoff.h"
#include "graupel/procedural_terrain.h"
#include "graupel/snow_accumulation.h"
#include "graupel/snow_deformation.h"
#include "graupel/snow_melt.h"
#include "graupel/water_surface.h"
#include "gr_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* Growth allowed between the first tenth and the end, in KiB. */
#define GR_SOAK_SLACK_KIB 2048

static long rss_kib(void) {
  long pages = 0, resident = 0;
  FILE *f = fopen("/proc/self/statm", "r");
  if (!f)
    return -1;
  if (fscanf(f, "%ld %ld", &pages, &resident) != 2)
    resident = -1;
  fclose(f);
  return resident < 0 ? -1 : resident * (sysconf(_SC_PAGESIZE) / 1024);
}

/* A small deterministic generator: the soak is random but reproducible. */
static unsigned long long rng_state = 0x9E3779B97F4A7C15ULL;
static double uniform(double lo, double hi) {
  rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
  return lo + (hi - lo) * (double)(rng_state >> 11) / 9007199254740992.0;
}

static const char *axpb_src = "__kernel void axpb(__global float *x, float a, int n) {"
                              " int i = get_global_id(0); if (i < n) x[i] = a * x[i] + 1.0f; }";

static void soak_runtime(long n_cycles) {
  long first = 0;
  double t0 = (double)clock();
  for (long c = 0; c < n_cycles; ++c) {
    gr_context *ctx = NULL;
    gr_status st = (c % 2) ? gr_context_acquire(NULL, &ctx) : gr_context_create(NULL, &ctx);
    CHECK_MSG(st == GR_OK, "cycle %ld: %s", c, gr_last_error(NULL));
    if (st != GR_OK)
      return;
    cl_program prog = NULL;
    cl_kernel k = NULL;
    cl_mem buf = NULL;
    float host[256];
    for (int i = 0; i < 256; ++i)
      host[i] = (float)i;
    st = gr_program_build_source(ctx, axpb_src, NULL, &prog);
    if (st == GR_OK)
      st = gr_kernel_create(ctx, prog, "axpb", &k);
    if (st == GR_OK)
      st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, sizeof(host), host, &buf);
    /* By name: a new kernel every cycle goes through the context's bounded
     * cache of argument names, whose memory must stay flat too. */
    cl_float a = 2.0f;
    cl_int n = 256;
    cl_mem x = buf;
    if (st == GR_OK)
      st = GR_KERNEL_ARG(ctx, k, n);
    if (st == GR_OK)
      st = GR_KERNEL_ARG(ctx, k, a);
    if (st == GR_OK)
      st = GR_KERNEL_ARG(ctx, k, x);
    if (st == GR_OK)
      st = gr_enqueue_1d(ctx, k, 256);
    if (st == GR_OK)
      st = gr_buffer_read(ctx, buf, 0, sizeof(host), host);
    CHECK_MSG(st == GR_OK, "cycle %ld: %s", c, gr_last_error(ctx));
    CHECK(host[255] == 511.0f);
    /* A failing build in the middle of the soak must not leak either. */
    if (c % 100 == 0) {
      cl_program bad = NULL;
      CHECK(gr_program_build_source(ctx, "__kernel void f( {", NULL, &bad) == GR_ERR_BUILD);
    }
    if (k)
      clReleaseKernel(k);
    if (prog)
      clReleaseProgram(prog);
    gr_buffer_release(&buf);
    gr_context_release(ctx);
    if (gr_test_failures > 10)
      return;
    if (c + 1 == n_cycles / 10)
      first = rss_kib();
  }
  long last = rss_kib();
  printf("runtime soak: %ld cycles in %.1f s CPU; resident %ld KiB after %ld, %ld KiB at the end\n",
         n_cycles, ((double)clock() - t0) / CLOCKS_PER_SEC, first, n_cycles / 10, last);
  CHECK_MSG(last - first < GR_SOAK_SLACK_KIB, "resident memory grew by %ld KiB", last - first);
}

static void soak_procedural_terrain(long n, const char *dir) {
  gr_context *ctx = NULL;
  if (gr_context_acquire(NULL, &ctx) != GR_OK) {
    CHECK_MSG(0, "%s", gr_last_error(NULL));
    return;
  }
  char path[4096];
  snprintf(path, sizeof(path), "%s/soak.exr", dir);
  long first = 0;
  for (long c = 0; c < n; ++c) {
    gr_grid g = {8 + (int)uniform(0, 57),
                 8 + (int)uniform(0, 57),
                 uniform(0.5, 10.0),
                 uniform(0.5, 10.0),
                 uniform(-1e5, 1e5),
                 uniform(-1e5, 1e5),
                 0,
                 0};
    gr_procedural_terrain_params p;
    gr_procedural_terrain_params_init(&p);
    p.seed = (int)uniform(-1e9, 1e9);
    p.type = (gr_noise_type)(int)uniform(0, 3);
    p.octaves = 1 + (int)uniform(0, 8);
    p.frequency = uniform(0.1, 50.0);
    p.lacunarity = uniform(1.0, 3.0);
    p.persistence = uniform(0.0, 1.0);
    p.offset = uniform(0.1, 2.0);
    p.gain = uniform(0.0, 4.0);
    p.h = uniform(0.0, 2.0);
    p.invert = c % 2;
    p.height_scale = uniform(0.0, 500.0);
    size_t cells = (size_t)g.nx * (size_t)g.ny;
    float *h = malloc(cells * sizeof(float));
    gr_status st = gr_procedural_terrain_generate(ctx, &g, &p, h);
    CHECK_MSG(st == GR_OK, "cycle %ld: %s", c, gr_last_error(ctx));
    /* The failing paths keep their sentence in the handle: no leak either. */
    if (c % 100 == 0) {
      gr_procedural_terrain *t = NULL;
      CHECK(gr_procedural_terrain_create(ctx, &g, &p, &t) == GR_OK);
      gr_procedural_terrain_params q = p;
      q.offset = 0.0;
      CHECK(gr_procedural_terrain_set_params(t, &q) == GR_ERR_INVALID_ARGUMENT);
      CHECK(strstr(gr_procedural_terrain_last_error(t), "Offset") != NULL);
      gr_procedural_terrain_destroy(t);
    }
    int bad = 0;
    for (size_t i = 0; i < cells; ++i)
      bad += !(h[i] >= 0.0f && h[i] <= (float)p.height_scale); /* also NaN */
    CHECK_MSG(bad == 0, "cycle %ld: %d values outside [0, %g] or not finite", c, bad,
              p.height_scale);
    /* EXR round trip, FLOAT: bit for bit. */
    const char *names[1] = {"elevation"};
    const float *planes[1] = {h};
    char err[512];
    gr_exr_image img;
    memset(&img, 0, sizeof(img));
    st = gr_exr_write(path, g.nx, g.ny, 1, names, planes, GR_EXR_FLOAT, err, sizeof(err));
    if (st == GR_OK)
      st = gr_exr_read(path, &img, err, sizeof(err));
    CHECK_MSG(st == GR_OK, "cycle %ld: %s", c, err);
    CHECK(st != GR_OK || (img.width == g.nx && img.height == g.ny &&
                          memcmp(img.data[0], h, cells * sizeof(float)) == 0));
    gr_exr_image_free(&img);
    free(h);
    if (gr_test_failures > 10)
      break;
    if (c + 1 == n / 10)
      first = rss_kib();
  }
  long last = rss_kib();
  printf("terrain soak: %ld generations and EXR round trips; resident %ld KiB after %ld, "
         "%ld KiB at the end\n",
         n, first, n / 10, last);
  CHECK_MSG(last - first < GR_SOAK_SLACK_KIB, "resident memory grew by %ld KiB", last - first);
  remove(path);
  gr_context_release(ctx);
}

static void random_rain_runoff_params(gr_rain_runoff_params *p) {
  gr_rain_runoff_params_init(p);
  /* Dry spells, drizzle and cloudbursts (up to 200 mm/h). */
  p->rain_rate = uniform(0.0, 1.0) < 0.2 ? 0.0 : uniform(0.0, 200.0 / 3.6e6);
  p->permeability = uniform(0.0, 1.0) < 0.3 ? 0.0 : uniform(0.0, 50.0 / 3.6e6);
  p->manning_n = uniform(0.01, 0.2);
  p->cfl = uniform(0.3, 0.9);
  p->max_dt = uniform(0.05, 2.0);
  /* Every kind of edge, each edge its own (levels may lie below the ground:
   * an outfall then), all from one draw, so that the later draws stay
   * those of the runs before there were kinds. */
  double u = uniform(0.0, 1.0);
  for (int e = 0; e < 4; ++e) {
    double digits = u * pow(4.0, e + 1);
    p->boundary[e] = (gr_boundary)((long)digits % 4);
    p->boundary_level[e] = -1.0 + 3.0 * (digits - floor(digits));
  }
  /* Both flow models, switched between phases on the same water. */
  p->flow_model = uniform(0.0, 1.0) < 0.5 ? GR_FLOW_SHALLOW_WATER : GR_FLOW_LOCAL_INERTIAL;
}

static void soak_rain_runoff(long n) {
  gr_context *ctx = NULL;
  if (gr_context_acquire(NULL, &ctx) != GR_OK) {
    CHECK_MSG(0, "%s", gr_last_error(NULL));
    return;
  }
  const gr_grid g = {48, 40, uniform(0.5, 5.0), uniform(0.5, 5.0), 0.0, 0.0, 0, 0};
  const size_t cells = (size_t)g.nx * (size_t)g.ny;
  float *b = malloc(cells * sizeof(float));
  float *h = malloc(cells * sizeof(float));
  float *v = malloc(3 * cells * sizeof(float));
  gr_procedural_terrain_params tp;
  gr_procedural_terrain_params_init(&tp);
  tp.seed = 11;
  tp.frequency = 40.0;
  tp.height_scale = 5.0;
  gr_rain_runoff_params p;
  random_rain_runoff_params(&p);
  gr_rain_runoff *sim = NULL;
  gr_status st = gr_procedural_terrain_generate(ctx, &g, &tp, b);
  if (st == GR_OK)
    st = gr_rain_runoff_create(ctx, &g, &p, &sim);
  if (st == GR_OK)
    st = gr_rain_runoff_set_field(sim, GR_FIELD_ELEVATION, b);
  CHECK_MSG(st == GR_OK, "set-up: %s", gr_last_error(ctx));
  /* Both flow models' programs built before the run: the phases switch
   * between them at random, and a program PoCL first compiles after the
   * first tenth (its kernel cache cold, after a change to the kernels)
   * leaves the compiler's memory behind (16 MB), which is not a leak. */
  for (int model = 0; st == GR_OK && model < 2; ++model) {
    gr_rain_runoff_params wp = p;
    wp.flow_model = model ? GR_FLOW_LOCAL_INERTIAL : GR_FLOW_SHALLOW_WATER;
    gr_rain_runoff *warm = NULL;
    gr_rain_runoff_ledger wl;
    double wdt = 0.0;
    st = gr_rain_runoff_create(ctx, &g, &wp, &warm);
    if (st == GR_OK)
      st = gr_rain_runoff_set_field(warm, GR_FIELD_ELEVATION, b);
    if (st == GR_OK)
      st = gr_rain_runoff_stable_dt(warm, &wdt);
    if (st == GR_OK)
      st = gr_rain_runoff_step(warm, wdt, 2);
    if (st == GR_OK)
      st = gr_rain_runoff_get_field(warm, GR_FIELD_VELOCITY, v);
    if (st == GR_OK)
      st = gr_rain_runoff_ledger_get(warm, &wl);
    if (st == GR_OK)
      st = gr_rain_runoff_advance(warm, 1.0, NULL);
    CHECK_MSG(st == GR_OK, "warm-up, flow model %d: %s", model, gr_last_error(ctx));
    gr_rain_runoff_destroy(warm);
  }
  long first = 0, done = 0;
  double worst = 0.0, t0 = (double)clock();
  const long chunk = 1000;
  while (st == GR_OK && done < n) {
    if (done % 5000 == 0) {
      random_rain_runoff_params(&p);
      st = gr_rain_runoff_set_params(sim, &p);
    }
    double dt = 0.0;
    if (st == GR_OK)
      st = gr_rain_runoff_stable_dt(sim, &dt);
    int k = (int)(n - done < chunk ? n - done : chunk);
    if (st == GR_OK)
      st = gr_rain_runoff_step(sim, dt, k);
    done += k;
    gr_rain_runoff_ledger led;
    if (st == GR_OK)
      st = gr_rain_runoff_get_field(sim, GR_FIELD_WATER_DEPTH, h);
    if (st == GR_OK)
      st = gr_rain_runoff_get_field(sim, GR_FIELD_VELOCITY, v);
    if (st == GR_OK)
      st = gr_rain_runoff_ledger_get(sim, &led);
    CHECK_MSG(st == GR_OK, "step %ld: %s", done, gr_last_error(ctx));
    if (st != GR_OK)
      break;
    int bad = 0;
    for (size_t i = 0; i < cells; ++i)
      bad += !(h[i] >= 0.0f && h[i] < 1e30f); /* NaN, infinite or negative */
    for (size_t i = 0; i < 3 * cells; ++i)
      bad += !(v[i] > -1e30f && v[i] < 1e30f);
    CHECK_MSG(bad == 0, "step %ld: %d depth or velocity values not finite or negative", done, bad);
    const double in = led.initial_volume + led.rain_volume + led.inflow_volume;
    const double rel = in > 0.0 ? fabs(led.balance_error) / in : fabs(led.balance_error);
    worst = rel > worst ? rel : worst;
    CHECK_MSG(rel <= 1e-4, "step %ld: balance error %g of %g m^3 came in", done, led.balance_error,
              in);
    CHECK_MSG(led.steps == done, "ledger counts %lld steps, %ld were taken", led.steps, done);
    if (done % 10000 == 0) {
      /* Create, use and free a second simulation: nothing may stay behind. */
      gr_rain_runoff *other = NULL;
      gr_status so = gr_rain_runoff_create(ctx, &g, &p, &other);
      if (so == GR_OK)
        so = gr_rain_runoff_set_field(other, GR_FIELD_ELEVATION, b);
      if (so == GR_OK)
        so = gr_rain_runoff_advance(other, 10.0, NULL);
      CHECK_MSG(so == GR_OK, "second simulation: %s", gr_last_error(ctx));
      /* A checkpoint of the long run into it, and a refused one: the state
       * comes over whole and nothing of either stays behind. */
      size_t bytes = 0;
      if (so == GR_OK)
        so = gr_rain_runoff_state_size(sim, &bytes);
      void *state = so == GR_OK ? malloc(bytes) : NULL;
      if (state) {
        so = gr_rain_runoff_state_save(sim, state, bytes);
        if (so == GR_OK)
          so = gr_rain_runoff_state_load(other, state, bytes);
        CHECK(gr_rain_runoff_state_load(other, state, bytes / 2) == GR_ERR_INVALID_ARGUMENT);
      }
      gr_rain_runoff_ledger lo;
      if (so == GR_OK)
        so = gr_rain_runoff_ledger_get(other, &lo);
      CHECK_MSG(so == GR_OK && lo.steps == done, "checkpoint: %s",
                gr_rain_runoff_last_error(other));
      free(state);
      gr_rain_runoff_destroy(other);
    }
    if (done == n / 10)
      first = rss_kib();
    if (gr_test_failures > 10)
      break;
  }
  long last = rss_kib();
  gr_rain_runoff_ledger led;
  if (sim && gr_rain_runoff_ledger_get(sim, &led) == GR_OK)
    printf("rain soak: %ld steps (%.0f s simulated) in %.1f s CPU; worst balance error %.3g of "
           "the water in; rain %.4g m^3, infiltrated %.4g, outflow %.4g, stored %.4g; resident "
           "%ld KiB after %ld steps, %ld KiB at the end\n",
           done, led.time, ((double)clock() - t0) / CLOCKS_PER_SEC, worst, led.rain_volume,
           led.infiltrated_volume, led.outflow_volume, led.stored_volume, first, n / 10, last);
  CHECK_MSG(last - first < GR_SOAK_SLACK_KIB, "resident memory grew by %ld KiB", last - first);
  gr_rain_runoff_destroy(sim);
  free(b);
  free(h);
  free(v);
  gr_context_release(ctx);
}

static void soak_snow_accumulation(long n) {
  gr_context *ctx = NULL;
  if (gr_context_acquire(NULL, &ctx) != GR_OK) {
    CHECK_MSG(0, "%s", gr_last_error(NULL));
    return;
  }
  const gr_grid g = {24, 20, 0.1, 0.1, 0.0, 0.0, 0, 0};
  const size_t cells = (size_t)g.nx * (size_t)g.ny;
  float *d = malloc(cells * sizeof(float)), *b = malloc(cells * sizeof(float));
  for (size_t c = 0; c < cells; ++c)
    b[c] = (float)(0.2 * sin(0.5 * (double)(c % 24)) * cos(0.4 * (double)(c / 24)));
  static const float bv[] = {-0.3f, -0.2f, -0.2f, 0.3f,  -0.2f, -0.2f, 0.3f, 0.2f,
                             -0.2f, -0.3f, 0.2f,  -0.2f, -0.3f, -0.2f, 0.2f, 0.3f,
                             -0.2f, 0.2f,  0.3f,  0.2f,  0.2f,  -0.3f, 0.2f, 0.2f};
  static const int bt[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                           1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  gr_mesh box = {bv, 8, bt, 12, {0}};
  gr_snow_accumulation_params p;
  gr_snow_accumulation_params_init(&p);
  p.exposure_resolution = 128;
  p.snowfall_rate = 1e-4;
  p.max_depth = 0.3;
  p.stability_factor = 0.5;
  p.flutter = 0.05;
  p.blur_radius = 2;
  p.dilation = 1;
  p.direction[0] = 0.3;
  gr_snow_accumulation *sim = NULL;
  gr_status st = gr_snow_accumulation_create(ctx, &g, &p, &sim);
  if (st == GR_OK)
    st = gr_snow_accumulation_set_field(sim, GR_FIELD_ELEVATION, b);
  CHECK_MSG(st == GR_OK, "set-up: %s", gr_last_error(ctx));
  long first = 0, done = 0;
  double worst = 0.0, t0 = (double)clock(), dt = 30.0;
  while (st == GR_OK && done < n) {
    /* A circle of 0.6 m radius every 600 steps, 0.8 m above the ground. */
    double a = 2.0 * 3.14159265358979 * (double)(done % 600) / 600.0;
    for (int k = 0; k < 16; ++k)
      box.transform[k] = (k % 5 == 0) ? 1.0 : 0.0;
    box.transform[12] = 1.2 + 0.6 * cos(a);
    box.transform[13] = 1.0 + 0.6 * sin(a);
    box.transform[14] = 0.8;
    st = gr_snow_accumulation_set_objects(sim, &box, 1);
    if (st == GR_OK)
      st = gr_snow_accumulation_step(sim, dt);
    ++done;
    if (st == GR_OK && (done % 1000 == 0 || done == n)) {
      gr_snow_accumulation_ledger led;
      st = gr_snow_accumulation_get_field(sim, GR_FIELD_SNOW_DEPTH, d);
      if (st == GR_OK)
        st = gr_snow_accumulation_ledger_get(sim, &led);
      if (st != GR_OK)
        break;
      int bad = 0;
      /* The soft cap lets the depth stand a little above MaxDepth: at
       * most a step's fall, shed at half per second. */
      for (size_t i = 0; i < cells; ++i)
        bad += !(d[i] >= 0.0f && d[i] <= 0.31f);
      CHECK_MSG(bad == 0, "step %ld: %d depths not finite or out of range", done, bad);
      double rel = fabs(led.balance_error) / led.snowfall_volume;
      worst = fmax(worst, rel);
      CHECK_MSG(rel <= 1e-9, "step %ld: balance error %g of the snowfall", done, rel);
      CHECK_MSG(led.steps == done, "ledger counts %lld steps, %ld were taken", led.steps, done);
      if (done % 10000 == 0) {
        gr_snow_accumulation *other = NULL;
        size_t bytes = 0;
        gr_status so = gr_snow_accumulation_create(ctx, &g, &p, &other);
        if (so == GR_OK)
          so = gr_snow_accumulation_set_objects(other, &box, 1);
        if (so == GR_OK)
          so = gr_snow_accumulation_state_size(sim, &bytes);
        void *state = so == GR_OK ? malloc(bytes) : NULL;
        if (state) {
          so = gr_snow_accumulation_state_save(sim, state, bytes);
          if (so == GR_OK)
            so = gr_snow_accumulation_state_load(other, state, bytes);
          CHECK(gr_snow_accumulation_state_load(other, state, bytes / 2) ==
                GR_ERR_INVALID_ARGUMENT);
        }
        gr_snow_accumulation_ledger lo;
        if (so == GR_OK)
          so = gr_snow_accumulation_ledger_get(other, &lo);
        CHECK_MSG(so == GR_OK && lo.steps == done && lo.stored_volume == led.stored_volume,
                  "checkpoint: %s",
                  other ? gr_snow_accumulation_last_error(other) : gr_last_error(ctx));
        free(state);
        gr_snow_accumulation_destroy(other);
      }
    }
    if (done == n / 10)
      first = rss_kib();
    if (gr_test_failures > 10)
      break;
  }
  CHECK_MSG(st == GR_OK, "step %ld: %s", done, sim ? gr_snow_accumulation_last_error(sim) : "");
  long last = rss_kib();
  gr_snow_accumulation_ledger led;
  if (sim && gr_snow_accumulation_ledger_get(sim, &led) == GR_OK)
    printf("snow accumulation soak: %ld steps in %.1f s CPU; worst balance error %.3g of the "
           "snowfall; snowfall %.4g m^3, stored %.4g (objects %.4g), shed %.4g; resident %ld KiB "
           "after %ld steps, %ld KiB at the end\n",
           done, ((double)clock() - t0) / CLOCKS_PER_SEC, worst, led.snowfall_volume,
           led.stored_volume, led.stored_volume_objects, led.shed_volume, first, n / 10, last);
  CHECK_MSG(last - first < GR_SOAK_SLACK_KIB, "resident memory grew by %ld KiB", last - first);
  gr_snow_accumulation_destroy(sim);
  free(d);
  free(b);
  gr_context_release(ctx);
}

static void soak_snow_deformation(long n) {
  gr_context *ctx = NULL;
  if (gr_context_acquire(NULL, &ctx) != GR_OK) {
    CHECK_MSG(0, "%s", gr_last_error(NULL));
    return;
  }
  const gr_grid g = {24, 20, 0.1, 0.1, 0.0, 0.0, 0, 0};
  const size_t cells = (size_t)g.nx * (size_t)g.ny;
  float *d = malloc(cells * sizeof(float)), *r = malloc(cells * sizeof(float));
  static const float bv[] = {-0.3f, -0.2f, -0.2f, 0.3f,  -0.2f, -0.2f, 0.3f, 0.2f,
                             -0.2f, -0.3f, 0.2f,  -0.2f, -0.3f, -0.2f, 0.2f, 0.3f,
                             -0.2f, 0.2f,  0.3f,  0.2f,  0.2f,  -0.3f, 0.2f, 0.2f};
  static const int bt[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                           1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  gr_mesh box = {bv, 8, bt, 12, {0}};
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  gr_snow_deformation *sim = NULL;
  gr_status st = gr_snow_deformation_create(ctx, &g, &p, &sim);
  CHECK_MSG(st == GR_OK, "set-up: %s", gr_last_error(ctx));
  long first = 0, done = 0;
  double worst = 0.0, t0 = (double)clock(), dt = 1.0 / 60.0;
  while (st == GR_OK && done < n) {
    /* A circle of 0.6 m radius every 600 steps, the box 0.1 m deep in the
     * snow, facing its motion. */
    double a = 2.0 * 3.14159265358979 * (double)(done % 600) / 600.0,
           w = 2.0 * 3.14159265358979 / 10.0;
    for (int k = 0; k < 16; ++k)
      box.transform[k] = 0.0;
    box.transform[0] = -sin(a), box.transform[1] = cos(a);
    box.transform[4] = -cos(a), box.transform[5] = -sin(a);
    box.transform[10] = box.transform[15] = 1.0;
    box.transform[12] = 1.2 + 0.6 * cos(a);
    box.transform[13] = 1.0 + 0.6 * sin(a);
    box.transform[14] = 0.4 + 0.2;
    double v[3] = {-0.6 * w * sin(a), 0.6 * w * cos(a), 0.0};
    st = gr_snow_deformation_set_objects(sim, &box, 1, v);
    if (st == GR_OK)
      st = gr_snow_deformation_step(sim, dt);
    ++done;
    if (st == GR_OK && (done % 1000 == 0 || done == n)) {
      gr_snow_deformation_ledger led;
      st = gr_snow_deformation_get_field(sim, GR_FIELD_SNOW_DEPTH, d);
      if (st == GR_OK)
        st = gr_snow_deformation_get_field(sim, GR_FIELD_SNOW_DENSITY, r);
      if (st == GR_OK)
        st = gr_snow_deformation_ledger_get(sim, &led);
      if (st != GR_OK)
        break;
      int bad = 0;
      for (size_t i = 0; i < cells; ++i)
        bad += !(d[i] >= 0.0f && d[i] < 1e4f) || !(r[i] >= 99.99f && r[i] <= 400.01f);
      CHECK_MSG(bad == 0, "step %ld: %d depths or densities not finite or out of range", done, bad);
      double mrel = fabs(led.balance_error) / led.initial_mass;
      double vrel = fabs(led.volume_error) / led.initial_volume;
      worst = fmax(worst, fmax(mrel, vrel));
      /* The volume moves in whole quanta: it closes to the ledger's own
       * rounding; the mass to that of the float densities. */
      CHECK_MSG(mrel <= 1e-5 && vrel <= 1e-12, "step %ld: mass error %g, volume error %g", done,
                mrel, vrel);
      CHECK_MSG(led.steps == done, "ledger counts %lld steps, %ld were taken", led.steps, done);
      if (done % 10000 == 0) {
        gr_snow_deformation *other = NULL;
        size_t bytes = 0;
        gr_status so = gr_snow_deformation_create(ctx, &g, &p, &other);
        if (so == GR_OK)
          so = gr_snow_deformation_state_size(sim, &bytes);
        void *state = so == GR_OK ? malloc(bytes) : NULL;
        if (state) {
          so = gr_snow_deformation_state_save(sim, state, bytes);
          if (so == GR_OK)
            so = gr_snow_deformation_state_load(other, state, bytes);
          CHECK(gr_snow_deformation_state_load(other, state, bytes / 2) == GR_ERR_INVALID_ARGUMENT);
        }
        gr_snow_deformation_ledger lo;
        if (so == GR_OK)
          so = gr_snow_deformation_ledger_get(other, &lo);
        CHECK_MSG(so == GR_OK && lo.steps == done, "checkpoint: %s",
                  other ? gr_snow_deformation_last_error(other) : gr_last_error(ctx));
        free(state);
        gr_snow_deformation_destroy(other);
      }
    }
    if (done == n / 10)
      first = rss_kib();
    if (gr_test_failures > 10)
      break;
  }
  CHECK_MSG(st == GR_OK, "step %ld: %s", done, sim ? gr_snow_deformation_last_error(sim) : "");
  long last = rss_kib();
  gr_snow_deformation_ledger led;
  if (sim && gr_snow_deformation_ledger_get(sim, &led) == GR_OK)
    printf("snow soak: %ld steps in %.1f s CPU; worst ledger error %.3g; displaced %.4g m^3, "
           "compressed %.4g of %.4g; resident %ld KiB after %ld steps, %ld KiB at the end\n",
           done, ((double)clock() - t0) / CLOCKS_PER_SEC, worst, led.displaced_volume,
           led.compressed_volume, led.initial_volume, first, n / 10, last);
  CHECK_MSG(last - first < GR_SOAK_SLACK_KIB, "resident memory grew by %ld KiB", last - first);
  gr_snow_deformation_destroy(sim);
  free(d);
  free(r);
  gr_context_release(ctx);
}

/* Water Surface: a lake in a bowl, its parameters drawn anew every 2000
 * steps (wave speed, damping, raindrops), stepped at the stable step;
 * every 1000 steps the waves are finite and bounded and the water's mean
 * level stays within 0.1 mm (raindrops move no water), every 10 000 a
 * checkpoint goes through another simulation. */
static void soak_water_surface(long n) {
  gr_context *ctx = NULL;
  if (gr_context_acquire(NULL, &ctx) != GR_OK) {
    CHECK_MSG(0, "%s", gr_last_error(NULL));
    return;
  }
  const gr_grid g = {48, 40, 0.5, 0.5, 0.0, 0.0, 0, 0};
  const size_t cells = (size_t)g.nx * (size_t)g.ny;
  float *b = malloc(cells * sizeof(float)), *w = malloc(cells * sizeof(float));
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      double x = (i - 23.5) / 24.0, y = (j - 19.5) / 20.0;
      b[(size_t)j * g.nx + i] = (float)(2.0 * (x * x + y * y) - 1.0);
    }
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.use_lake_level = 1;
  p.lake_level = 0.0;
  gr_water_surface *sim = NULL;
  gr_status st = gr_water_surface_create(ctx, &g, &p, &sim);
  if (st == GR_OK)
    st = gr_water_surface_set_field(sim, GR_FIELD_ELEVATION, b);
  CHECK_MSG(st == GR_OK, "set-up: %s", sim ? gr_water_surface_last_error(sim) : gr_last_error(ctx));
  long first = 0, done = 0;
  double worst = 0.0, dt = 0.0, t0 = (double)clock();
  while (st == GR_OK && done < n) {
    if (done % 2000 == 0) {
      p.wave_speed = uniform(0.3, 3.0);
      p.damping = uniform(0.0, 1.0) < 0.3 ? 0.0 : uniform(0.0, 0.5);
      p.drop_rate = uniform(0.0, 1.0) < 0.2 ? 0.0 : uniform(0.0, 2.0);
      p.drop_amplitude = uniform(0.0, 0.02);
      p.seed = (int)uniform(0.0, 1000.0);
      st = gr_water_surface_set_params(sim, &p);
      if (st == GR_OK)
        st = gr_water_surface_stable_dt(sim, &dt);
    }
    if (st == GR_OK)
      st = gr_water_surface_step(sim, dt, 1);
    ++done;
    if (st == GR_OK && (done % 1000 == 0 || done == n)) {
      gr_water_surface_ledger led;
      st = gr_water_surface_get(sim, GR_WATER_WAVE_HEIGHT, w);
      if (st == GR_OK)
        st = gr_water_surface_ledger_get(sim, &led);
      if (st != GR_OK)
        break;
      int bad = 0;
      for (size_t i = 0; i < cells; ++i)
        bad += !(fabs(w[i]) < 10.0f);
      CHECK_MSG(bad == 0, "step %ld: %d wave heights not finite or beyond 10 m", done, bad);
      /* The mean level over the wet area: the drops' dimples and the
       * scheme's face differences sum to zero, but the rounding of each
       * point's velocity update does not, and without damping the level
       * integrates it (measured: 3e-6 m after 17 000 undamped steps with
       * drops of 2 cm). */
      double area = (double)led.wet_points * g.dx * g.dy;
      double level = area > 0.0 ? fabs(led.wave_volume - led.initial_volume) / area : 0.0;
      worst = fmax(worst, level);
      CHECK_MSG(level <= 1e-4, "step %ld: the mean level moved by %g m", done, level);
      CHECK_MSG(led.steps == done, "ledger counts %lld steps, %ld were taken", led.steps, done);
      if (done % 10000 == 0) {
        gr_water_surface *other = NULL;
        size_t bytes = 0;
        gr_status so = gr_water_surface_create(ctx, &g, &p, &other);
        if (so == GR_OK)
          so = gr_water_surface_set_field(other, GR_FIELD_ELEVATION, b);
        if (so == GR_OK)
          so = gr_water_surface_state_size(sim, &bytes);
        void *state = so == GR_OK ? malloc(bytes) : NULL;
        if (state) {
          so = gr_water_surface_state_save(sim, state, bytes);
          if (so == GR_OK)
            so = gr_water_surface_state_load(other, state, bytes);
        }
        gr_water_surface_ledger lo;
        if (so == GR_OK)
          so = gr_water_surface_ledger_get(other, &lo);
        CHECK_MSG(so == GR_OK && lo.steps == done, "checkpoint: %s",
                  other ? gr_water_surface_last_error(other) : gr_last_error(ctx));
        free(state);
        gr_water_surface_destroy(other);
      }
    }
    if (done == n / 10)
      first = rss_kib();
    if (gr_test_failures > 10)
      break;
  }
  CHECK_MSG(st == GR_OK, "step %ld: %s", done, sim ? gr_water_surface_last_error(sim) : "");
  long last = rss_kib();
  printf(
      "water soak: %ld steps in %.1f s CPU; the mean level moved by %.3g m at most; resident %ld "
      "KiB after %ld steps, %ld KiB at the end\n",
      done, ((double)clock() - t0) / CLOCKS_PER_SEC, worst, first, n / 10, last);
  CHECK_MSG(last - first < GR_SOAK_SLACK_KIB, "resident memory grew by %ld KiB", last - first);
  gr_water_surface_destroy(sim);
  free(b);
  free(w);
  gr_context_release(ctx);
}

/* Snow Melt: hills of 24 x 20 points with snow, cast shadows, weather
 * drawn anew every 50 hourly steps; every 1000 steps the fields are finite
 * and in range and the ledger exact, every 10 000 a checkpoint goes
 * through another simulation. */
static void soak_snow_melt(long n) {
  gr_context *ctx = NULL;
  if (gr_context_acquire(NULL, &ctx) != GR_OK) {
    CHECK_MSG(0, "%s", gr_last_error(NULL));
    return;
  }
  const gr_grid g = {24, 20, 25.0, 25.0, 0.0, 0.0, 0, 0};
  const size_t cells = (size_t)g.nx * (size_t)g.ny;
  float *z = malloc(cells * sizeof(float)), *d = malloc(cells * sizeof(float));
  float *rho = malloc(cells * sizeof(float)), *w = malloc(cells * sizeof(float));
  for (size_t c = 0; c < cells; ++c) {
    double i = (double)(c % (size_t)g.nx), j = (double)(c / (size_t)g.nx);
    z[c] = (float)(1200.0 + 150.0 * sin(0.4 * i) * cos(0.3 * j) + 10.0 * j);
    d[c] = (float)(0.5 + 0.4 * sin(0.2 * i + 0.1 * j));
    rho[c] = 250.0f;
  }
  gr_snow_melt_params p;
  gr_snow_melt_params_init(&p);
  p.start_day = 300;
  gr_snow_melt *sim = NULL;
  gr_status st = gr_snow_melt_create(ctx, &g, &p, &sim);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(sim, GR_FIELD_ELEVATION, z);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(sim, GR_FIELD_SNOW_DEPTH, d);
  if (st == GR_OK)
    st = gr_snow_melt_set_field(sim, GR_FIELD_SNOW_DENSITY, rho);
  if (st == GR_OK)
    st = gr_snow_melt_set_terrain(sim, z);
  CHECK_MSG(st == GR_OK, "set-up: %s", sim ? gr_snow_melt_last_error(sim) : gr_last_error(ctx));
  long first = 0, done = 0;
  double t0 = (double)clock(), most = 0.0;
  while (st == GR_OK && done < n) {
    gr_snow_melt_forcing f = {uniform(-8.0, 16.0),
                              uniform(0.0, 1.0) < 0.5 ? 0.0 : uniform(0.0, 2.0), 0, 0};
    long chunk = n - done < 50 ? n - done : 50;
    st = gr_snow_melt_set_forcing(sim, &f);
    if (st == GR_OK)
      st = gr_snow_melt_mark(sim);
    if (st == GR_OK)
      st = gr_snow_melt_advance(sim, 3600.0 * (double)chunk, NULL);
    done += chunk;
    if (st == GR_OK && (done % 1000 == 0 || done == n)) {
      gr_snow_melt_ledger led;
      int bad = 0;
      for (int o = 0; st == GR_OK && o < GR_SNOW_MELT_OUTPUT_COUNT; ++o) {
        st = gr_snow_melt_get(sim, (gr_snow_melt_output)o, w);
        for (size_t i = 0; st == GR_OK && i < cells; ++i)
          bad += !(w[i] >= 0.0f && w[i] < 1e5f);
        if (o == GR_SNOW_MELT_SNOW_DEPTH)
          for (size_t i = 0; i < cells; ++i)
            most = fmax(most, w[i]);
      }
      if (st == GR_OK)
        st = gr_snow_melt_ledger_get(sim, &led);
      if (st != GR_OK)
        break;
      CHECK_MSG(bad == 0, "step %ld: %d output values not finite or out of range", done, bad);
      double in = led.snowfall_in + led.snowfall_volume + led.rain_volume;
      double out = led.stored_swe_volume + led.stored_liquid_volume + led.released_volume;
      CHECK_MSG(led.balance_error == 0.0 && fabs(in - out) <= 1e-9 * in,
                "step %ld: balance error %g m^3, in - out %g of %g m^3", done, led.balance_error,
                in - out, in);
      CHECK_MSG(led.steps == done, "ledger counts %lld steps, %ld were taken", led.steps, done);
      if (done % 10000 == 0) {
        gr_snow_melt *other = NULL;
        size_t bytes = 0;
        gr_status so = gr_snow_melt_create(ctx, &g, &p, &other);
        if (so == GR_OK)
          so = gr_snow_melt_set_terrain(other, z);
        if (so == GR_OK)
          so = gr_snow_melt_state_size(sim, &bytes);
        void *state = so == GR_OK ? malloc(bytes) : NULL;
        if (state) {
          so = gr_snow_melt_state_save(sim, state, bytes);
          if (so == GR_OK)
            so = gr_snow_melt_state_load(other, state, bytes);
        }
        gr_snow_melt_ledger lo;
        if (so == GR_OK)
          so = gr_snow_melt_ledger_get(other, &lo);
        CHECK_MSG(so == GR_OK && lo.steps == done && lo.released_volume == led.released_volume,
                  "checkpoint: %s", other ? gr_snow_melt_last_error(other) : gr_last_error(ctx));
        free(state);
        gr_snow_melt_destroy(other);
      }
    }
    if (first == 0 && done >= n / 10)
      first = rss_kib();
    if (gr_test_failures > 10)
      break;
  }
  CHECK_MSG(st == GR_OK, "step %ld: %s", done, sim ? gr_snow_melt_last_error(sim) : "");
  long last = rss_kib();
  printf("snow melt soak: %ld steps in %.1f s CPU; deepest snow %.3f m; the ledger exact at every "
         "check; resident %ld KiB after %ld steps, %ld KiB at the end\n",
         done, ((double)clock() - t0) / CLOCKS_PER_SEC, most, first, n / 10, last);
  CHECK_MSG(last - first < GR_SOAK_SLACK_KIB, "resident memory grew by %ld KiB", last - first);
  gr_snow_melt_destroy(sim);
  free(z), free(d), free(rho), free(w);
  gr_context_release(ctx);
}

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: test_soak runtime N | procedural_terrain N DIR | rain_runoff N | "
                    "snow_accumulation N | snow_deformation N | snow_melt N | water_surface N\n");
    return 2;
  }
  long n = atol(argv[2]);
  if (n < 10) {
    fprintf(stderr, "test_soak: N must be at least 10\n");
    return 2;
  }
  if (strcmp(argv[1], "runtime") == 0)
    soak_runtime(n);
  else if (strcmp(argv[1], "procedural_terrain") == 0 && argc > 3)
    soak_procedural_terrain(n, argv[3]);
  else if (strcmp(argv[1], "rain_runoff") == 0)
    soak_rain_runoff(n);
  else if (strcmp(argv[1], "snow_accumulation") == 0)
    soak_snow_accumulation(n);
  else if (strcmp(argv[1], "snow_deformation") == 0)
    soak_snow_deformation(n);
  else if (strcmp(argv[1], "water_surface") == 0)
    soak_water_surface(n);
  else if (strcmp(argv[1], "snow_melt") == 0)
    soak_snow_melt(n);
  else {
    fprintf(stderr, "usage: test_soak runtime N | procedural_terrain N DIR | rain_runoff N | "
                    "snow_accumulation N | snow_deformation N | snow_melt N | water_surface N\n");
    return 2;
  }
  return GR_TEST_RESULT();
}
