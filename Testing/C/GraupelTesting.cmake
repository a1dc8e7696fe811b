# graupel_add_core_test(): one declaration per C test program, and ctest gets
# one test per named subtest plus the program's memcheck, soak and
# no-platform variants.
#
#   graupel_add_core_test(<core>
#     SOURCE <file.c>...       the program test_<core>; its main is gr_test_main
#     [LIBS <lib>...]          linked besides graupel_core and m
#     [TIMEOUT <s>]            per subtest (default 120)
#     [ARGS <arg>...]          put before the subtest name (and --list) in every run
#     [MEMCHECK [<arg>...]]    memcheck.<core>: valgrind over `test_<core> <arg>...`
#                              (no args: every subtest but the by-name-only ones)
#     [SOAK <arg>...]          soak.<core>: `test_soak <core> <arg>...` (label soak)
#     [NO_PLATFORM <arg>...])  core.<core>.no_platform: `test_<core> <arg>...` with
#                              no OpenCL platform (OCL_ICD_VENDORS at an empty folder)
#
# Subtests are discovered from the built program, as gtest_discover_tests
# does: after each link, `test_<core> --list` prints the names and
# GraupelDiscoverTests.cmake writes a ctest include file with one
# core.<core>.<name> test each, running `test_<core> <name>`. A custom command
# rather than POST_BUILD, so that a changed declaration (labels, timeout,
# memcheck arguments) rewrites the file without a relink.
#
# Every subtest: labels core (and sanitize in a GRAUPEL_SANITIZE tree, with
# GRAUPEL_SANITIZER_ENV), SKIP_RETURN_CODE 77 (no OpenCL device: skipped, not
# failed), and GR_TEST_SCRATCH=<a folder of its own> in the environment for
# programs that write files. Memcheck tests exist only in a tree without
# sanitizers and with valgrind, and run after the core.<core>.* tests (whose
# kernel builds fill PoCL's cache: building kernels under valgrind is what
# takes the minutes).
#
# A program whose --list fails or prints something that is not a list of
# names (a program not yet converted to gr_test_main) gives one failing test,
# core.<core>.DISCOVERY_FAILED, that says so, never zero tests.

set(GRAUPEL_DISCOVER_SCRIPT "${CMAKE_CURRENT_LIST_DIR}/GraupelDiscoverTests.cmake")
set(GRAUPEL_SUPPRESSIONS_DIR "${CMAKE_CURRENT_LIST_DIR}/../sanitizers")

function(graupel_add_core_test core)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "TIMEOUT" "SOURCE;LIBS;ARGS;MEMCHECK;SOAK;NO_PLATFORM")
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "graupel_add_core_test(${core}): unknown arguments ${arg_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT arg_SOURCE)
    message(FATAL_ERROR "graupel_add_core_test(${core}): SOURCE <file.c>... is required")
  endif()
  if(NOT arg_TIMEOUT)
    set(arg_TIMEOUT 120)
  endif()
  set(memcheck_wanted 0)
  if("MEMCHECK" IN_LIST arg_KEYWORDS_MISSING_VALUES OR DEFINED arg_MEMCHECK)
    set(memcheck_wanted 1)
  endif()
  set(no_platform_wanted 0)
  if("NO_PLATFORM" IN_LIST arg_KEYWORDS_MISSING_VALUES OR DEFINED arg_NO_PLATFORM)
    set(no_platform_wanted 1)
  endif()

  set(target test_${core})
  add_executable(${target} ${arg_SOURCE})
  target_link_libraries(${target} PRIVATE graupel_core m ${arg_LIBS})
  set_target_properties(${target} PROPERTIES C_STANDARD 11 C_EXTENSIONS OFF)
  target_compile_definitions(${target} PRIVATE _POSIX_C_SOURCE=200809L)

  set(scratch "${CMAKE_CURRENT_BINARY_DIR}/scratch/${core}")
  file(MAKE_DIRECTORY "${scratch}" "${CMAKE_CURRENT_BINARY_DIR}/scratch/no_vendors")
  set(labels core)
  set(env "GR_TEST_SCRATCH=${scratch}")
  if(GRAUPEL_SANITIZE)
    list(APPEND labels sanitize)
    list(APPEND env ${GRAUPEL_SANITIZER_ENV})
  endif()

  set(memcheck_cmd "")
  if(memcheck_wanted AND NOT GRAUPEL_SANITIZE)
    find_program(VALGRIND valgrind)
    if(VALGRIND)
      set(memcheck_cmd ${VALGRIND} --error-exitcode=1 --leak-check=full
        --errors-for-leak-kinds=definite --show-possibly-lost=no
        --suppressions=${GRAUPEL_SUPPRESSIONS_DIR}/valgrind.supp)
    endif()
  endif()

  # Everything the discovery needs, with the program's path resolved.
  set(args_file "${CMAKE_CURRENT_BINARY_DIR}/${target}_discover_args.cmake")
  set(tests_file "${CMAKE_CURRENT_BINARY_DIR}/${target}_tests.cmake")
  string(CONCAT content
    "set(exe [==[$<TARGET_FILE:${target}>]==])\n"
    "set(core [==[${core}]==])\n"
    "set(out [==[${tests_file}]==])\n"
    "set(timeout [==[${arg_TIMEOUT}]==])\n"
    "set(labels [==[${labels}]==])\n"
    "set(env [==[${env}]==])\n"
    "set(list_env [==[${GRAUPEL_SANITIZER_ENV}]==])\n"
    "set(prefix_args [==[${arg_ARGS}]==])\n"
    "set(no_platform ${no_platform_wanted})\n"
    "set(no_platform_args [==[${arg_NO_PLATFORM}]==])\n"
    "set(no_platform_env [==[${env};OCL_ICD_VENDORS=${CMAKE_CURRENT_BINARY_DIR}/scratch/no_vendors]==])\n"
    "set(memcheck_cmd [==[${memcheck_cmd}]==])\n"
    "set(memcheck_args [==[${arg_MEMCHECK}]==])\n"
    "set(discover_script [==[${GRAUPEL_DISCOVER_SCRIPT}]==])\n"
    "set(cmake_command [==[${CMAKE_COMMAND}]==])\n")
  file(GENERATE OUTPUT "${args_file}" CONTENT "${content}")
  add_custom_command(
    OUTPUT "${tests_file}"
    COMMAND ${CMAKE_COMMAND} "-DARGS_FILE=${args_file}" -P "${GRAUPEL_DISCOVER_SCRIPT}"
    DEPENDS ${target} "${args_file}" "${GRAUPEL_DISCOVER_SCRIPT}"
    COMMENT "Listing the subtests of ${target}"
    VERBATIM)
  add_custom_target(${target}_discover ALL DEPENDS "${tests_file}")

  # ctest reads the discovered tests through this file; before the first
  # build it names the missing program instead of silently finding nothing.
  set(include_file "${CMAKE_CURRENT_BINARY_DIR}/${target}_include.cmake")
  file(WRITE "${include_file}"
    "if(EXISTS [==[${tests_file}]==])\n"
    "  include([==[${tests_file}]==])\n"
    "else()\n"
    "  add_test(core.${core}.NOT_BUILT [==[${target}_NOT_BUILT]==])\n"
    "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${include_file}")

  if(DEFINED arg_SOAK)
    if(NOT TARGET test_soak)
      message(FATAL_ERROR "graupel_add_core_test(${core} SOAK ...) needs the test_soak target first")
    endif()
    add_test(NAME soak.${core} COMMAND test_soak ${core} ${arg_SOAK})
    set(soak_env "")
    if(GRAUPEL_SANITIZE)
      set(soak_env ${GRAUPEL_SANITIZER_ENV})
    endif()
    set_tests_properties(soak.${core} PROPERTIES LABELS soak TIMEOUT 3600
      SKIP_RETURN_CODE 77 ENVIRONMENT "${soak_env}")
  endif()
endfunction()
