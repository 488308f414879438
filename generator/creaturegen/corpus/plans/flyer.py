"""The flyer body plan: a compact body with flapping wings, a head and a tail fin."""

from __future__ import annotations

from ..creature import Creature
from ..features import add_head
from ..vec import add, lerp


def flyer(c: Creature) -> None:
    """A compact body with two flapping wings (and sometimes a second pair), a head and a tail fin."""
    rng = c.rng
    radius = rng.uniform(0.1, 0.22)
    length = rng.uniform(0.25, 0.6)
    horizontal = rng.random() < 0.5
    a = [0.0, 0.1, -length / 2] if horizontal else [0.0, 0.08, 0.0]
    b = [0.0, 0.1, length / 2] if horizontal else [0.0, 0.08 + length, 0.0]
    body = c.capsule("body", None, a, b, radius, radius * rng.uniform(0.7, 1.0), colour=0)
    mid = lerp(a, b, 0.6)
    span = rng.uniform(0.4, 1.1)
    pairs = 2 if rng.random() < 0.3 else 1
    for pair in range(pairs):
        shift = [0.0, 0.0, -0.15 * length * pair] if horizontal else [0.0, -0.2 * length * pair, 0.0]
        for side, sign in (("left", 1.0), ("right", -1.0)):
            root = add(mid, [sign * radius * 0.8, 0.0, 0.0])
            root = add(root, shift)
            tip = add(
                root, [sign * span * (1.0 - 0.3 * pair), rng.uniform(0.0, 0.15), rng.uniform(-0.1, 0.1)]
            )
            wr = radius * rng.uniform(0.25, 0.45)
            name = f"wing-{side}" if pair == 0 else f"hindwing-{side}"
            c.capsule(
                name, body, root, tip, wr, wr * rng.uniform(0.2, 0.4), colour=1, flap=rng.uniform(0.2, 0.7)
            )
    head_r = radius * rng.uniform(0.6, 0.95)
    head_at = add(b, [0.0, head_r * 0.4, radius * 0.6]) if horizontal else add(b, [0.0, head_r * 0.6, radius])
    add_head(c, body, head_at, head_r, None, "insect" if rng.random() < 0.4 else "mammal")
    tail_a = add(a, [0.0, 0.0, -radius * 0.4])
    c.capsule(
        "tail-fin",
        body,
        tail_a,
        add(tail_a, [0.0, -0.05, -rng.uniform(0.2, 0.45)]),
        radius * 0.3,
        radius * 0.1,
        colour=2,
    )
