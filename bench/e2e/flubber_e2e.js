// flubber_e2e.js - flubber's per-frame figures on the single-contour pairs
// of the end-to-end bench (bench/e2e/run.py): at flubber's defaults
// (maxSegmentLength 10, string output) and at kmorph's accuracy.
//
// "Equal accuracy" sets maxSegmentLength so that a chord of the polygon
// strays at most the tolerance from the curve it replaces: kappa s^2 / 8
// <= tol, with kappa the largest curvature of the smooth parts measured on
// a dense sampling of the path (steps turning less than 0.2 rad; corners
// are not counted, so flubber's error at corners stays larger).
//
// Usage: node flubber_e2e.js PAIRS_JSON FRAMES
// PAIRS_JSON: [{"name", "a", "b", "tol"}]; prints one JSON line per pair:
// {"name", "default": {"us", "bytes", "points"}, "equal": {...,
// "max_segment"}}, where us, bytes and points are per frame.
'use strict';

const fs = require('fs');
const path = require('path');
const here = path.join(__dirname, '..', 'flubber');
const flubber = require(require.resolve('flubber', { paths: [here] }));
const { svgPathProperties } = require(
  require.resolve('svg-path-properties', { paths: [here] }));

function run(a, b, frames, options) {
  const t0 = process.hrtime.bigint();
  const interp = flubber.interpolate(a, b, options);
  let bytes = 0;
  for (let i = 0; i < frames; i++) bytes += interp(i / (frames - 1)).length;
  const us = Number(process.hrtime.bigint() - t0) / 1e3 / frames;
  const mid = flubber.interpolate(a, b, Object.assign({}, options,
                                                      { string: false }))(0.5);
  return { us, bytes: bytes / frames, points: mid.length };
}

function best(a, b, frames, options, runs) {
  let out = null;
  for (let r = 0; r < runs; r++) {
    const x = run(a, b, frames, options);
    if (out === null || x.us < out.us) out = x;
  }
  return out;
}

function maxSmoothCurvature(d) {
  const p = new svgPathProperties(d);
  const L = p.getTotalLength();
  const n = 20000, h = L / n;
  let kmax = 0, prev = null;
  for (let i = 0; i <= n; i++) {
    const t = p.getTangentAtLength(Math.min(i * h, L));
    const ang = Math.atan2(t.y, t.x);
    if (prev !== null) {
      let da = Math.abs(ang - prev);
      if (da > Math.PI) da = 2 * Math.PI - da;
      if (da < 0.2 && da / h > kmax) kmax = da / h;
    }
    prev = ang;
  }
  return kmax;
}

function main() {
  const pairs = JSON.parse(fs.readFileSync(process.argv[2], 'utf8'));
  const frames = Number(process.argv[3] || 1000);
  for (const pr of pairs) {
    best(pr.a, pr.b, 20, {}, 3); // warm the JIT on this pair
    const def = best(pr.a, pr.b, frames, {}, 3);
    const kappa = Math.max(maxSmoothCurvature(pr.a), maxSmoothCurvature(pr.b));
    const seg = kappa > 0 ? Math.sqrt(8 * pr.tol / kappa) : 10;
    const eqFrames = Math.max(10, Math.min(frames, 100));
    const eq = best(pr.a, pr.b, eqFrames, { maxSegmentLength: seg }, 1);
    eq.max_segment = seg;
    console.log(JSON.stringify({ name: pr.name, default: def, equal: eq }));
  }
}

main();
