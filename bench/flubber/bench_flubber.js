// bench_flubber.js - flubber's interpolate() on the shape pairs of
// tests/fixtures/shapes.json, timed the way kmorph's bench_morph times its
// morphs: setup plus 60 frames (t = i / 59), per-frame time with the setup
// amortised over the frames, best of the runs made over at least a second
// (as bench_morph does: on a shared machine a short series reads the
// machine's phase, not the code).
//
// Usage: node bench_flubber.js SHAPES_JSON
// Prints one line per pair, "flubber NAME US_PER_FRAME POINTS", where
// POINTS is the vertex count of flubber's middle frame (a polygon); lines
// starting with '#' are comments. flubber runs with its defaults
// (maxSegmentLength 10, string output), as a web page would use it.
'use strict';

const fs = require('fs');
const flubber = require('flubber');

const FRAMES = 60;
const RUNS = 15;          // at least this many runs,
const MIN_SECONDS = 1.0;  // and runs for at least this long

function morphOnce(a, b) {
  const interp = flubber.interpolate(a, b);
  let last = '';
  for (let i = 0; i < FRAMES; i++) last = interp(i / (FRAMES - 1));
  return last;
}

function main() {
  const path = process.argv[2];
  if (!path) {
    console.error('usage: node bench_flubber.js SHAPES_JSON');
    process.exit(2);
  }
  const shapes = JSON.parse(fs.readFileSync(path, 'utf8'));
  console.log(`# flubber ${require('flubber/package.json').version}, node ` +
              `${process.version}: setup + ${FRAMES} frames, best of the runs ` +
              `over ${MIN_SECONDS} s (at least ${RUNS})`);
  for (const pair of shapes.pairs) {
    // warm up the JIT on this pair before timing it
    for (let i = 0; i < 3; i++) morphOnce(pair.a_d, pair.b_d);
    let best = Infinity;
    const start = process.hrtime.bigint();
    for (let r = 0; r < RUNS ||
         Number(process.hrtime.bigint() - start) / 1e9 < MIN_SECONDS; r++) {
      const t0 = process.hrtime.bigint();
      morphOnce(pair.a_d, pair.b_d);
      const us = Number(process.hrtime.bigint() - t0) / 1e3;
      if (us < best) best = us;
    }
    const mid = flubber.interpolate(pair.a_d, pair.b_d, { string: false })(0.5);
    console.log(`flubber ${pair.name} ${(best / FRAMES).toFixed(2)} ${mid.length}`);
  }
}

main();
