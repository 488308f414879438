"""The biped body plan: an upright torso on two legs, with arms (sometimes clawed) and a head."""

from __future__ import annotations

from ..creature import Creature
from ..features import add_claws, add_head, add_tail
from ..vec import add, sub


def biped(c: Creature) -> None:
    """An upright torso on two legs, with arms and a head."""
    rng = c.rng
    reach = rng.uniform(0.5, 1.0)
    upper = reach * rng.uniform(0.45, 0.55)
    lower = reach - upper
    radius = rng.uniform(0.14, 0.28)
    torso = rng.uniform(0.35, 0.8)
    hip_y = reach * rng.uniform(0.85, 0.95)
    a, b = [0.0, hip_y + radius * 0.5, 0.0], [0.0, hip_y + radius * 0.5 + torso, rng.uniform(-0.02, 0.06)]
    body = c.capsule("body", None, a, b, radius, radius * rng.uniform(0.8, 1.15), colour=0)
    leg_r = min(radius * rng.uniform(0.25, 0.5), 0.3 * min(upper, lower))
    hip_x = max(radius * 0.55, leg_r * rng.uniform(1.5, 2.0))  # thighs clear of each other, as walkers' are
    for side, sign, phase in (("left", 1.0, 0.0), ("right", -1.0, 0.5)):
        c.leg(
            f"leg-{side}",
            body,
            [sign * hip_x, hip_y, rng.uniform(0.0, 0.1)],
            upper,
            lower,
            leg_r,
            phase,
            colour=2,
        )
    if rng.random() < 0.8:
        claws = rng.random() < 0.3
        arm = torso * rng.uniform(0.6, 1.0)
        arm_r = radius * rng.uniform(0.18, 0.35)
        for side, sign in (("left", 1.0), ("right", -1.0)):
            shoulder = [sign * radius * 0.85, b[1] - radius * 0.3, b[2]]
            hand = add(
                shoulder, [sign * arm * rng.uniform(0.2, 0.5), -arm * 0.8, arm * rng.uniform(0.1, 0.4)]
            )
            tip_r = arm_r * rng.uniform(0.55, 1.0)
            arm_id = c.capsule(f"arm-{side}", body, shoulder, hand, arm_r, tip_r, colour=1)
            if claws:
                add_claws(c, arm_id, hand, sub(hand, shoulder), tip_r, side)
    head_r = radius * rng.uniform(0.6, 1.0)
    neck = rng.random() < 0.5
    head_at = [0.0, b[1] + radius * 0.3 + head_r * (1.4 if neck else 0.7), b[2] + rng.uniform(0.0, 0.08)]
    add_head(c, body, head_at, head_r, b if neck else None, "mammal")
    if rng.random() < 0.35:
        add_tail(c, body, [0.0, a[1], -radius * 0.6], radius, torso)
