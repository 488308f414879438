// The closed-form sway pose in float64, the same formulas in the same order as creaturegen's
// Python reference (creature/sway.py): q_s = q_parent ⊗ axisAngle(axis_s, θ_s),
// t_s = R(q_parent)(pivot_s − R(axisAngle) pivot_s) + t_parent, θ_s = A sin(2π (n mod P)/P + φ_s).

import { rotate } from './motion/quat.js';

export { rotate };

/** Scratch space for one creature: per-slot quaternions and translations (float64), allocated once. */
export function createPoseScratch(slotCount) {
  return {
    quats: new Float64Array(slotCount * 4),
    trans: new Float64Array(slotCount * 3),
    local: new Float64Array(4),
    tmp: new Float64Array(3),
  };
}

/** Per-slot transforms at integer `tick` into `scratch` (no allocation). */
export function swayTransforms(data, tick, scratch) {
  const { parent, order, pivot, axis, phase, amplitude, period } = data.sway;
  const { quats, trans, local, tmp } = scratch;
  const n = ((tick % period) + period) % period;
  const phaseOfTick = 2 * Math.PI * (n / period);
  for (let k = 0; k < order.length; k++) {
    const s = order[k];
    const p = parent[s];
    if (p < 0) {
      quats[4 * s] = 0; quats[4 * s + 1] = 0; quats[4 * s + 2] = 0; quats[4 * s + 3] = 1;
      trans[3 * s] = 0; trans[3 * s + 1] = 0; trans[3 * s + 2] = 0;
      continue;
    }
    const angle = amplitude * Math.sin(phaseOfTick + phase[s]);
    const half = 0.5 * angle;
    const sh = Math.sin(half);
    const ax = axis[s];
    local[0] = ax[0] * sh; local[1] = ax[1] * sh; local[2] = ax[2] * sh; local[3] = Math.cos(half);
    const pv = pivot[s];
    rotate(local, 0, pv[0], pv[1], pv[2], tmp, 0);
    // q_s = q_p ⊗ local
    const px = quats[4 * p], py = quats[4 * p + 1], pz = quats[4 * p + 2], pw = quats[4 * p + 3];
    const bx = local[0], by = local[1], bz = local[2], bw = local[3];
    quats[4 * s] = pw * bx + px * bw + py * bz - pz * by;
    quats[4 * s + 1] = pw * by - px * bz + py * bw + pz * bx;
    quats[4 * s + 2] = pw * bz + px * by - py * bx + pz * bw;
    quats[4 * s + 3] = pw * bw - px * bx - py * by - pz * bz;
    rotate(quats, 4 * p, pv[0] - tmp[0], pv[1] - tmp[1], pv[2] - tmp[2], trans, 3 * s);
    trans[3 * s] += trans[3 * p];
    trans[3 * s + 1] += trans[3 * p + 1];
    trans[3 * s + 2] += trans[3 * p + 2];
  }
}

/**
 * Write one instance's pose rows (POSE_ROWS vec4 per slot) into `target` at float offset `base`:
 * (a, ra), (b, rb), (k, rgb), quaternion xyzw, (t, roundCone). Returns the creature-local AABB of the
 * posed primitives into `bounds` (min xyz, max xyz).
 */
export function writePoseRows(data, scratch, target, base, bounds) {
  const { quats, trans, tmp } = scratch;
  const slots = data.slots;
  const rows = data.poseRows;
  let minX = Infinity, minY = Infinity, minZ = Infinity, maxX = -Infinity, maxY = -Infinity, maxZ = -Infinity;
  for (let s = 0; s < slots.length; s++) {
    const row = slots[s];
    const o = base + s * rows * 4;
    for (let end = 0; end < 2; end++) {
      const c = end * 4;
      rotate(quats, 4 * s, row[c], row[c + 1], row[c + 2], tmp, 0);
      const x = tmp[0] + trans[3 * s], y = tmp[1] + trans[3 * s + 1], z = tmp[2] + trans[3 * s + 2];
      const r = row[c + 3];
      target[o + c] = x; target[o + c + 1] = y; target[o + c + 2] = z; target[o + c + 3] = r;
      if (x - r < minX) minX = x - r;
      if (y - r < minY) minY = y - r;
      if (z - r < minZ) minZ = z - r;
      if (x + r > maxX) maxX = x + r;
      if (y + r > maxY) maxY = y + r;
      if (z + r > maxZ) maxZ = z + r;
    }
    target[o + 8] = row[8]; target[o + 9] = row[9]; target[o + 10] = row[10]; target[o + 11] = row[11];
    target[o + 12] = quats[4 * s]; target[o + 13] = quats[4 * s + 1];
    target[o + 14] = quats[4 * s + 2]; target[o + 15] = quats[4 * s + 3];
    target[o + 16] = trans[3 * s]; target[o + 17] = trans[3 * s + 1]; target[o + 18] = trans[3 * s + 2];
    target[o + 19] = data.roundCone[s];
  }
  bounds[0] = minX; bounds[1] = minY; bounds[2] = minZ; bounds[3] = maxX; bounds[4] = maxY; bounds[5] = maxZ;
}
