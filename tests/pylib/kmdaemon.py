"""kmdaemon.py - what every Python test of kmorphd needs: the daemon on a
free loopback port (its stderr kept, sanitizer reports collected when
asked), HTTP to it on fresh or raw connections, bounded waits, its
resident memory and open descriptors from /proc, and the small request
shapes the suites share.

Used by tests/server (through kmtest.py, which adds the contract checks)
and tests/hardening (through hlib.py, which adds the result lines).
Standard library only; every wait is bounded in time.
"""
import glob
import http.client
import json
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
DAEMON = os.environ.get("KMORPHD", os.path.join(ROOT, "build", "kmorphd"))
HOST = "127.0.0.1"


# ---------------------------------------------------------------- shapes

def circle_svg(r, cx=0.0, cy=0.0):
    """A circle of radius r as two SVG arcs, starting at (cx + r, cy)."""
    return {"type": "svg",
            "d": "M %r %r A %r %r 0 1 1 %r %r A %r %r 0 1 1 %r %r Z" % (
                cx + r, cy, r, r, cx - r, cy, r, r, cx + r, cy)}


def square_svg(side):
    """The square [0, side]^2, counter-clockwise from the origin."""
    return {"type": "svg",
            "d": "M 0 0 L %r 0 L %r %r L 0 %r Z" % (side, side, side, side)}


def open_arc(r):
    """A half circle of radius r (open)."""
    return {"type": "svg", "d": "M %r 0 A %r %r 0 0 1 %r 0" % (r, r, r, -r)}


# ------------------------------------------------------------------ HTTP

class Reply:
    """One HTTP answer: status, headers (names in lower case), body."""

    def __init__(self, status, headers, body):
        self.status = status
        self.headers = {k.lower(): v for k, v in headers}
        self.body = body

    def header(self, name):
        return self.headers.get(name.lower())

    @property
    def ctype(self):
        return (self.header("Content-Type") or "").split(";")[0].strip()

    def json(self):
        return json.loads(self.body.decode("utf-8"))


def request(port, method, path, body=None, headers=None, timeout=30.0,
            content_type="application/json"):
    """One request on a fresh connection; returns a Reply. A body that is
    not bytes is sent as JSON. content_type is sent with a body unless the
    headers name one or it is None (to send a request exactly as given)."""
    hdrs = dict(headers or {})
    data = None
    if body is not None:
        data = body if isinstance(body, bytes) else json.dumps(body).encode()
        if content_type is not None:
            hdrs.setdefault("Content-Type", content_type)
    conn = http.client.HTTPConnection(HOST, port, timeout=timeout)
    try:
        conn.request(method, path, body=data, headers=hdrs)
        r = conn.getresponse()
        return Reply(r.status, r.getheaders(), r.read())
    finally:
        conn.close()


def raw_exchange(port, data, timeout=10.0, pause=None):
    """Send bytes on a raw socket (a list of chunks, with pause seconds
    between them, if given) and read until the server closes or timeout
    passes. Returns what was read (bytes)."""
    chunks = data if isinstance(data, list) else [data]
    out = b""
    with socket.create_connection((HOST, port), timeout=timeout) as s:
        s.settimeout(timeout)
        try:
            for i, c in enumerate(chunks):
                if i and pause:
                    time.sleep(pause)
                s.sendall(c)
        except OSError:
            pass  # the server may answer and close before all is sent
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                b = s.recv(65536)
            except OSError:
                break
            if not b:
                break
            out += b
    return out


def raw_status(raw):
    """Status code of a raw HTTP/1.1 answer, or None."""
    if not raw.startswith(b"HTTP/1."):
        return None
    return int(raw.split(b" ", 2)[1])


def wait_for(fn, timeout, interval=0.02):
    """Call fn until it returns a true value or timeout seconds pass."""
    deadline = time.monotonic() + timeout
    while True:
        v = fn()
        if v:
            return v
        if time.monotonic() >= deadline:
            return v
        time.sleep(interval)


# ---------------------------------------------------------------- daemon

class Daemon:
    """A kmorphd process (exe, else $KMORPHD, else build/kmorphd) on a port
    the OS chose (--port 0), its stderr in a private folder. KMORPH_*
    variables of the caller's environment are dropped, then env added.
    With sanitized=True, ASan/UBSan/LSan reports go to files in that
    folder (reports() lists them). stop() ends it with SIGTERM (SIGKILL if
    it does not exit), close() with SIGKILL; both remove the folder."""

    def __init__(self, *flags, exe=None, env=None, sanitized=False,
                 start_timeout=20.0):
        self.dir = tempfile.mkdtemp(prefix="kmorphd-")
        self.logpath = os.path.join(self.dir, "kmorphd.log")
        self.log = open(self.logpath, "wb")
        e = {k: v for k, v in os.environ.items()
             if not k.startswith("KMORPH_")}
        if sanitized:
            e["ASAN_OPTIONS"] = ("log_path=%s/asan:detect_leaks=1:"
                                 "abort_on_error=0:halt_on_error=1"
                                 % self.dir)
            e["UBSAN_OPTIONS"] = ("log_path=%s/ubsan:print_stacktrace=1:"
                                  "halt_on_error=1" % self.dir)
            e["LSAN_OPTIONS"] = "log_path=%s/lsan" % self.dir
        e.update(env or {})
        self.proc = subprocess.Popen(
            [exe or DAEMON, "--bind", HOST, "--port", "0", *flags],
            stdout=subprocess.DEVNULL, stderr=self.log, env=e)
        self.port = self._await_port(start_timeout)

    def _await_port(self, timeout):
        deadline = time.monotonic() + timeout
        why = "kmorphd did not start: "
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                why = "kmorphd exited: "
                break
            for line in self.text().splitlines():
                if "listening on http://" in line:
                    return int(line.split("http://", 1)[1]
                               .split(" ", 1)[0].rsplit(":", 1)[1])
            time.sleep(0.02)
        why += self.text()[-2000:]
        self.close()
        raise RuntimeError(why)

    def text(self):
        with open(self.logpath, encoding="utf-8", errors="replace") as f:
            return f.read()

    def reports(self):
        """Sanitizer report files written so far (name, first lines)."""
        out = []
        for p in sorted(glob.glob(os.path.join(self.dir, "*san*"))):
            with open(p, encoding="utf-8", errors="replace") as f:
                out.append((os.path.basename(p), f.read()[:3000]))
        return out

    def rss_kb(self):
        with open("/proc/%d/status" % self.proc.pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
        return 0

    def fds(self):
        return len(os.listdir("/proc/%d/fd" % self.proc.pid))

    def alive(self):
        return self.proc.poll() is None

    def request(self, method, path, body=None, headers=None, timeout=30.0):
        return request(self.port, method, path, body, headers, timeout)

    def terminate(self, timeout=30.0):
        """SIGTERM; returns (exit status or None if it did not exit within
        timeout, seconds to exit)."""
        t0 = time.monotonic()
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
        try:
            rc = self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            rc = None
        return rc, time.monotonic() - t0

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=10)

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                pass
        self.close()

    def close(self):
        self.kill()
        self.log.close()
        shutil.rmtree(self.dir, ignore_errors=True)
