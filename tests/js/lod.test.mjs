// The package's tier rule (core/lod.js) against creaturegen's Python reference (creature/lod.py).
//
//   LOD_CORE=out/<pkg>/core/index.js LOD_REFERENCE=reference.json node --test tests/js/lod.test.mjs
//
// tests/test_lod.py writes the reference. Contract: every tier sequence is the reference's, frame for
// frame; every projected size agrees to 1e-12 relative.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { test } from 'node:test';
import { pathToFileURL } from 'node:url';

const { LOD_CORE: corePath, LOD_REFERENCE: referencePath } = process.env;
if (!corePath || !referencePath) throw new Error('set LOD_CORE (a package\'s core/index.js) and LOD_REFERENCE');
const core = await import(pathToFileURL(corePath).href);
const ref = JSON.parse(readFileSync(referencePath, 'utf8'));

test('the tier order and hysteresis are the reference\'s', () => {
  assert.deepEqual([...core.TIER_ORDER], ref.order);
  assert.equal(core.TIER_HYSTERESIS, ref.hysteresis);
});

test('every body switches tiers where the reference does, frame for frame', () => {
  let switches = 0;
  for (const c of ref.sequences) {
    let current = null;
    const chosen = c.sizes.map((size) => (current = core.chooseTier(size, current, c.ceilings)));
    assert.deepEqual(chosen, c.tiers, `ceilings ${JSON.stringify(c.ceilings)}`);
    switches += chosen.filter((t, i) => i > 0 && t !== chosen[i - 1]).length;
  }
  assert.equal(switches, ref.switches);
});

test('projected sizes match the reference', () => {
  for (const c of ref.projections) {
    const camera = c.orthoHeight === null
      ? { isPerspectiveCamera: true, fov: c.fov, zoom: c.zoom }
      : { isOrthographicCamera: true, top: c.orthoHeight / 2, bottom: -c.orthoHeight / 2, zoom: c.zoom };
    const size = core.projectedSizePx(c.length, c.depth, c.viewport, camera);
    assert.ok(Math.abs(size - c.size) <= 1e-12 * c.size, `${JSON.stringify(c)}: ${size}`);
  }
});
