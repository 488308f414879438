"""The CPU reference sampler: distance, analytic gradient and colour of a compiled rig at points.

float64 is the reference; float32 mimics the GPU for parity tolerances. One pass: every slot's
distance and gradient, then the blend ops in program order (children first), then the roots by hard
min. The gradient is carried unnormalised, exactly as the GPU code does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..rig import CompiledRig
from ..rig.graph import Ref
from . import layout as col
from .blend import hard_min, lse_smin, poly_smin
from .colour import proximity_colour
from .floors import floors_for
from .primitives import primitive_field

Array = npt.NDArray[np.floating]


@dataclass(frozen=True)
class FieldSample:
    distance: Array  # (P,)
    gradient: Array  # (P, 3), unnormalised
    color: Array  # (P, 3), linear RGB


@dataclass(frozen=True)
class OpValue:
    """One op's result at every point, with its operands' distances (for the bound gates)."""

    distance: Array  # (P,)
    gradient: Array  # (P, 3)
    operands: Array  # (N, P) children's distances
    blend: Array  # poly: h (P,); lse: softmax weights (N, P)


def evaluate_ops(rig: CompiledRig, d_slots: Array, g_slots: Array) -> list[OpValue]:
    """Every op of the program in order; children are always evaluated before their parent."""
    values: list[OpValue] = []

    def get(ref: Ref) -> tuple[Array, Array]:
        if ref.kind == "slot":
            return d_slots[ref.index], g_slots[ref.index]
        return values[ref.index].distance, values[ref.index].gradient

    for op in rig.graph.ops:
        members = [get(c) for c in op.children]
        ds = np.stack([m[0] for m in members])
        if op.kernel == "poly":
            (dl, gl), (dr, gr) = members
            d, g, mix = poly_smin(dl, gl, dr, gr, op.k)
        else:
            d, g, mix = lse_smin(ds, np.stack([m[1] for m in members]), op.k)
        values.append(OpValue(d, g, ds, mix))
    return values


def evaluate_graph(rig: CompiledRig, d_slots: Array, g_slots: Array) -> tuple[Array, Array]:
    """The body's distance and gradient: the ops, then the roots by hard min."""
    values = evaluate_ops(rig, d_slots, g_slots)
    roots = [
        (d_slots[r.index], g_slots[r.index])
        if r.kind == "slot"
        else (values[r.index].distance, values[r.index].gradient)
        for r in rig.graph.roots
    ]
    d, g, _ = hard_min(np.stack([r[0] for r in roots]), np.stack([r[1] for r in roots]))
    return d, g


def sample(rig: CompiledRig, points: npt.ArrayLike, dtype: type[np.floating] = np.float64) -> FieldSample:
    """Evaluate the rest-pose field at points of shape (P, 3)."""
    p = np.asarray(points, dtype=dtype).reshape(-1, 3)
    slots = rig.slots.astype(dtype)
    d_slots, g_slots = primitive_field(slots, p, dtype=dtype)
    distance, gradient = evaluate_graph(rig, d_slots, g_slots)
    floors = floors_for(rig.body_scale)
    color = proximity_colour(d_slots, slots[:, col.K], slots[:, col.RGB], floors.k_floor)
    return FieldSample(distance, gradient, color)
