// plot.js - the curvature plot of a morph, kappa_t against s / L_t, drawn
// on the page from the frames themselves. Its scale ignores rounding noise
// (a polygon's edges have kappa 0, not +-1e-17 drawn as waves) and clips
// spikes (a cusp of a linear frame would flatten everything else), marking
// where it clips.
import { evalCurve } from "./kmorph.js";

const SVGNS = "http://www.w3.org/2000/svg";
/* Samples per knot span; relative step of the second derivative. */
const PER_SPAN = 24, DIFF = 1e-5;
/* |kappa| below this fraction of 2 pi / L is rounding: drawn as 0. */
const NOISE = 1e-9;
/* A largest |kappa| above SPIKE times the 95th percentile is clipped at
 * CLIP times that percentile. */
const SPIKE = 4, CLIP = 2;

/** Samples {s, kappa} of a curve (s as a fraction of its length, kappa
 * from the first derivative and a central difference of it, one-sided at
 * span ends), and its length. kappa is Infinity where the speed vanishes. */
export function curvatureSamples(curve) {
  const p = curve.degree, U = curve.knots, n = curve.control_points.length;
  const out = [];
  let s = 0, prev = null;
  for (let k = p; k < n; k++) {
    const a = U[k], b = U[k + 1];
    if (!(b > a)) continue;
    const h = (b - a) * DIFF;
    for (let j = prev === null ? 0 : 1; j <= PER_SPAN; j++) {
      const u = a + (b - a) * j / PER_SPAN;
      const u0 = Math.max(a, u - h), u1 = Math.min(b, u + h);
      const [, d] = evalCurve(curve, u, k);
      const d0 = evalCurve(curve, u0, k)[1], d1 = evalCurve(curve, u1, k)[1];
      const dd = [(d1[0] - d0[0]) / (u1 - u0), (d1[1] - d0[1]) / (u1 - u0)];
      const speed = Math.hypot(d[0], d[1]);
      const kappa = speed > 0 ? (d[0] * dd[1] - d[1] * dd[0]) / (speed * speed * speed) : Infinity;
      if (prev !== null) s += 0.5 * (prev.speed + speed) * (u - prev.u);
      prev = { u, speed };
      out.push({ s, kappa });
    }
  }
  const length = s;
  for (const q of out) q.s = length > 0 ? q.s / length : 0;
  return { samples: out, length };
}

/** The vertical range of the plot: {range, clipped, flat, peak} from all
 * |kappa| values and the mean length of the curves. */
export function plotScale(values, meanLength) {
  const ref = 2 * Math.PI / (meanLength || 1);
  const finite = values.filter(Number.isFinite).map(Math.abs).sort((x, y) => x - y);
  const peak = values.some((v) => !Number.isFinite(v)) ? Infinity : (finite[finite.length - 1] || 0);
  if (!(peak > NOISE * ref)) return { range: ref, clipped: false, flat: true, peak };
  const q95 = finite[Math.min(finite.length - 1, Math.floor(0.95 * finite.length))] || 0;
  if (peak > SPIKE * q95 && q95 > NOISE * ref)
    return { range: CLIP * q95, clipped: true, flat: false, peak };
  return { range: 1.05 * peak, clipped: false, flat: false, peak };
}

function el(name, attrs, parent) {
  const e = document.createElementNS(SVGNS, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}

function short(v) {
  if (!Number.isFinite(v)) return "∞";
  return Math.abs(v) >= 1e4 || (v !== 0 && Math.abs(v) < 1e-3) ? v.toExponential(2) : String(Number(v.toPrecision(3)));
}

/** An <svg> of kappa_t(s / L_t) for the given curves: [{curve, colour, t}]. */
export function curvaturePlot(curves, { width = 600, height = 220 } = {}) {
  const W = width, H = height, left = 56, right = 10, top = 12, bottom = 26;
  const sampled = curves.map((c) => ({ ...c, ...curvatureSamples(c.curve) }));
  const meanLength = sampled.reduce((sum, c) => sum + c.length, 0) / Math.max(1, sampled.length);
  const scale = plotScale(sampled.flatMap((c) => c.samples.map((q) => q.kappa)), meanLength);
  const R = scale.range, mid = top + (H - top - bottom) / 2, half = (H - top - bottom) / 2;
  const X = (s) => left + s * (W - left - right);
  const Y = (k) => mid - (Math.max(-R, Math.min(R, k)) / R) * half;
  const svg = el("svg", { viewBox: `0 0 ${W} ${H}`, class: "kappa-plot", role: "img",
                          "data-range": R, "data-clipped": scale.clipped ? "1" : "0", "data-flat": scale.flat ? "1" : "0",
                          "data-zero-y": mid });
  el("title", {}, svg).textContent = scale.flat
    ? "curvature: 0 along every piece (straight edges; corners are turns, not curvature)"
    : `curvature κ against s / L${scale.clipped ? `, clipped at ±${short(R)} (peaks up to ${short(scale.peak)})` : ""}`;
  el("line", { x1: left, x2: W - right, y1: mid, y2: mid, class: "axis" }, svg);
  el("line", { x1: left, x2: left, y1: top, y2: H - bottom, class: "axis" }, svg);
  for (const [k, label] of [[R, `${scale.clipped ? "≥ " : ""}${short(R)}`], [0, "0"], [-R, `${scale.clipped ? "≤ " : ""}${short(-R)}`]])
    el("text", { x: left - 4, y: Y(k) + 4, "text-anchor": "end", class: "tick" }, svg).textContent = label;
  for (const [s, label] of [[0, "0"], [0.5, "s / L"], [1, "1"]])
    el("text", { x: X(s), y: H - 8, "text-anchor": "middle", class: "tick" }, svg).textContent = label;
  for (const c of sampled) {
    const pts = c.samples.map((q) => `${X(q.s).toFixed(2)},${Y(Number.isFinite(q.kappa) ? q.kappa : Math.sign(q.kappa) * R || R).toFixed(2)}`);
    el("polyline", { points: pts.join(" "), class: "kappa", "data-t": c.t, style: `stroke: ${c.colour}` }, svg);
    if (!scale.clipped) continue;
    /* a mark at each run of clipped samples: the drawing breaks there */
    let inRun = false;
    for (const q of c.samples) {
      const over = !(Math.abs(q.kappa) <= R);
      if (over && !inRun) {
        const x = X(q.s), y = q.kappa > 0 ? top : H - bottom, dy = q.kappa > 0 ? 5 : -5;
        el("path", { d: `M${x - 5},${y + dy} L${x - 2},${y} L${x + 2},${y + dy} L${x + 5},${y}`, class: "clip-mark" }, svg);
      }
      inRun = over;
    }
  }
  if (scale.clipped)
    el("text", { x: W - right, y: top + 10, "text-anchor": "end", class: "tick clip-note" }, svg).textContent =
      `clipped at ±${short(R)}; peaks up to ${short(scale.peak)}`;
  return svg;
}
