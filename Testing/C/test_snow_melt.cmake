# Options of test_snow_melt for graupel_add_core_test (read by
# Testing/C/CMakeLists.txt; see GraupelTesting.cmake for each option).
# valgrind runs the subtest memcheck only: every host entry point once on a
# tiny grid. The soak (test_soak snow_melt N: hills with snow under changing
# weather, N hourly steps) checks the ledger and the fields as it goes.
set(GRAUPEL_CORE_TEST_OPTIONS
  MEMCHECK memcheck
  SOAK 100000)
