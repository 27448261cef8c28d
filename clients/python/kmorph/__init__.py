"""kmorph - client for the kmorph HTTP service (standard library only).

    from kmorph import Client
    km = Client("http://127.0.0.1:8080")        # or $KMORPH_URL
    sig = km.signature({"type": "svg", "d": "M 0 0 L 10 0 L 10 10 Z"})
    res = km.morph_job(request, on_progress=lambda s: print(s["progress"]))
    paths = frame_paths(res)                     # one SVG d string per frame
    at = interpolator(res); at(0.5)              # d string at any t

Compound shapes (glyphs with holes, icons of several parts) go in as an
SVG path with several subpaths or as ``shape([...contours])``; their
frames carry one contour per slot of ``result["contour_matches_used"]``
(None where a contour has shrunk to a point), and the helpers that read
frames (frame_path(s), frame_contours, interpolator, bounds) take both
kinds of result:

    ring = "M 90 50 A 40 40 0 1 1 10 50 A 40 40 0 1 1 90 50 Z " \
           "M 70 50 A 20 20 0 1 0 30 50 A 20 20 0 1 0 70 50 Z"
    disc = "M 90 50 A 40 40 0 1 1 10 50 A 40 40 0 1 1 90 50 Z"
    res = km.morph(morph_request(ring, disc, frames=30))
    res["contour_matches_used"]                 # [[0, 0], [1, None]]: the hole vanishes
    frame_contour_paths(res["frames"][-1])      # ["M...Z", None]

Every error answered by the service raises KmorphError carrying the
problem+json body (``.problem``, ``.status``, ``.errors`` with JSON
pointers). Network failures raise KmorphError with status 0. A job that
is cancelled through ``cancel`` (a threading.Event) raises JobCancelled
after the job was cancelled on the service too.

Also a command line: ``python3 -m kmorph --help``.
"""
from __future__ import annotations

import bisect
import dataclasses
import json
import math
import os
import re
import time
import urllib.error
import urllib.parse
import urllib.request
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

__version__ = "1.0.0"

JSON = Dict[str, Any]
Point = Tuple[float, float]

__all__ = [
    "__version__",
    "Client", "KmorphError", "JobCancelled", "ContourError", "DEFAULT_URL",
    "curve", "shape", "path_contours", "morph_request",
    "eval_curve", "curve_to_path", "sample_points", "frame_paths",
    "is_compound", "contour_pairs", "frame_contours", "frame_contour_paths",
    "frame_path", "interpolator", "bounds",
]

DEFAULT_URL = "http://127.0.0.1:8080"


class KmorphError(Exception):
    """A problem answered by the service (RFC 9457), or a transport
    failure described the same way (status 0)."""

    def __init__(self, problem, retry_after=None):
        self.problem = problem if isinstance(problem, dict) else {}
        p = self.problem
        self.status = p.get("status", 0) if isinstance(p.get("status"), int) else 0
        self.type = p.get("type", "about:blank")
        self.title = p.get("title", "")
        self.detail = p.get("detail", "")
        self.errors = p.get("errors") if isinstance(p.get("errors"), list) else []
        self.request_id = p.get("request_id")
        self.retry_after = retry_after
        super().__init__(self.detail or self.title or "kmorph request failed")

    def message_for(self, pointer: str) -> Optional[str]:
        """The message of the first error at `pointer` or below it, or None."""
        for e in self.errors:
            ptr = e.get("pointer", "")
            if ptr == pointer or ptr.startswith(pointer + "/"):
                return e.get("message")
        return None

    def contour_errors(self) -> List["ContourError"]:
        """The errors that name one contour of a compound shape, as
        ContourError: from a pointer /from/contours/K/..., or from an SVG
        `d` whose subpath K is at fault (with its character offset)."""
        out = []
        for e in self.errors:
            ptr, msg = e.get("pointer", "") or "", e.get("message", "") or ""
            at = re.search(r"\boffset (\d+)", msg)
            offset = int(at.group(1)) if at else None
            m = re.match(r"^/(from|to|curve)/contours/(\d+)(?:/|$)", ptr)
            if m:
                out.append(ContourError(m.group(1), int(m.group(2)), offset, ptr, msg))
                continue
            m = re.match(r"^/(from|to|curve)/d$", ptr)
            sub = re.search(r"\bsubpath (\d+)", msg)
            if m and sub:
                out.append(ContourError(m.group(1), int(sub.group(1)), offset, ptr, msg))
        return out

    def __str__(self):
        head = "%s %s" % (self.status, self.title) if self.status else self.title
        return "%s: %s" % (head, self.detail) if self.detail else head


@dataclasses.dataclass(frozen=True)
class ContourError:
    """One error about one contour: side "from", "to" or "curve"; contour,
    its index in the shape's contours (or the subpath's in an SVG d);
    offset, the character offset in that d when the service gave one."""
    side: str
    contour: int
    offset: object
    pointer: str
    message: str


class JobCancelled(KmorphError):
    """The job was cancelled (by the caller through `cancel`, or by
    someone else on the service)."""


class Client:
    """A connection to one kmorphd at `base_url` (default: $KMORPH_URL or
    http://127.0.0.1:8080). `timeout` bounds every request in seconds."""

    def __init__(self, base_url=None, timeout=60.0, poll_interval=0.05,
                 max_poll_interval=0.5):
        url = base_url or os.environ.get("KMORPH_URL") or DEFAULT_URL
        self.base_url = url.rstrip("/")
        self.timeout = timeout
        self.poll_interval = poll_interval
        self.max_poll_interval = max_poll_interval

    # ----------------------------------------------------------- HTTP

    def request(self, method: str, path: str, body: Any = None, accept: Optional[str] = None) -> Any:
        """One exchange; returns (status, headers, parsed body) where the
        body is a dict/list for JSON answers, str for others, None for
        204. Raises KmorphError for status >= 400 and network errors."""
        data = None
        headers = {"Accept": accept or "application/json, application/problem+json"}
        if body is not None:
            data = body.encode() if isinstance(body, str) else json.dumps(body).encode()
            headers["Content-Type"] = "application/json"
        req = urllib.request.Request(self.base_url + path, data=data,
                                     headers=headers, method=method)
        try:
            with urllib.request.urlopen(req, timeout=self.timeout) as r:
                return r.status, dict(r.headers), _parse(r.headers, r.read())
        except urllib.error.HTTPError as e:
            parsed = _parse(e.headers, e.read())
            if not isinstance(parsed, dict):
                parsed = {"type": "about:blank", "title": e.reason or "HTTP error",
                          "status": e.code, "detail": (parsed or "")[:500]}
            ra = e.headers.get("Retry-After") if e.headers else None
            raise KmorphError(parsed, float(ra) if ra else None) from None
        except (urllib.error.URLError, OSError) as e:
            reason = getattr(e, "reason", e)
            raise KmorphError({"type": "/problems/network", "title": "Network error",
                               "status": 0,
                               "detail": "cannot reach %s: %s" % (self.base_url, reason)}) from None

    # ------------------------------------------------------ endpoints

    def signature(self, curve: JSON, tolerance: Optional[float] = None, samples: Optional[int] = None) -> JSON:
        """POST /v1/signature: {"signature": ..., "samples"?: [[s, kappa]]}."""
        req = {"curve": curve}
        if tolerance is not None:
            req["tolerance"] = tolerance
        if samples is not None:
            req["samples"] = samples
        return self.request("POST", "/v1/signature", req)[2]

    def reconstruct(self, signature: JSON, tolerance: Optional[float] = None, degree: Optional[int] = None,
                    include: Optional[Sequence[str]] = None) -> JSON:
        """POST /v1/reconstruct: {"curve": ..., "error_bound": e}."""
        req = {"signature": signature}
        if tolerance is not None:
            req["tolerance"] = tolerance
        if degree is not None:
            req["degree"] = degree
        if include is not None:
            req["include"] = list(include)
        return self.request("POST", "/v1/reconstruct", req)[2]

    def morph(self, request: JSON) -> Union[JSON, str]:
        """POST /v1/morph: the morph result (a dict), or SVG text when
        request["format"] is "svg"."""
        accept = "image/svg+xml, application/problem+json" if request.get("format") == "svg" else None
        return self.request("POST", "/v1/morph", request, accept)[2]

    def submit_job(self, request: JSON) -> JSON:
        """POST /v1/jobs: the job status, with "location" from the header."""
        _, headers, body = self.request("POST", "/v1/jobs", request)
        body["location"] = _header(headers, "Location") or body["links"]["self"]
        return body

    def job(self, job_id: str) -> JSON:
        """GET /v1/jobs/{id}: state, progress, frames_done, frames_total."""
        return self.request("GET", "/v1/jobs/" + urllib.parse.quote(job_id))[2]

    def job_result(self, job_id: str) -> Union[JSON, str]:
        """GET /v1/jobs/{id}/result: the result of a done job."""
        return self.request("GET", "/v1/jobs/%s/result" % urllib.parse.quote(job_id),
                            accept="application/json, image/svg+xml, application/problem+json")[2]

    def cancel_job(self, job_id: str) -> None:
        """DELETE /v1/jobs/{id}: cancel a live job, forget a finished one."""
        self.request("DELETE", "/v1/jobs/" + urllib.parse.quote(job_id))

    def morph_job(self, request: JSON, on_progress: Optional[Callable[[JSON], None]] = None,
                  cancel: Any = None, timeout: Optional[float] = None) -> Union[JSON, str]:
        """Submit, poll (calling on_progress(status) with each status),
        fetch the result. `cancel` is a threading.Event (or anything with
        is_set()): once set, the job is cancelled on the service and
        JobCancelled is raised; so it is on KeyboardInterrupt (re-raised)
        and after `timeout` seconds (raising JobCancelled)."""
        status = self.submit_job(request)
        job_id = status["id"]
        delay = self.poll_interval
        deadline = None if timeout is None else time.monotonic() + timeout
        try:
            if on_progress:
                on_progress(status)
            while True:
                state = status["state"]
                if state == "done":
                    return self.job_result(job_id)
                if state == "failed":
                    err = status.get("error") or {}
                    raise KmorphError({"type": "/problems/job-failed", "title": "Job failed",
                                       "status": err.get("status", 500),
                                       "detail": err.get("detail", "the job failed"), "job": status})
                if state == "cancelled":
                    raise JobCancelled({"type": "/problems/job-cancelled", "title": "Job cancelled",
                                        "status": 409, "detail": "the job was cancelled",
                                        "job": status})
                if cancel is not None and _wait(cancel, delay):
                    self._cancel_quietly(job_id)
                    raise JobCancelled({"type": "/problems/job-cancelled", "title": "Job cancelled",
                                        "status": 409, "detail": "cancelled by the caller",
                                        "job": status})
                if cancel is None:
                    time.sleep(delay)
                if deadline is not None and time.monotonic() > deadline:
                    self._cancel_quietly(job_id)
                    raise JobCancelled({"type": "/problems/job-cancelled", "title": "Job cancelled",
                                        "status": 408, "detail": "the job took longer than %gs" % timeout,
                                        "job": status})
                delay = min(self.max_poll_interval, delay * 1.5)
                try:
                    status = self.job(job_id)
                except KmorphError as e:
                    if e.status in (429, 503):
                        time.sleep(e.retry_after or 1)
                        continue
                    raise
                if on_progress:
                    on_progress(status)
        except KeyboardInterrupt:
            self._cancel_quietly(job_id)
            raise

    def _cancel_quietly(self, job_id):
        try:
            self.cancel_job(job_id)
        except KmorphError:
            pass

    def health(self) -> Any:
        return self.request("GET", "/healthz")[2]

    def ready(self) -> Any:
        return self.request("GET", "/readyz")[2]


def _wait(event, seconds):
    """Wait up to `seconds` for event; True if it is set."""
    if hasattr(event, "wait"):
        return bool(event.wait(seconds))
    time.sleep(seconds)
    return bool(event.is_set())


def _header(headers, name):
    for k, v in headers.items():
        if k.lower() == name.lower():
            return v
    return None


def _parse(headers, raw):
    if raw is None or len(raw) == 0:
        return None
    ctype = (headers.get("Content-Type") if headers else "") or ""
    text = raw.decode("utf-8", "replace")
    if "json" in ctype:
        try:
            return json.loads(text)
        except ValueError:
            return text
    return text


# ----------------------------------------------------------- requests

def curve(value: Any) -> JSON:
    """A Curve for a request: an SVG path d string becomes {"type": "svg",
    "d": ...} (a compound shape when it has several subpaths), a list or
    tuple a shape of those contours, a dict is taken as it is."""
    if isinstance(value, str):
        return {"type": "svg", "d": value}
    if isinstance(value, (list, tuple)):
        return shape(value)
    if isinstance(value, dict):
        return value
    raise TypeError("a curve is an SVG path string, a list of contours or a curve dict")


_PATH_ARITY = {"M": 2, "L": 2, "H": 1, "V": 1, "C": 6, "S": 4, "Q": 4, "T": 2, "A": 7, "Z": 0}
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_SEPARATORS = re.compile(r"[\s,]*")


def _path_commands(d):
    """The commands of SVG path data as [(cmd, [arg text, ...])], one per
    command letter or implicit repetition; arc flags may be one digit
    without a separator ("a1 1 0 01 5 5"). Raises ValueError naming the
    offset of anything else."""
    out, i, cmd = [], 0, None

    def skip(i):
        return _SEPARATORS.match(d, i).end()

    i = skip(i)
    while i < len(d):
        if d[i].isalpha():
            if d[i].upper() not in _PATH_ARITY:
                raise ValueError("path data: unknown command %s at offset %d" % (d[i], i))
            cmd = d[i]
            i += 1
        elif cmd is None or cmd in "Zz":
            raise ValueError("path data: a command expected at offset %d" % i)
        args = []
        for k in range(_PATH_ARITY[cmd.upper()]):
            i = skip(i)
            if cmd.upper() == "A" and k in (3, 4) and d[i:i + 1] in ("0", "1"):
                args.append(d[i])
                i += 1
                continue
            m = _NUMBER.match(d, i)
            if not m:
                raise ValueError("path data: a number expected at offset %d" % i)
            args.append(m.group(0))
            i = m.end()
        out.append((cmd, args))
        # Pairs after a moveto are linetos of the same relativity.
        cmd = {"M": "L", "m": "l"}.get(cmd, cmd)
        i = skip(i)
    return out


def path_contours(d: str, close: bool = True) -> List[str]:
    """The subpaths of SVG path data, each as a d of its own that starts
    with an absolute moveto (so relative data after it keeps its meaning)
    and, with `close` (the default), ends with Z: SVG fills an open
    subpath as if it were closed, and a shape's contours must be closed
    (icon sets such as @mdi/svg close only their last subpath). Movetos
    that draw nothing are dropped."""
    out = []
    x = y = sx = sy = 0.0
    cur = None          # [text, drawn]
    closed = False

    def finish():
        if cur and cur[1]:
            out.append(cur[0] + ("Z" if close and not closed else ""))

    for cmd, args in _path_commands(d):
        up, v = cmd.upper(), [float(a) for a in args]
        rel = cmd != up
        if up == "M":
            finish()
            x, y = (x if rel else 0.0) + v[0], (y if rel else 0.0) + v[1]
            sx, sy = x, y
            cur, closed = ["M%s,%s" % (_num_text(x), _num_text(y)), False], False
            continue
        if cur is None or closed:
            finish()
            cur, closed = ["M%s,%s" % (_num_text(sx), _num_text(sy)), False], False
        cur[0] += cmd + " ".join(args)
        if up == "Z":
            x, y, closed = sx, sy, True
            continue
        cur[1] = True
        if up == "H":
            x = (x if rel else 0.0) + v[0]
        elif up == "V":
            y = (y if rel else 0.0) + v[0]
        else:
            x, y = (x if rel else 0.0) + v[-2], (y if rel else 0.0) + v[-1]
    finish()
    return out


def _num_text(v):
    return repr(int(v)) if v == int(v) and abs(v) < 1e15 else repr(v)


def shape(contours: Any, fill_rule: Optional[str] = None) -> JSON:
    """A compound shape {"type": "shape", "contours": [...]}: contours are
    closed curve dicts or d strings of one closed subpath each, or the
    whole shape is one d string, split by path_contours (and closed);
    fill_rule "nonzero" (the service's default) or "evenodd" decides the
    holes."""
    if isinstance(contours, str):
        contours = path_contours(contours)
    contours = list(contours)
    if not contours:
        raise ValueError("a shape needs at least one contour")
    out = {"type": "shape", "contours": [curve(c) for c in contours]}
    if fill_rule is not None:
        out["fill_rule"] = fill_rule
    return out


def morph_request(from_curve: Any, to_curve: Any, **options: Any) -> JSON:
    """A morph request from two curves (anything curve() takes) and the
    request's other members by their API names (frames, tolerance,
    contour_matches, include, ...); None values are left out."""
    req = {"from": curve(from_curve), "to": curve(to_curve)}
    req.update({k: v for k, v in options.items() if v is not None})
    return req


# ----------------------------------------------------------- geometry
# Output curves: {degree, knots, control_points, weights?, closed}.

def _find_span(U, p, n, u):
    if u >= U[n]:
        k = n - 1
        while k > p and U[k] == U[k + 1]:
            k -= 1
        return k
    if u <= U[p]:
        k = p
        while k < n - 1 and U[k] == U[k + 1]:
            k += 1
        return k
    return bisect.bisect_right(U, u, p, n) - 1


def _basis_ders(U, k, p, u):
    """N_{k-p..k,p}(u) and first derivatives on span k (The NURBS Book,
    A2.3), valid for any u (the span's polynomial continued)."""
    ndu = [[0.0] * (p + 1) for _ in range(p + 1)]
    left = [0.0] * (p + 1)
    right = [0.0] * (p + 1)
    ndu[0][0] = 1.0
    for j in range(1, p + 1):
        left[j] = u - U[k + 1 - j]
        right[j] = U[k + j] - u
        saved = 0.0
        for r in range(j):
            ndu[j][r] = right[r + 1] + left[j - r]
            tmp = ndu[r][j - 1] / ndu[j][r]
            ndu[r][j] = saved + right[r + 1] * tmp
            saved = left[j - r] * tmp
        ndu[j][j] = saved
    N = [ndu[j][p] for j in range(p + 1)]
    D = [0.0] * (p + 1)
    if p >= 1:
        for r in range(p + 1):
            d = 0.0
            if r >= 1:
                d += ndu[r - 1][p - 1] / ndu[p][r - 1]
            if r <= p - 1:
                d -= ndu[r][p - 1] / ndu[p][r]
            D[r] = p * d
    return N, D


def eval_curve(curve: JSON, u: float, span: Optional[int] = None) -> Tuple[Point, Point]:
    """((x, y), (dx/du, dy/du)) of an output curve at parameter u, on knot
    span `span` if given (one-sided values at knots)."""
    p, P, U = curve["degree"], curve["control_points"], curve["knots"]
    W = curve.get("weights")
    k = _find_span(U, p, len(P), u) if span is None else span
    N, D = _basis_ders(U, k, p, u)
    x = y = w = dx = dy = dw = 0.0
    for j in range(p + 1):
        i = k - p + j
        wi = W[i] if W else 1.0
        x += N[j] * wi * P[i][0]
        y += N[j] * wi * P[i][1]
        w += N[j] * wi
        dx += D[j] * wi * P[i][0]
        dy += D[j] * wi * P[i][1]
        dw += D[j] * wi
    px, py = x / w, y / w
    return (px, py), ((dx - dw * px) / w, (dy - dw * py) / w)


def _spans(curve):
    p, U, n = curve["degree"], curve["knots"], len(curve["control_points"])
    return [(k, U[k], U[k + 1]) for k in range(p, n) if U[k + 1] > U[k]]


def _num(v):
    r = round(v, 6)
    if r == 0:
        return "0"
    s = repr(r)
    return s[:-2] if s.endswith(".0") else s


def curve_to_path(curve: JSON, pieces: int = 8) -> str:
    """SVG path data of a curve as cubic Béziers: exact for non-rational
    curves of degree <= 3, else `pieces` Hermite cubics per knot span."""
    m = 1 if curve["degree"] <= 3 and not curve.get("weights") else pieces
    out = []
    for k, a, b in _spans(curve):
        for i in range(m):
            u0, u1 = a + (b - a) * i / m, a + (b - a) * (i + 1) / m
            h = (u1 - u0) / 3
            (p0, d0), (p1, d1) = eval_curve(curve, u0, k), eval_curve(curve, u1, k)
            if not out:
                out.append("M%s,%s" % (_num(p0[0]), _num(p0[1])))
            out.append("C%s,%s %s,%s %s,%s" % (
                _num(p0[0] + h * d0[0]), _num(p0[1] + h * d0[1]),
                _num(p1[0] - h * d1[0]), _num(p1[1] - h * d1[1]),
                _num(p1[0]), _num(p1[1])))
    return "".join(out) + ("Z" if curve.get("closed") else "")


def sample_points(curve: JSON, n: int = 200, per_span: int = 24) -> List[Point]:
    """n points at equal fractions of the curve's arc length."""
    dense = []
    spans = list(_spans(curve))
    # at least eight dense points a sample: a frame of few long pieces (a
    # circle in eight) sampled 24 to a piece cuts chords inside it
    per = max(per_span, -(-8 * n // max(1, len(spans))))
    for k, a, b in spans:
        for i in range(1 if dense else 0, per + 1):
            dense.append(eval_curve(curve, a + (b - a) * i / per, k)[0])
    cum = [0.0]
    for i in range(1, len(dense)):
        cum.append(cum[-1] + math.dist(dense[i], dense[i - 1]))
    total, out, j = cum[-1], [], 0
    for i in range(n):
        s = 0.0 if n == 1 else total * i / (n - 1)
        while j < len(dense) - 2 and cum[j + 1] < s:
            j += 1
        seg = cum[j + 1] - cum[j]
        f = min(1.0, max(0.0, (s - cum[j]) / seg)) if seg > 0 else 0.0
        out.append((dense[j][0] + f * (dense[j + 1][0] - dense[j][0]),
                    dense[j][1] + f * (dense[j + 1][1] - dense[j][1])))
    return out


def _points_to_path(pts, closed):
    end = len(pts) - 1 if closed and len(pts) > 2 else len(pts)
    d = "M%s,%s" % (_num(pts[0][0]), _num(pts[0][1]))
    d += "".join("L%s,%s" % (_num(x), _num(y)) for x, y in pts[1:end])
    return d + ("Z" if closed else "")


def is_compound(result_or_frame: JSON) -> bool:
    """Whether a morph result (or frame) is of compound shapes: frames with
    "contours" in place of "curve"."""
    f = result_or_frame
    if isinstance(f, dict) and isinstance(f.get("frames"), list):
        f = f["frames"][0] if f["frames"] else None
    return isinstance(f, dict) and isinstance(f.get("contours"), list)


def contour_pairs(result: JSON) -> List[JSON]:
    """The slots of a morph as [(slot, from, to)]: which contour of `from`
    went to which of `to` (from None: it appears; to None: it vanishes).
    A single-curve morph has the one slot (0, 0, 0)."""
    used = result.get("contour_matches_used")
    if not isinstance(used, list):
        return [(0, 0, 0)]
    return [(k, i, j) for k, (i, j) in enumerate(used)]


def frame_contours(frame: JSON) -> List[Optional[JSON]]:
    """A frame's curves, one per slot: the CurveOut dict, or None where
    the contour is a point at this t. A single-curve frame gives [curve]."""
    return frame["contours"] if isinstance(frame.get("contours"), list) else [frame["curve"]]


def frame_contour_paths(frame: JSON, pieces: int = 8) -> List[Optional[str]]:
    """SVG path data per slot of a frame (None for a collapsed contour)."""
    return [None if c is None else (c.get("svg_d") or curve_to_path(c, pieces))
            for c in frame_contours(frame)]


def frame_path(frame: JSON, pieces: int = 8) -> str:
    """A frame's whole SVG path data: the service's svg_d when the request
    included it, else converted here; for shapes one closed subpath per
    present contour, in slot order, to fill with the shape's fill rule."""
    if isinstance(frame.get("contours"), list):
        if isinstance(frame.get("svg_d"), str):
            return frame["svg_d"]
        return "".join(d for d in frame_contour_paths(frame, pieces) if d is not None)
    return frame["curve"].get("svg_d") or curve_to_path(frame["curve"], pieces)


def frame_paths(result: JSON, pieces: int = 8) -> List[str]:
    """One SVG d string per frame (see frame_path)."""
    return [frame_path(f, pieces) for f in result["frames"]]


def _mean(pts):
    return (sum(p[0] for p in pts) / len(pts), sum(p[1] for p in pts) / len(pts))


def _collapse_point(frames, pts, i):
    """The point a collapsed contour (None at frame i) shrinks into or
    grows from: the centre of its samples at the nearest frame where it is
    present, carried on to t_i along the centre's motion between that
    frame and the next one present beyond it (the service shrinks such a
    contour about a centre that moves smoothly: exact to first order)."""
    for d in range(1, len(pts)):
        for p in (i - d, i + d):
            if p < 0 or p >= len(pts) or pts[p] is None:
                continue
            c = _mean(pts[p])
            q = p + (1 if p > i else -1)
            if q < 0 or q >= len(pts) or pts[q] is None or frames[q]["t"] == frames[p]["t"]:
                return c
            c2 = _mean(pts[q])
            f = (frames[i]["t"] - frames[p]["t"]) / (frames[p]["t"] - frames[q]["t"])
            return (c[0] + f * (c[0] - c2[0]), c[1] + f * (c[1] - c2[1]))
    return (0.0, 0.0)


def _slot_tracks(frames, samples):
    """Per slot: samples per frame (None where collapsed), the point a
    collapsed contour shrinks into or grows from, closedness per frame."""
    per_frame = [[None if c is None else sample_points(c, samples) for c in frame_contours(f)]
                 for f in frames]
    tracks = []
    for k in range(len(per_frame[0])):
        pts = [row[k] for row in per_frame]
        closed = [True if frame_contours(f)[k] is None else bool(frame_contours(f)[k].get("closed"))
                  for f in frames]
        points = [None if p is not None else _collapse_point(frames, pts, i) for i, p in enumerate(pts)]
        tracks.append((pts, points, closed))
    return tracks


def interpolator(result: JSON, samples: int = 200, collapsed: str = "point",
                 per_contour: bool = False) -> Callable[[float], Any]:
    """A function t -> d for t in [0, 1]: each frame's curve (each contour
    of a shape) resampled at equal arc-length fractions, blended linearly
    between neighbouring frames; every string has one structure. A
    contour that vanishes or appears is blended with the point it shrinks
    into: collapsed="point" keeps it as a degenerate subpath there (the
    structure never changes), "omit" leaves it out where its length is 0.
    per_contour=True returns a list of one d per slot (None if omitted)."""
    frames = result["frames"]
    if not frames:
        raise ValueError("the morph result has no frames")
    if collapsed not in ("point", "omit"):
        raise ValueError('collapsed is "point" or "omit"')
    ts = [f["t"] for f in frames]
    tracks = _slot_tracks(frames, samples)

    def at(t):
        t = min(max(float(t), ts[0]), ts[-1])
        if len(frames) == 1:
            i = j = 0
        else:
            i = min(max(bisect.bisect_right(ts, t) - 1, 0), len(ts) - 2)
            j = i + 1
        span = ts[j] - ts[i]
        f = (t - ts[i]) / span if span > 0 else 0.0
        out = []
        for pts, points, closed in tracks:
            a, b = pts[i], pts[j]
            if collapsed == "omit" and ((a is None and b is None) or (a is None and f == 0)
                                        or (b is None and f == 1)):
                out.append(None)
                continue
            pa = a if a is not None else [points[i]] * samples
            pb = b if b is not None else [points[j]] * samples
            mixed = [(p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1])) for p, q in zip(pa, pb)]
            out.append(_points_to_path(mixed, closed[i] if f < 0.5 else closed[j]))
        return out if per_contour else "".join(d for d in out if d is not None)
    return at


def bounds(result: JSON) -> Tuple[float, float, float, float]:
    """(min_x, min_y, max_x, max_y) of every frame's control polygon (every
    contour of a shape), which holds the curves."""
    pts = [p for f in result["frames"] for c in frame_contours(f) if c is not None
           for p in c["control_points"]]
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    return min(xs), min(ys), max(xs), max(ys)
