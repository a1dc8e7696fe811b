/* Runtime tests: device listing and choice, the shared context's reference
 * count, a trivial kernel, kernel arguments by name, a failing build's log,
 * buffer limits, per-thread errors, the embedded sources, the field table,
 * mesh and point validation, and that every error is a sentence.
 * `test_runtime memcheck` (what valgrind runs) covers the same host paths with
 * one program build.
 * `test_runtime --expect-no-platform` (the same as `test_runtime
 * no_platform`; run with OCL_ICD_VENDORS pointing at an empty folder) checks
 * the no-driver path. */
#include "graupel/cl_runtime.h"
#include "graupel/reduce.h"
#include "gr_test.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>
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
  CHECK(strcmp(gr_field_unit(GR_FIELD_SNOW_DENSITY), "kg/m^3") == 0);
  CHECK(strcmp(gr_field_unit(GR_FIELD_DISCHARGE), "m^2/s") == 0);
  CHECK(strcmp(gr_field_unit(GR_FIELD_VELOCITY), "m/s") == 0);
  CHECK(strcmp(gr_field_unit(GR_FIELD_ELEVATION), "m") == 0);
  CHECK(gr_field_unit(GR_FIELD_COUNT) == NULL && gr_field_name((gr_field)-1) == NULL);
  CHECK(gr_field_components(GR_FIELD_COUNT) == 0);
  /* Every field has a name, 1 or 3 components and a unit. */
  for (int f = 0; f < GR_FIELD_COUNT; ++f) {
    const char *u = gr_field_unit((gr_field)f);
    int c = gr_field_components((gr_field)f);
    CHECK_MSG(gr_field_name((gr_field)f) && u && u[0] && (c == 1 || c == 3), "field %d", f);
  }

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

  /* ":N" picks the N-th of the devices a request matches: ":0" the first,
   * one past the last none, with the whole request in the sentence. */
  char nth[160];
  snprintf(nth, sizeof(nth), "%s:0", infos[0].name);
  opt.device = nth;
  CHECK(gr_context_create(&opt, &ctx) == GR_OK);
  CHECK(ctx && strcmp(gr_context_device_name(ctx), infos[0].name) == 0);
  gr_context_release(ctx);
  int same_name = 0;
  for (int i = 0; i < count && i < 8; ++i)
    same_name += strstr(infos[i].name, infos[0].name) != NULL ||
                 strstr(infos[i].platform, infos[0].name) != NULL;
  snprintf(nth, sizeof(nth), "%s:%d", infos[0].name, same_name);
  if (count <= 8) {
    CHECK(gr_context_create(&opt, &ctx) == GR_ERR_NO_DEVICE);
    CHECK(ctx == NULL);
    CHECK_MSG(strstr(gr_last_error(NULL), nth) != NULL, "'%s'", gr_last_error(NULL));
  }
  opt.device = "auto:0";
  CHECK(gr_context_create(&opt, &ctx) == GR_OK);
  gr_context *first = NULL;
  opt.device = "auto";
  CHECK(gr_context_create(&opt, &first) == GR_OK);
  CHECK(ctx && first && gr_context_device(ctx) == gr_context_device(first));
  gr_context_release(ctx);
  gr_context_release(first);

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
    setenv("GRAUPEL_DEVICE", "cpu:0", 1);
    CHECK(gr_context_create(&opt, &ctx) == GR_OK);
    CHECK(ctx && gr_context_device_info(ctx, &info) == GR_OK && info.is_cpu);
    gr_context_release(ctx);
    setenv("GRAUPEL_DEVICE", "cpu:64", 1);
    CHECK(gr_context_create(&opt, &ctx) == GR_ERR_NO_DEVICE);
    CHECK(strstr(gr_last_error(NULL), "'cpu:64' (from GRAUPEL_DEVICE)") != NULL);
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
  /* An error goes to the caller, not also to the log: reported once. */
  CHECK(gr_set_error(a, GR_ERR_INVALID_ARGUMENT, "A test error.") == GR_ERR_INVALID_ARGUMENT);
  CHECK(strcmp(gr_last_error(a), "A test error.") == 0 && log_lines == 1);
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

static int count_of(const char *hay, const char *needle) {
  int n = 0;
  for (const char *p = hay; (p = strstr(p, needle)) != NULL; p += strlen(needle))
    ++n;
  return n;
}

static void test_embed(void) {
  /* Every kernels/cl header a source includes is inlined, recursively, once:
   * procedural_terrain.cl includes common.h and procedural_terrain_shared.h
   * (not common.h), whose definitions must be in the embedded text. */
  CHECK(gr_kernel_source_count() >= 3);
  const char *tn = gr_kernel_source_find("procedural_terrain");
  CHECK(tn != NULL);
  if (!tn)
    return;
  CHECK(strstr(tn, "#include") == NULL);
  CHECK(strstr(tn, "gr_hash_u32") != NULL);
  CHECK_MSG(count_of(tn, "#define GR_PT_TABLE_STRIDE 4") == 1, "%d",
            count_of(tn, "#define GR_PT_TABLE_STRIDE 4"));
  CHECK(count_of(tn, "#define GR_PT_KIND_BILLOW 2") == 1);
  for (int i = 0; i < gr_kernel_source_count(); ++i) {
    const gr_kernel_source *src = gr_kernel_source_at(i);
    /* No include of a kernels/cl header is left, and common.h comes once
     * even where several headers include it. */
    CHECK_MSG(strstr(src->text, "#include \"") == NULL, "%s keeps an include", src->name);
    CHECK_MSG(count_of(src->text, "#define GRAUPEL_CL_COMMON_H") == 1, "%s has common.h %d times",
              src->name, count_of(src->text, "#define GRAUPEL_CL_COMMON_H"));
  }
  CHECK(gr_kernel_source_find("nope") == NULL);
  CHECK(gr_kernel_source_at(gr_kernel_source_count()) == NULL);
}

static void test_kernels(void) {
  gr_context *ctx = NULL;
  CHECK(gr_context_create(NULL, &ctx) == GR_OK);
  if (!ctx)
    return;

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
  CHECK(gr_enqueue_1d(ctx, k, N) == GR_OK);
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

  /* The detail can be set and read (it is the calling thread's). */
  CHECK(gr_set_error(ctx, GR_ERR_IO, "Test sentence %d.", 7) == GR_ERR_IO);
  CHECK(strcmp(gr_last_error(ctx), "Test sentence 7.") == 0);
  CHECK(gr_cl_check(ctx, CL_SUCCESS, "nothing") == GR_OK);
  CHECK(gr_cl_check(ctx, CL_OUT_OF_HOST_MEMORY, "Something") == GR_ERR_OUT_OF_MEMORY);
  CHECK(strstr(gr_last_error(ctx), "CL_OUT_OF_HOST_MEMORY") != NULL);
  gr_context_release(ctx);
}

/* Arguments by name: set in any order, checked by what the kernel computes. */
static void test_kernel_arg(void) {
  gr_context *ctx = NULL;
  CHECK(gr_context_create(NULL, &ctx) == GR_OK);
  if (!ctx)
    return;
  const char *src = "__kernel void axpb(__global float *x, float a, float b, int n) {"
                    " int i = get_global_id(0); if (i < n) x[i] = a * x[i] + b; }\n"
                    "__kernel void bxpa(int n, float b, float a, __global float *x) {"
                    " int i = get_global_id(0); if (i < n) x[i] = b * x[i] + a; }";
  cl_program prog = NULL;
  CHECK(gr_program_build_source(ctx, src, NULL, &prog) == GR_OK);
  if (!prog) {
    gr_context_release(ctx);
    return;
  }
  enum { N = 257 };
  float host[N];
  for (int i = 0; i < N; ++i)
    host[i] = (float)i;
  cl_mem x = NULL;
  CHECK(gr_buffer_create(ctx, CL_MEM_READ_WRITE, sizeof(host), host, &x) == GR_OK);
  cl_float a = 2.0f, b = -3.0f;
  cl_int n = N;
  /* Kernels are created and released in turn so that a new kernel may get a
   * released one's handle: the cached names must not leak across. */
  for (int round = 0; round < 6; ++round) {
    const char *name = round % 2 ? "bxpa" : "axpb";
    cl_kernel k = NULL;
    CHECK(gr_kernel_create(ctx, prog, name, &k) == GR_OK);
    if (!k)
      break;
    CHECK(GR_KERNEL_ARG(ctx, k, n) == GR_OK);
    CHECK(GR_KERNEL_ARG(ctx, k, b) == GR_OK);
    CHECK(GR_KERNEL_ARG(ctx, k, x) == GR_OK);
    CHECK(GR_KERNEL_ARG(ctx, k, a) == GR_OK);
    CHECK(gr_buffer_write(ctx, x, 0, sizeof(host), host) == GR_OK);
    CHECK(gr_enqueue_1d(ctx, k, N) == GR_OK);
    float out[N];
    CHECK(gr_buffer_read(ctx, x, 0, sizeof(out), out) == GR_OK);
    int wrong = 0;
    for (int i = 0; i < N; ++i)
      wrong += out[i] != (round % 2 ? b * (float)i + a : a * (float)i + b);
    CHECK_MSG(wrong == 0, "%s, round %d: %d of %d values wrong", name, round, wrong, N);
    a += 1.0f;
    clReleaseKernel(k);
  }

  /* An unknown name and a wrong size give a sentence naming the kernel, the
   * argument and (for the driver's refusal) the OpenCL error. */
  cl_kernel k = NULL;
  CHECK(gr_kernel_create(ctx, prog, "axpb", &k) == GR_OK);
  cl_int nope = 1;
  CHECK(GR_KERNEL_ARG(ctx, k, nope) == GR_ERR_INVALID_ARGUMENT);
  const char *e = gr_last_error(ctx);
  CHECK_MSG(strstr(e, "'axpb'") && strstr(e, "'nope'") && is_sentence(e), "'%s'", e);
  double wide = 1.0;
  CHECK(gr_kernel_arg(ctx, k, "n", sizeof(wide), &wide) == GR_ERR_OPENCL);
  e = gr_last_error(ctx);
  CHECK_MSG(strstr(e, "'axpb'") && strstr(e, "'n'") && strstr(e, "CL_INVALID_ARG_SIZE") &&
                is_sentence(e),
            "'%s'", e);
  CHECK(gr_kernel_arg(ctx, NULL, "n", sizeof(n), &n) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_kernel_arg(ctx, k, NULL, sizeof(n), &n) == GR_ERR_INVALID_ARGUMENT);

  /* More kernels than the cache holds: every one still finds its names. */
  int failures = 0;
  for (int i = 0; i < 100; ++i) {
    cl_kernel ki = NULL;
    if (gr_kernel_create(ctx, prog, i % 2 ? "bxpa" : "axpb", &ki) != GR_OK) {
      ++failures;
      continue;
    }
    failures += GR_KERNEL_ARG(ctx, ki, n) != GR_OK;
    failures += GR_KERNEL_ARG(ctx, ki, x) != GR_OK;
    clReleaseKernel(ki);
  }
  CHECK_MSG(failures == 0, "%d failures", failures);
  clReleaseKernel(k);
  clReleaseProgram(prog);
  gr_buffer_release(&x);
  gr_context_release(ctx);
}

static void *other_thread(void *arg) {
  gr_set_error(NULL, GR_ERR_IO, "The other thread failed.");
  snprintf((char *)arg, 64, "%s", gr_last_error(NULL));
  return NULL;
}

static void test_errors_per_thread(void) {
  gr_set_error(NULL, GR_ERR_BUILD, "The main thread failed.");
  char seen[64] = "";
  pthread_t th;
  CHECK(pthread_create(&th, NULL, other_thread, seen) == 0);
  pthread_join(th, NULL);
  CHECK(strcmp(seen, "The other thread failed.") == 0);
  CHECK(strcmp(gr_last_error(NULL), "The main thread failed.") == 0);

  /* gr_error_keep copies the thread's sentence into a handle's buffer,
   * truncated and terminated, and only for a failure. */
  char keep[12];
  memset(keep, 'x', sizeof(keep));
  CHECK(gr_error_keep(keep, sizeof(keep), GR_ERR_BUILD) == GR_ERR_BUILD);
  CHECK(strcmp(keep, "The main th") == 0);
  gr_set_error(NULL, GR_ERR_IO, "Another.");
  CHECK(gr_error_keep(keep, sizeof(keep), GR_OK) == GR_OK);
  CHECK(strcmp(keep, "The main th") == 0);
  CHECK(gr_error_keep(NULL, 0, GR_ERR_IO) == GR_ERR_IO);
  /* A sentence may quote the one before it. */
  gr_set_error(NULL, GR_ERR_IO, "Inner.");
  gr_set_error(NULL, GR_ERR_IO, "Outer: %s", gr_last_error(NULL));
  CHECK(strcmp(gr_last_error(NULL), "Outer: Inner.") == 0);
}

/* A unit cube, counter-clockwise seen from outside. */
static const float cube_v[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1,    0, 0, 0,
                               1, 1, 0, 1, 1, 1, 1, 0, 1, 1, 0.5f, 0, 0};
static const int cube_t[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                             2, 3, 7, 2, 7, 6, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};

static gr_mesh cube(float *v, int *t) {
  gr_mesh m;
  memset(&m, 0, sizeof(m));
  memcpy(v, cube_v, sizeof(cube_v));
  memcpy(t, cube_t, sizeof(cube_t));
  m.vertices = v;
  m.nvertices = 8; /* the ninth, (0.5, 0, 0), only for the zero-area case */
  m.triangles = t;
  m.ntriangles = 12;
  for (int i = 0; i < 4; ++i)
    m.transform[5 * i] = 1.0;
  m.transform[12] = 10.0; /* a translation */
  return m;
}

/* gr_mesh_check: the answers of gr_mesh_validate, with a memo of the last
 * mesh that passed. The same arrays under a new transform pass on the memo
 * (and a singular transform is still refused); a mesh changed in place, the
 * same pointers, is checked again and refused when broken; an open mesh
 * remembered as such is checked again when asked for a closed one. */
static void test_mesh_memo(void) {
  float v[27];
  int t[39];
  char msg[512];
  gr_mesh_memo memo;
  memset(&memo, 0, sizeof(memo));
  gr_mesh m = cube(v, t);
  CHECK_MSG(gr_mesh_check(&memo, &m, 1, msg, sizeof(msg)) == GR_OK, "%s", msg);
  CHECK(memo.vertices && memo.ntriangles == 12 && memo.closed == 1);
  m.transform[12] = 20.0; /* moved */
  CHECK(gr_mesh_check(&memo, &m, 1, msg, sizeof(msg)) == GR_OK);
  m.transform[10] = 0.0;
  CHECK(gr_mesh_check(&memo, &m, 1, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT &&
        strstr(msg, "singular"));
  m.transform[10] = 1.0;
  t[1] = 1, t[2] = 2; /* triangle 0 flipped in place */
  CHECK(gr_mesh_check(&memo, &m, 1, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT &&
        strstr(msg, "winding"));
  CHECK(memo.vertices == NULL); /* a refused mesh is not remembered */
  CHECK(gr_mesh_check(&memo, &m, 0, msg, sizeof(msg)) == GR_OK && memo.closed == 0);
  CHECK(gr_mesh_check(&memo, &m, 1, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  m = cube(v, t);
  CHECK(gr_mesh_check(&memo, &m, 1, msg, sizeof(msg)) == GR_OK);
  v[3 * 3 + 1] = NAN; /* a vertex broken in place */
  CHECK(gr_mesh_check(&memo, &m, 1, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT &&
        strstr(msg, "vertex 3"));
  CHECK(gr_mesh_check(NULL, &m, 1, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  gr_mesh_memo_free(&memo);
  CHECK(memo.vertices == NULL && memo.triangles == NULL);
}

static void test_mesh(void) {
  float v[27];
  int t[39];
  char msg[512];
  gr_mesh m = cube(v, t);
  CHECK_MSG(gr_mesh_validate(&m, 1, msg, sizeof(msg)) == GR_OK, "%s", msg);

  m.ntriangles = 11; /* (1, 6, 5) removed: its three edges are open */
  CHECK(gr_mesh_validate(&m, 1, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "open") && strstr(msg, "vertices 1 and 5") && is_sentence(msg), "'%s'",
            msg);
  CHECK(gr_mesh_validate(&m, 0, msg, sizeof(msg)) == GR_OK);

  m = cube(v, t);
  t[1] = 1, t[2] = 2; /* triangle 0 flipped */
  CHECK(gr_mesh_validate(&m, 1, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "winding") && strstr(msg, "triangles 0 and") && is_sentence(msg), "'%s'",
            msg);
  CHECK(gr_mesh_validate(&m, 0, msg, sizeof(msg)) == GR_OK);

  m = cube(v, t);
  v[3 * 3 + 1] = NAN;
  CHECK(gr_mesh_validate(&m, 0, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "vertex 3") && strstr(msg, "nan") && is_sentence(msg), "'%s'", msg);

  m = cube(v, t);
  t[3 * 7 + 2] = 8;
  CHECK(gr_mesh_validate(&m, 0, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "triangle 7") && strstr(msg, "vertex 8") && strstr(msg, "0 to 7"), "'%s'",
            msg);
  t[3 * 7 + 2] = -1;
  CHECK(gr_mesh_validate(&m, 0, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);

  m = cube(v, t);
  m.nvertices = 9;
  t[36] = 0, t[37] = 8, t[38] = 1; /* collinear corners: zero area */
  m.ntriangles = 13;
  CHECK(gr_mesh_validate(&m, 0, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "triangle 12") && strstr(msg, "zero area"), "'%s'", msg);
  t[37] = 1, t[38] = 1; /* a repeated corner */
  CHECK(gr_mesh_validate(&m, 0, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(msg, "zero area") != NULL);
  /* A tiny but proper triangle is not degenerate. */
  float tiny[] = {0, 0, 0, 1e-6f, 0, 0, 0, 1e-6f, 0};
  int tri[] = {0, 1, 2};
  gr_mesh small = m;
  small.vertices = tiny, small.nvertices = 3, small.triangles = tri, small.ntriangles = 1;
  CHECK(gr_mesh_validate(&small, 0, msg, sizeof(msg)) == GR_OK);
  CHECK(gr_mesh_validate(&small, 1, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);

  m = cube(v, t);
  m.transform[10] = 0.0; /* z scaled to nothing */
  CHECK(gr_mesh_validate(&m, 1, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "singular") && is_sentence(msg), "'%s'", msg);
  m.transform[10] = 1e-9; /* small but invertible: a scale, not a fault */
  CHECK(gr_mesh_validate(&m, 1, msg, sizeof(msg)) == GR_OK);
  m.transform[10] = 1.0;
  m.transform[13] = INFINITY;
  CHECK(gr_mesh_validate(&m, 1, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "element 13") && strstr(msg, "finite"), "'%s'", msg);

  m = cube(v, t);
  m.ntriangles = 0;
  CHECK(gr_mesh_validate(&m, 0, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_mesh_validate(NULL, 0, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_mesh_validate(NULL, 0, NULL, 0) == GR_ERR_INVALID_ARGUMENT);
}

static void test_points(void) {
  float pos[] = {0, 0, 0, 1, 2, 3, 4, 5, 6};
  float diameter[] = {1e-3f, 2e-3f, 3e-3f};
  float velocity[] = {0, 0, -5, 0, 0, -6, 1, 0, -7};
  gr_points_array arrays[2] = {{"diameter", 1, diameter}, {"velocity", 3, velocity}};
  gr_points p = {pos, 3, arrays, 2};
  char msg[512];
  CHECK_MSG(gr_points_validate(&p, msg, sizeof(msg)) == GR_OK, "%s", msg);
  gr_points none = {NULL, 0, NULL, 0};
  CHECK(gr_points_validate(&none, msg, sizeof(msg)) == GR_OK);

  pos[4] = NAN;
  CHECK(gr_points_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "point 1") && strstr(msg, "y = nan") && is_sentence(msg), "'%s'", msg);
  pos[4] = 2;
  arrays[1].name = "";
  CHECK(gr_points_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "array 1") && strstr(msg, "no name"), "'%s'", msg);
  arrays[1].name = NULL;
  CHECK(gr_points_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  arrays[1].name = "diameter";
  CHECK(gr_points_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "'diameter'") && strstr(msg, "distinct"), "'%s'", msg);
  arrays[1].name = "velocity";
  arrays[1].components = 0;
  CHECK(gr_points_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "'velocity'") && strstr(msg, "0 components"), "'%s'", msg);
  arrays[1].components = 10;
  CHECK(gr_points_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK(strstr(msg, "10 components") != NULL);
  arrays[1].components = 3;
  velocity[8] = INFINITY;
  CHECK(gr_points_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(msg, "'velocity'") && strstr(msg, "point 2") && strstr(msg, "component 2"),
            "'%s'", msg);
  velocity[8] = -7;
  CHECK(gr_points_validate(&p, msg, sizeof(msg)) == GR_OK);
  p.npoints = -1;
  CHECK(gr_points_validate(&p, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_points_validate(NULL, NULL, 0) == GR_ERR_INVALID_ARGUMENT);
}

/* For valgrind, where every program build takes seconds: the paths of
 * kernels and kernel_arg with one program build (kernel_arg's source) and one
 * refused build, plus the argument cache's eviction: more kernels alive at
 * once than the cache holds (64 entries). */
static void test_memcheck_kernels(void) {
  gr_context *ctx = NULL;
  CHECK(gr_context_create(NULL, &ctx) == GR_OK);
  if (!ctx)
    return;
  cl_program p2 = NULL;
  CHECK(gr_program_get(ctx, "unknown_core", NULL, &p2) == GR_ERR_INVALID_ARGUMENT);
  CHECK(p2 == NULL && is_sentence(gr_last_error(ctx)));
  CHECK(gr_program_get(NULL, "rain_runoff", NULL, &p2) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_program_build_source(ctx, NULL, NULL, &p2) == GR_ERR_INVALID_ARGUMENT);

  const char *src = "__kernel void axpb(__global float *x, float a, float b, int n) {"
                    " int i = get_global_id(0); if (i < n) x[i] = a * x[i] + b; }\n"
                    "__kernel void bxpa(int n, float b, float a, __global float *x) {"
                    " int i = get_global_id(0); if (i < n) x[i] = b * x[i] + a; }";
  cl_program prog = NULL;
  CHECK(gr_program_build_source(ctx, src, NULL, &prog) == GR_OK);
  enum { N = 19, KEPT = 80 };
  float host[N], out[N];
  for (int i = 0; i < N; ++i)
    host[i] = (float)i;
  cl_mem x = NULL;
  CHECK(gr_buffer_create(ctx, CL_MEM_READ_WRITE, sizeof(host), host, &x) == GR_OK);
  cl_kernel *kept = calloc(KEPT, sizeof(cl_kernel));
  if (!prog || !x || !kept) {
    free(kept);
    clReleaseProgram(prog);
    gr_buffer_release(&x);
    gr_context_release(ctx);
    return;
  }
  cl_float a = 2.0f, b = -3.0f;
  cl_int n = N;

  /* Positional arguments, and a wrong index named with the kernel. */
  cl_kernel k = NULL;
  CHECK(gr_kernel_create(ctx, prog, "axpb", &k) == GR_OK);
  CHECK(gr_kernel_args(ctx, k, sizeof(cl_mem), &x, sizeof(cl_float), &a, sizeof(cl_float), &b,
                       sizeof(cl_int), &n, (size_t)0) == GR_OK);
  CHECK(gr_enqueue_1d(ctx, k, N) == GR_OK);
  CHECK(gr_buffer_read(ctx, x, 0, sizeof(out), out) == GR_OK);
  int wrong = 0;
  for (int i = 0; i < N; ++i)
    wrong += out[i] != a * (float)i + b;
  CHECK_MSG(wrong == 0, "positional: %d of %d values wrong", wrong, N);
  CHECK(gr_kernel_args(ctx, k, sizeof(cl_mem), &x, sizeof(cl_float), &a, sizeof(cl_float), &b,
                       sizeof(cl_int), &n, sizeof(cl_int), &n, (size_t)0) == GR_ERR_OPENCL);
  CHECK(strstr(gr_last_error(ctx), "axpb") && strstr(gr_last_error(ctx), "argument 4"));
  cl_kernel none = NULL;
  CHECK(gr_kernel_create(ctx, prog, "no_such_kernel", &none) == GR_ERR_OPENCL);
  CHECK(strstr(gr_last_error(ctx), "no_such_kernel") != NULL);

  /* By name: unknown names, wrong sizes and missing handles are sentences. */
  cl_int nope = 1;
  CHECK(GR_KERNEL_ARG(ctx, k, nope) == GR_ERR_INVALID_ARGUMENT);
  CHECK_MSG(strstr(gr_last_error(ctx), "'nope'") && is_sentence(gr_last_error(ctx)), "'%s'",
            gr_last_error(ctx));
  double wide = 1.0;
  CHECK(gr_kernel_arg(ctx, k, "n", sizeof(wide), &wide) == GR_ERR_OPENCL);
  CHECK(strstr(gr_last_error(ctx), "CL_INVALID_ARG_SIZE") != NULL);
  CHECK(gr_kernel_arg(ctx, NULL, "n", sizeof(n), &n) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_kernel_arg(ctx, k, NULL, sizeof(n), &n) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_kernel_arg(NULL, k, "n", sizeof(n), &n) == GR_ERR_INVALID_ARGUMENT);
  clReleaseKernel(k);

  /* KEPT kernels alive at once, alternating argument orders: setting x on
   * each after n on all of them finds every early entry evicted; the first
   * kernel, re-read, still computes with its own argument order. */
  int failures = 0;
  for (int i = 0; i < KEPT; ++i) {
    failures += gr_kernel_create(ctx, prog, i % 2 ? "bxpa" : "axpb", &kept[i]) != GR_OK;
    failures += kept[i] && GR_KERNEL_ARG(ctx, kept[i], n) != GR_OK;
  }
  for (int i = 0; i < KEPT; ++i)
    failures += kept[i] && GR_KERNEL_ARG(ctx, kept[i], x) != GR_OK;
  CHECK_MSG(failures == 0, "%d failures", failures);
  for (int r = 0; r < 2 && kept[r]; ++r) {
    CHECK(GR_KERNEL_ARG(ctx, kept[r], a) == GR_OK);
    CHECK(GR_KERNEL_ARG(ctx, kept[r], b) == GR_OK);
    CHECK(gr_buffer_write(ctx, x, 0, sizeof(host), host) == GR_OK);
    CHECK(gr_enqueue_1d(ctx, kept[r], N) == GR_OK);
    CHECK(gr_buffer_read(ctx, x, 0, sizeof(out), out) == GR_OK);
    wrong = 0;
    for (int i = 0; i < N; ++i)
      wrong += out[i] != (r ? b * (float)i + a : a * (float)i + b);
    CHECK_MSG(wrong == 0, "kernel %d after eviction: %d of %d values wrong", r, wrong, N);
  }
  /* A released kernel's handle may come back for the other kernel: its
   * cached names must not be used. */
  for (int i = 0; i < KEPT; ++i)
    if (kept[i])
      clReleaseKernel(kept[i]);
  for (int round = 0; round < 2; ++round) {
    k = NULL;
    CHECK(gr_kernel_create(ctx, prog, round ? "bxpa" : "axpb", &k) == GR_OK);
    if (!k)
      break;
    CHECK(GR_KERNEL_ARG(ctx, k, n) == GR_OK && GR_KERNEL_ARG(ctx, k, x) == GR_OK);
    CHECK(GR_KERNEL_ARG(ctx, k, a) == GR_OK && GR_KERNEL_ARG(ctx, k, b) == GR_OK);
    CHECK(gr_buffer_write(ctx, x, 0, sizeof(host), host) == GR_OK);
    CHECK(gr_enqueue_1d(ctx, k, N) == GR_OK);
    CHECK(gr_buffer_read(ctx, x, 0, sizeof(out), out) == GR_OK);
    wrong = 0;
    for (int i = 0; i < N; ++i)
      wrong += out[i] != (round ? b * (float)i + a : a * (float)i + b);
    CHECK_MSG(wrong == 0, "round %d: %d of %d values wrong", round, wrong, N);
    clReleaseKernel(k);
  }
  free(kept);
  clReleaseProgram(prog);
  gr_buffer_release(&x);
  CHECK(x == NULL);
  gr_buffer_release(&x);

  /* A failing build reports the driver's log. Refused options take the same
   * path as a compile error (the kernels subtest has one) without running
   * the compiler, which under valgrind takes seconds. */
  CHECK(gr_program_build_source(ctx, src, "-cl-no-such-option-xyz", &prog) == GR_ERR_BUILD);
  CHECK(prog == NULL);
  CHECK_MSG(strstr(gr_last_error(ctx), "Build log") &&
                strstr(gr_last_error(ctx), "-cl-no-such-option-xyz") &&
                strstr(gr_last_error(ctx), "failed to build"),
            "'%s'", gr_last_error(ctx));

  /* Buffer limits, and the error helpers. */
  gr_device_info info;
  CHECK(gr_context_device_info(ctx, &info) == GR_OK);
  cl_mem big = NULL;
  CHECK(gr_buffer_create(ctx, CL_MEM_READ_WRITE, (size_t)info.max_alloc_bytes + 4096, NULL, &big) ==
        GR_ERR_TOO_LARGE);
  CHECK(big == NULL && strstr(gr_last_error(ctx), "MiB") != NULL);
  CHECK(gr_buffer_create(ctx, CL_MEM_READ_WRITE, 0, NULL, &big) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_context_device_info(ctx, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_cl_check(ctx, CL_SUCCESS, "nothing") == GR_OK);
  CHECK(gr_cl_check(ctx, CL_OUT_OF_HOST_MEMORY, "Something") == GR_ERR_OUT_OF_MEMORY);
  CHECK(strstr(gr_last_error(ctx), "CL_OUT_OF_HOST_MEMORY") != NULL);
  gr_context_release(ctx);
}

/* What valgrind runs (memcheck.runtime): every host entry point and error
 * path once, with one program build; the full subtests run natively and
 * under ASan. */
static void test_memcheck(void) {
  test_names();
  test_devices();
  test_shared();
  test_embed();
  test_memcheck_kernels();
  test_errors_per_thread();
  test_mesh();
  test_points();
}

/* Without an OpenCL device the tests that need one are skipped (77). */
static int have_device(void) {
  gr_context *ctx = NULL;
  if (gr_context_create(NULL, &ctx) != GR_OK)
    return 0;
  gr_context_release(ctx);
  return 1;
}

/* gr_enqueue_1d runs every item once (a 2-D launch of n x 1 runs each 16
 * times on a GPU, which a read-modify-write kernel must not see): an
 * integer count per item. */
static void test_enqueue_1d(void) {
  gr_context *ctx = NULL;
  CHECK(gr_context_create(NULL, &ctx) == GR_OK);
  if (!ctx)
    return;
  const char *src = "__kernel void tally(__global int *count, int n) {"
                    " int i = get_global_id(0); if (i < n) atomic_inc(count + i); }";
  cl_program prog = NULL;
  cl_kernel k = NULL;
  CHECK(gr_program_build_source(ctx, src, NULL, &prog) == GR_OK);
  if (prog)
    CHECK(gr_kernel_create(ctx, prog, "tally", &k) == GR_OK);
  enum { N = 1000 };
  int host[N] = {0};
  cl_mem count = NULL;
  CHECK(gr_buffer_create(ctx, CL_MEM_READ_WRITE, sizeof(host), host, &count) == GR_OK);
  cl_int n = N;
  if (k && count) {
    CHECK(GR_KERNEL_ARG(ctx, k, count) == GR_OK);
    CHECK(GR_KERNEL_ARG(ctx, k, n) == GR_OK);
    CHECK(gr_enqueue_1d(ctx, k, N) == GR_OK);
    CHECK(gr_enqueue_1d(ctx, k, 0) == GR_OK); /* nothing */
    CHECK(gr_buffer_read(ctx, count, 0, sizeof(host), host) == GR_OK);
    int wrong = 0;
    for (int i = 0; i < N; ++i)
      wrong += host[i] != 1;
    printf("enqueue_1d: %d of %d items ran other than once\n", wrong, N);
    CHECK(wrong == 0);
  }
  gr_buffer_release(&count);
  if (k)
    clReleaseKernel(k);
  gr_context_release(ctx);
}

/* The ledger fixed point (graupel/reduce.h): floats convert exactly (or to
 * within 2^-54 below 2^-31), words add up the same in any order and split,
 * 128-bit products are exact and round once to double, and packed integers
 * sum exactly through doubles. */
static double fixed_exact(gr_fixed f) {
  /* Exact in double for the values used here (both words small). */
  return ldexp((double)f.coarse, -GR_FIXED_COARSE_BITS) +
         ldexp((double)f.fine, -GR_FIXED_FINE_BITS);
}

static void test_fixed_point(void) {
  const float xs[] = {0.0f,   1.0f,    -1.0f,    0.1f,     3.3e-5f,
                      1e-7f,  0.7f,    123.456f, -0.0123f, 4.6566129e-10f /* 2^-31 */,
                      1e-12f, -3e-15f, 1e-30f,   2.5e5f};
  int exact = 1, near = 1;
  for (size_t k = 0; k < sizeof(xs) / sizeof(xs[0]); ++k) {
    gr_fixed f = gr_fixed_from_float(xs[k]);
    double back = fixed_exact(f), err = fabs(back - (double)xs[k]);
    CHECK_MSG(f.fine > -(1ll << 30) && f.fine < (1ll << 30), "%g: fine word %lld", xs[k], f.fine);
    if (fabsf(xs[k]) >= 4.6566129e-10f)
      exact &= back == (double)xs[k];
    else
      near &= err < ldexp(1.0, -54);
    CHECK_MSG(gr_fixed_value(f) == back, "%g: gr_fixed_value %.17g, the words %.17g", xs[k],
              gr_fixed_value(f), back);
  }
  CHECK_MSG(exact, "floats from 2^-31 up convert exactly");
  CHECK_MSG(near, "smaller floats convert to within 2^-54");

  /* A sum of many floats: the same words in any order and any split. */
  enum { N = 5000 };
  static float v[N];
  for (int i = 0; i < N; ++i)
    v[i] = (float)(0.3 * sin(i * 0.37) * sin(i * 0.37) * (i % 7 == 0 ? 1e4 : 1.0) +
                   (i % 11 == 0 ? -2e-6 : 0.0));
  gr_fixed forward = {0, 0}, backward = {0, 0}, parts[2] = {{0, 0}, {0, 0}};
  double naive_f = 0.0, naive_b = 0.0;
  for (int i = 0; i < N; ++i) {
    gr_fixed_add(&forward, gr_fixed_from_float(v[i]));
    gr_fixed_add(&backward, gr_fixed_from_float(v[N - 1 - i]));
    gr_fixed_add(&parts[i % 3 == 0], gr_fixed_from_float(v[i]));
    naive_f += v[i];
    naive_b += v[N - 1 - i];
  }
  gr_fixed_add(&parts[0], parts[1]);
  CHECK(forward.coarse == backward.coarse && forward.fine == backward.fine);
  CHECK(forward.coarse == parts[0].coarse && forward.fine == parts[0].fine);
  CHECK(gr_fixed_value(forward) == gr_fixed_value(parts[0]));
  CHECK_NEAR(gr_fixed_value(forward), naive_f, 1e-12 * fabs(naive_f));
  printf("fixed point: %d floats summed forward, backward and split: the same words (%.17g); "
         "double sums forward and backward differ by %.3g\n",
         N, gr_fixed_value(forward), naive_f - naive_b);

  /* 128-bit products, signs, and one rounding to double. */
  gr_wide p = gr_wide_mul(3ll << 40, 5ll << 30);
  CHECK(gr_wide_value(p, 0) == ldexp(15.0, 70));
  gr_wide q = gr_wide_mul(-(3ll << 40), 5ll << 30);
  CHECK(gr_wide_value(q, 10) == -ldexp(15.0, 60));
  gr_wide_add(&p, q);
  CHECK(p.lo == 0 && p.hi == 0);
  gr_wide big = gr_wide_mul(INT64_MAX, INT64_MAX); /* (2^63 - 1)^2 = 2^126 - 2^64 + 1 */
  CHECK(big.hi == INT64_MAX / 2 && big.lo == 1u);
  gr_wide s3 = gr_wide_scale(gr_wide_mul(-7, 1ll << 40), 1ll << 50);
  CHECK(gr_wide_value(s3, 90) == -7.0);
  /* 2^64 + 2^11 + 1: above the halfway point between 2^64 and its next
   * double (2^12 away), so it rounds up; without the 1 it ties to even. */
  gr_wide tie = {(1ull << 11) + 1u, 1};
  CHECK(gr_wide_value(tie, 0) == ldexp(1.0, 64) + ldexp(1.0, 12));
  tie.lo = 1ull << 11;
  CHECK(gr_wide_value(tie, 0) == ldexp(1.0, 64));

  /* Packed through doubles and summed as an allreduce would: exact totals. */
  const long long vals[3][2] = {{INT64_MAX / 4, -5}, {-(INT64_MAX / 8), 1ll << 40}, {12345, -7}};
  const gr_wide wides[3] = {gr_wide_mul(1ll << 62, 1ll << 60), gr_wide_mul(-3, 1ll << 62),
                            gr_wide_mul(-(1ll << 61), 1ll << 61)};
  double sum[GR_FIXED_PACKED(2, 1)] = {0};
  long long want[2] = {0, 0};
  gr_wide want_w = {0, 0};
  for (int r = 0; r < 3; ++r) {
    double packed[GR_FIXED_PACKED(2, 1)];
    gr_fixed_pack(vals[r], 2, &wides[r], 1, packed);
    for (int k = 0; k < GR_FIXED_PACKED(2, 1); ++k) {
      CHECK(packed[k] == floor(packed[k]) && fabs(packed[k]) <= 4294967296.0);
      sum[k] += packed[k];
    }
    want[0] += vals[r][0];
    want[1] += vals[r][1];
    gr_wide_add(&want_w, wides[r]);
  }
  long long got[2];
  gr_wide got_w;
  gr_fixed_unpack(sum, got, 2, &got_w, 1);
  CHECK(got[0] == want[0] && got[1] == want[1]);
  CHECK(got_w.lo == want_w.lo && got_w.hi == want_w.hi);
}

/* Integer sums beyond reduce.h's bounds wrap modulo 2^64 on the host as on
 * the device, never overflow (the sanitizer build traps on an overflow): a
 * damaged checkpoint's huge depths made rain runoff's ledger add two
 * partial sums of 2^62 (fuzz_state_load). */
static void test_sums_wrap(void) {
  const long long quarter = 1ll << 62;
  gr_fixed f = {quarter, quarter};
  gr_fixed_add(&f, f);
  CHECK(f.coarse == INT64_MIN && f.fine == INT64_MIN);
  gr_fixed_add(&f, f);
  CHECK(f.coarse == 0 && f.fine == 0);
  gr_context *ctx = NULL;
  CHECK(gr_context_create(NULL, &ctx) == GR_OK);
  if (!ctx)
    return;
  /* Every group's partial sum is 2^62. */
  const char *src = "__kernel void quarters(__global long *partial, __local long *scratch) {"
                    " if (get_local_id(0) == 0) partial[get_group_id(0)] = 1L << 62; }";
  cl_program prog = NULL;
  cl_kernel k = NULL;
  gr_reduction_i64 r;
  memset(&r, 0, sizeof(r));
  CHECK(gr_program_build_source(ctx, src, NULL, &prog) == GR_OK);
  if (prog)
    CHECK(gr_kernel_create(ctx, prog, "quarters", &k) == GR_OK);
  if (k && gr_reduction_i64_init(ctx, k, 1u << 16, 1, &r) == GR_OK) {
    long long sum = 0;
    CHECK(gr_reduction_i64_run(ctx, &r, k, &sum) == GR_OK);
    const unsigned long long want = (unsigned long long)r.groups << 62;
    CHECK_MSG(r.groups >= 2 && sum == (long long)want, "%zu groups: %lld", r.groups, sum);
  }
  gr_reduction_i64_release(&r);
  if (k)
    clReleaseKernel(k);
  if (prog)
    clReleaseProgram(prog);
  gr_context_release(ctx);
}

static const gr_subtest tests[] = {
    {"no_platform", test_no_platform, 1}, /* only with OCL_ICD_VENDORS at an empty folder */
    {"names", test_names, 0},
    {"devices", test_devices, 0},
    {"shared", test_shared, 0},
    {"embed", test_embed, 0},
    {"kernels", test_kernels, 0},
    {"kernel_arg", test_kernel_arg, 0},
    {"enqueue_1d", test_enqueue_1d, 0},
    {"errors_per_thread", test_errors_per_thread, 0},
    {"mesh", test_mesh, 0},
    {"mesh_memo", test_mesh_memo, 0},
    {"points", test_points, 0},
    {"fixed_point", test_fixed_point, 0},
    {"sums_wrap", test_sums_wrap, 0},
    {"memcheck", test_memcheck, 1}, /* what valgrind runs */
};

int main(int argc, char **argv) {
  int n = (int)(sizeof(tests) / sizeof(tests[0]));
  /* The no-driver check runs without the device set-up, which would skip it. */
  if (argc == 2 &&
      (strcmp(argv[1], "--expect-no-platform") == 0 || strcmp(argv[1], "no_platform") == 0)) {
    static char name[] = "no_platform";
    char *args[] = {argv[0], name, NULL};
    return gr_test_main(2, args, tests, n, NULL, NULL);
  }
  return gr_test_main(argc, argv, tests, n, have_device, NULL);
}
