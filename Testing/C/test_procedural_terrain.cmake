# Options of test_procedural_terrain for graupel_add_core_test (read by
# Testing/C/CMakeLists.txt; see GraupelTesting.cmake for each option).
set(GRAUPEL_CORE_TEST_OPTIONS
  MEMCHECK
  SOAK 10000 ${soak_scratch})
