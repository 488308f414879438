"""The surface stage end to end: sample, extract, validate, weight, choose deformation, correct, store.

One call per (body, tier). Every step reports progress (these are the slow parts of a build) and every
measured property becomes a SurfaceGate; ``SurfaceRejectedError`` names the first failed gate and the
part it concerns, so a build never ships a surface that failed one. The result is cached on disk by the
three signatures (surface/cache.py); a hit skips everything but reading the file.

The stages, in the order the data flows: the validated rest mesh (surface/lattice.py, while the motion
envelope steps in forked workers), the skin weights (surface/weights.py, mended by surface/remedies.py),
the deformation method per joint (surface/deform.py), the correction region and each vertex's program
(surface/correction_region.py), the posed skin over the envelope (surface/posed.py), then the asset and
its sidecar.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import numpy.typing as npt

from .. import __version__
from ..candidates import DEFAULT_TIER, CandidateSet
from ..model import layout as col
from ..model.skeleton import Skeleton
from ..motion.compiled import CompiledCreature
from ..motion.envelope import PendingEnvelope, PoseEnvelope, start_pose_envelope
from ..rig import CompiledRig
from ..rig.signatures import signatures as rig_signatures
from . import identity
from .asset import SurfaceAsset
from .backend_choice import SamplingBackends
from .cache import CachedSurface, SurfaceCache
from .components import ComponentPolicy
from .correction_region import (
    SKIN_ERROR_FACTOR,
    CorrectionStage,
    correction_stage,
    runtime_skin,
    vertex_trust,
)
from .deform import DeformationChoice, choose_deformation, seam_corrector
from .extract import Extraction
from .field64 import BodyField
from .frames import radial_coordinates, rest_frames
from .gates import SurfaceGate
from .lattice import ValidatedMesh, validated_mesh
from .mesh_gates import surface_error
from .posed import PosedQuality, choice_skinner, posed_gates, posed_quality
from .progress import Progress, stderr_progress
from .refusal import fail_on, mesh_remedy
from .remedies import spread_steep_weights
from .sidecar import gate_from_row, gate_rows, signature_rows
from .skinning import METHODS, vertex_methods
from .weights import SkinWeights, skin_weights

F64 = npt.NDArray[np.float64]


@dataclass(frozen=True)
class SurfaceBuild:
    tier: str
    signatures: dict[str, str]
    asset: SurfaceAsset
    sidecar: dict[str, object]
    gates: tuple[SurfaceGate, ...]
    cached: bool
    folder: Path | None = None
    timings: dict[str, float] = field(default_factory=dict)
    # The tier's candidate programs when this build computed them (a cache hit leaves them to the plan).
    candidates: CandidateSet | str | None = None

    @property
    def passed(self) -> bool:
        return all(g.passed for g in self.gates)


def build_surface(
    creature: CompiledCreature,
    *,
    tier: str = DEFAULT_TIER,
    backend: str = "auto",
    cache: SurfaceCache | None = None,
    progress: Progress = stderr_progress,
    strict: bool = True,
) -> SurfaceBuild:
    """The validated reference surface of one body at one tier (from the cache when it is there)."""
    rig = creature.rig
    extra: dict[str, object] = {"creaturegen": __version__, "sources": identity.source_digest()}
    compiler = identity.compiler_signature(rig, tier, extra)
    geometry = rig_signatures(rig).geometryDigest
    settings = identity.settings_digest(tier, extra)
    key = _Key(geometry, settings, extra)
    if cache is None:
        return _extract_surface(creature, key, tier, backend, None, progress, strict)
    with cache.building(compiler, geometry, tier, settings):
        hit: CachedSurface | None = cache.lookup(compiler, geometry, tier, settings)
        if hit is not None:
            progress(f"cache hit {hit.folder}")
            cached = tuple(gate_from_row(g) for g in gate_rows(hit.sidecar))
            return SurfaceBuild(
                tier, dict(signature_rows(hit.sidecar)), hit.asset, hit.sidecar, cached, True, hit.folder
            )
        return _extract_surface(creature, key, tier, backend, cache, progress, strict)


@dataclass(frozen=True)
class _Key:
    """What the cold path needs of the lookup key (the compilerSignature is recomputed with the rest)."""

    geometry: str
    settings: str
    extra: dict[str, object]


def _extract_surface(
    creature: CompiledCreature,
    key: _Key,
    tier: str,
    backend: str,
    cache: SurfaceCache | None,
    progress: Progress,
    strict: bool,
) -> SurfaceBuild:
    """Extract, gate, weight, choose deformations and correct: the cold path of build_surface.

    The motion envelope is started first: its runs step in forked workers (motion/envelope.py) while this
    process samples, extracts and gates the mesh, which needs no motion; forking is safe only before the
    sampling backend has started a GPU device's threads. The skin weights are the first to wait for it."""
    with start_pose_envelope(creature) as pending:
        return _extract_with(creature, key, tier, backend, cache, progress, strict, pending)


@dataclass
class _Stages:
    """What the cold path measured so far: the gates in the order they were taken, and each stage's time."""

    gates: list[SurfaceGate]
    timings: dict[str, float]

    def timed(self, name: str, since: float) -> float:
        self.timings[name] = time.perf_counter() - since
        return self.timings[name]


def _extract_with(
    creature: CompiledCreature,
    key: _Key,
    tier: str,
    backend: str,
    cache: SurfaceCache | None,
    progress: Progress,
    strict: bool,
    pending: PendingEnvelope,
) -> SurfaceBuild:
    """``_extract_surface`` with its envelope under way: the stages in order, refusing after each one when
    ``strict``, then the asset and its sidecar stored in the cache."""
    rig, skeleton = creature.rig, creature.skeleton
    t0 = time.perf_counter()
    validated, envelope = _mesh_stage(rig, skeleton, tier, backend, progress, strict, pending)
    stages = _Stages(validated.gates, validated.timings)
    ex, policy, weights = _weights_stage(rig, skeleton, validated, envelope, tier, progress, strict, stages)
    choice = _deformation_stage(rig, skeleton, ex, weights, envelope, progress, stages)
    t = time.perf_counter()
    correction = correction_stage(creature, tier, ex, weights, choice, envelope, progress)
    stages.timed("correction", t)
    stages.gates += correction.gates
    if strict:
        fail_on(correction.gates, f"surface {tier} correction")
    quality, posed = _posed_stage(rig, ex, weights, skeleton, choice, correction, envelope, progress, stages)

    sig = identity.surface_signatures(rig, tier, ex.mesh.faces, choice.methods, key.extra)
    signatures = {
        "compilerSignature": sig.compilerSignature,
        "topologySignature": sig.topologySignature,
        "geometryDigest": sig.geometryDigest,
    }
    asset = _asset(rig, tier, ex, weights, skeleton, choice, correction, signatures)
    sidecar = _sidecar(
        rig, tier, signatures, validated, (ex, policy), envelope, choice, correction, (quality, posed), stages
    )
    folder = None
    if cache is not None:
        folder = cache.store(
            sig.compilerSignature, sig.topologySignature, key.geometry, tier, key.settings, asset, sidecar
        )
    stages.timings["total"] = time.perf_counter() - t0
    return SurfaceBuild(
        tier, signatures, asset, sidecar, tuple(stages.gates), False, folder, stages.timings, correction.found
    )


def _mesh_stage(
    rig: CompiledRig,
    skeleton: Skeleton,
    tier: str,
    backend: str,
    progress: Progress,
    strict: bool,
    pending: PendingEnvelope,
) -> tuple[ValidatedMesh, PoseEnvelope]:
    """The validated rest mesh, then the motion envelope (which stepped meanwhile)."""
    validated = validated_mesh(rig, skeleton, tier, SamplingBackends(rig, backend, progress), progress)
    t = time.perf_counter()
    envelope = pending.result()
    validated.timings["envelope"] = time.perf_counter() - t
    progress(
        f"motion envelope: {len(envelope.runs)} runs × {envelope.ticks} ticks "
        f"({envelope.samples:,} poses measured; waited {validated.timings['envelope']:.2f} s after the mesh)"
    )
    policy, grid = validated.policy, validated.grid
    if policy.detached:
        progress(f"declared: {', '.join(policy.detached)} detached from the body (the field leaves a gap)")
    if strict:
        remedy = mesh_remedy(validated.gates, policy.handles_certain, validated.refinement, grid.spacing)
        fail_on(validated.gates, f"surface {tier}", remedy)
    return validated, envelope


def _weights_stage(
    rig: CompiledRig,
    skeleton: Skeleton,
    validated: ValidatedMesh,
    envelope: PoseEnvelope,
    tier: str,
    progress: Progress,
    strict: bool,
    stages: _Stages,
) -> tuple[Extraction, ComponentPolicy, SkinWeights]:
    """Skin weights over the motion groups the envelope measured; a steep weight jump on an otherwise
    sound mesh is first mended by splitting the triangles across it (which changes the mesh)."""
    t = time.perf_counter()
    rest_field = BodyField(rig.graph, rig.slots)
    ex, policy = validated.extraction, validated.policy
    still = envelope.still_joints(rig.body_scale)
    weights = skin_weights(ex.mesh, rest_field, skeleton, still=still)
    if not weights.gate("weights.continuity").passed and not [g for g in stages.gates if not g.passed]:
        ex, stages.gates, policy, weights = spread_steep_weights(
            rig,
            (ex, stages.gates, policy, []),
            weights,
            rest_field,
            skeleton,
            validated.grid,
            still,
            progress,
        )
    stages.gates += list(weights.gates)
    elapsed = stages.timed("weights", t)
    progress(f"skin weights: {weights.barrier_edges} barrier edges, {elapsed:.2f} s")
    if strict:
        fail_on(list(weights.gates), f"surface {tier} skin weights")
    return ex, policy, weights


def _deformation_stage(
    rig: CompiledRig,
    skeleton: Skeleton,
    ex: Extraction,
    weights: SkinWeights,
    envelope: PoseEnvelope,
    progress: Progress,
    stages: _Stages,
) -> DeformationChoice:
    """Each joint's skinning method, swept over the envelope's limits (surface/deform.py)."""
    t = time.perf_counter()
    mesh = ex.mesh
    choice = choose_deformation(
        mesh,
        weights.indices,
        weights.weights,
        BodyField(rig.graph, rig.slots),
        skeleton,
        rig.slots,
        rig.graph,
        rig.body_scale,
        limits={j.child: envelope.sweep_limits(j.child) for j in envelope.joints},
        limits_from="motion envelope (motion/envelope.py), widened by its margins",
        limits_at={j.child: j.worst_run for j in envelope.joints},
        corrector=seam_corrector(
            mesh,
            ex.normals,
            rig.slots,
            rig.graph,
            vertex_trust(rig, mesh, ex.normals, weights.indices),
            SKIN_ERROR_FACTOR * rig.body_scale,
            skeleton,
            weights.indices.astype(np.int64),
            weights.weights,
        ),
    )
    elapsed = stages.timed("deformation", t)
    for joint in choice.joints:
        stages.gates += [
            SurfaceGate(
                f"deform.{joint.joint}.{joint.method}.{g.name}",
                g.value,
                g.threshold,
                g.unit,
                g.direction,
                g.detail,
            )
            for g in joint.gates
        ]
    counts = {m: choice.methods.count(m) for m in METHODS}
    progress(f"deformation per joint: {counts} in {elapsed:.2f} s")
    return choice


def _posed_stage(
    rig: CompiledRig,
    ex: Extraction,
    weights: SkinWeights,
    skeleton: Skeleton,
    choice: DeformationChoice,
    correction: CorrectionStage,
    envelope: PoseEnvelope,
    progress: Progress,
    stages: _Stages,
) -> tuple[PosedQuality, list[SurfaceGate]]:
    """The shipped skin at the envelope's whole-body poses (surface/posed.py): recorded, not enforced."""
    t = time.perf_counter()
    mesh = ex.mesh
    pair = (weights.indices, weights.weights)
    quality = posed_quality(
        rig,
        mesh,
        pair,
        choice_skinner(mesh, ex.normals, pair, skeleton, choice),
        correction.radius,
        envelope.poses,
        envelope.pose_labels,
    )
    names = skeleton.names
    posed = posed_gates(quality, [names[s] for s in weights.indices[mesh.faces[:, 0], 0]])
    elapsed = stages.timed("posed", t)
    creases = max((p.creases for p in quality.poses), default=0)
    progress(
        f"posed skin over {len(quality.poses)} envelope poses: "
        + ", ".join(f"{g.name.removeprefix('posed.')} {g.value:g}" for g in posed)
        + f" (visible creases along the parts' hard union: {creases}) in {elapsed:.2f} s"
    )
    return quality, posed


def _radial(rig: CompiledRig, mesh_vertices: F64, dominant: npt.NDArray[np.int32], frames: F64) -> F64:
    """Each vertex's (θ, along) in its dominant slot's rest frame: the continuous radial frame the runtime
    carries, chosen once at rest (never from the posed direction)."""
    radial = np.zeros((mesh_vertices.shape[0], 2))
    for s in range(rig.slot_count):
        rows = np.flatnonzero(dominant == s)
        if rows.size:
            length = float(np.linalg.norm(rig.slots[s, col.B] - rig.slots[s, col.A]))
            theta, along = radial_coordinates(mesh_vertices[rows], frames[s], length)
            radial[rows, 0], radial[rows, 1] = theta, along
    return radial


def _asset(
    rig: CompiledRig,
    tier: str,
    ex: Extraction,
    weights: SkinWeights,
    skeleton: Skeleton,
    choice: DeformationChoice,
    correction: CorrectionStage,
    signatures: dict[str, str],
) -> SurfaceAsset:
    """The .glb's content: the rest mesh and everything the runtime reads per vertex."""
    mesh, colour, programs = ex.mesh, correction.colour, correction.programs
    frames = rest_frames(rig, skeleton)
    radial = _radial(rig, mesh.vertices, weights.indices[:, 0], frames)
    methods = vertex_methods(weights.indices, weights.weights, choice.methods, skeleton)
    return SurfaceAsset(
        positions=mesh.vertices.astype(np.float32),
        normals=ex.normals.astype(np.float32),
        indices=mesh.faces.reshape(-1).astype(np.uint32),
        slots=weights.indices.astype(np.uint16),
        weights=weights.weights.astype(np.float32),
        candidate=programs.astype(np.uint16),
        radial=radial.astype(np.float32),
        rest_frames=np.transpose(frames, (0, 2, 1)).astype(np.float32),
        skin=runtime_skin(methods, correction.radius),
        cor_centers=np.where((methods == 2)[:, None], choice.centers, 0.0).astype(np.float32),
        extras={"creaturegen": __version__, "tier": tier, **signatures},
        colour_slots=None if colour is None else colour.slots,
        colour_weights=None if colour is None else colour.weights,
    )


def _sidecar(
    rig: CompiledRig,
    tier: str,
    signatures: dict[str, str],
    validated: ValidatedMesh,
    extracted: tuple[Extraction, ComponentPolicy],
    envelope: PoseEnvelope,
    choice: DeformationChoice,
    correction: CorrectionStage,
    posed_skin: tuple[PosedQuality, list[SurfaceGate]],
    stages: _Stages,
) -> dict[str, object]:
    """assets/surface.json: every measurement of the cold build, read back by a cache hit. ``extracted``
    is the mesh and component policy after the weight remedy (which may split triangles)."""
    (ex, policy), (quality, posed) = extracted, posed_skin
    mesh, grid, report = ex.mesh, validated.grid, correction.report
    sidecar: dict[str, object] = {
        "tier": tier,
        "signatures": signatures,
        "counts": {"vertices": mesh.vertex_count, "triangles": mesh.face_count, "slots": rig.slot_count},
        "grid": {
            "shape": list(grid.shape),
            "spacing": grid.spacing,
            "origin": list(grid.origin),
            "refinement": validated.refinement,
            "limitedBy": grid.limited_by,
        },
        "sampling": validated.sampling.as_dict(),
        "extraction": {"residual": ex.residual, "relaxReverted": ex.relax_reverted},
        "components": {
            "count": policy.count,
            "owners": list(policy.owners),
            "splitRoots": list(policy.split_roots),
            "detached": list(policy.detached),
        },
        "motionEnvelope": envelope.describe(),
        "deformation": choice.describe(),
        "correction": {
            **report.as_dict(),
            "region": int(correction.region.sum()),
            "skinOnlyError": correction.worst_skin,
            "candidateNote": correction.candidate_note,
        },
        "posed": {**quality.describe(), "gates": [g.as_dict() for g in posed]},
        "gates": [g.as_dict() for g in stages.gates],
        "surfaceError": surface_error(stages.gates),
        "timings": stages.timings,
    }
    if correction.contract is not None and correction.colour is not None:
        sidecar["skinRepresentation"] = correction.contract.describe()
    return sidecar
