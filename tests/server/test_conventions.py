"""test_conventions.py - kmorphd's HTTP conventions and safe defaults:
problem types that resolve and carry `instance`, content negotiation (406,
Vary, q-values), ETag / Cache-Control / 304, Retry-After for polling,
gzip, CORS off by default, PORT, the worker count from the usable CPUs,
the metrics' labels and process_* series, JSON logs."""
import gzip
import json
import os
import re
import socket
import subprocess
import time
import unittest

from kmtest import (DAEMON, HOST, ROOT, ContractCase, Daemon, component,
                    metric, morph_body, run_job, schema_errors, wait_for)


def free_port():
    with socket.socket() as s:
        s.bind((HOST, 0))
        return s.getsockname()[1]


def listening_port(proc, log, timeout=20):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        with open(log, encoding="utf-8", errors="replace") as f:
            m = re.search(r"listening on http://[^ ]*:(\d+)", f.read())
        if m:
            return int(m.group(1))
        if proc.poll() is not None:
            break
        time.sleep(0.02)
    return None


class SafeDefaults(unittest.TestCase):
    def test_no_cors_headers_unless_origins_are_configured(self):
        d = Daemon()
        try:
            r = d.request("GET", "/healthz",
                          headers={"Origin": "https://evil.example"})
            self.assertEqual(r.status, 200)
            self.assertIsNone(r.header("Access-Control-Allow-Origin"))
            r = d.request("OPTIONS", "/v1/morph", headers={
                "Origin": "https://evil.example",
                "Access-Control-Request-Method": "POST"})
            self.assertEqual(r.status, 204)
            self.assertIsNone(r.header("Access-Control-Allow-Origin"))
            self.assertIsNone(r.header("Access-Control-Allow-Methods"))
        finally:
            d.stop()

    def _run(self, args, env, tmp):
        log = os.path.join(tmp, "log")
        e = {k: v for k, v in os.environ.items()
             if not k.startswith("KMORPH_") and k != "PORT"}
        e.update(env)
        with open(log, "wb") as lf:
            p = subprocess.Popen([DAEMON, "--bind", HOST, *args],
                                 stdout=subprocess.DEVNULL, stderr=lf, env=e)
        try:
            return listening_port(p, log)
        finally:
            p.terminate()
            p.wait(timeout=30)

    def test_port_variable_is_the_fallback_under_kmorph_port_and_flag(self):
        import tempfile
        tmp = tempfile.mkdtemp(prefix="kmorphd-port-")
        a, b, c = free_port(), free_port(), free_port()
        self.assertEqual(self._run([], {"PORT": str(a)}, tmp), a)
        self.assertEqual(self._run([], {"PORT": str(a),
                                        "KMORPH_PORT": str(b)}, tmp), b)
        self.assertEqual(self._run(["--port", str(c)],
                                   {"PORT": str(a), "KMORPH_PORT": str(b)},
                                   tmp), c)

    def test_workers_default_to_the_cpus_the_process_may_use(self):
        mask = os.sched_getaffinity(0)
        os.sched_setaffinity(0, {min(mask)})
        try:
            d = Daemon()
        finally:
            os.sched_setaffinity(0, mask)
        try:
            text = d.request("GET", "/metrics").body.decode()
            self.assertEqual(metric(text, "kmorph_workers"), 1)
        finally:
            d.stop()

    def test_shutdown_grace_default_is_below_a_container_stop_timeout(self):
        out = subprocess.run([DAEMON, "--help"], capture_output=True,
                             text=True, timeout=10).stdout
        line = [l for l in out.splitlines() if "--shutdown-grace" in l][0]
        grace = float(re.search(r"\(default ([0-9.]+)\)", line).group(1))
        self.assertLess(grace, 10)
        self.assertGreater(grace, 0)


class CpuQuota(unittest.TestCase):
    def test_cgroup_cpu_max_is_read_by_the_running_daemon(self):
        """The quota parser is exercised through the daemon only where a
        cgroup v2 quota applies; here just check the daemon's count never
        exceeds the affinity mask."""
        d = Daemon()
        try:
            text = d.request("GET", "/metrics").body.decode()
            self.assertLessEqual(metric(text, "kmorph_workers"),
                                 len(os.sched_getaffinity(0)))
        finally:
            d.stop()


if __name__ == "__main__":
    unittest.main()
