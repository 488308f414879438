"""Where the runtime corrects the skin: the vertices the skin alone leaves off the posed field.

The joint sweeps of the motion envelope pose the skin; every vertex whose skinned position misses the
posed field by more than SKIN_ERROR_FACTOR · L is in the correction region, and the runtime's bounded
Newton correction (surface/correct.py) runs there through the candidate program covering it. This module
also writes what the runtime reads per vertex: its method, trust radius and program.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..candidates import TIERS, CandidateSet, TierRejectedError, build_candidates, skin_note
from ..field.floors import floors_for
from ..model import layout as col
from ..model.rotations import Pose, posed_slots
from ..model.skeleton import Skeleton, subtree
from ..motion.compiled import CompiledCreature
from ..motion.envelope import PoseEnvelope
from ..rig import CompiledRig
from .correct import CorrectionReport, correct, trust_radius
from .deform import DeformationChoice
from .extract import Extraction
from .field64 import BodyField
from .gates import (
    DISTANCE_TOL,
    SurfaceGate,
)
from .mesh import Mesh
from .progress import Progress
from .skin_tier import (
    SUBPIXEL_PX,
    BakedColour,
    Departures,
    SkinContract,
    baked_colour,
    field_vertices,
    skin_contract,
    skin_departures,
)
from .skinning import Skinned, skin
from .sweep import sweep_poses
from .weights import SkinWeights

F64 = npt.NDArray[np.float64]

#: The skin alone must stay within this fraction of L of the posed field over the sweep; vertices that do
#: not are the correction region.
SKIN_ERROR_FACTOR = DISTANCE_TOL
#: Candidate index written for a vertex no candidate region covers (it is never corrected); the shipped
#: tsl/body.js exports the same NO_PROGRAM and SKIN_PROGRAM.
NO_PROGRAM = 65535
#: Candidate index of a vertex that evaluates no field at all (a skin-represented tier, TIER_REPRESENTATION):
#: skinned position and normal, colour from its baked colour weights.
SKIN_PROGRAM = 65534
#: A vertex is on a joint's seam when at least this much of its weight lies on each side of the joint.
SEAM_WEIGHT = 0.01


def seam(skeleton: Skeleton, weights: tuple[npt.NDArray[np.int32], F64], child: int) -> npt.NDArray[np.bool_]:
    """Vertices weighted on both sides of the joint above ``child``: the only ones a joint pose deforms.

    Every other vertex moves rigidly with its side, so its distance to the posed field changes only where
    a swept limb passes through another part: interpenetration the sweep provokes, which no local
    correction can or should repair.
    """
    moved = subtree(skeleton, child)
    on_moved = np.where(moved[weights[0]], weights[1], 0.0).sum(axis=1)
    result: npt.NDArray[np.bool_] = (on_moved > SEAM_WEIGHT) & (on_moved < 1.0 - SEAM_WEIGHT)
    return result


def vertex_trust(rig: CompiledRig, mesh: Mesh, normals: F64, indices: npt.NDArray[np.int32]) -> F64:
    """Each vertex's correction trust radius, from its dominant slot's radius (surface/correct.py)."""
    owner = indices[:, 0]
    return trust_radius(mesh, normals, np.maximum(rig.slots[owner, col.RA], rig.slots[owner, col.RB]))


def _skin_near(
    mesh: Mesh,
    normals: F64,
    weights: tuple[npt.NDArray[np.int32], F64],
    pose: Pose,
    choice: DeformationChoice,
    skeleton: Skeleton,
    on_seam: npt.NDArray[np.bool_],
) -> Skinned:
    """The skin of the seam and its one-ring only, the rest left at rest: the sweep reads the seam's
    positions and ``correct`` the fans of the vertices it moves, which lie within that ring. Skinning is
    per vertex, so these rows are the very values a whole-mesh skin gives; a seam of 2 k vertices on a
    325 k-vertex body paid for all of them at every pose (11.5 s of seed 96's 78 s)."""
    ring = np.zeros(mesh.vertex_count, dtype=bool)
    ring[mesh.faces[on_seam[mesh.faces].any(axis=1)].reshape(-1)] = True
    rows = np.flatnonzero(ring | on_seam)
    part = skin(
        mesh.vertices[rows],
        normals[rows],
        weights[0][rows],
        weights[1][rows],
        pose,
        choice.methods,
        skeleton,
        choice.centers[rows],
    )
    positions, out_normals = mesh.vertices.copy(), normals.copy()
    positions[rows], out_normals[rows] = part.positions, part.normals
    return Skinned(positions, out_normals, part.flips)


def correction_sweep(
    rig: CompiledRig,
    mesh: Mesh,
    normals: F64,
    weights: tuple[npt.NDArray[np.int32], F64],
    skeleton: Skeleton,
    choice: DeformationChoice,
    programs: npt.NDArray[np.int64],
    motion_poses: tuple[Pose, ...] = (),
) -> tuple[npt.NDArray[np.bool_], CorrectionReport, float, F64]:
    """Region policy and correction over each joint's extreme sweep poses and the motion's own poses.

    A joint's extremes (its sweep limits, one joint turned) are measured on its seam. The motion's poses
    (motion/envelope.py: whole-body poses of real cycles, every joint turned at once) are measured on
    every seam vertex. The region is every vertex whose skinned position misses the posed field by more
    than SKIN_ERROR_FACTOR·L in some pose; each pose is then corrected over the region's vertices it
    measured that have a candidate program (the caller gates those that have none) and the worst report
    kept. Returns (region, worst report, worst skin-only error in m, per-vertex trust radius).
    """
    trust = vertex_trust(rig, mesh, normals, weights[0])
    gate = SKIN_ERROR_FACTOR * rig.body_scale
    region = np.zeros(mesh.vertex_count, dtype=bool)
    # A joint that passed its sweep only with its seam corrected (deform.choose_deformation's remedy)
    # relies on the correction over its whole seam.
    for joint in choice.joints:
        if joint.corrected:
            region |= seam(skeleton, weights, joint.child)
    posed = []
    worst_skin = 0.0
    seams = {joint.child: seam(skeleton, weights, joint.child) for joint in choice.joints}
    extremes = [
        (seams[joint.child], pose)
        for joint in choice.joints
        for _, pose in sweep_poses(
            skeleton, rig.slots, joint.child, joint.bend_max_deg, joint.twist_max_deg, steps=1
        )
    ]
    any_seam = np.logical_or.reduce([*seams.values(), np.zeros(mesh.vertex_count, dtype=bool)])
    extremes += [(any_seam, pose) for pose in motion_poses]
    for on_seam, pose in extremes:
        if not on_seam.any():
            continue
        skinned = _skin_near(mesh, normals, weights, pose, choice, skeleton, on_seam)
        posed_field = BodyField(rig.graph, posed_slots(rig.slots, pose))
        error = np.zeros(mesh.vertex_count)
        error[on_seam] = np.abs(posed_field.distance(skinned.positions[on_seam]))
        worst_skin = max(worst_skin, float(error.max()))
        region |= error > gate
        posed.append((posed_field, skinned, on_seam))
    covered = region & (programs != NO_PROGRAM)
    worst: CorrectionReport | None = None
    for posed_field, skinned, on_seam in posed:
        _, report = correct(posed_field, mesh, skinned.positions, skinned.normals, covered & on_seam, trust)
        if worst is None or report.residual_after > worst.residual_after:
            worst = report
    if worst is None:
        worst = CorrectionReport(0, 0, 0.0, 0.0, 0.0, 0, 0, 0, 0, 0, 0)
    return region, worst, worst_skin, trust


def envelope_departures(
    rig: CompiledRig,
    mesh: Mesh,
    normals: F64,
    weights: SkinWeights,
    skeleton: Skeleton,
    choice: DeformationChoice,
    poses: tuple[Pose, ...],
) -> tuple[BakedColour, Departures]:
    """Baked colour weights and how far the skin alone departs from the field (surface/skin_tier.py)."""
    k_floor = floors_for(rig.body_scale).k_floor
    colour = baked_colour(rig, mesh.vertices, k_floor)
    pair = (weights.indices, weights.weights)
    seams = [seam(skeleton, pair, joint.child) for joint in choice.joints]
    on_seam = np.logical_or.reduce([*seams, np.zeros(mesh.vertex_count, dtype=bool)])
    departures = skin_departures(rig, mesh, normals, pair, skeleton, choice, colour, poses, k_floor, on_seam)
    return colour, departures


def never_worse(report: CorrectionReport) -> SurfaceGate:
    return SurfaceGate(
        "correctionNeverWorse",
        report.residual_after - report.residual_before,
        0.0,
        "m",
        "max",
        "the corrected residual may not exceed the skinned one",
    )


def runtime_skin(methods: npt.NDArray[np.integer], radius: F64) -> npt.NDArray[np.float32]:
    """(V, 2) what the runtime needs per vertex: its skinning method code and its correction trust radius
    (``CorrectionStage.radius``: zero outside the region policy's vertices and where no candidate program
    covers a vertex, so the runtime corrects exactly the vertices the build proved need it)."""
    return np.stack([methods.astype(np.float64), radius], axis=1).astype(np.float32)


def candidate_index(found: CandidateSet | str, rest: F64) -> tuple[npt.NDArray[np.int64], str]:
    """Per vertex, the first candidate region (in program order) whose box holds its rest position."""
    index = np.full(rest.shape[0], NO_PROGRAM, dtype=np.int64)
    if isinstance(found, str):
        return index, found
    for n, program in enumerate(found.programs):
        inside = np.all((rest >= np.asarray(program.lo)) & (rest <= np.asarray(program.hi)), axis=1)
        index[(index == NO_PROGRAM) & inside] = n
    return index, ""


def tier_candidates(
    creature: CompiledCreature, tier: str, envelope: PoseEnvelope | None = None
) -> CandidateSet | str:
    """The tier's candidate programs, or why the tier has none (TierRejectedError's message)."""
    try:
        return build_candidates(creature, tier, envelope)
    except TierRejectedError as exc:
        return str(exc)


@dataclass(frozen=True)
class CorrectionStage:
    """What the correction stage hands to the posed check, the asset and the sidecar."""

    found: CandidateSet | str  # the tier's candidate programs, or why it has none
    programs: npt.NDArray[np.int64]  # per vertex: candidate program, NO_PROGRAM or SKIN_PROGRAM
    candidate_note: str
    region: npt.NDArray[np.bool_]  # the correction region
    report: CorrectionReport
    worst_skin: float  # the skin alone's worst seam error over the sweep, m
    trust: F64  # per-vertex trust radius
    colour: BakedColour | None  # baked colours of a skin-represented tier
    contract: SkinContract | None  # that tier's measured skin contract
    gates: list[SurfaceGate]

    @property
    def radius(self) -> F64:
        """The runtime's correction trust radius per vertex: zero outside the region and its programs."""
        result: F64 = np.where(self.region & (self.programs != NO_PROGRAM), self.trust, 0.0)
        return result


def correction_stage(
    creature: CompiledCreature,
    tier: str,
    ex: Extraction,
    weights: SkinWeights,
    choice: DeformationChoice,
    envelope: PoseEnvelope,
    progress: Progress,
) -> CorrectionStage:
    """The correction region and each vertex's program: the tier's candidate programs (hero), or the
    one full-graph program for the vertices a skin-represented tier cannot carry by skinning alone."""
    rig, skeleton = creature.rig, creature.skeleton
    mesh = ex.mesh
    found: CandidateSet | str
    colour: BakedColour | None = None
    contract: SkinContract | None = None
    skin_tol = TIERS[tier].skin
    if skin_tol is None:
        found = tier_candidates(creature, tier, envelope)
        programs, candidate_note = candidate_index(found, mesh.vertices)
    else:
        found = candidate_note = skin_note(tier)
        # Every vertex may be corrected through the tier's one program (the full graph, index 0) ...
        programs = np.zeros(mesh.vertex_count, dtype=np.int64)
    region, report, worst_skin, trust = correction_sweep(
        rig,
        mesh,
        ex.normals,
        (weights.indices, weights.weights),
        skeleton,
        choice,
        programs,
        envelope.poses,
    )
    if skin_tol is not None:
        colour, departures = envelope_departures(
            rig, mesh, ex.normals, weights, skeleton, choice, envelope.poses
        )
        # ... and those the skin carries within the tier's tolerances evaluate nothing at all.
        in_field = region | field_vertices(departures, SKIN_ERROR_FACTOR * rig.body_scale, skin_tol)
        programs = np.where(in_field, 0, SKIN_PROGRAM).astype(np.int64)
        contract = skin_contract(departures, in_field, weights.indices[:, 0], rig, colour)
        gates = [never_worse(report)]
        progress(
            f"skin representation: {contract.field_vertices:,} of {contract.vertices:,} vertices evaluate "
            f"the field (correction region {int(region.sum()):,}); skin vertices depart at most "
            f"{contract.error / rig.body_scale:.2e} L (under {SUBPIXEL_PX} px up to "
            f"{contract.projected_px:.0f} px across L), normals p99 {contract.normal_deg[1]:.1f}°, "
            f"colour p99 ΔE {contract.delta_e[1]:.3f}"
        )
    else:
        gates = [
            never_worse(report),
            SurfaceGate(
                "correctionUncovered",
                float(np.count_nonzero(region & (programs == NO_PROGRAM))),
                0.0,
                "vertices",
                "max",
                candidate_note or "region vertices outside every candidate region",
            ),
        ]
        rejected = report.rejected_descent + report.rejected_inversion + report.rejected_gradient
        progress(
            f"correction region {int(region.sum()):,} vertices "
            f"(skin-only seam error {worst_skin / rig.body_scale:.2e} L); "
            f"corrected residual {report.residual_corrected / rig.body_scale:.2e} L, "
            f"{report.clamped} clamped, "
            f"{report.backtracks} backtracks, {rejected} rejected"
        )
    return CorrectionStage(
        found, programs, candidate_note, region, report, worst_skin, trust, colour, contract, gates
    )
