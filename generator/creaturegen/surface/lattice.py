"""A validated rest mesh: sample, extract and gate on a lattice, refining it until every mesh gate passes.

The lattice starts at the tier's spacing; a failed mesh gate is first answered by the remedies
(surface/remedies.py), then by a √2 finer lattice, within a refinement budget. When every lattice fails,
the best one (the finest for a wrong genus) is reported, so the refusal names what the finest look saw.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np
import numpy.typing as npt

from ..candidates import DEFAULT_TIER
from ..model.skeleton import Skeleton
from ..rig import CompiledRig
from .backends import FieldBackend
from .components import ComponentPolicy
from .extract import Extraction, extract
from .field64 import BodyField
from .gates import SurfaceGate
from .grid import FIRST_CELLS_LIMIT, Grid, GridTooFineError, make_grid, tier_offset
from .handles import certain_handle_possible
from .mesh_gates import NORMAL_GATES, surface_mesh_gates
from .progress import Progress
from .remedies import Remedy, remedied
from .sampling import sample_band
from .topology import components

F64 = npt.NDArray[np.float64]

#: Finer lattices tried (each √2 finer) when a mesh gate fails before the build gives up ...
MAX_REFINEMENTS = 2
#: ... and further ones, up to EXTRA_REFINEMENTS more, while the lattice stays under SMALL_LATTICE_NODES
#: nodes: a small body with a narrow fillet (eyes sunk into a small head) needs a few more halvings than a
#: big one, and on a small lattice they cost little; a big body's refinements are the expensive ones.
#: 2 M nodes refused seeds 166 (zeroSetToMesh at its cone body) and 134 (a handle among eight legs); they
#: pass at 3.1 M and 3.8 M nodes, 20 s and 30 s cold. A passing build never reaches these refinements.
EXTRA_REFINEMENTS = 3
SMALL_LATTICE_NODES = 8_000_000


class LatticeBackend(Protocol):
    """Picks the sampling backend per lattice (backend_choice.SamplingBackends): a refined lattice may
    warrant a backend the first did not."""

    def for_lattice(self, nodes: int) -> tuple[FieldBackend, str]: ...


@dataclass(frozen=True)
class FixedBackend:
    """One backend for every lattice, for a caller that has chosen already."""

    backend: FieldBackend
    why: str

    def for_lattice(self, nodes: int) -> tuple[FieldBackend, str]:
        return self.backend, self.why


@dataclass(frozen=True)
class SamplingReport:
    backend: str
    choice: str  # why this backend: measured calibration or the caller's request
    coarse: int
    fine: int
    settled: int
    dense: int
    active_blocks: int
    total_blocks: int
    seconds: float

    def as_dict(self) -> dict[str, object]:
        return dict(self.__dict__)


@dataclass(frozen=True)
class ValidatedMesh:
    """The extracted mesh at the first lattice whose mesh gates pass (or the finest tried)."""

    extraction: Extraction
    gates: list[SurfaceGate]
    policy: ComponentPolicy
    grid: Grid
    refinement: int
    sampling: SamplingReport
    timings: dict[str, float]
    deferred: bool = False  # euler failed with no certain handle: the other gates wait (``_deferred``)


def _may_refine(refinement: int, grid: Grid, tier: str = DEFAULT_TIER) -> bool:
    """Whether the lattice after ``grid`` (refinement + 1) is within the refinement budget. A lower tier's
    budget counts from the hero's first lattice: it may refine as far as the hero would, so a mesh gate
    the hero's lattices pass never refuses a lower tier for starting coarser."""
    base = MAX_REFINEMENTS + tier_offset(tier)
    if refinement < base:
        return True
    nodes = 2.0**1.5 * float(np.prod(grid.shape))  # √2 finer along each axis
    return refinement < base + EXTRA_REFINEMENTS and nodes <= SMALL_LATTICE_NODES


def _failed_count(attempt: ValidatedMesh) -> int:
    return sum(not g.passed for g in attempt.gates)


def _fails_euler(attempt: ValidatedMesh) -> bool:
    return any(g.name == "euler" and not g.passed for g in attempt.gates)


def validated_mesh(
    rig: CompiledRig, skeleton: Skeleton, tier: str, backends: LatticeBackend, progress: Progress
) -> ValidatedMesh:
    """Sample, extract and gate; retry √2 finer while a mesh gate fails and the refinement budget lasts
    (``_may_refine``). The result is the first lattice that passes or, when none does, the one that
    failed the fewest gates (the first of those): refining can make a mesh worse (two parts closer than a
    finer lattice resolves open a handle the coarser one had closed), and the user should hear about the
    best. When every lattice has the wrong genus it is the finest, whose contacts are the best resolved.
    A lattice refined at once for its genus (``ValidatedMesh.deferred``) is judged in full only when
    that choice needs it, so the choice is the one that judging every lattice in full would make."""
    attempts: list[ValidatedMesh] = []
    refinement = 0
    while True:
        try:
            attempt = _one_lattice(rig, skeleton, tier, backends, progress, refinement)
        except GridTooFineError as exc:
            if not attempts:
                raise
            progress(f"no finer lattice: {exc}")
            break
        attempts.append(attempt)
        failed = [g.name for g in attempt.gates if not g.passed]
        if not failed:
            break
        if not attempt.deferred:
            if failed == ["euler"] and attempt.policy.handles_certain:
                progress("the field itself closes these handles: a finer lattice cannot open them")
                break
            if not _may_refine(refinement, attempt.grid, tier):
                break
        progress("refining the lattice by √2 and extracting again")
        refinement += 1
    last = attempts[-1]
    if last.deferred or _failed_count(last):
        if all(_fails_euler(a) for a in attempts):
            # Every lattice has the wrong genus: the finest resolves the contacts best, and the coarser
            # ones need no judging in full to lose to it.
            attempts[-1] = _judged_in_full(rig, skeleton, last, progress) if last.deferred else last
            best = attempts[-1]
        else:
            attempts = [_judged_in_full(rig, skeleton, a, progress) if a.deferred else a for a in attempts]
            best = min(attempts, key=_failed_count)
    else:
        best = last
    spent = {key: sum(a.timings[key] for a in attempts) for key in best.timings}
    best = replace(best, timings=spent)
    last = attempts[-1]
    if best.refinement != last.refinement:
        progress(
            f"keeping refinement {best.refinement} ({_failed_count(best)} failed gates) over the finer "
            f"refinement {last.refinement} ({_failed_count(last)} failed)"
        )
    return best


def _one_lattice(
    rig: CompiledRig,
    skeleton: Skeleton,
    tier: str,
    backends: LatticeBackend,
    progress: Progress,
    refinement: int,
) -> ValidatedMesh:
    """One lattice: sample, extract and gate (or, when ``_deferred``, only the genus)."""
    timings: dict[str, float] = {"sampling": 0.0, "extraction": 0.0, "validation": 0.0}
    rest_field = BodyField(rig.graph, rig.slots)
    grid = make_grid(rig.slots, rig.graph, tier, rig.slot_parts, refinement)
    chosen, why = backends.for_lattice(int(np.prod(grid.shape)))
    if grid.limited_by:
        progress(
            f"{grid.limited_by} is too thin for the {tier} sagitta target within "
            f"{FIRST_CELLS_LIMIT} cells; sampling there first, the mesh gates judge it"
        )
    progress(
        f"lattice {grid.shape} at h = {grid.spacing:.4g} m ({tier}, refinement {refinement}); "
        f"narrow-band sampling with {chosen.name}"
    )
    t = time.perf_counter()
    band = sample_band(grid, chosen, rig.graph, rig.slots, rig.body_scale)
    timings["sampling"] += time.perf_counter() - t
    progress(
        f"sampled {band.fine_samples:,} fine + {band.coarse_samples:,} coarse nodes "
        f"({band.fine_samples / band.dense_samples:.1%} of a dense pass)"
    )
    t = time.perf_counter()
    ex = extract(rest_field, band, rig.body_scale)
    timings["extraction"] += time.perf_counter() - t
    progress(f"extracted {ex.mesh.vertex_count:,} vertices, {ex.mesh.face_count:,} triangles")
    sampling = SamplingReport(
        chosen.name,
        why,
        band.coarse_samples,
        band.fine_samples,
        band.settled_samples,
        band.dense_samples,
        band.active_blocks,
        band.total_blocks,
        timings["sampling"],
    )
    t = time.perf_counter()
    genus = _deferred(rig, ex, rest_field, skeleton, grid, refinement, tier)
    timings["validation"] += time.perf_counter() - t
    if genus is not None:
        progress(
            f"mesh gates: euler failed ({genus.detail}); no contact between unjoined parts is certain to "
            "stay, so a finer lattice follows and the other gates wait"
        )
        policy = ComponentPolicy(0, (), (), (), (), ())
        return ValidatedMesh(ex, [genus], policy, grid, refinement, sampling, timings, deferred=True)
    refine_next = _may_refine(refinement, grid, tier)
    ex, gates, policy, _ = _gated(rig, ex, rest_field, skeleton, grid, timings, progress, refine_next)
    return ValidatedMesh(ex, gates, policy, grid, refinement, sampling, timings)


def _deferred(
    rig: CompiledRig,
    ex: Extraction,
    rest_field: BodyField,
    skeleton: Skeleton,
    grid: Grid,
    refinement: int,
    tier: str,
) -> SurfaceGate | None:
    """The failed euler gate when this lattice will be refined whatever its other gates say, else None.

    That is when the genus is wrong, a finer lattice is within the budget, and no handle can be certain
    (handles.certain_handle_possible): the build then refines without remedies, and the lattice's other
    gates matter only if no finer one passes, when ``_judged_in_full`` computes them. On a 160k-vertex
    first lattice they cost ~11 s (gates, component policy, a genus per contacting pair of parts)."""
    if not _may_refine(refinement, grid, tier):
        return None
    found = components(ex.mesh)
    off = np.flatnonzero(found.euler != 2)
    if off.size == 0:
        return None
    distances = rest_field.slot_distances(ex.mesh.vertices)
    if certain_handle_possible(ex.mesh, distances, rest_field.distance, skeleton, rig.slots, rig.slot_parts):
        return None
    detail = f"genus {found.genus[off][:5].tolist()} at components {off[:5].tolist()}"
    return SurfaceGate("euler", float(off.size), 0.0, "components", "max", detail)


def _judged_in_full(
    rig: CompiledRig, skeleton: Skeleton, attempt: ValidatedMesh, progress: Progress
) -> ValidatedMesh:
    """A deferred lattice with every gate computed, as ``_one_lattice`` would have judged it."""
    rest_field = BodyField(rig.graph, rig.slots)
    timings = dict(attempt.timings)
    progress(f"no finer lattice passed: judging refinement {attempt.refinement} in full")
    ex, gates, policy, _ = _gated(
        rig, attempt.extraction, rest_field, skeleton, attempt.grid, timings, progress
    )
    return replace(attempt, extraction=ex, gates=gates, policy=policy, timings=timings, deferred=False)


def _gated(
    rig: CompiledRig,
    ex: Extraction,
    rest_field: BodyField,
    skeleton: Skeleton,
    grid: Grid,
    timings: dict[str, float],
    progress: Progress,
    refine_next: bool = False,
) -> Remedy:
    """Every mesh gate of one lattice, after the local normal remedies when they may pass it
    (``refine_next``: a finer lattice follows unless this one passes)."""
    t = time.perf_counter()
    gates, policy = surface_mesh_gates(rig, ex, rest_field, skeleton, grid)
    timings["validation"] += time.perf_counter() - t
    failed = [g.name for g in gates if not g.passed]
    progress(
        f"mesh gates: {len(gates) - len(failed)}/{len(gates)} passed"
        + (f"; failed {failed}" if failed else "")
    )
    if any(name in NORMAL_GATES for name in failed) and "euler" not in failed:
        # Not when the genus is wrong: neither remedy changes the topology, so it can neither spare a
        # finer lattice nor pass this one, and re-gating a large mesh for it cost seed 88 nine seconds
        # (and seed 83's refusal seven).
        t = time.perf_counter()
        ex, gates, policy, failed = remedied(
            rig, ex, gates, policy, failed, rest_field, skeleton, grid, progress, refine_next
        )
        timings["validation"] += time.perf_counter() - t
    return ex, gates, policy, failed
