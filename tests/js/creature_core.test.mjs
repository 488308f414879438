// The JS core of a built creature package against creaturegen's Python reference (creature/sway.py).
//
//   CREATURE_CORE=out/<pkg>/core/index.js CREATURE_REFERENCE=reference.json node --test tests/js/creature_core.test.mjs
//
// tests/test_creature_package.py writes the reference (ticks 0..240 and a few seeds) and runs this file.
// Contract: quaternions and translations (float64) agree to 1e-12 absolute, LCG draws and tick offsets
// exactly, float32 pose rows bitwise or within 1 ulp (V8's and the C library's sin may differ by an ulp),
// or, for a coordinate that cancels to ~0 where float64 noise spans many float32 ulps, within 1e-12.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { test } from 'node:test';
import { pathToFileURL } from 'node:url';

const { CREATURE_CORE: corePath, CREATURE_REFERENCE: referencePath } = process.env;
if (!corePath || !referencePath) {
  throw new Error('set CREATURE_CORE (a package\'s core/index.js) and CREATURE_REFERENCE (the Python reference JSON)');
}
const core = await import(pathToFileURL(corePath).href);
const ref = JSON.parse(readFileSync(referencePath, 'utf8'));
const data = core.CREATURE;

const F64_TOLERANCE = 1e-12;
const F32_ULPS = 1;

/** Float32 bit patterns as integers ordered like the floats they encode (+0 and -0 both 0). */
const ordered = (bits) => (bits & 0x80000000 ? -(bits & 0x7fffffff) : bits);

function worstAbs(actual, expected, what) {
  assert.equal(actual.length, expected.length, `${what}: length`);
  let worst = 0;
  for (let i = 0; i < expected.length; i++) {
    const d = Math.abs(actual[i] - expected[i]);
    if (Number.isNaN(d)) return NaN; // fails the caller's `<=` check
    if (d > worst) worst = d;
  }
  return worst;
}

test('the package carries the constants the reference used', () => {
  assert.equal(data.slots.length, ref.slotCount);
  assert.equal(data.poseRows, ref.constants.poseRows);
  assert.deepEqual(data.lcg, ref.constants.lcg);
  assert.equal(data.sway.period, ref.constants.period);
  assert.equal(data.sway.amplitude, ref.constants.amplitude);
  assert.deepEqual(data.roundCone, ref.constants.roundCone);
});

test('LCG draws are exactly equal', () => {
  for (const { seed, draws } of ref.lcg) {
    let state = seed >>> 0;
    const got = draws.map(() => (state = core.lcgNext(state, data.lcg.a, data.lcg.c)));
    assert.deepEqual(got, draws, `seed ${seed}`);
  }
});

test('instanceOffset matches: tick offset exactly, yaw to 1e-12', () => {
  for (const { seed, tickOffset, yaw } of ref.instances) {
    const got = core.instanceOffset(seed, data.lcg, data.sway.period);
    assert.equal(got.tickOffset, tickOffset, `seed ${seed}`);
    assert.ok(Math.abs(got.yaw - yaw) <= F64_TOLERANCE, `seed ${seed}: yaw ${got.yaw} vs ${yaw}`);
  }
});

test('swayTransforms and writePoseRows match the reference at every tick', (t) => {
  const slots = ref.slotCount;
  const rowFloats = slots * data.poseRows * 4;
  const scratch = core.createPoseScratch(slots);
  const pad = 8; // write at a non-zero base: the base offset is honoured, the rest of the page untouched
  const page = new Float32Array(pad + rowFloats + pad).fill(-7);
  const bits = new Uint32Array(page.buffer);
  const bounds = new Float64Array(6);
  const referenceBits = new Uint32Array(1);
  const referenceFloat = new Float32Array(referenceBits.buffer);
  let worstQ = 0, worstT = 0, worstUlps = 0, nearZero = 0, frames = 0, exactRows = 0;
  for (const { label, tickShift, frames: expected } of ref.cases) {
    for (const frame of expected) {
      const tick = frame.tick + tickShift;
      core.swayTransforms(data, tick, scratch);
      const q = worstAbs(scratch.quats, frame.quats, `${label} tick ${tick} quats`);
      const tr = worstAbs(scratch.trans, frame.trans, `${label} tick ${tick} trans`);
      assert.ok(q <= F64_TOLERANCE, `${label} tick ${tick}: quaternion error ${q}`);
      assert.ok(tr <= F64_TOLERANCE, `${label} tick ${tick}: translation error ${tr}`);
      worstQ = Math.max(worstQ, q);
      worstT = Math.max(worstT, tr);
      core.writePoseRows(data, scratch, page, pad, bounds);
      let exact = true;
      for (let i = 0; i < rowFloats; i++) {
        const ulps = Math.abs(ordered(bits[pad + i]) - ordered(frame.rowBits[i]));
        if (ulps === 0) continue;
        exact = false;
        referenceBits[0] = frame.rowBits[i];
        const diff = Math.abs(page[pad + i] - referenceFloat[0]);
        if (ulps <= F32_ULPS) {
          worstUlps = Math.max(worstUlps, ulps);
        } else if (diff <= F64_TOLERANCE) {
          // a coordinate that cancels to ~0: float64 noise (<= 1e-12) is many float32 ulps of a tiny number
          nearZero += 1;
        } else {
          assert.fail(`${label} tick ${tick}: pose row float ${i} is ${page[pad + i]}, reference ` +
            `${referenceFloat[0]} (${ulps} ulps, ${diff} apart)`);
        }
      }
      exactRows += exact;
      frames += 1;
      for (let i = 0; i < pad; i++) {
        assert.equal(page[i], -7, 'writePoseRows wrote before its base');
        assert.equal(page[pad + rowFloats + i], -7, 'writePoseRows wrote past its instance');
      }
      // the returned bounds hold every posed end sphere
      for (let s = 0; s < slots; s++) {
        for (let end = 0; end < 2; end++) {
          const o = pad + s * data.poseRows * 4 + end * 4;
          const r = page[o + 3];
          for (let k = 0; k < 3; k++) {
            assert.ok(page[o + k] - r >= bounds[k] - 1e-6 && page[o + k] + r <= bounds[3 + k] + 1e-6, 'bounds');
          }
        }
      }
    }
  }
  assert.equal(frames, ref.frameCount);
  t.diagnostic(`frames ${frames}, worst |dq| ${worstQ}, worst |dt| ${worstT}, worst ulps ${worstUlps}, ` +
    `floats within 1e-12 but > 1 ulp (near zero) ${nearZero}, bitwise-equal frames ${exactRows}`);
});
