// harness.mjs - what the browser tests of the page share: a live kmorphd
// and Debian's headless Chromium driven by playwright-core, pages that
// record console errors and the service's morph answers, and small
// helpers to drive the page. Every wait is bounded in time.
import { before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { chromium } from "playwright-core";
import { startDaemon, ROOT } from "../lib/daemon.mjs";

export { ROOT };
export const ARTIFACTS = path.join(ROOT, "build", "clients-e2e");
const FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
               "--disable-background-networking", "--disable-component-update", "--disable-sync"];

/** Start the daemon and the browser before the file's tests and stop
 * them after; the returned object gets `daemon` and `context`. */
export function useBrowser({ viewport = { width: 1280, height: 1000 } } = {}) {
  const env = {};
  let profile;
  before(async () => {
    fs.mkdirSync(ARTIFACTS, { recursive: true });
    env.daemon = await startDaemon();
    profile = fs.mkdtempSync(path.join(os.tmpdir(), "kmorph-chromium-"));
    /* A persistent context is how Playwright takes a fresh --user-data-dir. */
    env.context = await chromium.launchPersistentContext(profile, {
      executablePath: "/usr/bin/chromium", headless: true, args: FLAGS, timeout: 60000, viewport,
    });
  });
  after(async () => {
    if (env.context) await env.context.close();
    if (env.daemon) await env.daemon.stop();
    if (profile) fs.rmSync(profile, { recursive: true, force: true });
  });
  return env;
}

/** A fresh page that records console errors, page errors and the JSON
 * answers of POST /v1/morph and /v1/jobs/{id}/result (with their
 * requests), opened at `query` (e.g. "?from=..."). */
export async function openPage(env, query = "", { viewport } = {}) {
  const page = await env.context.newPage();
  if (viewport) await page.setViewportSize(viewport);
  const errors = [], morphs = [], requests = [];
  page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
  page.on("pageerror", (e) => errors.push("page error: " + e.message));
  page.on("request", (r) => {
    const u = new URL(r.url());
    if (u.pathname.startsWith("/v1/")) requests.push({ path: u.pathname, method: r.method(), body: r.postData() });
  });
  /* the handlers below read bodies asynchronously: morphAndWait awaits
   * them, or a test could look at `morphs` before the answer is in */
  page.kmPending = [];
  page.on("response", (r) => page.kmPending.push((async () => {
    const u = new URL(r.url());
    const isMorph = u.pathname === "/v1/morph" && r.request().method() === "POST";
    const isResult = /^\/v1\/jobs\/[0-9a-f]+\/result$/.test(u.pathname);
    if ((isMorph || isResult) && r.status() === 200 && /json/.test(r.headers()["content-type"] || "")) {
      try { morphs.push({ request: isMorph ? JSON.parse(r.request().postData()) : null, result: await r.json() }); }
      catch { /* page gone */ }
    }
  })()));
  await page.goto(env.daemon.url + "/" + query, { waitUntil: "load" });
  await page.waitForSelector("body[data-ready='1']", { timeout: 10000 });
  return { page, errors, morphs, requests };
}

export async function waitForEditor(page) {
  await page.waitForFunction(() => document.querySelectorAll("#editor path.from, #editor path.to").length === 2,
                             null, { timeout: 10000 });
}

/** Click Morph and wait until `count` panels show and the page is idle. */
export async function morphAndWait(page, count) {
  const before = Number(await page.evaluate(() => document.body.dataset.morphs || 0));
  await page.click("#morph");
  await page.waitForFunction(([n, k]) => Number(document.body.dataset.morphs || 0) > k &&
                                         document.querySelectorAll("#panels .panel").length === n &&
                                         !document.querySelector("#morph").disabled, [count, before], { timeout: 60000 });
  await Promise.all(page.kmPending);
}

/** The JSON answer of the page's morph with this method and frame count. */
export function answerFor(morphs, method, frames) {
  const hits = morphs.filter((m) => m.result.method === method && m.result.frames.length === frames &&
                                    m.result.frames.every((f) => f.curve ? f.curve.svg_d : f.svg_d));
  assert.ok(hits.length >= 1, `no ${method} answer with ${frames} frames among ${morphs.length}`);
  return hits[hits.length - 1];
}

export async function setScrub(page, t) {
  await page.$eval("#scrub", (el, t) => {
    el.value = String(Math.round(t * Number(el.max)));
    el.dispatchEvent(new Event("input", { bubbles: true }));
  }, t);
}

/** Screen coordinates of the point at arc-length fraction f of an editor curve. */
export function screenPoint(page, which, f) {
  return page.$eval(`#editor path.${which}`, (p, f) => {
    const q = p.getPointAtLength(f * p.getTotalLength());
    const m = p.ownerSVGElement.getScreenCTM();
    return { x: q.x * m.a + q.y * m.c + m.e, y: q.x * m.b + q.y * m.d + m.f };
  }, f);
}

/** Write a screenshot under build/ for a person to look at. */
export async function screenshot(page, name) {
  const shot = path.join(ARTIFACTS, name);
  await page.screenshot({ path: shot, fullPage: true });
  assert.ok(fs.statSync(shot).size > 5000, `${name} is not empty`);
  return shot;
}
