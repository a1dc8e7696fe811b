# Runs a libFuzzer harness for ctest (cmake -P).
#
# Fuzzing:     -DHARNESS=exe -DSEEDS=dir -DWORK=dir -DARTIFACTS=dir -DSECONDS=n
#              [-DDICT=file]
#   WORK is emptied and filled with a copy of SEEDS (which stays untouched),
#   then the harness fuzzes it for SECONDS; new inputs go to WORK, a crashing
#   input to ARTIFACTS.
# Regressions: -DREGRESSIONS=dir -DHARNESS_DIR=dir -DHARNESSES=a,b,c
#   runs fuzz_<h> once on every file of REGRESSIONS/<h>/ but README.md.
set(common -rss_limit_mb=2048 -max_len=65536 -timeout=10)

if(DEFINED REGRESSIONS)
  string(REPLACE "," ";" harnesses "${HARNESSES}")
  set(failed "")
  foreach(h IN LISTS harnesses)
    file(GLOB inputs LIST_DIRECTORIES false "${REGRESSIONS}/${h}/*")
    list(FILTER inputs EXCLUDE REGEX "/README\\.md$")
    list(LENGTH inputs n)
    if(n EQUAL 0)
      message(STATUS "fuzz_${h}: no regression inputs")
      continue()
    endif()
    message(STATUS "fuzz_${h}: ${n} regression inputs")
    execute_process(COMMAND "${HARNESS_DIR}/fuzz_${h}" ${common} ${inputs}
      RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
      list(APPEND failed "fuzz_${h} (exit ${rc})")
    endif()
  endforeach()
  if(failed)
    message(FATAL_ERROR "Regression inputs fail: ${failed}")
  endif()
  return()
endif()

foreach(v HARNESS SEEDS WORK ARTIFACTS SECONDS)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "run_fuzz.cmake needs -D${v}=...")
  endif()
endforeach()
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}" "${ARTIFACTS}")
file(GLOB seeds LIST_DIRECTORIES false "${SEEDS}/*")
if(seeds)
  file(COPY ${seeds} DESTINATION "${WORK}")
endif()
set(dict_arg "")
if(DICT)
  set(dict_arg "-dict=${DICT}")
endif()
execute_process(
  COMMAND "${HARNESS}" ${common} -max_total_time=${SECONDS} -print_final_stats=1 ${dict_arg}
          "-artifact_prefix=${ARTIFACTS}/" "${WORK}"
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${HARNESS} failed (exit ${rc}); the input is in ${ARTIFACTS}/")
endif()
