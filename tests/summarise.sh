#!/usr/bin/env bash
# summarise.sh - total the per-suite counts that the test runners appended
# and print the closing line CI reads. Exit non-zero if anything failed.
results=${KM_RESULTS:-build/test-results.txt}
[ -f "$results" ] || { echo "0 passed, 1 failed"; exit 1; }
awk '{ p += $2; f += $3 } END { printf "%d passed, %d failed\n", p, f; exit (f > 0 || p == 0) }' "$results"
