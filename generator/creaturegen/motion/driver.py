"""The fixed-step driver, the Python reference of core/motion/driver.js.

Integer ticks are authoritative. Render frames feed wall-clock ``dt``, clamped to [0, MAX_FRAME_S]; the
accumulator is capped at MAX_ACCUMULATOR_S so a hitch never triggers a catch-up storm; ``alpha`` says how
far the render pose lies between the previous and the current fixed step (feet never pop on hitches).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from . import quat as vq

MAX_FRAME_S: Final = 0.25
MAX_ACCUMULATOR_S: Final = 0.25


@dataclass
class Driver:
    hz: int
    accumulator: float = 0.0
    alpha: float = 0.0

    def advance(self, dt: float) -> int:
        step = 1.0 / self.hz
        clamped = min(dt, MAX_FRAME_S) if dt > 0.0 else 0.0
        self.accumulator = min(self.accumulator + clamped, MAX_ACCUMULATOR_S)
        steps = 0
        while self.accumulator >= step:
            self.accumulator -= step
            steps += 1
        self.alpha = self.accumulator / step
        return steps


def interpolate_root(prev: list[float], cur: list[float], alpha: float) -> list[float]:
    """Position and squash lerped; the heading (cos, sin) lerped and renormalised."""
    c = prev[3] + (cur[3] - prev[3]) * alpha
    s = prev[4] + (cur[4] - prev[4]) * alpha
    n = math.sqrt(c * c + s * s)
    return [
        prev[0] + (cur[0] - prev[0]) * alpha,
        prev[1] + (cur[1] - prev[1]) * alpha,
        prev[2] + (cur[2] - prev[2]) * alpha,
        c / n,
        s / n,
        prev[5] + (cur[5] - prev[5]) * alpha,
    ]


def interpolate_slot(
    q0: vq.Quat, t0: vq.Vec, q1: vq.Quat, t1: vq.Vec, alpha: float
) -> tuple[vq.Quat, vq.Vec]:
    """Normalised lerp of the quaternion on q0's hemisphere, lerp of the translation."""
    sign = -1.0 if q0[0] * q1[0] + q0[1] * q1[1] + q0[2] * q1[2] + q0[3] * q1[3] < 0.0 else 1.0
    q = [q0[i] + (sign * q1[i] - q0[i]) * alpha for i in range(4)]
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return [q[0] / n, q[1] / n, q[2] / n, q[3] / n], [t0[i] + (t1[i] - t0[i]) * alpha for i in range(3)]
