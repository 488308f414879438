"""The swimmer body plan: a horizontal streamlined body with fins and a rope tail."""

from __future__ import annotations

from ..creature import Creature
from ..features import add_eyes, add_spikes
from ..vec import add, lerp


def swimmer(c: Creature) -> None:
    """A horizontal streamlined body with fins and a rope tail."""
    rng = c.rng
    radius = rng.uniform(0.12, 0.3)
    length = rng.uniform(0.4, 1.2)
    y = radius + rng.uniform(0.05, 0.2)
    a, b = [0.0, y, -length / 2], [0.0, y + rng.uniform(-0.05, 0.15), length / 2]
    body = c.capsule("body", None, a, b, radius, radius * rng.uniform(0.7, 1.0), colour=0)
    head_r = radius * rng.uniform(0.6, 0.9)
    head = c.capsule(
        "head",
        body,
        add(b, [0.0, 0.0, radius * 0.2]),
        add(b, [0.0, rng.uniform(-0.05, 0.05), radius * rng.uniform(0.8, 1.6)]),
        head_r,
        head_r * rng.uniform(0.5, 0.8),
        colour=1,
    )
    if rng.random() < 0.7:
        add_eyes(c, head, add(b, [0.0, 0.0, radius * 0.6]), head_r, [0.0, 0.0, 1.0])
    if rng.random() < 0.7:
        fin_a = lerp(a, b, 0.55)
        fin_a = add(fin_a, [0.0, radius * 0.7, 0.0])
        c.capsule(
            "dorsal-fin",
            body,
            fin_a,
            add(fin_a, [0.0, radius * rng.uniform(0.7, 1.4), -length * 0.3]),
            radius * 0.18,
            radius * 0.08,
            colour=2,
        )
    elif rng.random() < 0.4:
        add_spikes(c, body, a, b, radius)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        root = add(lerp(a, b, 0.65), [sign * radius * 0.6, -radius * 0.3, 0.0])
        c.capsule(
            f"fin-{side}",
            body,
            root,
            add(root, [sign * radius * rng.uniform(1.2, 2.5), -radius * 0.4, -radius * 0.8]),
            radius * rng.uniform(0.12, 0.2),
            radius * 0.06,
            colour=2,
        )
    c.rope(
        "tail",
        body,
        add(a, [0.0, 0.0, -radius * 0.3]),
        rng.randint(4, 10),
        length * rng.uniform(0.5, 1.1),
        radius * rng.uniform(0.3, 0.5),
        rng.uniform(0.3, 0.7),
        colour=2,
    )
