// Analytic two-bone IK (creaturegen's Python reference: motion/ik.py): law of cosines, a scale-derived reach
// clamp and a Gram-Schmidt bend hint. The knee lies in the plane of the hip→target direction and the leg's
// rest bend hint, so the solution is a pure function of the target (no solver state, no iteration). It is
// written as two rigid slot transforms (thigh about the hip, shin about the knee) built from rest and posed
// orthonormal frames: the bone direction and the knee's hinge axis. Shared by the walker's and the
// hopper's legs (gait.js placeLeg).

import { fromFrames, gramSchmidt, normalizeInto, rotate } from './quat.js';

/** Two-bone IK of `leg` toward t[0..2] (creature frame) into the leg's slots (motion/ik.py solve_leg); the
 * state's `ik` gets the knee (0..2), the foot (3..5), clamped (6) and the residual (7). */
export function solveLeg(st, leg, t) {
  const quats = st.quats, trans = st.trans, turned = st.turned, frames = st.frames, ik = st.ik;
  const u3 = st.u3, w3 = st.w3, n3 = st.n3, hinge1 = st.hinge1;
  const hip = leg.hip, knee0 = leg.knee, foot0 = leg.foot, hint = leg.hint, a = leg.a, b = leg.b;
  const dx = t[0] - hip[0], dy = t[1] - hip[1], dz = t[2] - hip[2];
  const dist = Math.sqrt(dx * dx + dy * dy + dz * dz);
  let ux = 0, uy = -1, uz = 0;
  if (dist !== 0) { ux = dx / dist; uy = dy / dist; uz = dz / dist; }
  const reach = Math.min(Math.max(dist, leg.reachMin), leg.reachMax);
  u3[0] = ux; u3[1] = uy; u3[2] = uz;
  gramSchmidt(hint, 0, u3, 0, w3, 0);
  let cosA = (a * a + reach * reach - b * b) / (2 * a * reach);
  cosA = Math.min(Math.max(cosA, -1), 1);
  const sinA = Math.sqrt(1 - cosA * cosA);
  const kx = hip[0] + a * (cosA * ux + sinA * w3[0]);
  const ky = hip[1] + a * (cosA * uy + sinA * w3[1]);
  const kz = hip[2] + a * (cosA * uz + sinA * w3[2]);
  const fx = hip[0] + reach * ux, fy = hip[1] + reach * uy, fz = hip[2] + reach * uz;
  // Frames: the bone and the knee's hinge axis (rest: leg.hinge; posed: u × v), motion/ik.py.
  const h0 = leg.hinge;
  n3[0] = uy * w3[2] - uz * w3[1]; n3[1] = uz * w3[0] - ux * w3[2]; n3[2] = ux * w3[1] - uy * w3[0];
  normalizeInto(n3, 0, hinge1, 0);
  // thigh: rest frame (0..5), posed frame (6..11)
  n3[0] = knee0[0] - hip[0]; n3[1] = knee0[1] - hip[1]; n3[2] = knee0[2] - hip[2];
  normalizeInto(n3, 0, frames, 0);
  gramSchmidt(h0, 0, frames, 0, frames, 3);
  n3[0] = kx - hip[0]; n3[1] = ky - hip[1]; n3[2] = kz - hip[2];
  normalizeInto(n3, 0, frames, 6);
  gramSchmidt(hinge1, 0, frames, 6, frames, 9);
  const up = leg.upper, lo = leg.lower;
  fromFrames(frames, quats, 4 * up);
  rotate(quats, 4 * up, hip, 0, turned, 0);
  trans[3 * up] = hip[0] - turned[0]; trans[3 * up + 1] = hip[1] - turned[1]; trans[3 * up + 2] = hip[2] - turned[2];
  n3[0] = foot0[0] - knee0[0]; n3[1] = foot0[1] - knee0[1]; n3[2] = foot0[2] - knee0[2];
  normalizeInto(n3, 0, frames, 0);
  gramSchmidt(h0, 0, frames, 0, frames, 3);
  n3[0] = fx - kx; n3[1] = fy - ky; n3[2] = fz - kz;
  normalizeInto(n3, 0, frames, 6);
  gramSchmidt(hinge1, 0, frames, 6, frames, 9);
  fromFrames(frames, quats, 4 * lo);
  rotate(quats, 4 * lo, knee0, 0, turned, 0);
  trans[3 * lo] = kx - turned[0]; trans[3 * lo + 1] = ky - turned[1]; trans[3 * lo + 2] = kz - turned[2];
  ik[0] = kx; ik[1] = ky; ik[2] = kz; ik[3] = fx; ik[4] = fy; ik[5] = fz;
  ik[6] = reach !== dist ? 1 : 0;
  // Lengths as quat.norm3 in Python, sqrt((x² + y²) + z²), written inline: a call returning a double that
  // V8 does not inline boxes it.
  const tx = kx - hip[0], ty = ky - hip[1], tz = kz - hip[2];
  const sx = fx - kx, sy = fy - ky, sz = fz - kz;
  const thigh = Math.sqrt(tx * tx + ty * ty + tz * tz);
  const shin = Math.sqrt(sx * sx + sy * sy + sz * sz);
  ik[7] = Math.max(Math.abs(thigh - a), Math.abs(shin - b)) / (a + b);
}
