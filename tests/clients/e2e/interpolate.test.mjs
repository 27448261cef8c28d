// interpolate.test.mjs - the JS client's flubber-style interpolator in a
// real browser: the module the page is served with, imported into the
// page, asked for a square -> circle morph; every t gives SVG path data
// that the browser itself measures (SVGPathElement.getTotalLength), and
// string: false gives the points the string is drawn through.
// Curvature interpolation blends lengths linearly (the paper's
// L_t = (1 - t) L_0 + t L_1), so a square of side 10 (L_0 = 40) and a
// circle of radius 10 (L_1 = 20 pi) have L_t known exactly at every t.
import { test } from "node:test";
import assert from "node:assert/strict";
import { useBrowser, openPage } from "./harness.mjs";

const env = useBrowser();
const SQUARE = "M 0 0 L 10 0 L 10 10 L 0 10 Z";
const CIRCLE = "M 15 5 A 10 10 0 1 1 -5 5 A 10 10 0 1 1 15 5 Z";

test("interpolate() in the browser: path data at any t, lengths blended linearly", async () => {
  const { page, errors } = await openPage(env);
  const got = await page.evaluate(async ([from, to]) => {
    const km = await import("/kmorph.js");
    const at = await km.interpolate(from, to);
    const points = await km.interpolate(from, to, { string: false });
    const svg = document.createElementNS("http://www.w3.org/2000/svg", "svg");
    const path = document.createElementNS("http://www.w3.org/2000/svg", "path");
    svg.appendChild(path);
    document.body.appendChild(svg);
    const out = [];
    for (const t of [0, 0.25, 0.5, 0.73, 1]) {
      const d = at(t);
      path.setAttribute("d", d);
      out.push({ t, d, length: path.getTotalLength(), points: points(t) });
    }
    svg.remove();
    return out;
  }, [SQUARE, CIRCLE]);
  for (const { t, d, length, points } of got) {
    assert.match(d, /^M/, `t = ${t}: path data`);
    const want = (1 - t) * 40 + t * 20 * Math.PI;
    /* the browser's own arc length is approximate: 0.5% */
    assert.ok(Math.abs(length - want) <= 0.005 * want, `t = ${t}: length ${length}, want ${want}`);
    assert.ok(Array.isArray(points) && points.length > 2, `t = ${t}: point arrays`);
    for (const p of points)
      assert.ok(p.length === 2 && p.every(Number.isFinite), `t = ${t}: a point ${JSON.stringify(p)}`);
  }
  /* the ends are the inputs: the square's corners at t = 0 lie on it */
  const first = got[0].points;
  const onSquare = (x, y) => Math.min(Math.abs(x), Math.abs(x - 10), Math.abs(y), Math.abs(y - 10)) < 1e-3;
  assert.ok(first.every(([x, y]) => onSquare(x, y)), "t = 0 is the square");
  const last = got[got.length - 1].points;
  const r = last.map(([x, y]) => Math.hypot(x - 5, y - 5));
  assert.ok(r.every((v) => Math.abs(v - 10) < 1e-3), "t = 1 is the circle (radius 10 about (5, 5))");
  assert.deepEqual(errors, []);
});
