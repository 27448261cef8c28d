#!/usr/bin/env bash
# run.sh - the server suite: lint api/openapi.yaml with Redocly, check that
# the generated api/src/openapi.c matches it, then run the Python tests
# against a live kmorphd (build/kmorphd, or $KMORPHD). Appends
# "tests/server <passed> <failed>" to the results file summarise.sh totals.
set -u
cd "$(dirname "$0")/../.."
results=${KM_RESULTS:-build/test-results.txt}
mkdir -p "$(dirname "$results")"
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
passed=0
failed=0
pass() { passed=$((passed + 1)); echo "ok   $1"; }
fail() { failed=$((failed + 1)); echo "FAIL $1"; }

# 1. The contract passes a real OpenAPI linter.
export REDOCLY_TELEMETRY=off REDOCLY_SUPPRESS_UPDATE_NOTICE=true
if [ ! -x tests/server/node_modules/.bin/redocly ]; then
  (cd tests/server && npm ci --no-audit --no-fund --loglevel=error >/dev/null 2>&1)
fi
if [ -x tests/server/node_modules/.bin/redocly ]; then
  if out=$(cd tests/server && timeout 120 npx --no-install redocly lint ../../api/openapi.yaml 2>&1) \
     && ! printf '%s\n' "$out" | grep -q "warning"; then
    pass "openapi.yaml passes redocly lint"
  else
    printf '%s\n' "$out" | tail -n 30
    fail "openapi.yaml passes redocly lint"
  fi
else
  fail "redocly lint (could not install @redocly/cli with npm ci)"
fi

# 2. The served JSON is generated from the YAML, not edited beside it.
if "$PY" api/gen_openapi_c.py --check; then
  pass "api/src/openapi.c is generated from api/openapi.yaml"
else
  fail "api/src/openapi.c is generated from api/openapi.yaml"
fi

# 3. The live-daemon tests.
out=$(cd tests/server && timeout "${KM_TEST_TIMEOUT:-900}" "$PY" -m unittest -v \
        test_contract test_jobs test_load test_shutdown test_http_framing test_signals \
        test_bounds test_shapes test_healthcheck test_conventions test_precision 2>&1)
rc=$?
printf '%s\n' "$out" | grep -E ' \.\.\. |^(FAIL|ERROR):|^Ran |^OK|^FAILED|Error|assert' | head -n 400
ran=$(printf '%s\n' "$out" | sed -n 's/^Ran \([0-9]*\) tests\{0,1\}.*/\1/p' | tail -n 1)
bad=$(printf '%s\n' "$out" | grep -cE '^(FAIL|ERROR): ')
skipped=$(printf '%s\n' "$out" | grep -cE ' \.\.\. skipped')
ran=${ran:-0}
if [ "$rc" -ne 0 ] && [ "$bad" -eq 0 ]; then
  printf '%s\n' "$out" | tail -n 40
  bad=1
fi
passed=$((passed + ran - bad - skipped))
failed=$((failed + bad))
[ "$passed" -lt 0 ] && passed=0

echo "tests/server: $passed passed, $failed failed"
echo "tests/server $passed $failed" >>"$results"
[ "$failed" -eq 0 ]
