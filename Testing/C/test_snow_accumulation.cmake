# Options of test_snow_accumulation for graupel_add_core_test (read by
# Testing/C/CMakeLists.txt; see GraupelTesting.cmake for each option).
# valgrind runs the subtest memcheck only: every entry point and error path
# once, on a tiny grid. The soak (test_soak snow_accumulation N: a box
# circling under tilted, fluttering snow on a 24 x 20 field) takes about
# 40 s for 10^5 steps on PoCL here.
set(GRAUPEL_CORE_TEST_OPTIONS
  MEMCHECK memcheck
  SOAK 100000)
