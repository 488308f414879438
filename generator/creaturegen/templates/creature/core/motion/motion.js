// One creature's locomotion in float64, tick by tick: the same formulas in the same order as creaturegen's
// Python reference (motion/simulate.py, Motion). Order of writes per tick (the last stage touching a slot
// wins):
//   1. root: position, yaw and squash (closed form for walkers, hoppers and flyers; the swimmer's vertical
//      response is integrated): root.js, hop.js, swim.js;
//   2. base pose: per-slot local rotations composed down the skeleton (flyer bank and flap, swimmer
//      undulation; identity otherwise): base-pose.js, flight.js, swim.js;
//   3. legs: plant in the support frame → world target → inverse root transform → body-frame IK →
//      creature-local leg slots (a hopper's two legs plant together on the ground and tuck in the air):
//      gait.js, ik.js, hop.js;
//   4. ropes: fixed-step verlet in world space, the anchor following the posed body, written last: ropes.js.
// createMotion makes the state (state.js) and composes the stages, each a function of that state.
// Integer ticks are authoritative: seekTick(n) resets and steps n times, so it equals n step() calls bit
// for bit. Nothing allocates after createMotion (typed scratch only); the only variation is the seeded LCG.

import { drawGenome, express, individualSize } from '../genome.js';
import { instanceYaw } from '../lcg.js';
import { hashBytes } from '../hash.js';
import { basePose } from './base-pose.js';
import { derive } from './derived.js';
import { walk } from './gait.js';
import { hopAt, hopGates, hopLegs } from './hop.js';
import { SWIMMER_CHANNELS, createFlatGround, createGravity, toWorld } from './providers.js';
import { stepRopes } from './ropes.js';
import { grounded, path } from './root.js';
import { createState, readGates, resetGates } from './state.js';
import { followSurface } from './swim.js';
import { sincos } from './trig.js';

// The walking locomotion types (creaturegen spec/character.py WALKERS): one gait, any even leg count 2..8.
const WALKERS = ['biped', 'quadruped', 'hexapod', 'octopod', 'walker'];

export class TierRefusedError extends Error {}

/** Throws TierRefusedError unless a swimmer has a water provider representing every channel it reads
 * (absent channels are absent, never zero); `who` names the caller in the message. */
export function assertWaterFor(kind, water, who = kind) {
  if (kind !== 'swimmer') return;
  if (!water) throw new TierRefusedError(`${who}: no WaterSurfaceProvider was injected`);
  const missing = SWIMMER_CHANNELS.filter((c) => !water.channels.includes(c));
  if (missing.length) throw new TierRefusedError(`${who}: the water provider does not represent ${missing.join(', ')}`);
}

export function createMotion(data, lcg, { support = createFlatGround(), gravity = createGravity(), water = null, seed = 0, position = [0, 0, 0], genome = null } = {}) {
  // The individual's motion data: the authored parameters scaled by its size and gait genes (the seed's,
  // unless a genome is given). Its size also scales its rest geometry (core/pose.js writePoseRows).
  const genes = genome ?? drawGenome(seed, lcg);
  const size = individualSize(data, genes);
  const m = express(data, genes);
  const kind = m.type;
  assertWaterFor(kind, water);
  const gravity0 = gravity.at(0, new Float64Array(3));
  const d = derive(m, gravity0);
  const theta0 = -instanceYaw(seed, lcg);
  const st = createState({
    data: m, d, kind, size, isWalker: WALKERS.includes(kind), support, gravity, water, gravity0, theta0, position, rootAt,
  });
  const motion = {
    data: m, derived: d, kind, size, quats: st.quats, trans: st.trans, root: st.root,
    prevQuats: st.prevQuats, prevTrans: st.prevTrans, prevRoot: st.prevRoot, nodes: st.nodes, support, gravity, water,
    /** Worst values since reset (allocates a plain object). */
    get gates() { return readGates(st); },
    get tick() { return st.tick; },
    reset() { resetState(st); },
    step() { stepState(st); },
    stepTicks(n = 1) { for (let k = 0; k < n; k++) motion.step(); },
    seekTick(n) {
      if (!Number.isInteger(n) || n < 0) throw new Error(`seekTick: a non-negative integer (got ${n})`);
      resetState(st);
      motion.stepTicks(n);
    },
    renderPose(alpha, outQuats, outTrans, outRoot) { renderPose(st, alpha, outQuats, outTrans, outRoot); },
    feet(out) { return feet(st, out); },
    stateVector() { return stateVector(st); },
    stateHash() { return stateHash(st, motion.stateVector()); },
  };
  resetState(st);
  return motion;
}

// --- one tick --------------------------------------------------------------------------------------------

/** Support frame (into f) and root (x, y, z, cos yaw, sin yaw, squash; into out) at tick n. The state's
 * `rootAt`: gait.js and hop.js ask it where a lifting foot's home will be when it lands. */
function rootAt(st, n, f, out) {
  const m = st.data, kind = st.kind;
  const dist1 = st.dist1, onPath = st.onPath, sc = st.sc;
  const time = n * st.d.dt;
  // A static support (flat ground, the slope) was sampled once; a moving one is asked every tick.
  if (st.support.static === true) f.set(st.staticFrame);
  else st.support.frame(time, f);
  dist1[0] = m.speed * time;
  if (st.isWalker) {
    path(st, dist1, onPath);
    grounded(st, f, onPath, st.level, out);
  } else if (kind === 'hopper') {
    hopAt(st, n, st.hopOut);
    path(st, st.hopOut, onPath);
    grounded(st, f, onPath, st.hopLift, out);
  } else if (kind === 'flyer') {
    path(st, dist1, onPath);
    sincos(onPath, 2, sc, 0);
    out[0] = onPath[0]; out[1] = m.altitude - m.groundY; out[2] = onPath[1]; out[3] = sc[1]; out[4] = sc[0]; out[5] = 1;
  } else if (kind === 'swimmer') {
    path(st, dist1, onPath);
    sincos(onPath, 2, sc, 0);
    out[0] = onPath[0]; out[1] = st.swim[0]; out[2] = onPath[1]; out[3] = sc[1]; out[4] = sc[0]; out[5] = 1;
  } else {
    const still = st.still, pos = st.position;
    still[0] = pos[0]; still[1] = pos[2]; still[2] = -st.theta0;
    grounded(st, f, still, st.level, out);
  }
}

/** Tick n: the stages in order, each writing the state (`integrate` false at reset). */
function update(st, n, integrate) {
  const kind = st.kind;
  if (kind === 'swimmer') followSurface(st, n, integrate);
  rootAt(st, n, st.frame, st.root);
  if (kind === 'hopper') hopGates(st, n, st.root);
  basePose(st, n);
  if (st.data.legs.length) {
    if (kind === 'hopper') hopLegs(st, n, st.frame, integrate);
    else walk(st, n, st.frame, integrate);
  }
  if (st.data.ropes.length) stepRopes(st, st.frame, integrate);
}

/** Back to tick 0: the path's centre from the spawn position, feet planted, the swimmer at rest, gates
 * cleared; then tick 0 (the ropes start at rest), which is also the previous step. */
function resetState(st) {
  const radius = st.data.pathRadius;
  const sc = st.sc, centre = st.centre, pos = st.position;
  sc[2] = st.theta0;
  sincos(sc, 2, sc, 0);
  centre[0] = pos[0] - radius * sc[1];
  centre[1] = pos[1];
  centre[2] = pos[2] - radius * sc[0];
  st.tick = 0;
  st.planted.fill(1); st.plant.fill(0); st.swingFrom.fill(0); st.swingTo.fill(0); st.liftTick.fill(0);
  st.swim.fill(0);
  resetGates(st);
  update(st, 0, false);
  st.prevQuats.set(st.quats); st.prevTrans.set(st.trans); st.prevRoot.set(st.root);
}

/** One fixed step: the current pose becomes the previous one, then the next tick. */
function stepState(st) {
  st.prevQuats.set(st.quats); st.prevTrans.set(st.trans); st.prevRoot.set(st.root);
  st.tick += 1;
  update(st, st.tick, true);
}

// --- output ----------------------------------------------------------------------------------------------

/** The render pose between the previous and the current fixed step (motion/driver.py): position and
 * squash lerped, heading (cos, sin) lerped and renormalised, quaternions nlerped on the previous one's
 * hemisphere. */
function renderPose(st, alpha, outQuats, outTrans, outRoot) {
  const quats = st.quats, trans = st.trans, root = st.root, prevQuats = st.prevQuats, prevTrans = st.prevTrans, prevRoot = st.prevRoot;
  const S = st.data.parent.length;
  const c = prevRoot[3] + (root[3] - prevRoot[3]) * alpha;
  const s = prevRoot[4] + (root[4] - prevRoot[4]) * alpha;
  const n = Math.sqrt(c * c + s * s);
  outRoot[0] = prevRoot[0] + (root[0] - prevRoot[0]) * alpha;
  outRoot[1] = prevRoot[1] + (root[1] - prevRoot[1]) * alpha;
  outRoot[2] = prevRoot[2] + (root[2] - prevRoot[2]) * alpha;
  outRoot[3] = c / n;
  outRoot[4] = s / n;
  outRoot[5] = prevRoot[5] + (root[5] - prevRoot[5]) * alpha;
  for (let s = 0; s < S; s++) {
    const o = 4 * s;
    const sign = prevQuats[o] * quats[o] + prevQuats[o + 1] * quats[o + 1] + prevQuats[o + 2] * quats[o + 2] + prevQuats[o + 3] * quats[o + 3] < 0 ? -1 : 1;
    const x = prevQuats[o] + (sign * quats[o] - prevQuats[o]) * alpha;
    const y = prevQuats[o + 1] + (sign * quats[o + 1] - prevQuats[o + 1]) * alpha;
    const z = prevQuats[o + 2] + (sign * quats[o + 2] - prevQuats[o + 2]) * alpha;
    const w = prevQuats[o + 3] + (sign * quats[o + 3] - prevQuats[o + 3]) * alpha;
    const n = Math.sqrt(x * x + y * y + z * z + w * w);
    outQuats[o] = x / n; outQuats[o + 1] = y / n; outQuats[o + 2] = z / n; outQuats[o + 3] = w / n;
    for (let k = 0; k < 3; k++) outTrans[3 * s + k] = prevTrans[3 * s + k] + (trans[3 * s + k] - prevTrans[3 * s + k]) * alpha;
  }
}

/** Each leg's plant point in world space at the current tick and whether it is planted: (x, y, z, planted)
 * per leg into `out` (4 × legs numbers). A read accessor for markers and checks; it changes no state. */
function feet(st, out) {
  const frame2 = st.frame2;
  st.support.frame(st.tick * st.d.dt, frame2);
  for (let i = 0; i < st.data.legs.length; i++) {
    toWorld(frame2, st.plant, 3 * i, out, 4 * i);
    out[4 * i + 3] = st.planted[i];
  }
  return out;
}

/** Root, every slot's quaternion and translation, rope nodes (what parity compares); allocates. */
function stateVector(st) {
  const quats = st.quats, trans = st.trans;
  const out = Array.from(st.root);
  for (let s = 0; s < st.data.parent.length; s++) out.push(...quats.subarray(4 * s, 4 * s + 4), ...trans.subarray(3 * s, 3 * s + 3));
  for (const n of st.nodes) out.push(...n);
  return out;
}

/** FNV-1a over the tick and the float64 state (the state vector `values`, then the previous rope nodes,
 * feet and swimmer); allocates. */
function stateHash(st, values) {
  const plant = st.plant, swingFrom = st.swingFrom, swingTo = st.swingTo;
  for (const n of st.prevNodes) values.push(...n);
  for (let i = 0; i < st.data.legs.length; i++) {
    values.push(st.planted[i], ...plant.subarray(3 * i, 3 * i + 3), ...swingFrom.subarray(3 * i, 3 * i + 3), ...swingTo.subarray(3 * i, 3 * i + 3), st.liftTick[i]);
  }
  values.push(st.swim[0], st.swim[1], st.centre[0], st.centre[2]);
  return hashBytes(new Uint8Array(Float64Array.from(values).buffer), st.tick);
}
