"""The CPU reference sampler: distance, analytic gradient and colour of a compiled rig at points.

float64 is the reference; float32 mimics the GPU for parity tolerances. One pass: every slot's
distance and gradient, then the blend ops in program order (children first), then the roots by hard
min. The gradient is carried unnormalised, exactly as the GPU code does.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
import numpy.typing as npt

from ..model import layout as col
from ..model.graph import BlendGraph, Ref
from .blend import hard_min, lse_smin, lse_smin_distance, poly_smin, poly_smin_distance
from .colour import proximity_colour
from .floors import floors_for
from .primitives import primitive_distance, primitive_field

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


def evaluate_ops(graph: BlendGraph, d_slots: Array, g_slots: Array) -> list[OpValue]:
    """Every op of the program in order; children are always evaluated before their parent."""
    values: list[OpValue] = []

    def get(ref: Ref) -> tuple[Array, Array]:
        if ref.kind == "slot":
            return d_slots[ref.index], g_slots[ref.index]
        return values[ref.index].distance, values[ref.index].gradient

    for op in graph.ops:
        members = [get(c) for c in op.children]
        ds = np.stack([m[0] for m in members])
        if op.kernel == "poly":
            (dl, gl), (dr, gr) = members
            d, g, mix = poly_smin(dl, gl, dr, gr, op.k)
        else:
            d, g, mix = lse_smin(ds, np.stack([m[1] for m in members]), op.k)
        values.append(OpValue(d, g, ds, mix))
    return values


def evaluate_graph(graph: BlendGraph, d_slots: Array, g_slots: Array) -> tuple[Array, Array]:
    """The body's distance and gradient: the ops, then the roots by hard min.

    ``d_slots``/``g_slots`` are indexed by the graph's slot refs; a candidate program passes only its
    kept leaves, renumbered.
    """
    values = evaluate_ops(graph, d_slots, g_slots)
    ds = [d_slots[r.index] if r.kind == "slot" else values[r.index].distance for r in graph.roots]
    gs = [g_slots[r.index] if r.kind == "slot" else values[r.index].gradient for r in graph.roots]
    d, g, _ = hard_min(np.stack(ds), np.stack(gs))
    return d, g


def evaluate_op_distances(graph: BlendGraph, d_slots: Array) -> list[Array]:
    """Every op's distance in program order, bit-identical to ``evaluate_ops``'s; no gradient is formed."""
    values: list[Array] = []
    for op in graph.ops:
        ds = [d_slots[c.index] if c.kind == "slot" else values[c.index] for c in op.children]
        if op.kernel == "poly":
            d, _ = poly_smin_distance(ds[0], ds[1], op.k)
        else:
            d, _ = lse_smin_distance(np.stack(ds), op.k)
        values.append(d)
    return values


def evaluate_distance(graph: BlendGraph, d_slots: Array) -> Array:
    """The body's distance alone, bit-identical to ``evaluate_graph``'s; no gradient is formed."""
    values = evaluate_op_distances(graph, d_slots)
    roots = np.stack([d_slots[r.index] if r.kind == "slot" else values[r.index] for r in graph.roots])
    result: Array = roots[np.argmin(roots, axis=0), np.arange(roots.shape[1])]
    return result


def sample_distance(
    graph: BlendGraph,
    slots: npt.NDArray[np.float64],
    points: npt.ArrayLike,
    dtype: type[np.floating] = np.float64,
) -> Array:
    """Distance only, for central-difference taps: the sampler's formulas without the gradient work."""
    p = np.asarray(points, dtype=dtype).reshape(-1, 3)
    return evaluate_distance(graph, primitive_distance(slots, p, dtype=dtype))


def sample_graph(
    graph: BlendGraph,
    slots: npt.NDArray[np.float64],
    points: npt.ArrayLike,
    k_floor: float,
    dtype: type[np.floating] = np.float64,
) -> FieldSample:
    """Evaluate any program over the slot rows it indexes (a full rig, or a candidate's kept leaves)."""
    p = np.asarray(points, dtype=dtype).reshape(-1, 3)
    # The float64 table goes to primitive_field so each slot's form is chosen on exact values.
    d_slots, g_slots = primitive_field(slots, p, dtype=dtype)
    table = slots.astype(dtype)
    distance, gradient = evaluate_graph(graph, d_slots, g_slots)
    color = proximity_colour(d_slots, table[:, col.K], table[:, col.RGB], k_floor)
    return FieldSample(distance, gradient, color)


class CompiledBody(Protocol):
    """What the sampler reads of a compiled rig (rig.CompiledRig has it), so the field sits below the
    compiler: the blend program, the slot table and the body scale its floors follow."""

    @property
    def graph(self) -> BlendGraph: ...
    @property
    def slots(self) -> npt.NDArray[np.float64]: ...
    @property
    def body_scale(self) -> float: ...


def sample(rig: CompiledBody, points: npt.ArrayLike, dtype: type[np.floating] = np.float64) -> FieldSample:
    """Evaluate the rest-pose field at points of shape (P, 3)."""
    return sample_graph(rig.graph, rig.slots, points, floors_for(rig.body_scale).k_floor, dtype)
