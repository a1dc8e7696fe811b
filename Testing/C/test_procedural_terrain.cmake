# Options of test_procedural_terrain for graupel_add_core_test (read by
# Testing/C/CMakeLists.txt; see GraupelTesting.cmake for each option).
# valgrind runs the subtest memcheck only: every host entry point and error
# path once, on tiny grids and two kernel variants (each variant built under
# valgrind costs many seconds; the whole program took minutes).
set(GRAUPEL_CORE_TEST_OPTIONS
  MEMCHECK memcheck
  SOAK 10000 ${soak_scratch})
