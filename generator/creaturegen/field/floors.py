"""Scale-derived numerical floors of the field, recorded in the compilerSignature.

Lengths are fractions of the body size L so a mouse and a whale behave alike; the weight floor is
dimensionless.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Floors:
    #: Smallest blend width the colour kernel divides by (kCap can make k tiny): 1e-3·L.
    k_floor: float
    #: Relative colour weight below which a leaf cannot move an 8-bit channel by a step: 2^-10.
    weight_floor: float
    #: Smallest |radial| before the gradient falls back to a deterministic perpendicular: 1e-12·L.
    gradient_floor: float
    #: Base step of the central-difference verification taps: 1e-6·L.
    epsilon_length: float


def floors_for(body_scale: float) -> Floors:
    return Floors(
        k_floor=1e-3 * body_scale,
        weight_floor=2.0**-10,
        gradient_floor=1e-12 * body_scale,
        epsilon_length=1e-6 * body_scale,
    )
