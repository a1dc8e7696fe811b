/* Soak: many cycles of what exists, with resident memory flat.
 *
 *   test_soak runtime N      N cycles of context, program, kernel and buffer
 *                            creation, use and release (private and shared)
 *   test_soak terrain N DIR  N terrain generations (random valid parameters)
 *                            and EXR round trips of the result through DIR
 *
 * Memory is "flat" when the resident set after the last cycle exceeds the one
 * after the first tenth of the cycles by less than a small allowance (the
 * allocator and the OpenCL runtime settle in during that first tenth). Every
 * generated field is checked for NaN, infinity and its documented bounds. */
#include "graupel/cl_runtime.h"
#include "graupel/exr_io.h"
#include "graupel/terrain_noise.h"
#include "gr_test.h"

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

static void soak_runtime(long n) {
  long first = 0;
  double t0 = (double)clock();
  for (long c = 0; c < n; ++c) {
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
    cl_float a = 2.0f;
    cl_int count = 256;
    if (st == GR_OK)
      st = gr_kernel_args(ctx, k, sizeof(cl_mem), &buf, sizeof(cl_float), &a, sizeof(cl_int),
                          &count, (size_t)0);
    if (st == GR_OK)
      st = gr_enqueue_2d(ctx, k, 0, 0, 256, 1, NULL);
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
    if (c + 1 == n / 10)
      first = rss_kib();
  }
  long last = rss_kib();
  printf("runtime soak: %ld cycles in %.1f s CPU; resident %ld KiB after %ld, %ld KiB at the end\n",
         n, ((double)clock() - t0) / CLOCKS_PER_SEC, first, n / 10, last);
  CHECK_MSG(last - first < GR_SOAK_SLACK_KIB, "resident memory grew by %ld KiB", last - first);
}

static void soak_terrain(long n, const char *dir) {
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
    gr_terrain_noise_params p;
    gr_terrain_noise_params_init(&p);
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
    gr_status st = gr_terrain_noise_generate(ctx, &g, &p, h);
    CHECK_MSG(st == GR_OK, "cycle %ld: %s", c, gr_last_error(ctx));
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

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: test_soak runtime N | terrain N DIR\n");
    return 2;
  }
  long n = atol(argv[2]);
  if (n < 10) {
    fprintf(stderr, "test_soak: N must be at least 10\n");
    return 2;
  }
  if (strcmp(argv[1], "runtime") == 0)
    soak_runtime(n);
  else if (strcmp(argv[1], "terrain") == 0 && argc > 3)
    soak_terrain(n, argv[3]);
  else {
    fprintf(stderr, "usage: test_soak runtime N | terrain N DIR\n");
    return 2;
  }
  return GR_TEST_RESULT();
}
