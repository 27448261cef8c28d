// web.test.mjs - the kmorph page (clients/web) end to end in Debian's
// headless Chromium driven by playwright-core: load it from a live
// kmorphd, morph the paper's spirals with both methods, and check that
// what the page shows (frame count, self-intersection counts, drawn
// paths) is what the API answered; scrub to t = 1/2 and keep a screenshot
// under build/. Any console error fails the test.
import { test } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { useBrowser, openPage as open, waitForEditor, morphAndWait, answerFor, setScrub, screenPoint,
         ARTIFACTS } from "./harness.mjs";

const env = useBrowser();
const openPage = (query) => open(env, query);

test("the spiral example morphed both ways shows exactly what the API returned", async () => {
  const { page, errors, morphs } = await openPage();
  await page.selectOption("#example", "spirals");
  await waitForEditor(page);
  await page.selectOption("#method", "both");
  await page.fill("#frames", "11");
  await morphAndWait(page, 2);

  for (const method of ["curvature", "linear"]) {
    const { request, result } = answerFor(morphs, method, 11);
    /* The page sent the paper's spirals: kappa = s and kappa = -s/2 on [0, 4]. */
    assert.deepEqual(request.from.signature.kappa.coefficients, [0, 4]);
    assert.deepEqual(request.to.signature.kappa.coefficients, [0, -2]);
    assert.equal(request.frames, 11);
    const panel = `#panel-${method}`;
    const shown = await page.$$eval(`${panel} .filmstrip svg`, (els) => els.map((e) => ({
      frame: Number(e.dataset.frame), si: Number(e.dataset.si), bad: e.classList.contains("bad"),
      d: e.querySelector("path").getAttribute("d") })));
    assert.equal(shown.length, 11, "filmstrip frames");
    const rows = await page.$$eval(`${panel} table.metrics tbody tr`, (trs) => trs.map((tr) => ({
      si: Number(tr.children[5].textContent), bad: tr.classList.contains("bad") })));
    assert.equal(rows.length, 11, "metrics rows");
    result.frames.forEach((f, i) => {
      const si = f.metrics.self_intersections;
      assert.equal(shown[i].d, f.curve.svg_d, `${method} frame ${i} path`);
      assert.equal(shown[i].si, si, `${method} frame ${i} filmstrip count`);
      assert.equal(rows[i].si, si, `${method} frame ${i} table count`);
      assert.equal(rows[i].bad, si > 0, `${method} frame ${i} highlighted iff it self-intersects`);
      assert.equal(shown[i].bad, si > 0);
    });
    const summary = await page.textContent(`${panel} .summary`);
    const bad = result.frames.filter((f) => f.metrics.self_intersections > 0).length;
    assert.match(summary, new RegExp(`^11 frames · ${bad} self-intersecting`));
    /* At t = 0 the stage draws frame 0 exactly. */
    assert.equal(await page.getAttribute(`${panel} .stage path.current`, "d"), result.frames[0].curve.svg_d);
  }
  /* The paper's point (Fig. 3 vs Fig. 4): linear interpolation of the
   * spirals self-intersects, curvature blending does not. */
  const lin = answerFor(morphs, "linear", 11).result, cur = answerFor(morphs, "curvature", 11).result;
  assert.ok(lin.frames.some((f) => f.metrics.self_intersections > 0));
  assert.ok(cur.frames.every((f) => f.metrics.self_intersections === 0));

  await setScrub(page, 0.5);
  assert.equal(await page.textContent("#t-value"), "t = 0.500");
  for (const [method, result] of [["curvature", cur], ["linear", lin]]) {
    const f = result.frames[5];
    assert.equal(f.t, 0.5);
    assert.equal(await page.getAttribute(`#panel-${method} .stage path.current`, "d"), f.curve.svg_d);
    assert.equal(Number(await page.textContent(`#panel-${method} .m-si`)), f.metrics.self_intersections);
    assert.equal(await page.$eval(`#panel-${method} .stage`, (s) => s.classList.contains("bad")),
                 f.metrics.self_intersections > 0);
  }
  /* Between frames the page draws a blend, not a frame. */
  await setScrub(page, 0.55);
  const between = await page.getAttribute("#panel-curvature .stage path.current", "d");
  assert.ok(!cur.frames.some((f) => f.curve.svg_d === between));
  await setScrub(page, 0.5);
  await page.waitForFunction(() => [...document.querySelectorAll(".plot")].every((p) => p.querySelector("svg.kappa-plot")),
                             null, { timeout: 20000 });
  /* the curvature blend's frames have max |kappa_t| = 4 |1 - 1.5 t|, largest
   * (4) at t = 0: the plot's scale is that peak and 5% (the frames are
   * cubic B-splines within the tolerance: their peak within 2.5%) */
  const range = Number(await page.getAttribute("#panel-curvature .plot svg", "data-range"));
  assert.ok(Math.abs(range / 1.05 - 4) < 0.1, String(range));
  const shot = path.join(ARTIFACTS, "spirals-t0.5.png");
  await page.screenshot({ path: shot, fullPage: true });
  assert.ok(fs.statSync(shot).size > 10000);
  assert.deepEqual(errors, []);
  await page.close();
});

test("a long morph runs as jobs with a progress bar and shows every frame", async () => {
  const { page, errors, morphs } = await openPage();
  await page.selectOption("#example", "square-circle");
  await waitForEditor(page);
  await page.fill("#frames", "600");
  await page.click("#morph");
  await page.waitForSelector("#progress:not([hidden])", { timeout: 10000 });
  await page.waitForFunction(() => document.querySelectorAll("#panels .panel").length === 2 &&
                                    !document.querySelector("#morph").disabled, null, { timeout: 120000 });
  assert.match(await page.textContent("#status"), /curvature: 600 frames, linear: 600 frames in \d+ ms \(jobs\)/);
  assert.equal(await page.isHidden("#progress"), true);
  const cur = answerFor(morphs, "curvature", 600).result;
  assert.equal(await page.$$eval("#panel-curvature table.metrics tbody tr", (r) => r.length), 600);
  await setScrub(page, 1);
  assert.equal(await page.getAttribute("#panel-curvature .stage path.current", "d"), cur.frames[599].curve.svg_d);
  assert.deepEqual(errors, []);
  await page.close();
});

test("service errors appear next to the field at fault", async () => {
  const { page, errors } = await openPage();
  await page.selectOption("#example", "square-circle");
  await waitForEditor(page);
  /* A path that turns back on itself is refused (422, pointer /to/d). */
  await page.fill("#curve-to", "M 0 0 L 100 0 L 0 0");
  await page.fill("#frames", "5");
  await page.click("#morph");
  await page.waitForFunction(() => document.querySelector("#error-to").textContent !== "", null, { timeout: 10000 });
  assert.match(await page.textContent("#error-to"), /Invalid curve \(422\)/);
  assert.equal(await page.textContent("#error-from"), "");
  assert.ok(await page.$eval("#field-to", (f) => f.classList.contains("has-error")));
  /* Frames below 2 are the frames field's fault. */
  await page.selectOption("#example", "square-circle");
  await waitForEditor(page);
  await page.fill("#frames", "1");
  await page.click("#morph");
  await page.waitForFunction(() => document.querySelector("#error-options").textContent !== "", null, { timeout: 10000 });
  assert.match(await page.textContent("#error-options"), /frames/);
  assert.ok(await page.$eval("#frames", (el) => el.parentElement.classList.contains("has-error")));
  assert.equal(await page.textContent("#error-to"), "");
  /* The only console errors are Chromium's notes of the refused requests. */
  assert.ok(errors.every((e) => /status of 422/.test(e)), errors.join("\n"));
  await page.close();
});

test("drawing by clicking control points makes a points curve the service fits", async () => {
  const { page, errors } = await openPage();
  await waitForEditor(page);
  await page.click(".draw[data-which='to']");
  const box = await page.locator("#editor").boundingBox();
  for (const [fx, fy] of [[0.3, 0.3], [0.5, 0.7], [0.7, 0.3], [0.85, 0.6]])
    await page.mouse.click(box.x + fx * box.width, box.y + fy * box.height);
  const drawn = JSON.parse(await page.inputValue("#curve-to"));
  assert.equal(drawn.type, "points");
  assert.equal(drawn.points.length, 4);
  /* Clicks left to right give increasing x in the editor's coordinates. */
  for (let i = 1; i < 4; i++) assert.ok(drawn.points[i][0] > drawn.points[i - 1][0]);
  await page.click(".draw[data-which='to']");
  await page.waitForFunction(() => {
    const p = document.querySelector("#editor path.to");
    return p && /C/.test(p.getAttribute("d"));
  }, null, { timeout: 10000 });
  assert.equal(await page.textContent("#error-to"), "");
  assert.deepEqual(errors, []);
  await page.close();
});

test("picked match pairs and the options reach the service, and the result honours the matches", async () => {
  const { page, errors, morphs } = await openPage();
  await page.selectOption("#example", "open-spirals");
  await waitForEditor(page);
  await page.click("#pick-matches");
  for (const [which, f] of [["from", 0.3], ["to", 0.6]]) {
    const pt = await screenPoint(page, which, f);
    await page.mouse.click(pt.x, pt.y);
  }
  await page.click("#pick-matches");
  assert.equal(await page.$$eval("#match-list li", (l) => l.length), 1);
  assert.equal(await page.inputValue("#matches-mode"), "pairs");
  await page.selectOption("#method", "curvature");
  await page.selectOption("#anchor", "centroid");
  await page.selectOption("#blend", "paper");
  await page.fill("#tolerance", "1e-3");
  await page.fill("#frames", "7");
  await morphAndWait(page, 1);
  const { request, result } = answerFor(morphs, "curvature", 7);
  assert.equal(request.anchor, "centroid");
  assert.equal(request.blend, "paper");
  assert.equal(request.tolerance, 1e-3);
  assert.equal(request.matches.length, 1);
  /* The clicked points are the nearest of 400 samples: within 1/400 of the aim. */
  assert.ok(Math.abs(request.matches[0][0] - 0.3) <= 0.0026, String(request.matches[0]));
  assert.ok(Math.abs(request.matches[0][1] - 0.6) <= 0.0026, String(request.matches[0]));
  assert.ok(result.matches_used.some(([a, b]) => Math.abs(a - request.matches[0][0]) < 1e-9 &&
                                                 Math.abs(b - request.matches[0][1]) < 1e-9));
  assert.deepEqual(errors, []);
  await page.close();
});

test("play advances t to 1; downloads give the JSON results and an SVG document", async () => {
  const { page, errors, morphs } = await openPage();
  await page.selectOption("#example", "circle-star");
  await waitForEditor(page);
  await page.fill("#frames", "9");
  await morphAndWait(page, 2);
  await page.click("#play");
  /* playing stops by itself at t = 1 (the label and t change in separate
   * frames, so wait for both) */
  await page.waitForFunction(() => document.querySelector("#t-value").textContent === "t = 1.000" &&
                                    document.querySelector("#play").textContent === "Play", null, { timeout: 10000 });
  assert.equal(await page.textContent("#play"), "Play");
  const cur = answerFor(morphs, "curvature", 9).result;
  assert.equal(await page.getAttribute("#panel-curvature .stage path.current", "d"), cur.frames[8].curve.svg_d);

  const [json] = await Promise.all([page.waitForEvent("download"), page.click("#download-json")]);
  const saved = JSON.parse(fs.readFileSync(await json.path(), "utf8"));
  assert.deepEqual(saved.curvature, cur);
  assert.equal(saved.linear.method, "linear");
  await page.selectOption("#svg-layout", "overlay");
  const download = page.waitForEvent("download");
  await page.click("#download-svg");
  const svg = await download;
  assert.match(svg.suggestedFilename(), /^kmorph-curvature-overlay\.svg$/);
  assert.match(fs.readFileSync(await svg.path(), "utf8").slice(0, 300), /<svg[\s>]/);
  assert.deepEqual(errors, []);
  await page.close();
});
