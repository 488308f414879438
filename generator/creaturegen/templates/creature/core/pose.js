// Pose pages: one instance's per-slot transforms (from the locomotion core, core/motion/motion.js) as the
// float32 rows the GPU reads, the same arithmetic in the same order as creaturegen's Python reference
// (creature/pose.py pose_rows). A posed point is x' = R(q_s)·(size·x) + t_s in creature-local space, size
// the individual's (core/genome.js); the root (position, heading, squash) is applied once, by the material.

import { rotate } from './motion/quat.js';

export { rotate };

/** vec4 rows per slot in a pose page: (a, ra), (b, rb), (k, rgb), quaternion xyzw, (t, roundCone)
 * (creaturegen creature/pose.py POSE_ROWS). */
export const POSE_ROWS = 5;

/**
 * Write one instance's slot rows (POSE_ROWS vec4 per slot) into `target` at float offset `base`:
 * (a, ra), (b, rb), (k, rgb), quaternion xyzw, (t, roundCone), from per-slot `quats` (xyzw) and `trans`,
 * and the individual's per-slot linear rgb `colours` at offset `co` (core/genome.js genomeColours; null
 * writes the authored colours). `tmp` is a 3-float scratch. Returns the creature-local AABB of the posed
 * primitives into `bounds` (min xyz, max xyz). `size` scales the rest ends, radii and blend widths (the
 * motion's `size`). Allocates nothing.
 */
export function writePoseRows(data, quats, trans, colours, co, tmp, target, base, bounds, size = 1) {
  const slots = data.slots;
  const rows = POSE_ROWS;
  let minX = Infinity, minY = Infinity, minZ = Infinity, maxX = -Infinity, maxY = -Infinity, maxZ = -Infinity;
  for (let s = 0; s < slots.length; s++) {
    const row = slots[s];
    const o = base + s * rows * 4;
    for (let end = 0; end < 2; end++) {
      const c = end * 4;
      tmp[0] = row[c] * size; tmp[1] = row[c + 1] * size; tmp[2] = row[c + 2] * size;
      rotate(quats, 4 * s, tmp, 0, tmp, 0);
      const x = tmp[0] + trans[3 * s], y = tmp[1] + trans[3 * s + 1], z = tmp[2] + trans[3 * s + 2];
      const r = row[c + 3] * size;
      target[o + c] = x; target[o + c + 1] = y; target[o + c + 2] = z; target[o + c + 3] = r;
      if (x - r < minX) minX = x - r;
      if (y - r < minY) minY = y - r;
      if (z - r < minZ) minZ = z - r;
      if (x + r > maxX) maxX = x + r;
      if (y + r > maxY) maxY = y + r;
      if (z + r > maxZ) maxZ = z + r;
    }
    target[o + 8] = row[8] * size;
    if (colours) {
      const c = co + 3 * s;
      target[o + 9] = colours[c]; target[o + 10] = colours[c + 1]; target[o + 11] = colours[c + 2];
    } else {
      target[o + 9] = row[9]; target[o + 10] = row[10]; target[o + 11] = row[11];
    }
    target[o + 12] = quats[4 * s]; target[o + 13] = quats[4 * s + 1];
    target[o + 14] = quats[4 * s + 2]; target[o + 15] = quats[4 * s + 3];
    target[o + 16] = trans[3 * s]; target[o + 17] = trans[3 * s + 1]; target[o + 18] = trans[3 * s + 2];
    target[o + 19] = data.roundCone[s];
  }
  bounds[0] = minX; bounds[1] = minY; bounds[2] = minZ; bounds[3] = maxX; bounds[4] = maxY; bounds[5] = maxZ;
}

/**
 * Write the two root rows at float offset `at`: (x, y, z, alive), (cos yaw, sin yaw, squash, size), from a
 * root (x, y, z, cos, sin, squash) as the locomotion core keeps it and the individual's size.
 */
export function writeRootRows(root, alive, target, at, size = 1) {
  target[at] = root[0]; target[at + 1] = root[1]; target[at + 2] = root[2]; target[at + 3] = alive;
  target[at + 4] = root[3]; target[at + 5] = root[4]; target[at + 6] = root[5]; target[at + 7] = size;
}

/**
 * World AABB of an instance from its creature-local AABB `local` and root: squash (1/√s, s, 1/√s) about
 * the creature origin, then the yaw (conservatively: the rotated box's bounds), then the position.
 */
export function rootBounds(local, root, out, at) {
  const k = 1 / Math.sqrt(root[5]);
  const c = root[3], s = root[4];
  const cx = 0.5 * (local[0] + local[3]) * k, cz = 0.5 * (local[2] + local[5]) * k;
  const hx = 0.5 * (local[3] - local[0]) * k, hz = 0.5 * (local[5] - local[2]) * k;
  const wx = Math.abs(c) * hx + Math.abs(s) * hz, wz = Math.abs(s) * hx + Math.abs(c) * hz;
  const px = c * cx + s * cz + root[0], pz = -s * cx + c * cz + root[2];
  out[at] = px - wx; out[at + 1] = local[1] * root[5] + root[1]; out[at + 2] = pz - wz;
  out[at + 3] = px + wx; out[at + 4] = local[4] * root[5] + root[1]; out[at + 5] = pz + wz;
}
