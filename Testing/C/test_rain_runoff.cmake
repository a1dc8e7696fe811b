# Options of test_rain_runoff for graupel_add_core_test (read by
# Testing/C/CMakeLists.txt; see GraupelTesting.cmake for each option).
# valgrind runs the rain core's host code only: every entry point and error
# path once, on tiny grids (the full suite steps too much for valgrind).
set(GRAUPEL_CORE_TEST_OPTIONS
  MEMCHECK memcheck
  SOAK 100000)
