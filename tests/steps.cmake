# steps.cmake — runs STEP1..STEP9 in order, each a command with its arguments
# separated by '|'; the step runner of the render tests (SL_STEPS, tests/CMakeLists.txt).
# Step i must exit with EXIT<i> (default 0); ERR<i> / OUT<i> are regular
# expressions its stderr / stdout must match. A step expected to fail (EXIT<i>
# not 0) must name its failure line in ERR<i> or OUT<i>, or the runner refuses
# it: under ASan a sanitizer report exits with 1, the code of "check failed",
# so an exit code alone cannot tell the expected failure from a crash. For the
# same reason a step whose output holds a sanitizer report (ASan, LSan, UBSan)
# fails whatever its exit code, and a signal never equals an expected code.
# When LeakSanitizer itself crashed (its tracer; see tests/sanitizer_retry.sh)
# the step runs once more and the second result stands. The runner's own
# checks are tested by tests/steps_selftest.cmake.
cmake_minimum_required(VERSION 3.25)
set(sanitizer_report "(ERROR|SUMMARY): [A-Za-z]*Sanitizer|: runtime error: |Sanitizer has encountered a fatal error")
foreach(i RANGE 1 9)
  if(NOT DEFINED STEP${i})
    continue()
  endif()
  set(want 0)
  if(DEFINED EXIT${i})
    set(want ${EXIT${i}})
  endif()
  if(NOT "${want}" STREQUAL "0" AND NOT DEFINED ERR${i} AND NOT DEFINED OUT${i})
    message(FATAL_ERROR "step ${i} expects exit ${want} but names no failure line (ERR${i} or OUT${i}): ${STEP${i}}")
  endif()
  string(REPLACE "|" ";" cmd "${STEP${i}}")
  foreach(attempt 1 2)
    execute_process(COMMAND ${cmd} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    message("step ${i}: ${STEP${i}}\n  exit ${rc}\n  stdout: ${out}\n  stderr: ${err}")
    if(attempt EQUAL 2 OR NOT "${out}${err}" MATCHES "LeakSanitizer has encountered a fatal error"
       OR "${out}${err}" MATCHES "detected memory leaks")
      break()
    endif()
    message("step ${i}: LeakSanitizer itself crashed (not a test result); running the step once more")
  endforeach()
  if("${out}${err}" MATCHES "${sanitizer_report}")
    message(FATAL_ERROR "step ${i}: its output holds a sanitizer report ('${CMAKE_MATCH_0}'): a crash, not a result")
  endif()
  if(NOT "${rc}" STREQUAL "${want}")
    message(FATAL_ERROR "step ${i} exited with '${rc}', expected ${want}")
  endif()
  if(DEFINED ERR${i} AND NOT err MATCHES "${ERR${i}}")
    message(FATAL_ERROR "step ${i}: stderr does not match '${ERR${i}}'")
  endif()
  if(DEFINED OUT${i} AND NOT out MATCHES "${OUT${i}}")
    message(FATAL_ERROR "step ${i}: stdout does not match '${OUT${i}}'")
  endif()
endforeach()
