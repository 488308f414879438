"""Scale-derived numerical floors of the field, recorded in the compilerSignature.

Lengths are fractions of the body size L so a mouse and a whale behave alike; the weight floor is
dimensionless.
"""

from __future__ import annotations

from dataclasses import dataclass

from .primitives import GRADIENT_FLOOR


@dataclass(frozen=True)
class Floors:
    #: Smallest blend width the colour kernel divides by (kCap can make k tiny): 1e-3·L.
    k_floor: float
    #: Omitted share of the colour weight that cannot move a channel (in [0, 1]) by an 8-bit step: 2^-8.
    weight_floor: float
    #: Smallest |radial| before the gradient falls back to a deterministic perpendicular, as a factor of
    #: each slot's own size (length + radius), so it scales with the body like the lengths.
    gradient_floor: float
    #: Base step of the central-difference verification taps: 1e-6·L.
    epsilon_length: float


def floors_for(body_scale: float) -> Floors:
    return Floors(
        k_floor=1e-3 * body_scale,
        weight_floor=2.0**-8,
        gradient_floor=GRADIENT_FLOOR,
        epsilon_length=1e-6 * body_scale,
    )
