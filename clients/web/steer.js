// steer.js - the direction and start point of a single curve, rewritten
// exactly in its own terms: an SVG path as absolute segments (reversed
// segment by segment, or started at another of its vertices, as GSAP's
// shapeIndex does), a points curve as its list of points. Curves of other
// kinds (B-splines, signatures, compound shapes) are not rewritten here.
import { pathCommands } from "./shapes.js";

/** The segments of a one-subpath SVG path as absolute pieces
 * {k: "L"|"Q"|"C"|"A", p: [points...], arc?}, from its start point, and
 * whether it is closed; null for a path of several subpaths. */
export function pathSegments(d) {
  const segs = [];
  let x = 0, y = 0, start = null, closed = false, prevC = null, prevQ = null;
  for (const [cmd, a] of pathCommands(d)) {
    const lower = cmd.toLowerCase(), rel = cmd === lower;
    const X = (v) => (rel ? x + v : v), Y = (v) => (rel ? y + v : v);
    if (closed && lower !== "m") return null;
    let ctrlC = null, ctrlQ = null;
    if (lower === "m") {
      if (segs.length) return null;
      x = X(a[0]); y = Y(a[1]);
      start = [x, y];
    } else if (lower === "z") {
      closed = true;
      if (x !== start[0] || y !== start[1]) segs.push({ k: "L", p: [[start[0], start[1]]] });
      x = start[0]; y = start[1];
    } else if (lower === "l" || lower === "h" || lower === "v") {
      const nx = lower === "v" ? x : X(a[0]), ny = lower === "h" ? y : lower === "v" ? Y(a[0]) : Y(a[1]);
      segs.push({ k: "L", p: [[nx, ny]] });
      x = nx; y = ny;
    } else if (lower === "c" || lower === "s") {
      const c1 = lower === "c" ? [X(a[0]), Y(a[1])] : prevC ? [2 * x - prevC[0], 2 * y - prevC[1]] : [x, y];
      const r = lower === "c" ? a.slice(2) : a;
      const c2 = [X(r[0]), Y(r[1])], e = [X(r[2]), Y(r[3])];
      segs.push({ k: "C", p: [c1, c2, e] });
      ctrlC = c2; x = e[0]; y = e[1];
    } else if (lower === "q" || lower === "t") {
      const c = lower === "q" ? [X(a[0]), Y(a[1])] : prevQ ? [2 * x - prevQ[0], 2 * y - prevQ[1]] : [x, y];
      const e = lower === "q" ? [X(a[2]), Y(a[3])] : [X(a[0]), Y(a[1])];
      segs.push({ k: "Q", p: [c, e] });
      ctrlQ = c; x = e[0]; y = e[1];
    } else if (lower === "a") {
      const e = [X(a[5]), Y(a[6])];
      segs.push({ k: "A", arc: a.slice(0, 5), p: [e] });
      x = e[0]; y = e[1];
    }
    prevC = ctrlC; prevQ = ctrlQ;
  }
  if (!start || !segs.length) return null;
  return { start, segs, closed };
}

const num = (v) => String(Math.round(v * 1e6) / 1e6);
const pt = (p) => `${num(p[0])},${num(p[1])}`;

function segmentsPath({ start, segs, closed }) {
  let d = "M" + pt(start);
  const last = segs[segs.length - 1];
  /* Z draws a last line back to the start */
  if (closed && segs.length > 1 && last.k === "L" && last.p[0][0] === start[0] && last.p[0][1] === start[1])
    segs = segs.slice(0, -1);
  for (const s of segs) {
    if (s.k === "A") d += ` A${s.arc.map(num).join(" ")} ${pt(s.p[0])}`;
    else d += ` ${s.k}${s.p.map(pt).join(" ")}`;
  }
  return closed ? d + " Z" : d;
}

/** The end point of segment i (the start point for i = -1). */
function endOf(path, i) { return i < 0 ? path.start : path.segs[i].p[path.segs[i].p.length - 1]; }

/** The same path run backwards: every segment reversed (control points
 * swapped, an arc's sweep flag flipped). */
export function reversePath(d) {
  const path = pathSegments(d);
  if (!path) return null;
  const n = path.segs.length, segs = [];
  for (let i = n - 1; i >= 0; i--) {
    const s = path.segs[i], from = endOf(path, i - 1);
    if (s.k === "L") segs.push({ k: "L", p: [from] });
    else if (s.k === "Q") segs.push({ k: "Q", p: [s.p[0], from] });
    else if (s.k === "C") segs.push({ k: "C", p: [s.p[1], s.p[0], from] });
    else segs.push({ k: "A", arc: [s.arc[0], s.arc[1], s.arc[2], s.arc[3], s.arc[4] ? 0 : 1], p: [from] });
  }
  return segmentsPath({ start: endOf(path, n - 1), segs, closed: path.closed });
}

/** A closed path started at its vertex k (mod the number of vertices)
 * instead of its first: the same curve, another seam. */
export function rotatePath(d, k) {
  const path = pathSegments(d);
  if (!path || !path.closed) return null;
  const n = path.segs.length, j = ((k % n) + n) % n;
  if (!j) return segmentsPath(path);
  const segs = [...path.segs.slice(j), ...path.segs.slice(0, j)];
  return segmentsPath({ start: endOf(path, j - 1), segs, closed: true });
}

/** The number of vertices a closed path can start at (0 when it cannot
 * be rewritten here). */
export function vertexCount(d) {
  const path = pathSegments(d);
  return path && path.closed ? path.segs.length : 0;
}

/** A curve object reversed or started elsewhere, or null when its kind
 * is not rewritten here. `how` is {reverse: true} or {rotate: k}. */
export function steerCurve(curve, how) {
  if (curve.type === "svg") {
    const d = how.reverse ? reversePath(curve.d) : rotatePath(curve.d, how.rotate);
    return d ? { type: "svg", d } : null;
  }
  if (curve.type === "points" && Array.isArray(curve.points) && curve.points.length > 1) {
    const pts = curve.points.slice();
    if (how.reverse) {
      /* a closed curve keeps its start point */
      if (curve.closed) pts.push(...pts.splice(1).reverse());
      else pts.reverse();
    } else {
      if (!curve.closed) return null;
      const j = ((how.rotate % pts.length) + pts.length) % pts.length;
      pts.push(...pts.splice(0, j));
    }
    return { ...curve, points: pts };
  }
  return null;
}

/** The points a closed curve can be started at (its vertices, in order
 * from its start), or [] when it cannot be rewritten here. */
export function startPoints(curve) {
  if (curve.type === "svg") {
    const path = pathSegments(curve.d);
    if (!path || !path.closed) return [];
    return path.segs.map((_, i) => endOf(path, i - 1));
  }
  if (curve.type === "points" && curve.closed && Array.isArray(curve.points)) return curve.points.slice();
  return [];
}
