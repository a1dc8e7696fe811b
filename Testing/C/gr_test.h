/* Minimal assertion helpers for the C core tests: each CHECK prints the file,
 * line and values on failure and counts it; a test's main returns
 * GR_TEST_RESULT() so ctest sees the failure. */
#ifndef GR_TEST_H
#define GR_TEST_H

#include "graupel/runtime.h"

#include <math.h>
#include <stdio.h>

static int gr_test_failures = 0;
static int gr_test_checks = 0;

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

#endif
