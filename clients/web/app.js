// app.js - the kmorph page: choose, paste or draw two curves, morph them
// with the curvature method and the linear baseline (synchronously, or as
// jobs with a progress bar for long morphs), then play, scrub and inspect
// the frames. All service calls go through kmorph.js.
import { Client, KmorphError, curveToPath, samplePoints } from "./kmorph.js";
import { CURVES, PAIRS } from "./examples.js";
import { splitSubpaths, slotColour, isShapeResult, framePath, frameMetrics, frameIsBad, resultBounds,
         slotPoints } from "./shapes.js";
import { curvaturePlot } from "./plot.js";
import { steerCurve, startPoints } from "./steer.js";
import { parseEasing, ease, easeInverse, cssKeyframes, svgAnimate, dList, EASINGS } from "./motion.js";

const km = new Client();
const $ = (sel, root = document) => root.querySelector(sel);
const SVGNS = "http://www.w3.org/2000/svg";

/* Above this many frames a morph goes through the job API. */
const JOB_FRAMES = 150;
/* Filmstrip thumbnails at most (evenly chosen frames beyond that). */
const FILM_MAX = 40;
/* Frames of the curvature plot at most (a subset of the morph's times). */
const PLOT_MAX = 21;

const state = {
  input: { from: null, to: null },      /* parsed curve objects */
  /* each input as the editor draws it: {contours: [d], closed, compound,
   * fillRule}, or null */
  display: { from: null, to: null },
  contourMatches: null,                 /* contour_matches_used of the shown morph */
  drawing: null,                        /* "from" | "to" while clicking points */
  drawn: { from: [], to: [] },
  picking: false,
  pending: null,                        /* a picked fraction on `from` awaiting its partner */
  matches: [],
  /* the correspondence the shown morph used, in fractions of the editor's
   * paths: {pairs: [[a, b]], start: {from, to}, dir: {from, to}} */
  used: null,
  sentPin: false,                       /* the morph got [[0.5, 0.5]] only to keep the starts */
  drag: null,                           /* {index, side} while a used match is dragged */
  results: [],                          /* [{method, result, request}] */
  panels: [],
  t: 0,
  playing: false,
  controller: null,
};

// ------------------------------------------------------------ curve input

/** A curve object from the text of a curve field (SVG d or JSON). Throws
 * an Error with a readable message. */
function parseCurve(text) {
  const s = text.trim();
  if (!s) throw new Error("give a curve: an SVG path d string or a JSON curve");
  if (s.startsWith("{")) {
    let o;
    try { o = JSON.parse(s); } catch (e) { throw new Error("not valid JSON: " + e.message); }
    if (o.type) return o;
    if (o.signature) return { type: "signature", signature: o.signature };
    if (o.kappa) return { type: "signature", signature: o };
    if (o.control_points) return { type: "bspline", ...o };
    throw new Error("a JSON curve needs type, signature, kappa or control_points");
  }
  if (!/^[Mm]/.test(s)) throw new Error("an SVG path must start with M (or paste a JSON curve)");
  let subpaths;
  try { subpaths = splitSubpaths(s); } catch (e) { throw new Error("SVG path: " + e.message); }
  if (!subpaths.length) throw new Error("SVG path: it draws nothing (a moveto alone)");
  if (subpaths.length > 1) {
    const open = subpaths.findIndex((p) => !p.closed);
    if (open >= 0) throw new Error(`SVG path: subpath ${open + 1} of ${subpaths.length} is not closed by Z (each contour of a compound shape must be)`);
  }
  return { type: "svg", d: s };
}

/* A path whose end is this close to its start (relative to its size) is
 * closed when sent; one within CLOSE_OFFER is offered a Z. */
const CLOSE_AUTO = 1e-6, CLOSE_OFFER = 0.05;

/** How far a single open SVG path ends from its start: {gap, size}, or
 * null for closed, compound or other curves. */
function openGap(curve) {
  if (!curve || curve.type !== "svg") return null;
  let subpaths;
  try { subpaths = splitSubpaths(curve.d); } catch { return null; }
  if (subpaths.length !== 1 || subpaths[0].closed) return null;
  const { start, end, box } = subpaths[0];
  return { gap: Math.hypot(end[0] - start[0], end[1] - start[1]), size: Math.hypot(box[2] - box[0], box[3] - box[1]) };
}

/** The curve as it is sent: an SVG path that returns to its start
 * within rounding is closed with Z (its frames would explode open). */
function sentCurve(curve) {
  const g = openGap(curve);
  return g && g.gap <= CLOSE_AUTO * g.size ? { ...curve, d: curve.d.trimEnd() + " Z" } : curve;
}

/** The note under a curve field about closing it, and the closed box. */
function updateClosedNote(which) {
  const curve = state.input[which], note = $("#note-" + which), box = $(`.draw-closed[data-which=${which}]`);
  note.replaceChildren();
  if (curve && curve.type === "svg") {
    box.checked = /z\s*$/i.test(curve.d);
    box.disabled = !!(state.display[which] && state.display[which].compound);
  } else box.disabled = false;
  const g = openGap(curve);
  if (!g || g.gap > CLOSE_OFFER * g.size) return;
  if (g.gap <= CLOSE_AUTO * g.size) {
    note.textContent = "This path ends where it starts: it is sent closed (Z added).";
    return;
  }
  note.append(`This path ends ${fmt(g.gap)} from its start and is open. `);
  const btn = document.createElement("button");
  btn.type = "button";
  btn.className = "close-path";
  btn.textContent = "Close it with Z";
  btn.addEventListener("click", () => setClosed(which, true));
  note.appendChild(btn);
}

/** Close (Z at the end) or open a single SVG path in its field. */
function setClosed(which, closed) {
  const ta = $("#curve-" + which), text = ta.value.trimEnd();
  if (text.startsWith("{")) {
    try {
      const c = JSON.parse(text);
      if (c.type === "points" || c.type === "bspline") { c.closed = closed; ta.value = JSON.stringify(c); }
    } catch { /* the field's own error says what is wrong */ }
  } else if (closed && !/z$/i.test(text)) ta.value = text + " Z";
  else if (!closed) ta.value = text.replace(/\s*[zZ]$/, "");
  updateCurve(which);
}

function curveText(curve) {
  return curve.type === "svg" ? curve.d : JSON.stringify(curve);
}

function setFieldError(which, message) {
  const el = $("#error-" + which);
  el.textContent = message || "";
  const field = which === "from" || which === "to" ? $("#field-" + which) : null;
  if (field) field.classList.toggle("has-error", !!message);
}

/** An input as the editor draws it: one path per contour (a compound
 * shape's subpaths or contours, else the curve itself), whether every
 * contour is closed, and the fill rule. */
async function displayShape(curve) {
  if (curve.type === "shape") {
    const contours = (curve.contours || []).map((c) => contourPath(c));
    return { contours, closed: true, compound: true, fillRule: curve.fill_rule || "nonzero" };
  }
  if (curve.type === "svg") {
    let subpaths = null;
    try { subpaths = splitSubpaths(curve.d); } catch { subpaths = null; /* the service says what is wrong */ }
    if (subpaths && subpaths.length > 1)
      return { contours: subpaths.map((p) => p.d), closed: subpaths.every((p) => p.closed), compound: true,
               fillRule: "nonzero" };
    return single(curve.d, /z\s*$/i.test(curve.d));
  }
  const d = await displayPath(curve);
  return single(d, curve.type === "bspline" ? !!curve.closed : /z\s*$/i.test(d));
}

function single(d, closed) { return { contours: [d], closed, compound: false, fillRule: "nonzero" }; }

function contourPath(c) {
  if (!c || typeof c !== "object") return "";
  if (c.type === "svg") return typeof c.d === "string" ? c.d : "";
  if (c.type === "bspline") { try { return curveToPath(c); } catch { return ""; } }
  if (c.type === "points" && Array.isArray(c.points)) return pointsPath(c.points, true);
  return "";
}

/** The SVG d to show for a single curve: the B-spline drawn here, or
 * (signatures and fitted points) the service's reconstruction. */
async function displayPath(curve) {
  if (curve.type === "bspline") return curveToPath(curve);
  let sig = curve.signature;
  if (curve.type === "points") {
    try {
      sig = (await km.signature(curve)).signature;
    } catch (e) { throw retarget(e, "/curve", ""); }
  }
  try {
    return (await km.reconstruct(sig, { include: ["svg_d"] })).curve.svg_d;
  } catch (e) { throw retarget(e, "/signature", curve.type === "signature" ? "/signature" : ""); }
}

/* Problems about a helper request point at its own fields; say it the
 * way the curve field understands. */
function retarget(e, from, to) {
  if (e instanceof KmorphError)
    e.errors = e.errors.map((x) => ({ ...x, pointer: (x.pointer || "").replace(from, to) }));
  return e;
}

let previewSeq = { from: 0, to: 0 };
async function updateCurve(which) {
  const seq = ++previewSeq[which];
  const text = $("#curve-" + which).value;
  let curve;
  try {
    curve = parseCurve(text);
  } catch (e) {
    state.input[which] = null;
    state.display[which] = null;
    setFieldError(which, e.message);
    updateClosedNote(which);
    renderEditor();
    return;
  }
  const changed = JSON.stringify(curve) !== JSON.stringify(state.input[which]);
  state.input[which] = curve;
  if (changed) forgetMatches();
  if (changed && state.pairError) {
    /* a fault of the pair is gone with either curve changed */
    state.pairError = false;
    setFieldError(which === "from" ? "to" : "from", "");
  }
  try {
    const shown = await displayShape(curve);
    if (seq !== previewSeq[which]) return;
    state.display[which] = shown;
    setFieldError(which, "");
  } catch (e) {
    if (seq !== previewSeq[which]) return;
    state.display[which] = curve.type === "points" ? single(pointsPath(curve.points, curve.closed), !!curve.closed) : null;
    setFieldError(which, problemText(e));
  }
  updateClosedNote(which);
  renderEditor();
}

function pointsPath(pts, closed) {
  if (!pts.length) return "";
  return "M" + pts.map((p) => `${p[0]},${p[1]}`).join("L") + (closed ? "Z" : "");
}

function problemText(e) {
  if (e instanceof KmorphError) {
    const lines = [`${e.title || "Error"}${e.status ? ` (${e.status})` : ""}: ${e.detail}`];
    return lines.join("\n");
  }
  return e && e.message ? e.message : String(e);
}

// ----------------------------------------------------------------- editor

function svgEl(name, attrs = {}, parent) {
  const el = document.createElementNS(SVGNS, name);
  for (const [k, v] of Object.entries(attrs)) el.setAttribute(k, v);
  if (parent) parent.appendChild(el);
  return el;
}

function renderEditor() {
  const svg = $("#editor"), g = $("#editor-content");
  g.replaceChildren();
  const compound = isCompound();
  for (const which of ["from", "to"]) {
    if (state.drawing === which) {
      const d = pointsPath(state.drawn[which], $(`.draw-closed[data-which=${which}]`).checked);
      if (d) svgEl("path", { d, class: which, "data-which": which }, g);
      continue;
    }
    const shown = state.display[which];
    if (!shown || !shown.contours.some(Boolean)) continue;
    /* a closed single curve against a compound shape is a shape of one contour */
    const outlined = shown.compound || (compound && shown.closed);
    /* One path of every contour, filled under the fill rule (holes show as
     * holes); a compound shape's contours are outlined one by one in the
     * colour of their pair. */
    svgEl("path", { d: shown.contours.join(" "), class: `${which}${shown.closed ? " fillable" : ""}${outlined ? " shape" : ""}`,
                    "data-which": which, "fill-rule": shown.fillRule }, g);
    if (outlined)
      shown.contours.forEach((d, i) => svgEl("path", { d, class: "contour", "data-which": which, "data-contour": i,
                                                       style: `stroke: ${contourColour(which, i)}` }, g));
  }
  if (!state.drawing) fitViewBox(svg, g);
  const r = viewScale(svg) * 4;
  if (state.drawing)
    for (const p of state.drawn[state.drawing]) svgEl("circle", { cx: p[0], cy: p[1], r, class: "ctrl" }, g);
  for (const [a, b] of state.matches) {
    const pa = pointAt("from", a), pb = pointAt("to", b);
    if (!pa || !pb) continue;
    svgEl("line", { x1: pa.x, y1: pa.y, x2: pb.x, y2: pb.y, class: "match" }, g);
    svgEl("circle", { cx: pa.x, cy: pa.y, r, class: "match", fill: "var(--from)" }, g);
    svgEl("circle", { cx: pb.x, cy: pb.y, r, class: "match", fill: "var(--to)" }, g);
  }
  if (state.pending != null) {
    const p = pointAt("from", state.pending);
    if (p) svgEl("circle", { cx: p.x, cy: p.y, r: r * 1.5, class: "match", fill: "var(--from)" }, g);
  }
  if (!state.drawing && !compound) {
    renderStartHelpers(g, r);
    renderUsed(g, r);
  }
  renderMatchList();
}

/** Where each curve starts and which way it runs, as the morph takes it:
 * the service's chosen start after a morph, else the curve's own. */
function renderStartHelpers(g, r) {
  for (const which of ["from", "to"]) {
    if (!pathOf(which)) continue;
    const f = state.used ? state.used.start[which] : 0, dir = state.used ? state.used.dir[which] : 1;
    const p0 = pointAt(which, f), p1 = pointAt(which, wrap01(f + dir * 0.04));
    if (!p0 || !p1) continue;
    const colour = which === "from" ? "var(--from)" : "var(--to)";
    svgEl("circle", { cx: p0.x, cy: p0.y, r: r * 1.6, class: "start", "data-which": which, stroke: colour }, g);
    const dx = p1.x - p0.x, dy = p1.y - p0.y, len = Math.hypot(dx, dy) || 1, ux = dx / len, uy = dy / len;
    /* an arrowhead at p1 along the chord from the start */
    const a = r * 3, w = r * 1.6;
    svgEl("path", { d: `M${p0.x},${p0.y}L${p1.x},${p1.y}M${p1.x - a * ux + w * uy},${p1.y - a * uy - w * ux}` +
                       `L${p1.x},${p1.y}L${p1.x - a * ux - w * uy},${p1.y - a * uy + w * ux}`,
                    class: "direction", "data-which": which, stroke: colour }, g);
  }
}

/** The matches the shown morph used, as handles that can be dragged
 * along their curve (or moved with the arrow keys); letting go morphs
 * again with them as picked pairs. */
function renderUsed(g, r) {
  if (!state.used) return;
  state.used.pairs.forEach(([a, b], i) => {
    const pa = pointAt("from", a), pb = pointAt("to", b);
    if (!pa || !pb) return;
    svgEl("line", { x1: pa.x, y1: pa.y, x2: pb.x, y2: pb.y, class: "used" }, g);
    [[pa, "from", a], [pb, "to", b]].forEach(([p, side, f]) => {
      const c = svgEl("circle", { cx: p.x, cy: p.y, r: r * 1.8, class: "used", "data-which": side, "data-index": i,
                                  tabindex: "0", role: "slider", "aria-valuemin": "0", "aria-valuemax": "1",
                                  "aria-valuenow": f.toFixed(4),
                                  "aria-label": `match ${i + 1} on the ${side} curve (arrow keys move it, Enter morphs)`,
                                  fill: side === "from" ? "var(--from)" : "var(--to)" }, g);
      c.addEventListener("pointerdown", (ev) => startDrag(ev, i, side));
      c.addEventListener("keydown", (ev) => keyDrag(ev, i, side));
    });
  });
}

const wrap01 = (f) => ((f % 1) + 1) % 1;

function startDrag(ev, index, side) {
  if (state.drawing || state.picking) return;
  ev.preventDefault();
  ev.stopPropagation();
  state.drag = { index, side };
  $("#editor").setPointerCapture(ev.pointerId);
}

function onDragMove(ev) {
  if (!state.drag) return;
  const [x, y] = editorPoint(ev);
  const f = nearestFraction(state.drag.side, x, y);
  if (f == null) return;
  state.used.pairs[state.drag.index][state.drag.side === "from" ? 0 : 1] = f;
  renderEditor();
}

function onDragEnd() {
  if (!state.drag) return;
  state.drag = null;
  state.suppressClick = true;
  useMatchesAsPicked();
}

function keyDrag(ev, index, side) {
  const step = { ArrowLeft: -0.005, ArrowDown: -0.005, ArrowRight: 0.005, ArrowUp: 0.005 }[ev.key];
  if (ev.key === "Enter") { ev.preventDefault(); useMatchesAsPicked(); return; }
  if (step === undefined) return;
  ev.preventDefault();
  ev.stopPropagation();
  const k = side === "from" ? 0 : 1, pair = state.used.pairs[index];
  pair[k] = Math.round(wrap01(pair[k] + step) * 1e4) / 1e4;
  renderEditor();
  const again = $(`#editor circle.used[data-which=${side}][data-index="${index}"]`);
  if (again) again.focus();
}

/** The used correspondence as picked pairs, and the morph again. Picked
 * pairs make the starts of closed curves correspond, so a start of `to`
 * the service chose is kept by starting `to` there (exact at one of its
 * vertices), else by a pair of the two starts. */
async function useMatchesAsPicked() {
  const u = state.used;
  if (!u) return;
  let pairs = u.pairs.map((p) => p.slice());
  let keep = false;
  if (curvesClosed() && !atSeam(u.start.to)) {
    const v = nearestStart("to", u.start.to);
    if (v && Math.abs(wrap01(v.f - u.start.to + 0.5) - 0.5) < 0.01) {
      await steer("to", { rotate: v.k });
      pairs = pairs.map(([a, b]) => [a, Math.round(wrap01(b - v.f) * 1e4) / 1e4]);
      keep = true;
    } else pairs.push([0, u.start.to]);
  }
  state.matches = pairs.filter(([a, b]) => !(keep && atSeam(a) && atSeam(b))).sort((p, q) => p[0] - q[0]);
  $("#matches-mode").value = "pairs";
  renderEditor();
  runMorph();
}

/** The vertex of a curve nearest to editor fraction f: its index and
 * fraction, or null. */
function nearestStart(which, f) {
  let curve;
  try { curve = parseCurve($("#curve-" + which).value); } catch { return null; }
  let best = null;
  startPoints(curve).forEach(([x, y], k) => {
    const g = nearestFraction(which, x, y), d = Math.abs(wrap01(g - f + 0.5) - 0.5);
    if (!best || d < best.d) best = { k, f: g, d };
  });
  return best;
}

/** The correspondence a single-curve morph used, on the editor's paths:
 * frame 0 is `from` and the last frame `to` where they stand, each
 * started and run as the morph took it. */
function usedCorrespondence(result) {
  const frames = result.frames;
  if (!frames.length || !frames[0].curve || !pathOf("from") || !pathOf("to")) return null;
  const N = 1000;
  const ends = { from: samplePoints(frames[0].curve, N + 1), to: samplePoints(frames[frames.length - 1].curve, N + 1) };
  const at = (which, f) => { const q = ends[which][Math.round(f * N)]; return nearestFraction(which, q[0], q[1]); };
  const start = {}, dir = {};
  for (const which of ["from", "to"]) {
    start[which] = at(which, 0);
    const d = wrap01(at(which, 0.02) - start[which] + 0.5) - 0.5;
    dir[which] = d < 0 ? -1 : 1;
  }
  let pairs = (result.matches_used || []).map(([a, b]) => [at("from", a), at("to", b)]);
  if (state.sentPin) pairs = [];
  return { pairs, start, dir };
}

/** The colour of input contour i: its pair's after a morph, else its side's. */
function contourColour(which, i) {
  const side = which === "from" ? "var(--from)" : "var(--to)";
  if (!state.contourMatches) return side;
  const k = state.contourMatches.findIndex((pair) => pair[which === "from" ? 0 : 1] === i);
  return k < 0 ? side : slotColour(k);
}

function isCompound() {
  return ["from", "to"].some((w) => state.display[w] && state.display[w].compound);
}

function fitViewBox(svg, g) {
  let box = null;
  try { box = g.getBBox(); } catch { box = null; }
  if (!box || !(box.width > 0 || box.height > 0)) { svg.setAttribute("viewBox", "0 0 200 200"); return; }
  const pad = Math.max(box.width, box.height) * 0.08 || 1;
  svg.setAttribute("viewBox", `${box.x - pad} ${box.y - pad} ${box.width + 2 * pad} ${box.height + 2 * pad}`);
}

function viewScale(svg) {
  const vb = svg.viewBox.baseVal, w = svg.clientWidth || 600, h = svg.clientHeight || 260;
  return Math.max(vb.width / w, vb.height / h) || 1;
}

function pathOf(which) { return $(`#editor path.${which}`); }

function pointAt(which, fraction) {
  const p = pathOf(which);
  if (!p) return null;
  return p.getPointAtLength(fraction * p.getTotalLength());
}

/** The arc-length fraction of the point of `which` nearest to (x, y). */
function nearestFraction(which, x, y) {
  const p = pathOf(which);
  if (!p) return null;
  const L = p.getTotalLength(), n = 400;
  let best = 0, bestD = Infinity;
  for (let i = 0; i <= n; i++) {
    const q = p.getPointAtLength(L * i / n), d = Math.hypot(q.x - x, q.y - y);
    if (d < bestD) { bestD = d; best = i / n; }
  }
  return Math.round(best * 1e4) / 1e4;
}

function editorPoint(ev) {
  const svg = $("#editor"), pt = svg.createSVGPoint();
  pt.x = ev.clientX; pt.y = ev.clientY;
  const m = svg.getScreenCTM();
  const q = m ? pt.matrixTransform(m.inverse()) : pt;
  return [Math.round(q.x * 100) / 100, Math.round(q.y * 100) / 100];
}

function onEditorClick(ev) {
  if (state.drawing) {
    const which = state.drawing;
    state.drawn[which].push(editorPoint(ev));
    drawnChanged();
    return;
  }
  if (state.picking) {
    const [x, y] = editorPoint(ev);
    if (state.pending == null) {
      state.pending = nearestFraction("from", x, y);
    } else {
      const b = nearestFraction("to", x, y);
      if (b != null) state.matches.push([state.pending, b]);
      state.matches.sort((p, q) => p[0] - q[0]);
      state.pending = null;
      $("#matches-mode").value = "pairs";
    }
    renderEditor();
  }
}

/** The drawn points into the curve field and the editor. */
function drawnChanged() {
  const which = state.drawing;
  $("#curve-" + which).value = JSON.stringify({ type: "points", points: state.drawn[which],
                                                closed: $(`.draw-closed[data-which=${which}]`).checked });
  $("#undo-point").disabled = !state.drawn[which].length;
  renderEditor();
}

/** Take back the last drawn point (Undo, Ctrl-Z or Cmd-Z while drawing). */
function undoPoint() {
  if (!state.drawing || !state.drawn[state.drawing].length) return;
  state.drawn[state.drawing].pop();
  drawnChanged();
}

/** Add a point at the middle of the editor's view (Enter or the button
 * while drawing, for drawing without a mouse), then move it with the
 * arrow keys. */
function addPointByKey() {
  if (!state.drawing) return;
  const vb = $("#editor").viewBox.baseVal;
  const pts = state.drawn[state.drawing], last = pts[pts.length - 1];
  const step = Math.max(vb.width, vb.height) / 20;
  pts.push(last ? [Math.round((last[0] + step) * 100) / 100, last[1]]
                : [Math.round((vb.x + vb.width / 2) * 100) / 100, Math.round((vb.y + vb.height / 2) * 100) / 100]);
  drawnChanged();
}

function nudgePoint(dx, dy) {
  const pts = state.drawing && state.drawn[state.drawing];
  if (!pts || !pts.length) return;
  const vb = $("#editor").viewBox.baseVal, step = Math.max(vb.width, vb.height) / 50, p = pts[pts.length - 1];
  p[0] = Math.round((p[0] + dx * step) * 100) / 100;
  p[1] = Math.round((p[1] + dy * step) * 100) / 100;
  drawnChanged();
}

/** Reverse a curve or start it at its next or previous vertex, in its
 * field's own terms; a start chosen here is kept (see optionsRequest). */
async function steer(which, how) {
  let curve;
  try { curve = parseCurve($("#curve-" + which).value); } catch (e) { setFieldError(which, e.message); return; }
  const out = steerCurve(curve, how);
  const note = $("#note-" + which);
  if (!out) {
    note.textContent = how.reverse ? "Only an SVG path or drawn points can be reversed here."
                                   : "Only a closed SVG path or closed drawn points can be started elsewhere here.";
    return;
  }
  $("#curve-" + which).value = curveText(out);
  $(`select.pick[data-testid=pick-${which}]`).value = "";
  if (!how.reverse) $("#keep-starts").checked = true;
  await updateCurve(which);
}

function toggleDraw(which) {
  const btn = $(`.draw[data-which=${which}]`);
  if (state.drawing === which) {
    state.drawing = null;
    btn.textContent = "Draw";
    $("#editor").classList.remove("drawing");
    $("#editor-hint").textContent = EDITOR_HINT;
    $("#undo-point").disabled = true;
    $("#add-point").disabled = true;
    updateCurve(which);
    return;
  }
  if (state.drawing) toggleDraw(state.drawing);
  stopPicking();
  state.drawing = which;
  state.drawn[which] = [];
  btn.textContent = "Done";
  $("#editor").classList.add("drawing");
  $("#editor-hint").textContent = `Click control points of the ${which} curve, then Done ` +
    "(or, with the editor focused: Enter adds a point, the arrow keys move it; Ctrl-Z or Undo takes it back).";
  $("#undo-point").disabled = true;
  $("#add-point").disabled = false;
  renderEditor();
}

const EDITOR_HINT = "The two input curves. Use Draw to click control points, or Pick pairs to match points.";

function stopPicking() {
  state.picking = false;
  state.pending = null;
  $("#editor").classList.remove("picking");
  $("#pick-matches").textContent = "Pick pairs";
  $("#editor-hint").textContent = EDITOR_HINT;
}

/** Picked pairs and contour colours name points of the curves they were
 * made on: a changed curve drops them. */
function forgetMatches() {
  state.contourMatches = null;
  state.used = null;
  if (!state.matches.length && state.pending == null) return;
  state.matches = [];
  state.pending = null;
  if ($("#matches-mode").value === "pairs") $("#matches-mode").value = "none";
}

/* A pick within one sampling step of a curve's ends is at its seam (the
 * start of a closed curve) or its end; sent SEAM_EPS inside, which the
 * service takes as the end itself up to rounding. */
const SEAM_PICK = 1 / 400 + 1e-9, SEAM_EPS = 1e-4;
const atSeam = (f) => f <= SEAM_PICK || f >= 1 - SEAM_PICK;

function curvesClosed() {
  return ["from", "to"].every((w) => state.display[w] && state.display[w].closed);
}

/** The picked pairs as the service takes them: strictly inside (0, 1).
 * On closed curves the two starts always correspond when pairs are
 * given, so a pick of both starts needs no pair, and a start matched with
 * an inner point is sent just after the seam or just before it, whichever
 * leaves less of the partner's length to the sliver between the two. */
function sendablePairs() {
  const closed = curvesClosed(), out = [];
  /* the service runs a closed `to` of the other orientation backwards
   * from its own start: its fractions then count the other way round */
  const flip = closed && orientation("from") * orientation("to") < 0;
  for (const [a, picked] of state.matches) {
    const b = flip && !atSeam(picked) ? 1 - picked : picked;
    if (closed && atSeam(a) && atSeam(b)) continue;
    const inside = (f, other) => (!atSeam(f) ? f : closed ? (other < 0.5 ? SEAM_EPS : 1 - SEAM_EPS)
                                                          : (f < 0.5 ? SEAM_EPS : 1 - SEAM_EPS));
    out.push([inside(a, b), inside(b, a)]);
  }
  return out.sort((p, q) => p[0] - q[0]);
}

/** The sign of the area an editor path encloses (1 or -1; 0 without one). */
function orientation(which) {
  const p = pathOf(which);
  if (!p) return 0;
  const L = p.getTotalLength(), n = 200;
  let area = 0, prev = p.getPointAtLength(0);
  for (let i = 1; i <= n; i++) {
    const q = p.getPointAtLength(L * i / n);
    area += prev.x * q.y - q.x * prev.y;
    prev = q;
  }
  return Math.sign(area);
}

function renderMatchList() {
  const ul = $("#match-list");
  ul.replaceChildren();
  for (const [a, b] of state.matches) {
    const li = document.createElement("li");
    const where = (f) => f.toFixed(4) + (atSeam(f) ? (curvesClosed() ? " (start)" : f < 0.5 ? " (start)" : " (end)") : "");
    li.textContent = curvesClosed() && atSeam(a) && atSeam(b)
      ? "start ↔ start (the starts of closed curves correspond whenever pairs are picked)"
      : `from ${where(a)} ↔ to ${where(b)} (arc-length fractions)`;
    ul.appendChild(li);
  }
}

// ------------------------------------------------------------------ morph

function optionsRequest() {
  const req = { metrics: true, include: ["svg_d"] };
  const frames = Number($("#frames").value);
  req.frames = Number.isInteger(frames) ? frames : $("#frames").value;
  req.closure = $("#closure").value;
  req.anchor = $("#anchor").value;
  req.blend = $("#blend").value;
  const tol = $("#tolerance").value.trim();
  if (tol !== "") {
    const v = Number(tol);
    req.tolerance = Number.isFinite(v) ? v : tol;
  }
  const mode = $("#matches-mode").value;
  state.sentPin = false;
  if (mode === "auto") req.matches = "auto";
  else if (mode === "pairs" && !isCompound()) {
    const pairs = sendablePairs();
    if (pairs.length) req.matches = pairs;
  }
  /* Closed curves without pairs get the start of `to` the service aligns
   * best; one proportional pair keeps both starts as given and is
   * otherwise the global morph exactly (see NUMERICS.md, Matches). */
  if (!req.matches && mode !== "auto" && $("#keep-starts").checked && curvesClosed() && !isCompound()) {
    req.matches = [[0.5, 0.5]];
    state.sentPin = true;
  }
  return req;
}

const FIELD_OF = [
  [/^\/from(\/|$)/, "from"], [/^\/to(\/|$)/, "to"], [/^\/closed$/, "curves"],
  [/^\/(frames|times|matches|closure|anchor|blend|tolerance|method|orient|degree)(\/|$)/, "options"],
];
const INPUT_OF = { frames: "#frames", times: "#frames", matches: "#matches-mode", closure: "#closure",
                   anchor: "#anchor", blend: "#blend", tolerance: "#tolerance", method: "#method" };

function clearErrors() {
  for (const w of ["from", "to", "options", "general"]) setFieldError(w, "");
  for (const sel of Object.values(INPUT_OF)) $(sel).parentElement.classList.remove("has-error");
}

/** A JSON pointer of a request said in words ("/matches/1/0" -> "match
 * 2, from fraction"). */
function pointerWords(pointer) {
  const parts = (pointer || "").split("/").slice(1);
  if (!parts.length) return "the request";
  const [key, i, j] = parts;
  if (key === "matches" && i !== undefined)
    return `picked pair ${Number(i) + 1}` + (j === "0" ? ", on the from curve" : j === "1" ? ", on the to curve" : "");
  if (key === "contour_matches" && i !== undefined) return `contour pair ${Number(i) + 1}`;
  const words = { frames: "frames", times: "times", closure: "closure", anchor: "anchor", blend: "blend",
                  tolerance: "tolerance", method: "method", orient: "orientation", degree: "degree",
                  closed: "open or closed curves", svg: "SVG layout" };
  return words[key] || parts.join(" ");
}

/** Show a service problem next to the field(s) it points at. */
function showProblem(e, method) {
  const prefix = method ? `${method}: ` : "";
  if (!(e instanceof KmorphError) || !e.errors.length) {
    setFieldError("general", prefix + problemText(e));
    return;
  }
  const per = {};
  for (const x of e.errors) {
    const hit = FIELD_OF.find(([re]) => re.test(x.pointer || ""));
    const where = hit ? hit[1] : "general";
    if (where === "curves") {
      /* an open curve against a closed one: the fault of both curves */
      for (const w of ["from", "to"]) (per[w] ||= []).push(x.message);
      state.pairError = true;
      continue;
    }
    (per[where] ||= []).push(`${where === "general" || where === "options" ? `${pointerWords(x.pointer)}: ` : ""}${x.message}`);
    const key = (x.pointer || "").split("/")[1];
    if (where === "options" && INPUT_OF[key]) $(INPUT_OF[key]).parentElement.classList.add("has-error");
  }
  for (const [where, msgs] of Object.entries(per))
    setFieldError(where, `${prefix}${e.title} (${e.status}): ${msgs.join("; ")}`);
}

function setBusy(busy) {
  $("#morph").disabled = busy;
  $("#cancel").disabled = !busy;
}

/* The last few morph answers by their request: asking again for what
 * the page has (the same curves and options, or one method of a pair
 * morphed side by side) takes no call. */
const ANSWERS_KEPT = 4;
const answers = new Map();

function remember(key, result) {
  answers.set(key, result);
  while (answers.size > ANSWERS_KEPT) answers.delete(answers.keys().next().value);
}

async function runMorph() {
  try { await morphOnce(); } finally {
    /* finished morphs, counted for whoever waits for the page */
    document.body.dataset.morphs = String(Number(document.body.dataset.morphs || 0) + 1);
  }
}

async function morphOnce() {
  clearErrors();
  for (const which of ["from", "to"]) {
    try { state.input[which] = parseCurve($("#curve-" + which).value); } catch (e) {
      setFieldError(which, e.message);
      return;
    }
  }
  const base = { from: sentCurve(state.input.from), to: sentCurve(state.input.to), ...optionsRequest() };
  const choice = $("#method").value;
  const methods = choice === "both" ? ["curvature", "linear"] : [choice];
  const asJob = $("#use-job").checked || (Number(base.frames) > JOB_FRAMES);
  const ac = new AbortController();
  state.controller = ac;
  setBusy(true);
  const bar = $("#progress");
  bar.hidden = false;
  if (asJob) bar.value = 0; else bar.removeAttribute("value");
  const progress = Object.fromEntries(methods.map((m) => [m, 0]));
  $("#status").textContent = asJob ? "submitting jobs…" : "morphing…";
  const started = performance.now();
  const runs = methods.map(async (method) => {
    const request = { ...base, method };
    const key = JSON.stringify(request);
    const known = answers.get(key);
    if (known) {
      /* the same request answered before: its answer, not another call */
      answers.delete(key);
      answers.set(key, known);
      return { method, request, result: known };
    }
    try {
      const result = asJob
        ? await km.morphJob(request, { signal: ac.signal, onProgress: (s) => {
            progress[method] = s.progress;
            const mean = methods.reduce((sum, m) => sum + progress[m], 0) / methods.length;
            bar.value = mean;
            $("#status").textContent = `job ${s.state}: ${Math.floor(mean * 100)}%`;
          } })
        : await km.morph(request, { signal: ac.signal });
      remember(key, result);
      return { method, request, result };
    } catch (e) {
      return { method, request, error: e };
    }
  });
  const outcomes = await Promise.all(runs);
  setBusy(false);
  bar.hidden = true;
  state.controller = null;
  if (ac.signal.aborted) {
    $("#status").textContent = "cancelled";
    return;
  }
  const failed = outcomes.filter((o) => o.error);
  /* The same fault in both requests is shown once. */
  const seen = new Set();
  for (const o of failed) {
    const key = o.error instanceof KmorphError ? JSON.stringify(o.error.errors) + o.error.detail : String(o.error);
    if (seen.has(key)) continue;
    seen.add(key);
    showProblem(o.error, failed.length < outcomes.length ? o.method : "");
  }
  const ok = outcomes.filter((o) => o.result);
  if (!ok.length) {
    clearResults();
    $("#status").textContent = "failed: see the messages by the fields";
    return;
  }
  const ms = Math.round(performance.now() - started);
  $("#status").textContent = `${ok.map((o) => `${o.method}: ${o.result.frames.length} frames`).join(", ")} in ${ms} ms` +
                             (asJob ? " (jobs)" : "");
  showResults(ok);
  saveUrl();
}

// ---------------------------------------------------------------- results

/** Take the shown results away (they belong to another request). */
function clearResults() {
  stop();
  state.results = [];
  state.panels = [];
  state.contourMatches = null;
  state.used = null;
  $("#panels").replaceChildren();
  $("#results").hidden = true;
  renderContourList();
  renderEditor();
}

function showResults(outcomes) {
  stop();
  state.results = outcomes;
  $("#results").hidden = false;
  const panels = $("#panels");
  panels.replaceChildren();
  state.panels = [];
  /* One viewBox for every panel, so shapes compare at the same scale. */
  let b = [Infinity, Infinity, -Infinity, -Infinity];
  for (const o of outcomes) {
    const c = resultBounds(o.result);
    b = [Math.min(b[0], c[0]), Math.min(b[1], c[1]), Math.max(b[2], c[2]), Math.max(b[3], c[3])];
  }
  const pad = Math.max(b[2] - b[0], b[3] - b[1]) * 0.05 || 1;
  const viewBox = `${b[0] - pad} ${b[1] - pad} ${b[2] - b[0] + 2 * pad} ${b[3] - b[1] + 2 * pad}`;
  for (const o of outcomes) state.panels.push(buildPanel(o, viewBox));
  for (const p of state.panels) panels.appendChild(p.root);
  const shape = isShapeResult(outcomes[0].result);
  state.contourMatches = shape ? outcomes[0].result.contour_matches_used || null : null;
  const main = outcomes.find((o) => o.method === "curvature") || outcomes[0];
  state.used = shape ? null : usedCorrespondence(main.result);
  renderContourList();
  renderEditor();
  const n = outcomes[0].result.frames.length;
  /* Slider steps land exactly on frames: k steps per frame interval. */
  const k = Math.max(1, Math.ceil(1000 / Math.max(1, n - 1)));
  state.steps = Math.max(1, (n - 1) * k);
  $("#scrub").max = String(state.steps);
  setT(0);
  for (const p of state.panels) loadPlot(p);
}

/** Which contour went to which: one line per pair, in its colour. */
function renderContourList() {
  const ul = $("#contour-list");
  ul.replaceChildren();
  ul.hidden = !state.contourMatches;
  if (!state.contourMatches) return;
  state.contourMatches.forEach(([i, j], k) => {
    const li = document.createElement("li");
    li.dataset.slot = k;
    const sw = document.createElement("span");
    sw.className = "swatch slot";
    sw.style.background = slotColour(k);
    li.appendChild(sw);
    li.append(i === null ? `to contour ${j} grows from a point`
                         : j === null ? `from contour ${i} shrinks to a point`
                                      : `from contour ${i} → to contour ${j}`);
    ul.appendChild(li);
  });
}

function fmt(v, digits = 4) {
  if (typeof v !== "number") return "";
  if (v !== 0 && (Math.abs(v) >= 1e5 || Math.abs(v) < 1e-3)) return v.toExponential(2);
  return Number(v.toPrecision(digits + 2)).toString();
}

/** The fill rule of a frame: the nearer input's (from's for t < 1/2), as
 * the service's filmstrip does. */
function fillRuleAt(t) {
  const shown = state.display[t < 0.5 ? "from" : "to"];
  return shown ? shown.fillRule : "nonzero";
}

function buildPanel(o, viewBox) {
  const root = $("#panel-template").content.firstElementChild.cloneNode(true);
  const { method, result } = o;
  const shape = isShapeResult(result);
  root.id = "panel-" + method;
  root.dataset.method = method;
  root.classList.toggle("compound", shape);
  const paths = result.frames.map(framePath);
  const metrics = result.frames.map(frameMetrics);
  const maxSi = Math.max(0, ...metrics.map((m) => m.self_intersections || 0));
  const badFrames = metrics.filter((m) => m.self_intersections > 0).length;
  const apart = shape ? metrics.filter((m) => m.mutual_intersections > 0 || m.nesting_ok === false).length : 0;
  $(".method-name", root).textContent = method === "curvature" ? "Curvature blend" : "Linear (control points)";
  $(".summary", root).textContent = `${result.frames.length} frames · ${badFrames} self-intersecting` +
                                    (badFrames ? ` (up to ${maxSi})` : "") +
                                    (shape ? ` · ${apart} with contours crossing or a hole outside` : "");
  const stage = $(".stage", root);
  stage.setAttribute("viewBox", viewBox);
  stage.dataset.testid = "stage-" + method;
  $(".ghost.from", stage).setAttribute("d", paths[0]);
  $(".ghost.to", stage).setAttribute("d", paths[paths.length - 1]);
  const current = $(".current", stage);
  /* only closed curves have an inside to fill */
  const fillable = shape || result.frames.every((f) => f.curve.closed);
  current.classList.toggle("fillable", fillable);
  /* A compound frame's contours outlined one by one in their pair's colour. */
  const slotPaths = shape ? result.frames[0].contours.map((_, k) =>
    svgEl("path", { class: "slot", "data-slot": k, style: `stroke: ${slotColour(k)}` }, stage)) : [];
  /* Filmstrip: every frame, or FILM_MAX evenly chosen. */
  const film = $(".filmstrip", root);
  const n = paths.length, count = Math.min(n, FILM_MAX);
  const picks = [...new Set(Array.from({ length: count }, (_, i) => Math.round(i * (n - 1) / Math.max(1, count - 1))))];
  const thumbs = new Map();
  for (const i of picks) {
    const f = result.frames[i], m = metrics[i];
    const svg = svgEl("svg", { viewBox, preserveAspectRatio: "xMidYMid meet", "data-frame": i,
                               "data-si": f.metrics ? m.self_intersections : "" }, film);
    svgEl("title", {}, svg).textContent = `frame ${i}, t = ${fmt(f.t)}` +
      (f.metrics ? `, ${m.self_intersections} self-intersections` : "") +
      (shape && f.metrics ? `, ${m.mutual_intersections} crossings between contours` +
                            (m.nesting_ok ? "" : ", a hole outside its contour") : "");
    svgEl("path", { d: paths[i], class: fillable ? "fillable" : "", "fill-rule": fillRuleAt(f.t) }, svg);
    if (shape)
      f.contours.forEach((c, k) => c && svgEl("path", { d: curveToPath(c), class: "slot", "data-slot": k,
                                                        style: `stroke: ${slotColour(k)}` }, svg));
    if (frameIsBad(m)) svg.classList.add("bad");
    svg.setAttribute("tabindex", "0");
    svg.setAttribute("role", "button");
    svg.setAttribute("aria-label", `frame ${i}, t = ${fmt(f.t)}`);
    svg.addEventListener("click", () => { stop(); setT(f.t); });
    svg.addEventListener("keydown", (e) => { if (e.key === "Enter") { stop(); setT(f.t); } });
    thumbs.set(i, svg);
  }
  /* Metrics of every frame; frames drawn wrong stand out. */
  const tbody = $("tbody", root), rows = [];
  const tableFrames = result.frames.length <= 2000 ? result.frames : null;
  if (tableFrames) {
    const frag = document.createDocumentFragment();
    tableFrames.forEach((f, i) => {
      const m = metrics[i];
      const tr = document.createElement("tr");
      tr.dataset.frame = i;
      const cells = [i, fmt(f.t), fmt(m.length), fmt(m.max_abs_kappa), fmt(m.bending_energy),
                     m.self_intersections ?? "", fmt(m.closure_gap)];
      if (shape) cells.push(m.mutual_intersections ?? "", m.nesting_ok === undefined ? "" : m.nesting_ok ? "yes" : "no");
      for (const v of cells) {
        const td = document.createElement("td");
        td.textContent = v;
        tr.appendChild(td);
      }
      if (frameIsBad(m)) tr.classList.add("bad");
      tr.addEventListener("click", () => { stop(); setT(f.t); });
      rows.push(tr);
      frag.appendChild(tr);
    });
    tbody.appendChild(frag);
  } else {
    $(".metrics-details summary", root).textContent = `Per-frame metrics (${result.frames.length} frames: download JSON for all)`;
  }
  return { root, method, result, shape, paths, metrics, stage, slotPaths, thumbs, rows, cache: new Map(),
           current: -1, request: o.request };
}

const SAMPLES = 240;

/** Points of slot k of frame i (k = 0 for a single curve), at equal
 * arc-length fractions; a slot absent in frame i takes its partner frame
 * j's contour collapsed to a point. */
function framePoints(panel, i, k, j) {
  const key = `${i}/${k}`;
  let pts = panel.cache.get(key);
  if (!pts) {
    const f = panel.result.frames[i];
    if (!panel.shape) pts = samplePoints(f.curve, SAMPLES);
    else if (f.contours[k]) pts = slotPoints(f.contours[k], null, SAMPLES);
    else if (panel.result.frames[j].contours[k]) pts = slotPoints(null, panel.result.frames[j].contours[k], SAMPLES);
    else pts = null;
    panel.cache.set(key, pts);
  }
  return pts;
}

function blendPath(a, b, f, closed) {
  const end = closed ? a.length - 1 : a.length;
  let d = "";
  for (let j = 0; j < end; j++) {
    const x = a[j][0] + f * (b[j][0] - a[j][0]), y = a[j][1] + f * (b[j][1] - a[j][1]);
    d += `${j ? "L" : "M"}${x.toFixed(5)},${y.toFixed(5)}`;
  }
  return closed ? d + "Z" : d;
}

/** The path of a panel at time t: the frame's own path at a frame time,
 * else a blend of the two frames around t at equal arc-length fractions
 * (slot by slot for compound shapes). `slots` has each slot's path. */
function pathAt(panel, t) {
  const frames = panel.result.frames, n = frames.length;
  let i = 0;
  while (i < n - 2 && t > frames[i + 1].t) i++;
  for (const j of [i, Math.min(i + 1, n - 1)])
    if (Math.abs(frames[j].t - t) < 1e-9) {
      const slots = panel.shape ? frames[j].contours.map((c) => (c ? curveToPath(c) : "")) : null;
      return { d: panel.paths[j], slots, frame: j, exact: true };
    }
  const f = (t - frames[i].t) / (frames[i + 1].t - frames[i].t || 1);
  const frame = f < 0.5 ? i : i + 1;
  if (!panel.shape) {
    const d = blendPath(framePoints(panel, i, 0), framePoints(panel, i + 1, 0), f, frames[i].curve.closed);
    return { d, slots: null, frame, exact: false };
  }
  const slots = frames[i].contours.map((_, k) => {
    const a = framePoints(panel, i, k, i + 1), b = framePoints(panel, i + 1, k, i);
    return a && b ? blendPath(a, b, f, true) : "";
  });
  return { d: slots.join(""), slots, frame, exact: false };
}

function setT(t) {
  state.t = Math.min(1, Math.max(0, t));
  $("#scrub").value = String(Math.round(state.t * state.steps));
  $("#t-value").textContent = `t = ${state.t.toFixed(3)}`;
  let label = "";
  for (const p of state.panels) {
    const at = pathAt(p, state.t);
    const cur = $(".current", p.stage);
    cur.setAttribute("d", at.d);
    cur.setAttribute("fill-rule", fillRuleAt(state.t));
    cur.dataset.frame = at.exact ? String(at.frame) : "";
    if (at.slots) p.slotPaths.forEach((el, k) => el.setAttribute("d", at.slots[k]));
    const m = p.metrics[at.frame];
    const root = p.root;
    $(".m-length", root).textContent = fmt(m.length);
    $(".m-kappa", root).textContent = fmt(m.max_abs_kappa);
    $(".m-energy", root).textContent = fmt(m.bending_energy);
    const si = $(".m-si", root);
    si.textContent = m.self_intersections ?? "";
    si.classList.toggle("bad", m.self_intersections > 0);
    si.dataset.testid = "si-" + p.method;
    $(".m-gap", root).textContent = fmt(m.closure_gap);
    if (p.shape) {
      const mi = $(".m-mutual", root), nest = $(".m-nesting", root);
      mi.textContent = m.mutual_intersections ?? "";
      mi.classList.toggle("bad", m.mutual_intersections > 0);
      nest.textContent = m.nesting_ok === undefined ? "" : m.nesting_ok ? "yes" : "no";
      nest.classList.toggle("bad", m.nesting_ok === false);
    }
    p.stage.classList.toggle("bad", frameIsBad(m));
    if (p.current !== at.frame) {
      if (p.rows[p.current]) p.rows[p.current].classList.remove("current");
      if (p.thumbs.get(p.current)) p.thumbs.get(p.current).classList.remove("current");
      if (p.rows[at.frame]) p.rows[at.frame].classList.add("current");
      const thumb = p.thumbs.get(at.frame);
      if (thumb) {
        thumb.classList.add("current");
        /* the filmstrip follows the current frame */
        const strip = thumb.parentElement, a = strip.getBoundingClientRect(), b = thumb.getBoundingClientRect();
        if (b.left < a.left || b.right > a.right) strip.scrollLeft += b.left - a.left - (a.width - b.width) / 2;
      }
      p.current = at.frame;
    }
    label = at.exact ? `frame ${at.frame} of ${p.result.frames.length - 1}`
                     : `≈ frame ${at.frame} of ${p.result.frames.length - 1} (blend)`;
  }
  $("#frame-label").textContent = label;
  $("#frame-label").title = label.includes("blend")
    ? "Between frames the stage blends the two nearest frames; the numbers are the nearest frame's." : "";
}

/** The plot of kappa_t(s / L_t) for a subset of the frames, drawn here
 * from the frames (see plot.js): single curves from the from colour to
 * the to colour by t, compound shapes contour by contour in their pair's
 * colour. */
function loadPlot(panel) {
  const div = $(".plot", panel.root);
  const frames = panel.result.frames, n = frames.length, count = Math.min(n, PLOT_MAX);
  const picks = [...new Set(Array.from({ length: count }, (_, i) => Math.round(i * (n - 1) / Math.max(1, count - 1))))];
  const curves = [];
  for (const i of picks) {
    const f = frames[i];
    if (panel.shape) f.contours.forEach((c, k) => c && curves.push({ curve: c, colour: slotColour(k), t: f.t }));
    else curves.push({ curve: f.curve, colour: mixColour(f.t), t: f.t });
  }
  try {
    div.replaceChildren(curvaturePlot(curves));
  } catch (e) {
    div.textContent = "no curvature plot: " + problemText(e);
  }
}

/** The colour of time t between the from and to colours. */
function mixColour(t) {
  const a = [0x1f, 0x6f, 0xd1], b = [0xd1, 0x57, 0x1f];
  return `rgb(${a.map((x, i) => Math.round(x + t * (b[i] - x))).join(",")})`;
}

// --------------------------------------------------------------- playback

/** The easing chosen on the page (linear when the text is not one). */
function easing() {
  const points = parseEasing($("#easing").value.trim());
  $("#easing").parentElement.classList.toggle("has-error", !points);
  return points || EASINGS.linear;
}

function duration() {
  const v = Number($("#duration").value);
  return v > 0 && v <= 600 ? v : 3;
}

/* Playback runs a phase through [0, 1] in the chosen duration; t is the
 * eased phase. Once stops at the end; loop starts again; ping-pong runs
 * back. */
function play() {
  if (!state.panels.length) return;
  const curve = easing();
  state.playing = true;
  $("#play").textContent = "Pause";
  if (state.t >= 1 && $("#repeat").value !== "ping-pong") setT(0);
  if (state.phase === undefined || Math.abs(ease(curve, state.phase) - state.t) > 1e-6) state.phase = easeInverse(curve, state.t);
  if ($("#repeat").value !== "ping-pong" || !state.direction) state.direction = 1;
  if (state.direction < 0 && state.phase <= 0) state.direction = 1;
  if (state.direction > 0 && state.phase >= 1 && $("#repeat").value === "ping-pong") state.direction = -1;
  let last = performance.now();
  const step = (now) => {
    if (!state.playing) return;
    /* a frame's time stamp may precede the moment play was pressed */
    const dt = Math.max(0, (now - last) / 1000);
    last = Math.max(last, now);
    let phase = state.phase + state.direction * dt / duration();
    const repeat = $("#repeat").value;
    if ((state.direction > 0 && phase >= 1) || (state.direction < 0 && phase <= 0)) {
      if (repeat === "once") {
        state.phase = Math.min(1, Math.max(0, phase));
        setT(ease(curve, state.phase));
        stop();
        return;
      }
      if (repeat === "loop") phase = phase >= 1 ? phase - 1 : phase + 1;
      else { state.direction = -state.direction; phase = phase >= 1 ? 2 - phase : -phase; }
    }
    state.phase = phase;
    setT(ease(curve, phase));
    requestAnimationFrame(step);
  };
  requestAnimationFrame(step);
}

/** Go to the frame `by` frames before or after the current t. */
function stepFrame(by) {
  if (!state.panels.length) return;
  stop();
  const ts = state.panels[0].result.frames.map((f) => f.t);
  let i;
  if (by > 0) { i = ts.findIndex((t) => t > state.t + 1e-9); if (i < 0) i = ts.length - 1; }
  else { i = ts.length - 1; while (i > 0 && ts[i] >= state.t - 1e-9) i--; }
  setT(ts[i]);
}

function onKey(e) {
  if (!state.panels.length || e.ctrlKey || e.metaKey || e.altKey) return;
  const tag = (e.target.tagName || "").toLowerCase();
  if (tag === "textarea" || (tag === "input" && !["range", "checkbox"].includes(e.target.type)) || tag === "select") return;
  const keys = { " ": () => (state.playing ? stop() : play()), ArrowRight: () => stepFrame(1), ArrowLeft: () => stepFrame(-1),
                 Home: () => { stop(); setT(0); }, End: () => { stop(); setT(1); } };
  if (!keys[e.key]) return;
  e.preventDefault();
  keys[e.key]();
}

function stop() {
  state.playing = false;
  $("#play").textContent = "Play";
}

// -------------------------------------------------------------- downloads

function download(name, blob) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

function downloadJson() {
  const data = state.results.length === 1 ? state.results[0].result
    : Object.fromEntries(state.results.map((o) => [o.method, o.result]));
  download("kmorph.json", new Blob([JSON.stringify(data)], { type: "application/json" }));
}

async function downloadSvg() {
  clearErrors();
  const layout = $("#svg-layout").value;
  const bar = $("#download-progress"), note = $("#download-status");
  for (const o of state.results) {
    const { include, ...rest } = o.request;
    const req = { ...rest, format: "svg", svg: { layout } };
    const name = `kmorph-${o.method}-${layout}.svg`;
    /* a large export takes a while to arrive: show how much has */
    const onDownload = ({ received, total }) => {
      bar.hidden = false;
      if (total) bar.value = received / total; else bar.removeAttribute("value");
      note.textContent = `${name}: ${kib(received)}` + (total ? ` of ${kib(total)} KiB` : " KiB received");
    };
    note.textContent = `${name}: waiting for the service…`;
    try {
      const svg = Number(req.frames) > JOB_FRAMES ? await km.morphJob(req, { onDownload }) : await km.morph(req, { onDownload });
      const blob = new Blob([svg], { type: "image/svg+xml" });
      download(name, blob);
      note.textContent = `${name}: ${kib(blob.size)} KiB`;
    } catch (e) {
      note.textContent = `${name}: failed`;
      showProblem(e, o.method);
    }
    bar.hidden = true;
  }
}

const kib = (bytes) => (bytes / 1024).toFixed(bytes < 10240 ? 1 : 0);

// ----------------------------------------------------------------- export

/* At most this many frames go into an export (evenly chosen). */
const EXPORT_MAX = 61;

function exportResult() {
  const o = state.results.find((r) => r.method === "curvature") || state.results[0];
  if (!o) return null;
  const frames = o.result.frames, n = frames.length, count = Math.min(n, EXPORT_MAX);
  const picks = [...new Set(Array.from({ length: count }, (_, i) => Math.round(i * (n - 1) / Math.max(1, count - 1))))];
  return { ...o.result, frames: picks.map((i) => frames[i]) };
}

function showExport(kind) {
  const result = exportResult();
  if (!result) return;
  const opts = { duration: duration(), easing: easing(), pingPong: $("#repeat").value === "ping-pong",
                 fillRule: state.display.from ? state.display.from.fillRule : "nonzero" };
  const once = $("#repeat").value === "once";
  let text;
  if (kind === "css") {
    text = cssKeyframes(result, opts);
    if (once) text = text.replace(" infinite", " 1 forwards");
    text = "/* <svg viewBox=...><path class=\"kmorph\"/></svg> */\n" + text;
  } else if (kind === "svg") {
    text = svgAnimate(result, opts);
    if (once) text = text.replace('repeatCount="indefinite"', 'repeatCount="1" fill="freeze"');
  } else if (kind === "d") {
    text = dList(result);
  } else {
    const req = state.results[0].request;
    text = `import { Client, interpolator } from "./kmorph.js";\n` +
           `const km = new Client({ baseUrl: ${JSON.stringify(location.origin)} });\n` +
           `const result = await km.morph(${JSON.stringify({ ...req, method: result.method, metrics: false })});\n` +
           `const at = interpolator(result);      // t in [0, 1] -> path d\n` +
           `const [x1, y1, x2, y2] = ${JSON.stringify(opts.easing)}, ms = ${opts.duration * 1000};\n` +
           `// ease(p) solves the cubic-bezier (x1, y1, x2, y2) for p; at(ease(p)) each frame:\n` +
           `// requestAnimationFrame((now) => path.setAttribute("d", at(ease(((now - start) % ms) / ms))));\n`;
  }
  $("#export-text").value = text;
  $("#export-text").dataset.kind = kind;
  $("#export-status").textContent = `${kind === "d" ? "d list" : kind.toUpperCase()}: ${result.frames.length} frames, ${Math.round(text.length / 1024)} KiB`;
}

async function copyText(text, what) {
  try {
    await navigator.clipboard.writeText(text);
    $("#export-status").textContent = `${what} copied`;
  } catch {
    $("#export-text").select();
    $("#export-status").textContent = `${what}: select and copy it from the box (the browser did not allow copying)`;
  }
}

/* The state kept in the URL's fragment: both curves' text and the options. */
const URL_FIELDS = ["method", "frames", "matches-mode", "closure", "anchor", "blend", "tolerance", "repeat", "duration", "easing"];
const URL_CHECKS = ["keep-starts"];

function saveUrl() {
  const st = { from: $("#curve-from").value, to: $("#curve-to").value };
  for (const id of URL_FIELDS) st[id] = $("#" + id).value;
  for (const id of URL_CHECKS) st[id] = $("#" + id).checked;
  history.replaceState(null, "", "#" + encodeURIComponent(JSON.stringify(st)));
}

/** Fill the page from the URL's fragment; false when it holds none. */
function loadUrl() {
  if (location.hash.length < 2) return false;
  let st;
  try { st = JSON.parse(decodeURIComponent(location.hash.slice(1))); } catch { return false; }
  if (!st || typeof st.from !== "string" || typeof st.to !== "string") return false;
  for (const id of URL_FIELDS) if (typeof st[id] === "string") $("#" + id).value = st[id];
  for (const id of URL_CHECKS) if (typeof st[id] === "boolean") $("#" + id).checked = st[id];
  for (const which of ["from", "to"]) {
    $("#curve-" + which).value = st[which];
    $(`select.pick[data-testid=pick-${which}]`).value = "";
    updateCurve(which);
  }
  return true;
}

// ------------------------------------------------------------------ setup

function fillSelects() {
  const ex = $("#example");
  for (const [id, label] of PAIRS) ex.add(new Option(label, id));
  for (const sel of document.querySelectorAll("select.pick")) {
    sel.add(new Option("(custom)", ""));
    for (const [id, c] of Object.entries(CURVES)) sel.add(new Option(c.label, id));
  }
}

function chooseCurve(which, id) {
  const c = CURVES[id];
  if (!c) return;
  $(`select.pick[data-testid=pick-${which}]`).value = id;
  $("#curve-" + which).value = curveText(c.curve);
  $(`.draw-closed[data-which=${which}]`).checked = c.curve.type === "svg" && /z\s*$/i.test(c.curve.d);
  updateCurve(which);
}

function chooseExample(id) {
  const pair = PAIRS.find((p) => p[0] === id);
  if (!pair) return;
  state.matches = [];
  state.pending = null;
  $("#keep-starts").checked = false;
  if ($("#matches-mode").value === "pairs") $("#matches-mode").value = "none";
  chooseCurve("from", pair[2]);
  chooseCurve("to", pair[3]);
}

function init() {
  fillSelects();
  $("#example").addEventListener("change", (e) => chooseExample(e.target.value));
  for (const which of ["from", "to"]) {
    $(`select.pick[data-testid=pick-${which}]`).addEventListener("change", (e) => chooseCurve(which, e.target.value));
    let timer = null;
    $("#curve-" + which).addEventListener("input", () => {
      $(`select.pick[data-testid=pick-${which}]`).value = "";
      clearTimeout(timer);
      timer = setTimeout(() => updateCurve(which), 300);
    });
    $(`.draw[data-which=${which}]`).addEventListener("click", () => toggleDraw(which));
    $(`.reverse[data-which=${which}]`).addEventListener("click", () => steer(which, { reverse: true }));
    $(`.start-prev[data-which=${which}]`).addEventListener("click", () => steer(which, { rotate: -1 }));
    $(`.start-next[data-which=${which}]`).addEventListener("click", () => steer(which, { rotate: 1 }));
    $(`.draw-closed[data-which=${which}]`).addEventListener("change", (e) => {
      if (state.drawing === which) { renderEditor(); return; }
      setClosed(which, e.target.checked);
    });
  }
  $("#editor").addEventListener("click", (ev) => {
    if (state.suppressClick) { state.suppressClick = false; return; }
    onEditorClick(ev);
  });
  $("#editor").addEventListener("pointermove", onDragMove);
  $("#editor").addEventListener("pointerup", onDragEnd);
  $("#editor").addEventListener("pointercancel", () => { state.drag = null; });
  $("#editor").addEventListener("keydown", (e) => {
    if (e.target !== $("#editor") || !state.drawing) return;
    const moves = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1] };
    if (e.key === "Enter") { e.preventDefault(); addPointByKey(); }
    else if (moves[e.key]) { e.preventDefault(); nudgePoint(...moves[e.key]); }
  });
  $("#undo-point").addEventListener("click", undoPoint);
  $("#add-point").addEventListener("click", addPointByKey);
  document.addEventListener("keydown", (e) => {
    if (state.drawing && (e.ctrlKey || e.metaKey) && !e.shiftKey && e.key.toLowerCase() === "z") {
      e.preventDefault();
      undoPoint();
    }
  });
  $("#pick-matches").addEventListener("click", () => {
    if (state.picking) { stopPicking(); renderEditor(); return; }
    if (state.drawing) toggleDraw(state.drawing);
    if (isCompound()) {
      $("#editor-hint").textContent = "Picked pairs match points of single curves; the contours of compound shapes are paired by the service (see the colours after Morph).";
      return;
    }
    state.picking = true;
    $("#editor").classList.add("picking");
    $("#pick-matches").textContent = "Stop picking";
    $("#editor-hint").textContent = "Click a point on the from curve, then its partner on the to curve.";
  });
  $("#clear-matches").addEventListener("click", () => { state.matches = []; state.pending = null; renderEditor(); });
  for (const sel of Object.values(INPUT_OF))
    $(sel).addEventListener("input", () => {
      $(sel).parentElement.classList.remove("has-error");
      setFieldError("options", "");
      setFieldError("general", "");
    });
  $("#outline-only").addEventListener("change", (e) => document.body.classList.toggle("outlines", e.target.checked));
  $("#morph").addEventListener("click", runMorph);
  $("#cancel").addEventListener("click", () => state.controller && state.controller.abort());
  $("#scrub").addEventListener("input", (e) => { stop(); setT(Number(e.target.value) / state.steps); });
  $("#play").addEventListener("click", () => (state.playing ? stop() : play()));
  $("#download-json").addEventListener("click", downloadJson);
  $("#download-svg").addEventListener("click", downloadSvg);
  $("#step-back").addEventListener("click", () => stepFrame(-1));
  $("#step-on").addEventListener("click", () => stepFrame(1));
  document.addEventListener("keydown", onKey);
  for (const [id, kind] of [["#export-css", "css"], ["#export-svg", "svg"], ["#export-js", "js"], ["#export-d", "d"]])
    $(id).addEventListener("click", () => showExport(kind));
  $("#export-copy").addEventListener("click", () => copyText($("#export-text").value, "export"));
  $("#share").addEventListener("click", () => { saveUrl(); copyText(location.href, "link"); });
  if (!loadUrl()) chooseExample(PAIRS[0][0]);
  document.body.dataset.ready = "1";
}

init();
