# Options of test_water_surface for graupel_add_core_test (read by
# Testing/C/CMakeLists.txt; see GraupelTesting.cmake for each option).
# valgrind runs the subtest memcheck only: every host entry point once on a
# tiny grid (the physics subtests step too much for valgrind). The soak
# (test_soak water_surface N: a lake in a bowl, its waves and raindrops
# drawn anew every 2000 steps) takes about 12 s for 10^5 steps on PoCL here.
set(GRAUPEL_CORE_TEST_OPTIONS
  MEMCHECK memcheck
  SOAK 100000)
