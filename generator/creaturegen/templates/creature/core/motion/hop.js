// The hop (creaturegen's Python reference: motion/hop.py): a hopper's root in closed form (idle, crouch,
// air, landing), its gates, and its two legs.
// The root's height over a hop cycle is known in closed form, so the apex is checked against it every
// cycle (a hopper on legs also sinks on them in the crouch and the landing, by the derived dip). A hopper's
// legs plant, push off, tuck and land together (not by phase group as a walker's, gait.js); they share the
// walker's leg placement (gait.js placeLeg).

import { countPlanted, home, placeLeg } from './gait.js';
import { toWorld } from './providers.js';
import { toLocalRoot } from './root.js';
import { G } from './state.js';
import { sincos } from './trig.js';

/** (distance along the path, height above the support, squash) of the hopper at tick n into out[0..2]. In
 * the crouch and the landing a hopper on legs also sinks on them (d.dip, 0 without legs). */
export function hopAt(st, n, out) {
  const m = st.data, d = st.d, sc = st.sc;
  const c = m.constants;
  const hopLength = m.speed > 0 ? m.hopLength : 0;
  const k = Math.floor(n / d.hopCycle);
  let r = n % d.hopCycle;
  if (r < d.hopIdle) { out[0] = k * hopLength; out[1] = 0; out[2] = 1; return; }
  r -= d.hopIdle;
  if (r < d.crouch) {
    sc[2] = Math.PI * (r / d.crouch);
    sincos(sc, 2, sc, 0);
    out[0] = k * hopLength; out[1] = 0 - d.dip * sc[0]; out[2] = 1 - c.hopSquash * sc[0]; return;
  }
  r -= d.crouch;
  if (r < d.air) {
    const ts = r * d.dt;
    const tau = r / d.air;
    const e = 2 * tau - 1;
    out[0] = k * hopLength + hopLength * tau;
    out[1] = d.v0 * ts - 0.5 * d.g * ts * ts;
    out[2] = 1 + c.hopStretch * (e * e);
    return;
  }
  r -= d.air;
  sc[2] = Math.PI * (r / d.land);
  sincos(sc, 2, sc, 0);
  out[0] = (k + 1) * hopLength; out[1] = 0 - d.dip * sc[0]; out[2] = 1 - c.hopSquash * sc[0];
}

/** The squash's determinant every tick, and the height at the apex tick against the closed form. */
export function hopGates(st, n, root) {
  const d = st.d, gv = st.gates, hopOut = st.hopOut;
  const squash = root[5];
  const k = 1 / Math.sqrt(squash);
  gv[G.squashDet] = Math.max(gv[G.squashDet], Math.abs(k * squash * k - 1));
  if (n % d.hopCycle === d.hopIdle + d.crouch + d.halfAir) {
    hopAt(st, n, hopOut);
    gv[G.apexError] = Math.max(gv[G.apexError], Math.abs(hopOut[1] - d.apex));
    gv[G.apexSquash] = squash;
  }
}

/** A hopper's two hind legs, together (motion/hop.py hop_legs): planted while the body is on the support
 * (idle, crouch, landing); from the first air tick each foot leaves its take-off plant (swingFrom), is drawn
 * up toward its hip (leg.tuck) at the apex and reaches for its landing plant (swingTo: the rest foot under
 * the root at the landing tick). The target blends the two (smoothstep) in the creature frame, pulled
 * toward the tuck by (4τ(1 − τ))². */
export function hopLegs(st, n, frame, integrate) {
  const m = st.data, d = st.d, gv = st.gates, root = st.root;
  const planted = st.planted, plant = st.plant, swingFrom = st.swingFrom, swingTo = st.swingTo, liftTick = st.liftTick;
  const atHome = st.atHome, ahead = st.ahead, target = st.target, airFrom = st.airFrom, airTo = st.airTo, v3 = st.v3;
  const L = m.legs.length;
  const r = n % d.hopCycle;
  const airborne = d.hopIdle + d.crouch <= r && r < d.hopIdle + d.crouch + d.air;
  let swinging = 0;
  for (let i = 0; i < L; i++) {
    const leg = m.legs[i];
    const o = 3 * i;
    if (!integrate) {
      planted[i] = 1;
      home(st, leg, frame, root, atHome);
      plant[o] = atHome[0]; plant[o + 1] = atHome[1]; plant[o + 2] = atHome[2];
    } else if (planted[i] && airborne) {
      planted[i] = 0; liftTick[i] = n;
      swingFrom[o] = plant[o]; swingFrom[o + 1] = plant[o + 1]; swingFrom[o + 2] = plant[o + 2];
      st.rootAt(st, n + d.air, st.frame2, st.root2);
      home(st, leg, st.frame2, st.root2, ahead);
      swingTo[o] = ahead[0]; swingTo[o + 1] = ahead[1]; swingTo[o + 2] = ahead[2];
      gv[G.steps] += 1;
    } else if (!planted[i] && !airborne) {
      planted[i] = 1; plant[o] = swingTo[o]; plant[o + 1] = swingTo[o + 1]; plant[o + 2] = swingTo[o + 2];
    }
    if (planted[i]) {
      toWorld(frame, plant, o, v3, 0);
      toLocalRoot(root, v3, 0, target, 0);
    } else {
      swinging += 1;
      const tau = (n - liftTick[i]) / d.air;
      const sigma = tau * tau * (3 - 2 * tau);
      const arc = 4 * tau * (1 - tau);
      const pull = arc * arc;
      toWorld(frame, swingFrom, o, v3, 0);
      toLocalRoot(root, v3, 0, airFrom, 0);
      toWorld(frame, swingTo, o, v3, 0);
      toLocalRoot(root, v3, 0, airTo, 0);
      const hip = leg.hip, rest = leg.foot, tuck = leg.tuck;
      for (let k = 0; k < 3; k++) {
        const base = airFrom[k] + (airTo[k] - airFrom[k]) * sigma;
        const tucked = hip[k] + (rest[k] - hip[k]) * tuck;
        target[k] = base + (tucked - base) * pull;
      }
    }
    placeLeg(st, leg, i, target, frame);
  }
  countPlanted(st, swinging);
}
