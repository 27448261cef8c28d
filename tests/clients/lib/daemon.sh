# daemon.sh - sourced by the shell client tests: start build/kmorphd (or
# $KMORPHD) on a free loopback port, bounded in time, and stop it on exit.
# Sets KMORPH_URL and KMORPHD_PID.

km_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)
km_daemon_log=$(mktemp "${TMPDIR:-/tmp}/kmorphd-clients.XXXXXX")

start_daemon() {
  local bin=${KMORPHD:-$km_root/build/kmorphd} port= i
  [ -x "$bin" ] || { echo "no daemon at $bin (make build)" >&2; return 1; }
  env $(env | sed -n 's/^\(KMORPH_[A-Z_]*\)=.*/-u \1/p') \
    "$bin" --bind 127.0.0.1 --port 0 --web-root "$km_root/clients/web" "$@" \
    2>"$km_daemon_log" >/dev/null &
  KMORPHD_PID=$!
  for i in $(seq 1 100); do
    port=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$km_daemon_log")
    [ -n "$port" ] && break
    kill -0 "$KMORPHD_PID" 2>/dev/null || break
    sleep 0.1
  done
  if [ -z "$port" ]; then
    echo "kmorphd did not start:" >&2; cat "$km_daemon_log" >&2
    kill "$KMORPHD_PID" 2>/dev/null
    return 1
  fi
  export KMORPH_URL=http://127.0.0.1:$port
  trap stop_daemon EXIT
}

stop_daemon() {
  if [ -n "${KMORPHD_PID:-}" ] && kill -0 "$KMORPHD_PID" 2>/dev/null; then
    kill -TERM "$KMORPHD_PID"
    for _ in $(seq 1 50); do kill -0 "$KMORPHD_PID" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$KMORPHD_PID" 2>/dev/null
  fi
  rm -f "$km_daemon_log"
}
