// Swimming (creaturegen's Python reference: motion/swim.py): a swimmer follows the water's free surface at
// its buoyancy depth, and undulates.
// Stage 1 of a tick (motion.js) for a swimmer: its height is not closed form but a critically damped
// response (at swimResponse·√(g/L) rad/s, derived.js) toward the injected water's free surface less its
// depth, integrated tick by tick; a material current, where the water represents one, carries its path's
// centre. Stage 2 (the base pose): an undulation about Y at every skeleton root, at the Strouhal frequency.

import { axisAngle } from './quat.js';
import { path } from './root.js';
import { G } from './state.js';
import { sincos } from './trig.js';

/** The swimmer's height and vertical speed at tick n (set on the target at reset), the current's drift
 * of its path, and the tracking gate after 2 s (motion/swim.py follow_surface). */
export function followSurface(st, n, integrate) {
  const m = st.data, d = st.d;
  const swim = st.swim, sample = st.sample, onPath = st.onPath, query = st.query, centre = st.centre, gv = st.gates;
  const time = n * d.dt;
  st.dist1[0] = m.speed * time;
  path(st, st.dist1, onPath);
  query[0] = onPath[0]; query[1] = onPath[1]; query[2] = time;
  st.water.sample(query, sample);
  const eta = sample.freeSurfacePoint[1];
  const tgt = eta - d.swimDepth - m.centreY;
  const tv = sample.geometricNormalVelocityMps[0] / sample.freeSurfaceNormal[1];
  if (!integrate) { swim[0] = tgt; swim[1] = tv; }
  else {
    const om = d.swimOmega;
    const acc = om * om * (tgt - swim[0]) + 2 * om * (tv - swim[1]);
    swim[1] = swim[1] + acc * d.dt;
    swim[0] = swim[0] + swim[1] * d.dt;
  }
  if (st.hasCurrent) {
    centre[0] = centre[0] + sample.materialCurrentVelocityMps[0] * d.dt;
    centre[2] = centre[2] + sample.materialCurrentVelocityMps[2] * d.dt;
  }
  if (time >= 2) gv[G.swimTracking] = Math.max(gv[G.swimTracking], Math.abs(swim[0] - tgt));
}

/** A swimmer's local rotations at tick n into the state's `locals` (marked in `hasLocal`): its undulation
 * at the roots (motion/swim.py undulation_locals). */
export function undulationLocals(st, n) {
  const m = st.data, d = st.d;
  const locals = st.locals, hasLocal = st.hasLocal, sc = st.sc, axis4 = st.axis4;
  const time = n * d.dt;
  sc[2] = 2 * Math.PI * d.undulationHz * time;
  sincos(sc, 2, sc, 0);
  const angle = m.undulation * sc[0];
  axis4[0] = 0; axis4[1] = 1; axis4[2] = 0; axis4[3] = angle;
  for (let i = 0; i < m.roots.length; i++) { const r = m.roots[i]; axisAngle(axis4, 0, locals, 4 * r); hasLocal[r] = 1; }
}
