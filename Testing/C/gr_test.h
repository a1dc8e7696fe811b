/* Minimal assertion helpers for the C core tests: each CHECK prints the file,
 * line and values on failure and counts it; a test's main returns
 * GR_TEST_RESULT() so ctest sees the failure. */
#ifndef GR_TEST_H
#define GR_TEST_H

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

#endif
