// The base pose (creaturegen's Python reference: motion/base_pose.py): per-slot local rotations composed
// down the skeleton.
// Stage 2 of a tick (motion.js): the flyer's bank and flap (flight.js) and the swimmer's undulation
// (swim.js), identity otherwise, composed from the roots down about each slot's pivot. The legs and ropes
// stages then overwrite their own slots (the last stage touching a slot wins).

import { wingLocals } from './flight.js';
import { mul, rotate } from './quat.js';
import { undulationLocals } from './swim.js';

/** Every slot's base pose at tick n into the state's quaternions and translations. */
export function basePose(st, n) {
  st.hasLocal.fill(0);
  if (st.kind === 'flyer') wingLocals(st, n);
  else if (st.kind === 'swimmer' && st.d.undulationHz > 0) undulationLocals(st, n);
  composeBase(st);
}

/** The state's local rotations (identity where `hasLocal` is 0) composed down the skeleton about the
 * pivots, into its quaternions and translations (motion/base_pose.py compose_base). */
export function composeBase(st) {
  const m = st.data;
  const locals = st.locals, hasLocal = st.hasLocal, quats = st.quats, trans = st.trans, turned = st.turned, v3 = st.v3;
  for (let k = 0; k < m.order.length; k++) {
    const s = m.order[k];
    if (!hasLocal[s]) { locals[4 * s] = 0; locals[4 * s + 1] = 0; locals[4 * s + 2] = 0; locals[4 * s + 3] = 1; }
    const pv = m.pivot[s];
    rotate(locals, 4 * s, pv, 0, turned, 0);
    const ax = pv[0] - turned[0], ay = pv[1] - turned[1], az = pv[2] - turned[2];
    const p = m.parent[s];
    if (p < 0) {
      quats[4 * s] = locals[4 * s]; quats[4 * s + 1] = locals[4 * s + 1]; quats[4 * s + 2] = locals[4 * s + 2]; quats[4 * s + 3] = locals[4 * s + 3];
      trans[3 * s] = ax; trans[3 * s + 1] = ay; trans[3 * s + 2] = az;
    } else {
      mul(quats, 4 * p, locals, 4 * s, quats, 4 * s);
      v3[0] = ax; v3[1] = ay; v3[2] = az;
      rotate(quats, 4 * p, v3, 0, turned, 0);
      trans[3 * s] = turned[0] + trans[3 * p]; trans[3 * s + 1] = turned[1] + trans[3 * p + 1]; trans[3 * s + 2] = turned[2] + trans[3 * p + 2];
    }
  }
}
