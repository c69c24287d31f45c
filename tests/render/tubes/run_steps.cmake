# run_steps.cmake — runs STEP1..STEP6 in order (each a command with arguments
# separated by '|'), failing on the first non-zero exit. Used by tubes.cmake for
# tests that chain sightline-render, tubes-check and sightline-diff.
foreach(i RANGE 1 6)
  if(DEFINED STEP${i})
    string(REPLACE "|" ";" cmd "${STEP${i}}")
    execute_process(COMMAND ${cmd} RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "step ${i} failed (exit ${rc}): ${STEP${i}}")
    endif()
  endif()
endforeach()
