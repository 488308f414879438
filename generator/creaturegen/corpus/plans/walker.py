"""The walker body plan: a horizontal torso on 4, 6 or 8 legs, a quadruped mammal or an insect/arachnid."""

from __future__ import annotations

from ..creature import Creature
from ..features import add_head, add_spikes, add_tail
from ..vec import mirror


def gait_phases(count: int) -> list[tuple[float, float]]:
    """(left, right) gait phase per leg pair, front to back: alternating sides and neighbours, the
    tripod/tetrapod pattern of real walkers."""
    return [(0.0, 0.5) if i % 2 == 0 else (0.5, 0.0) for i in range(count // 2)]


def walker(c: Creature, legs: int, insect: bool) -> None:
    """A horizontal torso on ``legs`` legs: a quadruped mammal, or an insect/arachnid body."""
    rng = c.rng
    reach = rng.uniform(0.3, 0.8)
    upper = reach * rng.uniform(0.45, 0.55)
    lower = reach - upper
    length = rng.uniform(0.5, 1.2) * (1.2 if legs >= 6 else 1.0)
    radius = rng.uniform(0.12, 0.26) * (0.8 if insect else 1.0)
    hip_y = reach * rng.uniform(0.6, 0.9)
    body_y = hip_y + radius * rng.uniform(0.3, 0.6)
    tilt = rng.uniform(-0.05, 0.1)
    back, front = [0.0, body_y - tilt, -length / 2], [0.0, body_y + tilt, length / 2]
    taper = radius * rng.uniform(0.75, 1.0) if rng.random() < 0.4 else None
    body = c.capsule("body", None, back, front, radius, taper, colour=0)
    thick = rng.random() < 0.25 and not insect
    leg_r = radius * (rng.uniform(0.35, 0.5) if thick else rng.uniform(0.12, 0.3))
    leg_r = min(leg_r, 0.3 * min(upper, lower))
    names = {4: ("front", "hind"), 6: ("front", "mid", "rear"), 8: ("front", "second", "third", "rear")}
    zs = [length / 2 * (0.75 - 1.5 * i / max(1, legs // 2 - 1)) for i in range(legs // 2)]
    spread = radius * rng.uniform(0.55, 0.95)
    for (left_phase, right_phase), z, name in zip(gait_phases(legs), zs, names[legs], strict=True):
        hip = [spread, hip_y, z]
        c.leg(f"leg-{name}-left", body, hip, upper, lower, leg_r, left_phase, colour=2)
        c.leg(f"leg-{name}-right", body, mirror(hip), upper, lower, leg_r, right_phase, colour=2)
    head_r = radius * rng.uniform(0.55, 0.95)
    neck = rng.random() < 0.45 and not insect
    head_at = [
        0.0,
        body_y + radius * (rng.uniform(0.5, 1.2) if neck else rng.uniform(0.0, 0.4)),
        length / 2 + radius * (rng.uniform(0.9, 1.5) if neck else rng.uniform(0.55, 0.85)),
    ]
    add_head(c, body, head_at, head_r, front if neck else None, "insect" if insect else "mammal")
    if rng.random() < 0.3:
        add_spikes(c, body, back, front, radius)
    if insect and rng.random() < 0.6:
        ab_r = radius * rng.uniform(1.0, 1.5)
        c.sphere(
            "abdomen", body, [0.0, body_y + ab_r * 0.2, -length / 2 - ab_r * rng.uniform(0.5, 0.9)], ab_r
        )
    elif rng.random() < 0.7:
        add_tail(c, body, [0.0, body_y, -length / 2 - radius * 0.3], radius, length)
