// The root: where the creature's body is on its circular path, how it stands on the support, and the
// transform between creature-local and world space (creaturegen's Python reference: motion/root.py).
// Stage 1 of a tick (motion.js): position, yaw and squash, in closed form for walkers, hoppers and flyers
// (the swimmer's vertical response is integrated, swim.js). The root is (x, y, z, cos yaw, sin yaw, squash);
// the squash scales the body by S = diag(1/√s, s, 1/√s), determinant 1.

import { toWorld } from './providers.js';
import { sincos } from './trig.js';

/** Support-local (u, w) and heading ψ on the circle after dv[0] metres, into out[0..2]. */
export function path(st, dv, out) {
  const radius = st.data.pathRadius;
  const sc = st.sc, centre = st.centre;
  sc[2] = st.theta0 + dv[0] / radius;
  sincos(sc, 2, sc, 0);
  out[0] = centre[0] + radius * sc[1];
  out[1] = centre[2] + radius * sc[0];
  out[2] = -sc[2];
}

/** How far the upright body sinks on a tilted support (heading c, s = hs[0], hs[1]) into hs[2]: halfway
 * between its lowest and highest rest foot, within constants.settleSlack of the legs' room to full
 * extension (motion/root.py settle). */
export function settle(st, f, hs) {
  const m = st.data;
  const L = m.legs.length;
  const c = hs[0], s = hs[1];
  const ny = f[7];
  let lowest = 0, highest = 0, room = Infinity;
  for (let i = 0; i < L; i++) {
    const leg = m.legs[i];
    const ft = leg.foot, hp = leg.hip;
    const rx = c * ft[0] + s * ft[2];
    const rz = -s * ft[0] + c * ft[2];
    const dy = -(f[6] * rx + f[8] * rz) / ny;
    if (dy < lowest) lowest = dy;
    if (dy > highest) highest = dy;
    const ex = hp[0] - ft[0], ey = hp[1] - ft[1], ez = hp[2] - ft[2];
    const spare = leg.reachMax - Math.sqrt(ex * ex + ey * ey + ez * ez);
    if (spare < room) room = spare;
  }
  hs[2] = lowest + Math.min(0.5 * (highest - lowest), m.constants.settleSlack * Math.max(room, 0));
}

/** Root (x, y, z, cos yaw, sin yaw, squash) into `out` on the support f at (u, w) = p[0], p[1], heading
 * ψ = p[2] in its plane; ls = (lift, squash). */
export function grounded(st, f, p, ls, out) {
  const m = st.data;
  const g3 = st.g3, v3 = st.v3, sc = st.sc;
  const psi = p[2], squash = ls[1];
  let lift = ls[0];
  g3[0] = p[0]; g3[1] = 0; g3[2] = p[1];
  toWorld(f, g3, 0, v3, 0);
  sincos(p, 2, sc, 0);
  const sp = sc[0], cp = sc[1];
  const fx = sp * f[3] + cp * f[9];
  const fz = sp * f[5] + cp * f[11];
  const norm = Math.sqrt(fx * fx + fz * fz);
  const c = fz / norm, s = fx / norm;
  if (m.legs.length) { sc[0] = c; sc[1] = s; settle(st, f, sc); lift = lift + sc[2]; }
  out[0] = v3[0]; out[1] = v3[1] + lift - m.groundY * squash; out[2] = v3[2]; out[3] = c; out[4] = s; out[5] = squash;
}

/** Creature-local x[xo..xo+2] → world, into out[o..o+2]: p + R_yaw(S·x), S = diag(1/√s, s, 1/√s), root r. */
export function toWorldRoot(r, x, xo, out, o) {
  const x0 = x[xo], x1 = x[xo + 1], x2 = x[xo + 2];
  const c = r[3], s = r[4], squash = r[5];
  const k = 1 / Math.sqrt(squash);
  const vx = x0 * k, vy = x1 * squash, vz = x2 * k;
  out[o] = r[0] + (c * vx + s * vz);
  out[o + 1] = r[1] + vy;
  out[o + 2] = r[2] + (-s * vx + c * vz);
}

/** World x[xo..xo+2] → creature-local, into out[o..o+2]: the inverse of toWorldRoot. */
export function toLocalRoot(r, x, xo, out, o) {
  const x0 = x[xo], x1 = x[xo + 1], x2 = x[xo + 2];
  const c = r[3], s = r[4], squash = r[5];
  const vx = x0 - r[0], vy = x1 - r[1], vz = x2 - r[2];
  const sq = Math.sqrt(squash);
  out[o] = (c * vx - s * vz) * sq;
  out[o + 1] = vy / squash;
  out[o + 2] = (s * vx + c * vz) * sq;
}
