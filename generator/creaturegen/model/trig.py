"""Portable sine and cosine: the same fdlibm kernels in Python and JS (core/motion/trig.js).

The C library's and V8's ``sin`` may differ in the last bit, and a driven verlet rope amplifies a 1e-16
difference a thousandfold within a few hundred ticks. Built from +, −, ×, ÷ and floor only (each correctly
rounded in IEEE 754 double, no fused multiply-add in either language), these give bit-identical results
in both, so locomotion parity holds however chaotic the rope. Accuracy: within about 1 ulp of the true
value for the arguments locomotion uses (|x| < 1e5).
"""

from __future__ import annotations

import math
from typing import Final

_INV_PIO2: Final = 6.36619772367581382433e-01
_PIO2_1: Final = 1.57079632673412561417e00
_PIO2_1T: Final = 6.07710050650619224932e-11
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11


def _ksin(x: float) -> float:
    z = x * x
    v = z * x
    r = _S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))
    return x + v * (_S1 + z * r)


def _kcos(x: float) -> float:
    z = x * x
    r = z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    hz = 0.5 * z
    w = 1.0 - hz
    return w + (((1.0 - w) - hz) + z * r)


def _reduce(x: float) -> tuple[int, float]:
    n = math.floor(x * _INV_PIO2 + 0.5)
    return n % 4, (x - n * _PIO2_1) - n * _PIO2_1T


def psin(x: float) -> float:
    q, y = _reduce(x)
    if q == 0:
        return _ksin(y)
    if q == 1:
        return _kcos(y)
    if q == 2:
        return -_ksin(y)
    return -_kcos(y)


def pcos(x: float) -> float:
    q, y = _reduce(x)
    if q == 0:
        return _kcos(y)
    if q == 1:
        return -_ksin(y)
    if q == 2:
        return -_kcos(y)
    return _ksin(y)
