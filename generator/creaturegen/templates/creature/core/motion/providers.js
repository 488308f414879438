// Injected providers, the same built-ins as creaturegen's Python reference (motion/providers.py).
// Locomotion never owns the world: gait asks a SupportSurfaceProvider where the ground is and how it moves,
// the swimmer asks a WaterSurfaceProvider for the channels it represents (an absent channel is absent,
// never zero), and gravity comes from a provider and is never scaled by creature scale.
// A support frame is 12 numbers: origin, tangent ex, outward normal ny, tangent ez; support-local
// (u, h, w) maps to origin + u·ex + h·ny + w·ez.

import { sincos } from './trig.js';

export const STANDARD_GRAVITY = 9.80665;
export const SWIMMER_CHANNELS = Object.freeze(['freeSurfacePoint', 'freeSurfaceNormal', 'geometricNormalVelocityMps']);

export function createGravity(vector = [0, -STANDARD_GRAVITY, 0]) {
  const v = Float64Array.from(vector);
  // constant: the core samples it once instead of every tick (no time passed per step).
  return { constant: true, at(time, out) { out[0] = v[0]; out[1] = v[1]; out[2] = v[2]; return out; } };
}

/** Support-local (u, h, w) = v[vo..vo+2] → world, into out[o..o+2]. */
export function toWorld(f, v, vo, out, o) {
  const u = v[vo], h = v[vo + 1], w = v[vo + 2];
  out[o] = f[0] + u * f[3] + h * f[6] + w * f[9];
  out[o + 1] = f[1] + u * f[4] + h * f[7] + w * f[10];
  out[o + 2] = f[2] + u * f[5] + h * f[8] + w * f[11];
}

/** World p[po..po+2] → support-local (u, h, w), into out[o..o+2]. */
export function toLocal(f, p, po, out, o) {
  const px = p[po], py = p[po + 1], pz = p[po + 2];
  const dx = px - f[0], dy = py - f[1], dz = pz - f[2];
  out[o] = dx * f[3] + dy * f[4] + dz * f[5];
  out[o + 1] = dx * f[6] + dy * f[7] + dz * f[8];
  out[o + 2] = dx * f[9] + dy * f[10] + dz * f[11];
}

/** The SupportSurfaceProvider surface every built-in shares: closest point, outward normal, point
 * velocity and acceleration, stable ids. Providers supply frame(), velocity() and acceleration(). */
function support(name, supportId, frame, velocity, acceleration, isStatic = false) {
  const f = new Float64Array(12);
  const local = new Float64Array(3);
  return {
    name, supportId,
    // static: the frame never moves, so the core samples it once instead of every tick.
    static: isStatic,
    frame,
    velocity,
    acceleration,
    featureId() { return 0; },
    closestPoint(time, p, out) {
      frame(time, f);
      toLocal(f, p, 0, local, 0);
      local[1] = 0;
      toWorld(f, local, 0, out, 0);
      return out;
    },
    normal(time, p, out) {
      frame(time, f);
      out[0] = f[6]; out[1] = f[7]; out[2] = f[8];
      return out;
    },
  };
}

const zero = (time, p, out) => { out[0] = 0; out[1] = 0; out[2] = 0; return out; };

export function createFlatGround() {
  return support('flat', 1, (time, out) => {
    out.fill(0); out[3] = 1; out[7] = 1; out[11] = 1; return out;
  }, zero, zero, true);
}

/** A plane through the origin rising along +z by `angle` radians (default 10°). */
export function createSlope(angle = 10 * (Math.PI / 180)) {
  const t = Float64Array.of(0, 0, angle);
  sincos(t, 2, t, 0);
  const c = t[1], s = t[0];
  return support('slope', 2, (time, out) => {
    out.fill(0); out[3] = 1; out[7] = c; out[8] = -s; out[10] = s; out[11] = c; return out;
  }, zero, zero, true);
}

/** The ground plane carried at constant velocity (m/s). */
export function createTranslatingPlatform(velocity = [0.3, 0, 0.1]) {
  const v = Float64Array.from(velocity);
  return support('translating', 3, (time, out) => {
    out.fill(0);
    out[0] = v[0] * time; out[1] = v[1] * time; out[2] = v[2] * time;
    out[3] = 1; out[7] = 1; out[11] = 1; return out;
  }, (time, p, out) => { out[0] = v[0]; out[1] = v[1]; out[2] = v[2]; return out; }, zero);
}

/** The ground plane turning about the vertical through `centre` at `omega` rad/s. */
export function createRotatingPlatform(centre = [0.5, 0, -0.4], omega = 0.35) {
  const c0 = Float64Array.from(centre);
  const t = new Float64Array(3); // sin, cos, angle
  return support('rotating', 4, (time, out) => {
    t[2] = omega * time;
    sincos(t, 2, t, 0);
    const c = t[1], s = t[0];
    out[0] = c0[0]; out[1] = c0[1]; out[2] = c0[2];
    out[3] = c; out[4] = 0; out[5] = -s; out[6] = 0; out[7] = 1; out[8] = 0; out[9] = s; out[10] = 0; out[11] = c;
    return out;
  }, (time, p, out) => {
    out[0] = omega * (p[2] - c0[2]); out[1] = 0; out[2] = -omega * (p[0] - c0[0]); return out;
  }, (time, p, out) => {
    const w2 = omega * omega;
    out[0] = -w2 * (p[0] - c0[0]); out[1] = 0; out[2] = -w2 * (p[2] - c0[2]); return out;
  });
}

export function builtinSupports() {
  return { flat: createFlatGround(), slope: createSlope(), translating: createTranslatingPlatform(), rotating: createRotatingPlatform() };
}

const WAVE_CHANNELS = ['freeSurfacePoint', 'geometricNormalVelocityMps', 'freeSurfaceNormal', 'waterColumnDepthMeters'];

/** Two travelling sine waves, η = A1 sin(k1 x − w1 t) + A2 sin(k2 z − w2 t + 0.7). `channels` lists what
 * it represents; sample(query, out) reads (x, z, time) from `query` and writes only those channels into `out`
 * (one Float64Array per channel). */
export function createAnalyticWater({
  channels = WAVE_CHANNELS, waves = [[0.06, 1.3, 1.7], [0.04, 0.9, 1.1]], level = 0, depth = 4,
} = {}) {
  const present = Object.freeze(channels.filter((c) => WAVE_CHANNELS.includes(c)));
  const [[a1, k1, w1], [a2, k2, w2]] = waves;
  const t1 = new Float64Array(3), t2 = new Float64Array(3); // sin, cos, phase of each wave
  return {
    channels: present,
    createSample() {
      return { freeSurfacePoint: new Float64Array(3), freeSurfaceNormal: new Float64Array(3), geometricNormalVelocityMps: new Float64Array(1), waterColumnDepthMeters: new Float64Array(1) };
    },
    sample(query, out) {
      const x = query[0], z = query[1], time = query[2];
      t1[2] = k1 * x - w1 * time;
      t2[2] = k2 * z - w2 * time + 0.7;
      sincos(t1, 2, t1, 0);
      sincos(t2, 2, t2, 0);
      const eta = level + a1 * t1[0] + a2 * t2[0];
      const detaDt = -a1 * w1 * t1[1] - a2 * w2 * t2[1];
      const gx = a1 * k1 * t1[1];
      const gz = a2 * k2 * t2[1];
      const inv = 1 / Math.sqrt(gx * gx + 1 + gz * gz);
      for (let i = 0; i < present.length; i++) {
        const name = present[i];
        const v = out[name];
        if (name === 'freeSurfacePoint') { v[0] = x; v[1] = eta; v[2] = z; }
        else if (name === 'freeSurfaceNormal') { v[0] = -gx * inv; v[1] = inv; v[2] = -gz * inv; }
        else if (name === 'geometricNormalVelocityMps') v[0] = detaDt * inv;
        else v[0] = eta + depth;
      }
      return out;
    },
  };
}
