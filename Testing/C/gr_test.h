/* Minimal assertion helpers for the C core tests: each CHECK prints the file,
 * line and values on failure and counts it; a test's main returns
 * GR_TEST_RESULT() so ctest sees the failure. */
#ifndef GR_TEST_H
#define GR_TEST_H

#include "graupel/runtime.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

/* The counts of checks and failures. A test program of several files
 * defines GR_TEST_SHARED_COUNTERS before including this header in each, and
 * defines gr_test_failures and gr_test_checks (0) in the one with main, so
 * that every file's CHECKs count in the one pair GR_TEST_RESULT reads. */
#ifdef GR_TEST_SHARED_COUNTERS
extern int gr_test_failures;
extern int gr_test_checks;
#else
static int gr_test_failures = 0;
static int gr_test_checks = 0;
#endif

#define CHECK(cond)                                                                                \
  do {                                                                                             \
    ++gr_test_checks;                                                                              \
    if (!(cond)) {                                                                                 \
      ++gr_test_failures;                                                                          \
      fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);                     \
    }                                                                                              \
  } while (0)

#define CHECK_MSG(cond, ...)                                                                       \
  do {                                                                                             \
    ++gr_test_checks;                                                                              \
    if (!(cond)) {                                                                                 \
      ++gr_test_failures;                                                                          \
      fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond);                     \
      fprintf(stderr, __VA_ARGS__);                                                                \
      fputc('\n', stderr);                                                                         \
    }                                                                                              \
  } while (0)

#define CHECK_NEAR(a, b, tol)                                                                      \
  do {                                                                                             \
    double gr_a_ = (double)(a), gr_b_ = (double)(b);                                               \
    CHECK_MSG(fabs(gr_a_ - gr_b_) <= (tol), "%.9g vs %.9g (tol %.3g)", gr_a_, gr_b_,               \
              (double)(tol));                                                                      \
  } while (0)

#define GR_TEST_RESULT()                                                                           \
  (printf("%d checks, %d failed\n", gr_test_checks, gr_test_failures),                             \
   gr_test_failures == 0 ? 0 : 1)

/* A 65536-wide grid whose float field needs one row more than the device's
 * largest buffer. 0 when that grid would pass the 4e9-point grid limit
 * instead (a device allowing larger buffers than any valid grid needs). */
static inline int gr_test_grid_beyond_device(const gr_context *ctx, gr_grid *g) {
  gr_device_info info;
  gr_status st = gr_context_device_info(ctx, &info);
  CHECK(st == GR_OK);
  if (st != GR_OK)
    return 0;
  gr_grid huge = {
      65536, (int)((double)info.max_alloc_bytes / 4.0 / 65536.0) + 2, 1.0, 1.0, 0.0, 0.0, 0, 0};
  *g = huge;
  return (double)huge.nx * huge.ny <= 4.0e9;
}

/* ctest's SKIP_RETURN_CODE: the test needs an OpenCL device and there is none. */
#define GR_TEST_SKIP 77

/* One named subtest of a test program. */
typedef struct gr_subtest {
  const char *name;
  void (*run)(void);
  int by_name_only; /* 1: left out of a run without names (long runs, memcheck subsets) */
} gr_subtest;

/* The one main of every C test program:
 *   test_x              every subtest but the by-name-only ones
 *   test_x NAME...      the named subtests
 *   test_x --list       the names, one per line (ctest makes one test of each)
 * setup (may be NULL) runs once before any subtest and returns 0 when there
 * is no OpenCL device: the program then exits with GR_TEST_SKIP. teardown
 * (may be NULL) runs after the last. */
static inline int gr_test_main(int argc, char **argv, const gr_subtest *tests, int ntests,
                               int (*setup)(void), void (*teardown)(void)) {
  if (argc > 1 && strcmp(argv[1], "--list") == 0) {
    for (int t = 0; t < ntests; ++t)
      printf("%s\n", tests[t].name);
    return 0;
  }
  for (int a = 1; a < argc; ++a) {
    int known = 0;
    for (int t = 0; t < ntests; ++t)
      known |= strcmp(argv[a], tests[t].name) == 0;
    if (!known) {
      fprintf(stderr, "%s: no subtest '%s' (--list names them)\n", argv[0], argv[a]);
      return 2;
    }
  }
  if (setup && !setup()) {
    fprintf(stderr, "%s: skipped: no OpenCL device (%s)\n", argv[0], gr_last_error(NULL));
    return GR_TEST_SKIP;
  }
  for (int t = 0; t < ntests; ++t) {
    int want = argc < 2 ? !tests[t].by_name_only : 0;
    for (int a = 1; a < argc; ++a)
      want |= strcmp(argv[a], tests[t].name) == 0;
    if (!want)
      continue;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int before = gr_test_failures;
    tests[t].run();
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("%-20s %s in %.2f s\n", tests[t].name, gr_test_failures == before ? "passed" : "FAILED",
           (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    fflush(stdout);
  }
  if (teardown)
    teardown();
  return GR_TEST_RESULT();
}

#endif
