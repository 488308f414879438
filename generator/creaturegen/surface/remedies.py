"""Mending a failed mesh short of a finer lattice: edge flips, splits toward the field, weight splits.

Each remedy is kept only when the gates it answers pass and no other gate gets worse; otherwise the build
goes on to a finer lattice (surface/lattice.py), which costs far more.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import numpy.typing as npt

from ..model.skeleton import Skeleton
from ..rig import CompiledRig
from .components import ComponentPolicy
from .extract import Extraction
from .field64 import BodyField
from .flips import flip_to_field
from .gates import (
    SurfaceGate,
    normal_gates,
)
from .grid import FINEST_TIER, Grid
from .mesh import Mesh
from .mesh_gates import CREASE_BAND_CELLS, NORMAL_GATES, P99_GATES, mesh_limits, surface_mesh_gates
from .progress import Progress
from .subdivide import (
    MARK_FACE_DEG,
    MARK_VERTEX_DEG,
    analytic_normals,
    split_faces,
    subdivide_to_field,
)
from .weights import CONTINUITY_MAX, SkinWeights, motion_groups, skin_weights, steep_faces

F64 = npt.NDArray[np.float64]

#: The weights.continuity remedy: rounds of splits, and the jump (as a fraction of the gate) that marks an
#: edge's triangles for splitting. Below the gate, so the edges just under it are split with the worst.
WEIGHT_SPLIT_ROUNDS = 3
WEIGHT_SPLIT_MARK = 0.75


Remedy = tuple[Extraction, list[SurfaceGate], ComponentPolicy, list[str]]


def _no_worse(failed: list[str], still: list[str]) -> bool:
    """Whether a remedy's mesh is kept: fewer gates fail, or the same number and none that passed before."""
    return len(still) < len(failed) or (len(still) == len(failed) and set(still) <= set(failed))


def remedied(
    rig: CompiledRig,
    ex: Extraction,
    gates: list[SurfaceGate],
    policy: ComponentPolicy,
    failed: list[str],
    rest_field: BodyField,
    skeleton: Skeleton,
    grid: Grid,
    progress: Progress,
    refine_next: bool = False,
) -> Remedy:
    """The local remedies for mesh-normal gates, before a whole finer lattice: edge flips toward the field
    (triangles spanning a bend along the wrong diagonal, surface/flips.py), then splits where the normals
    still disagree (surface/subdivide.py; only when the topology and the distances pass, which only a
    finer lattice mends). Each is kept only when it is ``_no_worse``. When only normal gates fail, both
    are applied and their sum is gated once (one gate pass on a 240k-vertex mesh takes ~15 s); the flips
    alone are gated only when the sum is not kept. With ``refine_next`` a remedy is worth a full gate pass
    only when it may pass the lattice (``_judged``)."""
    flipped_mesh, flips = flip_to_field(ex.mesh, rest_field.gradient)
    flipped = replace(ex, mesh=flipped_mesh)
    first, tail = split_marks(grid.tier)

    def split(base: Extraction, flipped_too: int) -> Remedy | None:
        """``base`` split toward the field and gated against the current failures: the result if kept.
        While a p99 gate still fails, its tail is split too (``split_marks``) and kept if no worse."""
        best: Remedy | None = None
        against = failed
        for marks in (first, tail):
            if marks == tail and not set(against) & P99_GATES:
                break
            candidate, added, declined = _split_toward_field(
                base if best is None else best[0], rest_field, marks
            )
            if not added:
                continue
            kept, result = _judged(rig, candidate, against, rest_field, skeleton, grid, refine_next)
            what = "where the normals disagree" if marks != tail else "where the normals pass the p99 bounds"
            lead = f"{flipped_too} edges flipped and {added} split" if flipped_too else f"{added} edges split"
            progress(
                f"{lead} toward the field {what} ({declined} marked triangles declined: a midpoint there "
                "would not reach the zero set): " + _verdict(result, kept)
            )
            if kept:
                best, against, flipped_too = result, result[3], 0
        return best

    only_normals = set(failed) <= NORMAL_GATES
    if only_normals and (both := split(flipped, flips)) is not None:
        return both
    if flips:
        kept, result = _judged(rig, flipped, failed, rest_field, skeleton, grid, refine_next)
        progress(f"{flips} edges flipped toward the field: " + _verdict(result, kept))
        if kept:
            ex, gates, policy, failed = result
    if failed and set(failed) <= NORMAL_GATES and not only_normals:
        return split(ex, 0) or (ex, gates, policy, failed)
    return ex, gates, policy, failed


def split_marks(tier: str) -> tuple[tuple[float, float], tuple[float, float]]:
    """(vertex, face) angles past which the normal remedy splits, first pass and tail pass, at ``tier``.
    At the hero: twice the p99 bounds, then the bounds themselves (subdivide.MARK_VERTEX_DEG,
    MARK_FACE_DEG, TAIL_MARKS). A lower tier's marks grow with its p99 bounds, since the hero's split its
    mesh where its own gates pass (the distant quadruped: 2,034 splits for a vertex p99 of 23.8° against
    20°, 2,050 vertices to 4,084), but never past half the maxima every tier keeps: the first pass must
    still mark the faces a failing maximum gate counts (a generated quadruped's face maximum at distant
    refinement 3 passed with marks at 20°, not at 80°)."""
    limits = mesh_limits(tier).normals
    scale = limits[1] / mesh_limits(FINEST_TIER).normals[1]
    first = (min(MARK_VERTEX_DEG * scale, limits[0] / 2.0), min(MARK_FACE_DEG * scale, limits[2] / 2.0))
    return first, (min(limits[1], first[0]), min(limits[3], first[1]))


def spread_steep_weights(
    rig: CompiledRig,
    current: Remedy,
    weights: SkinWeights,
    rest_field: BodyField,
    skeleton: Skeleton,
    grid: Grid,
    still: frozenset[int],
    progress: Progress,
) -> tuple[Extraction, list[SurfaceGate], ComponentPolicy, SkinWeights]:
    """The remedy for weights.continuity: split the triangles along whose edges a motion group's weight
    drops steeply (the rim of a small handle island, a short rope segment between two longer ones), so the
    transition spans more edges. The handles are placed by distances (HANDLE_GAP · r), not by edges, so
    the harmonic weights keep their shape and each split edge carries about half the jump. The split mesh
    is kept only when every mesh gate still passes and the jump falls; up to WEIGHT_SPLIT_ROUNDS rounds."""
    groups = motion_groups(skeleton, still)
    before = weights.gate("weights.continuity").value
    for _ in range(WEIGHT_SPLIT_ROUNDS):
        ex = current[0]
        steep = steep_faces(ex.mesh, weights, groups, WEIGHT_SPLIT_MARK * CONTINUITY_MAX)
        candidate, added, declined = _split_faces(ex, rest_field, steep)
        if not added:
            break
        kept, result = _judged(rig, candidate, [], rest_field, skeleton, grid)
        again = skin_weights(candidate.mesh, rest_field, skeleton, still=still) if kept else weights
        now, value = weights.gate("weights.continuity").value, again.gate("weights.continuity").value
        progress(
            f"weights.continuity {now:.3g}: {added} edges split where a weight drops by over "
            f"{WEIGHT_SPLIT_MARK * CONTINUITY_MAX:.2g} per edge ({declined} declined): "
            + (f"{value:.3g}" if kept else _verdict(result, kept))
        )
        # Kept only when the jump falls and no other weight gate starts failing.
        newly = _failing(again) - _failing(weights)
        if not kept or value >= now or newly:
            break
        current, weights = result, again
        if weights.gate("weights.continuity").passed:
            break
    if weights.gate("weights.continuity").value < before:
        progress(f"kept the split mesh: {current[0].mesh.vertex_count:,} vertices")
    return current[0], current[1], current[2], weights


def _failing(weights: SkinWeights) -> set[str]:
    return {g.name for g in weights.gates if not g.passed}


def _split_faces(
    ex: Extraction, rest_field: BodyField, faces: npt.NDArray[np.int64]
) -> tuple[Extraction, int, int]:
    """``ex`` with the longest edge of each of ``faces`` split onto the zero set (surface/subdivide.py)."""
    mesh, added, declined = split_faces(ex.mesh, faces, rest_field.field)
    return _with_split(ex, rest_field, mesh, added, declined)


def _with_split(
    ex: Extraction, rest_field: BodyField, mesh: Mesh, added: int, declined: int
) -> tuple[Extraction, int, int]:
    """A split mesh as an extraction: analytic normals, and the residual of the new vertices."""
    if added == 0:
        return ex, 0, declined
    normals = analytic_normals(mesh, rest_field.gradient)
    residual = float(np.max(np.abs(rest_field.distance(mesh.vertices[ex.mesh.vertex_count :]))))
    return replace(ex, mesh=mesh, normals=normals, residual=max(ex.residual, residual)), added, declined


def _split_toward_field(
    ex: Extraction, rest_field: BodyField, marks: tuple[float, float] = (MARK_VERTEX_DEG, MARK_FACE_DEG)
) -> tuple[Extraction, int, int]:
    """The extraction split locally toward the field (surface/subdivide.py), with its analytic normals and
    residual; returns (extraction, vertices added, marked faces declined)."""
    mesh, added, declined = subdivide_to_field(ex.mesh, rest_field.field, marks=marks)
    return _with_split(ex, rest_field, mesh, added, declined)


def _judged(
    rig: CompiledRig,
    candidate: Extraction,
    failed: list[str],
    rest_field: BodyField,
    skeleton: Skeleton,
    grid: Grid,
    refine_next: bool = False,
) -> tuple[bool, Remedy]:
    """A remedied extraction gated again: (kept, its result), kept when ``_no_worse`` than ``failed``.

    The normal-angle gates go first (gates.normal_gates, the same values a full pass computes): a remedy
    that already fails more of them, or other ones, than ``failed`` cannot be kept whatever the rest say,
    and is turned down without them (a full pass on a 140k-vertex mesh is ~5 s, the normals ~2 s). With
    ``refine_next`` (a finer lattice follows unless this one passes) so is one that still fails a max
    normal gate: as it stands it cannot pass the lattice. This is a choice, not an equivalence: a kept
    remedy could have been the base of a later step (the tail split, when a p99 gate also failed, or the
    split after flips), which is then tried from the unremedied mesh or not at all, so such a lattice
    gets one remedy path fewer before the finer lattice (which the corpus measures)."""
    smooth = rest_field.smooth(CREASE_BAND_CELLS * grid.spacing)
    normals = normal_gates(
        candidate.mesh,
        length_scale=rig.body_scale,
        field=rest_field.field,
        normal_limits=mesh_limits(grid.tier).normals,
        smooth=smooth,
    )
    partial = [g.name for g in normals if not g.passed]
    if not _may_be_no_worse(failed, partial) or (refine_next and set(partial) - P99_GATES):
        return False, (candidate, normals, ComponentPolicy(0, (), (), (), (), ()), partial)
    again, again_policy = surface_mesh_gates(rig, candidate, rest_field, skeleton, grid)
    still = [g.name for g in again if not g.passed]
    return _no_worse(failed, still), (candidate, again, again_policy, still)


def _may_be_no_worse(failed: list[str], some: list[str]) -> bool:
    """Whether a mesh whose failures include ``some`` can still be ``_no_worse`` than ``failed``: the other
    gates can only add failures, so not once ``some`` outnumbers ``failed`` or, as many, is not a subset."""
    return len(some) < len(failed) or (len(some) == len(failed) and set(some) <= set(failed))


def _verdict(result: Remedy, kept: bool) -> str:
    gates, still = result[1], result[3]
    which = "normal-angle" if all(g.name in NORMAL_GATES for g in gates) else "mesh"
    return (
        f"{which} gates {len(gates) - len(still)}/{len(gates)} passed"
        + (f"; failed {still}" if still else "")
        + ("" if kept else " (not kept)")
    )
