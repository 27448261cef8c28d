"""kmorph - client for the kmorph HTTP service (standard library only).

    from kmorph import Client
    km = Client("http://127.0.0.1:8080")        # or $KMORPH_URL
    sig = km.signature({"type": "svg", "d": "M 0 0 L 10 0 L 10 10 Z"})
    res = km.morph_job(request, on_progress=lambda s: print(s["progress"]))
    paths = frame_paths(res)                     # one SVG d string per frame
    at = interpolator(res); at(0.5)              # d string at any t

Every error answered by the service raises KmorphError carrying the
problem+json body (``.problem``, ``.status``, ``.errors`` with JSON
pointers). Network failures raise KmorphError with status 0. A job that
is cancelled through ``cancel`` (a threading.Event) raises JobCancelled
after the job was cancelled on the service too.

Also a command line: ``python3 -m kmorph --help``.
"""
import bisect
import json
import math
import os
import time
import urllib.error
import urllib.parse
import urllib.request

__all__ = [
    "Client", "KmorphError", "JobCancelled", "DEFAULT_URL",
    "eval_curve", "curve_to_path", "sample_points", "frame_paths",
    "interpolator", "bounds",
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

    def message_for(self, pointer):
        """The message of the first error at `pointer` or below it, or None."""
        for e in self.errors:
            ptr = e.get("pointer", "")
            if ptr == pointer or ptr.startswith(pointer + "/"):
                return e.get("message")
        return None

    def __str__(self):
        head = "%s %s" % (self.status, self.title) if self.status else self.title
        return "%s: %s" % (head, self.detail) if self.detail else head


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

    def request(self, method, path, body=None, accept=None):
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

    def signature(self, curve, tolerance=None, samples=None):
        """POST /v1/signature: {"signature": ..., "samples"?: [[s, kappa]]}."""
        req = {"curve": curve}
        if tolerance is not None:
            req["tolerance"] = tolerance
        if samples is not None:
            req["samples"] = samples
        return self.request("POST", "/v1/signature", req)[2]

    def reconstruct(self, signature, tolerance=None, degree=None, include=None):
        """POST /v1/reconstruct: {"curve": ..., "error_bound": e}."""
        req = {"signature": signature}
        if tolerance is not None:
            req["tolerance"] = tolerance
        if degree is not None:
            req["degree"] = degree
        if include is not None:
            req["include"] = list(include)
        return self.request("POST", "/v1/reconstruct", req)[2]

    def morph(self, request):
        """POST /v1/morph: the morph result (a dict), or SVG text when
        request["format"] is "svg"."""
        accept = "image/svg+xml, application/problem+json" if request.get("format") == "svg" else None
        return self.request("POST", "/v1/morph", request, accept)[2]

    def submit_job(self, request):
        """POST /v1/jobs: the job status, with "location" from the header."""
        _, headers, body = self.request("POST", "/v1/jobs", request)
        body["location"] = _header(headers, "Location") or body["links"]["self"]
        return body

    def job(self, job_id):
        """GET /v1/jobs/{id}: state, progress, frames_done, frames_total."""
        return self.request("GET", "/v1/jobs/" + urllib.parse.quote(job_id))[2]

    def job_result(self, job_id):
        """GET /v1/jobs/{id}/result: the result of a done job."""
        return self.request("GET", "/v1/jobs/%s/result" % urllib.parse.quote(job_id),
                            accept="application/json, image/svg+xml, application/problem+json")[2]

    def cancel_job(self, job_id):
        """DELETE /v1/jobs/{id}: cancel a live job, forget a finished one."""
        self.request("DELETE", "/v1/jobs/" + urllib.parse.quote(job_id))

    def morph_job(self, request, on_progress=None, cancel=None, timeout=None):
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

    def health(self):
        return self.request("GET", "/healthz")[2]

    def ready(self):
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


def eval_curve(curve, u, span=None):
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


def curve_to_path(curve, pieces=8):
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


def sample_points(curve, n=200, per_span=24):
    """n points at equal fractions of the curve's arc length."""
    dense = []
    for k, a, b in _spans(curve):
        for i in range(1 if dense else 0, per_span + 1):
            dense.append(eval_curve(curve, a + (b - a) * i / per_span, k)[0])
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


def frame_paths(result):
    """One SVG d string per frame: svg_d when the request included it,
    else the frame's B-spline converted here."""
    return [f["curve"].get("svg_d") or curve_to_path(f["curve"]) for f in result["frames"]]


def interpolator(result, samples=200):
    """A function t -> d for t in [0, 1]: frames resampled at equal
    arc-length fractions, blended linearly between neighbouring frames."""
    frames = result["frames"]
    if not frames:
        raise ValueError("the morph result has no frames")
    ts = [f["t"] for f in frames]
    pts = [sample_points(f["curve"], samples) for f in frames]
    closed = [bool(f["curve"].get("closed")) for f in frames]

    def at(t):
        t = min(max(float(t), ts[0]), ts[-1])
        if len(frames) == 1:
            return _points_to_path(pts[0], closed[0])
        i = min(max(bisect.bisect_right(ts, t) - 1, 0), len(ts) - 2)
        span = ts[i + 1] - ts[i]
        f = (t - ts[i]) / span if span > 0 else 0.0
        mixed = [(a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]))
                 for a, b in zip(pts[i], pts[i + 1])]
        return _points_to_path(mixed, closed[i] if f < 0.5 else closed[i + 1])
    return at


def bounds(result):
    """(min_x, min_y, max_x, max_y) of every frame's control polygon."""
    xs = [p[0] for f in result["frames"] for p in f["curve"]["control_points"]]
    ys = [p[1] for f in result["frames"] for p in f["curve"]["control_points"]]
    return min(xs), min(ys), max(xs), max(ys)
