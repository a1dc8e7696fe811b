/* Runtime tests: device listing and choice, the shared context's reference
 * count, a trivial kernel, a failing build's log, buffer limits, and that
 * every error is a sentence. With --expect-no-platform (run with
 * OCL_ICD_VENDORS pointing at an empty folder) it checks the no-driver path. */
#include "graupel/cl_runtime.h"
#include "gr_test.h"

#include <stdlib.h>
#include <string.h>

static int is_sentence(const char *s) {
  size_t n = strlen(s);
  return n > 10 && s[0] >= 'A' && s[0] <= 'Z' &&
         (s[n - 1] == '.' || strstr(s, "Build log") != NULL);
}

static void test_no_platform(void) {
  int count = -1;
  CHECK(gr_device_list(NULL, 0, &count) == GR_ERR_NO_PLATFORM);
  CHECK(count == 0);
  gr_context *ctx = (gr_context *)0x1;
  CHECK(gr_context_create(NULL, &ctx) == GR_ERR_NO_PLATFORM);
  CHECK(ctx == NULL);
  CHECK_MSG(is_sentence(gr_last_error(NULL)), "'%s'", gr_last_error(NULL));
  CHECK(strstr(gr_last_error(NULL), "pocl-opencl-icd") != NULL);
  CHECK(gr_context_acquire(NULL, &ctx) == GR_ERR_NO_PLATFORM);
  CHECK(ctx == NULL);
}

static void test_names(void) {
  /* Status values are pinned: they are part of the ABI. */
  CHECK(GR_OK == 0 && GR_ERR_INVALID_ARGUMENT == -1 && GR_ERR_BUILD == -5 && GR_ERR_ABORTED == -10);
  for (int a = GR_ERR_ABORTED; a <= GR_OK; ++a)
    for (int b = a + 1; b <= GR_OK; ++b)
      CHECK(strcmp(gr_status_string((gr_status)a), gr_status_string((gr_status)b)) != 0);
  CHECK(strcmp(gr_status_string(GR_ERR_BUILD), "GR_ERR_BUILD") == 0);
  CHECK(strcmp(gr_status_string((gr_status)-99), "GR_ERR_UNKNOWN") == 0);
  CHECK(strcmp(gr_cl_error_name(CL_BUILD_PROGRAM_FAILURE), "CL_BUILD_PROGRAM_FAILURE") == 0);
  for (int f = 0; f < GR_FIELD_COUNT; ++f)
    CHECK(gr_field_from_name(gr_field_name((gr_field)f)) == f);
  CHECK(strcmp(gr_field_name(GR_FIELD_SNOW_DEPTH), "snow_depth") == 0);
  CHECK(gr_field_from_name("nonsense") == -1);
  CHECK(gr_field_components(GR_FIELD_VELOCITY) == 3);
  CHECK(gr_field_components(GR_FIELD_ELEVATION) == 1);

  char msg[256];
  gr_grid g = {4, 4, 1.0, 1.0, 0.0, 0.0};
  CHECK(gr_grid_validate(&g, msg, sizeof(msg)) == GR_OK);
  g.dx = 0.0;
  CHECK(gr_grid_validate(&g, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK(is_sentence(msg) && strstr(msg, "spacing") != NULL);
  g.dx = 1.0;
  g.ny = 0;
  CHECK(gr_grid_validate(&g, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  g.ny = 4;
  g.x0 = NAN;
  CHECK(gr_grid_validate(&g, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
}

static void test_devices(void) {
  int count = 0;
  CHECK(gr_device_list(NULL, 0, &count) == GR_OK);
  CHECK(count >= 1);
  gr_device_info infos[8];
  int again = 0;
  CHECK(gr_device_list(infos, 8, &again) == GR_OK);
  CHECK(again == count);
  for (int i = 0; i < count && i < 8; ++i) {
    CHECK(infos[i].name[0] != '\0');
    CHECK(infos[i].platform[0] != '\0');
    CHECK(infos[i].max_alloc_bytes > 0);
    CHECK(infos[i].global_mem_bytes >= infos[i].max_alloc_bytes);
    CHECK(infos[i].is_gpu || infos[i].is_cpu || infos[i].compute_units > 0);
  }

  /* A request that matches nothing names itself in the error. */
  gr_context_options opt;
  gr_context_options_init(&opt);
  opt.device = "no-such-device-xyzzy";
  gr_context *ctx = NULL;
  CHECK(gr_context_create(&opt, &ctx) == GR_ERR_NO_DEVICE);
  CHECK(ctx == NULL);
  CHECK(strstr(gr_last_error(NULL), "no-such-device-xyzzy") != NULL);
  CHECK(is_sentence(gr_last_error(NULL)));

  /* A name substring picks that device. */
  opt.device = infos[0].name;
  CHECK(gr_context_create(&opt, &ctx) == GR_OK);
  CHECK(ctx && strcmp(gr_context_device_name(ctx), infos[0].name) == 0);
  gr_context_release(ctx);

  /* The environment variable is honoured when the option is empty. */
  int have_cpu = 0;
  for (int i = 0; i < count && i < 8; ++i)
    have_cpu |= infos[i].is_cpu;
  if (have_cpu) {
    setenv("GRAUPEL_DEVICE", "cpu", 1);
    opt.device = NULL;
    CHECK(gr_context_create(&opt, &ctx) == GR_OK);
    gr_device_info info;
    CHECK(gr_context_device_info(ctx, &info) == GR_OK);
    CHECK(info.is_cpu);
    CHECK(!gr_context_is_gpu(ctx));
    gr_context_release(ctx);
    /* ...and the option wins over the variable. */
    setenv("GRAUPEL_DEVICE", "no-such-device-xyzzy", 1);
    opt.device = "cpu";
    CHECK(gr_context_create(&opt, &ctx) == GR_OK);
    gr_context_release(ctx);
    opt.device = NULL;
    CHECK(gr_context_create(&opt, &ctx) == GR_ERR_NO_DEVICE);
    unsetenv("GRAUPEL_DEVICE");
  }
}

static int log_lines = 0;
static void count_log(void *user, gr_log_level level, const char *m) {
  (void)level;
  (void)m;
  ++*(int *)user;
}

static void test_shared(void) {
  gr_context_options opt;
  gr_context_options_init(&opt);
  opt.log = count_log;
  opt.log_user = &log_lines;
  gr_context *a = NULL, *b = NULL;
  CHECK(gr_context_acquire(&opt, &a) == GR_OK);
  CHECK(log_lines == 1); /* the chosen device is reported once */
  CHECK(gr_context_acquire(NULL, &b) == GR_OK);
  CHECK(a == b);
  CHECK(gr_context_refcount(a) == 2);
  CHECK(gr_context_retain(a) == a && gr_context_refcount(a) == 3);
  gr_context_release(a);
  gr_context_release(b);
  CHECK(gr_context_refcount(a) == 1);
  /* A private context is a different one. */
  gr_context *p = NULL;
  CHECK(gr_context_create(NULL, &p) == GR_OK);
  CHECK(p != a && gr_context_refcount(p) == 1);
  gr_context_release(p);
  gr_context_release(a); /* last reference: freed */
  gr_context_release(NULL);
  CHECK(gr_context_acquire(NULL, &b) == GR_OK);
  CHECK(gr_context_refcount(b) == 1);
  gr_context_release(b);
}

static void test_kernels(void) {
  gr_context *ctx = NULL;
  CHECK(gr_context_create(NULL, &ctx) == GR_OK);
  if (!ctx)
    return;

  /* Embedded sources: the shared header is inlined. */
  CHECK(gr_kernel_source_count() >= 2);
  const char *tn = gr_kernel_source_find("procedural_terrain");
  CHECK(tn != NULL);
  CHECK(tn && strstr(tn, "#include") == NULL);
  CHECK(tn && strstr(tn, "gr_hash_u32") != NULL);
  CHECK(gr_kernel_source_find("nope") == NULL);
  CHECK(gr_kernel_source_at(gr_kernel_source_count()) == NULL);

  /* Programs are built once per context. */
  cl_program p1 = NULL, p2 = NULL;
  CHECK(gr_program_get(ctx, "procedural_terrain", NULL, &p1) == GR_OK);
  CHECK(gr_program_get(ctx, "procedural_terrain", "", &p2) == GR_OK);
  CHECK(p1 != NULL && p1 == p2);
  CHECK(gr_program_get(ctx, "unknown_core", NULL, &p2) == GR_ERR_INVALID_ARGUMENT);
  CHECK(is_sentence(gr_last_error(ctx)));

  /* A trivial kernel computes what it should. */
  const char *src = "__kernel void axpb(__global float *x, float a, float b, "
                    "int n) { int i = get_global_id(0); if (i < n) x[i] = "
                    "a * x[i] + b; }";
  cl_program prog = NULL;
  cl_kernel k = NULL;
  CHECK(gr_program_build_source(ctx, src, NULL, &prog) == GR_OK);
  CHECK(gr_kernel_create(ctx, prog, "axpb", &k) == GR_OK);
  enum { N = 1000 };
  float host[N];
  for (int i = 0; i < N; ++i)
    host[i] = (float)i;
  cl_mem buf = NULL;
  CHECK(gr_buffer_create(ctx, CL_MEM_READ_WRITE, sizeof(host), host, &buf) == GR_OK);
  cl_float a = 2.0f, b = -3.0f;
  cl_int n = N;
  CHECK(gr_kernel_args(ctx, k, sizeof(cl_mem), &buf, sizeof(cl_float), &a, sizeof(cl_float), &b,
                       sizeof(cl_int), &n, (size_t)0) == GR_OK);
  CHECK(gr_enqueue_2d(ctx, k, 0, 0, N, 1, NULL) == GR_OK);
  memset(host, 0, sizeof(host));
  CHECK(gr_buffer_read(ctx, buf, 0, sizeof(host), host) == GR_OK);
  int wrong = 0;
  for (int i = 0; i < N; ++i)
    wrong += host[i] != 2.0f * (float)i - 3.0f;
  CHECK_MSG(wrong == 0, "%d of %d values wrong", wrong, N);

  /* A wrong argument index is reported with the kernel's name. */
  CHECK(gr_kernel_args(ctx, k, sizeof(cl_mem), &buf, sizeof(cl_float), &a, sizeof(cl_float), &b,
                       sizeof(cl_int), &n, sizeof(cl_int), &n, (size_t)0) == GR_ERR_OPENCL);
  CHECK(strstr(gr_last_error(ctx), "axpb") != NULL);
  CHECK(strstr(gr_last_error(ctx), "argument 4") != NULL);
  CHECK(gr_kernel_create(ctx, prog, "no_such_kernel", &k) == GR_ERR_OPENCL);
  CHECK(strstr(gr_last_error(ctx), "no_such_kernel") != NULL);
  clReleaseKernel(k);
  clReleaseProgram(prog);
  gr_buffer_release(&buf);
  CHECK(buf == NULL);
  gr_buffer_release(&buf); /* a zero handle is fine */

  /* A failing build reports the driver's log, which names the culprit. */
  const char *bad = "__kernel void broken(__global float *x) { x[0] = "
                    "undeclared_symbol_xyz; }";
  prog = NULL;
  CHECK(gr_program_build_source(ctx, bad, NULL, &prog) == GR_ERR_BUILD);
  CHECK(prog == NULL);
  const char *err = gr_last_error(ctx);
  CHECK_MSG(strstr(err, "Build log") != NULL, "'%s'", err);
  CHECK_MSG(strstr(err, "undeclared_symbol_xyz") != NULL, "'%s'", err);
  CHECK(strstr(err, "failed to build") != NULL);

  /* A buffer larger than the device allows is refused with the limit. */
  gr_device_info info;
  CHECK(gr_context_device_info(ctx, &info) == GR_OK);
  cl_mem big = NULL;
  size_t too_big = (size_t)info.max_alloc_bytes + 4096;
  CHECK(gr_buffer_create(ctx, CL_MEM_READ_WRITE, too_big, NULL, &big) == GR_ERR_TOO_LARGE);
  CHECK(big == NULL);
  CHECK(strstr(gr_last_error(ctx), "MiB") != NULL);
  CHECK(is_sentence(gr_last_error(ctx)));
  CHECK(gr_buffer_create(ctx, CL_MEM_READ_WRITE, 0, NULL, &big) == GR_ERR_INVALID_ARGUMENT);

  /* The detail can be set and read per context. */
  CHECK(gr_set_error(ctx, GR_ERR_IO, "Test sentence %d.", 7) == GR_ERR_IO);
  CHECK(strcmp(gr_last_error(ctx), "Test sentence 7.") == 0);
  CHECK(gr_cl_check(ctx, CL_SUCCESS, "nothing") == GR_OK);
  CHECK(gr_cl_check(ctx, CL_OUT_OF_HOST_MEMORY, "Something") == GR_ERR_OUT_OF_MEMORY);
  CHECK(strstr(gr_last_error(ctx), "CL_OUT_OF_HOST_MEMORY") != NULL);
  gr_context_release(ctx);
}

int main(int argc, char **argv) {
  if (argc > 1 && strcmp(argv[1], "--expect-no-platform") == 0) {
    test_no_platform();
    return GR_TEST_RESULT();
  }
  test_names();
  test_devices();
  test_shared();
  test_kernels();
  return GR_TEST_RESULT();
}
