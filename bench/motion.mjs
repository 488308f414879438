// The Node side of bench/motion.py: CPU cost and allocation of a creature package's locomotion core.
//
//   node --expose-gc --no-concurrent-recompilation bench/motion.mjs <package>/core/index.js '<json options>'
//
// --no-concurrent-recompilation: V8 then optimises on the main thread, at points fixed by call counts, not
// when its background compiler thread gets the CPU. On a loaded machine (CI beside Chromium's SwiftShader
// threads) a starved compiler landed the optimised step after the warm-up, and every measured window timed
// unoptimised code, which boxes every double (14 collections in one make test run; 46 per window with
// --concurrent-recompilation-delay=1000). The steady-state code is the same; only when it arrives is fixed.
//
// Prints one JSON object: per-step cost (µs per creature per fixed step, median of rounds, and the p50 / p95
// / max of single steps of the whole population), steady-state allocation (V8 heap growth and garbage
// collections over a run of steps, after a full collection), the bodies' peak live heap, and,
// for creatures with ropes, the rope cost against substeps × passes × segments. Bench code: it may use
// wall clocks; the shipped core it measures may not.
import { performance } from 'node:perf_hooks';
import { pathToFileURL } from 'node:url';
import { allocationWindows } from './alloc.mjs';

const [corePath, optionsText] = process.argv.slice(2);
if (!corePath) throw new Error('usage: node --expose-gc bench/motion.mjs <package>/core/index.js [json options]');
if (typeof globalThis.gc !== 'function') throw new Error('run node with --expose-gc');
if (!process.execArgv.includes('--no-concurrent-recompilation')) {
  throw new Error('run node with --no-concurrent-recompilation (allocation windows must not depend on the machine\'s load)');
}
const options = {
  bodies: 32, warm: 300, ticks: 300, rounds: 5, allocWarm: 20000, allocSteps: 5000, allocRounds: 5, ropeConfigs: [[1, 2], [2, 4], [4, 8]],
  only: null, ...JSON.parse(optionsText ?? '{}'),
};
const core = await import(pathToFileURL(corePath).href);
const data = core.CREATURE;

function bodies(motionData, count) {
  const out = [];
  for (let i = 0; i < count; i++) {
    out.push(core.createMotion(motionData, core.LCG, { water: core.createAnalyticWater(), seed: i + 1, position: [i * 3 * data.bodyScale, 0, 0] }));
  }
  return out;
}

/** Median µs per creature per step over rounds of `ticks` steps of every body, after `warm` steps. */
function stepCost(motionData, count = options.bodies) {
  const list = bodies(motionData, count);
  for (const m of list) m.stepTicks(options.warm);
  const samples = [];
  for (let r = 0; r < options.rounds; r++) {
    const t0 = process.hrtime.bigint();
    for (let k = 0; k < options.ticks; k++) for (let i = 0; i < list.length; i++) list[i].step();
    samples.push(Number(process.hrtime.bigint() - t0) / 1000 / (options.ticks * list.length));
  }
  samples.sort((a, b) => a - b);
  // Single fixed steps of the whole population, each timed alone: a step that spikes (a gait event, a
  // rope settling, a collection) shows in the p95 and the max, which round means smooth away.
  const steps = new Float64Array(options.rounds * options.ticks);
  for (let k = 0; k < steps.length; k++) {
    const t0 = performance.now();
    for (let i = 0; i < list.length; i++) list[i].step();
    steps[k] = ((performance.now() - t0) * 1000) / list.length;
  }
  steps.sort();
  const at = (q) => steps[Math.min(steps.length - 1, Math.floor(q * steps.length))];
  const perStep = { steps: steps.length, p50: at(0.5), p95: at(0.95), max: steps[steps.length - 1] };
  return { median: samples[Math.floor(samples.length / 2)], min: samples[0], max: samples.at(-1), samples, perStep };
}

/**
 * The live heap of `count` bodies: V8 heapUsed after a full collection at checkpoints over `allocSteps`
 * steps of all of them (garbage does not count), less the heap once they are released and collected (so
 * the code and type feedback their steps compiled, which stay, do not count either); the peak over the
 * checkpoints, and per body.
 */
function liveBytes(motionData, count = options.bodies) {
  let list = bodies(motionData, count);
  const heaps = [];
  const parts = 5;
  for (let c = 0; c <= parts; c++) {
    if (c > 0) for (let k = 0; k < options.allocSteps / parts; k++) for (let i = 0; i < list.length; i++) list[i].step();
    globalThis.gc();
    heaps.push(process.memoryUsage().heapUsed);
  }
  list = null;
  globalThis.gc();
  const released = process.memoryUsage().heapUsed;
  const checkpoints = heaps.map((h) => h - released);
  const peak = Math.max(...checkpoints);
  return { bodies: count, peakLiveBytes: peak, perBodyBytes: peak / count, checkpoints };
}

/** `steps` steps of `m`: the measured loop, a function of its own so it is optimised (and its compiled
 * code allocated) during the warm-up, not inside the measured window. */
function run(m, steps) {
  for (let k = 0; k < steps; k++) m.step();
}

/** Allocation of `allocSteps` steady-state steps of one body (bench/alloc.mjs). */
async function allocation(motionData) {
  const [m] = bodies(motionData, 1);
  const best = await allocationWindows((n) => run(m, n), { warm: options.allocWarm, window: options.allocSteps, rounds: options.allocRounds });
  return { steps: options.allocSteps, bytesPerStep: best.heapGrowthBytes / options.allocSteps, ...best };
}

const motion = data.motion;
const result = {
  package: data.slug, type: motion.type, hz: motion.hz, slots: data.slotCount, legs: motion.legs.length,
  ropes: motion.ropes.map((r) => ({ part: r.part, segments: r.slots.length })),
  node: process.version, v8Flags: process.execArgv,
  allocation: await allocation(motion),
  live: liveBytes(motion),
};
if (options.only !== 'allocation') result.step = stepCost(motion);
if (motion.ropes.length && options.only !== 'allocation') {
  const segments = motion.ropes.reduce((n, r) => n + r.slots.length, 0);
  const without = stepCost({ ...motion, ropes: [] });
  const configs = options.ropeConfigs.map(([substeps, passes]) => {
    const variant = { ...motion, constants: { ...motion.constants, ropeSubsteps: substeps, ropePasses: passes } };
    const cost = stepCost(variant);
    return { substeps, passes, segments, work: substeps * passes * segments, stepUs: cost.median, ropeUs: cost.median - without.median };
  });
  // Least squares of rope µs against substeps·passes·segments: the cost per unit of rope work.
  const n = configs.length;
  const mx = configs.reduce((a, c) => a + c.work, 0) / n, my = configs.reduce((a, c) => a + c.ropeUs, 0) / n;
  const slope = configs.reduce((a, c) => a + (c.work - mx) * (c.ropeUs - my), 0) / configs.reduce((a, c) => a + (c.work - mx) ** 2, 0);
  result.rope = { withoutRopesUs: without.median, configs, usPerUnit: slope, interceptUs: my - slope * mx };
}
console.log(JSON.stringify(result));
