"""Rest layout: where each part's primitive slots sit before any motion, in creature-local metres.

Rules (documented in the README's "Rest layout" section):
- A part's origin is its parent's origin plus the parent's anchor (its ``a``, else ``offset``, else
  ``hip``), accumulated along the parent chain; parentless parts have origin 0.
- capsule / cone: a and b relative to the origin; radii r at a, r2 (or r) at b.
- sphere: centre at origin + offset (default 0).
- rope: from origin + offset, ``segments`` equal segments laid along −Z (tails trail behind a +Z-facing
  creature); radius falls linearly from r at the anchor to r·taper at the tip.
- leg: the foot rests straight below the hip at a drop of clamp(hip height, 0.5·reach, 0.95·reach), where
  reach = upper + lower and the ground is y = 0; the knee bends toward +Z, solved by the law of cosines.
- ``scale`` multiplies every position, length, radius and blend width afterwards.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..spec import CharacterSpec
from ..spec.character import LegPart, Part, RopePart

LEG_DROP_MIN = 0.5
LEG_DROP_MAX = 0.95
ROPE_DIRECTION = (0.0, 0.0, -1.0)

Vec = tuple[float, float, float]


@dataclass(frozen=True)
class PartSlots:
    """The slots of one part, in rest pose, unscaled: rows of (a.xyz, ra, b.xyz, rb) and their classes."""

    geometry: np.ndarray  # (n, 8) float64
    classes: tuple[str, ...]


def _add(u: Vec, v: Vec | list[float] | None) -> Vec:
    if v is None:
        return u
    return (u[0] + v[0], u[1] + v[1], u[2] + v[2])


def anchor_of(part: Part) -> list[float] | None:
    """The point a child hangs from, relative to the part's origin."""
    if part.shape == "capsule" or part.shape == "cone":
        return part.a
    if part.shape == "leg":
        return part.hip
    return part.offset


def origins(spec: CharacterSpec) -> dict[str, Vec]:
    """Origin of every part; parents are acyclic (the gate guarantees it)."""
    by_id = {p.id: p for p in spec.parts}
    done: dict[str, Vec] = {}

    def origin(pid: str) -> Vec:
        if pid not in done:
            parent = by_id[pid].parent
            done[pid] = (0.0, 0.0, 0.0) if parent is None else _add(origin(parent), anchor_of(by_id[parent]))
        return done[pid]

    for part in spec.parts:
        origin(part.id)
    return done


def _row(a: Vec, ra: float, b: Vec, rb: float) -> list[float]:
    return [*a, ra, *b, rb]


def _rope(part: RopePart, origin: Vec) -> PartSlots:
    n = part.segments
    start = _add(origin, part.offset)
    step = part.length / n
    r = part.r
    taper = 1.0 if part.taper is None else part.taper
    points = [_add(start, [c * step * j for c in ROPE_DIRECTION]) for j in range(n + 1)]
    radii = [r * (1.0 + (taper - 1.0) * j / n) for j in range(n + 1)]
    rows = [_row(points[j], radii[j], points[j + 1], radii[j + 1]) for j in range(n)]
    return PartSlots(np.array(rows, dtype=np.float64), ("rope",) * n)


def _leg(part: LegPart, origin: Vec) -> PartSlots:
    hip = _add(origin, part.hip)
    upper, lower, r = part.upper, part.lower, part.r
    reach = upper + lower
    drop = min(max(hip[1], LEG_DROP_MIN * reach), LEG_DROP_MAX * reach)
    foot = (hip[0], hip[1] - drop, hip[2])
    cos_hip = (upper * upper + drop * drop - lower * lower) / (2.0 * upper * drop)
    angle = math.acos(max(-1.0, min(1.0, cos_hip)))
    knee = (hip[0], hip[1] - upper * math.cos(angle), hip[2] + upper * math.sin(angle))  # bends toward +Z
    rows = [_row(hip, r, knee, r), _row(knee, r, foot, r)]
    return PartSlots(np.array(rows, dtype=np.float64), ("leg-upper", "leg-lower"))


def part_slots(part: Part, origin: Vec) -> PartSlots:
    """Rest slots of one part (unscaled)."""
    if part.shape == "rope":
        return _rope(part, origin)
    if part.shape == "leg":
        return _leg(part, origin)
    r = part.r
    if part.shape == "sphere":
        centre = _add(origin, part.offset)
        return PartSlots(np.array([_row(centre, r, centre, r)]), ("sphere",))
    a, b = _add(origin, part.a), _add(origin, part.b)
    r2 = r if part.r2 is None else part.r2
    return PartSlots(np.array([_row(a, r, b, r2)]), (part.shape,))
