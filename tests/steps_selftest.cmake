# steps_selftest.cmake — the step runner (steps.cmake) must not let a wrong
# failure pass for an expected one. Each case runs the runner on a small sh
# command and checks the runner's verdict and its reason: the expected line
# followed by an abort, by a sanitizer report with the expected exit code, a
# warning with exit 0 where a failure is expected, the wrong line, a step that
# names no failure line, and (passing) the expected line with the expected
# code and a LeakSanitizer crash that goes away on the rerun. No GPU. The sh
# scripts avoid '|' and ';', which would split a step (newlines separate).
# Usage: cmake -DRUNNER=steps.cmake -DWORK=folder -P steps_selftest.cmake
cmake_minimum_required(VERSION 3.25)
file(MAKE_DIRECTORY ${WORK})
file(REMOVE ${WORK}/lsan_flag)
set(failures 0)

# runner_case(NAME name PASS|FAIL REASON regex ARGS -DSTEP1=... ...)
function(runner_case)
  cmake_parse_arguments(C "PASS;FAIL" "NAME;REASON" "ARGS" ${ARGN})
  execute_process(COMMAND ${CMAKE_COMMAND} ${C_ARGS} -P ${RUNNER} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(ok 1)
  if(C_PASS AND NOT rc EQUAL 0)
    set(ok 0)
  elseif(C_FAIL AND rc EQUAL 0)
    set(ok 0)
  endif()
  if(NOT err MATCHES "${C_REASON}")
    set(ok 0)
  endif()
  if(ok)
    message("ok   ${C_NAME}")
  else()
    message("FAIL ${C_NAME}: runner exit ${rc}, expected ${C_PASS}${C_FAIL}, reason '${C_REASON}'\n${err}")
    math(EXPR n "${failures} + 1")
    set(failures ${n} PARENT_SCOPE)
  endif()
endfunction()

set(line "FAIL: pixel \\(3, 4\\)")
runner_case(NAME expected_failure PASS REASON "exit 1"
  ARGS "-DSTEP1=sh|-c|echo 'FAIL: pixel (3, 4)' >&2 && exit 1" -DEXIT1=1 "-DERR1=${line}")
runner_case(NAME abort_after_the_line FAIL REASON "step 1 exited with '[^']+', expected 1"
  ARGS "-DSTEP1=sh|-c|echo 'FAIL: pixel (3, 4)' >&2 && kill -ABRT $$" -DEXIT1=1 "-DERR1=${line}")
runner_case(NAME asan_report_exit_1 FAIL REASON "holds a sanitizer report \\('ERROR: AddressSanitizer'\\)"
  ARGS "-DSTEP1=sh|-c|echo 'FAIL: pixel (3, 4)' >&2 && echo '==7==ERROR: AddressSanitizer: heap-use-after-free' >&2 && exit 1"
       -DEXIT1=1 "-DERR1=${line}")
runner_case(NAME leak_report_exit_1 FAIL REASON "holds a sanitizer report \\('ERROR: LeakSanitizer'\\)"
  ARGS "-DSTEP1=sh|-c|echo 'FAIL: pixel (3, 4)' >&2 && echo '==7==ERROR: LeakSanitizer: detected memory leaks' >&2 && exit 1"
       -DEXIT1=1 "-DERR1=${line}")
runner_case(NAME ubsan_report_exit_1 FAIL REASON "holds a sanitizer report \\(': runtime error: '\\)"
  ARGS "-DSTEP1=sh|-c|echo 'x.c:1:2: runtime error: signed integer overflow' >&2 && echo 'FAIL: pixel (3, 4)' >&2 && exit 1"
       -DEXIT1=1 "-DERR1=${line}")
runner_case(NAME warning_and_exit_0 FAIL REASON "step 1 exited with '0', expected 2"
  ARGS "-DSTEP1=sh|-c|echo 'params.attribute = 3: the dataset has 3 per-vertex attributes' >&2 && exit 0"
       -DEXIT1=2 "-DERR1=params\\.attribute = 3")
runner_case(NAME wrong_line FAIL REASON "step 1: stderr does not match"
  ARGS "-DSTEP1=sh|-c|echo 'tubes-check: cannot read scene.json' >&2 && exit 1" -DEXIT1=1 "-DERR1=${line}")
runner_case(NAME no_failure_line_named FAIL REASON "step 1 expects exit 1 but names no failure line"
  ARGS "-DSTEP1=sh|-c|exit 1" -DEXIT1=1)
runner_case(NAME wrong_stdout FAIL REASON "step 1: stdout does not match"
  ARGS "-DSTEP1=sh|-c|echo '\"pass\": true' && exit 1" -DEXIT1=1 "-DOUT1=\"failed\":[^\n]*\"max_mean\"")
runner_case(NAME lsan_crash_rerun PASS REASON "LeakSanitizer itself crashed"
  ARGS "-DSTEP1=sh|-c|test -e ${WORK}/lsan_flag && exit 0\ntouch ${WORK}/lsan_flag && echo '==7==LeakSanitizer has encountered a fatal error.' >&2 && exit 1")

if(failures GREATER 0)
  message(FATAL_ERROR "${failures} step-runner case(s) did not behave")
endif()
