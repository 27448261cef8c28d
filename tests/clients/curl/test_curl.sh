#!/usr/bin/env bash
# test_curl.sh - the curl scripts (clients/curl) against a live kmorphd:
# usage, every endpoint, the job flow with progress, SVG output, and
# errors (problem detail on stderr, non-zero exit). Expected numbers come
# from circles and squares, not from the service. Prints "ok"/"FAIL" per
# check and a closing "N passed, N failed" line.
set -u
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lib/daemon.sh"
bin=$km_root/clients/curl
work=$(mktemp -d "${TMPDIR:-/tmp}/kmorph-curl-test.XXXXXX")
passed=0
failed=0
check() { # check NAME COMMAND...: passes when COMMAND succeeds
  local name=$1; shift
  if ( "$@" ) >"$work/check.out" 2>&1; then passed=$((passed + 1)); echo "ok   $name"
  else failed=$((failed + 1)); echo "FAIL $name"; sed 's/^/     | /' "$work/check.out" | tail -n 15; fi
}
# near A B EPS: |A - B| <= EPS
near() { awk -v a="$1" -v b="$2" -v e="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; if (d <= e) exit 0; print a " is not within " e " of " b; exit 1 }'; }

start_daemon --max-job-frames 50000 || { echo "0 passed, 1 failed"; exit 1; }
trap 'stop_daemon; rm -rf "$work"' EXIT

PI=3.141592653589793
CIRCLE10="M 10 0 A 10 10 0 1 1 -10 0 A 10 10 0 1 1 10 0 Z"
SQUARE100="M 0 0 L 100 0 L 100 100 L 0 100 Z"
CIRCLE50="M 150 50 A 50 50 0 1 1 50 50 A 50 50 0 1 1 150 50 Z"
SPIRAL_A='{"length": 4, "start": {"point": [0, 0], "angle": 0}, "kappa": {"degree": 1, "knots": [0, 0, 4, 4], "coefficients": [0, 4]}}'
SPIRAL_B='{"length": 4, "start": {"point": [0, 0], "angle": 0}, "kappa": {"degree": 1, "knots": [0, 0, 4, 4], "coefficients": [0, -2]}}'

t_usage() {
  for s in km-signature km-reconstruct km-morph km-job km-job-status km-job-cancel km-health; do
    out=$("$bin/$s" -h) || { echo "$s -h failed"; return 1; }
    grep -q "^usage: $s" <<<"$out" || { echo "$s -h: $out"; return 1; }
  done
}
check "every script prints usage with -h and exits 0" t_usage

t_health() { [ "$("$bin/km-health")" = "ok ready" ]; }
check "km-health says ok ready" t_health

t_signature() {
  "$bin/km-signature" -s 7 -t 1e-8 "$CIRCLE10" >"$work/sig.json" || return 1
  near "$(jq .signature.length "$work/sig.json")" "$(awk -v p=$PI 'BEGIN{printf "%.17g\n", 20*p}')" 1e-6 &&
  jq -e '.samples | length == 7 and all(.[]; (.[1] - 0.1 | fabs) < 1e-7)' "$work/sig.json" >/dev/null &&
  near "$(jq '.signature.turning | fabs' "$work/sig.json")" "$(awk -v p=$PI 'BEGIN{printf "%.17g\n", 2*p}')" 1e-7
}
check "km-signature of a circle of radius 10: length 20 pi, kappa 1/10, turning 2 pi" t_signature

t_reconstruct() {
  "$bin/km-reconstruct" -t 1e-7 @"$work/sig.json" >"$work/rec.json" || return 1
  near "$(jq .curve.length "$work/rec.json")" "$(awk -v p=$PI 'BEGIN{printf "%.17g\n", 20*p}')" 1e-5 &&
  jq -e '.error_bound > 0 and .error_bound <= 1e-7' "$work/rec.json" >/dev/null &&
  # Every control point of a cubic B-spline of a circle is at distance >= r from its centre.
  jq -e '.curve.control_points | all(.[]; ((.[0] * .[0] + .[1] * .[1]) | sqrt) >= 10 - 1e-6)' "$work/rec.json" >/dev/null
}
check "km-reconstruct of that signature returns the circle (length 20 pi, bound within the tolerance)" t_reconstruct

t_reconstruct_path() {
  d=$("$bin/km-reconstruct" -p "$SPIRAL_A") || return 1
  [[ $d == M0,0C* ]] && [[ $d != *Z ]]
}
check "km-reconstruct -p prints the paper's open spiral as path data from its start (0, 0)" t_reconstruct_path

t_morph_lengths() {
  "$bin/km-morph" -n 5 -k "$SQUARE100" "$CIRCLE50" >"$work/m.json" || return 1
  [ "$(jq '.frames | length' "$work/m.json")" = 5 ] || return 1
  # The turning blend interpolates length linearly: L_t = (1-t) 400 + t 100 pi.
  for i in 0 1 2 3 4; do
    want=$(awk -v i=$i -v p=$PI 'BEGIN { t = i / 4; printf "%.17g\n", (1 - t) * 400 + t * 100 * p }')
    near "$(jq ".frames[$i].metrics.length" "$work/m.json")" "$want" 1e-6 || return 1
  done
}
check "km-morph square -> circle: 5 frames whose lengths go linearly from 400 to 100 pi" t_morph_lengths

t_morph_times() {
  "$bin/km-morph" -T 0,0.3,1 -M auto -m curvature -a centroid -c lsq -t 1e-4 "$SQUARE100" "$CIRCLE50" >"$work/t.json" &&
  [ "$(jq -c '[.frames[].t]' "$work/t.json")" = "[0,0.3,1]" ]
}
check "km-morph -T gives frames at exactly those times, with -M/-a/-c/-t accepted" t_morph_times

t_morph_linear() {
  "$bin/km-morph" -n 5 -k -m linear "$SPIRAL_A" "$SPIRAL_B" >"$work/lin.json" &&
  "$bin/km-morph" -n 5 -k "$SPIRAL_A" "$SPIRAL_B" >"$work/cur.json" &&
  jq -e '.method == "linear" and any(.frames[]; .metrics.self_intersections > 0)' "$work/lin.json" >/dev/null &&
  jq -e '.method == "curvature" and all(.frames[]; .metrics.self_intersections == 0)' "$work/cur.json" >/dev/null
}
check "km-morph of the paper's spirals: linear self-intersects, curvature does not" t_morph_linear

t_morph_request_file() {
  jq -n --argjson a "$SPIRAL_A" --argjson b "$SPIRAL_B" \
    '{from: {type: "signature", signature: $a}, to: {type: "signature", signature: $b}, frames: 9, include: ["svg_d"]}' >"$work/req.json"
  "$bin/km-morph" -r "$work/req.json" -n 3 >"$work/r.json" &&
  jq -e '(.frames | length) == 3 and all(.frames[]; .curve.svg_d | startswith("M"))' "$work/r.json" >/dev/null
}
check "km-morph -r takes a request file and options override its fields" t_morph_request_file

t_morph_svg() {
  "$bin/km-morph" -n 4 -o "$work/film.svg" "$SQUARE100" "$CIRCLE50" 2>/dev/null || return 1
  head -c 200 "$work/film.svg" | grep -q "<svg" || return 1
  if command -v xmllint >/dev/null; then xmllint --noout "$work/film.svg" || return 1; fi
  "$bin/km-morph" -n 4 -l animate "$SQUARE100" "$CIRCLE50" | grep -q "<animate"
}
check "km-morph -o FILE.svg writes a well-formed SVG filmstrip; -l animate animates" t_morph_svg

t_job() {
  "$bin/km-job" -i 0.05 -n 4000 -k -o "$work/job.json" "$SQUARE100" "$CIRCLE50" 2>"$work/job.err" || { cat "$work/job.err"; return 1; }
  grep -q "submitted" "$work/job.err" && grep -Eq "done 100% \(4000/4000 frames\)" "$work/job.err" || { cat "$work/job.err"; return 1; }
  jq -e '(.frames | length) == 4000' "$work/job.json" >/dev/null || return 1
  near "$(jq '.frames[2000].metrics.length' "$work/job.json")" "$(awk -v p=$PI 'BEGIN { t = 2000 / 3999; printf "%.17g\n", (1 - t) * 400 + t * 100 * p }')" 1e-6
}
check "km-job polls with progress to 'done 100%' and saves all 4000 frames" t_job

t_job_svg() {
  "$bin/km-job" -q -n 20 -o "$work/job.svg" "$SQUARE100" "$CIRCLE50" 2>/dev/null &&
  head -c 200 "$work/job.svg" | grep -q "<svg"
}
check "km-job -o FILE.svg saves the job's result as SVG" t_job_svg

t_job_status_cancel() {
  "$bin/km-job" -q -n 3 "$SQUARE100" "$CIRCLE50" >/dev/null 2>"$work/q.err" || return 1
  id=$(curl -s -X POST -H 'Content-Type: application/json' --data-binary @"$work/req.json" "$KMORPH_URL/v1/jobs" | jq -r .id)
  for _ in $(seq 1 50); do
    [ "$("$bin/km-job-status" "$id" | jq -r .state)" = done ] && break; sleep 0.1
  done
  "$bin/km-job-status" "$id" | jq -e '.state == "done" and .frames_total == 9' >/dev/null || return 1
  "$bin/km-job-cancel" "$id" 2>/dev/null || return 1
  # A finished job that was forgotten is gone: 404 with the problem on stderr.
  if "$bin/km-job-status" "$id" 2>"$work/gone.err"; then return 1; fi
  grep -q "404" "$work/gone.err"
}
check "km-job-status reports a done job; km-job-cancel forgets it; then status fails with 404" t_job_status_cancel

t_job_interrupted() {
  "$bin/km-job" -i 0.05 -n 50000 "$SQUARE100" "$CIRCLE50" >/dev/null 2>"$work/int.err" &
  pid=$!
  for _ in $(seq 1 100); do grep -q submitted "$work/int.err" && break; sleep 0.05; done
  id=$(sed -n 's/.*job \([0-9a-f]*\) submitted.*/\1/p' "$work/int.err")
  kill -TERM "$pid"
  wait "$pid"
  rc=$?
  [ -n "$id" ] && [ "$rc" -ne 0 ] || { echo "id=$id rc=$rc"; cat "$work/int.err"; return 1; }
  "$bin/km-job-status" "$id" | jq -e '.state == "cancelled" and .frames_done < 50000' >/dev/null
}
check "km-job stopped by a signal cancels its job on the service" t_job_interrupted

t_invalid() {
  if "$bin/km-morph" "M 0 0 L 1 0" "M 0 0 L 1 0 Z" >"$work/inv.out" 2>"$work/inv.err"; then return 1; fi
  [ ! -s "$work/inv.out" ] && grep -q "422 Invalid curve" "$work/inv.err" && grep -q "at /to/d:" "$work/inv.err"
}
check "an invalid curve exits non-zero with the 422 problem detail and its JSON pointer" t_invalid

t_bad_value() {
  if "$bin/km-morph" -m sideways "$SQUARE100" "$CIRCLE50" 2>"$work/bv.err"; then return 1; fi
  grep -q "/method" "$work/bv.err"
}
check "an unknown method exits non-zero naming /method" t_bad_value

t_unreachable() {
  if KMORPH_URL=http://127.0.0.1:9 "$bin/km-health" 2>"$work/un.err"; then return 1; fi
  grep -q "cannot reach http://127.0.0.1:9" "$work/un.err"
}
check "an unreachable service exits non-zero saying which URL" t_unreachable

t_usage_errors() {
  "$bin/km-morph" "$SQUARE100" 2>/dev/null; [ $? -eq 2 ] || return 1
  "$bin/km-morph" -x "$SQUARE100" "$CIRCLE50" 2>/dev/null; [ $? -eq 2 ] || return 1
  "$bin/km-signature" "not a curve" 2>/dev/null; [ $? -eq 2 ] || return 1
  "$bin/km-job-status" 2>/dev/null >/dev/null; [ $? -eq 2 ]
}
check "usage errors (missing curve, unknown option, not a curve) exit with status 2" t_usage_errors

# ------------------------------------------------------ compound shapes
# Real glyphs and icons of tests/fixtures/compound; what the scripts print
# is checked by shape_ends.py, which parses the inputs itself.
FIX=$km_root/tests/fixtures/compound
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
shape_d() { jq -r --arg id "$1" '(.glyphs // .icons)[] | select(.id == $id) | .d' "$FIX/$2.json"; }
# Tolerance of the requests (a 100-unit em, a 24-unit icon box) and the
# bound on the ends: the tolerance plus 2e-5 of the size for the sampling.
GLYPH_TOL=0.01 GLYPH_BOUND=0.012 ICON_TOL=0.003 ICON_BOUND=0.0035

# morph_ends NAME FROM TO TOL BOUND [OPTIONS...]: km-morph -p of the pair
# through the checker.
morph_ends() {
  local name=$1 from=$2 to=$3 tol=$4 bound=$5; shift 5
  "$bin/km-morph" -n 5 -p -t "$tol" "$@" "$from" "$to" >"$work/$name.lines" 2>"$work/$name.err" ||
    { cat "$work/$name.err"; return 1; }
  line=$(grep "^km-morph: contours: " "$work/$name.err") || { echo "no pairing on stderr"; cat "$work/$name.err"; return 1; }
  "$PY" "$here/shape_ends.py" "$from" "$to" "$work/$name.lines" "$line" "$bound" 5
}

t_shape_pairs() {
  for pair in "dejavu-serif/0 dejavu-serif/O glyphs" "dejavu-sans/O dejavu-sans/C glyphs" \
              "dejavu-sans/i dejavu-sans/l glyphs" "mdi/circle-double mdi/target icons"; do
    set -- $pair
    jq -e --arg a "$1" --arg b "$2" 'any(.pairs[]; .from == $a and .to == $b)' "$FIX/pairs.json" >/dev/null ||
      { echo "$1 -> $2 is not in pairs.json"; return 1; }
    if [ "$3" = glyphs ]; then tol=$GLYPH_TOL bound=$GLYPH_BOUND; else tol=$ICON_TOL bound=$ICON_BOUND; fi
    out=$(morph_ends pair "$(shape_d "$1" "$3")" "$(shape_d "$2" "$3")" "$tol" "$bound") || { echo "$1 -> $2: $out"; return 1; }
    echo "$1 -> $2: $out"
  done
}
check "km-morph -p of glyph and icon pairs (ring -> ring, O -> C, i -> l, 4 rings -> 3): ends are the inputs' contours, a valid pairing" t_shape_pairs

t_shape_collapse() {
  morph_ends oc "$(shape_d dejavu-sans/O glyphs)" "$(shape_d dejavu-sans/C glyphs)" $GLYPH_TOL $GLYPH_BOUND >/dev/null || return 1
  grep -q "^km-morph: contours: .*from [0-9] vanishes" "$work/oc.err" || { cat "$work/oc.err"; return 1; }
  # Two subpaths until t = 1, where the counter is a point and left out.
  [ "$(awk -F '\t' '{ n = gsub(/M/, "M", $2); printf "%s ", n }' "$work/oc.lines")" = "2 2 2 2 1 " ]
}
check "km-morph -p of O -> C: the counter vanishes, absent from the last line only" t_shape_collapse

t_shape_svg_file() {
  # dice-3 as an icon file ships: its die and pips in two <path> elements.
  d=$(shape_d mdi/dice-3 icons)
  die=${d%%ZM*}Z
  pips=M${d#*ZM}
  printf '<?xml version="1.0"?>\n<svg xmlns="http://www.w3.org/2000/svg"\n viewBox="0 0 24 24">\n <path d="%s"/>\n <path fill="red"\n   d="%s" />\n</svg>\n' \
    "$die" "$pips" >"$work/dice-3.svg"
  to=$(shape_d mdi/dice-5 icons)
  mine='[[0,0],[1,1],[2,2],[3,3],[null,4],[null,5]]'
  "$bin/km-morph" -n 5 -p -t $ICON_TOL -C "$mine" "@$work/dice-3.svg" "$to" >"$work/dice.lines" 2>"$work/dice.err" ||
    { cat "$work/dice.err"; return 1; }
  line=$(grep "^km-morph: contours: " "$work/dice.err")
  [ "$line" = "km-morph: contours: from 0 -> to 0, from 1 -> to 1, from 2 -> to 2, from 3 -> to 3, to 4 appears, to 5 appears" ] ||
    { echo "pairing: $line"; return 1; }
  "$PY" "$here/shape_ends.py" "$d" "$to" "$work/dice.lines" "$line" $ICON_BOUND 5
}
check "km-morph reads an SVG file's <path>s as one shape and honours -C contour matches (dice-3 -> dice-5)" t_shape_svg_file

t_shape_svg_fill() {
  # Two squares of the same turn: inside both the winding number is 2, so
  # the inner one is a hole under evenodd (said on a <g>) and filled under
  # nonzero (the default).
  sq="M0 0h10v10h-10zM2 2h6v6h-6z"
  printf '<svg xmlns="http://www.w3.org/2000/svg"><g fill-rule="evenodd"><path d="%s"/></g></svg>' "$sq" >"$work/eo.svg"
  printf '<svg xmlns="http://www.w3.org/2000/svg"><path d="%s"/></svg>' "$sq" >"$work/nz.svg"
  [ "$("$bin/km-signature" "@$work/eo.svg" | jq -c '[.roles, .fill_rule]')" = '[["outer","hole"],"evenodd"]' ] || return 1
  [ "$("$bin/km-signature" "@$work/nz.svg" | jq -c '.roles')" = '["outer","outer"]' ] || return 1
  # The lock as mdi ships it (only its last subpath closed) morphs, its
  # contours closed as SVG fills them: frame 0 is the closed fixture.
  src=$(jq -r '.icons[] | select(.id == "mdi/lock") | .d_source' "$FIX/icons.json")
  printf '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 24 24">\n<path d="%s"/>\n</svg>\n' "$src" >"$work/lock.svg"
  if "$bin/km-morph" -n 2 "$src" "$(shape_d mdi/lock-outline icons)" 2>"$work/lock.err" >/dev/null; then return 1; fi
  grep -q "subpath 0 .* is open" "$work/lock.err" || { cat "$work/lock.err"; return 1; }
  "$bin/km-morph" -n 5 -p -t $ICON_TOL "@$work/lock.svg" "$(shape_d mdi/lock-outline icons)" >"$work/lock.lines" 2>"$work/lock.err" ||
    { cat "$work/lock.err"; return 1; }
  "$PY" "$here/shape_ends.py" "$(shape_d mdi/lock icons)" "$(shape_d mdi/lock-outline icons)" "$work/lock.lines" \
    "$(grep "^km-morph: contours: " "$work/lock.err")" $ICON_BOUND 5
}
check "an SVG file keeps its fill rule (evenodd makes a hole) and its open subpaths are closed (mdi's lock morphs)" t_shape_svg_fill

t_path_contours_jq() {
  # The scripts' jq splitter over every icon as shipped and as closed: the
  # service answers the same signatures as for the closed fixture d.
  ( . "$bin/kmorph-lib.sh"
    jq -r "$km_path_contours_jq"' .icons[] | [.id, .d, (.d | path_contours | join(" ")), (.d_source | path_contours | join(" "))] | @tsv' \
      "$FIX/icons.json" >"$work/icons.tsv" ) || return 1
  sig() { jq -cn --arg d "$1" '{curve: {type: "svg", d: $d}}' |
            curl -sS -H 'Content-Type: application/json' --data-binary @- "$KMORPH_URL/v1/signature"; }
  n=0
  while IFS=$'\t' read -r id d closed shipped; do
    want=$(sig "$d")
    [ "$(sig "$closed")" = "$want" ] && [ "$(sig "$shipped")" = "$want" ] || { echo "$id differs"; return 1; }
    n=$((n + 1))
  done <"$work/icons.tsv"
  [ "$n" -eq "$(jq '.icons | length' "$FIX/icons.json")" ]
}
check "the jq path splitter closes every fixture icon as shipped into the fixture's contours (same signatures)" t_path_contours_jq

t_shape_job() {
  from=$(shape_d mdi/circle-double icons) to=$(shape_d mdi/target icons)
  "$bin/km-job" -q -i 0.05 -n 7 -p -t $ICON_TOL "$from" "$to" >"$work/job.lines" 2>"$work/job.err" || { cat "$work/job.err"; return 1; }
  "$bin/km-morph" -n 7 -p -t $ICON_TOL "$from" "$to" >"$work/sync.lines" 2>/dev/null || return 1
  cmp "$work/job.lines" "$work/sync.lines" && grep -q "^km-job: contours: " "$work/job.err"
}
check "km-job -p of shapes prints the synchronous morph's lines and the pairing" t_shape_job

t_shape_invalid() {
  bad=$(jq -cn '{type: "shape", contours: [{type: "svg", d: "M 0 0 L 10 0 L 10 10 Z"}, {type: "svg", d: "M 20 0 L 30 0 L 30 10"}]}')
  if "$bin/km-morph" "$bad" "M 0 0 L 10 0 L 10 10 Z" >"$work/si.out" 2>"$work/si.err"; then return 1; fi
  grep -q "at /from/contours/1: contour 1 is open" "$work/si.err" || { cat "$work/si.err"; return 1; }
  if "$bin/km-morph" "M 0 0 L 10 0 L 10 10 Z" "M 0 0 L 10 0 L 10 10 Z M 20 0 L 20 0 Z" 2>"$work/si2.err"; then return 1; fi
  grep -q "at /to/d: .*offset 23: subpath 1" "$work/si2.err" || { cat "$work/si2.err"; return 1; }
  "$bin/km-morph" -p -l animate "$SQUARE100" "$CIRCLE50" 2>"$work/si3.err"; [ $? -eq 2 ] || return 1
  grep -q "cannot be combined with -l" "$work/si3.err"
}
check "a bad contour exits 1 naming /from/contours/1, a bad subpath its offset; -p with -l is a usage error" t_shape_invalid

t_version() {
  want=$(sed -n '/^info:/,/^[^ ]/s/^  version: *"\{0,1\}\([^" ]*\).*/\1/p' "$km_root/api/openapi.yaml")
  [ -n "$want" ] || { echo "no info.version in openapi.yaml"; return 1; }
  for s in km-signature km-reconstruct km-morph km-job km-job-status km-job-cancel km-health; do
    [ "$("$bin/$s" --version)" = "$s $want" ] || { echo "$s --version: $("$bin/$s" --version)"; return 1; }
  done
}
check "every script's --version is the API's info.version" t_version

# A stand-in service that answers 503 (Retry-After: 1), then 429
# (Retry-After: 1), then 200: the scripts must wait and try again, and
# give up with the problem once KMORPH_RETRIES is spent.
t_retry() {
  cat >"$work/busy.py" <<'PY'
import http.server, json, sys, time
answers = [(503, "1"), (429, "1")]
seen = []
class H(http.server.BaseHTTPRequestHandler):
    def log_message(self, *a): pass
    def do_GET(self):
        seen.append(time.monotonic())
        if answers:
            code, after = answers.pop(0)
            body = json.dumps({"type": "/problems/busy", "title": "Busy", "status": code}).encode()
            self.send_response(code); self.send_header("Retry-After", after)
            self.send_header("Content-Type", "application/problem+json")
        else:
            body = json.dumps({"status": "ok"}).encode()
            self.send_response(200); self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(body))); self.end_headers(); self.wfile.write(body)
s = http.server.HTTPServer(("127.0.0.1", 0), H)
print(s.server_address[1], flush=True)
s.timeout = 20
deadline = time.monotonic() + 30
while time.monotonic() < deadline and len(seen) < int(sys.argv[1]):
    s.handle_request()
PY
  timeout 40 python3 "$work/busy.py" 4 >"$work/port1" & busy=$!
  for _ in $(seq 100); do [ -s "$work/port1" ] && break; sleep 0.1; done
  port=$(cat "$work/port1")
  start=$(date +%s.%N)
  out=$(KMORPH_URL=http://127.0.0.1:$port "$bin/km-health" 2>"$work/retry.err") || { cat "$work/retry.err"; return 1; }
  took=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')
  wait "$busy"
  [ "$out" = "ok ok" ] || { echo "got: $out"; return 1; }
  [ "$(grep -c 'retrying in 1s' "$work/retry.err")" -eq 2 ] || { cat "$work/retry.err"; return 1; }
  awk -v t="$took" 'BEGIN { exit !(t >= 2 && t < 20) }' || { echo "took $took s"; return 1; }
  timeout 40 python3 "$work/busy.py" 2 >"$work/port2" & busy=$!
  for _ in $(seq 100); do [ -s "$work/port2" ] && break; sleep 0.1; done
  port=$(cat "$work/port2")
  KMORPH_RETRIES=1 KMORPH_URL=http://127.0.0.1:$port "$bin/km-health" 2>"$work/retry2.err"; rc=$?
  wait "$busy"
  [ "$rc" -eq 1 ] || { echo "rc $rc"; return 1; }
  grep -q "429 Busy" "$work/retry2.err" || { cat "$work/retry2.err"; return 1; }
}
check "429 and 503 are retried after Retry-After, a bounded number of times" t_retry

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
