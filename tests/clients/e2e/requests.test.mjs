// requests.test.mjs - what the page asks the service for: one morph call
// per method the page shows (the plots are drawn from the frames), none
// for what it already has; and a large SVG export arriving with a
// progress bar that counts the bytes the file has.
import { test } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import { useBrowser, openPage, morphAndWait } from "./harness.mjs";

const env = useBrowser();
const L_FROM = "M0,0 L20,0 L20,6 L8,6 L8,14 L0,14 Z";
const L_TO = "M48,6 L48,14 L40,14 L40,0 L60,0 L60,6 Z";

async function setCurves(page) {
  await page.fill("#curve-from", L_FROM);
  await page.fill("#curve-to", L_TO);
  await page.waitForFunction(() => document.querySelectorAll("#editor path.from, #editor path.to").length === 2 &&
                                    /^M48,6/.test(document.querySelector("#editor path.to").getAttribute("d")),
                             null, { timeout: 10000 });
}

const morphCalls = (requests) => requests.filter((r) => r.path === "/v1/morph");

test("one morph call per method shown, plots from its frames, none for an answer the page has", async () => {
  const { page, errors, requests } = await openPage(env);
  await setCurves(page);
  /* SVG paths are drawn as given: no call before Morph */
  const atStart = requests.length;
  await morphAndWait(page, 2);
  const first = requests.slice(atStart);
  assert.deepEqual(first.map((r) => r.path).sort(), ["/v1/morph", "/v1/morph"]);
  assert.deepEqual(first.map((r) => JSON.parse(r.body).method).sort(), ["curvature", "linear"]);
  /* both panels have their curvature plot, drawn without another call */
  assert.equal(await page.$$eval("#panels .panel .plot svg", (s) => s.length), 2);
  /* the same curves and options again: the answers the page has */
  await morphAndWait(page, 2);
  assert.equal(requests.length, atStart + 2);
  /* one method of the pair just morphed: that answer, no call */
  await page.selectOption("#method", "curvature");
  await morphAndWait(page, 1);
  assert.equal(requests.length, atStart + 2);
  assert.equal(await page.$$eval("#panels .panel .plot svg", (s) => s.length), 1);
  /* another frame count is another morph: one call */
  await page.fill("#frames", "13");
  await morphAndWait(page, 1);
  assert.equal(morphCalls(requests.slice(atStart)).length, 3);
  assert.equal(requests.length, atStart + 3);
  assert.equal(await page.$$eval("#panel-curvature .filmstrip svg", (s) => s.length), 13);
  assert.deepEqual(errors, []);
  await page.close();
});

test("a large SVG export shows its download progress, byte for byte", async () => {
  const { page, errors } = await openPage(env);
  await setCurves(page);
  await page.selectOption("#method", "curvature");
  await page.fill("#frames", "1000");
  await morphAndWait(page, 1);
  await page.selectOption("#svg-layout", "animate");
  /* every text the status shows, and whether the bar was up meanwhile */
  await page.evaluate(() => {
    window.kmSeen = [];
    const note = document.querySelector("#download-status"), bar = document.querySelector("#download-progress");
    new MutationObserver(() => window.kmSeen.push({ text: note.textContent, bar: !bar.hidden,
                                                    value: bar.hasAttribute("value") ? bar.value : null }))
      .observe(note, { childList: true, characterData: true, subtree: true });
  });
  const [download] = await Promise.all([page.waitForEvent("download", { timeout: 120000 }), page.click("#download-svg")]);
  const size = fs.statSync(await download.path()).size;
  await page.waitForFunction(() => /KiB$/.test(document.querySelector("#download-status").textContent) &&
                                    document.querySelector("#download-progress").hidden, null, { timeout: 10000 });
  const seen = await page.evaluate(() => window.kmSeen);
  const name = "kmorph-curvature-animate.svg";
  assert.ok(size > 1 << 20, `a large export: ${size} bytes`);
  assert.equal(seen[seen.length - 1].text, `${name}: ${(size / 1024).toFixed(0)} KiB`);
  /* the bytes counted while the bar was up rise from 0 to the file's
   * size (in as many pieces as the network hands over) */
  const counts = seen.filter((s) => s.bar).map((s) => {
    const m = /: ([\d.]+)(?: of ([\d.]+) KiB| KiB received)$/.exec(s.text);
    assert.ok(m, s.text);
    if (m[2]) assert.equal(Number(m[2]), Number((size / 1024).toFixed(0)));
    return { kib: Number(m[1]), value: s.value };
  });
  assert.ok(counts.length >= 2, JSON.stringify(counts.slice(0, 5)));
  assert.deepEqual(counts[0], { kib: 0, value: 0 });
  assert.equal(counts[counts.length - 1].value, 1);
  for (let i = 1; i < counts.length; i++) assert.ok(counts[i].kib >= counts[i - 1].kib);
  assert.ok(counts[0].kib < counts[counts.length - 1].kib);
  assert.equal(counts[counts.length - 1].kib, Number((size / 1024).toFixed(0)));
  assert.deepEqual(errors, []);
  await page.close();
});
