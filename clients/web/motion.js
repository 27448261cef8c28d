// motion.js - timing and export of the page's morphs: easing curves
// (CSS cubic-bezier), and the frames as CSS @keyframes with d: path(),
// as an SVG <animate>, and as a list of d strings, all with one command
// structure so that browsers can interpolate between them.
import { samplePoints } from "./kmorph.js";

/** The named easings as CSS cubic-bezier control points. */
export const EASINGS = {
  linear: [0, 0, 1, 1],
  "ease-in-out": [0.42, 0, 0.58, 1],
  "ease-in": [0.42, 0, 1, 1],
  "ease-out": [0, 0, 0.58, 1],
};

/** Control points of an easing: a name above or "x1,y1,x2,y2" (x in
 * [0, 1]); null when the text is neither. */
export function parseEasing(text) {
  if (EASINGS[text]) return EASINGS[text];
  const v = String(text).replace(/^cubic-bezier\(|\)$/g, "").split(/[\s,]+/).filter(Boolean).map(Number);
  if (v.length !== 4 || !v.every(Number.isFinite) || v[0] < 0 || v[0] > 1 || v[2] < 0 || v[2] > 1) return null;
  return v;
}

function bezier(a, b, u) { /* one coordinate of the curve from 0 through a, b to 1 */
  const m = 1 - u;
  return 3 * m * m * u * a + 3 * m * u * u * b + u * u * u;
}

/** The eased progress y for progress x in [0, 1] (x(u) = x solved by
 * bisection: x(u) is monotone for x1, x2 in [0, 1]). */
export function ease(points, x) {
  const [x1, y1, x2, y2] = points;
  if (x <= 0 || x >= 1) return Math.min(1, Math.max(0, x));
  let lo = 0, hi = 1;
  for (let i = 0; i < 60; i++) {
    const mid = 0.5 * (lo + hi);
    if (bezier(x1, x2, mid) < x) lo = mid; else hi = mid;
  }
  return bezier(y1, y2, 0.5 * (lo + hi));
}

/** The progress x at which the easing reaches y (y(u) may be non-monotone
 * for y outside [0, 1]; the first crossing on a fine grid, refined). */
export function easeInverse(points, y) {
  if (y <= 0) return 0;
  if (y >= 1) return 1;
  const n = 2000;
  let prev = 0;
  for (let i = 1; i <= n; i++) {
    const x = i / n, v = ease(points, x);
    if (v >= y) {
      let lo = prev, hi = x;
      for (let k = 0; k < 50; k++) {
        const mid = 0.5 * (lo + hi);
        if (ease(points, mid) < y) lo = mid; else hi = mid;
      }
      return 0.5 * (lo + hi);
    }
    prev = x;
  }
  return 1;
}

const num = (v) => {
  const r = Math.round(v * 1000) / 1000;
  return Object.is(r, -0) ? "0" : String(r);
};

/** One d per frame with the same commands (M, L..., Z per contour): each
 * contour resampled at `samples` equal arc-length fractions; a contour
 * absent from a frame (collapsed) drawn at the centroid of its nearest
 * present frame, so it shrinks into or grows from that point. */
export function sameStructurePaths(result, samples = 120) {
  const frames = result.frames;
  const slots = frames[0].contours ? frames[0].contours.length : 1;
  const perSlot = [];
  for (let k = 0; k < slots; k++) {
    const pts = frames.map((f) => {
      const c = f.contours ? f.contours[k] : f.curve;
      return c ? samplePoints(c, samples) : null;
    });
    const closed = frames.map((f) => (f.contours ? true : !!f.curve.closed));
    for (let i = 0; i < pts.length; i++) {
      if (pts[i]) continue;
      let j = 1;
      while (!pts[i - j] && !pts[i + j] && j < pts.length) j++;
      const near = pts[i - j] || pts[i + j];
      if (!near) continue;
      const cx = near.reduce((s, p) => s + p[0], 0) / near.length, cy = near.reduce((s, p) => s + p[1], 0) / near.length;
      pts[i] = near.map(() => [cx, cy]);
    }
    perSlot.push(pts.map((p, i) => {
      if (!p) return "";
      const end = closed[i] ? p.length - 1 : p.length;
      let d = `M${num(p[0][0])},${num(p[0][1])}`;
      for (let j = 1; j < end; j++) d += `L${num(p[j][0])},${num(p[j][1])}`;
      return closed[i] ? d + "Z" : d;
    }));
  }
  return frames.map((_, i) => perSlot.map((s) => s[i]).join(""));
}

/** Where each frame falls in the animation's time (0..1) so that, run at
 * linear timing between keyframes, frame time t is reached at the eased
 * moment: the inverse of the easing. */
export function keyTimes(result, easing) {
  return result.frames.map((f) => easeInverse(easing, f.t));
}

/** CSS @keyframes animating `d: path(...)`, and a rule applying it. */
export function cssKeyframes(result, { duration = 3, easing = EASINGS.linear, pingPong = false, name = "kmorph" } = {}) {
  const ds = sameStructurePaths(result), kt = keyTimes(result, easing);
  let css = `@keyframes ${name} {\n`;
  ds.forEach((d, i) => { css += `  ${num(kt[i] * 100)}% { d: path("${d}"); }\n`; });
  css += "}\n";
  css += `.${name} { animation: ${name} ${duration}s linear infinite${pingPong ? " alternate" : ""}; }\n`;
  return css;
}

/** An SVG <path> with an <animate> of its d over the frames. */
export function svgAnimate(result, { duration = 3, easing = EASINGS.linear, pingPong = false, fillRule = "nonzero" } = {}) {
  let ds = sameStructurePaths(result), kt = keyTimes(result, easing);
  if (pingPong) {
    /* there and back in twice the time */
    ds = [...ds, ...ds.slice(0, -1).reverse()];
    kt = [...kt.map((k) => k / 2), ...kt.slice(0, -1).reverse().map((k) => 1 - k / 2)];
  }
  return `<path fill-rule="${fillRule}" d="${ds[0]}">\n  <animate attributeName="d" dur="${pingPong ? 2 * duration : duration}s" ` +
         `repeatCount="indefinite" calcMode="linear"\n    keyTimes="${kt.map(num).join(";")}"\n    values="${ds.join(";\n")}"/>\n</path>\n`;
}

/** The frames' d strings (same structure) as JSON, with their times. */
export function dList(result) {
  const ds = sameStructurePaths(result);
  return JSON.stringify(result.frames.map((f, i) => ({ t: f.t, d: ds[i] })), null, 1);
}
