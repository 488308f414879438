"""Cut the body's space into regions and choose each region's candidate program.

Regions start as a grid of cubes over the envelope-padded rest AABB (REGIONS_ALONG_LONGEST along the
longest axis). A cube whose interval says the surface cannot be within the band τ is skipped (outside
or deep inside). A cube whose program needs more than the tier's authored K is split into eight, up to
MAX_SPLITS times; past that, K grows up to the tier's cap, and past the cap the tier is rejected with
the region and the uncertified omission named.

Selection is greedy: start from the leaf with the smallest lower bound, and while a certificate fails,
add the omitted leaf with the smallest lower bound among the failing ones. Geometry decides every
choice; ties break on slot index, which is canonical (model/graph.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import layout as col
from ..model.graph import BlendGraph
from ..rig import CompiledRig
from .bounds import LeafBounds, leaf_bounds, subtree_info
from .program import CandidateProgram, build_program

REGIONS_ALONG_LONGEST = 4
MAX_SPLITS = 1


@dataclass(frozen=True)
class SkinTolerance:
    """How far a lower tier lets a skin vertex depart from the posed field before it becomes a field
    vertex. Colour: one just-noticeable OKLab difference (about 0.02) at the repeated tier, two at the
    distant one. Normal: the angle whose Lambert term error stays under sin θ of the light at grazing
    incidence and 1 − cos θ head-on (10°: 17 % and 1.5 %; 20°: 34 % and 6 %), on bodies a few dozen to a
    few hundred pixels tall."""

    normal_deg: float
    delta_e: float


@dataclass(frozen=True)
class Tier:
    name: str
    k: int  # authored starting K (the seed's tier table)
    k_cap: int | None  # K may grow up to this before the tier is rejected; None: up to every slot
    # None: every vertex evaluates its candidate program at runtime. Otherwise the skin representation
    # (surface/skin_tier.py): only vertices the skin departs from by more than these tolerances evaluate
    # the field, through the full graph, so the tier has no candidate programs.
    skin: SkinTolerance | None = None

    def cap(self, slot_count: int) -> int:
        return slot_count if self.k_cap is None else min(self.k_cap, slot_count)


#: The hero tier may keep every leaf (the full graph is always exact). The lower tiers keep the seed's
#: authored K and caps for the record, but use the skin representation and so no candidate programs:
#: their field vertices run the full graph (surface/skin_tier.py).
TIERS = {
    "hero": Tier("hero", 8, None),
    "repeated": Tier("repeated", 6, 8, SkinTolerance(10.0, 0.02)),
    "distant": Tier("distant", 4, 4, SkinTolerance(20.0, 0.04)),
}
#: The tier a build makes unless told otherwise: the one every example's candidate programs accept.
DEFAULT_TIER = "hero"


@dataclass(frozen=True)
class Tolerances:
    band: float  # τ: half-width of the band around the surface that programs must reproduce
    tail: float  # largest accepted n-ary tail bound, m
    weight_floor: float  # largest accepted omitted colour weight
    k_floor: float


class TierRejectedError(Exception):
    """The tier cannot bound the field within its K cap; the message names the region and omission."""


@dataclass(frozen=True)
class RegionSearch:
    programs: list[CandidateProgram]
    skipped_outside: int
    skipped_inside: int


def padded_box(slots: np.ndarray, excursion: np.ndarray, pad: float) -> tuple[np.ndarray, np.ndarray]:
    r = np.maximum(slots[:, col.RA], slots[:, col.RB]) + excursion
    lo = np.minimum(slots[:, col.A], slots[:, col.B]) - r[:, None]
    hi = np.maximum(slots[:, col.A], slots[:, col.B]) + r[:, None]
    return lo.min(axis=0) - pad, hi.max(axis=0) + pad


def initial_cells(lo: np.ndarray, hi: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    size = float((hi - lo).max()) / REGIONS_ALONG_LONGEST
    counts = np.maximum(np.ceil((hi - lo) / size).astype(int), 1)
    cells = []
    for i in range(counts[0]):
        for j in range(counts[1]):
            for k in range(counts[2]):
                corner = lo + size * np.array([i, j, k], dtype=np.float64)
                cells.append((corner, corner + size))
    return cells


def _split(lo: np.ndarray, hi: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    mid = 0.5 * (lo + hi)
    out = []
    for corner in np.ndindex(2, 2, 2):
        pick = np.array(corner, dtype=bool)
        out.append((np.where(pick, mid, lo), np.where(pick, hi, mid)))
    return out


def _select(
    graph: BlendGraph,
    slots: np.ndarray,
    bounds: LeafBounds,
    box: tuple[np.ndarray, np.ndarray],
    limit: int,
    tol: Tolerances,
) -> CandidateProgram:
    info = subtree_info(graph)
    kept = {int(np.argmin(bounds.lower))}
    while True:
        program = build_program(
            graph, info, bounds, slots, kept, box, tol.band, tol.tail, tol.weight_floor, tol.k_floor
        )
        failing = [c for c in program.certificates if not c.holds]
        if not failing or len(kept) >= limit:
            return program
        pool = {j for c in failing for j in c.omitted if j not in kept}
        kept.add(min(pool, key=lambda j: (bounds.lower[j], j)))


def search(rig: CompiledRig, excursion: np.ndarray, tier: Tier, tol: Tolerances) -> RegionSearch:
    lo, hi = padded_box(rig.slots, excursion, tol.band)
    todo = [(cell, 0) for cell in initial_cells(lo, hi)]
    programs: list[CandidateProgram] = []
    outside = inside = 0
    depth_total = max(subtree_info(rig.graph).depth, default=0.0)
    while todo:
        (c_lo, c_hi), splits = todo.pop(0)
        bounds = leaf_bounds(rig.slots, excursion, c_lo, c_hi)
        if float(bounds.lower.min()) - depth_total > tol.band:
            outside += 1
            continue
        if float(bounds.upper.min()) < -tol.band:
            inside += 1
            continue
        limit = tier.k if splits < MAX_SPLITS else tier.cap(rig.slot_count)
        program = _select(rig.graph, rig.slots, bounds, (c_lo, c_hi), limit, tol)
        if program.certified and len(program.leaves) <= tier.k:
            programs.append(program)
        elif splits < MAX_SPLITS:
            todo += [(child, splits + 1) for child in _split(c_lo, c_hi)]
        elif program.certified:
            programs.append(program)
        else:
            worst = next(c for c in program.certificates if not c.holds)
            cap = tier.cap(rig.slot_count)
            raise TierRejectedError(
                f"tier {tier.name}: region [{_fmt(c_lo)} .. {_fmt(c_hi)}] needs more than K = {cap} "
                f"leaves: {worst.kind} at {worst.place} does not hold "
                f"(value {worst.value:.4g}, threshold {worst.threshold:.4g}); it keeps "
                f"{_parts(rig, program.leaves)} and cannot omit {_parts(rig, worst.omitted)} "
                "(their motion brings them within the blend or colour reach of each other there). "
                "Build this creature at --tier hero, or move these parts apart or shorten the moving one"
            )
    return RegionSearch(programs, outside, inside)


def _parts(rig: CompiledRig, slots: tuple[int, ...]) -> str:
    """``part.<id>`` of each slot, once per part, in slot order."""
    names = dict.fromkeys(f"part.{rig.slot_parts[s]}" for s in sorted(slots))
    return ", ".join(names) or "nothing"


def _fmt(v: np.ndarray) -> str:
    return ", ".join(f"{x:.3f}" for x in v)
