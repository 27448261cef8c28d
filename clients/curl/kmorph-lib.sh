# kmorph-lib.sh - shared by the kmorph curl scripts (sourced, not run):
# the service URL, curve arguments, and one HTTP exchange that turns any
# problem+json answer into a message on stderr and a non-zero exit.
#
# KMORPH_URL   the service (default http://127.0.0.1:8080)
# KMORPH_CURL  extra curl options, e.g. "--max-time 30"
# KMORPH_RETRIES  how many times a 429 or 503 answer is retried (default 3),
#              each after its Retry-After (default 1 s, at most
#              KMORPH_RETRY_MAX seconds, default 10)

KMORPH_URL=${KMORPH_URL:-http://127.0.0.1:8080}
KMORPH_URL=${KMORPH_URL%/}
km_prog=$(basename "$0")
km_version=1.0.0
case "${1:-}" in --version | -V) echo "$km_prog $km_version"; exit 0 ;; esac

km_die() { echo "$km_prog: $*" >&2; exit 1; }
km_usage_error() { echo "$km_prog: $*" >&2; echo "try '$km_prog -h'" >&2; exit 2; }

command -v curl >/dev/null || km_die "curl is not installed"
command -v jq >/dev/null || km_die "jq is not installed"

# km_path_contours_jq: a jq definition. path_contours: the subpaths of the
# SVG path data in ., each a d of its own starting with an absolute moveto
# (relative data after it keeps its meaning) and closed with Z (SVG fills
# an open subpath as if closed; icon sets such as @mdi/svg close only
# their last one); movetos that draw nothing are dropped.
km_path_contours_jq='
def path_contours:
  def finish: (if .cur != null and .drawn then .out += [.cur + (if .closed then "" else "Z" end)] else . end) | .cur = null;
  def at: "M\(.sx),\(.sy)";
  {toks: [scan("[A-Za-z]|[-+]?(?:[0-9]+\\.?[0-9]*|\\.[0-9]+)(?:[eE][-+]?[0-9]+)?")],
   i: 0, cmd: null, out: [], cur: null, drawn: false, closed: false, x: 0, y: 0, sx: 0, sy: 0}
  | until(.i >= (.toks | length);
      (if (.toks[.i] | test("^[A-Za-z]$")) then .cmd = .toks[.i] | .i += 1
       elif .cmd == null or .cmd == "Z" or .cmd == "z" then error("path data: a command expected before \(.toks[.i])")
       else . end)
      | (.cmd | ascii_upcase) as $up
      | ({M: 2, L: 2, H: 1, V: 1, C: 6, S: 4, Q: 4, T: 2, A: 7, Z: 0}[$up] // error("path data: unknown command \(.cmd)")) as $n
      | .args = []
      | reduce range($n) as $k (.;
          if .i >= (.toks | length) or (.toks[.i] | test("^[A-Za-z]$")) then error("path data: a number expected after \(.cmd)")
          elif $up == "A" and ($k == 3 or $k == 4) and (.toks[.i] | length) > 1 and (.toks[.i] | test("^[01]")) then
            .args += [.toks[.i][0:1]] | .toks[.i] |= .[1:]
          else .args += [.toks[.i]] | .i += 1 end)
      | (.args | map(tonumber)) as $v
      | (.cmd != $up) as $rel
      | if $up == "M" then
          finish | .x = (if $rel then .x else 0 end) + $v[0] | .y = (if $rel then .y else 0 end) + $v[1]
          | .sx = .x | .sy = .y | .cur = at | .drawn = false | .closed = false
        else
          (if .cur == null or .closed then finish | .cur = at | .drawn = false | .closed = false else . end)
          | .cur += .cmd + (.args | join(" "))
          | if $up == "Z" then .x = .sx | .y = .sy | .closed = true
            else .drawn = true
              | if $up == "H" then .x = (if $rel then .x else 0 end) + $v[0]
                elif $up == "V" then .y = (if $rel then .y else 0 end) + $v[0]
                else .x = (if $rel then .x else 0 end) + $v[-2] | .y = (if $rel then .y else 0 end) + $v[-1] end
            end
        end
      | .cmd |= (if . == "M" then "L" elif . == "m" then "l" else . end))
  | finish | .out;
'

# km_svg_document_curve: the curve (JSON) of the SVG document on stdin: the
# contours of all its <path> elements, closed, as one shape under their
# fill rule (a path's own fill-rule attribute or style, else evenodd when a
# <svg> or <g> element says so). Transforms and other elements are not
# applied.
km_svg_document_curve() {
  local flat outer=nonzero tag d rule
  flat=$(tr '\n\r\t' '   ')
  printf '%s' "$flat" | grep -o '<\(svg\|g\)[[:space:]][^>]*>' |
    grep -q "fill-rule[[:space:]]*[:=][[:space:]]*[\"']\{0,1\}evenodd" && outer=evenodd
  printf '%s' "$flat" | grep -o '<path[[:space:]][^>]*>' | while IFS= read -r tag; do
    d=$(printf '%s' "$tag" | sed -n -e "s/.*[[:space:]]d[[:space:]]*=[[:space:]]*\"\([^\"]*\)\".*/\1/p" \
                                     -e "s/.*[[:space:]]d[[:space:]]*=[[:space:]]*'\([^']*\)'.*/\1/p")
    rule=$(printf '%s' "$tag" | sed -n "s/.*fill-rule[[:space:]]*[:=][[:space:]]*[\"']\{0,1\}\(evenodd\|nonzero\).*/\1/p")
    [ -n "$d" ] && jq -cn --arg d "$d" --arg r "${rule:-$outer}" '{d: $d, rule: $r}'
  done | jq -cs "$km_path_contours_jq"'
    if length == 0 then error("the SVG document has no <path> with a d attribute") else . end
    | (map(.rule) | unique) as $rules
    | if ($rules | length) > 1 then error("its <path>s have different fill rules") else . end
    | (map(.d | path_contours) | add) as $c
    | if ($c | length) == 0 then error("its paths draw nothing")
      elif ($c | length) == 1 then {type: "svg", d: $c[0]}
      elif $rules[0] == "evenodd" then {type: "shape", contours: ($c | map({type: "svg", d: .})), fill_rule: "evenodd"}
      else {type: "svg", d: ($c | join(" "))} end' 2>"$km_tmp/svgerr" ||
    km_usage_error "not a usable SVG document: $(sed 's/^jq: error ([^)]*): //' "$km_tmp/svgerr" | head -n 1)"
}

# km_curve ARG: a curve object (JSON) on stdout. ARG is an SVG path d
# string ("M 0 0 L 10 0"; several subpaths make a compound shape), a JSON
# curve object ('{"type": ...}', a shape among them), @FILE with either
# of those or an SVG document (its <path>s together are the shape), or @-
# for standard input. A file holding a signature (or a /v1/signature
# answer) becomes a signature curve. An SVG document gives its paths'
# contours, closed, as one shape under their fill rule.
km_curve() {
  local arg=$1 text
  case $arg in
    @-) text=$(cat) ;;
    @*) [ -r "${arg#@}" ] || km_usage_error "cannot read ${arg#@}"; text=$(cat -- "${arg#@}") ;;
    *) text=$arg ;;
  esac
  case $text in
    "<"*|[[:space:]]*"<"*) printf '%s' "$text" | km_svg_document_curve; return ;;
  esac
  if printf '%s' "$text" | jq -e 'type == "object"' >/dev/null 2>&1; then
    printf '%s' "$text" | jq -c '
      if has("type") then .
      elif has("signature") then {type: "signature", signature: .signature}
      elif has("kappa") then {type: "signature", signature: .}
      elif has("control_points") then {type: "bspline"} + .
      else error("not a curve: expected type, signature, kappa or control_points") end' 2>/dev/null ||
      km_usage_error "not a curve: $(printf '%.60s' "$text")"
  else
    case $text in
      [MmZz]*|" "*) jq -cn --arg d "$text" '{type: "svg", d: $d}' ;;
      *) km_usage_error "not an SVG path (must start with M) nor JSON: $(printf '%.60s' "$text")" ;;
    esac
  fi
}

# km_call METHOD PATH [BODY_FILE [ACCEPT]]: the answer's body goes to
# $km_body (a temporary file), its status to $km_status and its headers
# to $km_headers. Exits with a readable message on any error.
km_tmp=$(mktemp -d "${TMPDIR:-/tmp}/kmorph.XXXXXX")
trap 'rm -rf "$km_tmp"' EXIT
km_body=$km_tmp/body
km_headers=$km_tmp/headers
km_call() {
  local method=$1 path=$2 data=${3:-} accept=${4:-application/json}
  local args=(-sS -X "$method" -o "$km_body" -D "$km_headers" -w '%{http_code}'
              -H "Accept: $accept, application/problem+json")
  [ -n "$data" ] && args+=(-H "Content-Type: application/json" --data-binary "@$data")
  local tries=${KMORPH_RETRIES:-3} wait_max=${KMORPH_RETRY_MAX:-10} wait
  for (( ; ; tries-- )); do
    # shellcheck disable=SC2086
    km_status=$(curl "${args[@]}" ${KMORPH_CURL:-} "$KMORPH_URL$path" 2>"$km_tmp/err") ||
      km_die "cannot reach $KMORPH_URL: $(tail -n 1 "$km_tmp/err")"
    # An overloaded service (429, 503) refused the request without doing
    # it, so asking again after the delay it names is safe, even a POST.
    { [ "$km_status" = 429 ] || [ "$km_status" = 503 ]; } && [ "$tries" -gt 0 ] || break
    wait=$(km_header Retry-After)
    [[ "$wait" =~ ^[0-9]+$ ]] || wait=1
    [ "$wait" -gt "$wait_max" ] && wait=$wait_max
    echo "$km_prog: $km_status, retrying in ${wait}s" >&2
    sleep "$wait"
  done
  if [ "$km_status" -ge 400 ]; then
    if jq -e 'type == "object" and has("status")' "$km_body" >/dev/null 2>&1; then
      jq -r --arg p "$km_prog" '"\($p): \(.status) \(.title): \(.detail // "")",
             (.errors // [] | .[] | "  at \(.pointer): \(.message)")' "$km_body" >&2
    else
      echo "$km_prog: HTTP $km_status: $(head -c 300 "$km_body")" >&2
    fi
    exit 1
  fi
}

# km_header NAME: the value of a response header of the last km_call.
km_header() {
  tr -d '\r' <"$km_headers" | awk -v n="$(printf '%s' "$1" | tr 'A-Z' 'a-z')" -F': ' \
    'tolower($1) == n { sub(/^[^:]*: /, ""); print; exit }'
}

# Options shared by km-morph and km-job (their -h prints this).
km_morph_options='  -n FRAMES    number of evenly spaced frames (default 11)
  -T TIMES     explicit times instead, comma-separated: 0,0.25,1
  -m METHOD    curvature (default) or linear
  -b BLEND     turning (default) or paper
  -M MATCHES   auto, or pairs of arc-length fractions as JSON: [[0.2,0.3]]
  -C PAIRS     shapes: pairs of contour indices as JSON, null for a contour
               that vanishes or appears: [[0,0],[1,null]]
  -c CLOSURE   closed curves: auto, lsq, c0, c1, g2, none
  -a ANCHOR    placement: fit (default), start, centroid
  -O ORIENT    closed curves: auto, keep
  -t TOL       tolerance in the curves'"'"' units
  -g DEGREE    3 or 5
  -k           per-frame metrics (length, max |kappa|, self-intersections, ...)
  -d           include each frame'"'"'s SVG path data (svg_d)
  -p           print one line per frame: t, a tab, the frame'"'"'s path data
               (for shapes one M...Z per present contour; the pairing of
               the contours goes to stderr)
  -l LAYOUT    answer in SVG: filmstrip, overlay, animate or curvature_plot
  -o FILE      write the answer to FILE (FILE.svg asks for SVG, filmstrip
               unless -l says otherwise) instead of standard output
  -r FILE      start from the morph request in FILE (JSON); options and
               curves given on the command line replace its fields
FROM and TO are curves: an SVG path d string ("M 0 0 L 10 0 ..."; several
subpaths make a compound shape), a JSON curve object (a shape among them),
@FILE holding either, an SVG document or a signature, or @- for stdin.'

# km_morph_request ARGS...: parse the morph options and curves into the
# request file $km_req; sets $km_out (output file or empty) and $km_svg
# (1 when SVG is asked for) and $km_paths (1 for -p).
km_req=$km_tmp/request.json
km_morph_request() {
  local opt base='{}' edits=() OPTIND=1
  km_out=
  km_svg=0
  km_paths=0
  local layout=
  while getopts ':hn:T:m:b:M:C:c:a:O:t:g:kdpl:o:r:' opt; do
    case $opt in
      h) km_help; exit 0 ;;
      n) edits+=(--argjson n "$OPTARG" '.frames = $n | del(.times)') ;;
      T) edits+=(--arg ts "$OPTARG" '.times = ($ts | split(",") | map(tonumber)) | del(.frames)') ;;
      m) edits+=(--arg v "$OPTARG" '.method = $v') ;;
      b) edits+=(--arg v "$OPTARG" '.blend = $v') ;;
      M) if [ "$OPTARG" = auto ]; then edits+=('.matches = "auto"')
         else edits+=(--argjson v "$OPTARG" '.matches = $v'); fi ;;
      C) edits+=(--argjson v "$OPTARG" '.contour_matches = $v') ;;
      c) edits+=(--arg v "$OPTARG" '.closure = $v') ;;
      a) edits+=(--arg v "$OPTARG" '.anchor = $v') ;;
      O) edits+=(--arg v "$OPTARG" '.orient = $v') ;;
      t) edits+=(--argjson v "$OPTARG" '.tolerance = $v') ;;
      g) edits+=(--argjson v "$OPTARG" '.degree = $v') ;;
      k) edits+=('.metrics = true') ;;
      d) edits+=('.include = ((.include // []) + ["svg_d"] | unique)') ;;
      p) km_paths=1; edits+=('.include = ((.include // []) + ["svg_d"] | unique)') ;;
      l) layout=$OPTARG ;;
      o) km_out=$OPTARG ;;
      r) [ -r "$OPTARG" ] || km_usage_error "cannot read $OPTARG"; base=$(cat -- "$OPTARG") ;;
      :) km_usage_error "-$OPTARG needs a value" ;;
      *) km_usage_error "unknown option -$OPTARG" ;;
    esac
  done
  shift $((OPTIND - 1))
  printf '%s' "$base" | jq -e 'type == "object"' >/dev/null 2>&1 || km_usage_error "the -r request is not a JSON object"
  printf '%s' "$base" >"$km_req"
  if [ $# -eq 2 ]; then
    local from to
    from=$(km_curve "$1") || exit $?
    to=$(km_curve "$2") || exit $?
    jq -c --argjson a "$from" --argjson b "$to" '.from = $a | .to = $b' "$km_req" >"$km_req.new" && mv "$km_req.new" "$km_req"
  elif [ $# -ne 0 ]; then
    km_usage_error "give two curves, FROM and TO (or none with -r)"
  fi
  jq -e 'has("from") and has("to")' "$km_req" >/dev/null || km_usage_error "FROM and TO curves are needed"
  case $km_out in *.svg) [ "$km_paths" = 1 ] || [ -n "$layout" ] || layout=filmstrip ;; esac
  [ "$km_paths" = 1 ] && [ -n "$layout" ] && km_usage_error "-p prints path data lines; it cannot be combined with -l"
  [ -n "$layout" ] && { km_svg=1; edits+=(--arg l "$layout" '.format = "svg" | .svg = ((.svg // {}) + {layout: $l})'); }
  # Apply the edits one by one: each is [--arg name value ...] filter.
  local i=0 n=${#edits[@]} a=()
  while [ $i -lt $n ]; do
    case ${edits[$i]} in
      --arg|--argjson) a+=("${edits[$i]}" "${edits[$((i + 1))]}" "${edits[$((i + 2))]}"); i=$((i + 3)) ;;
      *) jq -c "${a[@]}" "${edits[$i]}" "$km_req" >"$km_req.new" 2>"$km_tmp/err" ||
           km_usage_error "bad option value: $(tail -n 1 "$km_tmp/err")"
         mv "$km_req.new" "$km_req"; a=(); i=$((i + 1)) ;;
    esac
  done
}

# km_emit_morph: a morph result as km_emit does, or with -p one "t<TAB>d"
# line per frame and, for shapes, the pairing of the contours on stderr.
km_emit_morph() {
  if [ "$km_paths" = 1 ]; then
    jq -r --arg p "$km_prog" 'select(has("contour_matches_used")) | .contour_matches_used |
        map(if .[0] == null then "to \(.[1]) appears" elif .[1] == null then "from \(.[0]) vanishes"
            else "from \(.[0]) -> to \(.[1])" end) | "\($p): contours: " + join(", ")' "$km_body" >&2
    jq -r '.frames[] | "\(.t)\t\(if has("contours") then .svg_d else .curve.svg_d end)"' "$km_body" >"$km_body.lines" ||
      km_die "the answer has no frames"
    mv "$km_body.lines" "$km_body"
  fi
  km_emit
}

# km_emit: the last answer's body to $km_out or standard output.
km_emit() {
  if [ -n "$km_out" ]; then
    cp "$km_body" "$km_out" || km_die "cannot write $km_out"
    echo "$km_prog: wrote $km_out ($(wc -c <"$km_out") bytes)" >&2
  else
    cat "$km_body"
    [ "$(tail -c 1 "$km_body" | od -An -c | tr -d ' ')" = '\n' ] || echo
  fi
}
