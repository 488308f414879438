"""Flight: a flyer circles its path at its altitude (closed form, simulate.Motion.root_at), banked into the
turn, its wings flapping.

Stage 2 of a tick (simulate.py, the base pose): the flyer's local rotations, a constant bank about Z at
every skeleton root (the coordinated turn's, atan2(v², gR)) and a flap about Z at every wing,
``sign·amplitude·sin(2πft)`` at the Strouhal frequency (both derived.py); base_pose.py composes them down
the skeleton.
"""

from __future__ import annotations

import math
from typing import Final

from ..model.trig import psin
from . import quat as vq
from .data import MotionData
from .derived import Derived

Z_AXIS: Final = [0.0, 0.0, 1.0]


def wing_locals(data: MotionData, d: Derived, time: float) -> dict[int, list[float]]:
    """Slot → local rotation of a flyer at ``time``: its bank at the roots, its flap at the wings."""
    locals_: dict[int, list[float]] = {}
    for r in data.roots:
        locals_[r] = [0.0, 0.0, d.bank_half_sin, d.bank_half_cos]
    flap = psin(2.0 * math.pi * d.flap_hz * time)
    for wing in data.wings:
        locals_[wing.slot] = vq.axis_angle(Z_AXIS, wing.sign * wing.amplitude * flap)
    return locals_
