"""The root: where the creature's body is on its circular path, how it stands on the support, and the
transform between creature-local and world space.

Stage 1 of a tick (simulate.py): position, yaw and squash, in closed form for walkers, hoppers and flyers
(the swimmer's vertical response is integrated, swim.py). The root is (x, y, z, cos yaw, sin yaw, squash);
the squash scales the body by S = diag(1/√s, s, 1/√s), determinant 1.
"""

from __future__ import annotations

import math

from ..model.trig import pcos, psin
from . import quat as vq
from .data import MotionData
from .providers import Frame, to_world
from .quat import Point, Vec
from .state import MotionState


def path(m: MotionState, dist: float) -> tuple[float, float, float]:
    """Support-local (u, w) and heading ψ on the circle after ``dist`` metres."""
    radius = m.data.path_radius
    theta = m.theta0 + dist / radius
    return m.centre[0] + radius * pcos(theta), m.centre[2] + radius * psin(theta), -theta


def grounded(
    data: MotionData, frame: Frame, u: float, w: float, psi: float, lift: float, squash: float
) -> list[float]:
    """Root (x, y, z, cos yaw, sin yaw, squash) on the support at (u, w), heading ψ in its plane."""
    ground = to_world(frame, [u, 0.0, w])
    sp, cp = psin(psi), pcos(psi)
    fx = sp * frame[3] + cp * frame[9]
    fz = sp * frame[5] + cp * frame[11]
    norm = math.sqrt(fx * fx + fz * fz)
    c, s = fz / norm, fx / norm
    if data.legs:
        lift = lift + settle(data, frame, c, s)
    y = ground[1] + lift - data.ground_y * squash
    return [ground[0], y, ground[2], c, s, squash]


def settle(data: MotionData, frame: Frame, c: float, s: float) -> float:
    """How far an upright body sinks on a tilted support: halfway between its lowest and highest rest
    foot's support height (relative to under the root), but never so far that a downhill leg must
    reach past ``settleSlack`` of the room its rest pose leaves to full extension. Sinking to the lowest
    foot, as it did, folded the uphill legs of a long body to a twentieth of their reach and turned
    their hips over (generated seed 189 on the 10° slope)."""
    ny = frame[7]
    lowest = highest = 0.0
    room = math.inf
    for leg in data.legs:
        r = vq.yaw_rotate(c, s, leg.foot)
        dy = -(frame[6] * r[0] + frame[8] * r[2]) / ny
        lowest, highest = min(lowest, dy), max(highest, dy)
        room = min(room, leg.reach_max - vq.distance(leg.hip, leg.foot))
    slack = float(data.constants.settle_slack)
    return lowest + min(0.5 * (highest - lowest), slack * max(room, 0.0))


def to_world_root(root: list[float], x: Point) -> Vec:
    """Creature-local → world: p + R_yaw(S·x), S = diag(1/√s, s, 1/√s) (determinant 1); the root is
    (x, y, z, cos yaw, sin yaw, squash)."""
    c, s, squash = root[3], root[4], root[5]
    k = 1.0 / math.sqrt(squash)
    r = vq.yaw_rotate(c, s, [x[0] * k, x[1] * squash, x[2] * k])
    return [root[0] + r[0], root[1] + r[1], root[2] + r[2]]


def to_local_root(root: list[float], x: Vec) -> Vec:
    """World → creature-local: the inverse of :func:`to_world_root`."""
    c, s, squash = root[3], root[4], root[5]
    r = vq.yaw_unrotate(c, s, [x[0] - root[0], x[1] - root[1], x[2] - root[2]])
    sq = math.sqrt(squash)
    return [r[0] * sq, r[1] / squash, r[2] * sq]
