# steps.cmake — runs STEP1..STEP9 in order, each a command with its arguments
# separated by '|'. Step i must exit with EXIT<i> (default 0: a test that
# expects a failure names the exact code, so a crash or a usage error does not
# pass for it); ERR<i> / OUT<i> are regular expressions its stderr / stdout
# must match. Used by tests/render/tubes_mesh.cmake and shaders.cmake.
foreach(i RANGE 1 9)
  if(NOT DEFINED STEP${i})
    continue()
  endif()
  string(REPLACE "|" ";" cmd "${STEP${i}}")
  execute_process(COMMAND ${cmd} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("step ${i}: ${STEP${i}}\n  exit ${rc}\n  stdout: ${out}\n  stderr: ${err}")
  set(want 0)
  if(DEFINED EXIT${i})
    set(want ${EXIT${i}})
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
