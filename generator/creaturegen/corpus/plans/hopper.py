"""The hopper body plan: a round upright body that hops, or a kangaroo on its two hind legs."""

from __future__ import annotations

from ..creature import Creature
from ..features import add_head, add_tail
from ..vec import add


def _kangaroo(c: Creature) -> None:
    """A hopper on two hind legs: a body leaning forward over hips under its rear, a thick rope tail,
    short arms and a head with long ears."""
    rng = c.rng
    reach = rng.uniform(0.4, 0.7)
    upper = reach * rng.uniform(0.42, 0.5)
    lower = reach - upper
    radius = rng.uniform(0.14, 0.24)
    hip_y = reach * rng.uniform(0.8, 0.95)
    back = [0.0, hip_y + radius * 0.4, -radius * 0.6]
    front = [0.0, back[1] + rng.uniform(0.2, 0.4), back[2] + rng.uniform(0.25, 0.45)]
    body = c.capsule("body", None, back, front, radius, radius * rng.uniform(0.65, 0.85), colour=0)
    leg_r = min(radius * rng.uniform(0.25, 0.35), 0.3 * min(upper, lower))
    hip_x = max(radius * 0.5, leg_r * rng.uniform(1.5, 2.0))
    for side, sign in (("left", 1.0), ("right", -1.0)):
        c.leg(
            f"leg-{side}",
            body,
            [sign * hip_x, hip_y, back[2] + radius * 0.9],
            upper,
            lower,
            leg_r,
            0.0,
            colour=2,
        )
        shoulder = add(front, [sign * radius * 0.45, -radius * 0.5, radius * 0.3])
        c.capsule(
            f"arm-{side}",
            body,
            shoulder,
            add(shoulder, [0.0, -radius * 0.7, radius * 0.35]),
            radius * 0.16,
            radius * 0.12,
            colour=1,
        )
    head_r = radius * rng.uniform(0.45, 0.6)
    add_head(c, body, add(front, [0.0, head_r * 1.6, radius * 0.5]), head_r, None, "mammal")
    add_tail(c, body, add(back, [0.0, -radius * 0.5, -radius * 0.3]), radius * 1.6, reach * 1.4)


def hopper(c: Creature) -> None:
    """A round upright body that hops (a slime, a bunny, a bean) or a kangaroo on its two legs."""
    rng = c.rng
    if rng.random() < 0.35:
        _kangaroo(c)
        return
    radius = rng.uniform(0.18, 0.35)
    height = rng.uniform(0.2, 0.8)
    body = c.capsule(
        "body",
        None,
        [0.0, radius, 0.0],
        [0.0, radius + height, rng.uniform(0.0, 0.1)],
        radius,
        radius * rng.uniform(0.7, 1.05),
        colour=0,
    )
    top = [0.0, radius + height, 0.0]
    if rng.random() < 0.6:
        c.sphere(
            "belly",
            body,
            [0.0, radius + height * 0.35, radius * 0.45],
            radius * rng.uniform(0.6, 0.85),
            colour=1,
        )
    for side, sign in (("left", 1.0), ("right", -1.0)):
        if rng.random() < 0.6:
            foot = [sign * radius * 0.55, radius * 0.25, radius * 0.4]
            c.capsule(
                f"foot-{side}",
                body,
                foot,
                add(foot, [0.0, 0.0, radius * rng.uniform(0.6, 1.1)]),
                radius * 0.28,
                colour=2,
            )
    head_r = radius * rng.uniform(0.6, 0.9)
    add_head(c, body, add(top, [0.0, head_r * 0.9, radius * 0.2]), head_r, None, "mammal")
    if rng.random() < 0.6:
        add_tail(c, body, [0.0, radius * 1.1, -radius * 0.8], radius, height + radius)
