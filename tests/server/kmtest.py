"""kmtest.py - helpers of the kmorphd tests: the daemon, HTTP and shapes
of tests/pylib/kmdaemon.py (re-exported here), request bodies, jobs and
metrics, and checks of answers against api/openapi.yaml.

Only the standard library plus Debian's python3-yaml and
python3-jsonschema. Every wait is bounded in time.
"""
import math
import os
import sys
import unittest

import yaml
from jsonschema import Draft202012Validator, RefResolver

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "pylib"))
from kmdaemon import (DAEMON, HOST, ROOT, Daemon, Reply,  # noqa: E402,F401
                      circle_svg, open_arc, raw_exchange, raw_status,
                      request, square_svg, wait_for)

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


# ---------------------------------------------------------- request bodies

def morph_body(frames, **extra):
    body = {"from": circle_svg(1.0), "to": circle_svg(2.0), "frames": frames}
    body.update(extra)
    return body


def heavy_morph_body(frames):
    """A circle-to-square morph with metrics: every frame is a
    closed-curve problem, but a planned one of tens of microseconds; tests
    that need a computation still running take ring_morph_body."""
    return {"from": circle_svg(10.0), "to": square_svg(15.0),
            "frames": frames, "metrics": True}


def ring_morph_body(frames):
    """A morph whose every frame is a compound shape (a ring of circles to
    a ring of squares) at a tolerance a thousand times finer than the
    default: some 7 ms a frame (12 ms under ASan) and 27 kB of answer, for
    tests that need a computation still running, where a single curve's
    frames are tens of microseconds. Its size makes the work, not the path
    a frame takes: at the default tolerance the frames of this ring fell
    from 8 ms to under 2 ms when compound frames got their band index.
    Prepared in about 0.06 s (0.15 s under ASan)."""
    def circle(r):
        return "M %g 0 A %g %g 0 1 1 %g 0 A %g %g 0 1 1 %g 0 Z" % (
            r, r, r, -r, r, r, r)

    def square(h):
        return "M %g %g L %g %g L %g %g L %g %g Z" % (
            -h, -h, h, -h, h, h, -h, h)
    return {"from": {"type": "svg", "d": circle(10.0) + " " + circle(5.0)},
            "to": {"type": "svg", "d": square(15.0) + " " + square(7.0)},
            "frames": frames, "metrics": True, "tolerance": 1e-6}


# ------------------------------------------------------------ jobs, metrics

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


class DaemonCase(ContractCase):
    """A contract case with one kmorphd (two compute threads) shared by
    the class's tests, as d."""

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "2")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()


def close_to(a, b, rel):
    return math.isclose(a, b, rel_tol=rel, abs_tol=rel)
