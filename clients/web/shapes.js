// shapes.js - compound shapes on the page: SVG path data split into its
// subpaths (as the service counts them, so contour i here is contour i in
// `contour_matches_used`), the frames of a compound morph as slots, and
// colours that show which contour went to which.
import { curveToPath, samplePoints } from "./kmorph.js";

/* Arguments per command; a moveto's extra pairs are linetos. */
const ARITY = { m: 2, l: 2, h: 1, v: 1, c: 6, s: 4, q: 4, t: 2, a: 7, z: 0 };

/** The commands of SVG path data as [letter, numbers], or throws an Error
 * saying where the data stops making sense. Arc flags may be written
 * without separators ("a1 1 0 011 1"), as SVG allows. */
export function pathCommands(d) {
  const out = [];
  let i = 0, cmd = null;
  const skip = () => { while (i < d.length && /[\s,]/.test(d[i])) i++; };
  const number = () => {
    skip();
    const m = /^[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?/.exec(d.slice(i, i + 64));
    if (!m) throw new Error(`a number is expected at character ${i}`);
    i += m[0].length;
    return Number(m[0]);
  };
  const flag = () => {
    skip();
    if (d[i] !== "0" && d[i] !== "1") throw new Error(`an arc flag (0 or 1) is expected at character ${i}`);
    return Number(d[i++]);
  };
  for (skip(); i < d.length; skip()) {
    if (/[a-zA-Z]/.test(d[i])) {
      cmd = d[i++];
      if (!(cmd.toLowerCase() in ARITY)) throw new Error(`unknown path command "${cmd}" at character ${i - 1}`);
      if (cmd.toLowerCase() === "z") { out.push([cmd, []]); continue; }
    } else if (cmd === null) {
      throw new Error("path data must start with M");
    } else if (cmd.toLowerCase() === "z") {
      throw new Error(`a command is expected at character ${i}`);
    }
    const lower = cmd.toLowerCase(), args = [];
    for (let k = 0; k < ARITY[lower]; k++) args.push(lower === "a" && (k === 3 || k === 4) ? flag() : number());
    out.push([cmd, args]);
    if (lower === "m") cmd = cmd === "m" ? "l" : "L";
  }
  return out;
}

/** The subpaths of SVG path data that draw something, each as path data
 * of its own starting with an absolute moveto, with whether it is closed
 * by Z, its start and end points and the box of its command end points.
 * Movetos that draw nothing are left out, as the service does. */
export function splitSubpaths(d) {
  const subpaths = [];
  let x = 0, y = 0, sx = 0, sy = 0, current = null;
  const finish = () => {
    if (current && current.draws)
      subpaths.push({ d: current.text.trim(), closed: current.closed, start: [sx, sy], end: [x, y], box: current.box });
    current = null;
  };
  const begin = () => { current = { text: `M${sx},${sy}`, draws: false, closed: false, box: [sx, sy, sx, sy] }; };
  for (const [cmd, a] of pathCommands(d)) {
    const lower = cmd.toLowerCase(), rel = cmd === lower;
    if (lower === "m") {
      finish();
      x = rel ? x + a[0] : a[0];
      y = rel ? y + a[1] : a[1];
      sx = x; sy = y;
      begin();
      continue;
    }
    if (!current || current.closed) { finish(); begin(); }
    current.text += " " + cmd + a.join(" ");
    current.draws = true;
    if (lower === "z") { current.closed = true; x = sx; y = sy; continue; }
    if (lower === "h") x = rel ? x + a[0] : a[0];
    else if (lower === "v") y = rel ? y + a[0] : a[0];
    else {
      const ex = a[a.length - 2], ey = a[a.length - 1];
      x = rel ? x + ex : ex;
      y = rel ? y + ey : ey;
    }
    const b = current.box;
    current.box = [Math.min(b[0], x), Math.min(b[1], y), Math.max(b[2], x), Math.max(b[3], y)];
  }
  finish();
  return subpaths;
}

/** Distinct colours for the pairs of contours, in slot order. */
export const SLOT_COLOURS = ["#1f6fd1", "#d1571f", "#2a9d3f", "#9b3fd1", "#c9a000", "#0fa3a3",
                             "#d13f8a", "#6b6b00", "#3f51d1", "#8a4b1f"];
export function slotColour(k) { return SLOT_COLOURS[k % SLOT_COLOURS.length]; }

/** Whether a morph result is of compound shapes (its frames have slots). */
export function isShapeResult(result) {
  return !!(result && result.frames.length && Array.isArray(result.frames[0].contours));
}

/** The path data of one frame: the service's svg_d when asked for, else
 * every present slot's contour converted here. */
export function framePath(frame) {
  if (frame.curve) return frame.curve.svg_d || curveToPath(frame.curve);
  if (frame.svg_d) return frame.svg_d;
  return frame.contours.filter(Boolean).map((c) => curveToPath(c)).join("");
}

/** The metrics of a frame of either kind, folded for the page: for a
 * compound frame the sum of lengths, bending energies and
 * self-intersections and the largest |kappa| and closure gap of its
 * contours, with the crossings between contours and the nesting check. */
export function frameMetrics(frame) {
  const m = frame.metrics;
  if (!m) return {};
  if (!m.contours) return m;
  const present = m.contours.filter(Boolean);
  const sum = (k) => present.reduce((s, c) => s + c[k], 0);
  const max = (k) => present.reduce((s, c) => Math.max(s, c[k]), 0);
  return { length: sum("length"), max_abs_kappa: max("max_abs_kappa"), bending_energy: sum("bending_energy"),
           self_intersections: sum("self_intersections"), closure_gap: max("closure_gap"),
           mutual_intersections: m.mutual_intersections, nesting_ok: m.nesting_ok };
}

/** A frame's metrics say something is wrong with its drawing. */
export function frameIsBad(m) {
  return m.self_intersections > 0 || m.mutual_intersections > 0 || m.nesting_ok === false;
}

/** Bounding box [minX, minY, maxX, maxY] of every frame's control
 * polygons (which contain the curves), for either kind of result. */
export function resultBounds(result) {
  let b = [Infinity, Infinity, -Infinity, -Infinity];
  for (const f of result.frames)
    for (const c of f.contours || [f.curve])
      if (c) for (const [x, y] of c.control_points)
        b = [Math.min(b[0], x), Math.min(b[1], y), Math.max(b[2], x), Math.max(b[3], y)];
  return b;
}

/** n points at equal arc-length fractions of a slot's contour, or, for a
 * slot collapsed to a point in this frame, the partner frame's points all
 * at their centroid (the point it shrinks into or grows from). */
export function slotPoints(curve, partner, n) {
  if (curve) return samplePoints(curve, n);
  const pts = samplePoints(partner, n);
  const cx = pts.reduce((s, p) => s + p[0], 0) / n, cy = pts.reduce((s, p) => s + p[1], 0) / n;
  return pts.map(() => [cx, cy]);
}
