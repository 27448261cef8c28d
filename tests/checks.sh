#!/usr/bin/env bash
# checks.sh - the tree's own checks beside the test suites: every C file
# laid out as .clang-format says (clang-format 14, Debian 12's), and the
# compound-shape fixtures consistent with what they claim to be, and the
# compound morphs of every fixture pair checked against them. Appends
# "checks/<name> <passed> <failed>" to the results file summarise.sh
# totals.
set -u
cd "$(dirname "$0")/.."
results=${KM_RESULTS:-build/test-results.txt}
mkdir -p "$(dirname "$results")"
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
status=0

# 1. Layout: the generated contract (api/src/openapi.c) is not checked.
files=$(git ls-files '*.c' '*.h' 2>/dev/null | grep -v '^api/src/openapi\.c$')
if [ -z "$files" ]; then
  files=$(find core api server cli tests bench -name '*.[ch]' | grep -v '^api/src/openapi\.c$')
fi
if out=$(clang-format --dry-run --Werror $files 2>&1); then
  echo "ok   format: $(echo "$files" | wc -w) C files as .clang-format lays them out"
  echo "checks/format 1 0" >>"$results"
else
  printf '%s\n' "$out" | head -n 20
  echo "FAIL format: run 'make format' (clang-format -i) and commit"
  echo "checks/format 0 1" >>"$results"
  status=1
fi

# 2. The compound-shape fixtures (tests/fixtures/compound), and 3. the
# compound morphs of every fixture pair (needs build/kmorph; 21 frames
# here, all 41 in make test-compound).
unittest_module() { # name module [VAR=value ...]
  local name=$1 module=$2
  shift 2
  out=$(cd tests/fixtures/compound && env "$@" "$PY" -m unittest "$module" 2>&1)
  rc=$?
  ran=$(printf '%s\n' "$out" | sed -n 's/^Ran \([0-9]*\) test.*/\1/p' | tail -n 1)
  bad=$(printf '%s\n' "$out" | sed -n 's/^\(FAIL\|ERROR\): \([a-z_0-9]*\).*/\2/p' | sort -u | wc -l)
  ran=${ran:-0}
  [ "$rc" -ne 0 ] && [ "$bad" -eq 0 ] && bad=1
  printf '%s\n' "$out" | grep -E '^(FAIL|ERROR):|^Ran|^OK|^FAILED|^  all pairs'
  echo "checks/$name $((ran - bad)) $bad" >>"$results"
  [ "$bad" -eq 0 ] || status=1
}
unittest_module compound-fixtures test_fixtures
unittest_module compound-morphs test_compound_morphs \
  KMORPH="$PWD/build/kmorph" KM_COMPOUND_FRAMES="${KM_COMPOUND_FRAMES:-21}" \
  KM_COMPOUND_REPORT="$PWD/build/compound-morphs.txt"
# 4. One version (VERSION): the contract's info.version, the generated
# km/version.h and both binaries' --version say the same.
version=$(cat VERSION)
header=build/gen/include/km/version.h
want=$(printf '%s' "$version" | awk -F. '{ printf "%d %d %d", $1, $2, $3 }')
got=$(awk '$1 == "#define" && $2 ~ /^KM_VERSION_(MAJOR|MINOR|PATCH)$/ { printf "%s ", $3 }' \
  "$header" 2>/dev/null | sed 's/ $//')
api_version=$(awk '/^info:/ { i = 1; next } i && /^[^ ]/ { i = 0 } i && $1 == "version:" { print $2; exit }' \
  api/openapi.yaml)
bad=0
for pair in "openapi.yaml info.version|$api_version" \
            "km/version.h numbers|$got|$want" \
            "kmorph --version|$(build/kmorph --version 2>&1)|kmorph $version" \
            "kmorphd --version|$(build/kmorphd --version 2>&1 | cut -d' ' -f1-2)|kmorphd $version"; do
  IFS='|' read -r what have expect <<<"$pair"
  expect=${expect:-$version}
  if [ "$have" != "$expect" ]; then
    echo "FAIL version: $what is '$have', VERSION says '$expect'"
    bad=$((bad + 1))
  fi
done
[ "$bad" -eq 0 ] && echo "ok   version: $version in the contract, km/version.h and both binaries"
echo "checks/version $((4 - bad)) $bad" >>"$results"
[ "$bad" -eq 0 ] || status=1
exit $status
