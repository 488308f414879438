// One creature's locomotion in float64, tick by tick: the same formulas in the same order as creaturegen's
// Python reference (motion/simulate.py). Order of writes per tick (the last stage touching a slot wins):
//   1. root: position, yaw and squash (closed form for walkers, hoppers and flyers; the swimmer's vertical
//      response is integrated);
//   2. base pose: per-slot local rotations composed down the skeleton (flyer bank and flap, swimmer
//      undulation; identity otherwise);
//   3. legs: plant in the support frame → world target → inverse root transform → body-frame IK →
//      creature-local leg slots (a hopper's two legs plant together on the ground and tuck in the air);
//   4. ropes: fixed-step verlet in world space, the anchor following the posed body, written last.
// Integer ticks are authoritative: seekTick(n) resets and steps n times, so it equals n step() calls bit
// for bit. Nothing allocates after createMotion (typed scratch only); the only variation is the seeded LCG.

import { drawGenome, express, individualSize } from '../genome.js';
import { instanceYaw } from '../lcg.js';
import { hashBytes } from '../hash.js';
import { axisAngle, fromFrames, fromTo, gramSchmidt, mul, normalizeInto, rotate } from './quat.js';
import { SWIMMER_CHANNELS, createFlatGround, createGravity, toLocal, toWorld } from './providers.js';
import { derive } from './derived.js';
import { sincos } from './trig.js';

// The walking locomotion types (creaturegen spec/character.py WALKERS): one gait, any even leg count 2..8.
const WALKERS = ['biped', 'quadruped', 'hexapod', 'octopod', 'walker'];
const GATE_NAMES = ['plantDrift', 'ikResidual', 'drawnFoot', 'clampedTicks', 'plantedSamples', 'bothSwingTicks',
  'fewestPlanted', 'steps', 'ropeAnchor', 'swimTracking', 'apexError', 'apexSquash', 'squashDet'];
const G = Object.freeze(Object.fromEntries(GATE_NAMES.map((name, i) => [name, i])));

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
  const yaw = instanceYaw(seed, lcg);
  const theta0 = -yaw;
  const pos = Float64Array.from(position);
  const S = m.parent.length;
  const L = m.legs.length;
  const isWalker = WALKERS.includes(kind);
  const hasCurrent = water ? water.channels.includes('materialCurrentVelocityMps') : false;
  const sample = water ? water.createSample() : null;

  // state
  const quats = new Float64Array(4 * S);
  const trans = new Float64Array(3 * S);
  const root = new Float64Array(6); // x, y, z, cos yaw, sin yaw, squash
  const prevQuats = new Float64Array(4 * S);
  const prevTrans = new Float64Array(3 * S);
  const prevRoot = new Float64Array(6);
  const centre = new Float64Array(3);
  const planted = new Uint8Array(L);
  const plant = new Float64Array(3 * L);
  const swingFrom = new Float64Array(3 * L);
  const swingTo = new Float64Array(3 * L);
  const liftTick = new Int32Array(L);
  const nodes = m.ropes.map((r) => new Float64Array(3 * r.rest.length));
  const prevNodes = m.ropes.map((r) => new Float64Array(3 * r.rest.length));
  const swim = new Float64Array(2); // y, vy
  let tick = 0;
  // Worst values since reset, measured every tick (motion/simulate.py Gates), in one typed array.
  const gv = new Float64Array(GATE_NAMES.length);

  // scratch
  const frame = new Float64Array(12);
  const frame2 = new Float64Array(12);
  const root2 = new Float64Array(6);
  const v3 = new Float64Array(3);
  const w3 = new Float64Array(3);
  const home = new Float64Array(3);
  const ahead = new Float64Array(3);
  const local = new Float64Array(3);
  const target = new Float64Array(3);
  const airFrom = new Float64Array(3); // a hopper's airborne foot: its take-off and landing plants, creature frame
  const airTo = new Float64Array(3);
  const hopOut = new Float64Array(3);
  const path = new Float64Array(3);
  const query = new Float64Array(3); // the water query (x, z, time): numbers in an array are never boxed
  const locals = new Float64Array(4 * S);
  const hasLocal = new Uint8Array(S);
  const turned = new Float64Array(3);
  const frames = new Float64Array(12);
  const ik = new Float64Array(16); // knee 0..2, foot 3..5, flags 6 (clamped), 7 (residual)
  const grav = Float64Array.from(gravity0);
  const staticFrame = support.frame(0, new Float64Array(12));
  const anchorLocal = new Float64Array(3);
  const anchorWorld = new Float64Array(3);
  const beforeWorld = new Float64Array(3);
  const ropeLocal = new Float64Array(6); // follow(): the node, then the node before it, support-local
  const localNodes = new Float64Array(3 * Math.max(1, ...m.ropes.map((r) => r.rest.length)));
  const e0 = new Float64Array(3);
  const hinge1 = new Float64Array(3);
  const u3 = new Float64Array(3);
  const n3 = new Float64Array(3);
  const g3 = new Float64Array(3);
  const sc = new Float64Array(3); // sin, cos, angle (trig.js sincos)
  const dist1 = new Float64Array(1);
  const still = new Float64Array(3);
  const axis4 = new Float64Array(4);
  const LEVEL = new Float64Array([0, 1]); // lift 0, squash 1
  const hopLift = hopOut.subarray(1, 3); // the hop's (lift, squash)
  const e1 = new Float64Array(3);
  const q = new Float64Array(4);

  function resetGates() {
    gv.fill(0);
    gv[G.apexSquash] = 1;
    gv[G.fewestPlanted] = L;
  }

  /** The gates as a plain object (allocates; the per-tick path writes the typed array only). */
  function readGates() {
    const out = {};
    for (const [name, index] of Object.entries(G)) out[name] = gv[index];
    return out;
  }

  // --- root ------------------------------------------------------------------------------------------

  // Doubles reach the helpers below through typed scratch arrays, never as arguments (see quat.js).
  function pathAt(dv, out) {
    const radius = m.pathRadius;
    sc[2] = theta0 + dv[0] / radius;
    sincos(sc, 2, sc, 0);
    out[0] = centre[0] + radius * sc[1];
    out[1] = centre[2] + radius * sc[0];
    out[2] = -sc[2];
  }

  /** How far the upright body sinks on a tilted support (heading c, s = hs[0], hs[1]) into hs[2]: halfway
   * between its lowest and highest rest foot, within constants.settleSlack of the legs' room to full
   * extension (motion/simulate.py Motion._settle). */
  function settle(f, hs) {
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

  /** Root on the support at (u, w) = p[0], p[1], heading ψ = p[2]; ls = (lift, squash). */
  function grounded(f, p, ls, out) {
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
    if (L) { sc[0] = c; sc[1] = s; settle(f, sc); lift = lift + sc[2]; }
    out[0] = v3[0]; out[1] = v3[1] + lift - m.groundY * squash; out[2] = v3[2]; out[3] = c; out[4] = s; out[5] = squash;
  }

  function hopAt(n, out) {
    const c = m.constants;
    const hopLength = m.speed > 0 ? m.hopLength : 0;
    const k = Math.floor(n / d.hopCycle);
    let r = n % d.hopCycle;
    if (r < d.hopIdle) { out[0] = k * hopLength; out[1] = 0; out[2] = 1; return; }
    r -= d.hopIdle;
    // In the crouch and the landing a hopper on legs also sinks on them (d.dip, 0 without legs).
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

  /** Support frame and root (x, y, z, cos yaw, sin yaw, squash) at tick n. */
  function rootAt(n, f, out) {
    const time = n * d.dt;
    // A static support (flat ground, the slope) was sampled once; a moving one is asked every tick.
    if (support.static === true) f.set(staticFrame);
    else support.frame(time, f);
    dist1[0] = m.speed * time;
    if (isWalker) {
      pathAt(dist1, path);
      grounded(f, path, LEVEL, out);
    } else if (kind === 'hopper') {
      hopAt(n, hopOut);
      pathAt(hopOut, path);
      grounded(f, path, hopLift, out);
    } else if (kind === 'flyer') {
      pathAt(dist1, path);
      sincos(path, 2, sc, 0);
      out[0] = path[0]; out[1] = m.altitude - m.groundY; out[2] = path[1]; out[3] = sc[1]; out[4] = sc[0]; out[5] = 1;
    } else if (kind === 'swimmer') {
      pathAt(dist1, path);
      sincos(path, 2, sc, 0);
      out[0] = path[0]; out[1] = swim[0]; out[2] = path[1]; out[3] = sc[1]; out[4] = sc[0]; out[5] = 1;
    } else {
      still[0] = pos[0]; still[1] = pos[2]; still[2] = -theta0;
      grounded(f, still, LEVEL, out);
    }
  }

  /** Creature-local → world: p + R_yaw(S·x), S = diag(1/√s, s, 1/√s). */
  function toWorldRoot(r, x, xo, out, o) {
    const x0 = x[xo], x1 = x[xo + 1], x2 = x[xo + 2];
    const c = r[3], s = r[4], squash = r[5];
    const k = 1 / Math.sqrt(squash);
    const vx = x0 * k, vy = x1 * squash, vz = x2 * k;
    out[o] = r[0] + (c * vx + s * vz);
    out[o + 1] = r[1] + vy;
    out[o + 2] = r[2] + (-s * vx + c * vz);
  }

  function toLocalRoot(r, x, xo, out, o) {
    const x0 = x[xo], x1 = x[xo + 1], x2 = x[xo + 2];
    const c = r[3], s = r[4], squash = r[5];
    const vx = x0 - r[0], vy = x1 - r[1], vz = x2 - r[2];
    const sq = Math.sqrt(squash);
    out[o] = (c * vx - s * vz) * sq;
    out[o + 1] = vy / squash;
    out[o + 2] = (s * vx + c * vz) * sq;
  }

  // --- one tick --------------------------------------------------------------------------------------

  function update(n, integrate) {
    const time = n * d.dt;
    if (kind === 'swimmer') swimStep(n, integrate);
    rootAt(n, frame, root);
    if (kind === 'hopper') hopGates(n);
    basePose(n);
    if (L) gait(n, integrate);
    if (m.ropes.length) ropes(integrate);
  }

  function swimStep(n, integrate) {
    const time = n * d.dt;
    dist1[0] = m.speed * time;
    pathAt(dist1, path);
    query[0] = path[0]; query[1] = path[1]; query[2] = time;
    water.sample(query, sample);
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
    if (hasCurrent) {
      centre[0] = centre[0] + sample.materialCurrentVelocityMps[0] * d.dt;
      centre[2] = centre[2] + sample.materialCurrentVelocityMps[2] * d.dt;
    }
    if (time >= 2) gv[G.swimTracking] = Math.max(gv[G.swimTracking], Math.abs(swim[0] - tgt));
  }

  function hopGates(n) {
    const squash = root[5];
    const k = 1 / Math.sqrt(squash);
    gv[G.squashDet] = Math.max(gv[G.squashDet], Math.abs(k * squash * k - 1));
    if (n % d.hopCycle === d.hopIdle + d.crouch + d.halfAir) {
      hopAt(n, hopOut);
      gv[G.apexError] = Math.max(gv[G.apexError], Math.abs(hopOut[1] - d.apex));
      gv[G.apexSquash] = squash;
    }
  }

  function basePose(n) {
    const time = n * d.dt;
    hasLocal.fill(0);
    if (kind === 'flyer') {
      for (let i = 0; i < m.roots.length; i++) { const r = m.roots[i]; locals[4 * r] = 0; locals[4 * r + 1] = 0; locals[4 * r + 2] = d.bankHalfSin; locals[4 * r + 3] = d.bankHalfCos; hasLocal[r] = 1; }
      sc[2] = 2 * Math.PI * d.flapHz * time;
      sincos(sc, 2, sc, 0);
      const flap = sc[0];
      for (let i = 0; i < m.wings.length; i++) {
        const w = m.wings[i];
        axis4[0] = 0; axis4[1] = 0; axis4[2] = 1; axis4[3] = w.sign * w.amplitude * flap;
        axisAngle(axis4, 0, locals, 4 * w.slot); hasLocal[w.slot] = 1;
      }
    } else if (kind === 'swimmer' && d.undulationHz > 0) {
      sc[2] = 2 * Math.PI * d.undulationHz * time;
      sincos(sc, 2, sc, 0);
      const angle = m.undulation * sc[0];
      axis4[0] = 0; axis4[1] = 1; axis4[2] = 0; axis4[3] = angle;
      for (let i = 0; i < m.roots.length; i++) { const r = m.roots[i]; axisAngle(axis4, 0, locals, 4 * r); hasLocal[r] = 1; }
    }
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

  // --- legs --------------------------------------------------------------------------------------------

  /** Support-local home of a foot: the rest foot under root r, on the support frame f. */
  function homeIn(leg, f, r, out) {
    toWorldRoot(r, leg.foot, 0, v3, 0);
    toLocal(f, v3, 0, out, 0);
    out[1] = 0;
  }

  function initialPlant(leg, i) {
    homeIn(leg, frame, root, home);
    if (m.speed <= 0) { plant[3 * i] = home[0]; plant[3 * i + 1] = 0; plant[3 * i + 2] = home[2]; return; }
    const lead = m.constants.stepLead * m.stepLength;
    const back = m.speed * d.dt * (d.cycle - d.swing - leg.group * d.window);
    dist1[0] = 0;
    pathAt(dist1, path);
    sincos(path, 2, sc, 0);
    const offset = lead - back;
    plant[3 * i] = home[0] + sc[0] * offset; plant[3 * i + 1] = 0; plant[3 * i + 2] = home[2] + sc[1] * offset;
  }

  /** Two-bone IK into the leg's slots (motion/ik.py); ik[0..2] knee, ik[3..5] foot, ik[6] clamped, ik[7] residual. */
  function solveLeg(leg, t) {
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

  function gait(n, integrate) {
    if (kind === 'hopper') { hopLegs(n, integrate); return; }
    const stepLength = m.stepLength;
    const lead = m.constants.stepLead * stepLength;
    const phase = n % d.cycle;
    let swinging = 0;
    for (let i = 0; i < L; i++) {
      const leg = m.legs[i];
      const o = 3 * i;
      if (!integrate) { planted[i] = 1; initialPlant(leg, i); }
      else if (!planted[i] && n - liftTick[i] >= d.swing) {
        planted[i] = 1; plant[o] = swingTo[o]; plant[o + 1] = swingTo[o + 1]; plant[o + 2] = swingTo[o + 2];
      }
      if (planted[i] && integrate) {
        homeIn(leg, frame, root, home);
        let du = home[0] - plant[o], dw = home[2] - plant[o + 2];
        const lag = Math.sqrt(du * du + dw * dw);
        const k = phase - leg.group * d.window;
        if (lag > stepLength && k >= 0 && k <= d.window - d.swing) {
          rootAt(n + d.swing, frame2, root2);
          homeIn(leg, frame2, root2, ahead);
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
      toLocalRoot(root, v3, 0, target, 0);
      placeLeg(leg, i);
    }
    countPlanted(swinging);
  }

  // A hopper's two hind legs, together (motion/simulate.py, Motion: the hopper's legs): planted while the body is on the
  // support (idle, crouch, landing); from the first air tick each foot leaves its take-off plant
  // (swingFrom), is drawn up toward its hip (leg.tuck) at the apex and reaches for its landing plant
  // (swingTo: the rest foot under the root at the landing tick). The target blends the two (smoothstep)
  // in the creature frame, pulled toward the tuck by (4τ(1 − τ))².
  function hopLegs(n, integrate) {
    const r = n % d.hopCycle;
    const airborne = d.hopIdle + d.crouch <= r && r < d.hopIdle + d.crouch + d.air;
    let swinging = 0;
    for (let i = 0; i < L; i++) {
      const leg = m.legs[i];
      const o = 3 * i;
      if (!integrate) {
        planted[i] = 1;
        homeIn(leg, frame, root, home);
        plant[o] = home[0]; plant[o + 1] = home[1]; plant[o + 2] = home[2];
      } else if (planted[i] && airborne) {
        planted[i] = 0; liftTick[i] = n;
        swingFrom[o] = plant[o]; swingFrom[o + 1] = plant[o + 1]; swingFrom[o + 2] = plant[o + 2];
        rootAt(n + d.air, frame2, root2);
        homeIn(leg, frame2, root2, ahead);
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
      placeLeg(leg, i);
    }
    countPlanted(swinging);
  }

  /** Two-bone IK of leg i toward `target` (creature frame) into its slots, and the leg gates. */
  function placeLeg(leg, i) {
    const o = 3 * i;
    solveLeg(leg, target);
    const span = leg.a + leg.b;
    gv[G.ikResidual] = Math.max(gv[G.ikResidual], ik[7]);
    rotate(quats, 4 * leg.lower, leg.foot, 0, v3, 0);
    const lo = 3 * leg.lower;
    const drawnX = v3[0] + trans[lo], drawnY = v3[1] + trans[lo + 1], drawnZ = v3[2] + trans[lo + 2];
    const ex = drawnX - ik[3], ey = drawnY - ik[4], ez = drawnZ - ik[5];
    gv[G.drawnFoot] = Math.max(gv[G.drawnFoot], Math.sqrt(ex * ex + ey * ey + ez * ez) / span);
    if (ik[6]) gv[G.clampedTicks] += 1;
    else if (planted[i]) {
      n3[0] = drawnX; n3[1] = drawnY; n3[2] = drawnZ;
      toWorldRoot(root, n3, 0, v3, 0);
      toLocal(frame, v3, 0, w3, 0);
      const px = w3[0] - plant[o], py = w3[1] - plant[o + 1], pz = w3[2] - plant[o + 2];
      gv[G.plantDrift] = Math.max(gv[G.plantDrift], Math.sqrt(px * px + py * py + pz * pz) / span);
      gv[G.plantedSamples] += 1;
    }
  }

  function countPlanted(swinging) {
    if (L === 2 && swinging === 2) gv[G.bothSwingTicks] += 1;
    gv[G.fewestPlanted] = Math.min(gv[G.fewestPlanted], L - swinging);
  }

  // --- ropes -------------------------------------------------------------------------------------------

  function anchorPoint(rope, j, out, o) {
    const p = rope.parent;
    const x = rope.rest[j];
    rotate(quats, 4 * p, x, 0, out, o);
    out[o] += trans[3 * p]; out[o + 1] += trans[3 * p + 1]; out[o + 2] += trans[3 * p + 2];
  }

  // The bend limit (motion/simulate.py, Motion: the rope bend limit): node j's neighbours at least bendMin apart; the anchor and
  // the point before it on the body are fixed, so the first two constraints move only the far node.
  function bend(cur, count, rope) {
    const bendMin = rope.bendMin;
    for (let j = 0; j < count - 1; j++) {
      const b = 3 * (j + 1);
      const ax = j === 0 ? beforeWorld[0] : cur[3 * (j - 1)];
      const ay = j === 0 ? beforeWorld[1] : cur[3 * (j - 1) + 1];
      const az = j === 0 ? beforeWorld[2] : cur[3 * (j - 1) + 2];
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

  // Follow the leader from the anchor (motion/simulate.py, Motion: follow the leader): each segment its rest length and
  // within the bend limit of the one before (the first of the body's direction into the anchor), and
  // above the support, lifted by swinging the segment about its first node so its length holds.
  function follow(cur, count, rope) {
    const seg = rope.segment, cMax = rope.bendCos, sMax = rope.bendSin, radius = rope.radius;
    let px = cur[0] - beforeWorld[0], py = cur[1] - beforeWorld[1], pz = cur[2] - beforeWorld[2];
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
      if (m.ropeGround) {
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

  function ropes(integrate) {
    const c = m.constants;
    if (!integrate) {
      m.ropes.forEach((rope, r) => {
        for (let j = 0; j < rope.rest.length; j++) {
          anchorPoint(rope, j, v3, 0);
          toWorldRoot(root, v3, 0, nodes[r], 3 * j);
          prevNodes[r][3 * j] = nodes[r][3 * j]; prevNodes[r][3 * j + 1] = nodes[r][3 * j + 1]; prevNodes[r][3 * j + 2] = nodes[r][3 * j + 2];
        }
      });
    }
    // A constant provider (createGravity) was sampled once; any other is asked every tick.
    if (gravity.constant !== true) gravity.at(tick * d.dt, grav);
    const substeps = c.ropeSubsteps, passes = c.ropePasses, keep = 1 - c.ropeDamping;
    const h = d.dt / substeps;
    const gx = grav[0] * h * h, gy = grav[1] * h * h, gz = grav[2] * h * h;
    for (let r = 0; r < m.ropes.length; r++) {
      const rope = m.ropes[r];
      const cur = nodes[r], prev = prevNodes[r];
      const count = rope.rest.length;
      anchorPoint(rope, 0, anchorLocal, 0);
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
            bend(cur, count, rope);
            if (m.ropeGround) {
              for (let j = 1; j < count; j++) {
                toLocal(frame, cur, 3 * j, w3, 0);
                if (w3[1] < radius[j]) { w3[1] = radius[j]; toWorld(frame, w3, 0, cur, 3 * j); }
              }
            }
          }
          follow(cur, count, rope);
        }
      }
      for (let j = 0; j < count; j++) toLocalRoot(root, cur, 3 * j, localNodes, 3 * j);
      const rest = rope.rest;
      // Segment frames by parallel transport down the chain (motion/simulate.py): each turns by the bend
      // from the one before, the first from its parent's, so the twist is continuous and well conditioned.
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
      gv[G.ropeAnchor] = Math.max(gv[G.ropeAnchor], err / m.bodyScale);
    }
  }

  // --- public ------------------------------------------------------------------------------------------

  function reset() {
    const radius = m.pathRadius;
    sc[2] = theta0;
    sincos(sc, 2, sc, 0);
    centre[0] = pos[0] - radius * sc[1];
    centre[1] = pos[1];
    centre[2] = pos[2] - radius * sc[0];
    tick = 0;
    planted.fill(1); plant.fill(0); swingFrom.fill(0); swingTo.fill(0); liftTick.fill(0);
    swim.fill(0);
    resetGates();
    update(0, false);
    prevQuats.set(quats); prevTrans.set(trans); prevRoot.set(root);
  }

  const motion = {
    data: m, derived: d, kind, size, quats, trans, root, prevQuats, prevTrans, prevRoot, nodes, support, gravity, water,
    get gates() { return readGates(); },
    get tick() { return tick; },
    reset,
    step() {
      prevQuats.set(quats); prevTrans.set(trans); prevRoot.set(root);
      tick += 1;
      update(tick, true);
    },
    stepTicks(n = 1) { for (let k = 0; k < n; k++) motion.step(); },
    seekTick(n) {
      if (!Number.isInteger(n) || n < 0) throw new Error(`seekTick: a non-negative integer (got ${n})`);
      reset();
      motion.stepTicks(n);
    },
    /** The render pose between the previous and the current fixed step (motion/driver.py): position and
     * squash lerped, heading (cos, sin) lerped and renormalised, quaternions nlerped on the previous one's
     * hemisphere. */
    renderPose(alpha, outQuats, outTrans, outRoot) {
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
    },
    /** Each leg's plant point in world space at the current tick and whether it is planted: (x, y, z, planted)
     * per leg into `out` (4 × legs numbers). A read accessor for markers and checks; it changes no state. */
    feet(out) {
      support.frame(tick * d.dt, frame2);
      for (let i = 0; i < L; i++) {
        toWorld(frame2, plant, 3 * i, out, 4 * i);
        out[4 * i + 3] = planted[i];
      }
      return out;
    },
    /** Root, every slot's quaternion and translation, rope nodes (what parity compares); allocates. */
    stateVector() {
      const out = Array.from(root);
      for (let s = 0; s < S; s++) out.push(...quats.subarray(4 * s, 4 * s + 4), ...trans.subarray(3 * s, 3 * s + 3));
      for (const n of nodes) out.push(...n);
      return out;
    },
    /** FNV-1a over the tick and the float64 state (state vector, previous rope nodes, feet, swimmer). */
    stateHash() {
      const values = motion.stateVector();
      for (const n of prevNodes) values.push(...n);
      for (let i = 0; i < L; i++) {
        values.push(planted[i], ...plant.subarray(3 * i, 3 * i + 3), ...swingFrom.subarray(3 * i, 3 * i + 3), ...swingTo.subarray(3 * i, 3 * i + 3), liftTick[i]);
      }
      values.push(swim[0], swim[1], centre[0], centre[2]);
      return hashBytes(new Uint8Array(Float64Array.from(values).buffer), tick);
    },
  };
  reset();
  return motion;
}
