"""Swimming: a swimmer follows the water's free surface at its buoyancy depth, and undulates.

Stage 1 of a tick (simulate.py) for a swimmer: its height is not closed form but a critically damped
response (at ``swimResponse·√(g/L)`` rad/s, derived.py) toward the injected water's free surface less its
depth, integrated tick by tick; a material current, where the water represents one, carries its path's
centre. Stage 2 (the base pose): an undulation about Y at every skeleton root, at the Strouhal frequency.
"""

from __future__ import annotations

import math
from typing import Final

from ..model.trig import psin
from . import quat as vq
from .data import MotionData
from .derived import Derived
from .root import path
from .state import MotionState

Y_AXIS: Final = [0.0, 1.0, 0.0]


def follow_surface(m: MotionState, n: int, integrate: bool) -> None:
    """The swimmer's height and vertical speed at tick ``n`` (set on the target at reset), the current's
    drift of its path, and the tracking gate after 2 s."""
    d, data = m.d, m.data
    time = n * d.dt
    u, w, _ = path(m, data.speed * time)
    assert m.water is not None
    sample = m.water.sample(u, w, time)
    eta = sample["freeSurfacePoint"][1]
    target = eta - d.swim_depth - data.centre_y
    target_v = sample["geometricNormalVelocityMps"][0] / sample["freeSurfaceNormal"][1]
    if not integrate:
        m.swim_y, m.swim_vy = target, target_v
    else:
        om = d.swim_omega
        acc = om * om * (target - m.swim_y) + 2.0 * om * (target_v - m.swim_vy)
        m.swim_vy = m.swim_vy + acc * d.dt
        m.swim_y = m.swim_y + m.swim_vy * d.dt
    current = sample.get("materialCurrentVelocityMps")
    if current is not None:
        m.centre[0] = m.centre[0] + current[0] * d.dt
        m.centre[2] = m.centre[2] + current[2] * d.dt
    if time >= 2.0:
        m.gates.swim_tracking = max(m.gates.swim_tracking, abs(m.swim_y - target))


def undulation_locals(data: MotionData, d: Derived, time: float) -> dict[int, list[float]]:
    """Slot → local rotation of a swimmer at ``time``: its undulation at the roots."""
    locals_: dict[int, list[float]] = {}
    angle = data.undulation * psin(2.0 * math.pi * d.undulation_hz * time)
    for r in data.roots:
        locals_[r] = vq.axis_angle(Y_AXIS, angle)
    return locals_
