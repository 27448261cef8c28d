#!/usr/bin/env python3
"""run_cluster.py - `make run-cluster` / `make stop-cluster`: a kmorph
cluster on loopback for trying by hand. start: redis-server, two kmorphd
sharing jobs through it (--jobs redis://...) and nginx in front (round
robin), each in the background with its pid file and log under
build/cluster/; prints the URLs. stop: ends each process it started, by
the pid in its file (after checking the pid is still that program).

Ports (environment): CLUSTER_PORT (nginx, 8090), CLUSTER_KMORPHD_PORTS
(8091,8092), CLUSTER_REDIS_PORT (6390). A port in use is an error.
CLUSTER_STATE: the folder of pid files and logs (build/cluster).
"""
import os
import signal
import socket
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "cluster"))
from cluster import (HOST, NGINX, REDIS_SERVER, daemon_has_jobs_flag,  # noqa
                     nginx_conf)

STATE = os.environ.get("CLUSTER_STATE", os.path.join(ROOT, "build", "cluster"))
DAEMON = os.environ.get("KMORPHD", os.path.join(ROOT, "build", "kmorphd"))
# Stopped in this order: the proxy first, the store last.
NAMES = ("nginx", "kmorphd1", "kmorphd2", "redis")


def ports():
    k = [int(p) for p in os.environ.get("CLUSTER_KMORPHD_PORTS",
                                        "8091,8092").split(",")]
    return (int(os.environ.get("CLUSTER_PORT", "8090")), k,
            int(os.environ.get("CLUSTER_REDIS_PORT", "6390")))


def in_use(port):
    with socket.socket() as s:
        return s.connect_ex((HOST, port)) == 0


def pidfile(name):
    return os.path.join(STATE, name + ".pid")


def read_pid(name):
    try:
        with open(pidfile(name)) as f:
            return int(f.read().strip())
    except (OSError, ValueError):
        return None


def running(name):
    """The pid in name's file if that process still runs the program it
    was started as (a pid reused by another program is not ours)."""
    pid = read_pid(name)
    if pid is None:
        return None
    try:
        with open("/proc/%d/cmdline" % pid, "rb") as f:
            argv0 = f.read().split(b"\0")[0].decode(errors="replace")
    except OSError:
        return None
    want = {"nginx": "nginx", "redis": "redis-server"}.get(name, "kmorphd")
    return pid if want in os.path.basename(argv0) or \
        argv0.startswith(want) else None


def spawn(name, argv):
    log = open(os.path.join(STATE, name + ".log"), "ab")
    p = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=log,
                         stderr=log, start_new_session=True, cwd=ROOT)
    with open(pidfile(name), "w") as f:
        f.write("%d\n" % p.pid)
    return p


def wait_port(port, proc, what, timeout=20.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            break
        if in_use(port):
            return
        time.sleep(0.05)
    stop()
    sys.exit("run-cluster: %s did not start; see build/cluster/ logs" % what)


def start():
    os.makedirs(STATE, exist_ok=True)
    live = [n for n in NAMES if running(n)]
    if live:
        sys.exit("run-cluster: already running (%s); make stop-cluster"
                 % ", ".join(live))
    front, backs, redis_port = ports()
    taken = [p for p in [front, redis_port] + backs if in_use(p)]
    if taken:
        sys.exit("run-cluster: port(s) in use on %s: %s (set CLUSTER_PORT, "
                 "CLUSTER_KMORPHD_PORTS, CLUSTER_REDIS_PORT)" %
                 (HOST, " ".join(map(str, taken))))
    shared = daemon_has_jobs_flag(DAEMON)
    if not shared:
        print("run-cluster: WARNING: %s has no --jobs flag: each instance "
              "keeps its own jobs in memory" % DAEMON)
    redis_url = "redis://%s:%d/0" % (HOST, redis_port)
    p = spawn("redis", [REDIS_SERVER, "--bind", HOST, "--port",
                        str(redis_port), "--dir", STATE, "--save", "",
                        "--appendonly", "yes", "--daemonize", "no"])
    wait_port(redis_port, p, "redis-server")
    for k, port in enumerate(backs):
        argv = [DAEMON, "--bind", HOST, "--port", str(port)]
        if shared:
            argv += ["--jobs", redis_url]
        p = spawn("kmorphd%d" % (k + 1), argv)
        wait_port(port, p, "kmorphd%d" % (k + 1))
    conf = os.path.join(STATE, "nginx.conf")
    with open(conf, "w") as f:
        f.write(nginx_conf(STATE, front, backs))
    p = spawn("nginx", [NGINX, "-c", conf, "-p", STATE, "-e",
                        os.path.join(STATE, "error.log")])
    wait_port(front, p, "nginx")
    print("kmorph cluster on loopback (pid files and logs in build/cluster/):")
    print("  http://%s:%d/  nginx, round robin over:" % (HOST, front))
    for k, port in enumerate(backs):
        print("    http://%s:%d/  kmorphd%d" % (HOST, port, k + 1))
    print("  %s  redis-server%s" % (redis_url,
                                    "" if shared else " (unused)"))
    print("stop with: make stop-cluster")


def stop():
    for name in NAMES:
        pid = running(name)
        if pid is not None:
            # nginx stops gracefully on SIGQUIT, the others on SIGTERM.
            os.kill(pid, signal.SIGQUIT if name == "nginx"
                    else signal.SIGTERM)
            deadline = time.monotonic() + 15
            while running(name) and time.monotonic() < deadline:
                time.sleep(0.05)
            if running(name):
                os.kill(pid, signal.SIGKILL)
            print("stopped %s (pid %d)" % (name, pid))
        try:
            os.unlink(pidfile(name))
        except OSError:
            pass


if __name__ == "__main__":
    if sys.argv[1:] == ["start"]:
        start()
    elif sys.argv[1:] == ["stop"]:
        stop()
    else:
        sys.exit("usage: run_cluster.py start|stop")
