# Options of test_water_surface for graupel_add_core_test (read by
# Testing/C/CMakeLists.txt; see GraupelTesting.cmake for each option).
# valgrind runs the subtest memcheck only: every host entry point once on a
# tiny grid (the physics subtests step too much for valgrind). No soak yet:
# test_soak.c has no water_surface entry.
set(GRAUPEL_CORE_TEST_OPTIONS
  MEMCHECK memcheck)
