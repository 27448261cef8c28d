// bench_flubber_shapes.js - flubber on the compound pairs of
// bench/shape_pairs.json (glyphs with holes, multi-part icons from
// tests/fixtures/compound), timed as bench_flubber.js times single shapes:
// setup plus 60 frames (t = i / 59), per-frame time with the setup
// amortised, best of the runs made over at least a second.
//
// flubber morphs one ring to one ring; compound shapes go through its
// multi-shape functions, as a page would use them, on the subpaths
// (flubber.splitPathString):
//   equal counts        interpolateAll(from, to)
//   many to one         combine(from, to[0])
//   one to many         separate(from[0], to)
//   m to n, both > 1    interpolateAll on the first min(m, n) - 1 subpaths
//                       in order, then combine (or separate) the rest
//                       with the last subpath of the side with fewer.
// All with { single: true }, so a frame is one path string; holes are
// morphed as rings like any other subpath (flubber has no notion of them).
//
// Usage: node bench_flubber_shapes.js PAIRS_JSON FIXTURE_DIR
// Prints "flubber FROM TO US_PER_FRAME POINTS" per pair (POINTS: the
// vertices of the middle frame's polygons) and the method used as a
// comment; lines starting with '#' are comments.
'use strict';

const fs = require('fs');
const path = require('path');
const flubber = require('flubber');

const FRAMES = 60;
const RUNS = 15;
const MIN_SECONDS = 1.0;

function fixtures(dir) {
  const byId = new Map();
  for (const [file, key] of [['glyphs.json', 'glyphs'], ['icons.json', 'icons']]) {
    const data = JSON.parse(fs.readFileSync(path.join(dir, file), 'utf8'));
    for (const g of data[key]) byId.set(g.id, g.d);
  }
  return byId;
}

// The interpolators of one compound morph, and how they were made; with
// string output each gives the frame's path (a list when not single).
function plan(a, b, options) {
  if (a.length === b.length)
    return { how: 'interpolateAll', fns: [flubber.interpolateAll(a, b, options)] };
  if (b.length === 1)
    return { how: 'combine', fns: [flubber.combine(a, b[0], options)] };
  if (a.length === 1)
    return { how: 'separate', fns: [flubber.separate(a[0], b, options)] };
  const k = Math.min(a.length, b.length) - 1;
  const fns = [flubber.interpolateAll(a.slice(0, k), b.slice(0, k), options)];
  if (a.length > b.length) fns.push(flubber.combine(a.slice(k), b[k], options));
  else fns.push(flubber.separate(a[k], b.slice(k), options));
  return { how: `interpolateAll x${k} + ` +
                (a.length > b.length ? 'combine' : 'separate'), fns };
}

function frame(fns, t) {
  let d = '';
  for (const f of fns) d += (d ? ' ' : '') + f(t);
  return d;
}

function morphOnce(a, b) {
  const { fns } = plan(a, b, { single: true });
  let last = '';
  for (let i = 0; i < FRAMES; i++) last = frame(fns, i / (FRAMES - 1));
  return last;
}

// Vertices of the middle frame: without single, each function of the
// plan is a list of ring interpolators, each ring a list of points.
function middlePoints(a, b) {
  const { fns } = plan(a, b, { single: false, string: false });
  let n = 0;
  for (const list of fns) for (const f of list) n += f(0.5).length;
  return n;
}

function main() {
  const [pairsPath, dir] = process.argv.slice(2);
  if (!pairsPath || !dir) {
    console.error('usage: node bench_flubber_shapes.js PAIRS_JSON FIXTURE_DIR');
    process.exit(2);
  }
  const byId = fixtures(dir);
  const pairs = JSON.parse(fs.readFileSync(pairsPath, 'utf8')).pairs;
  console.log(`# flubber ${require('flubber/package.json').version}, node ` +
              `${process.version}: compound pairs, setup + ${FRAMES} frames, ` +
              `best of the runs over ${MIN_SECONDS} s (at least ${RUNS})`);
  for (const [from, to] of pairs) {
    const a = flubber.splitPathString(byId.get(from));
    const b = flubber.splitPathString(byId.get(to));
    for (let i = 0; i < 3; i++) morphOnce(a, b);
    let best = Infinity;
    const start = process.hrtime.bigint();
    for (let r = 0; r < RUNS ||
         Number(process.hrtime.bigint() - start) / 1e9 < MIN_SECONDS; r++) {
      const t0 = process.hrtime.bigint();
      morphOnce(a, b);
      const us = Number(process.hrtime.bigint() - t0) / 1e3;
      if (us < best) best = us;
    }
    console.log(`# ${from} -> ${to}: ${a.length} -> ${b.length} subpaths, ` +
                plan(a, b, { single: true }).how);
    console.log(`flubber ${from} ${to} ${(best / FRAMES).toFixed(2)} ` +
                `${middlePoints(a, b)}`);
  }
}

main();
