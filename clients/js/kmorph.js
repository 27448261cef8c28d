// kmorph.js - client for the kmorph HTTP service, for browsers and Node 20.
//
// One dependency-free ES module. It talks to kmorphd with the platform's
// fetch (signature, reconstruct, synchronous morphs and jobs with progress
// and cancellation) and turns morph results into SVG path data: one `d`
// string per frame, and an interpolator t -> d for smooth animation (the
// shape of flubber's interpolate()).
//
//   import { Client, framePaths, interpolator } from "./kmorph.js";
//   const km = new Client({ baseUrl: "http://127.0.0.1:8080" });
//   const result = await km.morphJob(request, { onProgress: (s) => ..., signal });
//   const at = interpolator(result);   // at(0.5) -> "M...".
//
// Every failure of the service is thrown as a KmorphError whose `problem`
// is the RFC 9457 problem+json body the service sent (or one made up here
// for network failures, failed and cancelled jobs). Aborts through an
// AbortSignal reject with the signal's reason, as fetch does.

/** The base URL used when none is given: same origin in a browser,
 * $KMORPH_URL or the embedded default in Node. */
function defaultBaseUrl() {
  if (typeof globalThis.location !== "undefined" && globalThis.location.origin &&
      globalThis.location.origin !== "null") return "";
  const env = globalThis.process && globalThis.process.env;
  return (env && env.KMORPH_URL) || "http://127.0.0.1:8080";
}

/** An error answered by the service (or a transport failure described in
 * the same shape). `problem` is the problem+json object; `status`, `type`,
 * `title`, `detail` and `errors` (JSON pointers to the fields at fault)
 * are copied from it for convenience. */
export class KmorphError extends Error {
  constructor(problem, response) {
    const p = problem && typeof problem === "object" ? problem : {};
    super(p.detail || p.title || "kmorph request failed");
    this.name = "KmorphError";
    this.problem = p;
    this.status = typeof p.status === "number" ? p.status : (response ? response.status : 0);
    this.type = p.type || "about:blank";
    this.title = p.title || "";
    this.detail = p.detail || "";
    this.errors = Array.isArray(p.errors) ? p.errors : [];
    this.requestId = p.request_id || (response && response.headers.get("X-Request-Id")) || null;
    const ra = response && response.headers.get("Retry-After");
    this.retryAfter = ra != null && ra !== "" ? Number(ra) : null;
  }

  /** The message of the first error whose pointer is `pointer` or lies
   * below it (e.g. "/from" matches "/from/d"), or null. */
  messageFor(pointer) {
    for (const e of this.errors)
      if (e.pointer === pointer || (e.pointer || "").startsWith(pointer + "/")) return e.message;
    return null;
  }
}

function abortReason(signal) {
  if (signal.reason !== undefined) return signal.reason;
  const e = new Error("This operation was aborted");
  e.name = "AbortError";
  return e;
}

/** Wait ms milliseconds, or reject as soon as signal aborts. */
function sleep(ms, signal) {
  return new Promise((resolve, reject) => {
    if (signal && signal.aborted) return reject(abortReason(signal));
    const onAbort = () => { clearTimeout(timer); reject(abortReason(signal)); };
    const timer = setTimeout(() => {
      if (signal) signal.removeEventListener("abort", onAbort);
      resolve();
    }, ms);
    if (signal) signal.addEventListener("abort", onAbort, { once: true });
  });
}

/** A connection to one kmorphd. Options: baseUrl (default: same origin in
 * a browser, $KMORPH_URL or http://127.0.0.1:8080 in Node), fetch (an
 * implementation to use instead of globalThis.fetch), headers (added to
 * every request), pollInterval (first job poll delay in ms, default 50,
 * growing to maxPollInterval, default 500). */
export class Client {
  constructor(options = {}) {
    const base = options.baseUrl != null ? String(options.baseUrl) : defaultBaseUrl();
    this.baseUrl = base.replace(/\/+$/, "");
    this.fetch = options.fetch || globalThis.fetch.bind(globalThis);
    this.headers = options.headers || {};
    this.pollInterval = options.pollInterval || 50;
    this.maxPollInterval = options.maxPollInterval || 500;
  }

  /** One HTTP exchange. Returns {response, body}: body is parsed JSON for
   * JSON answers, text for others, null for 204. Throws KmorphError for
   * any status >= 400 and for network failures. */
  async request(method, path, { body, signal, accept } = {}) {
    const headers = { Accept: accept || "application/json, application/problem+json", ...this.headers };
    const init = { method, headers, signal };
    if (body !== undefined) {
      headers["Content-Type"] = "application/json";
      init.body = typeof body === "string" ? body : JSON.stringify(body);
    }
    let response;
    try {
      response = await this.fetch(this.baseUrl + path, init);
    } catch (e) {
      if (signal && signal.aborted) throw abortReason(signal);
      throw new KmorphError({ type: "/problems/network", title: "Network error", status: 0,
                              detail: `cannot reach ${this.baseUrl || "the service"}: ${e.message}` });
    }
    const ctype = response.headers.get("Content-Type") || "";
    let parsed = null;
    if (response.status !== 204) {
      const text = await response.text();
      if (/json/.test(ctype)) {
        try { parsed = JSON.parse(text); } catch { parsed = text; }
      } else parsed = text;
    }
    if (response.status >= 400) {
      const problem = parsed && typeof parsed === "object" ? parsed
        : { type: "about:blank", title: response.statusText || "HTTP error", status: response.status,
            detail: typeof parsed === "string" ? parsed.slice(0, 500) : "" };
      throw new KmorphError(problem, response);
    }
    return { response, body: parsed };
  }

  /** POST /v1/signature: the curvature signature of `curve`. Options:
   * tolerance, samples (n: also return n samples [s, kappa]), signal. */
  async signature(curve, { tolerance, samples, signal } = {}) {
    const req = { curve };
    if (tolerance != null) req.tolerance = tolerance;
    if (samples != null) req.samples = samples;
    return (await this.request("POST", "/v1/signature", { body: req, signal })).body;
  }

  /** POST /v1/reconstruct: the curve of a signature, and its error bound.
   * Options: tolerance, degree (3 or 5), include (e.g. ["svg_d"]), signal. */
  async reconstruct(signature, { tolerance, degree, include, signal } = {}) {
    const req = { signature };
    if (tolerance != null) req.tolerance = tolerance;
    if (degree != null) req.degree = degree;
    if (include != null) req.include = include;
    return (await this.request("POST", "/v1/reconstruct", { body: req, signal })).body;
  }

  /** POST /v1/morph: a whole morph, synchronously. Returns the morph
   * result object, or the SVG text when request.format is "svg". */
  async morph(request, { signal } = {}) {
    const accept = request.format === "svg" ? "image/svg+xml, application/problem+json" : undefined;
    return (await this.request("POST", "/v1/morph", { body: request, signal, accept })).body;
  }

  /** POST /v1/jobs: start a morph job. Returns the job status (id, state,
   * links) with `location` set from the Location header. */
  async submitJob(request, { signal } = {}) {
    const { response, body } = await this.request("POST", "/v1/jobs", { body: request, signal });
    return { ...body, location: response.headers.get("Location") || (body.links && body.links.self) };
  }

  /** GET /v1/jobs/{id}: state and progress. */
  async job(id, { signal } = {}) {
    return (await this.request("GET", `/v1/jobs/${encodeURIComponent(id)}`, { signal })).body;
  }

  /** GET /v1/jobs/{id}/result: the result of a done job (JSON object or
   * SVG text, as asked for when it was submitted). */
  async jobResult(id, { signal } = {}) {
    const accept = "application/json, image/svg+xml, application/problem+json";
    return (await this.request("GET", `/v1/jobs/${encodeURIComponent(id)}/result`, { signal, accept })).body;
  }

  /** DELETE /v1/jobs/{id}: cancel a live job or forget a finished one. */
  async cancelJob(id, { signal } = {}) {
    await this.request("DELETE", `/v1/jobs/${encodeURIComponent(id)}`, { signal });
  }

  /** The whole job flow: submit, poll (calling onProgress(status) with
   * every status seen, progress in 0..1), fetch the result. Aborting
   * `signal` cancels the job on the service (DELETE) and rejects with the
   * signal's reason. A failed or cancelled job throws a KmorphError whose
   * problem carries the job's error. */
  async morphJob(request, { onProgress, signal } = {}) {
    const first = await this.submitJob(request, { signal });
    const id = first.id;
    let status = first;
    let delay = this.pollInterval;
    try {
      if (onProgress) onProgress(status);
      for (;;) {
        if (status.state === "done") break;
        if (status.state === "failed") {
          const err = status.error || {};
          throw new KmorphError({ type: "/problems/job-failed", title: "Job failed",
                                  status: err.status || 500, detail: err.detail || "the job failed", job: status });
        }
        if (status.state === "cancelled")
          throw new KmorphError({ type: "/problems/job-cancelled", title: "Job cancelled", status: 409,
                                  detail: "the job was cancelled", job: status });
        await sleep(delay, signal);
        delay = Math.min(this.maxPollInterval, delay * 1.5);
        try {
          status = await this.job(id, { signal });
        } catch (e) {
          /* An overloaded service asks us to come back later. */
          if (e instanceof KmorphError && (e.status === 503 || e.status === 429)) {
            await sleep(1000 * (e.retryAfter || 1), signal);
            continue;
          }
          throw e;
        }
        if (onProgress) onProgress(status);
      }
      return await this.jobResult(id, { signal });
    } catch (e) {
      if (signal && signal.aborted) {
        /* Free the workers: the caller no longer wants the frames. */
        try { await this.cancelJob(id); } catch { /* already gone */ }
        throw abortReason(signal);
      }
      throw e;
    }
  }

  /** GET /healthz and /readyz. */
  async health({ signal } = {}) { return (await this.request("GET", "/healthz", { signal })).body; }
  async ready({ signal } = {}) { return (await this.request("GET", "/readyz", { signal })).body; }
}

// ------------------------------------------------------------ geometry
// Output curves are B-splines (or NURBS): {degree, knots, control_points,
// weights?, closed}. These helpers evaluate them so that results can be
// drawn without asking the service for svg_d.

/** Index k of the knot span [knots[k], knots[k+1]) holding u, among the
 * valid spans p..n-1 (the last span includes its right end). */
function findSpan(knots, p, n, u) {
  if (u >= knots[n]) {
    let k = n - 1;
    while (k > p && knots[k] === knots[k + 1]) k--;
    return k;
  }
  if (u <= knots[p]) {
    let k = p;
    while (k < n - 1 && knots[k] === knots[k + 1]) k++;
    return k;
  }
  let lo = p, hi = n;
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (u < knots[mid]) hi = mid; else lo = mid;
  }
  return lo;
}

/** Basis functions N_{k-p..k}(u) and their first derivatives on span k
 * (The NURBS Book, A2.3, first derivative only). Valid for any u: the
 * span's polynomial is continued beyond its ends. */
function basisDers(knots, k, p, u) {
  const ndu = Array.from({ length: p + 1 }, () => new Array(p + 1).fill(0));
  const left = new Array(p + 1).fill(0), right = new Array(p + 1).fill(0);
  ndu[0][0] = 1;
  for (let j = 1; j <= p; j++) {
    left[j] = u - knots[k + 1 - j];
    right[j] = knots[k + j] - u;
    let saved = 0;
    for (let r = 0; r < j; r++) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const tmp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * tmp;
      saved = left[j - r] * tmp;
    }
    ndu[j][j] = saved;
  }
  const N = new Array(p + 1), D = new Array(p + 1).fill(0);
  for (let j = 0; j <= p; j++) N[j] = ndu[j][p];
  if (p >= 1)
    for (let r = 0; r <= p; r++) {
      let d = 0;
      if (r >= 1) d += ndu[r - 1][p - 1] / ndu[p][r - 1];
      if (r <= p - 1) d -= ndu[r][p - 1] / ndu[p][r];
      D[r] = p * d;
    }
  return [N, D];
}

/** Point and first derivative of the curve at parameter u, using span k
 * if given (one-sided values at knots), else the span holding u.
 * Returns [[x, y], [dx, dy]]. */
export function evalCurve(curve, u, k) {
  const p = curve.degree, P = curve.control_points, U = curve.knots, W = curve.weights;
  const n = P.length;
  if (k === undefined) k = findSpan(U, p, n, u);
  const [N, D] = basisDers(U, k, p, u);
  let x = 0, y = 0, w = 0, dx = 0, dy = 0, dw = 0;
  for (let j = 0; j <= p; j++) {
    const i = k - p + j, wi = W ? W[i] : 1;
    x += N[j] * wi * P[i][0]; y += N[j] * wi * P[i][1]; w += N[j] * wi;
    dx += D[j] * wi * P[i][0]; dy += D[j] * wi * P[i][1]; dw += D[j] * wi;
  }
  const px = x / w, py = y / w;
  return [[px, py], [(dx - dw * px) / w, (dy - dw * py) / w]];
}

/** The non-empty knot spans of a curve as [k, a, b]. */
function spans(curve) {
  const p = curve.degree, U = curve.knots, n = curve.control_points.length, out = [];
  for (let k = p; k < n; k++) if (U[k + 1] > U[k]) out.push([k, U[k], U[k + 1]]);
  return out;
}

/** Numbers for path data: short, locale-free, no "-0". */
function num(v) {
  const r = Math.round(v * 1e6) / 1e6;
  return Object.is(r, -0) ? "0" : String(r);
}

/** SVG path data of a curve as cubic Béziers. Exact for non-rational
 * curves of degree <= 3 (one Bézier per knot span, by Hermite data);
 * other curves get `pieces` cubic Hermite pieces per span (default 8). */
export function curveToPath(curve, { pieces } = {}) {
  const exact = curve.degree <= 3 && !curve.weights;
  const m = exact ? 1 : (pieces || 8);
  let d = "";
  for (const [k, a, b] of spans(curve)) {
    for (let i = 0; i < m; i++) {
      const u0 = a + (b - a) * i / m, u1 = a + (b - a) * (i + 1) / m, h = (u1 - u0) / 3;
      const [p0, d0] = evalCurve(curve, u0, k), [p1, d1] = evalCurve(curve, u1, k);
      if (!d) d = `M${num(p0[0])},${num(p0[1])}`;
      d += `C${num(p0[0] + h * d0[0])},${num(p0[1] + h * d0[1])} ` +
           `${num(p1[0] - h * d1[0])},${num(p1[1] - h * d1[1])} ${num(p1[0])},${num(p1[1])}`;
    }
  }
  return curve.closed ? d + "Z" : d;
}

/** n points of the curve at equal fractions of its arc length (first and
 * last at its ends), by dense sampling and chord-length resampling. */
export function samplePoints(curve, n = 200, { perSpan = 24 } = {}) {
  const dense = [], cum = [0];
  for (const [k, a, b] of spans(curve))
    for (let i = dense.length ? 1 : 0; i <= perSpan; i++) dense.push(evalCurve(curve, a + (b - a) * i / perSpan, k)[0]);
  for (let i = 1; i < dense.length; i++)
    cum.push(cum[i - 1] + Math.hypot(dense[i][0] - dense[i - 1][0], dense[i][1] - dense[i - 1][1]));
  const total = cum[cum.length - 1], out = [];
  let j = 0;
  for (let i = 0; i < n; i++) {
    const s = n === 1 ? 0 : total * i / (n - 1);
    while (j < dense.length - 2 && cum[j + 1] < s) j++;
    const seg = cum[j + 1] - cum[j], f = seg > 0 ? Math.min(1, Math.max(0, (s - cum[j]) / seg)) : 0;
    out.push([dense[j][0] + f * (dense[j + 1][0] - dense[j][0]), dense[j][1] + f * (dense[j + 1][1] - dense[j][1])]);
  }
  return out;
}

function pointsToPath(pts, closed) {
  let d = `M${num(pts[0][0])},${num(pts[0][1])}`;
  /* A closed curve's last sample repeats its first: Z draws that edge. */
  const end = closed && pts.length > 2 ? pts.length - 1 : pts.length;
  for (let i = 1; i < end; i++) d += `L${num(pts[i][0])},${num(pts[i][1])}`;
  return closed ? d + "Z" : d;
}

/** One `d` string per frame of a morph result: the service's own svg_d
 * when the request asked for it (`"include": ["svg_d"]`), else the frame's
 * B-spline converted here. */
export function framePaths(result) {
  return result.frames.map((f) => f.curve.svg_d || curveToPath(f.curve));
}

/** A function t -> d for any t in [0, 1], like flubber's interpolate():
 * each frame is resampled at `samples` equal arc-length fractions and
 * points are blended linearly between the two frames around t (so frames
 * are hit exactly, up to the sampling, and motion in between is smooth).
 * Every string has the same structure, so the output also suits CSS/SMIL
 * path animation. Option `exact: true` returns the frame's own path when t
 * is a frame's t. */
export function interpolator(result, { samples = 200, exact = false } = {}) {
  const frames = result.frames;
  if (!frames.length) throw new RangeError("the morph result has no frames");
  const ts = frames.map((f) => f.t);
  const pts = frames.map((f) => samplePoints(f.curve, samples));
  const closed = frames.map((f) => !!f.curve.closed);
  const paths = exact ? framePaths(result) : null;
  return (t) => {
    t = Math.min(Math.max(+t, ts[0]), ts[ts.length - 1]);
    let i = 0;
    while (i < ts.length - 2 && t > ts[i + 1]) i++;
    if (frames.length === 1) return exact ? paths[0] : pointsToPath(pts[0], closed[0]);
    const span = ts[i + 1] - ts[i], f = span > 0 ? (t - ts[i]) / span : 0;
    if (exact) {
      if (Math.abs(t - ts[i]) < 1e-12) return paths[i];
      if (Math.abs(t - ts[i + 1]) < 1e-12) return paths[i + 1];
    }
    const a = pts[i], b = pts[i + 1];
    const mixed = a.map((q, j) => [q[0] + f * (b[j][0] - q[0]), q[1] + f * (b[j][1] - q[1])]);
    return pointsToPath(mixed, f < 0.5 ? closed[i] : closed[i + 1]);
  };
}

/** Bounding box [minX, minY, maxX, maxY] of the frames' control polygons
 * (which contain the curves), for choosing an SVG viewBox. */
export function bounds(result) {
  let b = [Infinity, Infinity, -Infinity, -Infinity];
  for (const f of result.frames)
    for (const [x, y] of f.curve.control_points)
      b = [Math.min(b[0], x), Math.min(b[1], y), Math.max(b[2], x), Math.max(b[3], y)];
  return b;
}

/** Convenience functions on a default client (same origin in a browser,
 * $KMORPH_URL or http://127.0.0.1:8080 in Node). */
let defaultClient = null;
function dc() { return (defaultClient ||= new Client()); }
export const signature = (curve, opts) => dc().signature(curve, opts);
export const reconstruct = (sig, opts) => dc().reconstruct(sig, opts);
export const morph = (req, opts) => dc().morph(req, opts);
export const morphJob = (req, opts) => dc().morphJob(req, opts);
