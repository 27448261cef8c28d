#!/usr/bin/env bash
# run-tests.sh - run cmocka test binaries, show their output, and append
# "name passed failed" per binary to the results file that summarise.sh
# totals. A binary that crashes or exits non-zero without reporting a
# failure counts as one failed test.
#
# With KM_TEST=NAME set, every binary runs only the tests NAME selects
# (tests/support/testmain.h); binaries with none of them stay silent and
# are not recorded, and a NAME that selects nothing anywhere fails.
set -u
results=${KM_RESULTS:-build/test-results.txt}
filter=${KM_TEST:-}
mkdir -p "$(dirname "$results")"
status=0
ran=0
for bin in "$@"; do
  out=$(CMOCKA_MESSAGE_OUTPUT=stdout timeout "${KM_TEST_TIMEOUT:-900}" "$bin" 2>&1)
  rc=$?
  passed=$(printf '%s\n' "$out" | sed -n 's/^\[  PASSED  \] \([0-9]*\) test(s)\./\1/p' | tail -n 1)
  failed=$(printf '%s\n' "$out" | sed -n 's/^\[  FAILED  \] \([0-9]*\) test(s).*/\1/p' | tail -n 1)
  passed=${passed:-0}
  failed=${failed:-0}
  if [ -n "$filter" ] && [ "$rc" -eq 0 ] && [ "$passed" -eq 0 ] && [ "$failed" -eq 0 ]; then
    continue
  fi
  printf '%s\n' "$out"
  if [ "$rc" -ne 0 ] && [ "$failed" -eq 0 ]; then
    echo "!! $bin exited with status $rc"
    failed=1
  fi
  [ "$failed" -ne 0 ] && status=1
  ran=$((ran + passed + failed))
  echo "$bin $passed $failed" >>"$results"
done
if [ -n "$filter" ] && [ "$ran" -eq 0 ]; then
  echo "!! no test matches KM_TEST=$filter (list them with a binary's -l)"
  status=1
fi
exit $status
