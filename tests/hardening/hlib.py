"""hlib.py - the hardening tests' view of tests/pylib/kmdaemon.py (the
daemon, its stderr, sanitizer reports, memory and descriptors, HTTP on
fresh or raw connections) plus what only they need: requests sent
exactly as given, raw requests whose answer is read even when the server
closes early, problem checks, and the result lines summarise.sh totals.

Standard library only; every wait is bounded.
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "pylib"))
import kmdaemon  # noqa: E402
from kmdaemon import (DAEMON, HOST, ROOT, Daemon,  # noqa: E402,F401
                      Reply, raw_exchange)

RESULTS = os.environ.get("KM_RESULTS",
                         os.path.join(ROOT, "build", "test-results.txt"))


def request(port, method, path, body=None, headers=None, timeout=30.0):
    """One request on a fresh connection with no Content-Type added: the
    barrage sends some bodies without one on purpose."""
    return kmdaemon.request(port, method, path, body, headers, timeout,
                            content_type=None)


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
    data = raw_exchange(port, head.encode() + (body or b""), timeout)
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
