#!/usr/bin/env bash
# run.sh - throughput and latency of kmorphd with wrk: GET /healthz, POST
# /v1/signature and a 30-frame POST /v1/morph of a fixture shape pair; then
# the same morphs computed in-process by the CLI on the same cores, for the
# ratio the service must stay within (1.5x). Loopback only; each wrk run is
# bounded by BENCH_SECONDS. Prints a Markdown table for bench/RESULTS.md.
set -eu
cd "$(dirname "$0")/../.."
secs=${BENCH_SECONDS:-10}
conns=${BENCH_CONNECTIONS:-16}
cores=$(nproc)
frames=30
tmp=$(mktemp -d)
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
pair=$("$PY" bench/http/bodies.py "$tmp" "$frames")

"${KMORPHD:-build/kmorphd}" --bind 127.0.0.1 --port 0 --access-log 0 --queue 1024 \
  --max-connections 1024 2>"$tmp/log" &
pid=$!
trap 'kill -TERM $pid 2>/dev/null; wait $pid 2>/dev/null; rm -rf "$tmp"' EXIT
port=""
for _ in $(seq 100); do
  port=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$tmp/log")
  [ -n "$port" ] && break
  sleep 0.05
done
[ -n "$port" ] || { cat "$tmp/log"; exit 1; }

post_script() { # body file -> wrk lua script
  printf 'wrk.method = "POST"\nwrk.headers["Content-Type"] = "application/json"\nwrk.body = [==[%s]==]\n' \
    "$(cat "$1")" >"$1.lua"
  echo "$1.lua"
}

# One wrk run: prints "rps p50 p99 non2xx".
bench() {
  local path=$1; shift
  local out
  out=$(wrk -t "$cores" -c "$conns" -d "${secs}s" --latency "$@" "http://127.0.0.1:$port$path")
  local rps p50 p99 bad
  rps=$(printf '%s\n' "$out" | awk '/^Requests\/sec/ {print $2}')
  p50=$(printf '%s\n' "$out" | awk '$1 == "50%" {print $2}')
  p99=$(printf '%s\n' "$out" | awk '$1 == "99%" {print $2}')
  bad=$(printf '%s\n' "$out" | awk '/Non-2xx/ {print $NF}')
  echo "$rps $p50 $p99 ${bad:-0}"
}

sig_lua=$(post_script "$tmp/signature.json")
morph_lua=$(post_script "$tmp/morph.json")
read -r h_rps h_50 h_99 h_bad < <(bench /healthz)
read -r s_rps s_50 s_99 s_bad < <(bench /v1/signature -s "$sig_lua")
read -r m_rps m_50 m_99 m_bad < <(bench /v1/morph -s "$morph_lua")

# In-process: the CLI runs the same request through the same api layer;
# one loop per core for the same wall time budget.
n=${BENCH_CLI_RUNS:-40}
t0=$(date +%s.%N)
loops=""
for c in $(seq "$cores"); do
  ( for _ in $(seq "$n"); do "${KMORPH_CLI:-build/kmorph}" morph <"$tmp/morph.json" >/dev/null; done ) &
  loops="$loops $!"
done
wait $loops
t1=$(date +%s.%N)
cli_rps=$(awk -v a="$t0" -v b="$t1" -v k="$((n * cores))" 'BEGIN {printf "%.1f", k / (b - a)}')
ratio=$(awk -v a="$cli_rps" -v b="$m_rps" 'BEGIN {printf "%.2f", (b > 0 ? a / b : 0)}')

cat <<EOT
| request | req/s | p50 | p99 | non-2xx |
|---|---|---|---|---|
| GET /healthz | $h_rps | $h_50 | $h_99 | $h_bad |
| POST /v1/signature ($pair a) | $s_rps | $s_50 | $s_99 | $s_bad |
| POST /v1/morph, $frames frames ($pair) | $m_rps | $m_50 | $m_99 | $m_bad |
| same morph in-process, kmorph CLI x $cores | $cli_rps | | | |

wrk: $cores threads, $conns connections, ${secs} s per row, on $cores cores.
In-process / HTTP morph throughput: $ratio (target: at most 1.5).
EOT
