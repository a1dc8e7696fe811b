# Options of test_terrain_analysis for graupel_add_core_test (read by
# Testing/C/CMakeLists.txt; see GraupelTesting.cmake for each option).
# valgrind runs the subtest memcheck only: every host entry point once on a
# tiny input (the other subtests compute too much for valgrind).
set(GRAUPEL_CORE_TEST_OPTIONS
  MEMCHECK memcheck)
