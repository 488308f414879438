// Flight (creaturegen's Python reference: motion/flight.py): a flyer circles its path at its altitude (in
// closed form, motion.js rootAt), banked into the turn, its wings flapping.
// Stage 2 of a tick (the base pose): the flyer's local rotations, a constant bank about Z at every skeleton
// root (the coordinated turn's, atan2(v², gR)) and a flap about Z at every wing, sign·amplitude·sin(2πft) at
// the Strouhal frequency (both derived.js); base-pose.js composes them down the skeleton.

import { axisAngle } from './quat.js';
import { sincos } from './trig.js';

/** A flyer's local rotations at tick n into the state's `locals` (marked in `hasLocal`): its bank at the
 * roots, its flap at the wings (motion/flight.py wing_locals). */
export function wingLocals(st, n) {
  const m = st.data, d = st.d;
  const locals = st.locals, hasLocal = st.hasLocal, sc = st.sc, axis4 = st.axis4;
  const time = n * d.dt;
  for (let i = 0; i < m.roots.length; i++) { const r = m.roots[i]; locals[4 * r] = 0; locals[4 * r + 1] = 0; locals[4 * r + 2] = d.bankHalfSin; locals[4 * r + 3] = d.bankHalfCos; hasLocal[r] = 1; }
  sc[2] = 2 * Math.PI * d.flapHz * time;
  sincos(sc, 2, sc, 0);
  const flap = sc[0];
  for (let i = 0; i < m.wings.length; i++) {
    const w = m.wings[i];
    axis4[0] = 0; axis4[1] = 0; axis4[2] = 1; axis4[3] = w.sign * w.amplitude * flap;
    axisAngle(axis4, 0, locals, 4 * w.slot); hasLocal[w.slot] = 1;
  }
}
