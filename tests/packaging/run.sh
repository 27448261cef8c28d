#!/usr/bin/env bash
# run.sh - the packaging suite: make install into temporary DESTDIRs and
# the installed files used from there (test_install.py), and the
# Dockerfile read and its commands and paths tried (test_dockerfile.py).
# Appends "tests/packaging <passed> <failed>" to the results file
# summarise.sh totals. KM_BUILD names the build folder to install (default build).
set -u
cd "$(dirname "$0")/../.."
results=${KM_RESULTS:-build/test-results.txt}
mkdir -p "$(dirname "$results")"
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
out=$(cd tests/packaging && timeout "${KM_TEST_TIMEOUT:-600}" "$PY" -m unittest -v test_install test_dockerfile 2>&1)
rc=$?
printf '%s\n' "$out" | grep -E ' \.\.\. |^(FAIL|ERROR):|^Ran |^OK|^FAILED|Error|assert' | head -n 200
ran=$(printf '%s\n' "$out" | sed -n 's/^Ran \([0-9]*\) tests\{0,1\}.*/\1/p' | tail -n 1)
bad=$(printf '%s\n' "$out" | grep -cE '^(FAIL|ERROR): ')
skipped=$(printf '%s\n' "$out" | grep -cE ' \.\.\. skipped')
ran=${ran:-0}
[ "$rc" -ne 0 ] && [ "$bad" -eq 0 ] && bad=1
passed=$((ran - bad - skipped))
[ "$passed" -lt 0 ] && passed=0
echo "tests/packaging: $passed passed, $bad failed"
echo "tests/packaging $passed $bad" >>"$results"
[ "$bad" -eq 0 ]
