"""Vector and quaternion helpers (xyzw), each written exactly as core/motion/quat.js writes it.

Vectors are 3-lists of floats and quaternions 4-lists; the formulas are spelled out term by term because
the parity law pins Python and JS to ~1e-15, which only holds when both evaluate the same expression tree.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ..model.trig import pcos, psin

Vec = list[float]
Quat = list[float]
#: A 3-vector argument that is only read: a list, or a tuple of the frozen motion data (motion/data.py).
Point = Sequence[float]

IDENTITY: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)


def rotate(q: Quat, v: Point) -> Vec:
    """R(q)·v by ``v + 2w(u×v) + 2u×(u×v)``."""
    x, y, z, w = q
    cx = y * v[2] - z * v[1]
    cy = z * v[0] - x * v[2]
    cz = x * v[1] - y * v[0]
    return [
        v[0] + 2.0 * (w * cx + y * cz - z * cy),
        v[1] + 2.0 * (w * cy + z * cx - x * cz),
        v[2] + 2.0 * (w * cz + x * cy - y * cx),
    ]


def mul(a: Quat, b: Quat) -> Quat:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]


def axis_angle(axis: Point, angle: float) -> Quat:
    half = 0.5 * angle
    s = psin(half)
    return [axis[0] * s, axis[1] * s, axis[2] * s, pcos(half)]


def dot(a: Point, b: Point) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: Point, b: Point) -> Vec:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def length(a: Point) -> float:
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def norm3(x: float, y: float, z: float) -> float:
    """|(x, y, z)| as sqrt((x² + y²) + z²), which the JS core writes inline (math.hypot and Math.hypot round
    differently, and a JS call returning a double boxes it unless V8 inlines the call)."""
    return math.sqrt(x * x + y * y + z * z)


def distance(a: Point, b: Point) -> float:
    return norm3(a[0] - b[0], a[1] - b[1], a[2] - b[2])


def normalize(a: Point) -> Vec:
    n = length(a)
    return [a[0] / n, a[1] / n, a[2] / n]


def gram_schmidt(hint: Point, u: Point) -> Vec:
    """The unit component of ``hint`` orthogonal to unit ``u`` (the knee's bend direction); when the hint
    is parallel to ``u`` the x axis (then z) stands in, so the frame is always defined."""
    h = dot(hint, u)
    v = [hint[0] - h * u[0], hint[1] - h * u[1], hint[2] - h * u[2]]
    if length(v) < 1e-9:
        fallback = [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 0.0, 1.0]
        h = dot(fallback, u)
        v = [fallback[0] - h * u[0], fallback[1] - h * u[1], fallback[2] - h * u[2]]
    return normalize(v)


def from_frames(u0: Point, v0: Point, u1: Point, v1: Point) -> Quat:
    """The rotation taking orthonormal frame (u0, v0, u0×v0) to (u1, v1, u1×v1), by Shepperd's method."""
    w0 = cross(u0, v0)
    w1 = cross(u1, v1)
    m = [[u1[i] * u0[j] + v1[i] * v0[j] + w1[i] * w0[j] for j in range(3)] for i in range(3)]
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0.0:
        s = math.sqrt(trace + 1.0) * 2.0
        return [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s]
    if m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2.0
        return [0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s]
    if m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2.0
        return [(m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s]
    s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2.0
    return [(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s]


def from_to(e0: Point, e1: Point) -> Quat:
    """The shortest rotation taking unit ``e0`` to unit ``e1`` (a half-turn about a perpendicular axis
    when they are opposite)."""
    d = dot(e0, e1)
    if d < -1.0 + 1e-12:
        axis = gram_schmidt([1.0, 0.0, 0.0] if abs(e0[0]) < 0.9 else [0.0, 1.0, 0.0], e0)
        return [axis[0], axis[1], axis[2], 0.0]
    c = cross(e0, e1)
    q = [c[0], c[1], c[2], 1.0 + d]
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return [q[0] / n, q[1] / n, q[2] / n, q[3] / n]


def yaw_rotate(c: float, s: float, v: Point) -> Vec:
    """The root yaw about +y, as the GPU's rootRotate writes it: forward +z turns to (sin ψ, 0, cos ψ)."""
    return [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]


def yaw_unrotate(c: float, s: float, v: Point) -> Vec:
    return [c * v[0] - s * v[2], v[1], s * v[0] + c * v[2]]
