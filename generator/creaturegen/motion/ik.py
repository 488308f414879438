"""Analytic two-bone IK: law of cosines, a scale-derived reach clamp and a Gram-Schmidt bend hint.

The knee lies in the plane of the hip→target direction and the leg's rest bend hint, so the solution is
a pure function of the target (no solver state, no iteration). The result is written as two rigid slot
transforms (thigh about the hip, shin about the knee) built from rest and posed orthonormal frames: the
bone direction and the knee's hinge axis (the normal of the hip-knee-foot plane). The hinge is continuous
wherever the hint is not parallel to hip→target; a second axis taken from the hint itself would flip the
bone 180° about its own axis whenever the bone swings through the hint direction (the skin would twist
with it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from . import quat as vq
from .data import LegData
from .quat import Quat, Vec


@dataclass(frozen=True)
class IKResult:
    q_upper: Quat
    t_upper: Vec
    q_lower: Quat
    t_lower: Vec
    knee: Vec
    foot: Vec
    clamped: bool
    residual: float  # max bone-length error / (a + b)


def solve_leg(leg: LegData, target: Vec) -> IKResult:
    hip, knee0, foot0, hint = leg.hip, leg.knee, leg.foot, leg.hint
    a, b = leg.a, leg.b
    d = [target[0] - hip[0], target[1] - hip[1], target[2] - hip[2]]
    dist = vq.length(d)
    u = [0.0, -1.0, 0.0] if dist == 0.0 else [d[0] / dist, d[1] / dist, d[2] / dist]
    reach = min(max(dist, leg.reach_min), leg.reach_max)
    clamped = reach != dist
    v = vq.gram_schmidt(hint, u)
    cos_a = (a * a + reach * reach - b * b) / (2.0 * a * reach)
    cos_a = min(max(cos_a, -1.0), 1.0)
    sin_a = math.sqrt(1.0 - cos_a * cos_a)
    knee = [hip[i] + a * (cos_a * u[i] + sin_a * v[i]) for i in range(3)]
    foot = [hip[i] + reach * u[i] for i in range(3)]
    hinge0 = leg.hinge
    hinge1 = vq.normalize(vq.cross(u, v))
    thigh0 = vq.normalize([knee0[0] - hip[0], knee0[1] - hip[1], knee0[2] - hip[2]])
    thigh1 = vq.normalize([knee[0] - hip[0], knee[1] - hip[1], knee[2] - hip[2]])
    q_upper = vq.from_frames(thigh0, vq.gram_schmidt(hinge0, thigh0), thigh1, vq.gram_schmidt(hinge1, thigh1))
    r_hip = vq.rotate(q_upper, hip)
    t_upper = [hip[0] - r_hip[0], hip[1] - r_hip[1], hip[2] - r_hip[2]]
    shin0 = vq.normalize([foot0[0] - knee0[0], foot0[1] - knee0[1], foot0[2] - knee0[2]])
    shin1 = vq.normalize([foot[0] - knee[0], foot[1] - knee[1], foot[2] - knee[2]])
    q_lower = vq.from_frames(shin0, vq.gram_schmidt(hinge0, shin0), shin1, vq.gram_schmidt(hinge1, shin1))
    r_knee = vq.rotate(q_lower, knee0)
    t_lower = [knee[0] - r_knee[0], knee[1] - r_knee[1], knee[2] - r_knee[2]]
    thigh_len = vq.distance(knee, hip)
    shin_len = vq.distance(foot, knee)
    residual = max(abs(thigh_len - a), abs(shin_len - b)) / (a + b)
    return IKResult(q_upper, t_upper, q_lower, t_lower, knee, foot, clamped, residual)
