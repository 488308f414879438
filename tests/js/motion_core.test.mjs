// The locomotion core of a built creature package against creaturegen's Python reference (motion/).
//
//   MOTION_CORE=out/<pkg>/core/index.js MOTION_REFERENCE=reference.json node --test tests/js/motion_core.test.mjs
//
// tests/test_motion.py writes the reference (creaturegen.motion.parity.motion_reference) and runs this file.
// Contract: after 0..1000 ticks on every built-in support surface, every number of the state vector (root,
// each slot's quaternion and translation, rope nodes) agrees to |js − py| ≤ 1e-12·max(|py|, L); the
// driver's step counts and alpha match exactly; seekTick(n) equals n steps bit for bit (stateHash); a
// swimmer without a required water channel is refused.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { test } from 'node:test';
import { pathToFileURL } from 'node:url';

const { MOTION_CORE: corePath, MOTION_REFERENCE: referencePath } = process.env;
if (!corePath || !referencePath) throw new Error('set MOTION_CORE (a package\'s core/index.js) and MOTION_REFERENCE');
const core = await import(pathToFileURL(corePath).href);
const ref = JSON.parse(readFileSync(referencePath, 'utf8'));
const data = core.CREATURE.motion;
const L = ref.bodyScale;

function spawn(support, seed) {
  return core.createMotion(data, core.LCG, { support: core.builtinSupports()[support], water: core.createAnalyticWater(), seed });
}

function worst(actual, expected, what) {
  assert.equal(actual.length, expected.length, `${what}: length`);
  let worstRatio = 0, at = -1;
  for (let i = 0; i < expected.length; i++) {
    const ratio = Math.abs(actual[i] - expected[i]) / Math.max(Math.abs(expected[i]), L);
    if (!(ratio <= worstRatio)) { worstRatio = ratio; at = i; }
  }
  return { ratio: worstRatio, at };
}

test('the package carries the motion data the reference used', () => {
  assert.deepEqual(JSON.parse(JSON.stringify(data)), ref.data);
});

test('JS core matches Python after 1000 ticks on every support surface', () => {
  const lines = [];
  for (const c of ref.cases) {
    const motion = spawn(c.support, c.seed);
    let frame = 0;
    let caseWorst = 0;
    for (let tick = 0; tick <= ref.ticks[ref.ticks.length - 1]; tick++) {
      if (tick) motion.step();
      if (tick !== c.frames[frame]?.tick) continue;
      const { ratio, at } = worst(motion.stateVector(), c.frames[frame].state, `${c.support} tick ${tick}`);
      assert.ok(ratio <= ref.relative, `${c.support} seed ${c.seed} tick ${tick}: number ${at} differs by ${ratio} relative`);
      caseWorst = Math.max(caseWorst, ratio);
      frame += 1;
    }
    assert.equal(frame, c.frames.length);
    const prev = { q: new Float64Array(motion.quats.length), t: new Float64Array(motion.trans.length), r: new Float64Array(6) };
    motion.step();
    motion.renderPose(c.render.alpha, prev.q, prev.t, prev.r);
    const render = Array.from(prev.r);
    for (let s = 0; s < prev.q.length / 4; s++) render.push(...prev.q.subarray(4 * s, 4 * s + 4), ...prev.t.subarray(3 * s, 3 * s + 3));
    const { ratio } = worst(render, c.render.state, `${c.support} render pose`);
    assert.ok(ratio <= ref.relative, `${c.support}: interpolated render pose differs by ${ratio}`);
    for (const key of ['steps', 'clampedTicks', 'bothSwingTicks', 'fewestPlanted', 'plantedSamples']) {
      const py = c.gates[key.replace(/[A-Z]/g, (ch) => `_${ch.toLowerCase()}`)];
      assert.equal(motion.gates[key], py, `${c.support}: gate ${key}`);
    }
    lines.push(`${c.support} seed ${c.seed}: worst ${caseWorst.toExponential(2)} relative`);
  }
  console.log(lines.join('\n'));
});

test('derived numbers match', () => {
  // From the individual of case 0 (its size and gait genes scale the authored data), as Python derived them.
  const individual = core.express(data, core.drawGenome(ref.cases[0].seed, core.LCG));
  const d = core.derive(individual, [0, -core.STANDARD_GRAVITY, 0]);
  const py = ref.cases[0].derived;
  for (const [k, v] of Object.entries(py)) {
    const js = d[k.replace(/_([a-z])/g, (_, ch) => ch.toUpperCase())];
    // Integers (tick counts) exactly; the rest within 1 ulp-scale (V8's and the C library's atan2 and
    // sin may differ in the last bit).
    if (Number.isInteger(v)) assert.equal(js, v, `derived ${k}`);
    else assert.ok(Math.abs(js - v) <= 4e-16 * Math.max(Math.abs(v), 1), `derived ${k}: ${js} vs ${v}`);
  }
});

test('the driver steps and interpolates exactly like Python', () => {
  const driver = core.createDriver(ref.driver.hz);
  for (const f of ref.driver.frames) {
    assert.equal(driver.advance(f.dt), f.steps, `dt ${f.dt}`);
    assert.equal(driver.alpha, f.alpha);
    assert.equal(driver.accumulator, f.accumulator);
  }
});

test('seekTick(n) and stepTicks(n) reach the same stateHash', () => {
  const a = spawn('rotating', 7);
  const b = spawn('rotating', 7);
  for (const n of [1, 37, 300]) {
    a.seekTick(n);
    b.reset();
    b.stepTicks(n);
    assert.equal(a.stateHash(), b.stateHash(), `tick ${n}`);
  }
  b.step();
  assert.notEqual(a.stateHash(), b.stateHash(), 'the hash sees a step');
});

test('a swimmer missing a required water channel is refused, not zero-filled', () => {
  const kept = core.SWIMMER_CHANNELS.slice(1);
  const water = core.createAnalyticWater({ channels: kept });
  if (data.type !== 'swimmer') return;
  assert.throws(() => core.createMotion(data, core.LCG, { water }), core.TierRefusedError);
  assert.throws(() => core.createMotion(data, core.LCG, {}), /no WaterSurfaceProvider/);
});
