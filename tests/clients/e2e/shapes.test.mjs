// shapes.test.mjs - compound shapes on the page: pasted multi-subpath SVG
// paths and JSON shapes are drawn filled under their fill rule, morph, and
// show which contour went to which (one colour per pair on both inputs and
// on every frame); the built-in glyph and icon pairs morph.
import { test } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { useBrowser, openPage, waitForEditor, morphAndWait, answerFor, setScrub, screenshot,
         ROOT } from "./harness.mjs";

const env = useBrowser();
const FIX = path.join(ROOT, "tests", "fixtures", "compound");
const glyphs = Object.fromEntries(JSON.parse(fs.readFileSync(path.join(FIX, "glyphs.json"), "utf8")).glyphs
  .map((g) => [g.id, g]));

/** Subpaths of path data whose movetos are all absolute and each followed
 * by drawing, as the fixtures are written: the count of M commands. */
const subpathCount = (d) => (d.match(/M/g) || []).length;

/** Centre of the box of the numbers of a subpath (x, y pairs). */
function boxOf(d) {
  const v = d.match(/[-+]?(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?/gi).map(Number);
  const xs = v.filter((_, i) => i % 2 === 0), ys = v.filter((_, i) => i % 2 === 1);
  return { x0: Math.min(...xs), x1: Math.max(...xs), y0: Math.min(...ys), y1: Math.max(...ys) };
}

/** Whether the page's path element `sel` fills the point (x, y) in its
 * own coordinates, under its fill rule (the browser's own test). */
function fills(page, sel, x, y) {
  return page.$eval(sel, (p, [x, y]) => p.isPointInFill(new DOMPoint(x, y)), [x, y]);
}

test("a pasted O -> C morphs: contours filled, paired by colour on inputs and frames, the counter shrinks away", async () => {
  const { page, errors, morphs } = await openPage(env);
  const O = glyphs["dejavu-sans/O"].d, C = glyphs["dejavu-sans/C"].d;
  await page.fill("#curve-from", O);
  await page.fill("#curve-to", C);
  await waitForEditor(page);
  /* the O's two subpaths; the C, a single closed curve, is a shape of one contour against it */
  await page.waitForFunction(() => document.querySelectorAll("#editor path.contour[data-which='from']").length === 2 &&
                                    document.querySelectorAll("#editor path.contour[data-which='to']").length === 1,
                             null, { timeout: 10000 });
  /* The O's counter is its smaller subpath; its centre is not filled
   * (nonzero, the counter turning the other way), the ring is. */
  const subs = O.split(/(?=M)/);
  assert.equal(subs.length, 2);
  const boxes = subs.map(boxOf);
  const counter = (boxes[0].x1 - boxes[0].x0) < (boxes[1].x1 - boxes[1].x0) ? 0 : 1;
  const cb = boxes[counter], ob = boxes[1 - counter];
  const mid = [(cb.x0 + cb.x1) / 2, (cb.y0 + cb.y1) / 2];
  assert.equal(await page.getAttribute("#editor path.from", "fill-rule"), "nonzero");
  assert.equal(await fills(page, "#editor path.from", ...mid), false, "the counter is a hole");
  assert.equal(await fills(page, "#editor path.from", (ob.x0 + cb.x0) / 2, mid[1]), true, "the ring is filled");

  await page.selectOption("#method", "both");
  await page.fill("#frames", "11");
  await morphAndWait(page, 2);
  for (const method of ["curvature", "linear"]) {
    const { result } = answerFor(morphs, method, 11);
    const pairs = result.contour_matches_used;
    /* the counter has no partner in C: it vanishes */
    assert.deepEqual(pairs.find((p) => p[1] === null), [counter, null]);
    const panel = `#panel-${method}`;
    const film = await page.$$eval(`${panel} .filmstrip svg`, (els) => els.map((e) => ({
      d: e.querySelector("path.fillable").getAttribute("d"), slots: e.querySelectorAll("path.slot").length,
      bad: e.classList.contains("bad") })));
    assert.equal(film.length, 11);
    result.frames.forEach((f, i) => {
      assert.equal(film[i].d, f.svg_d, `${method} frame ${i} path`);
      assert.equal(film[i].slots, f.contours.filter(Boolean).length, `${method} frame ${i} contours`);
      const m = f.metrics, si = m.contours.filter(Boolean).reduce((s, c) => s + c.self_intersections, 0);
      assert.equal(film[i].bad, si > 0 || m.mutual_intersections > 0 || !m.nesting_ok, `${method} frame ${i} marked`);
    });
    const rows = await page.$$eval(`${panel} table.metrics tbody tr`, (trs) => trs.map((tr) =>
      [...tr.children].map((td) => td.textContent)));
    result.frames.forEach((f, i) => {
      assert.equal(Number(rows[i][7]), f.metrics.mutual_intersections, `${method} row ${i} crossings`);
      assert.equal(rows[i][8], f.metrics.nesting_ok ? "yes" : "no", `${method} row ${i} nesting`);
    });
    assert.equal(await page.$eval(`${panel} .m-mutual`, (e) => getComputedStyle(e.parentElement).display !== "none"), true);
    /* at t = 0 the stage draws frame 0 filled, its contours in their pairs' colours */
    assert.equal(await page.getAttribute(`${panel} .stage path.current`, "d"), result.frames[0].svg_d);
    assert.notEqual(await page.$eval(`${panel} .stage path.current`, (p) => getComputedStyle(p).fill), "none");
    const slotColours = await page.$$eval(`${panel} .stage path.slot`, (l) => l.map((p) => getComputedStyle(p).stroke));
    assert.equal(slotColours.length, pairs.length);
    assert.equal(new Set(slotColours).size, pairs.length, "one colour per pair");
    for (const [k, [i, j]] of pairs.entries()) {
      if (i !== null)
        assert.equal(await page.$eval(`#editor path.contour[data-which='from'][data-contour='${i}']`,
                                      (p) => getComputedStyle(p).stroke), slotColours[k], `from contour ${i}`);
      if (j !== null)
        assert.equal(await page.$eval(`#editor path.contour[data-which='to'][data-contour='${j}']`,
                                      (p) => getComputedStyle(p).stroke), slotColours[k], `to contour ${j}`);
    }
  }
  const list = await page.$$eval("#contour-list li", (l) => l.map((li) => li.textContent));
  assert.ok(list.includes(`from contour ${counter} shrinks to a point`), list.join(" | "));
  assert.ok(list.includes(`from contour ${1 - counter} → to contour 0`), list.join(" | "));
  /* at t = 1 the vanished counter's slot draws nothing; between frames
   * every slot is drawn */
  const cur = answerFor(morphs, "curvature", 11).result;
  const gone = cur.contour_matches_used.findIndex((p) => p[1] === null);
  await setScrub(page, 1);
  assert.equal(await page.getAttribute(`#panel-curvature .stage path.slot[data-slot='${gone}']`, "d"), "");
  await setScrub(page, 0.95);
  assert.match(await page.getAttribute(`#panel-curvature .stage path.slot[data-slot='${gone}']`, "d"), /^M/);
  await setScrub(page, 0.5);
  await screenshot(page, "compound-O-C-t0.5.png");
  /* outlines only: nothing filled, outlines still drawn */
  await page.check("#outline-only");
  assert.equal(await page.$eval("#panel-curvature .stage path.current", (p) => getComputedStyle(p).fill), "none");
  assert.equal(await page.$eval("#editor path.from", (p) => getComputedStyle(p).fill), "none");
  assert.equal(await page.$eval("#panel-curvature .filmstrip svg path.fillable", (p) => getComputedStyle(p).fill), "none");
  assert.notEqual(await page.$eval("#panel-curvature .stage path.slot", (p) => getComputedStyle(p).stroke), "none");
  await screenshot(page, "compound-O-C-outlines.png");
  assert.deepEqual(errors, []);
  await page.close();
});

test("a JSON shape under evenodd is filled by that rule and its frames keep it until t = 1/2", async () => {
  const { page, errors, morphs } = await openPage(env);
  /* two squares turning the same way: a hole only under evenodd */
  const shape = { type: "shape", fill_rule: "evenodd", contours: [
    { type: "svg", d: "M0,0 H40 V40 H0 Z" }, { type: "svg", d: "M10,10 H30 V30 H10 Z" }] };
  await page.fill("#curve-from", JSON.stringify(shape));
  await page.fill("#curve-to", JSON.stringify({ ...shape, fill_rule: "nonzero" }));
  await waitForEditor(page);
  await page.waitForFunction(() => document.querySelectorAll("#editor path.contour").length === 4, null, { timeout: 10000 });
  assert.equal(await page.getAttribute("#editor path.from", "fill-rule"), "evenodd");
  assert.equal(await fills(page, "#editor path.from", 20, 20), false);
  assert.equal(await fills(page, "#editor path.from", 5, 20), true);
  assert.equal(await fills(page, "#editor path.to", 20, 20), true, "nonzero fills the inner square");
  await page.selectOption("#method", "linear");
  await page.fill("#frames", "5");
  await morphAndWait(page, 1);
  const { request } = answerFor(morphs, "linear", 5);
  assert.deepEqual(request.from, shape);
  const stage = "#panel-linear .stage path.current";
  assert.equal(await page.getAttribute(stage, "fill-rule"), "evenodd");
  assert.equal(await fills(page, stage, 20, 20), false);
  await setScrub(page, 1);
  assert.equal(await page.getAttribute(stage, "fill-rule"), "nonzero");
  assert.equal(await fills(page, stage, 20, 20), true);
  assert.deepEqual(errors, []);
  await page.close();
});

test("every built-in compound pair morphs and pairs every contour once", async () => {
  const { page, errors, morphs } = await openPage(env);
  const ids = await page.$$eval("#example option", (o) => o.map((x) => [x.value, x.textContent]));
  const compound = ids.filter(([, label]) => /^Compound/.test(label)).map(([id]) => id);
  assert.ok(compound.length >= 4, compound.join());
  for (const id of ["glyph-O-C", "ring-ring", "dice"]) assert.ok(compound.includes(id), id);
  await page.selectOption("#method", "curvature");
  await page.fill("#frames", "5");
  for (const id of compound) {
    morphs.length = 0;
    await page.selectOption("#example", id);
    await waitForEditor(page);
    const from = await page.inputValue("#curve-from"), to = await page.inputValue("#curve-to");
    await page.waitForFunction(([a, b]) =>
      document.querySelectorAll("#editor path.contour[data-which='from']").length === a &&
      document.querySelectorAll("#editor path.contour[data-which='to']").length === b,
      [subpathCount(from), subpathCount(to)], { timeout: 10000 });
    await morphAndWait(page, 1);
    const { result } = answerFor(morphs, "curvature", 5);
    const pairs = result.contour_matches_used;
    const fromSide = pairs.map((p) => p[0]).filter((i) => i !== null).sort(), toSide = pairs.map((p) => p[1]).filter((j) => j !== null).sort();
    assert.deepEqual(fromSide, [...Array(subpathCount(from)).keys()], `${id}: every from contour once`);
    assert.deepEqual(toSide, [...Array(subpathCount(to)).keys()], `${id}: every to contour once`);
    assert.equal(await page.$$eval("#contour-list li", (l) => l.length), pairs.length, id);
    assert.equal(await page.$$eval("#panel-curvature .stage path.slot", (l) => l.length), pairs.length, id);
    if (id === "dice") {
      await setScrub(page, 0.5);
      await screenshot(page, "compound-dice-t0.5.png");
    }
  }
  assert.deepEqual(errors, []);
  await page.close();
});

test("a relative moveto after Z starts the next contour where SVG puts it", async () => {
  const { page, errors } = await openPage(env);
  /* m is relative to the previous subpath's start (10, 10) after Z */
  await page.fill("#curve-from", "M10,10 h30 v30 h-30 z m5,5 v20 h20 v-20 z");
  await page.fill("#curve-to", "M10,10 h30 v30 h-30 z");
  await waitForEditor(page);
  /* two contours of the from shape, and the closed square against it */
  await page.waitForFunction(() => document.querySelectorAll("#editor path.contour").length === 3, null, { timeout: 10000 });
  const inner = await page.$eval("#editor path.contour[data-which='from'][data-contour='1']", (p) => {
    const b = p.getBBox();
    return [b.x, b.y, b.width, b.height];
  });
  assert.deepEqual(inner, [15, 15, 20, 20]);
  assert.equal(await fills(page, "#editor path.from", 25, 25), false, "the inner square is a hole");
  assert.deepEqual(errors, []);
  await page.close();
});
