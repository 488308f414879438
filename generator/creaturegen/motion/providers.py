"""Injected providers: gravity, support surfaces and water, with the built-ins the lab and tests use.

Locomotion never owns the world: gait asks a SupportSurfaceProvider where the ground is and how it moves,
the swimmer asks a WaterSurfaceProvider for the channels it represents, and gravity comes from a provider
(never scaled by creature scale). core/motion/providers.js implements the same built-ins with the same
formulas. A support frame is 12 floats: origin, then the tangent ``ex``, the outward normal ``ny`` and the
tangent ``ez``; support-local (u, h, w) maps to ``origin + u·ex + h·ny + w·ez``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Final, Protocol

from ..model.trig import pcos, psin
from .quat import Vec

STANDARD_GRAVITY: Final = 9.80665
#: Water channels the swimmer reads; without any of them the tier is refused. The shared sample also names
#: waterColumnDepthMeters, surfacePointVelocityMps, materialCurrentVelocityMps and densityKgPerM3.
SWIMMER_CHANNELS: Final = ("freeSurfacePoint", "freeSurfaceNormal", "geometricNormalVelocityMps")

Frame = list[float]


@dataclass(frozen=True)
class Gravity:
    vector: tuple[float, float, float] = (0.0, -STANDARD_GRAVITY, 0.0)
    #: The same vector at every instant: the core samples it once instead of every tick (the JS core
    #: would box the time it passes on every call V8 does not inline).
    constant: bool = True

    def at(self, time: float) -> Vec:
        return list(self.vector)


class Support(Protocol):
    @property
    def name(self) -> str: ...
    @property
    def support_id(self) -> int: ...

    def frame(self, time: float) -> Frame: ...
    def velocity(self, time: float, p: Vec) -> Vec: ...
    def acceleration(self, time: float, p: Vec) -> Vec: ...


def to_world(f: Frame, local: Vec) -> Vec:
    u, h, w = local
    return [
        f[0] + u * f[3] + h * f[6] + w * f[9],
        f[1] + u * f[4] + h * f[7] + w * f[10],
        f[2] + u * f[5] + h * f[8] + w * f[11],
    ]


def to_local(f: Frame, p: Vec) -> Vec:
    dx, dy, dz = p[0] - f[0], p[1] - f[1], p[2] - f[2]
    return [
        dx * f[3] + dy * f[4] + dz * f[5],
        dx * f[6] + dy * f[7] + dz * f[8],
        dx * f[9] + dy * f[10] + dz * f[11],
    ]


def closest_point(f: Frame, p: Vec) -> Vec:
    local = to_local(f, p)
    return to_world(f, [local[0], 0.0, local[2]])


@dataclass(frozen=True)
class FlatGround:
    name: str = "flat"
    support_id: int = 1

    def frame(self, time: float) -> Frame:
        return [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]

    def velocity(self, time: float, p: Vec) -> Vec:
        return [0.0, 0.0, 0.0]

    def acceleration(self, time: float, p: Vec) -> Vec:
        return [0.0, 0.0, 0.0]


@dataclass(frozen=True)
class Slope:
    """A plane through the origin rising along +z by ``angle`` radians."""

    angle: float = math.radians(10.0)
    name: str = "slope"
    support_id: int = 2

    def frame(self, time: float) -> Frame:
        c, s = pcos(self.angle), psin(self.angle)
        return [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c]

    def velocity(self, time: float, p: Vec) -> Vec:
        return [0.0, 0.0, 0.0]

    def acceleration(self, time: float, p: Vec) -> Vec:
        return [0.0, 0.0, 0.0]


@dataclass(frozen=True)
class TranslatingPlatform:
    """The ground plane carried at constant ``velocity`` (m/s)."""

    velocity_mps: tuple[float, float, float] = (0.3, 0.0, 0.1)
    name: str = "translating"
    support_id: int = 3

    def frame(self, time: float) -> Frame:
        v = self.velocity_mps
        return [v[0] * time, v[1] * time, v[2] * time, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]

    def velocity(self, time: float, p: Vec) -> Vec:
        return list(self.velocity_mps)

    def acceleration(self, time: float, p: Vec) -> Vec:
        return [0.0, 0.0, 0.0]


@dataclass(frozen=True)
class RotatingPlatform:
    """The ground plane turning about the vertical through ``centre`` at ``omega`` rad/s."""

    centre: tuple[float, float, float] = (0.5, 0.0, -0.4)
    omega: float = 0.35
    name: str = "rotating"
    support_id: int = 4

    def frame(self, time: float) -> Frame:
        a = self.omega * time
        c, s = pcos(a), psin(a)
        o = self.centre
        return [o[0], o[1], o[2], c, 0.0, -s, 0.0, 1.0, 0.0, s, 0.0, c]

    def velocity(self, time: float, p: Vec) -> Vec:
        rx, rz = p[0] - self.centre[0], p[2] - self.centre[2]
        return [self.omega * rz, 0.0, -self.omega * rx]

    def acceleration(self, time: float, p: Vec) -> Vec:
        w2 = self.omega * self.omega
        return [-w2 * (p[0] - self.centre[0]), 0.0, -w2 * (p[2] - self.centre[2])]


def builtin_supports() -> dict[str, Support]:
    return {s.name: s for s in (FlatGround(), Slope(), TranslatingPlatform(), RotatingPlatform())}


@dataclass(frozen=True)
class AnalyticWater:
    """Two travelling sine waves, ``η = A1 sin(k1 x − w1 t) + A2 sin(k2 z − w2 t + 0.7)``; ``channels``
    lists what it represents: an absent channel is absent from every sample, never zero."""

    channels: tuple[str, ...] = (
        "freeSurfacePoint",
        "geometricNormalVelocityMps",
        "freeSurfaceNormal",
        "waterColumnDepthMeters",
    )
    waves: tuple[tuple[float, float, float], ...] = field(default=((0.06, 1.3, 1.7), (0.04, 0.9, 1.1)))
    level: float = 0.0
    depth: float = 4.0

    def sample(self, x: float, z: float, time: float) -> dict[str, Vec]:
        (a1, k1, w1), (a2, k2, w2) = self.waves
        p1 = k1 * x - w1 * time
        p2 = k2 * z - w2 * time + 0.7
        eta = self.level + a1 * psin(p1) + a2 * psin(p2)
        deta_dt = -a1 * w1 * pcos(p1) - a2 * w2 * pcos(p2)
        gx = a1 * k1 * pcos(p1)
        gz = a2 * k2 * pcos(p2)
        inv = 1.0 / math.sqrt(gx * gx + 1.0 + gz * gz)
        full = {
            "freeSurfacePoint": [x, eta, z],
            "freeSurfaceNormal": [-gx * inv, inv, -gz * inv],
            "geometricNormalVelocityMps": [deta_dt * inv],
            "waterColumnDepthMeters": [eta + self.depth],
        }
        return {name: full[name] for name in self.channels if name in full}
