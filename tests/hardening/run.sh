#!/usr/bin/env bash
# run.sh - the hardening suite: known-slow inputs stay fast, the CLI under
# valgrind memcheck, the bad-input barrage against the release daemon and
# against the ASan+UBSan daemon, the server's own contract tests against
# the ASan daemon, load and faults. Each part appends "name passed failed"
# lines to build/test-results.txt; a short summary of counts, failures and
# memory closes the run.
#
# Usage: tests/hardening/run.sh [slow] [cli] [barrage] [asan] [load]
#        [faults] [sigterm] [hostile]     (default: all)
# Needs build/kmorph, build/kmorphd and build/asan/kmorphd (make
# test-hardening builds them). HARDENING_LONG=1 lengthens load and faults.
set -u
cd "$(dirname "$0")/../.."
results=${KM_RESULTS:-build/test-results.txt}
export KM_RESULTS=$results
mkdir -p build
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
parts=${*:-slow cli barrage asan load faults sigterm hostile}
summary=build/hardening-summary.txt
: >"$summary"
status=0
ulimit -n "$(ulimit -Hn)" 2>/dev/null || true

timed() { # name command...: run, print its wall time
  local name=$1 t0 rc
  shift
  t0=$(date +%s)
  "$@"
  rc=$?
  echo "   ($name: $(($(date +%s) - t0)) s)"
  [ "$rc" -eq 0 ] || status=1
}

slow_inputs() {
  # Requests the fuzzers once found slow (seconds to minutes of compute
  # for a few hundred bytes): each must be answered within 1 s by the
  # release CLI. The route is the file name's first word.
  local passed=0 failed=0 f route t0 t1 ms rc
  for f in tests/hardening/slow/*.json; do
    route=$(basename "$f" | cut -d- -f1)
    t0=$(date +%s%N)
    timeout 30 build/kmorph "$route" <"$f" >/dev/null 2>&1
    rc=$?
    t1=$(date +%s%N)
    ms=$(((t1 - t0) / 1000000))
    if [ "$rc" -le 1 ] && [ "$ms" -le 1000 ]; then
      passed=$((passed + 1))
      echo "ok   slow-inputs: $(basename "$f") answered in $ms ms"
    else
      failed=$((failed + 1))
      echo "FAIL slow-inputs: $(basename "$f") took $ms ms (exit $rc; limit 1000 ms)"
    fi
  done
  echo "slow-inputs: $passed within 1 s, $failed slower" >>"$summary"
  echo "hardening/slow-inputs $passed $failed" >>"$results"
  [ "$failed" -eq 0 ]
}

asan_contract() {
  # The server's own contract, job and load tests against the ASan+UBSan
  # daemon; any sanitizer report (LeakSanitizer runs at each exit) fails.
  local logdir out rc ran bad reports passed failed
  logdir=$(mktemp -d)
  out=$(cd tests/server && KMORPHD=../../build/asan/kmorphd \
        ASAN_OPTIONS="log_path=$logdir/asan:detect_leaks=1" \
        UBSAN_OPTIONS="log_path=$logdir/ubsan:print_stacktrace=1" \
        timeout 900 "$PY" -m unittest test_contract test_jobs test_load test_bounds \
          test_http_framing 2>&1)
  rc=$?
  ran=$(printf '%s\n' "$out" | sed -n 's/^Ran \([0-9]*\) test.*/\1/p' | tail -n 1)
  bad=$(printf '%s\n' "$out" | grep -cE '^(FAIL|ERROR): ')
  ran=${ran:-0}
  [ "$rc" -ne 0 ] && [ "$bad" -eq 0 ] && bad=1
  reports=$(ls "$logdir" | wc -l)
  passed=$((ran - bad))
  failed=$bad
  if [ "$reports" -eq 0 ]; then
    passed=$((passed + 1))
    echo "ok   contract-asan: no ASan/UBSan/LSan report from the daemon"
  else
    failed=$((failed + 1))
    echo "FAIL contract-asan: $reports sanitizer report(s):"
    head -n 40 "$logdir"/* | sed 's/^/  /'
  fi
  printf '%s\n' "$out" | grep -E '^(FAIL|ERROR):' | sed 's/^/  /'
  echo "contract-asan: $ran server tests against the ASan daemon, $bad failed, $reports sanitizer reports" >>"$summary"
  echo "hardening/contract-asan $passed $failed" >>"$results"
  rm -rf "$logdir"
  [ "$failed" -eq 0 ]
}

for p in $parts; do
  case $p in
    slow) timed "slow inputs" slow_inputs ;;
    cli) timed "CLI under valgrind" "$PY" tests/hardening/cli_leaks.py ;;
    barrage) timed "barrage, release daemon" "$PY" tests/hardening/barrage.py ;;
    asan)
      timed "barrage, ASan daemon" "$PY" tests/hardening/barrage.py \
        --daemon build/asan/kmorphd --asan --name barrage-asan
      timed "server tests, ASan daemon" asan_contract ;;
    load | faults | sigterm) timed "$p" "$PY" tests/hardening/load.py "$p" ;;
    hostile) timed "hostile mix" "$PY" tests/hardening/hostile_check.py ;;
    *) echo "unknown part $p"; status=1 ;;
  esac
done
echo "== hardening summary"
sed 's/^/   /' "$summary"
exit $status
