// Vector and quaternion helpers (xyzw) for the locomotion core, written term by term exactly as
// creaturegen's Python reference (motion/quat.py): Python and JS agree to ~1e-15 only when both evaluate
// the same expression tree. Every function reads vectors from (array, offset) and writes into `out` at
// offset `o`: no double crosses a call as an argument or a return value, so a call V8 does not inline
// boxes nothing, and nothing allocates.

import { sincos } from './trig.js';

/** R(q)·v by v + 2w(u×v) + 2u×(u×v); v at v[vo..vo+2]. */
export function rotate(q, qo, v, vo, out, o) {
  const vx = v[vo], vy = v[vo + 1], vz = v[vo + 2];
  const x = q[qo], y = q[qo + 1], z = q[qo + 2], w = q[qo + 3];
  const cx = y * vz - z * vy;
  const cy = z * vx - x * vz;
  const cz = x * vy - y * vx;
  out[o] = vx + 2 * (w * cx + y * cz - z * cy);
  out[o + 1] = vy + 2 * (w * cy + z * cx - x * cz);
  out[o + 2] = vz + 2 * (w * cz + x * cy - y * cx);
}

/** a ⊗ b into out (out may not alias a or b). */
export function mul(a, ao, b, bo, out, o) {
  const ax = a[ao], ay = a[ao + 1], az = a[ao + 2], aw = a[ao + 3];
  const bx = b[bo], by = b[bo + 1], bz = b[bo + 2], bw = b[bo + 3];
  out[o] = aw * bx + ax * bw + ay * bz - az * by;
  out[o + 1] = aw * by - ax * bz + ay * bw + az * bx;
  out[o + 2] = aw * bz + ax * by - ay * bx + az * bw;
  out[o + 3] = aw * bw - ax * bx - ay * by - az * bz;
}

/** The rotation about unit axis a[ao..ao+2] by the angle a[ao+3]. */
export function axisAngle(a, ao, out, o) {
  const ax = a[ao], ay = a[ao + 1], az = a[ao + 2];
  HALF[2] = 0.5 * a[ao + 3];
  sincos(HALF, 2, HALF, 0);
  const s = HALF[0];
  out[o] = ax * s; out[o + 1] = ay * s; out[o + 2] = az * s; out[o + 3] = HALF[1];
}

const HALF = new Float64Array(3);

/** Unit v[vo..vo+2] into out. */
export function normalizeInto(v, vo, out, o) {
  const vx = v[vo], vy = v[vo + 1], vz = v[vo + 2];
  const n = Math.sqrt(vx * vx + vy * vy + vz * vz);
  out[o] = vx / n; out[o + 1] = vy / n; out[o + 2] = vz / n;
}

/** The unit component of hint h[ho..] orthogonal to unit u[uo..] (x axis, then z, stand in when they are
 * parallel). */
export function gramSchmidt(hv, ho, uv, uo, out, o) {
  const hx = hv[ho], hy = hv[ho + 1], hz = hv[ho + 2], ux = uv[uo], uy = uv[uo + 1], uz = uv[uo + 2];
  let h = hx * ux + hy * uy + hz * uz;
  let vx = hx - h * ux, vy = hy - h * uy, vz = hz - h * uz;
  if (Math.sqrt(vx * vx + vy * vy + vz * vz) < 1e-9) {
    const fx = Math.abs(ux) < 0.9 ? 1 : 0, fz = Math.abs(ux) < 0.9 ? 0 : 1;
    h = fx * ux + 0 * uy + fz * uz;
    vx = fx - h * ux; vy = 0 - h * uy; vz = fz - h * uz;
  }
  out[o] = vx; out[o + 1] = vy; out[o + 2] = vz;
  normalizeInto(out, o, out, o);
}

/** The rotation taking frame (u0, v0, u0×v0) to (u1, v1, u1×v1), by Shepperd's method; f holds
 * u0, v0, u1, v1 at 0, 3, 6, 9. */
export function fromFrames(f, out, o) {
  const u0x = f[0], u0y = f[1], u0z = f[2], v0x = f[3], v0y = f[4], v0z = f[5];
  const u1x = f[6], u1y = f[7], u1z = f[8], v1x = f[9], v1y = f[10], v1z = f[11];
  const w0x = u0y * v0z - u0z * v0y, w0y = u0z * v0x - u0x * v0z, w0z = u0x * v0y - u0y * v0x;
  const w1x = u1y * v1z - u1z * v1y, w1y = u1z * v1x - u1x * v1z, w1z = u1x * v1y - u1y * v1x;
  const m00 = u1x * u0x + v1x * v0x + w1x * w0x, m01 = u1x * u0y + v1x * v0y + w1x * w0y, m02 = u1x * u0z + v1x * v0z + w1x * w0z;
  const m10 = u1y * u0x + v1y * v0x + w1y * w0x, m11 = u1y * u0y + v1y * v0y + w1y * w0y, m12 = u1y * u0z + v1y * v0z + w1y * w0z;
  const m20 = u1z * u0x + v1z * v0x + w1z * w0x, m21 = u1z * u0y + v1z * v0y + w1z * w0y, m22 = u1z * u0z + v1z * v0z + w1z * w0z;
  const trace = m00 + m11 + m22;
  if (trace > 0) {
    const s = Math.sqrt(trace + 1) * 2;
    out[o] = (m21 - m12) / s; out[o + 1] = (m02 - m20) / s; out[o + 2] = (m10 - m01) / s; out[o + 3] = 0.25 * s;
  } else if (m00 > m11 && m00 > m22) {
    const s = Math.sqrt(1 + m00 - m11 - m22) * 2;
    out[o] = 0.25 * s; out[o + 1] = (m01 + m10) / s; out[o + 2] = (m02 + m20) / s; out[o + 3] = (m21 - m12) / s;
  } else if (m11 > m22) {
    const s = Math.sqrt(1 + m11 - m00 - m22) * 2;
    out[o] = (m01 + m10) / s; out[o + 1] = 0.25 * s; out[o + 2] = (m12 + m21) / s; out[o + 3] = (m02 - m20) / s;
  } else {
    const s = Math.sqrt(1 + m22 - m00 - m11) * 2;
    out[o] = (m02 + m20) / s; out[o + 1] = (m12 + m21) / s; out[o + 2] = 0.25 * s; out[o + 3] = (m10 - m01) / s;
  }
}

const HALF_TURN_AXES = new Float64Array([1, 0, 0, 0, 1, 0]);

/** The shortest rotation taking unit e0 to unit e1 (a half-turn about a perpendicular when opposite). */
export function fromTo(e0, e0o, e1, e1o, out, o) {
  const e0x = e0[e0o], e0y = e0[e0o + 1], e0z = e0[e0o + 2], e1x = e1[e1o], e1y = e1[e1o + 1], e1z = e1[e1o + 2];
  const d = e0x * e1x + e0y * e1y + e0z * e1z;
  if (d < -1 + 1e-12) {
    gramSchmidt(HALF_TURN_AXES, Math.abs(e0x) < 0.9 ? 0 : 3, e0, e0o, out, o);
    out[o + 3] = 0;
    return;
  }
  const cx = e0y * e1z - e0z * e1y, cy = e0z * e1x - e0x * e1z, cz = e0x * e1y - e0y * e1x;
  const w = 1 + d;
  const n = Math.sqrt(cx * cx + cy * cy + cz * cz + w * w);
  out[o] = cx / n; out[o + 1] = cy / n; out[o + 2] = cz / n; out[o + 3] = w / n;
}
