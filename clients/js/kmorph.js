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
// Compound shapes (glyphs with holes, icons of several parts) go in as an
// SVG path with several subpaths or as shape(contours); their frames carry
// one contour per slot of result.contour_matches_used (null where a
// contour has shrunk to a point), and every helper here that reads frames
// (framePath(s), frameContours, interpolator, bounds) takes both kinds.
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

  /** The errors that name one contour of a compound shape, as
   * {side: "from" | "to" | "curve", contour, offset, pointer, message}:
   * `contour` is the index in the shape's `contours` (or the subpath's
   * index in an SVG `d`), `offset` the character offset in that `d` when
   * the service gave one, else null. */
  contourErrors() {
    const out = [];
    for (const e of this.errors) {
      const pointer = e.pointer || "", message = e.message || "";
      let m = /^\/(from|to|curve)\/contours\/(\d+)(?:\/|$)/.exec(pointer);
      if (m) {
        const at = /\boffset (\d+)/.exec(message);
        out.push({ side: m[1], contour: Number(m[2]), offset: at ? Number(at[1]) : null, pointer, message });
        continue;
      }
      m = /^\/(from|to|curve)\/d$/.exec(pointer);
      const sub = /\bsubpath (\d+)/.exec(message);
      if (m && sub) {
        const at = /\boffset (\d+)/.exec(message);
        out.push({ side: m[1], contour: Number(sub[1]), offset: at ? Number(at[1]) : null, pointer, message });
      }
    }
    return out;
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
/** The body of a response as text, calling onDownload({received, total})
 * with every chunk read. The chunks are decoded bytes: a gzip-coded body's
 * Content-Length counts other bytes (or is absent when it is compressed as
 * sent), so kmorphd names the decoded length in X-Uncompressed-Length. */
async function readWithProgress(response, onDownload) {
  const coded = response.headers.get("Content-Encoding");
  const length = Number(response.headers.get(coded ? "X-Uncompressed-Length" : "Content-Length"));
  const total = length > 0 ? length : null;
  const reader = response.body.getReader(), chunks = [];
  let received = 0;
  onDownload({ received, total });
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    chunks.push(value);
    received += value.length;
    onDownload({ received, total });
  }
  const all = new Uint8Array(received);
  let at = 0;
  for (const c of chunks) { all.set(c, at); at += c.length; }
  return new TextDecoder().decode(all);
}

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
   * any status >= 400 and for network failures. With onDownload, a
   * successful answer's body is read chunk by chunk and onDownload({received,
   * total}) called as bytes arrive (total: null when unknown, as for a
   * compressed body, whose Content-Length counts other bytes). */
  async request(method, path, { body, signal, accept, onDownload } = {}) {
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
      const text = onDownload && response.body && response.status < 400
        ? await readWithProgress(response, onDownload) : await response.text();
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
   * Options: tolerance, degree (3 or 5), precision, include (e.g.
   * ["svg_d"]), signal. */
  async reconstruct(signature, { tolerance, degree, precision, include, signal } = {}) {
    const req = { signature };
    if (tolerance != null) req.tolerance = tolerance;
    if (degree != null) req.degree = degree;
    if (precision != null) req.precision = precision;
    if (include != null) req.include = include;
    return (await this.request("POST", "/v1/reconstruct", { body: req, signal })).body;
  }

  /** POST /v1/morph: a whole morph, synchronously. Returns the morph
   * result object, or the SVG text when request.format is "svg".
   * Options: signal, onDownload (see request). */
  async morph(request, { signal, onDownload } = {}) {
    const accept = request.format === "svg" ? "image/svg+xml, application/problem+json" : undefined;
    return (await this.request("POST", "/v1/morph", { body: request, signal, accept, onDownload })).body;
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
  async jobResult(id, { signal, onDownload } = {}) {
    const accept = "application/json, image/svg+xml, application/problem+json";
    return (await this.request("GET", `/v1/jobs/${encodeURIComponent(id)}/result`, { signal, accept, onDownload })).body;
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
  async morphJob(request, { onProgress, onDownload, signal } = {}) {
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
      return await this.jobResult(id, { signal, onDownload });
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

// ------------------------------------------------------------ requests

/** A Curve for a request: an SVG path `d` string becomes {type: "svg", d}
 * (a compound shape when it has several subpaths), an array becomes a
 * shape of those contours, an object is taken as it is. */
export function curve(input) {
  if (typeof input === "string") return { type: "svg", d: input };
  if (Array.isArray(input)) return shape(input);
  if (input && typeof input === "object") return input;
  throw new TypeError("a curve is an SVG path string, an array of contours or a curve object");
}

/** Arguments of each path command, and which of them are arc flags
 * (written as one digit, possibly without a separator: "a1 1 0 01 5 5"). */
const PATH_ARITY = { M: 2, L: 2, H: 1, V: 1, C: 6, S: 4, Q: 4, T: 2, A: 7, Z: 0 };
const NUMBER = /[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?/y;

/** The commands of SVG path data as [{cmd, args: [text...]}], one entry
 * per command letter or implicit repetition. Throws a SyntaxError naming
 * the offset of anything else. */
function pathCommands(d) {
  const out = [];
  let i = 0, cmd = null;
  const skip = () => { while (i < d.length && /[\s,]/.test(d[i])) i++; };
  const number = (flag) => {
    skip();
    if (flag && (d[i] === "0" || d[i] === "1")) return d[i++];
    NUMBER.lastIndex = i;
    const m = NUMBER.exec(d);
    if (!m) throw new SyntaxError(`path data: a number expected at offset ${i}`);
    i += m[0].length;
    return m[0];
  };
  for (skip(); i < d.length; skip()) {
    if (/[A-Za-z]/.test(d[i])) {
      if (!(d[i].toUpperCase() in PATH_ARITY)) throw new SyntaxError(`path data: unknown command ${d[i]} at offset ${i}`);
      cmd = d[i++];
    } else if (cmd === null || /[Zz]/.test(cmd)) throw new SyntaxError(`path data: a command expected at offset ${i}`);
    const n = PATH_ARITY[cmd.toUpperCase()], args = [];
    for (let k = 0; k < n; k++) args.push(number(cmd.toUpperCase() === "A" && (k === 3 || k === 4)));
    out.push({ cmd, args });
    /* Pairs after a moveto are linetos of the same relativity. */
    if (cmd === "M") cmd = "L"; else if (cmd === "m") cmd = "l";
  }
  return out;
}

/** The subpaths of SVG path data, each as a `d` of its own that starts
 * with an absolute moveto (so relative data after it keeps its meaning)
 * and, with `close` (the default), ends with Z: SVG fills an open
 * subpath as if it were closed, and a shape's contours must be closed
 * (icon sets such as @mdi/svg close only their last subpath). Movetos
 * that draw nothing are dropped. */
export function pathContours(d, { close = true } = {}) {
  const out = [];
  let x = 0, y = 0, sx = 0, sy = 0, cur = null, closed = false;
  const finish = () => {
    if (cur && cur.drawn) out.push(cur.text + (close && !closed ? "Z" : ""));
    cur = null;
  };
  for (const { cmd, args } of pathCommands(d)) {
    const up = cmd.toUpperCase(), rel = cmd !== up, v = args.map(Number);
    if (up === "M") {
      finish();
      x = (rel ? x : 0) + v[0]; y = (rel ? y : 0) + v[1]; sx = x; sy = y;
      cur = { text: `M${x},${y}`, drawn: false };
      closed = false;
      continue;
    }
    if (!cur) cur = { text: `M${sx},${sy}`, drawn: false };
    if (closed) { finish(); cur = { text: `M${sx},${sy}`, drawn: false }; closed = false; }
    cur.text += cmd + args.join(" ");
    if (up === "Z") { x = sx; y = sy; closed = true; continue; }
    cur.drawn = true;
    if (up === "H") x = (rel ? x : 0) + v[0];
    else if (up === "V") y = (rel ? y : 0) + v[0];
    else { x = (rel ? x : 0) + v[v.length - 2]; y = (rel ? y : 0) + v[v.length - 1]; }
  }
  finish();
  return out;
}

/** A compound shape {type: "shape", contours, fill_rule?}: contours are
 * closed Curves or `d` strings of one closed subpath each, or the whole
 * shape is one `d` string, split by pathContours (and closed); fillRule
 * "nonzero" (the service's default) or "evenodd" decides the holes. */
export function shape(contours, { fillRule } = {}) {
  if (typeof contours === "string") contours = pathContours(contours);
  if (!Array.isArray(contours) || contours.length === 0)
    throw new TypeError("a shape needs an array of at least one contour");
  const out = { type: "shape", contours: contours.map(curve) };
  if (fillRule != null) out.fill_rule = fillRule;
  return out;
}

/** A morph request from two curves (anything curve() takes) and options
 * named as in the API (`contour_matches`) or in camelCase
 * (`contourMatches`, `fillRule` is not one: give it to shape()). */
export function morphRequest(from, to, options = {}) {
  const req = { from: curve(from), to: curve(to) };
  for (const [key, value] of Object.entries(options))
    if (value !== undefined) req[key.replace(/[A-Z]/g, (c) => "_" + c.toLowerCase())] = value;
  return req;
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
  const all = [...spans(curve)];
  /* at least eight dense points a sample: a frame of few long pieces (a
   * circle in eight) sampled 24 to a piece cuts chords 1.3e-4 of its
   * radius inside it */
  const per = Math.max(perSpan, Math.ceil((8 * n) / Math.max(1, all.length)));
  for (const [k, a, b] of all)
    for (let i = dense.length ? 1 : 0; i <= per; i++) dense.push(evalCurve(curve, a + (b - a) * i / per, k)[0]);
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

/** Whether a morph result (or one of its frames) is of compound shapes:
 * frames with `contours` in place of `curve`. */
export function isCompound(resultOrFrame) {
  const f = resultOrFrame && Array.isArray(resultOrFrame.frames) ? resultOrFrame.frames[0] : resultOrFrame;
  return !!f && Array.isArray(f.contours);
}

/** The slots of a compound morph as [{slot, from, to}]: which contour of
 * `from` went to which of `to` (from null: the contour appears; to null:
 * it vanishes). A single-curve morph has one slot {slot: 0, from: 0, to: 0}. */
export function contourPairs(result) {
  const used = result.contour_matches_used;
  if (!Array.isArray(used)) return [{ slot: 0, from: 0, to: 0 }];
  return used.map(([from, to], slot) => ({ slot, from, to }));
}

/** A frame's curves, one per slot: CurveOut or null where the contour is
 * a point at this t. A single-curve frame gives [curve]. */
export function frameContours(frame) {
  return Array.isArray(frame.contours) ? frame.contours : [frame.curve];
}

/** SVG path data per slot of a frame (null for a collapsed contour). */
export function frameContourPaths(frame, options) {
  return frameContours(frame).map((c) => (c ? c.svg_d || curveToPath(c, options) : null));
}

/** A frame's whole SVG path data: the service's svg_d when the request
 * asked for it (`"include": ["svg_d"]`), else the frame's B-splines
 * converted here; for shapes one closed subpath per present contour, in
 * slot order, to be filled with the shape's fill rule. */
export function framePath(frame, options) {
  if (Array.isArray(frame.contours)) {
    if (typeof frame.svg_d === "string") return frame.svg_d;
    return frameContourPaths(frame, options).filter((d) => d !== null).join("");
  }
  return frame.curve.svg_d || curveToPath(frame.curve, options);
}

/** One `d` string per frame of a morph result (see framePath). */
export function framePaths(result, options) {
  return result.frames.map((f) => framePath(f, options));
}

function meanPoint(pts) {
  let x = 0, y = 0;
  for (const p of pts) { x += p[0]; y += p[1]; }
  return [x / pts.length, y / pts.length];
}

/** The point a collapsed contour (null at frame i) shrinks into or grows
 * from: the centre of its samples at the nearest frame where it is
 * present, carried on to t_i along the centre's motion between that frame
 * and the next one present beyond it (the service shrinks such a contour
 * about a centre that moves smoothly, so this is exact to first order). */
function collapsePoint(frames, pts, i) {
  for (let d = 1; d < pts.length; d++)
    for (const p of [i - d, i + d]) {
      if (p < 0 || p >= pts.length || !pts[p]) continue;
      const c = meanPoint(pts[p]), q = p + Math.sign(p - i);
      if (q < 0 || q >= pts.length || !pts[q] || frames[q].t === frames[p].t) return c;
      const c2 = meanPoint(pts[q]), f = (frames[i].t - frames[p].t) / (frames[p].t - frames[q].t);
      return [c[0] + f * (c[0] - c2[0]), c[1] + f * (c[1] - c2[1])];
    }
  return [0, 0];
}

/** Where each slot's contour is at every frame: its samples, or for a
 * collapsed contour the point it shrinks into (or grows from). */
function slotTracks(frames, samples) {
  const perFrame = frames.map((f) => frameContours(f).map((c) => (c ? samplePoints(c, samples) : null)));
  const slots = perFrame[0].length;
  const tracks = [];
  for (let k = 0; k < slots; k++) {
    const pts = perFrame.map((row) => row[k]);
    const closed = frames.map((f) => { const c = frameContours(f)[k]; return c ? !!c.closed : true; });
    const points = pts.map((p, i) => (p ? null : collapsePoint(frames, pts, i)));
    tracks.push({ pts, points, closed });
  }
  return tracks;
}

/** A function t -> d for any t in [0, 1], like flubber's interpolate():
 * each frame's curve (each contour of a shape) is resampled at `samples`
 * equal arc-length fractions and points are blended linearly between the
 * two frames around t (so frames are hit exactly, up to the sampling, and
 * motion in between is smooth). Every string has the same structure, so
 * the output also suits CSS/SMIL path animation. A contour that vanishes
 * or appears is blended with the point it shrinks into: with `collapsed`
 * "point" (the default) it stays in the path as a degenerate subpath at
 * that point, so the structure never changes; with "omit" it is left out
 * where its length is zero. `perContour: true` returns, instead of one
 * string, an array of one string per slot (null where omitted). Option
 * `exact: true` returns the frame's own path when t is a frame's t. */
export function interpolator(result, { samples = 200, exact = false, collapsed = "point", perContour = false,
                                        string = true } = {}) {
  const frames = result.frames;
  if (!frames.length) throw new RangeError("the morph result has no frames");
  if (collapsed !== "point" && collapsed !== "omit") throw new RangeError('collapsed is "point" or "omit"');
  const ts = frames.map((f) => f.t);
  const tracks = slotTracks(frames, samples);
  const paths = exact ? frames.map((f) => (perContour ? frameContourPaths(f) : framePath(f))) : null;
  const degenerate = (c) => Array.from({ length: samples }, () => c);
  const compound = isCompound(result);
  /* string: false gives the blended points: one [[x, y]...] array for a
   * single curve, one per slot (null where omitted) for a shape. */
  const join = string
    ? (list) => (perContour ? list : list.filter((d) => d !== null).join(""))
    : (list) => (compound || perContour ? list : list[0]);
  return (t) => {
    t = Math.min(Math.max(+t, ts[0]), ts[ts.length - 1]);
    let i = 0;
    while (i < ts.length - 2 && t > ts[i + 1]) i++;
    const j = frames.length === 1 ? i : i + 1;
    const span = ts[j] - ts[i], f = span > 0 ? (t - ts[i]) / span : 0;
    if (exact && string) {
      if (Math.abs(t - ts[i]) < 1e-12) return paths[i];
      if (Math.abs(t - ts[j]) < 1e-12) return paths[j];
    }
    return join(tracks.map(({ pts, points, closed }) => {
      const a = pts[i], b = pts[j];
      if ((!a && !b) || (!a && f === 0) || (!b && f === 1)) {
        if (collapsed === "omit") return null;
      }
      const pa = a || degenerate(points[i]), pb = b || degenerate(points[j]);
      const mixed = pa.map((q, n) => [q[0] + f * (pb[n][0] - q[0]), q[1] + f * (pb[n][1] - q[1])]);
      return string ? pointsToPath(mixed, f < 0.5 ? closed[i] : closed[j]) : mixed;
    }));
  };
}

/** Options of interpolate() that shape the interpolator, not the request. */
const INTERPOLATOR_OPTIONS = ["samples", "exact", "collapsed", "perContour", "string"];

/** The flubber-style entry point: one morph of `from` into `to` (anything
 * curve() takes) computed once on the service, then a function t -> d for
 * any t in [0, 1] (see interpolator). Options: client (a Client; default
 * one on $KMORPH_URL or the page's origin), signal, the interpolator's
 * samples, exact, collapsed, perContour and string (false: point arrays
 * instead of path data), and anything else as morph request fields
 * (frames, method, contourMatches...; frames defaults to 11). */
export async function interpolate(from, to, options = {}) {
  const { client, signal, ...rest } = options;
  const shaping = {}, fields = {};
  for (const [key, value] of Object.entries(rest))
    (INTERPOLATOR_OPTIONS.includes(key) ? shaping : fields)[key] = value;
  if (fields.frames === undefined && fields.times === undefined) fields.frames = 11;
  const result = await (client || dc()).morph(morphRequest(from, to, fields), { signal });
  return interpolator(result, shaping);
}

/** interpolate() for lists of pairs froms[i] -> tos[i] (equal lengths),
 * the morphs made one after another: an array of interpolators, or with
 * `single: true` one function t -> the paths of all pairs joined. */
export async function interpolateAll(froms, tos, options = {}) {
  if (!Array.isArray(froms) || !Array.isArray(tos) || froms.length !== tos.length || froms.length === 0)
    throw new TypeError("interpolateAll needs two non-empty arrays of equal length");
  const { single = false, ...rest } = options;
  const each = [];
  for (let i = 0; i < froms.length; i++) each.push(await interpolate(froms[i], tos[i], rest));
  if (!single) return each;
  return (t) => (rest.string === false ? each.map((at) => at(t)) : each.map((at) => at(t)).join(""));
}

/** Bounding box [minX, minY, maxX, maxY] of the frames' control polygons
 * (which contain the curves), every contour of a shape included, for
 * choosing an SVG viewBox. */
export function bounds(result) {
  let b = [Infinity, Infinity, -Infinity, -Infinity];
  for (const f of result.frames)
    for (const c of frameContours(f))
      if (c)
        for (const [x, y] of c.control_points)
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
