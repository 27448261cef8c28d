// package.test.mjs - the kmorph npm package (clients/js): its package.json
// (version equal to the API's info.version), its type declarations
// covering every export, and the packed tarball installed into an empty
// project and used by name against a live kmorphd, through the
// flubber-style interpolate() whose ends must lie on the exact input
// curves (a circle and a square, checked by their equations here).
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { existsSync, mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync } from "node:fs";
import os from "node:os";
import path from "node:path";
import { pathToFileURL } from "node:url";
import { startDaemon, ROOT } from "../lib/daemon.mjs";
import * as source from "../../../clients/js/kmorph.js";

const PKG_DIR = path.join(ROOT, "clients", "js");
const pkg = JSON.parse(readFileSync(path.join(PKG_DIR, "package.json"), "utf8"));

let daemon, work, installed;
before(async () => {
  daemon = await startDaemon();
  work = mkdtempSync(path.join(os.tmpdir(), "kmorph-npm-"));
});
after(async () => {
  if (daemon) await daemon.stop();
  if (work) rmSync(work, { recursive: true, force: true });
});

test("package.json: name, module type, entry points, and the API's version", () => {
  assert.equal(pkg.name, "kmorph");
  assert.equal(pkg.type, "module");
  assert.equal(pkg.exports["."].default, "./kmorph.js");
  assert.equal(pkg.exports["."].types, "./kmorph.d.ts");
  assert.equal(pkg.types, "./kmorph.d.ts");
  assert.deepEqual([...pkg.files].sort(), ["kmorph.d.ts", "kmorph.js", "openapi.d.ts"]);
  const yaml = readFileSync(path.join(ROOT, "api", "openapi.yaml"), "utf8");
  const m = /^info:\n(?:[ \t]+.*\n)*?[ \t]+version:[ \t]*["']?([^"'\s]+)/m.exec(yaml);
  assert.ok(m, "info.version in api/openapi.yaml");
  assert.equal(pkg.version, m[1]);
  const versionFile = path.join(ROOT, "VERSION");
  if (existsSync(versionFile)) assert.equal(pkg.version, readFileSync(versionFile, "utf8").trim());
});

test("kmorph.d.ts declares every export of kmorph.js, and nothing else", () => {
  const dts = readFileSync(path.join(PKG_DIR, "kmorph.d.ts"), "utf8");
  const declared = new Set([...dts.matchAll(/^export\s+(?:declare\s+)?(?:function|class|const|let)\s+([A-Za-z_$][\w$]*)/gm)]
    .map((m) => m[1]));
  const exported = Object.keys(source).sort();
  assert.ok(exported.length >= 20, `${exported.length} exports`);
  for (const name of exported) assert.ok(declared.has(name), `${name} is declared in kmorph.d.ts`);
  for (const name of declared) assert.ok(exported.includes(name), `${name} is declared but not exported`);
});

/* TypeScript from the package's devDependencies (npm ci in clients/js). */
const TSC = path.join(PKG_DIR, "node_modules", ".bin", "tsc");
function tsc(project) {
  try {
    execFileSync(TSC, ["-p", project], { encoding: "utf8", timeout: 120000 });
  } catch (e) {
    assert.fail(`tsc -p ${project}:\n${e.stdout}${e.stderr}`);
  }
}

test("every schema of the contract is an exported type of kmorph.d.ts", () => {
  const yaml = readFileSync(path.join(ROOT, "api", "openapi.yaml"), "utf8");
  const block = /^components:\n(?:.*\n)*?  schemas:\n((?:(?:    .*| *)\n)*)/m.exec(yaml);
  assert.ok(block, "components.schemas in api/openapi.yaml");
  const schemas = [...block[1].matchAll(/^    ([A-Za-z]\w*):\s*$/gm)].map((m) => m[1]);
  assert.ok(schemas.length >= 25, `${schemas.length} schemas`);
  const dts = readFileSync(path.join(PKG_DIR, "kmorph.d.ts"), "utf8");
  for (const name of schemas)
    assert.match(dts, new RegExp(`^export type ${name} = Schemas\\["${name}"\\];$`, "m"), name);
});

test("the types compile strictly with tsc --noEmit, and refuse what the contract refuses", () => {
  /* openapi.d.ts is generated from the contract, as npm pack does. */
  execFileSync("npm", ["run", "--silent", "types"], { cwd: PKG_DIR, encoding: "utf8", timeout: 120000 });
  tsc(path.join(PKG_DIR, "tsconfig.json"));
  tsc(path.join(ROOT, "tests", "clients", "js", "types", "tsconfig.json"));
});

/** Pack clients/js, install the tarball offline into a fresh project and
 * import "kmorph" from a module of that project (so resolution goes
 * through node_modules and the package's exports map). */
async function install() {
  if (installed) return installed;
  const packed = JSON.parse(execFileSync("npm", ["pack", "--json", "--pack-destination", work, PKG_DIR],
                                         { encoding: "utf8", timeout: 60000 }));
  const files = packed[0].files.map((f) => f.path).sort();
  assert.deepEqual(files, ["kmorph.d.ts", "kmorph.js", "openapi.d.ts", "package.json"]);
  const tarball = packed[0].filename;
  assert.equal(tarball, `kmorph-${pkg.version}.tgz`);
  const project = path.join(work, "app");
  execFileSync("mkdir", ["-p", project]);
  writeFileSync(path.join(project, "package.json"), JSON.stringify({ name: "app", private: true, type: "module" }));
  execFileSync("npm", ["install", "--offline", "--no-audit", "--no-fund", "--loglevel=error", path.join(work, tarball)],
               { cwd: project, encoding: "utf8", timeout: 120000 });
  assert.deepEqual(readdirSync(path.join(project, "node_modules", "kmorph")).sort(),
                   ["kmorph.d.ts", "kmorph.js", "openapi.d.ts", "package.json"]);
  writeFileSync(path.join(project, "use.mjs"), 'export * from "kmorph";\n');
  installed = await import(pathToFileURL(path.join(project, "use.mjs")).href);
  return installed;
}

const R = 40, A = 60;
const circleD = `M ${R} 0 A ${R} ${R} 0 1 1 ${-R} 0 A ${R} ${R} 0 1 1 ${R} 0 Z`;
const squareD = `M ${-A / 2} ${-A / 2} L ${A / 2} ${-A / 2} L ${A / 2} ${A / 2} L ${-A / 2} ${A / 2} Z`;
/* Distance from a point to the circle |p| = R and to the square max(|x|, |y|) = A/2. */
const offCircle = ([x, y]) => Math.abs(Math.hypot(x, y) - R);
const offSquare = ([x, y]) => Math.abs(Math.max(Math.abs(x), Math.abs(y)) - A / 2);
const worst = (pts, off) => Math.max(...pts.map(off));

test("the installed package morphs by name: interpolate(from, to)(t)", async () => {
  const km = await install();
  assert.equal(typeof km.interpolate, "function");
  const client = new km.Client({ baseUrl: daemon.url });
  const at = await km.interpolate(circleD, squareD, { client, frames: 5 });
  const points = await km.interpolate(circleD, squareD, { client, frames: 5, string: false });
  const d0 = at(0), d5 = at(0.5), d1 = at(1);
  for (const d of [d0, d5, d1]) assert.match(d, /^M[-\d.e,]+(L[-\d.e,]+)+Z$/);
  assert.notEqual(d5, d0);
  assert.notEqual(d5, d1);
  const p0 = points(0), p5 = points(0.5), p1 = points(1);
  assert.equal(p0.length, 200);
  /* The ends are the inputs up to the service's tolerance and sampling. */
  const tol = 1e-3 * R;
  assert.ok(worst(p0, offCircle) < tol, `t = 0 is the circle: ${worst(p0, offCircle)}`);
  assert.ok(worst(p1, offSquare) < tol, `t = 1 is the square: ${worst(p1, offSquare)}`);
  /* Half way it is neither. */
  assert.ok(worst(p5, offCircle) > 0.5, `t = 0.5 is not the circle: ${worst(p5, offCircle)}`);
  assert.ok(worst(p5, offSquare) > 0.5, `t = 0.5 is not the square: ${worst(p5, offSquare)}`);
  /* Outside [0, 1] it holds the ends. */
  assert.equal(at(-1), d0);
  assert.equal(at(2), d1);
});

test("interpolateAll: one interpolator per pair, or one path with single", async () => {
  const km = await install();
  const client = new km.Client({ baseUrl: daemon.url });
  const shifted = `M ${R + 200} 0 A ${R} ${R} 0 1 1 ${200 - R} 0 A ${R} ${R} 0 1 1 ${R + 200} 0 Z`;
  const each = await km.interpolateAll([circleD, squareD], [squareD, shifted], { client, frames: 3, string: false });
  assert.equal(each.length, 2);
  assert.ok(worst(each[0](1), offSquare) < 1e-3 * R);
  assert.ok(worst(each[1](0), offSquare) < 1e-3 * R);
  assert.ok(worst(each[1](1).map(([x, y]) => [x - 200, y]), offCircle) < 1e-3 * R);
  const joined = await km.interpolateAll([circleD, squareD], [squareD, shifted], { client, frames: 3, single: true });
  assert.equal((joined(0.5).match(/M/g) || []).length, 2);
  await assert.rejects(km.interpolateAll([circleD], [], { client }), TypeError);
});

test("the installed package's types resolve by name in a TypeScript project", async () => {
  await install();
  const project = path.join(work, "app");
  writeFileSync(path.join(project, "use.ts"), [
    'import { Client, type MorphRequest, type MorphResult } from "kmorph";',
    'const req: MorphRequest = { from: { type: "svg", d: "M 0 0 L 1 0" }, to: { type: "svg", d: "M 0 0 L 0 1" } };',
    "export async function frames(): Promise<number> {",
    "  const r: MorphResult | string = await new Client().morph(req);",
    '  return typeof r === "string" ? 0 : r.frames.length;',
    "}",
    '// @ts-expect-error "frames" is a number',
    'export const bad: MorphRequest = { ...req, frames: "many" };',
    "",
  ].join("\n"));
  writeFileSync(path.join(project, "tsconfig.json"), JSON.stringify({
    compilerOptions: { strict: true, noEmit: true, module: "nodenext", moduleResolution: "nodenext",
                       target: "es2022", lib: ["es2022", "dom"], types: [] },
    files: ["use.ts"],
  }));
  tsc(project);
});

test("interpolate passes request errors on as KmorphError naming the field", async () => {
  const km = await install();
  const client = new km.Client({ baseUrl: daemon.url });
  await assert.rejects(km.interpolate(circleD, "M 0 0 Q", { client }), (e) => {
    assert.ok(e instanceof km.KmorphError, String(e));
    assert.equal(e.status >= 400 && e.status < 500, true);
    assert.ok(e.messageFor("/to"), JSON.stringify(e.errors));
    return true;
  });
});
