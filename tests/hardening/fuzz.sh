#!/usr/bin/env bash
# fuzz.sh - run libFuzzer targets for a bounded time each and record the
# outcome like the other suites.
#
# Usage: tests/hardening/fuzz.sh SECONDS NAME...
# Each build/fuzz/fuzz_NAME runs for SECONDS over its seeds in
# tests/fuzz/NAME/corpus plus the inputs it found before (kept in
# build/fuzz/NAME-corpus), with its dictionary, in fork mode so that a slow
# input is recorded and fuzzing goes on: any crash, sanitizer report, leak,
# input slower than 1 s (-timeout=1) or above 2 GiB is a failure. Artifacts
# land in build/fuzz/artifacts-<pid>/NAME/ (one folder per run, so that two
# runs in one tree do not remove each other's). Appends "fuzz/NAME 1 0" or
# "fuzz/NAME 0 1" per target to the results file summarise.sh totals.
# FUZZ_SEED fixes libFuzzer's seed (make test does, so that a run explores
# the same inputs each time; make fuzz does not, to explore new ones).
set -u
cd "$(dirname "$0")/../.."
results=${KM_RESULTS:-build/test-results.txt}
mkdir -p "$(dirname "$results")"
seconds=${1:?seconds}
shift
status=0
for name in "$@"; do
  bin=build/fuzz/fuzz_$name
  seeds=tests/fuzz/$name/corpus
  work=build/fuzz/$name-corpus
  arts=build/fuzz/artifacts-$$/$name
  mkdir -p "$work" "$arts"
  dict=$(ls tests/fuzz/"$name"/*.dict 2>/dev/null | head -n 1)
  log=$arts.log
  t0=$(date +%s)
  # The JSON targets take requests up to 16 KiB (the largest seeds are a
  # few KiB); the others keep libFuzzer's default from their seeds.
  maxlen=""
  case $name in api_*) maxlen=-max_len=16384 ;; curves) maxlen=-max_len=4096 ;; esac
  ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} \
  UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1} \
    timeout $((seconds + 120)) "$bin" -fork=1 -ignore_timeouts=1 \
      -ignore_ooms=0 -ignore_crashes=0 -max_total_time="$seconds" \
      -timeout=1 -rss_limit_mb=2048 -malloc_limit_mb=2048 $maxlen \
      ${FUZZ_SEED:+-seed="$FUZZ_SEED"} \
      ${dict:+-dict="$dict"} -artifact_prefix="$arts/" \
      "$work" "$seeds" >"$log" 2>&1
  rc=$?
  dt=$(($(date +%s) - t0))
  runs=$(grep -o '^#[0-9]*' "$log" | tail -n 1 | tr -d '#')
  cov=$(sed -n 's/.* cov: \([0-9]*\) .*/\1/p' "$log" | tail -n 1)
  found=$(ls "$arts" | wc -l)
  if [ "$found" -eq 0 ] && { [ "$rc" -eq 0 ] || [ "$rc" -eq 70 ]; }; then
    # 70 is libFuzzer's status for timeouts; with none saved it only means
    # a child was cut by -max_total_time.
    echo "ok   fuzz/$name: ${runs:-0} inputs in ${dt} s, coverage ${cov:-?}, corpus $(ls "$work" | wc -l)"
    echo "fuzz/$name 1 0" >>"$results"
  else
    status=1
    echo "FAIL fuzz/$name: ${runs:-0} inputs in ${dt} s, exit $rc, artifacts in $arts:"
    for a in "$arts"/*; do
      [ -f "$a" ] || continue
      printf '  %s (%d bytes): ' "$(basename "$a")" "$(wc -c <"$a")"
      head -c 160 "$a" | tr -c '[:print:]' '.'
      echo
    done
    grep -m 3 -E 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error|fuzz_(api|curves):' "$log" | sed 's/^/  /'
    [ "$found" -eq 0 ] && tail -n 20 "$log" | sed 's/^/  /'
    echo "fuzz/$name 0 1" >>"$results"
  fi
done
exit $status
