"""barrage.py - thousands of generated malformed requests against a live
kmorphd: every answer must be a 4xx application/problem+json whose status
matches its body (and the expected status where the fault fixes it), none
a 5xx, none slower than the hang limit; afterwards /healthz answers, the
daemon still serves a valid request, and its resident memory and open
file descriptors are back near where they started.

    python3 tests/hardening/barrage.py [--daemon build/kmorphd]
        [--asan] [--count N] [--name NAME]

--asan: the daemon is a sanitizer build; its reports are collected and
must be empty, and it must exit 0 on SIGTERM (LeakSanitizer runs then).
Appends "hardening/<name> passed failed" to build/test-results.txt.
"""
import argparse
import copy
import json
import math
import os
import random
import sys
import time
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(__file__))
import hlib  # noqa: E402
import kmreq  # noqa: E402

HANG_SECONDS = 10.0

ROUTES = {"signature": "/v1/signature", "reconstruct": "/v1/reconstruct",
          "morph": "/v1/morph"}

# Fields that must be present (object kind -> keys); removing one must be
# refused. The kind of an object is told by where it sits.
REQUIRED = {
    "signature": ["curve"], "reconstruct": ["signature"],
    "morph": ["from", "to"],
    "bspline": ["degree", "knots", "control_points"], "svg": ["d"],
    "points": ["points"], "sigcurve": ["signature"],
    "sig": ["length", "kappa"], "kappa": ["knots", "coefficients"],
}

# Output fields a request may carry without effect (a signature copied
# from a response), and optional fields where null reads as absent.
OUTPUT_ONLY = {"turning"}
NULL_MEANS_ABSENT = {"weights"}

OTHER_TYPES = {
    "number": ["x", True, None, {}, [], [1]],
    "string": [1, True, None, {}, [], ["a"]],
    "bool": [1, "true", None, {}, []],
    "array": [{}, "a", 1, True, None],
    "object": [[], "a", 1, True, None],
    "null": [],
}


def strict_json(data):
    """True if data is one RFC 8259 JSON text (no NaN/Infinity)."""
    def no_constants(c):
        raise ValueError(c)
    try:
        json.loads(data.decode("utf-8"), parse_constant=no_constants)
        return True
    except (ValueError, UnicodeDecodeError):
        return False


def kind_of(v):
    if isinstance(v, bool):
        return "bool"
    if isinstance(v, (int, float)):
        return "number"
    if isinstance(v, str):
        return "string"
    if isinstance(v, list):
        return "array"
    if isinstance(v, dict):
        return "object"
    return "null"


def paths(doc, prefix=()):
    """Every (path, value) in doc, depth first; arrays only to 2 items."""
    yield prefix, doc
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from paths(v, prefix + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc[:2]):
            yield from paths(v, prefix + (i,))


def set_at(doc, path, value):
    d = copy.deepcopy(doc)
    node = d
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value
    return d


def del_at(doc, path):
    d = copy.deepcopy(doc)
    node = d
    for p in path[:-1]:
        node = node[p]
    del node[path[-1]]
    return d


def object_kind(route, path, obj):
    """Which REQUIRED set applies to the object at path."""
    if path == ():
        return route
    if isinstance(obj, dict) and "type" in obj and obj["type"] in (
            "bspline", "svg", "points"):
        return obj["type"]
    if isinstance(obj, dict) and obj.get("type") == "signature":
        return "sigcurve"
    if path[-1] == "signature":
        return "sig"
    if path[-1] == "kappa":
        return "kappa"
    return None


class Gen:
    """Builds the barrage: (category, method, path, headers, body bytes,
    expected statuses or None for any 4xx)."""

    def __init__(self, seed):
        self.rnd = random.Random(seed)
        self.out = []
        self.base = [(r, n, b) for r, n, b in kmreq.valid_requests()
                     if len(kmreq.compact(b)) < 4000]

    def add(self, cat, route_or_path, body, expect=None, method="POST",
            ctype="application/json", headers=None):
        path = ROUTES.get(route_or_path, route_or_path)
        h = {}
        if ctype is not None:
            h["Content-Type"] = ctype
        h.update(headers or {})
        if body is not None and not isinstance(body, bytes):
            body = json.dumps(body, allow_nan=True).encode()
        self.out.append((cat, method, path, h, body, expect))

    def truncated(self, n):
        for _ in range(n):
            r, _, b = self.rnd.choice(self.base)
            data = kmreq.compact(b)
            cut = self.rnd.randrange(0, len(data) - 1)
            self.add("truncated-json", r, data[:cut], (400,))

    def invalid_json(self, n):
        breakers = [
            lambda s: s.replace(b":", b";", 1),
            lambda s: s.replace(b",", b",,", 1),
            lambda s: s[:-1] + b",}",
            lambda s: s + b"garbage",
            lambda s: s.replace(b'"', b"'", 2),
            lambda s: s.replace(b"{", b"{x", 1),
            lambda s: b"[" + s,
            lambda s: s.replace(b"[", b"[,", 1),
            lambda s: s.replace(b'":', b'"\x01:', 1),
            lambda s: s.replace(b'"', b'"\n', 1),
            lambda s: s.replace(b":", b"::", 1),
            lambda s: s.replace(b"]", b"]]", 1) if b"]" in s else s + b"]",
            lambda s: s + b"}",
            lambda s: s.replace(b"true", b"True") if b"true" in s
            else s.replace(b"{", b"{{", 1),
        ]
        fixed = [b"", b" ", b"{", b"}", b"[]x", b"nul", b"\"", b"{\"a\"}",
                 b"{\"a\":}", b"{,}", b"01", b"-", b"1.", b".5", b"+1",
                 b"0x10", b"{\"a\":1,}", b"\x00{}", b"{\"a\":1}{}"]
        for s in fixed:
            for r in ROUTES:
                self.add("invalid-json", r, s, (400,))
        made = 0
        while made < n:
            r, _, b = self.rnd.choice(self.base)
            f = self.rnd.choice(breakers)
            data = f(kmreq.compact(b))
            if strict_json(data):
                continue  # the change left it valid: not a bad request
            self.add("invalid-json", r, data, (400,))
            made += 1

    def wrong_types(self, limit):
        cands = []
        for r, _, b in self.base:
            for p, v in paths(b):
                if p == () or p[-1] in OUTPUT_ONLY:
                    continue
                for alt in OTHER_TYPES[kind_of(v)]:
                    if alt is None and p[-1] in NULL_MEANS_ABSENT:
                        continue
                    cands.append((r, set_at(b, p, alt), p))
        self.rnd.shuffle(cands)
        for r, body, p in cands[:limit]:
            self.add("wrong-type " + "/".join(map(str, p)), r, body,
                     (400, 422))

    def missing(self, limit):
        cands = []
        for r, _, b in self.base:
            for p, v in paths(b):
                if isinstance(v, dict):
                    kind = object_kind(r, p, v)
                    for k in REQUIRED.get(kind, []):
                        if k in v:
                            cands.append((r, del_at(b, p + (k,))))
        self.rnd.shuffle(cands)
        for r, body in cands[:limit]:
            self.add("missing-field", r, body, (400, 422))

    def nonfinite(self, limit):
        words = [b"NaN", b"Infinity", b"-Infinity", b"nan", b"inf", b"1e999",
                 b"-1e999", b"1e400"]
        cands = []
        for r, _, b in self.base:
            for p, v in paths(b):
                if kind_of(v) == "number" and not (
                        isinstance(p[-1], str) and p[-1] in OUTPUT_ONLY):
                    marker = "@@NUM@@"
                    data = kmreq.compact(set_at(b, p, marker))
                    for w in words:
                        cands.append((r, data.replace(b'"@@NUM@@"', w)))
        self.rnd.shuffle(cands)
        for r, body in cands[:limit]:
            self.add("nan-infinity", r, body, (400, 422))

    def at_limits(self):
        # control points just above the limit, a 10^6-element array (about
        # 6 MB, under the body limit), and bodies over the 8 MiB limit
        n = 100001
        pts = ",".join("[%d,%d]" % (i % 97, i % 89) for i in range(n))
        knots = ",".join(["0"] * 4 + [str(i) for i in range(1, n - 3)] +
                         [str(n - 3)] * 4)
        self.add("array-limit", "signature", (
            '{"curve":{"type":"bspline","degree":3,"knots":[%s],'
            '"control_points":[%s]}}' % (knots, pts)).encode(), (422,))
        big = ",".join(["[0,1]"] * 1000000)
        self.add("array-limit", "signature", (
            '{"curve":{"type":"points","points":[%s]}}' % big).encode(),
            (413, 422))
        self.add("array-limit", "morph", (
            '{"from":{"type":"points","points":[[0,0],[1,1]]},'
            '"to":{"type":"points","points":[[0,0],[1,1]]},"times":[%s]}'
            % ",".join(["0.5"] * 1000000)).encode(), (413, 422))
        self.add("array-limit", "signature", (
            '{"curve":{"type":"svg","d":"M 0 0 %s"},"samples":100001}'
            % ("L 1 1 L 0 0 " * 10)).encode(), (422,))
        self.add("too-large", "signature",
                 b'{"curve":{"type":"points","points":[' +
                 b"[0,0]," * (9 * 1024 * 1024 // 6) + b"[1,1]]}}", (413,),
                 headers={"X-Raw": "1"})

    def deep(self):
        for depth in (65, 100, 1000, 100000):
            self.add("deep-nesting", "signature", b"[" * depth + b"]" * depth,
                     (400,))
            self.add("deep-nesting", "morph",
                     b'{"a":' * depth + b"1" + b"}" * depth, (400,))
            self.add("deep-nesting", "reconstruct", b"[" * depth, (400,))
        for r in ROUTES:
            self.add("deep-nesting", r, b'{"curve":' + b"[" * 70 +
                     b"]" * 70 + b"}", (400,))

    def bad_utf8(self, n):
        bad = [b"\xff", b"\xc0\xaf", b"\xed\xa0\x80", b"\xe2\x82",
               b"\xf8\x88\x80\x80\x80", b"\x80", b"\xf4\x90\x80\x80",
               b"\\ud800", b"\\udc00x", b"\\u0000", b"\\uZZZZ", b"\\q"]
        for i in range(n):
            r, _, b = self.rnd.choice(self.base)
            data = kmreq.compact(b)
            quotes = [k for k in range(len(data)) if data[k:k + 1] == b'"']
            q = self.rnd.choice(quotes[::2]) + 1
            seq = bad[i % len(bad)]
            expect = (400, 422) if seq.startswith(b"\\u0000") or \
                seq.startswith(b"\\ud") else (400,)
            self.add("invalid-utf8", r, data[:q] + seq + data[q:], expect)

    def content_types(self):
        cts = ["text/plain", "application/xml", "multipart/form-data",
               "application/x-www-form-urlencoded", "image/svg+xml",
               "application/jsonx", "json",
               "text/json", "application/octet-stream"]
        for r, _, b in self.base[:12]:
            for ct in cts:
                self.add("content-type", r, b, (415,), ctype=ct)

    def routes_methods(self):
        body = kmreq.compact(self.base[0][2])
        for m in ("GET", "PUT", "PATCH", "DELETE"):
            for r in ROUTES:
                self.add("method", r, body if m != "GET" else None, (405,),
                         method=m)
        for m in ("PUT", "PATCH", "POST"):
            self.add("method", "/healthz", None, (405,), method=m)
            self.add("method", "/metrics", b"{}", (405,), method=m)
        for p in ("/v1/unknown", "/v2/signature", "/v1/signature/x",
                  "/v1//signature", "/V1/SIGNATURE", "/v1/jobs/nope",
                  "/v1/jobs/nope/result", "/v1/jobs/../../../etc/passwd",
                  "/v1/jobs/" + "9" * 300, "/v1/" + "a" * 2000,
                  "/v1/signature%2F", "/.env", "/v1/jobs/%ff%fe"):
            self.add("route", p, body, (404, 405), method="POST")
            self.add("route", p, None, (404, 405), method="GET")

    def bad_svg(self):
        ds = ["", "M", "L 1 1", "M 0 0", "M 0 0 Z", "M 0 0 L", "M 0 0 X 1 1",
              "M 1e999 0 L 1 1", "M 0 0 L 1.2.3 4", "M 0 0 L 1 1 M 2 2 L 3 3",
              "M 0 0 L 0 0", "M 0 0 A 0 0 0 0 0 0 0", "M 0 0 C 1 1 2 2",
              "M 0 0 L nan 1", "M 0 0 L 1e16 0", "M0,0L1,1,", "m 0 0 l",
              "M 0 0 A 1 1 0 2 0 1 1", "M 0 0 Q 1 1", "M 0 0 T", "Z",
              "M 0 0 L 1 0 L 0 0", "M 0 0 " + "L 1 1 " * 5 + "@",
              "\x01", "M 0 0 H", "M 0 0 V x",
              "M 0 0 L 1 0 z M 0 0"]
        for d in ds:
            self.add("invalid-svg", "signature",
                     {"curve": {"type": "svg", "d": d}}, (422,))
            self.add("invalid-svg", "morph",
                     {"from": {"type": "svg", "d": d},
                      "to": kmreq.circle_svg(1.0), "frames": 2}, (422,))

    def geometry(self):
        cusps = [
            {"type": "svg", "d": "M 0 0 L 1 0 L 0 0"},
            {"type": "svg", "d": "M 0 0 L 2 0 L 1 0"},
            {"type": "svg", "d": "M 0 0 C 2 0 -1 0 1 0"},
            {"type": "svg", "d": "M 0 0 C 1 1 1 1 0 0 L 5 5"},
            {"type": "bspline", "degree": 1, "knots": [0, 0, 1, 2, 2],
             "control_points": [[0, 0], [1, 0], [0, 0]]},
            {"type": "bspline", "degree": 3,
             "knots": [0, 0, 0, 0, 1, 1, 1, 1],
             "control_points": [[0, 0], [3, 0], [-2, 0], [1, 0]]},
            {"type": "bspline", "degree": 2, "knots": [0, 0, 0, 1, 1, 1],
             "control_points": [[0, 0], [0, 0], [0, 0]]},
            {"type": "points", "points": [[0, 0], [0, 0]]},
            {"type": "svg", "d": "M 5 5 L 5 5 L 5 5"},
        ]
        for c in cusps:
            self.add("non-regular", "signature", {"curve": c}, (422,))
            self.add("non-regular", "morph",
                     {"from": c, "to": kmreq.cubic_bspline(), "frames": 2},
                     (422,))
        circle = kmreq.circle_svg(1.0)
        double = {"type": "svg", "d": "M 1 0 A 1 1 0 1 1 -1 0 A 1 1 0 1 1 1 0"
                  " A 1 1 0 1 1 -1 0 A 1 1 0 1 1 1 0 Z"}
        eight = {"type": "points", "closed": True,
                 "points": [[0, 0], [1, 1], [2, 0], [1, -1], [0, 0],
                            [-1, 1], [-2, 0], [-1, -1]]}
        eight_svg = {"type": "svg", "d": "M 0 0 C 1 1 2 1 2 0 C 2 -1 1 -1 0 0"
                     " C -1 1 -2 1 -2 0 C -2 -1 -1 -1 0 0 Z"}
        open_arc = {"type": "svg", "d": "M 1 0 A 1 1 0 0 1 -1 0"}
        pairs = [(circle, double), (circle, eight), (circle, eight_svg),
                 (double, eight), (circle, open_arc), (open_arc, circle),
                 (kmreq.square_svg(2), double)]
        for a, b in pairs:
            for extra in ({}, {"orient": "keep"}, {"method": "linear"},
                          {"closure": "g2"}, {"matches": "auto"}):
                body = {"from": a, "to": b, "frames": 3}
                body.update(extra)
                expect = (422,)
                if extra.get("method") == "linear" and a is not open_arc \
                        and b is not open_arc:
                    continue  # the linear baseline morphs any closed pair
                self.add("turning-number", "morph", body, expect)
                self.add("turning-number", "/v1/jobs", body, expect)

    def field_values(self):
        m = {"from": kmreq.circle_svg(1.0), "to": kmreq.square_svg(2.0)}
        bad = [("frames", 0), ("frames", -1), ("frames", 1001),
               ("frames", 1.5), ("frames", 1e300), ("times", []),
               ("times", [-0.1]), ("times", [1.1]),
               ("method", "cubic"), ("blend", "x"), ("closure", "c3"),
               ("anchor", ""), ("orient", "up"), ("degree", 4),
               ("degree", 0), ("degree", 10), ("tolerance", -1),
               ("tolerance", 0), ("matches", [[0.5]]),
               ("matches", [[0.5, 0.2], [0.4, 0.6]]),
               ("matches", [[0, 0.5]]), ("matches", [[1.5, 0.5]]),
               ("matches", "manual"), ("include", ["nothing"]),
               ("format", "png"), ("svg", {"layout": "spiral"}),
               ("svg", {"width": -5}), ("svg", {"stroke": "<script>"}),
               ("metrics", "yes")]
        for k, v in bad:
            body = dict(m, frames=3)
            if k == "times":
                del body["frames"]
            body[k] = v
            self.add("bad-value", "morph", body, (400, 422))
            if (k, v) != ("frames", 1001):  # a job may have 10,000
                self.add("bad-value", "/v1/jobs", body, (400, 422))
        self.add("bad-value", "/v1/jobs", dict(m, frames=10001), (422,))
        sbad = [("samples", -1), ("samples", 100001), ("samples", 2.5),
                ("tolerance", -1e-3), ("tolerance", "1e-3")]
        for k, v in sbad:
            self.add("bad-value", "signature",
                     {"curve": kmreq.cubic_bspline(), k: v}, (400, 422))
        cb = kmreq.cubic_bspline()
        curves = [dict(cb, degree=0), dict(cb, degree=10),
                  dict(cb, knots=[0, 0, 0, 0, 0.7, 0.5, 1, 1, 1]),
                  dict(cb, knots=[0, 0, 0, 0.5, 1, 1, 1]),
                  dict(cb, knots=[0, 0, 0, 0, 0, 1, 1, 1, 1]),
                  dict(cb, knots=[1, 1, 1, 1, 1, 1, 1, 1, 1]),
                  dict(cb, weights=[1, 1, 0, 1, 1]),
                  dict(cb, weights=[1, 1, -1, 1, 1]), dict(cb, weights=[1]),
                  dict(cb, closed=True), dict(cb, control_points=[[0, 0]]),
                  dict(cb, control_points=[[0, 0, 0], [1, 2], [3, 3],
                                           [4, 1], [5, 0]]),
                  dict(cb, control_points=[[0, 0], [1, 2], [3, 3], [4, 1],
                                           [1e16, 0]]),
                  dict(cb, type="nurbs"),
                  {"type": "points", "points": [[0, 0]]},
                  {"type": "points", "points": [[0, 0], [1]]},
                  {"type": "signature", "signature": {"length": -1}}]
        for c in curves:
            self.add("invalid-curve", "signature", {"curve": c}, (422,))
        sig = kmreq.line_signature()
        sigs = [dict(sig, length=0), dict(sig, length=-2),
                dict(sig, kappa={"degree": 0, "knots": [0, 1],
                                 "coefficients": [0]}),
                dict(sig, kappa={"degree": 1, "knots": [0, 2],
                                 "coefficients": [0]}),
                dict(sig, kappa={"degree": 99, "knots": [0, 2],
                                 "coefficients": [0]}),
                dict(sig, corners=[{"s": 1, "turn": 4}]),
                dict(sig, corners=[{"s": 3, "turn": 1}]),
                dict(sig, corners=[{"s": 1.5, "turn": 1},
                                   {"s": 0.5, "turn": 1}]),
                dict(sig, start={"point": [0], "angle": 0}),
                dict(sig, start={"point": [0, 0], "angle": "north"})]
        for s in sigs:
            self.add("invalid-signature", "reconstruct", {"signature": s},
                     (422,))
            for deg in (4, 1):
                self.add("invalid-signature", "reconstruct",
                         {"signature": sig, "degree": deg}, (422,))

    def build(self, count):
        self.truncated(count // 6)
        self.invalid_json(count // 8)
        self.wrong_types(count // 4)
        self.missing(count // 12)
        self.nonfinite(count // 8)
        self.at_limits()
        self.deep()
        self.bad_utf8(count // 12)
        self.content_types()
        self.routes_methods()
        self.bad_svg()
        self.geometry()
        self.field_values()
        return self.out


def send(port, item):
    cat, method, path, headers, body, expect = item
    t0 = time.monotonic()
    try:
        if "X-Raw" in headers:
            # the daemon answers 413 from Content-Length and closes while
            # the body is still being sent: read the answer off the socket
            r = hlib.raw_request(port, method, path, headers, body,
                                 timeout=HANG_SECONDS * 3)
        else:
            r = hlib.request(port, method, path, body, headers,
                             timeout=HANG_SECONDS * 3)
    except Exception as e:  # noqa: BLE001 - every failure is reported
        return item, None, repr(e), time.monotonic() - t0
    dt = time.monotonic() - t0
    why = hlib.problem_ok(r)
    if not why and expect and r.status not in expect:
        why = "status %d, expected %s" % (r.status, expect)
    if not why and dt > HANG_SECONDS:
        why = "answered after %.1f s" % dt
    return item, r, why, dt


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--daemon", default=os.path.join(hlib.ROOT, "build",
                                                     "kmorphd"))
    ap.add_argument("--asan", action="store_true")
    ap.add_argument("--count", type=int, default=2400)
    ap.add_argument("--name", default="barrage")
    ap.add_argument("--workers", type=int, default=8)
    a = ap.parse_args()
    ck = hlib.Checks(a.name)
    items = Gen(20240611).build(a.count)
    d = hlib.Daemon("--threads", "2", "--queue", "256", "--access-log", "0",
                    exe=a.daemon, sanitized=a.asan)
    try:
        # warm up with valid requests so the baseline includes the pools,
        # then measure
        for r, _, b in kmreq.valid_requests()[:12]:
            d.request("POST", ROUTES[r], kmreq.compact(b),
                      {"Content-Type": "application/json"})
        rss0, fd0 = d.rss_kb(), d.fds()
        t0 = time.monotonic()
        with ThreadPoolExecutor(max_workers=a.workers) as ex:
            results = list(ex.map(lambda it: send(d.port, it), items))
        wall = time.monotonic() - t0
        bad = [(it, r, why) for it, r, why, dt in results if why]
        cats = {}
        for it, r, why, dt in results:
            c = cats.setdefault(it[0].split(" ")[0], [0, 0])
            c[0] += 1
            c[1] += bool(why)
        statuses = {}
        for it, r, why, dt in results:
            if r is not None:
                statuses[r.status] = statuses.get(r.status, 0) + 1
        slowest = max(dt for _, _, _, dt in results)
        print("barrage: %d requests in %.1f s, statuses %s, slowest %.2f s"
              % (len(items), wall, dict(sorted(statuses.items())), slowest))
        for c, (n, f) in sorted(cats.items()):
            print("  %-18s %5d sent %4d wrong" % (c, n, f))
        for it, r, why in bad[:25]:
            body = it[4] or b""
            print("  -> %s %s %s [%s] body %r: %s; answer %r" % (
                it[0], it[1], it[2], it[3].get("Content-Type"),
                body[:120], why, (r.body[:160] if r else None)))
        ck.check(len(items) >= 2000, "at least 2000 malformed requests "
                 "(%d)" % len(items))
        ck.check(not bad, "every answer a 4xx problem+json with the "
                 "expected status (%d of %d wrong)" % (len(bad), len(items)))
        ck.check(not any(r is not None and r.status >= 500
                         for _, r, _, _ in results),
                 "no 5xx answer")
        ck.check(slowest <= HANG_SECONDS, "no answer slower than %g s "
                 "(slowest %.2f s)" % (HANG_SECONDS, slowest))
        h = d.request("GET", "/healthz", timeout=10)
        ck.check(h.status == 200 and h.json().get("status") == "ok",
                 "/healthz answers ok afterwards")
        v = d.request("POST", "/v1/signature",
                      {"curve": kmreq.circle_svg(2.0)},
                      {"Content-Type": "application/json"})
        ck.check(v.status == 200 and math.isclose(
            v.json()["signature"]["length"], 4 * math.pi, rel_tol=1e-6),
            "a valid request is still answered correctly")
        time.sleep(0.5)
        rss1, fd1 = d.rss_kb(), d.fds()
        print("barrage: RSS %d kB before, %d kB after; fds %d before, %d "
              "after" % (rss0, rss1, fd0, fd1))
        if not a.asan:
            # glibc keeps some freed memory in its arenas; the 6-9 MB bodies
            # of the limit cases are what may stay cached.
            ck.check(rss1 <= rss0 + 64 * 1024,
                     "RSS back near its start (%d -> %d kB, bound +64 MiB)"
                     % (rss0, rss1))
        ck.check(fd1 <= fd0 + 2, "open file descriptors back to baseline "
                 "(%d -> %d)" % (fd0, fd1))
        rc, dt = d.terminate(timeout=60)
        ck.check(rc == 0, "SIGTERM afterwards: exit status 0 (%s, %.1f s)"
                 % (rc, dt))
        if a.asan:
            reps = d.reports()
            for name, text in reps:
                print("  sanitizer report %s:\n%s" % (name, text))
            ck.check(not reps, "no ASan/UBSan/LSan report from the daemon")
        with open(os.path.join(hlib.ROOT, "build", "hardening-summary.txt"),
                  "a") as f:
            f.write("%s: %d requests, %d wrong, %d 5xx, slowest %.2f s, "
                    "RSS %d -> %d kB, fds %d -> %d\n" % (
                        a.name, len(items), len(bad),
                        sum(1 for _, r, _, _ in results
                            if r is not None and r.status >= 500),
                        slowest, rss0, rss1, fd0, fd1))
    finally:
        d.close()
    return 0 if ck.record() else 1


if __name__ == "__main__":
    sys.exit(main())
