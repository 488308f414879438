"""A candidate program: the kept leaves of a region, every blend ancestor they need, and a certificate
for each omitted sibling.

Pruning keeps an op when two or more children still hold kept leaves, and passes a lone kept child
through otherwise. Omitting is justified per sibling:
- poly-saturation: the omitted child O stays at least k above the kept child K wherever K can matter,
  lower(O) ≥ min(upper(K), τ_ref) + k, so h clamps to exactly 0 and the op returns K bit for bit;
- lse-tail: the omitted members change the group by at most k·log(1 + Σ exp(−(lower_j − ref)/k)),
  which must stay under the tail tolerance;
- root-min: an omitted root stays above the kept roots' minimum wherever the surface can be;
- colour-weight: the colour error the omitted leaves can cause stays under the colour floor (one 8-bit
  quantum per linear channel; geometric saturation does not bound it). The colour is the proximity-weighted
  mean ``Σ w_i c_i / Σ w_i``; the nearest leaf has weight 1 and is kept whenever the omitted weights sum
  to W_O < 1, so dropping the omitted leaves moves the colour by ``W_O/(W_K + W_O)·|c̄_O − c̄_K|`` ≤
  ``W_O · max |c_o − c_k|`` per channel. Leaves of one colour (a rope's segments, a pair of legs) can
  then be omitted however near they are, which is what lets the capped tiers keep K: a bound on the
  weight alone refused regions for colour differences that were zero.
τ_ref widens the surface band τ by the slack each ancestor can spend (1.25·k for a polynomial node,
k·(1 + log N) for a group): beyond it a value can no longer reach the surface through its ancestors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ..model import layout as col
from ..model.graph import BlendGraph, BlendOp, Ref
from .bounds import LeafBounds, SubtreeInfo, ref_interval, ref_leaves

CertificateKind = Literal["poly-saturation", "lse-tail", "root-min", "colour-weight"]


@dataclass(frozen=True)
class Certificate:
    kind: CertificateKind
    place: str  # the op (blend.nodes.<id>, blend.groups.<id>, part.<id>) or "roots" / "colour"
    omitted: tuple[int, ...]  # omitted slot indices
    value: float  # margin (m, must be ≥ 0) or bound (m or weight, must be ≤ threshold)
    threshold: float
    holds: bool


@dataclass(frozen=True)
class CandidateProgram:
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    leaves: tuple[int, ...]  # kept slots (indices into the rig's table), canonical order
    graph: BlendGraph  # slot refs index into ``leaves``
    certificates: tuple[Certificate, ...]

    @property
    def certified(self) -> bool:
        return all(c.holds for c in self.certificates)


@dataclass
class _Pruner:
    graph: BlendGraph
    info: SubtreeInfo
    bounds: LeafBounds
    kept: set[int]
    band: float
    tail_tolerance: float
    slot_index: dict[int, int] = field(default_factory=dict)
    ops: list[BlendOp] = field(default_factory=list)
    certificates: list[Certificate] = field(default_factory=list)

    def prune(self, ref: Ref, slack: float) -> Ref | None:
        if ref.kind == "slot":
            if ref.index not in self.kept:
                return None
            self.slot_index.setdefault(ref.index, len(self.slot_index))
            return Ref("slot", self.slot_index[ref.index])
        op = self.graph.ops[ref.index]
        spend = 1.25 * op.k if op.kernel == "poly" else op.k * (1.0 + math.log(len(op.children)))
        pruned = [(child, self.prune(child, slack + spend)) for child in op.children]
        kept = [(c, p) for c, p in pruned if p is not None]
        omitted = [c for c, p in pruned if p is None]
        if not kept:
            return None
        if omitted:
            self._certify(op, [c for c, _ in kept], omitted, self.band + slack)
        if len(kept) == 1:
            return kept[0][1]
        self.ops.append(BlendOp(op.kernel, tuple(p for _, p in kept), op.k, op.place))
        return Ref("op", len(self.ops) - 1)

    def _certify(self, op: BlendOp, kept: list[Ref], omitted: list[Ref], reach: float) -> None:
        upper_kept = min(ref_interval(self.info, self.bounds, r)[1] for r in kept)
        leaves = tuple(i for r in omitted for i in ref_leaves(self.info, r))
        if op.kernel == "poly":
            lower = ref_interval(self.info, self.bounds, omitted[0])[0]
            margin = lower - (min(upper_kept, reach) + op.k)
            saturated = Certificate("poly-saturation", op.place, leaves, margin, 0.0, margin >= 0)
            self.certificates.append(saturated)
            return
        ref = min(upper_kept, reach)
        terms = sum(math.exp(-(ref_interval(self.info, self.bounds, r)[0] - ref) / op.k) for r in omitted)
        bound = op.k * math.log1p(terms)
        tol = self.tail_tolerance
        self.certificates.append(Certificate("lse-tail", op.place, leaves, bound, tol, bound <= tol))


def build_program(
    graph: BlendGraph,
    info: SubtreeInfo,
    bounds: LeafBounds,
    slots: np.ndarray,
    kept: set[int],
    box: tuple[np.ndarray, np.ndarray],
    band: float,
    tail_tolerance: float,
    weight_floor: float,
    k_floor: float,
) -> CandidateProgram:
    """Prune the graph to ``kept`` and certify every omission."""
    pruner = _Pruner(graph, info, bounds, kept, band, tail_tolerance)
    roots = [(r, pruner.prune(r, 0.0)) for r in graph.roots]
    kept_roots = [p for _, p in roots if p is not None]
    omitted_roots = [r for r, p in roots if p is None]
    if omitted_roots:
        upper = min(ref_interval(info, bounds, r)[1] for r, p in roots if p is not None)
        for root in omitted_roots:
            margin = ref_interval(info, bounds, root)[0] - min(upper, band)
            leaves = tuple(ref_leaves(info, root))
            pruner.certificates.append(Certificate("root-min", "roots", leaves, margin, 0.0, margin >= 0))
    pruner.certificates.append(_colour_certificate(info, bounds, slots, kept, band, weight_floor, k_floor))
    order = sorted(pruner.slot_index, key=pruner.slot_index.__getitem__)
    lo, hi = box
    return CandidateProgram(
        lo=(float(lo[0]), float(lo[1]), float(lo[2])),
        hi=(float(hi[0]), float(hi[1]), float(hi[2])),
        leaves=tuple(order),
        graph=BlendGraph(tuple(pruner.ops), tuple(kept_roots)),
        certificates=tuple(pruner.certificates),
    )


def _colour_certificate(
    info: SubtreeInfo,
    bounds: LeafBounds,
    slots: np.ndarray,
    kept: set[int],
    band: float,
    weight_floor: float,
    k_floor: float,
) -> Certificate:
    """Bound of the colour error of omitting leaves (module docstring): the omitted weights
    exp(−(lower_j − d_min)/max(k_j, kFloor)) summed, with d_min bounded by the kept leaves' upper bounds
    and, on the surface, by τ plus the deepest blend, times the largest linear-channel difference between
    an omitted and a kept colour. It holds when that is at most ``weight_floor`` and the omitted weight
    is below 1 (so the nearest leaf is a kept one)."""
    omitted = [j for j in range(len(slots)) if j not in kept]
    depth = max(info.depth, default=0.0)
    d_min = min(min(float(bounds.upper[i]) for i in kept), band + depth)
    widths = np.maximum(slots[omitted, col.K], k_floor)
    gaps = np.maximum(bounds.lower[omitted] - d_min, 0.0)
    total = float(np.exp(-gaps / widths).sum()) if omitted else 0.0
    colours = slots[:, col.RGB]
    kept_colours = colours[sorted(kept)]
    spread = float(np.abs(colours[omitted][:, None, :] - kept_colours[None, :, :]).max()) if omitted else 0.0
    value = total * spread
    holds = value <= weight_floor and total < 1.0
    return Certificate("colour-weight", "colour", tuple(omitted), value, weight_floor, holds)
