// kmorph.test.mjs - the JavaScript client (clients/js/kmorph.js) against a
// live kmorphd: every endpoint, the job flow with progress and
// cancellation, problem+json errors, and the path helpers, with expected
// numbers taken from closed forms (circles, the paper's linear-curvature
// spirals), not from the service.
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { startDaemon } from "../lib/daemon.mjs";
import { Client, KmorphError, evalCurve, curveToPath, samplePoints, framePaths, interpolator, bounds }
  from "../../../clients/js/kmorph.js";

let daemon, km;
before(async () => {
  daemon = await startDaemon(["--max-job-frames", "20000"]);
  km = new Client({ baseUrl: daemon.url });
});
after(async () => { if (daemon) await daemon.stop(); });

const TAU = 2 * Math.PI;
const circleSvg = (r) => ({ type: "svg", d: `M ${r} 0 A ${r} ${r} 0 1 1 ${-r} 0 A ${r} ${r} 0 1 1 ${r} 0 Z` });
const squareSvg = (a) => ({ type: "svg", d: `M 0 0 L ${a} 0 L ${a} ${a} L 0 ${a} Z` });
/* kappa(s) = c s on [0, L]: the paper's Cornu spirals (Fig. 3: c = 1 and -0.5, L = 4). */
const spiral = (c, L = 4) => ({ type: "signature", signature: {
  length: L, start: { point: [0, 0], angle: 0 },
  kappa: { degree: 1, knots: [0, 0, L, L], coefficients: [0, c * L] } } });
const unitCircleSignature = { length: TAU, start: { point: [0, 0], angle: 0 },
  kappa: { degree: 1, knots: [0, 0, TAU, TAU], coefficients: [1, 1] }, closed: true };

/** Points of an SVG path made only of M, C and Z commands (what the
 * helpers and the service write), at `per` parameters per Bézier. */
function bezierPoints(d, per = 8) {
  const nums = d.match(/-?\d*\.?\d+(?:e[-+]?\d+)?/gi).map(Number);
  const out = [];
  let x = nums[0], y = nums[1];
  for (let i = 2; i + 5 < nums.length; i += 6) {
    const [x1, y1, x2, y2, x3, y3] = nums.slice(i, i + 6);
    for (let j = 0; j <= per; j++) {
      const t = j / per, s = 1 - t;
      out.push([s * s * s * x + 3 * s * s * t * x1 + 3 * s * t * t * x2 + t * t * t * x3,
                s * s * s * y + 3 * s * s * t * y1 + 3 * s * t * t * y2 + t * t * t * y3]);
    }
    x = x3; y = y3;
  }
  return out;
}

test("signature of a circle of radius 5 has length 10 pi, curvature 1/5 and turning 2 pi", async () => {
  const r = await km.signature(circleSvg(5), { samples: 9, tolerance: 1e-7 });
  const sig = r.signature;
  assert.ok(Math.abs(sig.length - 10 * Math.PI) < 1e-5, `length ${sig.length}`);
  assert.ok(Math.abs(Math.abs(sig.turning) - TAU) < 1e-6, `turning ${sig.turning}`);
  assert.equal(r.samples.length, 9);
  for (const [, k] of r.samples) assert.ok(Math.abs(Math.abs(k) - 0.2) < 1e-5, `kappa ${k}`);
});

test("reconstruct of kappa = 1 over [0, 2 pi] is the unit circle around (0, 1) within the reported bound", async () => {
  const r = await km.reconstruct(unitCircleSignature, { tolerance: 1e-6, include: ["svg_d"] });
  assert.ok(r.error_bound > 0 && r.error_bound <= 1e-6);
  const c = r.curve, U = c.knots, p = c.degree;
  const a = U[p], b = U[U.length - p - 1];
  for (let i = 0; i <= 400; i++) {
    const [[x, y]] = evalCurve(c, a + (b - a) * i / 400);
    assert.ok(Math.abs(Math.hypot(x, y - 1) - 1) <= r.error_bound + 1e-12, `point ${i} at ${x},${y}`);
  }
  assert.ok(Math.abs(c.length - TAU) < 1e-5);
});

test("curveToPath of a cubic B-spline is exact: its Béziers stay on the circle", async () => {
  const r = await km.reconstruct(unitCircleSignature, { tolerance: 1e-7 });
  const d = curveToPath(r.curve);
  assert.match(d, /^M[^MZ]*Z$/);
  for (const [x, y] of bezierPoints(d, 6))
    assert.ok(Math.abs(Math.hypot(x, y - 1) - 1) < r.error_bound + 2e-6, `${x},${y}`);
});

test("samplePoints spaces points equally along the arc: chords of the unit circle equal 2 sin(pi/n)", async () => {
  const r = await km.reconstruct(unitCircleSignature, { tolerance: 1e-8 });
  const n = 64, pts = samplePoints(r.curve, n + 1, { perSpan: 64 });
  assert.equal(pts.length, n + 1);
  const chord = 2 * Math.sin(Math.PI / n);
  for (let i = 1; i <= n; i++) {
    const c = Math.hypot(pts[i][0] - pts[i - 1][0], pts[i][1] - pts[i - 1][1]);
    assert.ok(Math.abs(c - chord) < 1e-4, `chord ${i}: ${c} vs ${chord}`);
  }
});

test("morph of the paper's spirals blends curvature: max |kappa_t| = 4 |1 - 1.5 t| and length stays 4", async () => {
  const res = await km.morph({ from: spiral(1), to: spiral(-0.5), frames: 5, metrics: true, include: ["svg_d"] });
  assert.equal(res.method, "curvature");
  assert.equal(res.frames.length, 5);
  res.frames.forEach((f, i) => {
    const t = i / 4;
    assert.ok(Math.abs(f.t - t) < 1e-15);
    assert.ok(Math.abs(f.metrics.max_abs_kappa - 4 * Math.abs(1 - 1.5 * t)) < 1e-6, `t=${t}: ${f.metrics.max_abs_kappa}`);
    /* Bending energy: integral of (c s)^2 over [0, 4] = 64 c^2 / 3. */
    assert.ok(Math.abs(f.metrics.bending_energy - 64 * (1 - 1.5 * t) ** 2 / 3) < 1e-5);
    assert.ok(Math.abs(f.metrics.length - 4) < 1e-9);
    assert.equal(f.metrics.self_intersections, 0);
  });
  const paths = framePaths(res);
  assert.deepEqual(paths, res.frames.map((f) => f.curve.svg_d));
});

test("framePaths without svg_d converts every frame; its Béziers stay within the tolerance of the service's", async () => {
  const req = { from: spiral(1), to: spiral(-0.5), frames: 3, tolerance: 1e-6 };
  const a = await km.morph(req);
  const b = await km.morph({ ...req, include: ["svg_d"] });
  const mine = framePaths(a);
  assert.equal(mine.length, 3);
  mine.forEach((d, i) => {
    const theirs = bezierPoints(b.frames[i].curve.svg_d, 16);
    /* Every point of our path is near some point of the service's. */
    for (const [x, y] of bezierPoints(d, 4)) {
      let best = Infinity;
      for (const q of theirs) best = Math.min(best, Math.hypot(q[0] - x, q[1] - y));
      assert.ok(best < 0.02, `frame ${i}: ${best}`);
    }
  });
});

test("interpolator: circles of radius 1 and 3 give a circle of radius 2 at t = 1/2, between frames too", async () => {
  const res = await km.morph({ from: circleSvg(1), to: circleSvg(3), frames: 3, anchor: "centroid", tolerance: 1e-7 });
  const at = interpolator(res, { samples: 256 });
  const radiusSpread = (d) => {
    const pts = d.match(/-?\d*\.?\d+(?:e[-+]?\d+)?/gi).map(Number);
    const xy = [];
    for (let i = 0; i + 1 < pts.length; i += 2) xy.push([pts[i], pts[i + 1]]);
    const cx = xy.reduce((s, p) => s + p[0], 0) / xy.length, cy = xy.reduce((s, p) => s + p[1], 0) / xy.length;
    const rs = xy.map((p) => Math.hypot(p[0] - cx, p[1] - cy));
    return [Math.min(...rs), Math.max(...rs)];
  };
  const [lo, hi] = radiusSpread(at(0.5));
  assert.ok(lo > 2 - 1e-3 && hi < 2 + 1e-3, `radius ${lo}..${hi}`);
  /* Between frames the morph keeps the start point fixed relative to the
   * centre, so the blend of two concentric circles is concentric too. */
  const [lo2, hi2] = radiusSpread(at(0.25));
  assert.ok(lo2 > 1.5 - 2e-3 && hi2 < 1.5 + 2e-3, `radius at 1/4 ${lo2}..${hi2}`);
  assert.match(at(0), /Z$/);
  assert.equal(at(-1), at(0));
  assert.equal(interpolator(res, { exact: true })(1), curveToPath(res.frames[2].curve));
  const b = bounds(res);
  assert.ok(b[2] - b[0] >= 6 - 1e-6 && b[3] - b[1] >= 6 - 1e-6);
});

test("linear method of the spirals self-intersects where the curvature method does not (paper Fig. 4)", async () => {
  const req = { from: spiral(1), to: spiral(-0.5), frames: 5, metrics: true };
  const lin = await km.morph({ ...req, method: "linear" });
  const cur = await km.morph(req);
  assert.equal(lin.method, "linear");
  assert.ok(lin.frames.some((f) => f.metrics.self_intersections > 0));
  assert.ok(cur.frames.every((f) => f.metrics.self_intersections === 0));
});

test("morph as SVG returns an SVG document", async () => {
  const svg = await km.morph({ from: circleSvg(1), to: squareSvg(2), frames: 4, format: "svg", svg: { layout: "filmstrip" } });
  assert.equal(typeof svg, "string");
  assert.match(svg, /<svg[\s>]/);
  assert.equal((svg.match(/<path\b/g) || []).length >= 4, true);
});

test("morphJob reports rising progress to 1 and returns the same frames as the synchronous morph", async () => {
  const req = { from: circleSvg(10), to: squareSvg(15), frames: 400, metrics: true };
  const seen = [];
  const res = await km.morphJob(req, { onProgress: (s) => seen.push(s) });
  assert.ok(seen.length >= 2);
  assert.match(seen[0].id, /^[0-9a-f]{32}$/);
  for (let i = 1; i < seen.length; i++) assert.ok(seen[i].progress >= seen[i - 1].progress);
  const last = seen[seen.length - 1];
  assert.equal(last.state, "done");
  assert.equal(last.progress, 1);
  assert.equal(last.frames_total, 400);
  const sync = await km.morph(req);
  assert.equal(res.frames.length, 400);
  res.frames.forEach((f, i) => {
    assert.equal(f.t, sync.frames[i].t);
    assert.deepEqual(f.metrics, sync.frames[i].metrics);
  });
});

test("aborting morphJob rejects with the signal's reason and cancels the job on the service", async () => {
  const ac = new AbortController();
  let id = null;
  const req = { from: circleSvg(10), to: squareSvg(15), frames: 20000 };
  await assert.rejects(km.morphJob(req, { signal: ac.signal, onProgress: (s) => {
    id = s.id;
    if (s.state === "running" || s.state === "queued") ac.abort();
  } }), (e) => e.name === "AbortError");
  assert.ok(id);
  const s = await km.job(id);
  assert.equal(s.state, "cancelled");
  assert.ok(s.frames_done < 20000);
  await assert.rejects(km.jobResult(id), (e) => e instanceof KmorphError && e.status === 409);
});

test("an already aborted signal rejects before anything is sent", async () => {
  const ac = new AbortController();
  ac.abort();
  await assert.rejects(km.morph({ from: circleSvg(1), to: circleSvg(2) }, { signal: ac.signal }), (e) => e.name === "AbortError");
});

test("invalid input throws a KmorphError carrying the problem+json with a JSON pointer", async () => {
  const bad = { type: "bspline", degree: 3, knots: [0, 0, 0, 1, 1, 1], control_points: [[0, 0], [1, 1], [2, 0]] };
  await assert.rejects(km.morph({ from: circleSvg(1), to: bad }), (e) => {
    assert.ok(e instanceof KmorphError);
    assert.equal(e.status, 422);
    assert.equal(e.problem.status, 422);
    assert.equal(e.type, "/problems/invalid-curve");
    assert.ok(e.errors.some((x) => x.pointer.startsWith("/to")));
    assert.ok(e.messageFor("/to"));
    assert.equal(e.messageFor("/from"), null);
    assert.ok(e.requestId);
    return true;
  });
});

test("malformed JSON is a 400 problem; an unknown job is a 404 problem", async () => {
  await assert.rejects(km.request("POST", "/v1/morph", { body: "{\"from\": " }), (e) => e.status === 400 && e.problem.title !== undefined);
  await assert.rejects(km.job("0123456789abcdef0123456789abcdef"), (e) => e.status === 404);
  await assert.rejects(km.cancelJob("0123456789abcdef0123456789abcdef"), (e) => e.status === 404);
});

test("an unreachable service is a KmorphError with status 0 naming the address", async () => {
  const dead = new Client({ baseUrl: "http://127.0.0.1:9" });
  await assert.rejects(dead.health(), (e) => e instanceof KmorphError && e.status === 0 && /127\.0\.0\.1:9/.test(e.detail));
});

test("health and readiness answer ok and ready", async () => {
  assert.deepEqual(await km.health(), { status: "ok" });
  assert.deepEqual(await km.ready(), { status: "ready" });
});
