// steer.test.mjs - correspondence a designer can see and steer: the
// matches and starts the morph used drawn on both curves, a used match
// dragged along its curve (the next request carries it), the start of a
// closed curve rotated vertex by vertex and kept, a curve reversed; and
// undo of drawn points. Expected positions come from the geometry of the
// curves: `to` is `from` moved 40 units right, written from another
// vertex, so the start the service aligns best is from's start moved.
import { test } from "node:test";
import assert from "node:assert/strict";
import { useBrowser, openPage, waitForEditor, morphAndWait, answerFor, screenshot } from "./harness.mjs";

const env = useBrowser();
/* an L (no symmetry, so one start aligns best), perimeter 68 */
const L_FROM = "M0,0 L20,0 L20,6 L8,6 L8,14 L0,14 Z";
const L_TO = "M48,6 L48,14 L40,14 L40,0 L60,0 L60,6 Z";
const PERIMETER = 68;
/* arc length along L_TO from its start to (40,0): 8 + 8 + 14 */
const TO_START_SHIFT = 30 / PERIMETER;
/* the service aligns starts on 512 samples of the length: a start it
 * chooses is within one sample of the exact one */
const ALIGN_STEP = PERIMETER / 512;

async function editorCentre(page, sel) {
  return page.$eval(sel, (c) => [Number(c.getAttribute("cx")), Number(c.getAttribute("cy"))]);
}

function near(p, q, tol, what) {
  assert.ok(Math.hypot(p[0] - q[0], p[1] - q[1]) <= tol, `${what}: ${p} is not within ${tol} of ${q}`);
}

async function setCurves(page, from, to) {
  await page.fill("#curve-from", from);
  await page.fill("#curve-to", to);
  await page.waitForFunction(([a, b]) => {
    const pa = document.querySelector("#editor path.from"), pb = document.querySelector("#editor path.to");
    return pa && pb && pa.getAttribute("d") === a && pb.getAttribute("d") === b;
  }, [from, to], { timeout: 10000 });
}

test("the start the morph chose and its matches are shown on both curves, where the frames put them", async () => {
  const { page, errors, morphs } = await openPage(env);
  await page.selectOption("#method", "curvature");
  await setCurves(page, L_FROM, L_TO);
  /* before a morph the rings mark each curve's own start */
  near(await editorCentre(page, "#editor circle.start[data-which=to]"), [48, 6], 1e-6, "to's own start");
  await page.selectOption("#matches-mode", "auto");
  await morphAndWait(page, 1);
  const { result } = answerFor(morphs, "curvature", 11);
  /* the service started to at from's start moved by (40, 0) */
  near(result.frames[10].curve.control_points[0], [40, 0], ALIGN_STEP, "the last frame's start");
  near(await editorCentre(page, "#editor circle.start[data-which=from]"), [0, 0], 0.4, "from's start ring");
  near(await editorCentre(page, "#editor circle.start[data-which=to]"), [40, 0], 0.4, "to's start ring");
  /* both arrows leave their start along the first edge, +x */
  for (const which of ["from", "to"]) {
    const d = await page.$eval(`#editor path.direction[data-which=${which}]`, (p) => p.getAttribute("d"));
    const [x0, y0, x1, y1] = d.match(/-?[\d.e-]+/g).slice(0, 4).map(Number);
    assert.ok(x1 - x0 > 1 && Math.abs(y1 - y0) < 0.3, `${which} arrow ${d}`);
  }
  /* every used match is drawn on both curves; congruent curves pair
   * points 40 units apart */
  const used = result.matches_used;
  assert.ok(used.length >= 1, "auto matches on an L: its corners");
  const handles = await page.$$eval("#editor circle.used", (cs) => cs.map((c) => ({
    which: c.dataset.which, i: Number(c.dataset.index), x: Number(c.getAttribute("cx")), y: Number(c.getAttribute("cy")),
    name: c.getAttribute("aria-label") })));
  assert.equal(handles.length, 2 * used.length);
  for (let i = 0; i < used.length; i++) {
    const a = handles.find((h) => h.i === i && h.which === "from"), b = handles.find((h) => h.i === i && h.which === "to");
    near([b.x - a.x, b.y - a.y], [40, 0], 0.6, `match ${i + 1}`);
    assert.match(a.name, /match \d+ on the from curve/);
  }
  await screenshot(page, "steer-used.png");
  assert.deepEqual(errors, []);
  await page.close();
});

test("dragging a used match along its curve morphs again with it, from the start the morph chose", async () => {
  const { page, errors, requests, morphs } = await openPage(env);
  await page.selectOption("#method", "curvature");
  await setCurves(page, L_FROM, L_TO);
  await page.selectOption("#matches-mode", "auto");
  await morphAndWait(page, 1);
  const used = answerFor(morphs, "curvature", 11).result.matches_used;
  /* the first to handle, its arc-length fraction on L_TO (found here by
   * scanning the path), and a point 2% of the length further on */
  const target = await page.$eval("#editor circle.used[data-which=to][data-index='0']", (c) => {
    const p = document.querySelector("#editor path.to"), L = p.getTotalLength();
    const cx = Number(c.getAttribute("cx")), cy = Number(c.getAttribute("cy"));
    let best = 0, bd = Infinity;
    for (let i = 0; i <= 6800; i++) {
      const q = p.getPointAtLength(L * i / 6800), d = Math.hypot(q.x - cx, q.y - cy);
      if (d < bd) { bd = d; best = i / 6800; }
    }
    const f = (best + 0.02) % 1, q = p.getPointAtLength(L * f), m = p.ownerSVGElement.getScreenCTM();
    const screen = (x, y) => ({ x: x * m.a + y * m.c + m.e, y: x * m.b + y * m.d + m.f });
    return { f, from: screen(cx, cy), to: screen(q.x, q.y) };
  });
  const before = Number(await page.evaluate(() => document.body.dataset.morphs));
  const sent = requests.length;
  await page.mouse.move(target.from.x, target.from.y);
  await page.mouse.down();
  await page.mouse.move((target.from.x + target.to.x) / 2, (target.from.y + target.to.y) / 2, { steps: 3 });
  await page.mouse.move(target.to.x, target.to.y, { steps: 3 });
  await page.mouse.up();
  await page.waitForFunction((k) => Number(document.body.dataset.morphs) > k && !document.querySelector("#morph").disabled,
                             before, { timeout: 60000 });
  await Promise.all(page.kmPending);
  const req = JSON.parse(requests.slice(sent).filter((r) => r.path === "/v1/morph").pop().body);
  /* to now starts where the morph started it, so the starts still correspond */
  assert.match(req.to.d, /^M40,0 /);
  assert.equal(await page.$eval("#keep-starts", (c) => c.checked), true);
  assert.equal(req.matches.length, used.length);
  const expected = ((target.f - TO_START_SHIFT) % 1 + 1) % 1;
  assert.ok(Math.abs(req.matches[0][1] - expected) < 0.004, `dragged to ${req.matches[0][1]}, expected ${expected}`);
  /* the other pairs are the used ones, in the same frame of reference */
  for (let i = 1; i < used.length; i++) assert.ok(Math.abs(req.matches[i][1] - used[i][1]) < 0.004, `pair ${i + 1}`);
  const last = morphs[morphs.length - 1].result;
  assert.ok(Math.abs(last.matches_used[0][1] - expected) < 0.004);
  assert.deepEqual(errors, []);
  await page.close();
});

test("Start ◀ ▶ rotates a closed curve's start vertex by vertex and the morph keeps it; Reverse runs it backwards", async () => {
  const { page, errors, morphs } = await openPage(env);
  await page.selectOption("#method", "curvature");
  await setCurves(page, L_FROM, L_TO);
  for (let i = 0; i < 4; i++) await page.click(".start-next[data-which=to]");
  await page.click(".start-prev[data-which=to]");
  /* three vertices on: (48,6) -> (48,14) -> (40,14) -> (40,0) */
  assert.match(await page.inputValue("#curve-to"), /^M40,0 L60,0 L60,6 L48,6 L48,14 L40,14 Z$/);
  assert.equal(await page.$eval("#keep-starts", (c) => c.checked), true);
  await page.waitForFunction(() => /^M40,0/.test(document.querySelector("#editor path.to").getAttribute("d")), null, { timeout: 10000 });
  near(await editorCentre(page, "#editor circle.start[data-which=to]"), [40, 0], 1e-6, "the rotated start");
  /* now start to at a vertex that does not align: the morph keeps it */
  await page.click(".start-next[data-which=to]");
  await morphAndWait(page, 1);
  const { request, result } = answerFor(morphs, "curvature", 11);
  assert.deepEqual(request.matches, [[0.5, 0.5]]);
  near(result.frames[10].curve.control_points[0], [60, 0], 1e-6, "the kept start");
  near(await editorCentre(page, "#editor circle.start[data-which=to]"), [60, 0], 0.4, "the start ring");
  assert.equal(await page.$$eval("#editor circle.used", (c) => c.length), 0, "the pin is no match of the designer's");
  /* without keep, the service aligns the start again */
  await page.uncheck("#keep-starts");
  await morphAndWait(page, 1);
  near(morphs[morphs.length - 1].result.frames[10].curve.control_points[0], [40, 0], ALIGN_STEP, "the aligned start");
  /* Reverse: an open path runs the other way, and so does its morph */
  await setCurves(page, "M0,0 L10,0 L10,10", "M30,0 C40,0 40,10 30,10");
  await page.click(".reverse[data-which=from]");
  assert.equal(await page.inputValue("#curve-from"), "M10,10 L10,0 L0,0");
  await page.click(".reverse[data-which=to]");
  assert.equal(await page.inputValue("#curve-to"), "M30,10 C40,10 40,0 30,0");
  await morphAndWait(page, 1);
  const frames = morphs[morphs.length - 1].result.frames;
  near(frames[0].curve.control_points[0], [10, 10], 1e-6, "reversed from starts at its old end");
  near(frames[10].curve.control_points[0], [30, 10], 1e-6, "reversed to starts at its old end");
  /* a closed path reversed keeps its start */
  await page.fill("#curve-from", L_FROM);
  await page.click(".reverse[data-which=from]");
  assert.equal(await page.inputValue("#curve-from"), "M0,0 L0,14 L8,14 L8,6 L20,6 L20,0 Z");
  assert.deepEqual(errors, []);
  await page.close();
});

test("drawn points: Undo and Ctrl-Z take back the last one; Enter and the arrows draw without a mouse", async () => {
  const { page, errors } = await openPage(env);
  await page.click(".draw[data-which=from]");
  assert.equal(await page.$eval("#undo-point", (b) => b.disabled), true);
  const box = await page.$eval("#editor", (e) => { const r = e.getBoundingClientRect(); return [r.x, r.y, r.width, r.height]; });
  for (const [fx, fy] of [[0.3, 0.3], [0.6, 0.3], [0.6, 0.7], [0.3, 0.7]])
    await page.mouse.click(box[0] + fx * box[2], box[1] + fy * box[3]);
  const points = async () => JSON.parse(await page.inputValue("#curve-from")).points;
  const four = await points();
  assert.equal(four.length, 4);
  await page.keyboard.press("Control+z");
  assert.deepEqual(await points(), four.slice(0, 3));
  await page.click("#undo-point");
  assert.deepEqual(await points(), four.slice(0, 2));
  assert.equal(await page.$$eval("#editor circle.ctrl", (c) => c.length), 2);
  /* keyboard: focus the editor, Enter adds a point, arrows move it */
  await page.focus("#editor");
  await page.keyboard.press("Enter");
  const added = (await points())[2];
  await page.keyboard.press("ArrowDown");
  const moved = (await points())[2];
  assert.equal(moved[0], added[0]);
  assert.ok(moved[1] > added[1], `${moved} is below ${added}`);
  await page.keyboard.press("Meta+z");
  assert.equal((await points()).length, 2);
  await page.click(".draw[data-which=from]");
  assert.equal(await page.$eval("#undo-point", (b) => b.disabled), true);
  assert.deepEqual(errors, []);
  await page.close();
});
