"""kmtest.py - shared helpers of the kmorphd tests: start the daemon on a
free loopback port, talk HTTP to it, and check answers against
api/openapi.yaml.

Only the standard library plus Debian's python3-yaml and
python3-jsonschema. Every wait is bounded in time.
"""
import http.client
import json
import math
import os
import signal
import socket
import subprocess
import tempfile
import time
import unittest

import yaml
from jsonschema import Draft202012Validator, RefResolver

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
DAEMON = os.environ.get("KMORPHD", os.path.join(ROOT, "build", "kmorphd"))
HOST = "127.0.0.1"

with open(os.path.join(ROOT, "api", "openapi.yaml"), encoding="utf-8") as _f:
    SPEC = yaml.safe_load(_f)
_RESOLVER = RefResolver("", SPEC)


def deref(node):
    """Follow a local $ref ("#/components/...") to its target."""
    while isinstance(node, dict) and "$ref" in node:
        target = SPEC
        for part in node["$ref"].lstrip("#/").split("/"):
            target = target[part.replace("~1", "/").replace("~0", "~")]
        node = target
    return node


def schema_errors(instance, schema):
    """Messages of every way instance fails schema (empty if valid)."""
    v = Draft202012Validator(schema, resolver=_RESOLVER)
    return ["%s at /%s" % (e.message, "/".join(str(p) for p in e.path))
            for e in v.iter_errors(instance)]


def component(name):
    return SPEC["components"]["schemas"][name]


# ---------------------------------------------------------------- curves

def circle_svg(r, cx=0.0, cy=0.0):
    """A circle of radius r as two SVG arcs, starting at (cx + r, cy)."""
    return {"type": "svg",
            "d": "M %r %r A %r %r 0 1 1 %r %r A %r %r 0 1 1 %r %r Z" % (
                cx + r, cy, r, r, cx - r, cy, r, r, cx + r, cy)}


def square_svg(side):
    return {"type": "svg",
            "d": "M 0 0 L %r 0 L %r %r L 0 %r Z" % (side, side, side, side)}


def open_arc(r):
    """A half circle of radius r (open)."""
    return {"type": "svg", "d": "M %r 0 A %r %r 0 0 1 %r 0" % (r, r, r, -r)}


def morph_body(frames, **extra):
    body = {"from": circle_svg(1.0), "to": circle_svg(2.0), "frames": frames}
    body.update(extra)
    return body


def heavy_morph_body(frames):
    """A morph that keeps a worker busy for a while: every frame of a
    circle-to-square morph is a closed-curve problem."""
    return {"from": circle_svg(10.0), "to": square_svg(15.0),
            "frames": frames, "metrics": True}


# ------------------------------------------------------------------ HTTP

class Reply:
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


def request(port, method, path, body=None, headers=None, timeout=30.0):
    """One request on a fresh connection; returns a Reply."""
    hdrs = dict(headers or {})
    data = None
    if body is not None:
        data = body if isinstance(body, bytes) else json.dumps(body).encode()
        hdrs.setdefault("Content-Type", "application/json")
    conn = http.client.HTTPConnection(HOST, port, timeout=timeout)
    try:
        conn.request(method, path, body=data, headers=hdrs)
        r = conn.getresponse()
        return Reply(r.status, r.getheaders(), r.read())
    finally:
        conn.close()


# ---------------------------------------------------------------- daemon

class Daemon:
    """A kmorphd process on a port the OS chose (--port 0)."""

    def __init__(self, *flags, env=None):
        self.log = tempfile.NamedTemporaryFile(
            prefix="kmorphd-", suffix=".log", delete=False)
        e = dict(os.environ)
        for k in list(e):
            if k.startswith("KMORPH_"):
                del e[k]
        e.update(env or {})
        self.proc = subprocess.Popen(
            [DAEMON, "--bind", HOST, "--port", "0", *flags],
            stdout=subprocess.DEVNULL, stderr=self.log, env=e)
        self.port = None
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and self.port is None:
            if self.proc.poll() is not None:
                raise RuntimeError("kmorphd exited: " + self.text())
            for line in self.text().splitlines():
                if "listening on http://" in line:
                    self.port = int(line.split("http://", 1)[1]
                                    .split(" ", 1)[0].rsplit(":", 1)[1])
            time.sleep(0.02)
        if self.port is None:
            self.stop()
            raise RuntimeError("kmorphd did not start: " + self.text())

    def text(self):
        with open(self.log.name, encoding="utf-8", errors="replace") as f:
            return f.read()

    def request(self, method, path, body=None, headers=None, timeout=30.0):
        return request(self.port, method, path, body, headers, timeout)

    def terminate(self, timeout=20.0):
        """SIGTERM; returns (exit status, seconds to exit)."""
        t0 = time.monotonic()
        self.proc.send_signal(signal.SIGTERM)
        rc = self.proc.wait(timeout=timeout)
        return rc, time.monotonic() - t0

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=5)
        self.log.close()
        try:
            os.unlink(self.log.name)
        except OSError:
            pass


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


def run_job(daemon, body, timeout=15):
    """POST body to /v1/jobs (asserting 202 is the caller's: the reply is
    returned) and wait until the job is done or failed: (reply, id, last
    status document, or None if it did not end in time)."""
    r = daemon.request("POST", "/v1/jobs", body=body)
    if r.status != 202:
        return r, None, None
    jid = r.json()["id"]

    def final():
        s = daemon.request("GET", "/v1/jobs/" + jid).json()
        return s if s["state"] in ("done", "failed") else None
    return r, jid, wait_for(final, timeout)


def metric(text, name, labels=None):
    """The value of one sample in Prometheus text, or None."""
    want = name
    if labels:
        want += "{" + ",".join('%s="%s"' % kv for kv in labels.items()) + "}"
    for line in text.splitlines():
        if line.startswith(want + " "):
            return float(line.rsplit(" ", 1)[1])
    return None


class ContractCase(unittest.TestCase):
    """Assertions that an answer is what api/openapi.yaml promises."""

    def assertDocumented(self, reply, path, method):
        ops = SPEC["paths"][path]
        self.assertIn(method.lower(), ops, "%s %s not in the contract" %
                      (method, path))
        op = ops[method.lower()]
        st = str(reply.status)
        self.assertIn(st, op["responses"],
                      "%s %s answered %s, which the contract does not list"
                      % (method, path, st))
        resp = deref(op["responses"][st])
        self.assertTrue(reply.header("X-Request-Id"),
                        "every answer carries X-Request-Id")
        for h in resp.get("headers", {}):
            self.assertTrue(reply.header(h), "%s %s %s lacks header %s" %
                            (method, path, st, h))
        content = resp.get("content")
        if not content:
            self.assertEqual(reply.body, b"")
            return None
        self.assertIn(reply.ctype, content, "%s %s %s: content type %r" %
                      (method, path, st, reply.ctype))
        schema = content[reply.ctype].get("schema", {})
        if reply.ctype.endswith("json"):
            doc = reply.json()
            errs = schema_errors(doc, schema)
            self.assertEqual(errs, [], "%s %s %s: body does not match "
                             "its schema" % (method, path, st))
            if reply.status >= 400:
                self.assertEqual(doc["status"], reply.status)
            return doc
        return reply.body

    def assertResponse(self, reply, name):
        """reply matches components/responses/<name> (for answers that no
        single operation lists, e.g. 405 for a method the path lacks)."""
        resp = SPEC["components"]["responses"][name]
        self.assertTrue(reply.header("X-Request-Id"))
        for h in resp.get("headers", {}):
            self.assertTrue(reply.header(h), "%s lacks header %s" % (name, h))
        content = resp["content"]
        self.assertIn(reply.ctype, content)
        doc = reply.json()
        self.assertEqual(schema_errors(doc, content[reply.ctype]["schema"]),
                         [])
        self.assertEqual(doc["status"], reply.status)
        return doc

    def assertProblem(self, reply, status, path, method, rid=None):
        self.assertEqual(reply.status, status, reply.body[:300])
        self.assertEqual(reply.ctype, "application/problem+json")
        doc = self.assertDocumented(reply, path, method)
        if rid is not None:
            self.assertEqual(reply.header("X-Request-Id"), rid)
            self.assertEqual(doc.get("request_id"), rid)
        return doc


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
            except (socket.timeout, OSError):
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


def close_to(a, b, rel):
    return math.isclose(a, b, rel_tol=rel, abs_tol=rel)
