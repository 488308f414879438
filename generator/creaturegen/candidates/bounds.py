"""Interval bounds of leaf and subtree distances over a box and the pose envelope.

A leaf's distance is Lipschitz with constant λ = √(1+s²) (tapered capsule) or 1 (exact round cone),
so over a box of half-diagonal h around c, and with the slot free to move by e:
    d(c) − λh − e ≤ d ≤ d(c) + λh + e.
Blends only go below the minimum, by at most k/4 per polynomial node and k·log N per n-ary group, so a
subtree lies in [min over its leaves of the lower bounds − its depth, min of the upper bounds].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..field.primitives import primitive_field, slot_uses_round_cone
from ..model import layout as col
from ..model.graph import BlendGraph, Ref

FloatArray = npt.NDArray[np.float64]


def lipschitz(slots: FloatArray) -> FloatArray:
    length = np.linalg.norm(slots[:, col.B] - slots[:, col.A], axis=1)
    slope = np.divide(
        np.abs(slots[:, col.RB] - slots[:, col.RA]), length, out=np.zeros_like(length), where=length > 0
    )
    return np.where(slot_uses_round_cone(slots), 1.0, np.sqrt(1.0 + slope * slope))


@dataclass(frozen=True)
class LeafBounds:
    lower: FloatArray  # (S,)
    upper: FloatArray  # (S,)


def leaf_bounds(slots: FloatArray, excursion: FloatArray, lo: FloatArray, hi: FloatArray) -> LeafBounds:
    centre = 0.5 * (lo + hi)
    half_diagonal = 0.5 * float(np.linalg.norm(hi - lo))
    d, _ = primitive_field(slots, centre[None, :])
    spread = lipschitz(slots) * half_diagonal + excursion
    return LeafBounds(d[:, 0] - spread, d[:, 0] + spread)


@dataclass(frozen=True)
class SubtreeInfo:
    """Leaves and blend depth below each op, for bounding omitted siblings."""

    leaves: list[list[int]]  # per op
    depth: list[float]  # per op: how far below its leaves' minimum the op can go


def subtree_info(graph: BlendGraph) -> SubtreeInfo:
    leaves: list[list[int]] = []
    depth: list[float] = []
    for op in graph.ops:
        own = op.k / 4.0 if op.kernel == "poly" else op.k * math.log(len(op.children))
        below = 0.0
        mine: list[int] = []
        for child in op.children:
            if child.kind == "slot":
                mine.append(child.index)
            else:
                mine += leaves[child.index]
                below = max(below, depth[child.index])
        leaves.append(mine)
        depth.append(own + below)
    return SubtreeInfo(leaves, depth)


def ref_leaves(info: SubtreeInfo, ref: Ref) -> list[int]:
    return [ref.index] if ref.kind == "slot" else info.leaves[ref.index]


def ref_interval(info: SubtreeInfo, bounds: LeafBounds, ref: Ref) -> tuple[float, float]:
    """Interval of a slot's or op's distance over the box and envelope."""
    idx = ref_leaves(info, ref)
    depth = 0.0 if ref.kind == "slot" else info.depth[ref.index]
    return float(bounds.lower[idx].min()) - depth, float(bounds.upper[idx].min())
