"""The still body plan (locomotion ``none``): a snail, a mushroom-like blob or a statue."""

from __future__ import annotations

from ..creature import Creature
from ..features import add_eyes, add_head
from ..vec import add


def still(c: Creature) -> None:
    """A creature that does not move: a snail, a mushroom-like blob or a statue on a pedestal."""
    rng = c.rng
    plan = rng.random()
    if plan < 0.4:
        foot = c.capsule("foot", None, [0.0, 0.08, -0.3], [0.0, 0.1, 0.3], 0.1, 0.08, colour=1)
        shell_r = rng.uniform(0.16, 0.28)
        c.sphere("shell", foot, [0.0, 0.1 + shell_r * 0.9, -0.05], shell_r, colour=0)
        head = c.sphere("head", foot, [0.0, 0.14, 0.36], 0.09, colour=1)
        for side, sign in (("left", 1.0), ("right", -1.0)):
            a = [sign * 0.03, 0.2, 0.38]
            c.capsule(f"stalk-{side}", head, a, add(a, [sign * 0.06, 0.18, 0.05]), 0.018, 0.012, colour=1)
    elif plan < 0.7:
        stem = c.capsule("stem", None, [0.0, 0.1, 0.0], [0.0, 0.5, 0.0], 0.12, 0.09, colour=3)
        c.sphere("cap", stem, [0.0, 0.55, 0.0], rng.uniform(0.2, 0.3), colour=0)
        add_eyes(c, stem, [0.0, 0.3, 0.0], 0.11, [0.0, 0.0, 1.0])
    else:
        radius = rng.uniform(0.18, 0.3)
        body = c.capsule("body", None, [0.0, radius, 0.0], [0.0, radius + 0.4, 0.0], radius, colour=0)
        head_r = radius * 0.8
        add_head(c, body, [0.0, radius + 0.4 + head_r * 1.1, 0.05], head_r, None, "mammal")
        for side, sign in (("left", 1.0), ("right", -1.0)):
            c.capsule(
                f"arm-{side}",
                body,
                [sign * radius * 0.8, radius + 0.3, 0.0],
                [sign * radius * 1.8, radius + 0.05, 0.12],
                radius * 0.25,
                radius * 0.18,
                colour=2,
            )
