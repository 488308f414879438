"""A random creature under construction: parts placed in creature space first and written relative to
the parent's anchor, the way the spec's rest layout reads it (rig/layout.py), so the numbers look like
hand-written ones. Features (corpus/features.py) and body plans (corpus/plans/) add parts through it; the
blends (corpus/blends.py) read its parent hierarchy.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from typing import Any

from .vec import Vec, r3, sub


@dataclass
class Part:
    """A part placed in creature space; ``anchor`` is the world point its children hang from."""

    data: dict[str, Any]
    origin: Vec
    anchor: Vec
    radius: float
    parent: str | None
    children: list[str] = field(default_factory=list)


class Creature:
    """Parts in creature space, written out relative to their parents' anchors."""

    def __init__(self, rng: random.Random, palette: tuple[str, ...]) -> None:
        self.rng = rng
        self.palette = palette
        self.parts: dict[str, Part] = {}

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
            data[key] = r3(sub(value, origin)) if key in ("a", "b", "offset", "hip") else value
        data["color"] = self.palette[colour % len(self.palette)]
        self.parts[pid] = Part(data, origin, anchor, r, parent)
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
