"""hlib.py - shared pieces of the hardening tests: a kmorphd on a free
loopback port (its stderr kept, sanitizer reports collected), HTTP on
fresh or raw connections, the daemon's resident memory and open file
descriptors from /proc, and the result lines summarise.sh totals.

Standard library only; every wait is bounded.
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
HOST = "127.0.0.1"
RESULTS = os.environ.get("KM_RESULTS",
                         os.path.join(ROOT, "build", "test-results.txt"))


class Daemon:
    """kmorphd on --port 0. With sanitized=True, ASan/UBSan/LSan reports go
    to files in a private folder (reports() lists them)."""

    def __init__(self, exe, *flags, sanitized=False):
        self.dir = tempfile.mkdtemp(prefix="kmorph-hardening-")
        self.logpath = os.path.join(self.dir, "kmorphd.log")
        self.log = open(self.logpath, "wb")
        env = {k: v for k, v in os.environ.items()
               if not k.startswith("KMORPH_")}
        if sanitized:
            env["ASAN_OPTIONS"] = ("log_path=%s/asan:detect_leaks=1:"
                                   "abort_on_error=0:halt_on_error=1"
                                   % self.dir)
            env["UBSAN_OPTIONS"] = ("log_path=%s/ubsan:print_stacktrace=1:"
                                    "halt_on_error=1" % self.dir)
            env["LSAN_OPTIONS"] = "log_path=%s/lsan" % self.dir
        self.proc = subprocess.Popen(
            [exe, "--bind", HOST, "--port", "0", *flags],
            stdout=subprocess.DEVNULL, stderr=self.log, env=env)
        self.port = None
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline and self.port is None:
            if self.proc.poll() is not None:
                raise RuntimeError("kmorphd exited: " + self.text()[-2000:])
            for line in self.text().splitlines():
                if "listening on http://" in line:
                    self.port = int(line.split("http://", 1)[1]
                                    .split(" ", 1)[0].rsplit(":", 1)[1])
            time.sleep(0.02)
        if self.port is None:
            self.kill()
            raise RuntimeError("kmorphd did not start: " + self.text())

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
        """SIGTERM; returns (exit status or None, seconds to exit)."""
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

    def close(self):
        self.kill()
        self.log.close()
        shutil.rmtree(self.dir, ignore_errors=True)


class Reply:
    def __init__(self, status, headers, body):
        self.status = status
        self.headers = {k.lower(): v for k, v in headers}
        self.body = body

    @property
    def ctype(self):
        return (self.headers.get("content-type") or "").split(";")[0].strip()

    def json(self):
        return json.loads(self.body.decode("utf-8"))


def request(port, method, path, body=None, headers=None, timeout=30.0):
    """One request on a fresh connection."""
    hdrs = dict(headers or {})
    if body is not None and not isinstance(body, bytes):
        body = json.dumps(body).encode()
    conn = http.client.HTTPConnection(HOST, port, timeout=timeout)
    try:
        conn.request(method, path, body=body, headers=hdrs)
        r = conn.getresponse()
        return Reply(r.status, r.getheaders(), r.read())
    finally:
        conn.close()


def raw(port, data, timeout=10.0):
    """Send raw bytes, read until the server closes or timeout."""
    out = b""
    with socket.create_connection((HOST, port), timeout=timeout) as s:
        try:
            s.sendall(data)
        except OSError:
            pass
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


def raw_request(port, method, path, headers, body, timeout=30.0):
    """A request on a raw socket whose answer is read even when the server
    answers and closes before the whole body is sent; returns a Reply
    (status 0 if no HTTP answer came)."""
    head = "%s %s HTTP/1.1\r\nHost: %s\r\nConnection: close\r\n" % (
        method, path, HOST)
    for k, v in headers.items():
        if k != "X-Raw":
            head += "%s: %s\r\n" % (k, v)
    head += "Content-Length: %d\r\n\r\n" % len(body or b"")
    data = raw(port, head.encode() + (body or b""), timeout)
    hdr, _, rest = data.partition(b"\r\n\r\n")
    lines = hdr.decode("latin-1").split("\r\n")
    try:
        status = int(lines[0].split(" ", 2)[1])
    except (IndexError, ValueError):
        return Reply(0, [], data)
    hs = [tuple(x.split(": ", 1)) for x in lines[1:] if ": " in x]
    hd = {k.lower(): v for k, v in hs}
    if hd.get("transfer-encoding", "").lower() == "chunked":
        out, buf = b"", rest
        while buf:
            size_s, _, buf = buf.partition(b"\r\n")
            size = int(size_s.split(b";")[0] or b"0", 16)
            if size == 0:
                break
            out, buf = out + buf[:size], buf[size + 2:]
        rest = out
    return Reply(status, hs, rest)


def problem_ok(reply):
    """'' if reply is a 4xx problem+json whose status matches, else why."""
    if not 400 <= reply.status < 500:
        return "status %d" % reply.status
    if reply.ctype != "application/problem+json":
        return "content type %r" % reply.ctype
    try:
        doc = reply.json()
    except ValueError:
        return "body is not JSON"
    if doc.get("status") != reply.status or not isinstance(
            doc.get("type"), str) or not isinstance(doc.get("title"), str):
        return "problem lacks type/title/status"
    return ""


def record(name, passed, failed):
    os.makedirs(os.path.dirname(RESULTS), exist_ok=True)
    with open(RESULTS, "a") as f:
        f.write("%s %d %d\n" % (name, passed, failed))


class Checks:
    """Named pass/fail checks of one suite, printed as they happen."""

    def __init__(self, suite):
        self.suite = suite
        self.passed = 0
        self.failed = 0

    def check(self, ok, what, detail=""):
        if ok:
            self.passed += 1
            print("ok   %s: %s" % (self.suite, what))
        else:
            self.failed += 1
            print("FAIL %s: %s%s" % (self.suite, what,
                                     (" - " + detail) if detail else ""))
        return ok

    def record(self):
        record("hardening/" + self.suite, self.passed, self.failed)
        return self.failed == 0
