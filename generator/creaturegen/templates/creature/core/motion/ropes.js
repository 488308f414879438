// Ropes (tails, tentacles; creaturegen's Python reference: motion/ropes.py): fixed-step verlet in world
// space, the anchor following the posed body.
// Stage 4 of a tick (motion.js), written last: each substep moves the nodes by their velocity and gravity,
// then relaxation passes restore the segment lengths, hold the bend limit (a node's neighbours at least
// bendMin apart) and, for creatures standing on the support, keep the nodes above it by their radius; a
// follow-the-leader pass from the anchor then sets every segment to its rest length inside the bend
// limit's cone. The rope's slots are posed by parallel transport down the chain.

import { toLocal, toWorld } from './providers.js';
import { fromTo, mul, normalizeInto, rotate } from './quat.js';
import { toLocalRoot, toWorldRoot } from './root.js';
import { G } from './state.js';

/** Rest point j of the rope moved rigidly with its parent slot (creature-local), into out[o..o+2]. */
export function anchorPoint(st, rope, j, out, o) {
  const trans = st.trans;
  const p = rope.parent;
  const x = rope.rest[j];
  rotate(st.quats, 4 * p, x, 0, out, o);
  out[o] += trans[3 * p]; out[o + 1] += trans[3 * p + 1]; out[o + 2] += trans[3 * p + 2];
}

/** Every rope's nodes where its rest pose puts them on the posed body, not moving (the previous nodes the
 * same): the ropes at reset (motion/ropes.py rest_nodes). */
export function restNodes(st) {
  const nodes = st.nodes, prevNodes = st.prevNodes, v3 = st.v3;
  st.data.ropes.forEach((rope, r) => {
    for (let j = 0; j < rope.rest.length; j++) {
      anchorPoint(st, rope, j, v3, 0);
      toWorldRoot(st.root, v3, 0, nodes[r], 3 * j);
      prevNodes[r][3 * j] = nodes[r][3 * j]; prevNodes[r][3 * j + 1] = nodes[r][3 * j + 1]; prevNodes[r][3 * j + 2] = nodes[r][3 * j + 2];
    }
  });
}

/** The bend limit (motion/ropes.py bend): node j's neighbours at least rope.bendMin apart; the anchor and
 * the point `before` it on the body are fixed, so the first two constraints move only the far node. */
export function bend(cur, count, before, rope) {
  const bendMin = rope.bendMin;
  for (let j = 0; j < count - 1; j++) {
    const b = 3 * (j + 1);
    const ax = j === 0 ? before[0] : cur[3 * (j - 1)];
    const ay = j === 0 ? before[1] : cur[3 * (j - 1) + 1];
    const az = j === 0 ? before[2] : cur[3 * (j - 1) + 2];
    const dx = cur[b] - ax, dy = cur[b + 1] - ay, dz = cur[b + 2] - az;
    const dist = Math.sqrt(dx * dx + dy * dy + dz * dz);
    if (dist >= bendMin || dist === 0) continue;
    const f = (dist - bendMin) / dist;
    if (j <= 1) {
      cur[b] = cur[b] - dx * f; cur[b + 1] = cur[b + 1] - dy * f; cur[b + 2] = cur[b + 2] - dz * f;
    } else {
      const a = 3 * (j - 1);
      const hf = 0.5 * f;
      cur[a] = ax + dx * hf; cur[a + 1] = ay + dy * hf; cur[a + 2] = az + dz * hf;
      cur[b] = cur[b] - dx * hf; cur[b + 1] = cur[b + 1] - dy * hf; cur[b + 2] = cur[b + 2] - dz * hf;
    }
  }
}

/** Follow the leader from the anchor (motion/ropes.py follow): each segment its rest length and within the
 * bend limit of the one before (the first of the body's direction from `before` into the anchor), and
 * above the support frame, lifted by swinging the segment about its first node so its length holds. */
export function follow(st, cur, count, before, rope, frame) {
  const ropeLocal = st.ropeLocal, ground = st.data.ropeGround;
  const seg = rope.segment, cMax = rope.bendCos, sMax = rope.bendSin, radius = rope.radius;
  let px = cur[0] - before[0], py = cur[1] - before[1], pz = cur[2] - before[2];
  const n = Math.sqrt(px * px + py * py + pz * pz);
  px = px / n; py = py / n; pz = pz / n;
  for (let j = 1; j < count; j++) {
    const a = 3 * (j - 1), b = 3 * j;
    let ux = cur[b] - cur[a], uy = cur[b + 1] - cur[a + 1], uz = cur[b + 2] - cur[a + 2];
    const dist = Math.sqrt(ux * ux + uy * uy + uz * uz);
    if (dist === 0) { ux = px; uy = py; uz = pz; } else { ux = ux / dist; uy = uy / dist; uz = uz / dist; }
    const c = ux * px + uy * py + uz * pz;
    if (c < cMax) {
      const wx = ux - c * px, wy = uy - c * py, wz = uz - c * pz;
      const wn = Math.sqrt(wx * wx + wy * wy + wz * wz);
      if (wn === 0) { ux = px; uy = py; uz = pz; } else {
        ux = cMax * px + sMax * (wx / wn);
        uy = cMax * py + sMax * (wy / wn);
        uz = cMax * pz + sMax * (wz / wn);
      }
    }
    cur[b] = cur[a] + seg * ux; cur[b + 1] = cur[a + 1] + seg * uy; cur[b + 2] = cur[a + 2] + seg * uz;
    if (ground) {
      toLocal(frame, cur, b, ropeLocal, 0);
      if (ropeLocal[1] < radius[j]) {
        toLocal(frame, cur, a, ropeLocal, 3);
        const dy = Math.min(seg, Math.max(-seg, radius[j] - ropeLocal[4]));
        let dx = ropeLocal[0] - ropeLocal[3], dz = ropeLocal[2] - ropeLocal[5];
        const flat = Math.sqrt(dx * dx + dz * dz);
        const wide = Math.sqrt(Math.max(seg * seg - dy * dy, 0));
        if (flat === 0) { dx = wide; dz = 0; } else { dx = dx * (wide / flat); dz = dz * (wide / flat); }
        ropeLocal[0] = ropeLocal[3] + dx; ropeLocal[1] = ropeLocal[4] + dy; ropeLocal[2] = ropeLocal[5] + dz;
        toWorld(frame, ropeLocal, 0, cur, b);
        ux = (cur[b] - cur[a]) / seg; uy = (cur[b + 1] - cur[a + 1]) / seg; uz = (cur[b + 2] - cur[a + 2]) / seg;
      }
    }
    px = ux; py = uy; pz = uz;
  }
}

/** The ropes' stage of one tick on the support frame (motion/ropes.py step_ropes): integrate (unless at
 * reset, where they start at rest), then pose the rope slots from the nodes. */
export function stepRopes(st, frame, integrate) {
  const m = st.data, d = st.d, c = m.constants, ground = m.ropeGround, root = st.root, grav = st.grav;
  const anchorLocal = st.anchorLocal, anchorWorld = st.anchorWorld, beforeWorld = st.beforeWorld, v3 = st.v3, w3 = st.w3;
  const quats = st.quats, trans = st.trans;
  if (!integrate) restNodes(st);
  // A constant provider (createGravity) was sampled once; any other is asked every tick.
  if (st.gravity.constant !== true) st.gravity.at(st.tick * d.dt, grav);
  const substeps = c.ropeSubsteps, passes = c.ropePasses, keep = 1 - c.ropeDamping;
  const h = d.dt / substeps;
  const gx = grav[0] * h * h, gy = grav[1] * h * h, gz = grav[2] * h * h;
  for (let r = 0; r < m.ropes.length; r++) {
    const rope = m.ropes[r];
    const cur = st.nodes[r], prev = st.prevNodes[r];
    const count = rope.rest.length;
    anchorPoint(st, rope, 0, anchorLocal, 0);
    toWorldRoot(root, anchorLocal, 0, anchorWorld, 0);
    const seg = rope.segment, radius = rope.radius;
    const bf = rope.before;
    rotate(quats, 4 * rope.parent, bf, 0, v3, 0);
    const bp = 3 * rope.parent;
    v3[0] = v3[0] + trans[bp]; v3[1] = v3[1] + trans[bp + 1]; v3[2] = v3[2] + trans[bp + 2];
    toWorldRoot(root, v3, 0, beforeWorld, 0);
    if (integrate) {
      for (let sub = 0; sub < substeps; sub++) {
        for (let k = 0; k < 3; k++) { cur[k] = anchorWorld[k]; prev[k] = anchorWorld[k]; }
        for (let j = 1; j < count; j++) {
          const o = 3 * j;
          const x0 = cur[o], x1 = cur[o + 1], x2 = cur[o + 2];
          const vx = (x0 - prev[o]) * keep, vy = (x1 - prev[o + 1]) * keep, vz = (x2 - prev[o + 2]) * keep;
          prev[o] = x0; prev[o + 1] = x1; prev[o + 2] = x2;
          cur[o] = x0 + vx + gx; cur[o + 1] = x1 + vy + gy; cur[o + 2] = x2 + vz + gz;
        }
        for (let pass = 0; pass < passes; pass++) {
          for (let j = 0; j < count - 1; j++) {
            const a = 3 * j, b = a + 3;
            const dx = cur[b] - cur[a], dy = cur[b + 1] - cur[a + 1], dz = cur[b + 2] - cur[a + 2];
            const dist = Math.sqrt(dx * dx + dy * dy + dz * dz);
            if (dist === 0) continue;
            const f = (dist - seg) / dist;
            if (j === 0) {
              cur[b] = cur[b] - dx * f; cur[b + 1] = cur[b + 1] - dy * f; cur[b + 2] = cur[b + 2] - dz * f;
            } else {
              const hf = 0.5 * f;
              cur[a] = cur[a] + dx * hf; cur[a + 1] = cur[a + 1] + dy * hf; cur[a + 2] = cur[a + 2] + dz * hf;
              cur[b] = cur[b] - dx * hf; cur[b + 1] = cur[b + 1] - dy * hf; cur[b + 2] = cur[b + 2] - dz * hf;
            }
          }
          bend(cur, count, beforeWorld, rope);
          if (ground) {
            for (let j = 1; j < count; j++) {
              toLocal(frame, cur, 3 * j, w3, 0);
              if (w3[1] < radius[j]) { w3[1] = radius[j]; toWorld(frame, w3, 0, cur, 3 * j); }
            }
          }
        }
        follow(st, cur, count, beforeWorld, rope, frame);
      }
    }
    poseRope(st, rope, cur, anchorLocal);
  }
}

/** The rope's slots from its world nodes `cur`, and the anchor gate: the posed anchor of segment 0
 * against `anchorLocal`, the body's (motion/ropes.py pose_rope). */
export function poseRope(st, rope, cur, anchorLocal) {
  const quats = st.quats, trans = st.trans, localNodes = st.localNodes, root = st.root, gv = st.gates;
  const n3 = st.n3, e0 = st.e0, e1 = st.e1, q = st.q, turned = st.turned;
  const count = rope.rest.length;
  for (let j = 0; j < count; j++) toLocalRoot(root, cur, 3 * j, localNodes, 3 * j);
  const rest = rope.rest;
  // Segment frames by parallel transport down the chain: each turns by the bend from the one before, the
  // first from its parent's, so the twist is continuous and well conditioned.
  n3[0] = rest[1][0] - rest[0][0]; n3[1] = rest[1][1] - rest[0][1]; n3[2] = rest[1][2] - rest[0][2];
  normalizeInto(n3, 0, e1, 0);
  rotate(quats, 4 * rope.parent, e1, 0, e0, 0);
  let prevSlot = rope.parent;
  for (let j = 0; j < rope.slots.length; j++) {
    const slot = rope.slots[j];
    const a = rest[j];
    const o = 3 * j;
    n3[0] = localNodes[o + 3] - localNodes[o]; n3[1] = localNodes[o + 4] - localNodes[o + 1]; n3[2] = localNodes[o + 5] - localNodes[o + 2];
    normalizeInto(n3, 0, e1, 0);
    fromTo(e0, 0, e1, 0, q, 0);
    mul(q, 0, quats, 4 * prevSlot, quats, 4 * slot);
    prevSlot = slot;
    e0[0] = e1[0]; e0[1] = e1[1]; e0[2] = e1[2];
    rotate(quats, 4 * slot, a, 0, turned, 0);
    trans[3 * slot] = localNodes[o] - turned[0]; trans[3 * slot + 1] = localNodes[o + 1] - turned[1]; trans[3 * slot + 2] = localNodes[o + 2] - turned[2];
  }
  const s0 = rope.slots[0];
  rotate(quats, 4 * s0, rest[0], 0, turned, 0);
  const ex = turned[0] + trans[3 * s0] - anchorLocal[0], ey = turned[1] + trans[3 * s0 + 1] - anchorLocal[1];
  const ez = turned[2] + trans[3 * s0 + 2] - anchorLocal[2];
  const err = Math.sqrt(ex * ex + ey * ey + ez * ez);
  gv[G.ropeAnchor] = Math.max(gv[G.ropeAnchor], err / st.data.bodyScale);
}
