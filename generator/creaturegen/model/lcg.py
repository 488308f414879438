"""The seeded LCG every instance draws from: integer arithmetic, identical in Python and the shipped JS,
so the reference reproduces any spawned instance from its seed (no Math.random anywhere)."""

from __future__ import annotations

import math
from typing import Final

#: Numerical Recipes LCG, modulo 2³²: state' = (a·state + c) mod 2^32. The shipped core/lcg.js exports the
#: same LCG_A and LCG_C (tests/test_runtime_constants.py), so the JS streams are this module's.
LCG_A: Final = 1664525
LCG_C: Final = 1013904223


def lcg_next(state: int) -> int:
    return (LCG_A * state + LCG_C) % (1 << 32)


def mix_seed(seed: int) -> int:
    """The first state of an instance's LCG stream: ``seed`` through murmur3's 32-bit finaliser.

    An LCG is affine, so the k-th draws of consecutive seeds would form an arithmetic progression: spawn
    seeds 0, 1, 2, … would get headings and genes on a regular lattice. The finaliser decorrelates them.
    """
    h = seed % (1 << 32)
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & 0xFFFFFFFF
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & 0xFFFFFFFF
    h ^= h >> 16
    return h


def instance_yaw(seed: int) -> float:
    """Yaw in [0, 2π) of an instance spawned from ``seed``: the second draw of its stream (the first is
    reserved)."""
    second = lcg_next(lcg_next(mix_seed(seed)))
    return second / 4294967296.0 * 2.0 * math.pi
