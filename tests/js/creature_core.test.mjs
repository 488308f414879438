// The JS core of a built creature package against creaturegen's Python reference: LCG draws and headings
// (creature/pose.py), and the pose rows the population uploads, written from the locomotion core's state
// (createMotion → writePoseRows + writeRootRows) against motion/simulate.py → pose_rows + root_rows.
//
//   CREATURE_CORE=out/<pkg>/core/index.js CREATURE_REFERENCE=reference.json node --test tests/js/creature_core.test.mjs
//
// tests/test_creature_package.py writes the reference (ticks 0..240 for three seeds) and runs this file.
// Contract: LCG draws exact, headings to 1e-12, float32 rows bitwise (the motion cores agree bit for bit,
// tests/test_motion.py), and the world bounds hold every squashed, turned and moved end sphere.
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

test('the package carries the constants the reference used', () => {
  assert.equal(data.slots.length, ref.slotCount);
  assert.equal(core.POSE_ROWS, ref.constants.poseRows);
  assert.deepEqual({ ...core.LCG }, ref.constants.lcg);
  assert.deepEqual(data.roundCone, ref.constants.roundCone);
  assert.equal(data.maxParts, data.slotCount + 1, 'one extra part per instance holds the root rows');
});

test('LCG draws are exactly equal', () => {
  for (const { seed, draws } of ref.lcg) {
    let state = seed >>> 0;
    const got = draws.map(() => (state = core.lcgNext(state, core.LCG.a, core.LCG.c)));
    assert.deepEqual(got, draws, `seed ${seed}`);
  }
});

test('instanceYaw matches to 1e-12', () => {
  for (const { seed, mixed, yaw } of ref.instances) {
    assert.equal(core.mixSeed(seed), mixed, `seed ${seed}: mixSeed`);
    const got = core.instanceYaw(seed, core.LCG);
    assert.ok(Math.abs(got - yaw) <= 1e-12, `seed ${seed}: yaw ${got} vs ${yaw}`);
  }
});

test('pose rows and root rows from the motion core match the reference bit for bit', (t) => {
  const rowFloats = ref.slotCount * core.POSE_ROWS * 4;
  const total = rowFloats + 8;
  const pad = 8; // write at a non-zero base: the base offset is honoured, the rest of the page untouched
  const page = new Float32Array(pad + total + pad).fill(-7);
  const bits = new Uint32Array(page.buffer);
  const tmp = new Float64Array(3);
  const local = new Float64Array(6);
  const world = new Float64Array(6);
  const p = new Float64Array(3);
  let frames = 0, minSquash = Infinity, maxSquash = -Infinity;
  for (const { seed, size, frames: expected } of ref.cases) {
    const motion = core.createMotion(data.motion, core.LCG, { water: core.createAnalyticWater(), seed });
    assert.equal(motion.size, size, `seed ${seed}: size`);
    const colours = core.genomeColours(data, core.drawGenome(seed, core.LCG), new Float64Array(3 * ref.slotCount));
    for (const frame of expected) {
      if (frame.tick) motion.step();
      assert.equal(motion.tick, frame.tick);
      core.writePoseRows(data, motion.quats, motion.trans, colours, 0, tmp, page, pad, local, motion.size);
      core.writeRootRows(motion.root, 1, page, pad + rowFloats, motion.size);
      for (let i = 0; i < total; i++) {
        if (bits[pad + i] !== frame.rowBits[i]) assert.fail(`seed ${seed} tick ${frame.tick}: row float ${i} is ${page[pad + i]}`);
      }
      for (let i = 0; i < pad; i++) {
        assert.equal(page[i], -7, 'wrote before its base');
        assert.equal(page[pad + total + i], -7, 'wrote past its instance');
      }
      // World bounds: every end sphere, squashed (1/√s, s, 1/√s), turned and moved, lies inside.
      const root = motion.root;
      core.rootBounds(local, root, world, 0);
      const k = 1 / Math.sqrt(root[5]);
      minSquash = Math.min(minSquash, root[5]);
      maxSquash = Math.max(maxSquash, root[5]);
      for (let s = 0; s < ref.slotCount; s++) {
        for (let end = 0; end < 2; end++) {
          const o = pad + s * core.POSE_ROWS * 4 + end * 4;
          // The squashed sphere is an ellipsoid: semi-axes r/√s across (unchanged by the yaw) and r·s up.
          const across = page[o + 3] * k, up = page[o + 3] * root[5];
          const x = page[o] * k, y = page[o + 1] * root[5], z = page[o + 2] * k;
          p[0] = root[3] * x + root[4] * z + root[0]; p[1] = y + root[1]; p[2] = -root[4] * x + root[3] * z + root[2];
          for (let a = 0; a < 3; a++) {
            const r = a === 1 ? up : across;
            assert.ok(p[a] - r >= world[a] - 1e-6 && p[a] + r <= world[3 + a] + 1e-6, `seed ${seed} tick ${frame.tick}: bounds axis ${a}`);
          }
        }
      }
      frames += 1;
    }
  }
  assert.equal(frames, ref.frameCount);
  t.diagnostic(`frames ${frames}, bitwise equal: all; squash range [${minSquash}, ${maxSquash}]`);
});
