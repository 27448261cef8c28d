#!/usr/bin/env bash
# run.sh - the client suites against live kmorphd daemons (each suite
# starts its own on a free loopback port): the curl scripts, the JS module
# (node --test, its npm package packed and installed, its types checked
# with tsc), the Python module (unittest) and, when Chromium and
# playwright-core are there, the web page end to end. Appends
# "tests/clients/<suite> <passed> <failed>" lines to the results file that
# tests/summarise.sh totals.
set -u
cd "$(dirname "$0")/../.."
results=${KM_RESULTS:-build/test-results.txt}
mkdir -p "$(dirname "$results")"
limit=${KM_TEST_TIMEOUT:-900}
status=0
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3

record() { # record SUITE PASSED FAILED
  echo "tests/clients/$1: $2 passed, $3 failed"
  echo "tests/clients/$1 $2 $3" >>"$results"
  [ "$3" -eq 0 ] || status=1
}

echo "-- clients/curl"
out=$(timeout "$limit" tests/clients/curl/test_curl.sh 2>&1); rc=$?
printf '%s\n' "$out"
p=$(printf '%s\n' "$out" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\1/p' | tail -n 1)
f=$(printf '%s\n' "$out" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\2/p' | tail -n 1)
p=${p:-0}; f=${f:-0}
[ "$rc" -ne 0 ] && [ "$f" -eq 0 ] && f=1
record curl "$p" "$f"

# node --test prints "# pass N" and "# fail N" (TAP).
node_counts() { # node_counts OUTPUT RC -> "passed failed"
  local p f
  p=$(printf '%s\n' "$1" | sed -n 's/^# pass \([0-9]*\)$/\1/p' | tail -n 1)
  f=$(printf '%s\n' "$1" | sed -n 's/^# fail \([0-9]*\)$/\1/p' | tail -n 1)
  c=$(printf '%s\n' "$1" | sed -n 's/^# cancelled \([0-9]*\)$/\1/p' | tail -n 1)
  p=${p:-0}; f=$(( ${f:-0} + ${c:-0} ))
  [ "$2" -ne 0 ] && [ "$f" -eq 0 ] && f=1
  echo "$p $f"
}

echo "-- clients/js"
# The package's devDependencies (typescript, openapi-typescript) for its
# types test and npm pack; the tests that need them fail without.
if [ ! -x clients/js/node_modules/.bin/tsc ]; then
  (cd clients/js && timeout 300 npm ci --no-audit --no-fund --loglevel=error >/dev/null 2>&1)
fi
out=$(timeout "$limit" node --test tests/clients/js/ 2>&1); rc=$?
printf '%s\n' "$out" | grep -E '^(not )?ok |^# (tests|pass|fail)|Error|expected|actual' | head -n 200
record js $(node_counts "$out" "$rc")

echo "-- clients/python"
out=$(timeout "$limit" "$PY" -m unittest -v tests/clients/python/test_kmorph.py tests/clients/python/test_shapes.py \
  tests/clients/python/test_package.py 2>&1); rc=$?
printf '%s\n' "$out" | grep -E ' \.\.\. |^(FAIL|ERROR):|^Ran |^OK|^FAILED|Error|assert' | head -n 200
ran=$(printf '%s\n' "$out" | sed -n 's/^Ran \([0-9]*\) tests\{0,1\}.*/\1/p' | tail -n 1)
bad=$(printf '%s\n' "$out" | grep -cE '^(FAIL|ERROR): ')
ran=${ran:-0}
[ "$rc" -ne 0 ] && [ "$bad" -eq 0 ] && bad=1
record python $((ran - bad < 0 ? 0 : ran - bad)) "$bad"

echo "-- clients/web in Chromium"
e2e=tests/clients/e2e
if [ ! -x /usr/bin/chromium ]; then
  echo "no /usr/bin/chromium (make deps installs it)"
  record e2e 0 1
else
  if [ ! -d "$e2e/node_modules/playwright-core" ]; then
    (cd "$e2e" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 timeout 300 npm ci --no-audit --no-fund --loglevel=error >/dev/null 2>&1)
  fi
  if [ ! -d "$e2e/node_modules/playwright-core" ]; then
    echo "could not install playwright-core with npm ci"
    record e2e 0 1
  else
    out=$(PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 timeout "$limit" node --test "$e2e"/*.test.mjs 2>&1); rc=$?
    printf '%s\n' "$out" | grep -E '^(not )?ok |^# (tests|pass|fail)|Error|expected|actual|console' | head -n 200
    record e2e $(node_counts "$out" "$rc")
  fi
fi
exit $status
