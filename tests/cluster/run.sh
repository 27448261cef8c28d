#!/usr/bin/env bash
# run.sh - the cluster suite: redis-server, several kmorphd (build/kmorphd,
# or $KMORPHD) sharing jobs through it and nginx in front, all on loopback,
# started and stopped by the tests; and the checks of deploy/. Appends
# "tests/cluster <passed> <failed>" to the results file summarise.sh totals.
set -u
cd "$(dirname "$0")/../.."
results=${KM_RESULTS:-build/test-results.txt}
mkdir -p "$(dirname "$results")"
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3

out=$(cd tests/cluster && timeout "${KM_TEST_TIMEOUT:-600}" "$PY" -m unittest -v \
        test_cluster test_deploy test_run_cluster 2>&1)
rc=$?
printf '%s\n' "$out" | grep -E ' \.\.\. |^(FAIL|ERROR):|^Ran |^OK|^FAILED|Error|assert' | head -n 200
ran=$(printf '%s\n' "$out" | sed -n 's/^Ran \([0-9]*\) tests\{0,1\}.*/\1/p' | tail -n 1)
bad=$(printf '%s\n' "$out" | grep -cE '^(FAIL|ERROR): ')
skipped=$(printf '%s\n' "$out" | grep -cE ' \.\.\. skipped')
ran=${ran:-0}
if [ "$rc" -ne 0 ] && [ "$bad" -eq 0 ]; then
  # Killed by the timeout or broken before the summary: count one failure.
  printf '%s\n' "$out" | tail -n 40
  bad=1
fi
passed=$((ran - bad - skipped))
[ "$passed" -lt 0 ] && passed=0

echo "tests/cluster: $passed passed, $bad failed"
echo "tests/cluster $passed $bad" >>"$results"
[ "$bad" -eq 0 ]
