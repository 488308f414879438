"""Plausible random creatures: the project's own corpus, so the compiler is tuned against creatures nobody
here wrote rather than against a handful of examples.

A spec is drawn from one seed by a body plan per locomotion type (a walker's torso on legs, an upright
biped with arms, a hopper's round body, a flyer's wings, a swimmer's fins and tail, a still creature), then
features a designer reaches for: heads on necks, eyes, ears and horns on heads (small parts on big ones),
snouts, rope tails, tapered and thick limbs, 8-legged walkers; the default blend graph, an explicit binary
tree or n-ary groups; sizes from 0.1 to 5 (the spec's ``scale``). Everything is placed in creature space
first and written relative to the parent's anchor, the way the spec's rest layout reads it
(rig/layout.py), so the numbers look like hand-written ones. Pure: the same seed gives the same JSON.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field
from typing import Any

Vec = list[float]

#: Locomotion types the generator draws from (``random --locomotion``), with their share of a corpus.
LOCOMOTION_WEIGHTS: dict[str, float] = {
    "biped": 0.15,
    "quadruped": 0.2,
    "hexapod": 0.1,
    "octopod": 0.08,
    "hopper": 0.12,
    "flyer": 0.12,
    "swimmer": 0.13,
    "none": 0.1,
}
#: The spec's ``scale`` is drawn log-uniformly in this range (metres per authored unit).
SCALE_RANGE = (0.1, 5.0)
#: Part counts the generator aims for (features are added until the count is in range).
PART_RANGE = (4, 24)
PALETTES = (
    ("#6f9a54", "#8dbb6a", "#556f3f", "#d9c27a"),
    ("#7f8fba", "#ddad77", "#5a6485", "#f0e6d0"),
    ("#b5653a", "#e0b06e", "#7b4a2c", "#2b2b2b"),
    ("#5db4d1", "#d8b58c", "#2f6f8a", "#f5f5f5"),
    ("#8a8a8a", "#c0c0c0", "#4d4d4d", "#e8d44d"),
    ("#a05fa8", "#e5a1c9", "#5e2f66", "#fff3a0"),
    ("#3b5f8f", "#2c3e55", "#d9d2c0", "#c04040"),
    ("gray", "#ddd", "DarkSlateGray", "gold"),
    ("sienna", "wheat", "saddlebrown", "black"),
    ("seagreen", "palegreen", "darkolivegreen", "#fff"),
)


def _r3(v: Vec) -> Vec:
    """Three decimals, as a designer writes; -0.0 printed as 0."""
    return [round(c, 3) + 0.0 for c in v]


def _add(u: Vec, v: Vec) -> Vec:
    return [u[0] + v[0], u[1] + v[1], u[2] + v[2]]


def _sub(u: Vec, v: Vec) -> Vec:
    return [u[0] - v[0], u[1] - v[1], u[2] - v[2]]


def _lerp(u: Vec, v: Vec, t: float) -> Vec:
    return [u[i] + (v[i] - u[i]) * t for i in range(3)]


def _mirror(v: Vec) -> Vec:
    return [-v[0], v[1], v[2]]


@dataclass
class _Part:
    """A part placed in creature space; ``anchor`` is the world point its children hang from."""

    data: dict[str, Any]
    origin: Vec
    anchor: Vec
    radius: float
    parent: str | None
    children: list[str] = field(default_factory=list)


class _Creature:
    """Parts in creature space, written out relative to their parents' anchors."""

    def __init__(self, rng: random.Random, palette: tuple[str, ...]) -> None:
        self.rng = rng
        self.palette = palette
        self.parts: dict[str, _Part] = {}

    def _origin(self, parent: str | None) -> Vec:
        return [0.0, 0.0, 0.0] if parent is None else list(self.parts[parent].anchor)

    def _add(
        self,
        pid: str,
        shape: str,
        parent: str | None,
        fields: dict[str, Any],
        anchor: Vec,
        r: float,
        colour: int,
    ) -> str:
        origin = self._origin(parent)
        data: dict[str, Any] = {"id": pid, "shape": shape}
        if parent is not None:
            data["parent"] = parent
        for key, value in fields.items():
            data[key] = _r3(_sub(value, origin)) if key in ("a", "b", "offset", "hip") else value
        data["color"] = self.palette[colour % len(self.palette)]
        self.parts[pid] = _Part(data, origin, anchor, r, parent)
        if parent is not None:
            self.parts[parent].children.append(pid)
        return pid

    def capsule(
        self,
        pid: str,
        parent: str | None,
        a: Vec,
        b: Vec,
        r: float,
        r2: float | None = None,
        colour: int = 0,
        flap: float | None = None,
    ) -> str:
        shape = "capsule" if r2 is None or abs(r2 - r) < 1e-3 else "cone"
        fields: dict[str, Any] = {"a": a, "b": b, "r": round(r, 4)}
        if shape == "cone":
            fields["r2"] = round(float(r2 or r), 4)
        if flap is not None:
            fields["flap"] = round(flap, 3)
        return self._add(pid, shape, parent, fields, list(a), max(r, r2 or r), colour)

    def sphere(self, pid: str, parent: str | None, centre: Vec, r: float, colour: int = 0) -> str:
        return self._add(pid, "sphere", parent, {"offset": centre, "r": round(r, 4)}, list(centre), r, colour)

    def rope(
        self,
        pid: str,
        parent: str,
        start: Vec,
        segments: int,
        length: float,
        r: float,
        taper: float,
        colour: int = 0,
    ) -> str:
        fields = {
            "offset": start,
            "segments": segments,
            "length": round(length, 3),
            "r": round(r, 4),
            "taper": round(taper, 3),
        }
        return self._add(pid, "rope", parent, fields, list(start), r, colour)

    def leg(
        self,
        pid: str,
        parent: str,
        hip: Vec,
        upper: float,
        lower: float,
        r: float,
        phase: float,
        colour: int = 0,
    ) -> str:
        fields = {
            "hip": hip,
            "upper": round(upper, 3),
            "lower": round(lower, 3),
            "r": round(r, 4),
            "phase": phase,
        }
        return self._add(pid, "leg", parent, fields, list(hip), r, colour)

    def roots(self) -> list[str]:
        return [p for p, part in self.parts.items() if part.parent is None]


# --- features ----------------------------------------------------------------------------------------


def _eyes(c: _Creature, head: str, centre: Vec, r: float, forward: Vec) -> None:
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


def _ears(c: _Creature, head: str, centre: Vec, r: float, long: bool) -> None:
    """Cones rising from the top of the head, rooted inside it."""
    rng = c.rng
    length = r * (rng.uniform(1.4, 2.6) if long else rng.uniform(0.5, 1.0))
    base = r * rng.uniform(0.22, 0.38)
    tip = base * rng.uniform(0.3, 0.7)
    tilt = rng.uniform(0.2, 0.6)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        a = _add(centre, [sign * r * 0.45, r * 0.6, -r * 0.1])
        b = _add(a, [sign * length * tilt * 0.5, length, -length * rng.uniform(0.0, 0.4)])
        c.capsule(f"ear-{side}", head, a, b, base, tip, colour=1)


def _horns(c: _Creature, head: str, centre: Vec, r: float) -> None:
    rng = c.rng
    length = r * rng.uniform(0.6, 1.5)
    base = r * rng.uniform(0.12, 0.22)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        a = _add(centre, [sign * r * 0.35, r * 0.7, r * 0.2])
        b = _add(a, [sign * length * 0.5, length * 0.7, length * rng.uniform(0.1, 0.6)])
        c.capsule(f"horn-{side}", head, a, b, base, base * rng.uniform(0.2, 0.5), colour=3)


def _antennae(c: _Creature, head: str, centre: Vec, r: float) -> None:
    rng = c.rng
    length = r * rng.uniform(1.2, 2.5)
    base = r * rng.uniform(0.08, 0.14)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        a = _add(centre, [sign * r * 0.35, r * 0.55, r * 0.5])
        b = _add(a, [sign * length * 0.4, length * 0.6, length * 0.7])
        c.capsule(f"antenna-{side}", head, a, b, base, base * 0.6, colour=3)


def _snout(c: _Creature, head: str, centre: Vec, r: float) -> None:
    rng = c.rng
    length = r * rng.uniform(0.6, 1.4)
    a = _add(centre, [0.0, -r * 0.2, r * 0.5])
    b = _add(a, [0.0, -r * rng.uniform(0.0, 0.3), length])
    c.capsule("snout", head, a, b, r * rng.uniform(0.45, 0.7), r * rng.uniform(0.3, 0.45), colour=1)


def _mandibles(c: _Creature, head: str, centre: Vec, r: float) -> None:
    rng = c.rng
    length = r * rng.uniform(0.5, 1.0)
    base = r * rng.uniform(0.12, 0.2)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        a = _add(centre, [sign * r * 0.4, -r * 0.35, r * 0.75])
        b = _add(a, [-sign * length * 0.3, -length * 0.2, length])
        c.capsule(f"mandible-{side}", head, a, b, base, base * 0.4, colour=2)


def _head(c: _Creature, parent: str, at: Vec, r: float, neck_from: Vec | None, kind: str) -> str:
    """A head sphere at ``at`` (on a tapered neck from ``neck_from`` when given) with its features."""
    rng = c.rng
    owner = parent
    if neck_from is not None:
        neck_r = r * rng.uniform(0.45, 0.75)
        owner = c.capsule("neck", parent, neck_from, at, neck_r * rng.uniform(1.1, 1.4), neck_r, colour=0)
    head = c.sphere("head", owner, at, r, colour=1)
    if rng.random() < 0.8:
        _eyes(c, head, at, r, [0.0, 0.0, 1.0])
    feature = rng.random()
    if kind == "insect":
        if feature < 0.6:
            _antennae(c, head, at, r)
        if rng.random() < 0.4:
            _mandibles(c, head, at, r)
    else:
        if feature < 0.35:
            _ears(c, head, at, r, long=rng.random() < 0.4)
        elif feature < 0.55:
            _horns(c, head, at, r)
        if rng.random() < 0.5:
            _snout(c, head, at, r)
    return head


def _spikes(c: _Creature, body: str, back: Vec, front: Vec, radius: float) -> None:
    """A row of small cones along the top of the body (a dorsal ridge), each rooted inside it."""
    rng = c.rng
    count = rng.randint(2, 7)
    height = radius * rng.uniform(0.35, 0.8)
    base = radius * rng.uniform(0.12, 0.22)
    for i in range(count):
        t = (i + 0.5) / count
        root = _add(_lerp(back, front, t), [0.0, radius * 0.75, 0.0])
        tip = _add(root, [0.0, height, -height * rng.uniform(0.1, 0.5)])
        c.capsule(f"spike-{i + 1}", body, root, tip, base, base * rng.uniform(0.15, 0.4), colour=3)


def _claws(c: _Creature, limb: str, hand: Vec, toward: Vec, r: float, side: str) -> None:
    """Two or three small claws at the end of an arm (a capsule), splayed around its axis."""
    rng = c.rng
    n = math.sqrt(sum(x * x for x in toward)) or 1.0
    axis = [x / n for x in toward]
    for i in range(rng.randint(2, 3)):
        spread = [0.35 * (i - 1), -0.2, 0.35]
        tip = _add(hand, [(axis[k] + spread[k]) * r * 2.2 for k in range(3)])
        c.capsule(f"claw-{side}-{i + 1}", limb, hand, tip, r * 0.35, r * 0.12, colour=3)


def _tail(c: _Creature, parent: str, start: Vec, r_body: float, scale: float) -> None:
    rng = c.rng
    segments = rng.randint(3, 10)
    length = scale * rng.uniform(0.5, 1.4)
    r = r_body * rng.uniform(0.2, 0.45)
    c.rope("tail", parent, start, segments, length, r, rng.uniform(0.25, 0.8), colour=2)


# --- body plans ----------------------------------------------------------------------------------------


def _phases(count: int) -> list[tuple[float, float]]:
    """(left, right) gait phase per leg pair, front to back: alternating sides and neighbours, the
    tripod/tetrapod pattern of real walkers."""
    return [(0.0, 0.5) if i % 2 == 0 else (0.5, 0.0) for i in range(count // 2)]


def _walker(c: _Creature, legs: int, insect: bool) -> None:
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
    for (left_phase, right_phase), z, name in zip(_phases(legs), zs, names[legs], strict=True):
        hip = [spread, hip_y, z]
        c.leg(f"leg-{name}-left", body, hip, upper, lower, leg_r, left_phase, colour=2)
        c.leg(f"leg-{name}-right", body, _mirror(hip), upper, lower, leg_r, right_phase, colour=2)
    head_r = radius * rng.uniform(0.55, 0.95)
    neck = rng.random() < 0.45 and not insect
    head_at = [
        0.0,
        body_y + radius * (rng.uniform(0.5, 1.2) if neck else rng.uniform(0.0, 0.4)),
        length / 2 + radius * (rng.uniform(0.9, 1.5) if neck else rng.uniform(0.55, 0.85)),
    ]
    _head(c, body, head_at, head_r, front if neck else None, "insect" if insect else "mammal")
    if rng.random() < 0.3:
        _spikes(c, body, back, front, radius)
    if insect and rng.random() < 0.6:
        ab_r = radius * rng.uniform(1.0, 1.5)
        c.sphere(
            "abdomen", body, [0.0, body_y + ab_r * 0.2, -length / 2 - ab_r * rng.uniform(0.5, 0.9)], ab_r
        )
    elif rng.random() < 0.7:
        _tail(c, body, [0.0, body_y, -length / 2 - radius * 0.3], radius, length)


def _biped(c: _Creature) -> None:
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
            hand = _add(
                shoulder, [sign * arm * rng.uniform(0.2, 0.5), -arm * 0.8, arm * rng.uniform(0.1, 0.4)]
            )
            tip_r = arm_r * rng.uniform(0.55, 1.0)
            arm_id = c.capsule(f"arm-{side}", body, shoulder, hand, arm_r, tip_r, colour=1)
            if claws:
                _claws(c, arm_id, hand, _sub(hand, shoulder), tip_r, side)
    head_r = radius * rng.uniform(0.6, 1.0)
    neck = rng.random() < 0.5
    head_at = [0.0, b[1] + radius * 0.3 + head_r * (1.4 if neck else 0.7), b[2] + rng.uniform(0.0, 0.08)]
    _head(c, body, head_at, head_r, b if neck else None, "mammal")
    if rng.random() < 0.35:
        _tail(c, body, [0.0, a[1], -radius * 0.6], radius, torso)


def _kangaroo(c: _Creature) -> None:
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
        shoulder = _add(front, [sign * radius * 0.45, -radius * 0.5, radius * 0.3])
        c.capsule(
            f"arm-{side}",
            body,
            shoulder,
            _add(shoulder, [0.0, -radius * 0.7, radius * 0.35]),
            radius * 0.16,
            radius * 0.12,
            colour=1,
        )
    head_r = radius * rng.uniform(0.45, 0.6)
    _head(c, body, _add(front, [0.0, head_r * 1.6, radius * 0.5]), head_r, None, "mammal")
    _tail(c, body, _add(back, [0.0, -radius * 0.5, -radius * 0.3]), radius * 1.6, reach * 1.4)


def _hopper(c: _Creature) -> None:
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
                _add(foot, [0.0, 0.0, radius * rng.uniform(0.6, 1.1)]),
                radius * 0.28,
                colour=2,
            )
    head_r = radius * rng.uniform(0.6, 0.9)
    _head(c, body, _add(top, [0.0, head_r * 0.9, radius * 0.2]), head_r, None, "mammal")
    if rng.random() < 0.6:
        _tail(c, body, [0.0, radius * 1.1, -radius * 0.8], radius, height + radius)


def _flyer(c: _Creature) -> None:
    """A compact body with two flapping wings (and sometimes a second pair), a head and a tail fin."""
    rng = c.rng
    radius = rng.uniform(0.1, 0.22)
    length = rng.uniform(0.25, 0.6)
    horizontal = rng.random() < 0.5
    a = [0.0, 0.1, -length / 2] if horizontal else [0.0, 0.08, 0.0]
    b = [0.0, 0.1, length / 2] if horizontal else [0.0, 0.08 + length, 0.0]
    body = c.capsule("body", None, a, b, radius, radius * rng.uniform(0.7, 1.0), colour=0)
    mid = _lerp(a, b, 0.6)
    span = rng.uniform(0.4, 1.1)
    pairs = 2 if rng.random() < 0.3 else 1
    for pair in range(pairs):
        shift = [0.0, 0.0, -0.15 * length * pair] if horizontal else [0.0, -0.2 * length * pair, 0.0]
        for side, sign in (("left", 1.0), ("right", -1.0)):
            root = _add(mid, [sign * radius * 0.8, 0.0, 0.0])
            root = _add(root, shift)
            tip = _add(
                root, [sign * span * (1.0 - 0.3 * pair), rng.uniform(0.0, 0.15), rng.uniform(-0.1, 0.1)]
            )
            wr = radius * rng.uniform(0.25, 0.45)
            name = f"wing-{side}" if pair == 0 else f"hindwing-{side}"
            c.capsule(
                name, body, root, tip, wr, wr * rng.uniform(0.2, 0.4), colour=1, flap=rng.uniform(0.2, 0.7)
            )
    head_r = radius * rng.uniform(0.6, 0.95)
    head_at = (
        _add(b, [0.0, head_r * 0.4, radius * 0.6]) if horizontal else _add(b, [0.0, head_r * 0.6, radius])
    )
    _head(c, body, head_at, head_r, None, "insect" if rng.random() < 0.4 else "mammal")
    tail_a = _add(a, [0.0, 0.0, -radius * 0.4])
    c.capsule(
        "tail-fin",
        body,
        tail_a,
        _add(tail_a, [0.0, -0.05, -rng.uniform(0.2, 0.45)]),
        radius * 0.3,
        radius * 0.1,
        colour=2,
    )


def _swimmer(c: _Creature) -> None:
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
        _add(b, [0.0, 0.0, radius * 0.2]),
        _add(b, [0.0, rng.uniform(-0.05, 0.05), radius * rng.uniform(0.8, 1.6)]),
        head_r,
        head_r * rng.uniform(0.5, 0.8),
        colour=1,
    )
    if rng.random() < 0.7:
        _eyes(c, head, _add(b, [0.0, 0.0, radius * 0.6]), head_r, [0.0, 0.0, 1.0])
    if rng.random() < 0.7:
        fin_a = _lerp(a, b, 0.55)
        fin_a = _add(fin_a, [0.0, radius * 0.7, 0.0])
        c.capsule(
            "dorsal-fin",
            body,
            fin_a,
            _add(fin_a, [0.0, radius * rng.uniform(0.7, 1.4), -length * 0.3]),
            radius * 0.18,
            radius * 0.08,
            colour=2,
        )
    elif rng.random() < 0.4:
        _spikes(c, body, a, b, radius)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        root = _add(_lerp(a, b, 0.65), [sign * radius * 0.6, -radius * 0.3, 0.0])
        c.capsule(
            f"fin-{side}",
            body,
            root,
            _add(root, [sign * radius * rng.uniform(1.2, 2.5), -radius * 0.4, -radius * 0.8]),
            radius * rng.uniform(0.12, 0.2),
            radius * 0.06,
            colour=2,
        )
    c.rope(
        "tail",
        body,
        _add(a, [0.0, 0.0, -radius * 0.3]),
        rng.randint(4, 10),
        length * rng.uniform(0.5, 1.1),
        radius * rng.uniform(0.3, 0.5),
        rng.uniform(0.3, 0.7),
        colour=2,
    )


def _still(c: _Creature) -> None:
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
            c.capsule(f"stalk-{side}", head, a, _add(a, [sign * 0.06, 0.18, 0.05]), 0.018, 0.012, colour=1)
    elif plan < 0.7:
        stem = c.capsule("stem", None, [0.0, 0.1, 0.0], [0.0, 0.5, 0.0], 0.12, 0.09, colour=3)
        c.sphere("cap", stem, [0.0, 0.55, 0.0], rng.uniform(0.2, 0.3), colour=0)
        _eyes(c, stem, [0.0, 0.3, 0.0], 0.11, [0.0, 0.0, 1.0])
    else:
        radius = rng.uniform(0.18, 0.3)
        body = c.capsule("body", None, [0.0, radius, 0.0], [0.0, radius + 0.4, 0.0], radius, colour=0)
        head_r = radius * 0.8
        _head(c, body, [0.0, radius + 0.4 + head_r * 1.1, 0.05], head_r, None, "mammal")
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


# --- blends ----------------------------------------------------------------------------------------------


def _ref(c: _Creature, pid: str, nodes: dict[str, str]) -> dict[str, str]:
    return {"node": nodes[pid]} if pid in nodes else {"part": pid}


def _tree_blend(c: _Creature) -> dict[str, Any]:
    """A binary tree following the parent hierarchy: each part absorbs its children's subtrees in turn,
    with a width a designer would pick (a fraction of the thinner side's radius)."""
    rng = c.rng
    nodes: list[dict[str, Any]] = []
    subtree: dict[str, str] = {}

    def fold(pid: str) -> float:
        part = c.parts[pid]
        radius = part.radius
        left: dict[str, str] = {"part": pid}
        for child in part.children:
            child_r = fold(child)
            k = max(0.004, rng.uniform(0.3, 0.6) * min(radius, child_r))
            node_id = f"{pid}-{child}"
            nodes.append({"id": node_id, "left": left, "right": _ref(c, child, subtree), "k": round(k, 4)})
            left = {"node": node_id}
        if "node" in left:
            subtree[pid] = left["node"]
        return radius

    roots = c.roots()
    for root in roots:
        fold(root)
    return {"mode": "tree", "roots": [_ref(c, r, subtree) for r in roots], "nodes": nodes}


def _nary_blend(c: _Creature) -> dict[str, Any]:
    """n-ary groups: a part and its children's subtrees in one order-independent group."""
    rng = c.rng
    groups: list[dict[str, Any]] = []
    subtree: dict[str, str] = {}

    def fold(pid: str) -> float:
        part = c.parts[pid]
        if not part.children:
            return part.radius
        members = [{"part": pid}]
        smallest = part.radius
        for child in part.children:
            smallest = min(smallest, fold(child))
            members.append(_ref(c, child, subtree))
        k = max(0.004, rng.uniform(0.15, 0.35) * smallest)
        subtree[pid] = f"{pid}-group"
        groups.append({"id": subtree[pid], "members": members, "kernel": "log-sum-exp", "k": round(k, 4)})
        return part.radius

    roots = c.roots()
    for root in roots:
        fold(root)
    return {"mode": "symmetric-nary", "roots": [_ref(c, r, subtree) for r in roots], "groups": groups}


# --- the spec --------------------------------------------------------------------------------------------


def _locomotion(kind: str, c: _Creature, rng: random.Random) -> dict[str, Any] | None:
    size = max(
        abs(v)
        for p in c.parts.values()
        for key in ("a", "b", "offset", "hip")
        for v in (p.data.get(key) or [0.0])
    )
    if kind in ("biped", "quadruped", "hexapod", "octopod"):
        legs = [p.data for p in c.parts.values() if p.data["shape"] == "leg"]
        reach = min(leg["upper"] + leg["lower"] for leg in legs)
        return {
            "type": kind,
            "speed": round(rng.uniform(0.3, 1.4), 3),
            "stepLength": round(reach * rng.uniform(0.35, 0.7), 3),
            "stepHeight": round(reach * rng.uniform(0.1, 0.25), 3),
        }
    if kind == "hopper":
        return {
            "type": "hopper",
            "speed": round(rng.uniform(0.4, 1.2), 3),
            "hopLength": round(rng.uniform(0.4, 1.4), 3),
            "hopHeight": round(rng.uniform(0.3, 1.0), 3),
        }
    if kind == "flyer":
        return {
            "type": "flyer",
            "speed": round(rng.uniform(0.5, 1.5), 3),
            "altitude": round(rng.uniform(1.0, 3.0), 3),
            "radius": round(rng.uniform(1.0, 3.0) + size, 3),
        }
    if kind == "swimmer":
        return {
            "type": "swimmer",
            "speed": round(rng.uniform(0.3, 1.0), 3),
            "undulation": round(rng.uniform(0.1, 0.4), 3),
            "buoyancy": round(rng.uniform(0.85, 1.1), 3),
        }
    return None


def random_creature(seed: int, locomotion: str | None = None) -> dict[str, Any]:
    """One plausible creature spec (a JSON-ready dict) drawn from ``seed``; ``locomotion`` pins its type."""
    rng = random.Random(seed)
    kinds = list(LOCOMOTION_WEIGHTS)
    kind = locomotion or rng.choices(kinds, weights=[LOCOMOTION_WEIGHTS[k] for k in kinds])[0]
    if kind not in LOCOMOTION_WEIGHTS:
        raise ValueError(f"unknown locomotion {kind!r} (known: {', '.join(kinds)})")
    c = _Creature(rng, rng.choice(PALETTES))
    if kind in ("quadruped", "hexapod", "octopod"):
        legs = {"quadruped": 4, "hexapod": 6, "octopod": 8}[kind]
        _walker(c, legs, insect=legs >= 6 or rng.random() < 0.15)
    elif kind == "biped":
        _biped(c)
    elif kind == "hopper":
        _hopper(c)
    elif kind == "flyer":
        _flyer(c)
    elif kind == "swimmer":
        _swimmer(c)
    else:
        _still(c)
    spec: dict[str, Any] = {
        "name": f"Random {kind.capitalize()} {seed}",
        "seed": seed % (2**32),
        "scale": round(math.exp(rng.uniform(math.log(SCALE_RANGE[0]), math.log(SCALE_RANGE[1]))), 3),
    }
    loco = _locomotion(kind, c, rng)
    if loco is not None:
        spec["locomotion"] = loco
    spec["parts"] = [p.data for p in c.parts.values()]
    style = rng.random()
    if style < 0.2:
        spec["blend"] = _tree_blend(c)
    elif style < 0.35:
        spec["blend"] = _nary_blend(c)
    return spec
