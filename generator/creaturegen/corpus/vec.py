"""3-vectors of the corpus generator, as the spec writes them: plain lists of three floats.

The generator places every part in creature space with these before writing it relative to its parent's
anchor (corpus/creature.py), so the numbers stay plain JSON lists rather than arrays.
"""

from __future__ import annotations

Vec = list[float]


def r3(v: Vec) -> Vec:
    """Three decimals, as a designer writes; -0.0 printed as 0."""
    return [round(c, 3) + 0.0 for c in v]


def add(u: Vec, v: Vec) -> Vec:
    return [u[0] + v[0], u[1] + v[1], u[2] + v[2]]


def sub(u: Vec, v: Vec) -> Vec:
    return [u[0] - v[0], u[1] - v[1], u[2] - v[2]]


def lerp(u: Vec, v: Vec, t: float) -> Vec:
    return [u[i] + (v[i] - u[i]) * t for i in range(3)]


def mirror(v: Vec) -> Vec:
    return [-v[0], v[1], v[2]]
