// defects.test.mjs - what a first browser session found broken on the
// page, one test each: a start point picked on a closed curve, results of
// an earlier morph left under a failure, picks outliving their curves,
// the linear panel's metrics on smooth shapes, a scrubber that moves
// while playing, the closed box and paths that return to their start,
// plot scales set by rounding noise or cusps, and how errors are shown.
import { test } from "node:test";
import assert from "node:assert/strict";
import { useBrowser, openPage, waitForEditor, morphAndWait, answerFor, setScrub, screenPoint } from "./harness.mjs";

const env = useBrowser();
const text = (page, sel) => page.textContent(sel);

test("1. a pick at a closed curve's start is accepted: sent just off the seam", async () => {
  const { page, errors, morphs } = await openPage(env);
  await page.selectOption("#example", "square-circle");
  await waitForEditor(page);
  await page.click("#pick-matches");
  /* the square's start corner (30, 30), then a point 0.6 along the circle */
  for (const [which, f] of [["from", 0], ["to", 0.6]]) {
    const pt = await screenPoint(page, which, f);
    await page.mouse.click(pt.x, pt.y);
  }
  await page.click("#pick-matches");
  assert.match(await text(page, "#match-list li"), /from 0\.0000 \(start\)/);
  await page.selectOption("#method", "curvature");
  await page.fill("#frames", "5");
  await morphAndWait(page, 1);
  const { request, result } = answerFor(morphs, "curvature", 5);
  assert.equal(request.matches.length, 1);
  const [a, b] = request.matches[0];
  /* 0.6 is past the middle: the start goes just before the seam, so that
   * the sliver between them carries the shorter 0.4 of the circle */
  assert.equal(a, 1 - 1e-4);
  assert.ok(Math.abs(b - 0.6) <= 0.0026, String(b));
  assert.ok(result.matches_used.some(([x, y]) => x === a && y === b));
  assert.equal(await text(page, "#error-options"), "");
  /* both starts picked: the pair the service always keeps, not sent */
  await page.click("#clear-matches");
  await page.click("#pick-matches");
  for (const which of ["from", "to"]) {
    const pt = await screenPoint(page, which, 0);
    await page.mouse.click(pt.x, pt.y);
  }
  await page.click("#pick-matches");
  assert.match(await text(page, "#match-list li"), /^start ↔ start/);
  assert.deepEqual(errors, []);
  await page.close();
});

test("2. a failed morph takes the earlier results away", async () => {
  const { page, errors } = await openPage(env);
  await page.selectOption("#example", "square-circle");
  await waitForEditor(page);
  await page.fill("#frames", "5");
  await morphAndWait(page, 2);
  assert.equal(await page.isHidden("#results"), false);
  /* a path that turns back on itself is refused (422, /to/d) */
  await page.fill("#curve-to", "M 0 0 L 100 0 L 0 0");
  await page.click("#morph");
  await page.waitForFunction(() => document.querySelector("#error-to").textContent !== "" &&
                                    !document.querySelector("#morph").disabled, null, { timeout: 10000 });
  assert.equal(await page.isHidden("#results"), true);
  assert.equal(await page.$$eval("#panels .panel", (l) => l.length), 0);
  assert.match(await text(page, "#status"), /^failed/);
  assert.ok(errors.every((e) => /status of 422/.test(e)), errors.join("\n"));
  await page.close();
});

test("3. picked pairs go with a changed curve; the picking hint goes with Stop picking", async () => {
  const { page, errors } = await openPage(env);
  await page.selectOption("#example", "open-spirals");
  await waitForEditor(page);
  const hint = await text(page, "#editor-hint");
  await page.click("#pick-matches");
  assert.notEqual(await text(page, "#editor-hint"), hint);
  for (const [which, f] of [["from", 0.3], ["to", 0.6]]) {
    const pt = await screenPoint(page, which, f);
    await page.mouse.click(pt.x, pt.y);
  }
  await page.click("#pick-matches");
  assert.equal(await text(page, "#editor-hint"), hint);
  assert.equal(await page.$$eval("#match-list li", (l) => l.length), 1);
  assert.equal(await page.inputValue("#matches-mode"), "pairs");
  await page.selectOption("[data-testid='pick-to']", "arrow");
  await page.waitForFunction(() => document.querySelectorAll("#match-list li").length === 0, null, { timeout: 10000 });
  assert.equal(await page.$$eval("#editor .match", (l) => l.length), 0);
  assert.equal(await page.inputValue("#matches-mode"), "none");
  assert.deepEqual(errors, []);
  await page.close();
});

test("4. the linear panel's metrics on smooth shapes are the shapes' own", async () => {
  const { page, errors, morphs } = await openPage(env);
  await page.selectOption("[data-testid='pick-from']", "heart");
  await page.selectOption("[data-testid='pick-to']", "circle");
  await waitForEditor(page);
  await page.selectOption("#method", "both");
  await page.fill("#frames", "3");
  await morphAndWait(page, 2);
  answerFor(morphs, "linear", 3);
  const num = async (sel) => Number(await text(page, sel));
  /* t = 1 is the circle of radius 80: kappa 1/80, bending 2 pi r / r^2 */
  await setScrub(page, 1);
  assert.ok(Math.abs(await num("#panel-linear .m-kappa") - 1 / 80) < 1e-5);
  assert.ok(Math.abs(await num("#panel-linear .m-energy") - 2 * Math.PI / 80) < 1e-4);
  /* t = 0 is the heart: both methods measure the same input */
  await setScrub(page, 0);
  const lin = await num("#panel-linear .m-kappa"), cur = await num("#panel-curvature .m-kappa");
  assert.ok(Math.abs(lin - cur) <= 0.01 * cur, `${lin} vs ${cur}`);
  assert.ok(Math.abs(await num("#panel-linear .m-energy") - await num("#panel-curvature .m-energy")) <=
            0.01 * await num("#panel-curvature .m-energy"));
  assert.deepEqual(errors, []);
  await page.close();
});

test("5. the scrubber keeps its place and width while playing", async () => {
  const { page, errors } = await openPage(env);
  await page.selectOption("#example", "circle-star");
  await waitForEditor(page);
  await page.fill("#frames", "11");
  await morphAndWait(page, 2);
  const boxes = await page.evaluate(() => new Promise((resolve) => {
    const seen = new Set();
    document.querySelector("#play").click();
    const look = () => {
      const r = document.querySelector("#scrub").getBoundingClientRect();
      seen.add(`${r.x.toFixed(1)} ${r.width.toFixed(1)}`);
      if (document.querySelector("#play").textContent === "Play") resolve([...seen]);
      else requestAnimationFrame(look);
    };
    requestAnimationFrame(look);
  }));
  assert.deepEqual(boxes.length, 1, boxes.join(" | "));
  assert.deepEqual(errors, []);
  await page.close();
});

test("6. a path back at its start is sent closed; a near one is offered Z; the closed box works", async () => {
  const { page, errors, morphs } = await openPage(env);
  await page.selectOption("#example", "square-circle");
  await waitForEditor(page);
  /* the square drawn back to its start without Z */
  await page.fill("#curve-from", "M30,30 H170 V170 H30 V30");
  await page.waitForFunction(() => /sent closed/.test(document.querySelector("#note-from").textContent), null, { timeout: 10000 });
  await page.selectOption("#method", "curvature");
  await page.fill("#frames", "5");
  await morphAndWait(page, 1);
  const { request } = answerFor(morphs, "curvature", 5);
  assert.equal(request.from.d, "M30,30 H170 V170 H30 V30 Z");
  assert.equal(await text(page, "#error-from"), "");
  /* 5 short of its start: offered a Z */
  await page.fill("#curve-from", "M30,30 H170 V170 H30 V35");
  await page.waitForSelector("#note-from button.close-path", { timeout: 10000 });
  assert.match(await text(page, "#note-from"), /ends 5 from its start/);
  assert.equal(await page.isChecked(".draw-closed[data-which='from']"), false);
  await page.click("#note-from button.close-path");
  assert.equal(await page.inputValue("#curve-from"), "M30,30 H170 V170 H30 V35 Z");
  await page.waitForFunction(() => document.querySelector(".draw-closed[data-which='from']").checked, null, { timeout: 10000 });
  /* the box opens and closes a pasted path */
  await page.uncheck(".draw-closed[data-which='from']");
  assert.equal(await page.inputValue("#curve-from"), "M30,30 H170 V170 H30 V35");
  await page.check(".draw-closed[data-which='from']");
  assert.equal(await page.inputValue("#curve-from"), "M30,30 H170 V170 H30 V35 Z");
  assert.deepEqual(errors, []);
  await page.close();
});

test("7. plots: straight edges are 0, not rounding noise; cusp spikes are clipped with a mark", async () => {
  const { page, errors } = await openPage(env);
  await page.selectOption("#example", "arrow");
  await waitForEditor(page);
  await page.fill("#frames", "7");
  await morphAndWait(page, 2);
  for (const method of ["curvature", "linear"]) {
    const plot = `#panel-${method} .plot svg.kappa-plot`;
    await page.waitForSelector(plot, { timeout: 10000 });
    assert.equal(await page.getAttribute(plot, "data-flat"), "1", method);
    /* every point of every frame's curve on the zero line */
    const off = await page.$eval(plot, (svg) => Math.max(...[...svg.querySelectorAll("polyline")].flatMap((l) =>
      l.getAttribute("points").split(" ").map((p) => Math.abs(Number(p.split(",")[1]) - Number(svg.dataset.zeroY))))));
    assert.ok(off < 0.01, `${method}: ${off}`);
  }
  /* the spirals' linear frames nearly cusp (|kappa| to 1e4): clipped and
   * marked; the curvature blend's (|kappa| <= 4) is not */
  await page.selectOption("#example", "spirals");
  await waitForEditor(page);
  await morphAndWait(page, 2);
  assert.equal(await page.getAttribute("#panel-linear .plot svg", "data-clipped"), "1");
  assert.ok(await page.$$eval("#panel-linear .plot .clip-mark", (l) => l.length) >= 1);
  assert.match(await text(page, "#panel-linear .plot .clip-note"), /clipped at ±[\d.]+; peaks up to/);
  const range = Number(await page.getAttribute("#panel-linear .plot svg", "data-range"));
  assert.ok(range < 100, String(range));
  assert.equal(await page.getAttribute("#panel-curvature .plot svg", "data-clipped"), "0");
  assert.deepEqual(errors, []);
  await page.close();
});

test("8. errors: by the curves, in words, gone when fixed, and SVG checked while typing", async () => {
  const { page, errors } = await openPage(env);
  await page.selectOption("#example", "square-circle");
  await waitForEditor(page);
  /* a closed square against an open spiral: the fault of the pair */
  await page.selectOption("[data-testid='pick-to']", "spiral-open-a");
  await waitForEditor(page);
  await page.click("#morph");
  await page.waitForFunction(() => document.querySelector("#error-from").textContent !== "", null, { timeout: 10000 });
  for (const w of ["from", "to"]) assert.match(await text(page, `#error-${w}`), /open curve into a closed one/);
  assert.equal(await text(page, "#error-general"), "");
  assert.doesNotMatch(await text(page, "#error-from"), /\(\/closed\)/);
  /* changing either curve takes the pair's fault away from both */
  await page.selectOption("[data-testid='pick-to']", "round");
  await page.waitForFunction(() => document.querySelector("#error-from").textContent === "" &&
                                    document.querySelector("#error-to").textContent === "", null, { timeout: 10000 });
  /* frames below 2: named in words, and gone as soon as frames change */
  await page.fill("#frames", "1");
  await page.click("#morph");
  await page.waitForFunction(() => document.querySelector("#error-options").textContent !== "", null, { timeout: 10000 });
  const msg = await text(page, "#error-options");
  assert.match(msg, /frames: /);
  assert.doesNotMatch(msg, /\(\/frames\)/);
  await page.fill("#frames", "5");
  assert.equal(await text(page, "#error-options"), "");
  assert.equal(await page.$eval("#frames", (el) => el.parentElement.classList.contains("has-error")), false);
  /* bad path data is pointed at while typing, before any Morph */
  await page.fill("#curve-to", "M 0 0 L 10");
  await page.waitForFunction(() => /SVG path: a number is expected at character 10/.test(document.querySelector("#error-to").textContent),
                             null, { timeout: 5000 });
  await page.fill("#curve-to", "M 0 0 L 10 0 L 10 10 Z M 5 5 L 6 6");
  await page.waitForFunction(() => /subpath 2 of 2 is not closed/.test(document.querySelector("#error-to").textContent),
                             null, { timeout: 5000 });
  assert.ok(errors.every((e) => /status of 422/.test(e)), errors.join("\n"));
  await page.close();
});
