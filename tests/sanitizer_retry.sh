#!/usr/bin/env bash
# sanitizer_retry.sh — runs one test command (ctest's COMMAND for the unit,
# render and server tests). When the command fails only because
# LeakSanitizer itself crashed — "LeakSanitizer has encountered a fatal
# error", its tracer dying while it stops the threads Mesa's llvmpipe keeps
# at exit (seen about once in a few hundred GL test runs on 2 busy cores) —
# that is a failure of the sanitizer, not a finding, and the command runs
# once more; the second result stands. A test failure ("check failed"), a
# leak report ("detected memory leaks") or any other crash fails at once.
# Usage: sanitizer_retry.sh COMMAND [ARGS...]
set -u
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
"$@" > >(tee -a "$log") 2> >(tee -a "$log" >&2)
rc=$?
wait
if [ "$rc" -ne 0 ] && grep -q "LeakSanitizer has encountered a fatal error" "$log" &&
   ! grep -qE "detected memory leaks|check failed" "$log"; then
  echo "sanitizer_retry: LeakSanitizer crashed (not a test result); running the test once more" >&2
  "$@"
  rc=$?
fi
exit "$rc"
