// session.test.mjs - the page as a designer uses it: a scripted session
// (paste two icon paths, morph, pick a start point, play, scrub, export
// CSS and check in the browser that the export animates) at 1400 px and
// 390 px wide, with screenshots under build/; playback from the keyboard,
// stepping, ping-pong and easing; state in the URL; dark mode.
import { test } from "node:test";
import assert from "node:assert/strict";
import { useBrowser, openPage, waitForEditor, morphAndWait, answerFor, setScrub, screenPoint,
         screenshot } from "./harness.mjs";

const env = useBrowser();
/* two icons on a 24-unit box: a five-pointed star and a ring of arcs */
const STAR = "M12,2 L14.94,8.1 L21.51,8.91 L16.76,13.5 L17.88,20.09 L12,16.9 L6.12,20.09 L7.24,13.5 L2.49,8.91 L9.06,8.1 Z";
const DISC = "M12,3 A9,9 0 1,1 12,21 A9,9 0 1,1 12,3 Z";

/** The cubic-bezier easing y(x), solved here by Newton steps on x(u). */
function bezierAt([x1, y1, x2, y2], x) {
  const f = (a, b, u) => 3 * (1 - u) ** 2 * u * a + 3 * (1 - u) * u * u * b + u ** 3;
  const df = (a, b, u) => 3 * (1 - u) ** 2 * a + 6 * (1 - u) * u * (b - a) + 3 * u * u * (1 - b);
  let u = x;
  for (let i = 0; i < 30; i++) u -= (f(x1, x2, u) - x) / df(x1, x2, u);
  return f(y1, y2, u);
}

for (const width of [1400, 390]) {
  test(`a scripted session at ${width} px: paste, morph, pick a start, play, scrub, export CSS that animates`, async () => {
    const { page, errors, morphs } = await openPage(env, "", { viewport: { width, height: 900 } });
    await page.fill("#curve-from", STAR);
    await page.fill("#curve-to", DISC);
    await waitForEditor(page);
    await page.fill("#frames", "21");
    await morphAndWait(page, 2);
    await screenshot(page, `session-${width}-morphed.png`);
    /* the star's start (its top point) matched with the ring's right side */
    await page.click("#pick-matches");
    for (const [which, f] of [["from", 0], ["to", 0.25]]) {
      const pt = await screenPoint(page, which, f);
      await page.mouse.click(pt.x, pt.y);
    }
    await page.click("#pick-matches");
    await morphAndWait(page, 2);
    const { request } = answerFor(morphs, "curvature", 21);
    assert.equal(request.matches.length, 1);
    assert.equal(request.matches[0][0], 1e-4);
    await page.fill("#duration", "0.6");
    await page.click("#play");
    await page.waitForFunction(() => document.querySelector("#t-value").textContent === "t = 1.000" &&
                                      document.querySelector("#play").textContent === "Play", null, { timeout: 15000 })
      .catch(async (e) => { throw new Error(e.message + " at " + await page.evaluate(() =>
        document.querySelector("#t-value").textContent + " / " + document.querySelector("#play").textContent)); });
    await setScrub(page, 0.5);
    await screenshot(page, `session-${width}-t0.5.png`);
    /* no sideways scrolling at this width */
    assert.ok(await page.evaluate(() => document.documentElement.scrollWidth) <= width);
    await page.selectOption("#repeat", "loop");
    await page.click("#export-css");
    const css = await page.inputValue("#export-text");
    assert.match(css, /@keyframes kmorph \{/);
    assert.match(css, /animation: kmorph 0\.6s linear infinite/);
    await screenshot(page, `session-${width}-export.png`);
    /* the export in a page of its own, paused at the start, the middle and the end */
    const shot = await env.context.newPage();
    const dAt = async (delay) => {
      await shot.setContent(`<style>${css} .kmorph { animation-play-state: paused; animation-delay: ${-delay}s; }</style>` +
                            `<svg viewBox="0 0 24 24" width="240" height="240"><path class="kmorph"/></svg>`);
      return shot.$eval("path", (p) => getComputedStyle(p).d);
    };
    const [d0, dMid, d1] = [await dAt(0), await dAt(0.3), await dAt(0.5999)];
    assert.match(d0, /^path\("M/);
    assert.notEqual(dMid, d0);
    assert.notEqual(dMid, d1);
    await shot.close();
    assert.deepEqual(errors, []);
    await page.close();
  });
}

test("playback: keyboard, stepping, ping-pong, easing in the export, the filmstrip follows", async () => {
  const { page, errors } = await openPage(env);
  await page.selectOption("#example", "circle-star");
  await waitForEditor(page);
  await page.fill("#frames", "41");
  await page.selectOption("#method", "curvature");
  await morphAndWait(page, 1);
  await page.focus("#scrub");
  await page.keyboard.press("End");
  assert.equal(await page.textContent("#t-value"), "t = 1.000");
  /* the last thumbnail scrolled into the strip's view */
  assert.ok(await page.$eval("#panel-curvature .filmstrip", (strip) => {
    const cur = strip.querySelector("svg.current"), a = strip.getBoundingClientRect(), b = cur.getBoundingClientRect();
    return cur.dataset.frame === "40" && b.left >= a.left - 1 && b.right <= a.right + 1;
  }));
  await page.keyboard.press("Home");
  assert.equal(await page.textContent("#t-value"), "t = 0.000");
  await page.keyboard.press("ArrowRight");
  assert.equal(await page.textContent("#t-value"), "t = 0.025");
  await page.click("#step-on");
  assert.equal(await page.textContent("#t-value"), "t = 0.050");
  await page.keyboard.press("ArrowLeft");
  assert.equal(await page.textContent("#t-value"), "t = 0.025");
  /* ping-pong: up to 1, then back down, until space pauses it */
  await page.selectOption("#repeat", "ping-pong");
  await page.fill("#duration", "0.5");
  await page.focus("#scrub");
  await page.keyboard.press(" ");
  assert.equal(await page.textContent("#play"), "Pause");
  await page.waitForFunction(() => {
    const t = Number(document.querySelector("#t-value").textContent.slice(4));
    window.kmMax = Math.max(window.kmMax || 0, t);
    return window.kmMax > 0.95 && t < 0.5;
  }, null, { timeout: 15000, polling: "raf" });
  await page.keyboard.press(" ");
  assert.equal(await page.textContent("#play"), "Play");
  /* ease-in-out: frame t = 0.1 is reached where the easing reaches 0.1 */
  await page.fill("#easing", "ease-in-out");
  await page.click("#export-css");
  const css = await page.inputValue("#export-text");
  const keys = [...css.matchAll(/^ {2}([\d.]+)% \{/gm)].map((m) => Number(m[1]) / 100);
  assert.equal(keys.length, 41);
  assert.equal(keys[0], 0);
  assert.equal(keys[40], 1);
  assert.ok(Math.abs(keys[20] - 0.5) < 1e-3);
  assert.ok(Math.abs(bezierAt([0.42, 0, 0.58, 1], keys[4]) - 0.1) < 2e-3, String(keys[4]));
  /* the same frames as an SVG animate with as many keyTimes as values */
  await page.click("#export-svg");
  const svg = await page.inputValue("#export-text");
  const kt = /keyTimes="([^"]*)"/.exec(svg)[1].split(";"), values = /values="([^"]*)"/.exec(svg)[1].split(";");
  assert.equal(kt.length, 81);
  assert.equal(values.length, 81);
  assert.deepEqual(errors, []);
  await page.close();
});

test("the URL holds the curves and options: a shared link opens the same morph", async () => {
  const { page, errors } = await openPage(env);
  await page.selectOption("#example", "letters");
  await waitForEditor(page);
  await page.fill("#frames", "7");
  await page.selectOption("#blend", "paper");
  await morphAndWait(page, 2);
  const url = page.url();
  assert.match(url, /#%7B/);
  const again = await openPage(env, new URL(url).hash);
  await waitForEditor(again.page);
  for (const sel of ["#curve-from", "#curve-to", "#frames", "#blend"])
    assert.equal(await again.page.inputValue(sel), await page.inputValue(sel), sel);
  assert.deepEqual(errors, []);
  assert.deepEqual(again.errors, []);
  await again.page.close();
  await page.close();
});

test("the numbers say their units and meaning", async () => {
  const { page, errors } = await openPage(env);
  await page.selectOption("#example", "circle-star");
  await waitForEditor(page);
  await page.fill("#frames", "3");
  await morphAndWait(page, 2);
  const title = (sel) => page.$eval(`#panel-curvature ${sel}`, (b) => b.parentElement.title);
  assert.match(await title(".m-kappa"), /1 \/ units/);
  assert.match(await title(".m-energy"), /∫ κ² ds/);
  assert.match(await title(".m-gap"), /before the closure/);
  assert.match(await page.textContent("#panel-curvature .m-gap", { timeout: 1000 }).then(() =>
    page.$eval("#panel-curvature .m-gap", (b) => b.parentElement.textContent)), /before closing/);
  assert.deepEqual(errors, []);
  await page.close();
});

test("dark mode follows prefers-color-scheme", async () => {
  const { page, errors } = await openPage(env);
  const luminance = () => page.$eval("body", (b) => {
    const [r, g, bl] = getComputedStyle(b).backgroundColor.match(/\d+/g).map(Number);
    return (0.2126 * r + 0.7152 * g + 0.0722 * bl) / 255;
  });
  await page.emulateMedia({ colorScheme: "light" });
  assert.ok(await luminance() > 0.8);
  await page.emulateMedia({ colorScheme: "dark" });
  assert.ok(await luminance() < 0.2);
  await page.selectOption("#example", "glyph-O-C");
  await waitForEditor(page);
  await page.fill("#frames", "5");
  await morphAndWait(page, 2);
  await screenshot(page, "dark-O-C.png");
  assert.deepEqual(errors, []);
  await page.close();
});
