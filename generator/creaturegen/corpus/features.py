"""Features a designer reaches for, added to a random creature's body plan: heads (on necks), eyes,
ears, horns, antennae, snouts and mandibles on heads (small parts on big ones), dorsal spikes, claws and
rope tails. Each draws its own sizes from the creature's random stream, in a fixed order.
"""

from __future__ import annotations

import math

from .creature import Creature
from .vec import Vec, add, lerp


def add_eyes(c: Creature, head: str, centre: Vec, r: float, forward: Vec) -> None:
    """Two small spheres on the head's front, sunk a third to two thirds of their radius into it."""
    rng = c.rng
    er = r * rng.uniform(0.16, 0.32)
    spread = rng.uniform(0.3, 0.55)
    up = rng.uniform(0.15, 0.45)
    sink = rng.uniform(0.35, 0.7) * er
    for side, sign in (("left", 1.0), ("right", -1.0)):
        d = [sign * spread, up, forward[2]]
        n = math.sqrt(sum(x * x for x in d))
        pos = [centre[i] + d[i] / n * (r + er - sink) for i in range(3)]
        c.sphere(f"eye-{side}", head, pos, er, colour=3)


def add_ears(c: Creature, head: str, centre: Vec, r: float, long: bool) -> None:
    """Cones rising from the top of the head, rooted inside it."""
    rng = c.rng
    length = r * (rng.uniform(1.4, 2.6) if long else rng.uniform(0.5, 1.0))
    base = r * rng.uniform(0.22, 0.38)
    tip = base * rng.uniform(0.3, 0.7)
    tilt = rng.uniform(0.2, 0.6)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        a = add(centre, [sign * r * 0.45, r * 0.6, -r * 0.1])
        b = add(a, [sign * length * tilt * 0.5, length, -length * rng.uniform(0.0, 0.4)])
        c.capsule(f"ear-{side}", head, a, b, base, tip, colour=1)


def add_horns(c: Creature, head: str, centre: Vec, r: float) -> None:
    rng = c.rng
    length = r * rng.uniform(0.6, 1.5)
    base = r * rng.uniform(0.12, 0.22)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        a = add(centre, [sign * r * 0.35, r * 0.7, r * 0.2])
        b = add(a, [sign * length * 0.5, length * 0.7, length * rng.uniform(0.1, 0.6)])
        c.capsule(f"horn-{side}", head, a, b, base, base * rng.uniform(0.2, 0.5), colour=3)


def add_antennae(c: Creature, head: str, centre: Vec, r: float) -> None:
    rng = c.rng
    length = r * rng.uniform(1.2, 2.5)
    base = r * rng.uniform(0.08, 0.14)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        a = add(centre, [sign * r * 0.35, r * 0.55, r * 0.5])
        b = add(a, [sign * length * 0.4, length * 0.6, length * 0.7])
        c.capsule(f"antenna-{side}", head, a, b, base, base * 0.6, colour=3)


def add_snout(c: Creature, head: str, centre: Vec, r: float) -> None:
    rng = c.rng
    length = r * rng.uniform(0.6, 1.4)
    a = add(centre, [0.0, -r * 0.2, r * 0.5])
    b = add(a, [0.0, -r * rng.uniform(0.0, 0.3), length])
    c.capsule("snout", head, a, b, r * rng.uniform(0.45, 0.7), r * rng.uniform(0.3, 0.45), colour=1)


def add_mandibles(c: Creature, head: str, centre: Vec, r: float) -> None:
    rng = c.rng
    length = r * rng.uniform(0.5, 1.0)
    base = r * rng.uniform(0.12, 0.2)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        a = add(centre, [sign * r * 0.4, -r * 0.35, r * 0.75])
        b = add(a, [-sign * length * 0.3, -length * 0.2, length])
        c.capsule(f"mandible-{side}", head, a, b, base, base * 0.4, colour=2)


def add_head(c: Creature, parent: str, at: Vec, r: float, neck_from: Vec | None, kind: str) -> str:
    """A head sphere at ``at`` (on a tapered neck from ``neck_from`` when given) with its features."""
    rng = c.rng
    owner = parent
    if neck_from is not None:
        neck_r = r * rng.uniform(0.45, 0.75)
        owner = c.capsule("neck", parent, neck_from, at, neck_r * rng.uniform(1.1, 1.4), neck_r, colour=0)
    head = c.sphere("head", owner, at, r, colour=1)
    if rng.random() < 0.8:
        add_eyes(c, head, at, r, [0.0, 0.0, 1.0])
    feature = rng.random()
    if kind == "insect":
        if feature < 0.6:
            add_antennae(c, head, at, r)
        if rng.random() < 0.4:
            add_mandibles(c, head, at, r)
    else:
        if feature < 0.35:
            add_ears(c, head, at, r, long=rng.random() < 0.4)
        elif feature < 0.55:
            add_horns(c, head, at, r)
        if rng.random() < 0.5:
            add_snout(c, head, at, r)
    return head


def add_spikes(c: Creature, body: str, back: Vec, front: Vec, radius: float) -> None:
    """A row of small cones along the top of the body (a dorsal ridge), each rooted inside it."""
    rng = c.rng
    count = rng.randint(2, 7)
    height = radius * rng.uniform(0.35, 0.8)
    base = radius * rng.uniform(0.12, 0.22)
    for i in range(count):
        t = (i + 0.5) / count
        root = add(lerp(back, front, t), [0.0, radius * 0.75, 0.0])
        tip = add(root, [0.0, height, -height * rng.uniform(0.1, 0.5)])
        c.capsule(f"spike-{i + 1}", body, root, tip, base, base * rng.uniform(0.15, 0.4), colour=3)


def add_claws(c: Creature, limb: str, hand: Vec, toward: Vec, r: float, side: str) -> None:
    """Two or three small claws at the end of an arm (a capsule), splayed around its axis."""
    rng = c.rng
    n = math.sqrt(sum(x * x for x in toward)) or 1.0
    axis = [x / n for x in toward]
    for i in range(rng.randint(2, 3)):
        spread = [0.35 * (i - 1), -0.2, 0.35]
        tip = add(hand, [(axis[k] + spread[k]) * r * 2.2 for k in range(3)])
        c.capsule(f"claw-{side}-{i + 1}", limb, hand, tip, r * 0.35, r * 0.12, colour=3)


def add_tail(c: Creature, parent: str, start: Vec, r_body: float, scale: float) -> None:
    rng = c.rng
    segments = rng.randint(3, 10)
    length = scale * rng.uniform(0.5, 1.4)
    r = r_body * rng.uniform(0.2, 0.45)
    c.rope("tail", parent, start, segments, length, r, rng.uniform(0.25, 0.8), colour=2)
