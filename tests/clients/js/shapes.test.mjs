// shapes.test.mjs - the JavaScript client (clients/js/kmorph.js) with compound
// shapes against a live kmorphd: real glyph and icon pairs from
// tests/fixtures/compound morph with frames 0 and 1 equal to the inputs'
// contours (each input path parsed and sampled here, independently of the
// client and the service), a valid contour pairing, a caller's pairing
// honoured, a vanishing contour null at t = 1 and shrinking to a point in
// the interpolator, jobs, and errors naming the contour.
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import path from "node:path";
import { startDaemon, ROOT } from "../lib/daemon.mjs";
import { Client, KmorphError, curve, shape, pathContours, morphRequest, isCompound, contourPairs, frameContours,
         frameContourPaths, framePath, framePaths, interpolator, bounds } from "../../../clients/js/kmorph.js";

const FIXTURES = path.join(ROOT, "tests", "fixtures", "compound");
const byId = new Map();
for (const g of JSON.parse(readFileSync(path.join(FIXTURES, "glyphs.json"), "utf8")).glyphs) byId.set(g.id, g);
for (const i of JSON.parse(readFileSync(path.join(FIXTURES, "icons.json"), "utf8")).icons) byId.set(i.id, i);
const pairs = JSON.parse(readFileSync(path.join(FIXTURES, "pairs.json"), "utf8")).pairs;
const pathOf = (id) => { const x = byId.get(id); assert.ok(x, `fixture ${id}`); return x.d; };
const pairOf = (from, to) => {
  const p = pairs.find((q) => q.from === from && q.to === to);
  assert.ok(p, `pair ${from} -> ${to} in pairs.json`);
  return p;
};

let daemon, km;
before(async () => {
  daemon = await startDaemon();
  km = new Client({ baseUrl: daemon.url });
});
after(async () => { if (daemon) await daemon.stop(); });

// ------------------------------------------------ an SVG path, sampled here

/** The subpaths of SVG path data as dense polylines (SVG 1.1 section 8.3:
 * M L H V C S Q T A Z, absolute and relative; arcs by the endpoint to
 * centre conversion of implementation note F.6.5). `per` points per
 * segment, arcs by angle. */
function subpaths(d, per = 48) {
  const tokens = d.match(/[MmLlHhVvCcSsQqTtAaZz]|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?/g);
  const out = [];
  let i = 0, cmd = null, x = 0, y = 0, sx = 0, sy = 0, cur = null, lastC = null, lastQ = null;
  const num = () => Number(tokens[i++]);
  const bez = (P) => {
    for (let k = 1; k <= per; k++) {
      const t = k / per;
      let pts = P.map((p) => p.slice());
      while (pts.length > 1) pts = pts.slice(1).map((p, n) => [pts[n][0] + t * (p[0] - pts[n][0]), pts[n][1] + t * (p[1] - pts[n][1])]);
      cur.push(pts[0]);
    }
  };
  const arc = (rx, ry, phiDeg, large, sweep, x2, y2) => {
    if (rx === 0 || ry === 0) { cur.push([x2, y2]); return; }
    rx = Math.abs(rx); ry = Math.abs(ry);
    const phi = phiDeg * Math.PI / 180, c = Math.cos(phi), s = Math.sin(phi);
    const dx = (x - x2) / 2, dy = (y - y2) / 2;
    const x1p = c * dx + s * dy, y1p = -s * dx + c * dy;
    const lambda = (x1p * x1p) / (rx * rx) + (y1p * y1p) / (ry * ry);
    if (lambda > 1) { rx *= Math.sqrt(lambda); ry *= Math.sqrt(lambda); }
    const num2 = rx * rx * ry * ry - rx * rx * y1p * y1p - ry * ry * x1p * x1p;
    let f = Math.sqrt(Math.max(0, num2 / (rx * rx * y1p * y1p + ry * ry * x1p * x1p)));
    if (large === sweep) f = -f;
    const cxp = f * rx * y1p / ry, cyp = -f * ry * x1p / rx;
    const cx = c * cxp - s * cyp + (x + x2) / 2, cy = s * cxp + c * cyp + (y + y2) / 2;
    const ang = (ux, uy, vx, vy) => Math.atan2(ux * vy - uy * vx, ux * vx + uy * vy);
    const t1 = ang(1, 0, (x1p - cxp) / rx, (y1p - cyp) / ry);
    let dt = ang((x1p - cxp) / rx, (y1p - cyp) / ry, (-x1p - cxp) / rx, (-y1p - cyp) / ry);
    if (!sweep && dt > 0) dt -= 2 * Math.PI;
    if (sweep && dt < 0) dt += 2 * Math.PI;
    const n = Math.max(4, Math.ceil(Math.abs(dt) / (2 * Math.PI) * 4 * per));
    for (let k = 1; k <= n; k++) {
      const a = t1 + dt * k / n;
      cur.push([cx + rx * Math.cos(a) * c - ry * Math.sin(a) * s, cy + rx * Math.cos(a) * s + ry * Math.sin(a) * c]);
    }
  };
  while (i < tokens.length) {
    if (/[A-Za-z]/.test(tokens[i])) cmd = tokens[i++];
    const rel = cmd === cmd.toLowerCase(), ox = rel ? x : 0, oy = rel ? y : 0;
    switch (cmd.toUpperCase()) {
      case "M": {
        x = ox + num(); y = oy + num(); sx = x; sy = y;
        cur = [[x, y]]; out.push(cur);
        cmd = rel ? "l" : "L"; lastC = lastQ = null; break;
      }
      case "Z": x = sx; y = sy; cur.push([x, y]); cur = [[x, y]]; out.push(cur); lastC = lastQ = null; break;
      case "L": { const nx = ox + num(), ny = oy + num(); bez([[x, y], [nx, ny]]); x = nx; y = ny; lastC = lastQ = null; break; }
      case "H": { const nx = ox + num(); bez([[x, y], [nx, y]]); x = nx; lastC = lastQ = null; break; }
      case "V": { const ny = (rel ? y : 0) + num(); bez([[x, y], [x, ny]]); y = ny; lastC = lastQ = null; break; }
      case "C": case "S": {
        let c1;
        if (cmd.toUpperCase() === "C") c1 = [ox + num(), oy + num()];
        else c1 = lastC ? [2 * x - lastC[0], 2 * y - lastC[1]] : [x, y];
        const c2 = [ox + num(), oy + num()], e = [ox + num(), oy + num()];
        bez([[x, y], c1, c2, e]); lastC = c2; lastQ = null; [x, y] = e; break;
      }
      case "Q": case "T": {
        let c1;
        if (cmd.toUpperCase() === "Q") c1 = [ox + num(), oy + num()];
        else c1 = lastQ ? [2 * x - lastQ[0], 2 * y - lastQ[1]] : [x, y];
        const e = [ox + num(), oy + num()];
        bez([[x, y], c1, e]); lastQ = c1; lastC = null; [x, y] = e; break;
      }
      case "A": {
        const rx = num(), ry = num(), phi = num(), large = num() !== 0, sweep = num() !== 0;
        const nx = ox + num(), ny = oy + num();
        arc(rx, ry, phi, large, sweep, nx, ny); x = nx; y = ny; lastC = lastQ = null; break;
      }
      default: throw new Error(`path command ${cmd}`);
    }
  }
  return out.filter((p) => p.length > 1);
}

/** Distance from point q to the polyline P. */
function toPolyline(q, P) {
  let best = Infinity;
  for (let k = 1; k < P.length; k++) {
    const [ax, ay] = P[k - 1], [bx, by] = P[k], vx = bx - ax, vy = by - ay;
    const L2 = vx * vx + vy * vy;
    const u = L2 > 0 ? Math.min(1, Math.max(0, ((q[0] - ax) * vx + (q[1] - ay) * vy) / L2)) : 0;
    best = Math.min(best, Math.hypot(ax + u * vx - q[0], ay + u * vy - q[1]));
  }
  return best;
}

/** Symmetric Hausdorff distance between two dense polylines. */
function hausdorff(P, Q) {
  let h = 0;
  for (const p of P) h = Math.max(h, toPolyline(p, Q));
  for (const q of Q) h = Math.max(h, toPolyline(q, P));
  return h;
}

const polyLength = (P) => P.slice(1).reduce((s, p, k) => s + Math.hypot(p[0] - P[k][0], p[1] - P[k][1]), 0);

/** Tolerance of every request here (font units of a 100-unit em, icon
 * units of a 24-unit box) and the margin allowed beyond it for the
 * sampling of both sides (48 points per input segment, 16 per Bézier of
 * the frame: chords within 1e-4 of the curves at these sizes) and the
 * 1e-6 rounding of path numbers: 2e-5 of the shape's size. */
const TOL = { glyph: 0.01, icon: 0.003 };
const MARGIN = { glyph: 0.002, icon: 0.0005 };

/** Frames 0 and 1 reproduce the inputs: slot k of frame 0 is contour i of
 * `from` for the pair [i, j] (null when i is null), of frame 1 contour j
 * of `to`; each compared as point sets (start point and direction free). */
function assertEndsAreInputs(res, fromD, toD, bound) {
  let worst = 0;
  const ends = [[res.frames[0], subpaths(fromD), 0], [res.frames[res.frames.length - 1], subpaths(toD), 1]];
  for (const [frame, inputs, side] of ends) {
    const paths = frameContourPaths(frame);
    assert.equal(paths.length, res.contour_matches_used.length, "one contour per slot");
    res.contour_matches_used.forEach((pair, k) => {
      const want = pair[side];
      if (want === null) { assert.equal(paths[k], null, `slot ${k} at t = ${side} is collapsed`); return; }
      assert.notEqual(paths[k], null, `slot ${k} at t = ${side} is present`);
      const mine = subpaths(paths[k], 16);
      assert.equal(mine.length, 1, "one subpath per contour");
      const h = hausdorff(mine[0], inputs[want]);
      assert.ok(h <= bound, `t = ${side}, slot ${k} (contour ${want}): distance ${h} > ${bound}`);
      worst = Math.max(worst, h);
    });
  }
  return worst;
}

/** Every contour of either side appears exactly once across the pairs. */
function assertValidAssignment(used, nFrom, nTo) {
  const seenFrom = new Array(nFrom).fill(0), seenTo = new Array(nTo).fill(0);
  for (const [i, j] of used) {
    assert.ok(i !== null || j !== null, "no empty pair");
    if (i !== null) { assert.ok(Number.isInteger(i) && i >= 0 && i < nFrom); seenFrom[i]++; }
    if (j !== null) { assert.ok(Number.isInteger(j) && j >= 0 && j < nTo); seenTo[j]++; }
  }
  assert.deepEqual(seenFrom, new Array(nFrom).fill(1), `from contours ${seenFrom}`);
  assert.deepEqual(seenTo, new Array(nTo).fill(1), `to contours ${seenTo}`);
}

const CASES = [
  ["dejavu-serif/0", "dejavu-serif/O", "a ring to a ring"],
  ["dejavu-sans/O", "dejavu-sans/C", "O -> C: the counter vanishes"],
  ["dejavu-sans/i", "dejavu-sans/l", "i -> l: the dot vanishes"],
  ["mdi/circle-double", "mdi/target", "four rings to three"],
  ["mdi/dice-3", "mdi/dice-5", "a 4-contour icon gains two pips"],
];

for (const [from, to, why] of CASES) {
  test(`${from} -> ${to} (${why}): frames 0 and 1 are the inputs' contours, the pairing is an assignment`, async (t) => {
    const pair = pairOf(from, to);
    const kind = pair.kind;
    const req = morphRequest(pathOf(from), pathOf(to), { frames: 5, tolerance: TOL[kind] });
    const res = await km.morph(req);
    assert.ok(isCompound(res));
    assert.equal(res.frames.length, 5);
    assertValidAssignment(res.contour_matches_used, pair.counts[0], pair.counts[1]);
    assert.deepEqual(contourPairs(res), res.contour_matches_used.map(([f, t], slot) => ({ slot, from: f, to: t })));
    const worst = assertEndsAreInputs(res, pathOf(from), pathOf(to), TOL[kind] + MARGIN[kind]);
    t.diagnostic(`${from} -> ${to}: ends within ${worst.toPrecision(3)} of the inputs (tolerance ${TOL[kind]})`);
    /* The combined path has one closed subpath per present contour. */
    for (const f of res.frames) {
      const present = frameContours(f).filter((c) => c !== null).length;
      const d = framePath(f);
      assert.equal((d.match(/M/g) || []).length, present);
      assert.equal((d.match(/Z/g) || []).length, present);
    }
    /* A B-spline lies in its control polygon's hull: bounds holds every
     * contour of every frame (paths are written to 1e-6). */
    const [x0, y0, x1, y1] = bounds(res);
    for (const f of res.frames)
      for (const d of frameContourPaths(f))
        for (const [x, y] of d ? subpaths(d, 8)[0] : [])
          assert.ok(x >= x0 - 1e-6 && x <= x1 + 1e-6 && y >= y0 - 1e-6 && y <= y1 + 1e-6, `(${x}, ${y}) outside the bounds`);
  });
}

test("O -> C: the counter is null at t = 1 and the service's svg_d is the client's combined path", async () => {
  const res = await km.morph(morphRequest(pathOf("dejavu-sans/O"), pathOf("dejavu-sans/C"),
                                          { frames: 3, tolerance: TOL.glyph, include: ["svg_d"] }));
  const slot = res.contour_matches_used.findIndex(([, j]) => j === null);
  assert.ok(slot >= 0, "one contour of O has no partner in C");
  const last = res.frames[2];
  assert.equal(frameContours(last)[slot], null);
  assert.equal(frameContours(res.frames[1])[slot] !== null, true);
  assert.equal(framePaths(res)[2], last.svg_d);
  assert.equal((last.svg_d.match(/M/g) || []).length, 1);
  /* Without svg_d the client writes the same shape itself. */
  const mine = subpaths(framePath({ t: 1, contours: last.contours.map((c) => c && { ...c, svg_d: undefined }) }), 16);
  const theirs = subpaths(last.svg_d, 16);
  assert.equal(mine.length, 1);
  /* The service writes its numbers to within the tolerance, not more. */
  assert.ok(hausdorff(mine[0], theirs[0]) <= TOL.glyph, `${hausdorff(mine[0], theirs[0])}`);
});

test("O -> C interpolator: the counter shrinks monotonically to length 0 at t = 1, one structure throughout", async () => {
  const res = await km.morph(morphRequest(pathOf("dejavu-sans/O"), pathOf("dejavu-sans/C"),
                                          { frames: 5, tolerance: TOL.glyph }));
  const slot = res.contour_matches_used.findIndex(([, j]) => j === null);
  const at = interpolator(res, { samples: 120, perContour: true });
  const whole = interpolator(res, { samples: 120 });
  const shape0 = whole(0).replace(/-?[\d.e]+/g, "#");
  let prev = Infinity;
  for (let k = 0; k <= 40; k++) {
    const t = k / 40;
    const d = at(t)[slot];
    assert.notEqual(d, null);
    const len = polyLength(subpaths(d, 1)[0]);
    assert.ok(len <= prev + 1e-9, `t = ${t}: length ${len} after ${prev}`);
    prev = len;
    assert.equal(whole(t).replace(/-?[\d.e]+/g, "#"), shape0, `structure at t = ${t}`);
  }
  assert.ok(prev < 1e-9, `length at t = 1 is ${prev}`);
  /* With collapsed: "omit" the point is left out at t = 1 and only there. */
  const omit = interpolator(res, { samples: 120, collapsed: "omit" });
  assert.equal((omit(1).match(/M/g) || []).length, 1);
  assert.equal((omit(0.99).match(/M/g) || []).length, 2);
  /* At a frame's t the interpolator is that frame. */
  const mid = subpaths(at(0.5)[slot], 1)[0];
  const frame = subpaths(frameContourPaths(res.frames[2])[slot], 16)[0];
  assert.ok(hausdorff(mid, frame) < 0.05, `t = 0.5: ${hausdorff(mid, frame)}`);
});

test("a caller's contour_matches is honoured: frame 1's slots are the contours it names", async () => {
  const from = pathOf("mdi/dice-3"), to = pathOf("mdi/dice-5");
  const auto = await km.morph(morphRequest(from, to, { frames: 2, tolerance: TOL.icon }));
  /* dice-3: the die and its pips 1-3; give each pip the to-contour of the
   * same index and let 4 and 5 appear, which the automatic pairing does not. */
  const mine = [[0, 0], [1, 1], [2, 2], [3, 3], [null, 4], [null, 5]];
  assert.notDeepEqual(auto.contour_matches_used, mine, "the test's pairing differs from the automatic one");
  const res = await km.morph(morphRequest(from, to, { frames: 2, tolerance: TOL.icon, contourMatches: mine }));
  assert.deepEqual([...res.contour_matches_used].sort(), [...mine].sort());
  assertValidAssignment(res.contour_matches_used, 4, 6);
  assertEndsAreInputs(res, from, to, TOL.icon + MARGIN.icon);
});

test("a shape object gives the same morph as the compound SVG path", async () => {
  const d = pathOf("liberation-sans/i");
  const parts = d.match(/M[^M]*/g).map((s) => s.trim());
  assert.equal(parts.length, 2);
  const a = await km.morph(morphRequest(d, pathOf("liberation-sans/j"), { frames: 3, tolerance: TOL.glyph }));
  const b = await km.morph(morphRequest(shape(parts, { fillRule: "nonzero" }), pathOf("liberation-sans/j"),
                                        { frames: 3, tolerance: TOL.glyph }));
  assert.deepEqual(b, a);
  assert.deepEqual(curve(parts), { type: "shape", contours: parts.map((p) => ({ type: "svg", d: p })) });
});

test("a morph job of shapes reports progress and answers the synchronous morph's frames", async () => {
  const req = morphRequest(pathOf("mdi/circle-double"), pathOf("mdi/target"), { frames: 9, tolerance: TOL.icon });
  const seen = [];
  const res = await km.morphJob(req, { onProgress: (s) => seen.push(s.progress) });
  assert.equal(seen[seen.length - 1], 1);
  const sync = await km.morph(req);
  assert.deepEqual(res.contour_matches_used, sync.contour_matches_used);
  assert.deepEqual(framePaths(res), framePaths(sync));
});

test("the signature of a shape answers one signature and role per contour", async () => {
  const r = await km.signature(curve(pathOf("dejavu-sans/O")));
  assert.equal(r.signatures.length, 2);
  assert.deepEqual([...r.roles].sort(), ["hole", "outer"]);
  /* The outer contour of O is longer than its counter. */
  const outer = r.roles.indexOf("outer"), hole = r.roles.indexOf("hole");
  assert.ok(r.signatures[outer].length > r.signatures[hole].length);
});

test("a bad contour is a KmorphError naming /from/contours/K; a bad subpath names its index and offset", async () => {
  const good = "M 0 0 L 10 0 L 10 10 Z";
  await assert.rejects(km.morph(morphRequest(shape([good, "M 20 0 L 30 0 L 30 10"]), good)), (e) => {
    assert.ok(e instanceof KmorphError);
    assert.equal(e.status, 422);
    assert.ok(e.messageFor("/from/contours/1"), JSON.stringify(e.errors));
    assert.deepEqual(e.contourErrors().map(({ side, contour }) => ({ side, contour })), [{ side: "from", contour: 1 }]);
    return true;
  });
  const bad = "M 0 0 L 10 0 L 10 10 Z M 20 0 L 20 0 Z";
  await assert.rejects(km.morph(morphRequest(good, bad)), (e) => {
    const [c] = e.contourErrors();
    assert.equal(c.side, "to");
    assert.equal(c.contour, 1);
    assert.equal(c.offset, bad.indexOf("M 20"), c.message);
    return true;
  });
  await assert.rejects(km.morph(morphRequest(good, shape([good, { type: "points", points: [[1, 1]], closed: true }]))),
                       (e) => e.contourErrors()[0].pointer.startsWith("/to/contours/1"));
});

test("pathContours closes an icon's open subpaths as SVG fills them: the shipped d is a 422, its contours morph", async () => {
  const icon = byId.get("mdi/lock"), to = pathOf("mdi/lock-outline");
  assert.notEqual(icon.d_source, icon.d, "mdi ships this icon with open subpaths");
  await assert.rejects(km.morph(morphRequest(icon.d_source, to, { frames: 2 })), (e) => {
    assert.equal(e.status, 422);
    assert.deepEqual(e.contourErrors().map((c) => [c.side, c.contour]), [["from", 0]]);
    return true;
  });
  const parts = pathContours(icon.d_source);
  assert.equal(parts.length, icon.subpaths);
  /* Each contour is the same point set as that subpath of the closed d. */
  const closed = subpaths(icon.d);
  parts.forEach((p, k) => {
    assert.match(p, /^M[^Mm]*[Zz]$/);
    const mine = subpaths(p);
    assert.equal(mine.length, 1);
    assert.ok(hausdorff(mine[0], closed[k]) < 1e-9, `contour ${k}`);
  });
  const a = await km.morph(morphRequest(parts.join(" "), to, { frames: 3, tolerance: TOL.icon }));
  const b = await km.morph(morphRequest(icon.d, to, { frames: 3, tolerance: TOL.icon }));
  assert.deepEqual(a, b);
});

test("pathContours starts each contour with an absolute moveto: relative subpaths stay where they were", () => {
  /* Two squares, the second placed by a relative moveto from the open
   * first one's last point (10, 30): its corners are (15, 35) and (25, 45). */
  const d = "m 10 10 h 20 v 20 h -20 m 5 5 h 10 v 10 h -10";
  const parts = pathContours(d);
  assert.equal(parts.length, 2);
  const box = (pts) => [Math.min(...pts.map((p) => p[0])), Math.min(...pts.map((p) => p[1])),
                        Math.max(...pts.map((p) => p[0])), Math.max(...pts.map((p) => p[1]))];
  assert.deepEqual(box(subpaths(parts[0])[0]), [10, 10, 30, 30]);
  assert.deepEqual(box(subpaths(parts[1])[0]), [15, 35, 25, 45]);
  /* Closing adds the fourth side: the perimeter is 4 times the side. */
  assert.ok(Math.abs(polyLength(subpaths(parts[1])[0]) - 40) < 1e-9);
  assert.deepEqual(pathContours("M 0 0 M 1 1 L 2 1 L 2 2 Z", { close: false }), ["M1,1L2 1L2 2Z"]);
  assert.deepEqual(pathContours("M0 0h5v5Z", { close: false }), ["M0,0h5v5Z"]);
  assert.throws(() => pathContours("M 0 0 X 1"), /offset 6/);
});

test("a shape from one d under evenodd makes an inner square of the same turn a hole; nonzero fills it", async () => {
  const d = "M 0 0 L 10 0 L 10 10 L 0 10 Z M 2 2 L 8 2 L 8 8 L 2 8 Z";
  const evenodd = await km.signature(shape(d, { fillRule: "evenodd" }));
  const nonzero = await km.signature(shape(d));
  /* The inner square's region is inside both contours: winding number 2,
   * filled under nonzero, empty (even) under evenodd. */
  assert.deepEqual(evenodd.roles, ["outer", "hole"]);
  assert.equal(evenodd.fill_rule, "evenodd");
  assert.deepEqual(nonzero.roles, ["outer", "outer"]);
});

test("i -> l between frames: the vanishing dot follows the service's frames into its point", async () => {
  const from = pathOf("dejavu-sans/i"), to = pathOf("dejavu-sans/l");
  const res = await km.morph(morphRequest(from, to, { frames: 11, tolerance: 0.001 }));
  const slot = res.contour_matches_used.findIndex(([, j]) => j === null);
  const truth = await km.morph(morphRequest(from, to, { times: [0.95, 0.99], tolerance: 0.001,
                                                        contourMatches: res.contour_matches_used }));
  const at = interpolator(res, { samples: 400, perContour: true });
  /* The dot's centre moves on a smooth track: carried on from the frames
   * at 0.8 and 0.9 it lands within 2e-4 of the em of the service's dot
   * (which is at most 2.2 long here, so 400 samples cut its corners by
   * less than 0.003); the centre of the frame at 0.9 alone is 0.27 off. */
  for (const f of truth.frames) {
    const h = hausdorff(subpaths(frameContourPaths(f)[slot], 16)[0], subpaths(at(f.t)[slot], 1)[0]);
    assert.ok(h < 0.02, `t = ${f.t}: ${h}`);
  }
});

test("pathContours of every fixture glyph and icon (and each icon as shipped) gives the same signatures as its closed d", async () => {
  let n = 0;
  for (const x of byId.values()) {
    const want = await km.signature(curve(x.d));
    for (const d of x.d_source ? [x.d, x.d_source] : [x.d]) {
      const parts = pathContours(d);
      assert.equal(parts.length, want.signatures ? want.signatures.length : 1, x.id);
      assert.deepEqual(await km.signature(curve(parts.join(" "))), want, x.id);
      n++;
    }
  }
  assert.equal(n, byId.size + [...byId.values()].filter((x) => x.d_source).length);
});
