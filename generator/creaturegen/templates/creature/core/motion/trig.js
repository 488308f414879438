// Portable sine and cosine: the same fdlibm kernels as creaturegen's Python reference (model/trig.py).
// V8's Math.sin and the C library's sin may differ in the last bit, and a driven verlet rope amplifies
// that a thousandfold within a few hundred ticks. Built from +, −, ×, ÷ and floor only (each correctly
// rounded, no fused multiply-add in either language), these are bit-identical in Python and JS.
// One function computes both (every caller here wants both or pays nothing for the other).

const INV_PIO2 = 6.36619772367581382433e-01;
const PIO2_1 = 1.57079632673412561417e+00;
const PIO2_1T = 6.07710050650619224932e-11;
const S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03, S3 = -1.98412698298579493134e-04;
const S4 = 2.75573137070700676789e-06, S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
const C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03, C3 = 2.48015872894767294178e-05;
const C4 = -2.75573143513906633035e-07, C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;

/**
 * sin and cos of a[ao] into out[o], out[o + 1]: the reference's psin and pcos (model/trig.py), which share
 * the range reduction and the ksin/kcos kernels, term by term. Angle and results travel through arrays, so
 * no double crosses a call and nothing is boxed (quat.js).
 */
export function sincos(a, ao, out, o) {
  const x = a[ao];
  const n = Math.floor(x * INV_PIO2 + 0.5);
  const y = (x - n * PIO2_1) - n * PIO2_1T;
  const q = ((n % 4) + 4) % 4;
  const z = y * y;
  // ksin(y) and kcos(y), term by term
  const v = z * y;
  const rs = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
  const sn = y + v * (S1 + z * rs);
  const rc = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
  const hz = 0.5 * z;
  const w = 1 - hz;
  const cs = w + (((1 - w) - hz) + z * rc);
  if (q === 0) { out[o] = sn; out[o + 1] = cs; } else if (q === 1) { out[o] = cs; out[o + 1] = -sn; } else if (q === 2) { out[o] = -sn; out[o + 1] = -cs; } else { out[o] = -cs; out[o + 1] = sn; }
}
