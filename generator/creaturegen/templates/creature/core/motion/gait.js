// The legged gait of a walker (creaturegen's Python reference: motion/gait.py): feet planted in the support
// frame, lifted by phase group.
// Stage 3 of a tick (motion.js): the gait plants feet in the support frame → world target → inverse root
// transform → body-frame IK → creature-local leg slots. A planted foot stays where it landed in the support
// frame; it lifts when it lags stepLength behind its home (the rest foot under the root) and its group's
// lift window is open, and lands stepLead·stepLength ahead of where its home will be when the swing ends.
// One phase group swings at a time, so the other groups' feet stay down. The leg placement (IK and the leg
// gates) is shared with the hopper's legs (hop.js).

import { solveLeg } from './ik.js';
import { toLocal, toWorld } from './providers.js';
import { rotate } from './quat.js';
import { path, toLocalRoot, toWorldRoot } from './root.js';
import { G } from './state.js';
import { sincos } from './trig.js';

/** Support-local home of a foot into `out`: the rest foot of `leg` under root r, on the support frame f. */
export function home(st, leg, f, r, out) {
  const v3 = st.v3;
  toWorldRoot(r, leg.foot, 0, v3, 0);
  toLocal(f, v3, 0, out, 0);
  out[1] = 0;
}

/** Where a steady gait would have foot i at tick 0, into its plant: group g last landed
 * (cycle − swing − g·W) ticks of travel ago at stepLead·s ahead of its home, so every group lifts as its
 * window opens (motion/gait.py initial_plant). */
export function initialPlant(st, leg, i, frame) {
  const m = st.data, d = st.d;
  const atHome = st.atHome, plant = st.plant, sc = st.sc, onPath = st.onPath;
  home(st, leg, frame, st.root, atHome);
  if (m.speed <= 0) { plant[3 * i] = atHome[0]; plant[3 * i + 1] = 0; plant[3 * i + 2] = atHome[2]; return; }
  const lead = m.constants.stepLead * m.stepLength;
  const back = m.speed * d.dt * (d.cycle - d.swing - leg.group * d.window);
  st.dist1[0] = 0;
  path(st, st.dist1, onPath);
  sincos(onPath, 2, sc, 0);
  const offset = lead - back;
  plant[3 * i] = atHome[0] + sc[0] * offset; plant[3 * i + 1] = 0; plant[3 * i + 2] = atHome[2] + sc[1] * offset;
}

/** Tick n of a walker's legs on the support frame: plant, lift or swing each foot, then place its leg. */
export function walk(st, n, frame, integrate) {
  const m = st.data, d = st.d, gv = st.gates;
  const planted = st.planted, plant = st.plant, swingFrom = st.swingFrom, swingTo = st.swingTo, liftTick = st.liftTick;
  const atHome = st.atHome, ahead = st.ahead, local = st.local, target = st.target, v3 = st.v3;
  const L = m.legs.length;
  const stepLength = m.stepLength;
  const lead = m.constants.stepLead * stepLength;
  const phase = n % d.cycle;
  let swinging = 0;
  for (let i = 0; i < L; i++) {
    const leg = m.legs[i];
    const o = 3 * i;
    if (!integrate) { planted[i] = 1; initialPlant(st, leg, i, frame); }
    else if (!planted[i] && n - liftTick[i] >= d.swing) {
      planted[i] = 1; plant[o] = swingTo[o]; plant[o + 1] = swingTo[o + 1]; plant[o + 2] = swingTo[o + 2];
    }
    if (planted[i] && integrate) {
      home(st, leg, frame, st.root, atHome);
      let du = atHome[0] - plant[o], dw = atHome[2] - plant[o + 2];
      const lag = Math.sqrt(du * du + dw * dw);
      const k = phase - leg.group * d.window;
      if (lag > stepLength && k >= 0 && k <= d.window - d.swing) {
        st.rootAt(st, n + d.swing, st.frame2, st.root2);
        home(st, leg, st.frame2, st.root2, ahead);
        du = ahead[0] - plant[o]; dw = ahead[2] - plant[o + 2];
        const dl = Math.sqrt(du * du + dw * dw);
        planted[i] = 0; liftTick[i] = n;
        swingFrom[o] = plant[o]; swingFrom[o + 1] = plant[o + 1]; swingFrom[o + 2] = plant[o + 2];
        swingTo[o] = ahead[0]; swingTo[o + 1] = 0; swingTo[o + 2] = ahead[2];
        if (dl > 0) { swingTo[o] = ahead[0] + du / dl * lead; swingTo[o + 2] = ahead[2] + dw / dl * lead; }
        gv[G.steps] += 1;
      }
    }
    if (planted[i]) { local[0] = plant[o]; local[1] = plant[o + 1]; local[2] = plant[o + 2]; }
    else {
      swinging += 1;
      const tau = (n - liftTick[i]) / d.swing;
      const sigma = tau * tau * (3 - 2 * tau);
      local[0] = swingFrom[o] + (swingTo[o] - swingFrom[o]) * sigma;
      local[1] = m.stepHeight * (4 * tau * (1 - tau));
      local[2] = swingFrom[o + 2] + (swingTo[o + 2] - swingFrom[o + 2]) * sigma;
    }
    toWorld(frame, local, 0, v3, 0);
    toLocalRoot(st.root, v3, 0, target, 0);
    placeLeg(st, leg, i, target, frame);
  }
  countPlanted(st, swinging);
}

/** Two-bone IK of leg i toward `target` (creature frame) into its slots, and the leg gates: the IK
 * residual, the drawn foot against the IK foot, clamped ticks, and a planted foot's drift from its plant
 * on the support frame (motion/gait.py place_leg). */
export function placeLeg(st, leg, i, target, frame) {
  const gv = st.gates, quats = st.quats, trans = st.trans, ik = st.ik, v3 = st.v3, w3 = st.w3, n3 = st.n3, plant = st.plant;
  const o = 3 * i;
  solveLeg(st, leg, target);
  const span = leg.a + leg.b;
  gv[G.ikResidual] = Math.max(gv[G.ikResidual], ik[7]);
  rotate(quats, 4 * leg.lower, leg.foot, 0, v3, 0);
  const lo = 3 * leg.lower;
  const drawnX = v3[0] + trans[lo], drawnY = v3[1] + trans[lo + 1], drawnZ = v3[2] + trans[lo + 2];
  const ex = drawnX - ik[3], ey = drawnY - ik[4], ez = drawnZ - ik[5];
  gv[G.drawnFoot] = Math.max(gv[G.drawnFoot], Math.sqrt(ex * ex + ey * ey + ez * ez) / span);
  if (ik[6]) gv[G.clampedTicks] += 1;
  else if (st.planted[i]) {
    n3[0] = drawnX; n3[1] = drawnY; n3[2] = drawnZ;
    toWorldRoot(st.root, n3, 0, v3, 0);
    toLocal(frame, v3, 0, w3, 0);
    const px = w3[0] - plant[o], py = w3[1] - plant[o + 1], pz = w3[2] - plant[o + 2];
    gv[G.plantDrift] = Math.max(gv[G.plantDrift], Math.sqrt(px * px + py * py + pz * pz) / span);
    gv[G.plantedSamples] += 1;
  }
}

/** The stance gates of one tick, `swinging` feet in the air (motion/gait.py count_planted). */
export function countPlanted(st, swinging) {
  const gv = st.gates;
  const L = st.data.legs.length;
  if (L === 2 && swinging === 2) gv[G.bothSwingTicks] += 1;
  gv[G.fewestPlanted] = Math.min(gv[G.fewestPlanted], L - swinging);
}
