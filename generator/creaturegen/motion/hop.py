"""The hop: a hopper's root in closed form (idle, crouch, air, landing), its gates, and its two legs.

The root's height over a hop cycle is known in closed form, so the apex is checked against it every cycle
(a hopper on legs also sinks on them in the crouch and the landing, by the derived ``dip``). A hopper's
legs plant, push off, tuck and land together (not by phase group as a walker's, gait.py); they share the
walker's leg placement (gait.place_leg).
"""

from __future__ import annotations

import math

from ..model.trig import psin
from .data import MotionData
from .derived import Derived
from .gait import count_planted, home, place_leg
from .providers import Frame, to_world
from .root import to_local_root
from .state import MotionState


def hop_at(data: MotionData, d: Derived, n: int) -> tuple[float, float, float]:
    """(distance along the path, height above the support, squash) of the hopper at tick ``n``. In the
    crouch and the landing a hopper on legs also sinks on them (``dip``, 0 without legs)."""
    c = data.constants
    hop_length = data.hop_length if data.speed > 0.0 else 0.0
    k, m = divmod(n, d.hop_cycle)
    if m < d.hop_idle:
        return k * hop_length, 0.0, 1.0
    m -= d.hop_idle
    if m < d.crouch:
        sink = psin(math.pi * (m / d.crouch))
        return k * hop_length, 0.0 - d.dip * sink, 1.0 - c.hop_squash * sink
    m -= d.crouch
    if m < d.air:
        ts = m * d.dt
        tau = m / d.air
        e = 2.0 * tau - 1.0
        y = d.v0 * ts - 0.5 * d.g * ts * ts
        return k * hop_length + hop_length * tau, y, 1.0 + c.hop_stretch * (e * e)
    m -= d.air
    sink = psin(math.pi * (m / d.land))
    return (k + 1) * hop_length, 0.0 - d.dip * sink, 1.0 - c.hop_squash * sink


def hop_gates(m: MotionState, n: int, root: list[float]) -> None:
    """The squash's determinant every tick, and the height at the apex tick against the closed form."""
    squash = root[5]
    k = 1.0 / math.sqrt(squash)
    m.gates.squash_det = max(m.gates.squash_det, abs(k * squash * k - 1.0))
    d = m.d
    if n % d.hop_cycle == d.hop_idle + d.crouch + d.half_air:
        _, lift, _ = hop_at(m.data, d, n)
        m.gates.apex_error = max(m.gates.apex_error, abs(lift - d.apex))
        m.gates.apex_squash = squash


def hop_legs(m: MotionState, n: int, frame: Frame, integrate: bool) -> None:
    """A hopper's two hind legs, together: planted on the support while the body is on it (idle, crouch,
    landing), their plants fixed in the support frame while the IK bends them under the sinking, squashed
    body; airborne from the first air tick, when each foot leaves its take-off plant (s), is drawn up
    toward its hip (``tuck`` of the rest hip-foot distance) at the apex and reaches for its landing plant
    (t): the rest foot under the root at the landing tick, known in closed form when it takes off. The
    target blends s and t (smoothstep σ(τ)) in the creature frame, pulled toward the tuck by
    (4τ(1 − τ))², so a leg first stretches toward the ground it left (the push-off), then folds, then
    stretches toward the ground ahead."""
    d = m.d
    phase = n % d.hop_cycle
    airborne = d.hop_idle + d.crouch <= phase < d.hop_idle + d.crouch + d.air
    swinging = 0
    for leg, foot in zip(m.data.legs, m.feet, strict=True):
        if not integrate:
            foot.planted, foot.p = True, home(leg, frame, m.root)
        elif foot.planted and airborne:
            foot.planted, foot.n0, foot.s = False, n, list(foot.p)
            foot.t = home(leg, *m.root_at(n + d.air))
            m.gates.steps += 1
        elif not foot.planted and not airborne:
            foot.planted, foot.p = True, list(foot.t)
        if foot.planted:
            target = to_local_root(m.root, to_world(frame, foot.p))
        else:
            swinging += 1
            tau = (n - foot.n0) / d.air
            sigma = tau * tau * (3.0 - 2.0 * tau)
            arc = 4.0 * tau * (1.0 - tau)
            pull = arc * arc
            a = to_local_root(m.root, to_world(frame, foot.s))
            b = to_local_root(m.root, to_world(frame, foot.t))
            hip, rest, tuck = leg.hip, leg.foot, leg.tuck
            target = [0.0, 0.0, 0.0]
            for k in range(3):
                base = a[k] + (b[k] - a[k]) * sigma
                tucked = hip[k] + (rest[k] - hip[k]) * tuck
                target[k] = base + (tucked - base) * pull
        place_leg(m, leg, foot, target, frame)
    count_planted(m, swinging)
