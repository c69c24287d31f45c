# run_steps.cmake — runs STEP1..STEP6 in order (each a command with arguments
# separated by '|'), failing on the first non-zero exit. Used by tubes.cmake for
# tests that chain sightline-render, tubes-check and sightline-diff.
# EXPECT_FAIL_STEP=N: step N must exit with 1 ("check failed"), not 0 and not
# another code (bad input, GPU, crash), so a test that proves a check can fail
# does not pass on an unrelated error. Steps after it do not run.
foreach(i RANGE 1 6)
  if(DEFINED STEP${i})
    string(REPLACE "|" ";" cmd "${STEP${i}}")
    execute_process(COMMAND ${cmd} RESULT_VARIABLE rc)
    if(DEFINED EXPECT_FAIL_STEP AND i EQUAL EXPECT_FAIL_STEP)
      if(NOT rc EQUAL 1)
        message(FATAL_ERROR "step ${i} should have failed its check (exit 1), got exit ${rc}: ${STEP${i}}")
      endif()
      return()
    endif()
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "step ${i} failed (exit ${rc}): ${STEP${i}}")
    endif()
  endif()
endforeach()
