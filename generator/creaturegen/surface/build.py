"""The surface stage end to end: sample, extract, validate, weight, choose deformation, correct, store.

One call per (body, tier). Every step reports progress (these are the slow parts of a build) and every
measured property becomes a SurfaceGate; ``SurfaceRejectedError`` names the first failed gate and the
part it concerns, so a build never ships a surface that failed one. The result is cached on disk by the
three signatures (surface/asset.py); a hit skips everything but reading the file.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import numpy.typing as npt

from .. import __version__
from ..candidates import TIERS, CandidateSet, TierRejectedError, build_candidates, skin_note
from ..field.floors import floors_for
from ..model import layout as col
from ..model.rotations import Pose, posed_slots
from ..model.skeleton import Skeleton, build_skeleton, subtree
from ..motion.envelope import PendingEnvelope, PoseEnvelope, start_pose_envelope
from ..rig import CompiledRig
from ..rig.signatures import signatures as rig_signatures
from ..spec import CharacterSpec
from . import deform, identity
from .asset import CachedSurface, SurfaceAsset, SurfaceCache
from .backends import (
    BACKENDS,
    BackendChoiceError,
    BackendUnavailableError,
    FieldBackend,
    NumpyBackend,
    make_backend,
    time_backend,
)
from .components import ComponentPolicy, component_policy
from .correct import CorrectionReport, correct, trust_radius
from .extract import Extraction, extract
from .field64 import BodyField
from .flips import flip_to_field
from .gates import (
    DISTANCE_TOL,
    FACE_NORMAL_P99_DEG,
    VERTEX_NORMAL_P99_DEG,
    Direction,
    SurfaceGate,
    mesh_gates,
    normal_gates,
)
from .grid import FIRST_CELLS_LIMIT, Grid, GridTooFineError, make_grid, tier_offset
from .handles import certain_handle_possible, handle_contacts
from .mesh import Mesh
from .posed import choice_skinner, posed_gates, posed_quality
from .sampling import sample_band
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
from .subdivide import (
    MARK_FACE_DEG,
    MARK_VERTEX_DEG,
    TAIL_MARKS,
    analytic_normals,
    split_faces,
    subdivide_to_field,
)
from .topology import components
from .weights import CONTINUITY_MAX, SkinWeights, motion_groups, skin_weights, steep_faces

F64 = npt.NDArray[np.float64]
Progress = Callable[[str], None]

#: The default surface tier: the one every example's candidate programs accept.
DEFAULT_TIER = "hero"
#: Our extracted and relaxed meshes keep their 1st-percentile minimum angle above this (degrees); raw
#: marching cubes would sit near 1.5°, which is why the relaxation exists.
MIN_ANGLE_P1_DEG = 15.0
#: The skin alone must stay within this fraction of L of the posed field over the sweep; vertices that do
#: not are the correction region.
SKIN_ERROR_FACTOR = DISTANCE_TOL
#: What a refusal of the posed skin (surface/posed.py) tells the user: the motion carries a limb's skin
#: into a fold or through another sheet where the body has none.
POSED_REMEDY = (
    "; the motion presses this skin into itself at that pose: a smaller turn there (a shorter step or hop, "
    "a gentler slope run), a thinner limb at its joint, or more room between the limb and the part it "
    "swings against keeps the skin clear"
)
#: Mesh-normal maxima (degrees): a blend fillet narrower than a few lattice cells turns the true normal
#: faster than a triangle can follow, so the worst vertex sits well above the bulk (the p99 gates of
#: surface/gates.py stay at 5° and 10°). Shading uses the analytic normals stored per vertex, not these.
VERTEX_NORMAL_MAX_DEG = 45.0
FACE_NORMAL_MAX_DEG = 60.0
#: Vertices within this many lattice cells of a hard-min crease between two blend roots are left out of
#: the normal gates: the analytic normal itself jumps there, so no mesh normal can agree with it.
CREASE_BAND_CELLS = 2.0
#: The mesh gates an edge flip (surface/flips.py) and a local subdivision (surface/subdivide.py) can mend,
#: tried in that order before a finer lattice.
#: (vertex max, vertex p99, face max, face p99) normal angles, degrees: every mesh gate pass uses these.
NORMAL_LIMITS = (VERTEX_NORMAL_MAX_DEG, VERTEX_NORMAL_P99_DEG, FACE_NORMAL_MAX_DEG, FACE_NORMAL_P99_DEG)
NORMAL_GATES = frozenset(
    {"vertexNormalAngleMax", "vertexNormalAngleP99", "faceNormalAngleMax", "faceNormalAngleP99", "inverted"}
)
#: The area-weighted tails among them: a second, finer split pass answers these (subdivide.TAIL_MARKS).
P99_GATES = frozenset({"vertexNormalAngleP99", "faceNormalAngleP99"})
#: Finer lattices tried (each √2 finer) when a mesh gate fails before the build gives up ...
MAX_REFINEMENTS = 2
#: ... and further ones, up to EXTRA_REFINEMENTS more, while the lattice stays under SMALL_LATTICE_NODES
#: nodes: a small body with a narrow fillet (eyes sunk into a small head) needs a few more halvings than a
#: big one, and on a small lattice they cost little; a big body's refinements are the expensive ones.
#: 2 M nodes refused seeds 166 (zeroSetToMesh at its cone body) and 134 (a handle among eight legs); they
#: pass at 3.1 M and 3.8 M nodes, 20 s and 30 s cold. A passing build never reaches these refinements.
EXTRA_REFINEMENTS = 3
SMALL_LATTICE_NODES = 8_000_000
#: The weights.continuity remedy: rounds of splits, and the jump (as a fraction of the gate) that marks an
#: edge's triangles for splitting. Below the gate, so the edges just under it are split with the worst.
WEIGHT_SPLIT_ROUNDS = 3
WEIGHT_SPLIT_MARK = 0.75
#: Calibration points for picking the faster sampling backend.
CALIBRATION_POINTS = 32768
#: wgpu's start-up before its first sample (adapter, device, wgpu-native's cffi type parsing, the first
#: pipeline): 3.1 s to 4.2 s measured in a cProfile'd build on the 2-core machine under load, so 2 s is
#: a floor. Against numpy's 0.3 µs per point that is several million samples.
WGPU_STARTUP_S = 2.0
#: Nodes a build may sample per node of its first lattice: the narrow band holds 15-35 % of a dense
#: lattice (the sampling report's "% of a dense pass"), and the refinement budget allows two √2 finer
#: lattices (2^1.5 and 2^3 times the nodes): 0.35 · (1 + 2.83 + 8) ≈ 4.1.
SAMPLED_NODES_PER_FIRST_NODE = 4.1
#: Candidate index written for a vertex no candidate region covers (it is never corrected).
NO_PROGRAM = 65535
#: Candidate index of a vertex that evaluates no field at all (a skin-represented tier, TIER_REPRESENTATION):
#: skinned position and normal, colour from its baked colour weights.
SKIN_PROGRAM = 65534


class SurfaceRejectedError(Exception):
    """A gate failed; the message names the gate, its value, its threshold and the part."""


def stderr_progress(message: str) -> None:
    print(f"  surface: {message}", file=sys.stderr, flush=True)


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


def choose_backend(
    rig: CompiledRig, requested: str, progress: Progress, tier: str = DEFAULT_TIER
) -> tuple[FieldBackend, str]:
    """The requested backend, or for "auto" the faster of numpy and wgpu measured on this machine.

    Faster for the whole build, start-up included: wgpu pays WGPU_STARTUP_S before its first sample, so
    when numpy is predicted to finish every lattice the build may sample in less than that, wgpu is not
    started at all. Otherwise both are timed on the same points and the faster per point is chosen."""
    if requested != "auto":
        if requested not in BACKENDS:
            raise BackendChoiceError(f"--backend: unknown {requested!r}; choose auto, {', '.join(BACKENDS)}")
        return make_backend(requested, rig.graph, rig.slots), "requested"
    numpy_backend = NumpyBackend(rig.graph, rig.slots)
    rng = np.random.default_rng(0)
    lo = np.min(np.minimum(rig.slots[:, col.A], rig.slots[:, col.B]), axis=0)
    hi = np.max(np.maximum(rig.slots[:, col.A], rig.slots[:, col.B]), axis=0)
    points = rng.uniform(lo, hi, (CALIBRATION_POINTS, 3)).astype(np.float32)
    t_numpy = time_backend(numpy_backend, points, repeats=2)
    try:
        nodes = float(np.prod(make_grid(rig.slots, rig.graph, tier, rig.slot_parts, 0).shape))
    except GridTooFineError:
        nodes = math.inf
    predicted = t_numpy / CALIBRATION_POINTS * nodes * SAMPLED_NODES_PER_FIRST_NODE
    if predicted < WGPU_STARTUP_S:
        why = (
            f"numpy predicted {predicted:.2f} s for every lattice the build may sample, under wgpu's "
            f"{WGPU_STARTUP_S:g} s start-up ({CALIBRATION_POINTS}-point calibration: numpy "
            f"{t_numpy * 1e3:.1f} ms)"
        )
        progress(f"sampling backend numpy ({why})")
        return numpy_backend, why
    try:
        gpu = make_backend("wgpu", rig.graph, rig.slots)
        t_gpu = time_backend(gpu, points, repeats=2)
    except BackendUnavailableError as exc:
        progress(f"sampling backend numpy (wgpu unavailable: {exc})")
        return numpy_backend, f"wgpu unavailable: {exc}"
    chosen: FieldBackend = gpu if t_gpu < t_numpy else numpy_backend
    why = f"{CALIBRATION_POINTS}-point calibration: numpy {t_numpy * 1e3:.1f} ms, wgpu {t_gpu * 1e3:.1f} ms"
    progress(f"sampling backend {chosen.name} ({why})")
    return chosen, why


def tier_candidates(
    spec: CharacterSpec, rig: CompiledRig, tier: str, envelope: PoseEnvelope | None = None
) -> CandidateSet | str:
    """The tier's candidate programs, or why the tier has none (TierRejectedError's message)."""
    try:
        return build_candidates(spec, rig, tier, envelope)
    except TierRejectedError as exc:
        return str(exc)


def candidate_index(found: CandidateSet | str, rest: F64) -> tuple[npt.NDArray[np.int64], str]:
    """Per vertex, the first candidate region (in program order) whose box holds its rest position."""
    index = np.full(rest.shape[0], NO_PROGRAM, dtype=np.int64)
    if isinstance(found, str):
        return index, found
    for n, program in enumerate(found.programs):
        inside = np.all((rest >= np.asarray(program.lo)) & (rest <= np.asarray(program.hi)), axis=1)
        index[(index == NO_PROGRAM) & inside] = n
    return index, ""


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
    choice: deform.DeformationChoice,
    skeleton: Skeleton,
    on_seam: npt.NDArray[np.bool_],
) -> deform.Skinned:
    """The skin of the seam and its one-ring only, the rest left at rest: the sweep reads the seam's
    positions and ``correct`` the fans of the vertices it moves, which lie within that ring. Skinning is
    per vertex, so these rows are the very values a whole-mesh skin gives; a seam of 2 k vertices on a
    325 k-vertex body paid for all of them at every pose (11.5 s of seed 96's 78 s)."""
    ring = np.zeros(mesh.vertex_count, dtype=bool)
    ring[mesh.faces[on_seam[mesh.faces].any(axis=1)].reshape(-1)] = True
    rows = np.flatnonzero(ring | on_seam)
    part = deform.skin(
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
    return deform.Skinned(positions, out_normals, part.flips)


def correction_sweep(
    rig: CompiledRig,
    mesh: Mesh,
    normals: F64,
    weights: tuple[npt.NDArray[np.int32], F64],
    skeleton: Skeleton,
    choice: deform.DeformationChoice,
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
        for _, pose in deform.sweep_poses(
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


def _skin_departures(
    rig: CompiledRig,
    mesh: Mesh,
    normals: F64,
    weights: SkinWeights,
    skeleton: Skeleton,
    choice: deform.DeformationChoice,
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


def _never_worse(report: CorrectionReport) -> SurfaceGate:
    return SurfaceGate(
        "correctionNeverWorse",
        report.residual_after - report.residual_before,
        0.0,
        "m",
        "max",
        "the corrected residual may not exceed the skinned one",
    )


def runtime_skin(
    indices: npt.NDArray[np.int32],
    weights: F64,
    choice: deform.DeformationChoice,
    skeleton: Skeleton,
    region: npt.NDArray[np.bool_],
    programs: npt.NDArray[np.int64],
    trust: F64,
) -> npt.NDArray[np.float32]:
    """(V, 2) what the runtime needs per vertex: its skinning method code and its correction trust radius.

    The trust radius is zero outside the region policy's vertices (and where no candidate program covers
    a vertex), so the runtime corrects exactly the vertices the build proved need it.
    """
    method = deform.vertex_methods(indices, weights, choice.methods, skeleton).astype(np.float64)
    radius = np.where(region & (programs != NO_PROGRAM), trust, 0.0)
    return np.stack([method, radius], axis=1).astype(np.float32)


def posed_gate_rows(sidecar: dict[str, object]) -> list[dict[str, object]]:
    """The posed-skin gates (surface/posed.py) as the sidecar records them (cache hits included)."""
    posed = sidecar.get("posed")
    rows = posed.get("gates", []) if isinstance(posed, dict) else []
    return [r for r in rows if isinstance(r, dict)] if isinstance(rows, list) else []


def refuse_posed(sidecar: dict[str, object], tier: str) -> None:
    """Raise SurfaceRejectedError when a posed-skin gate failed. The gates are recorded, not enforced by
    the build: the caller asks for this (``creaturegen build --posed-gates refuse``)."""
    _fail_on(
        [_gate_from_row(r) for r in posed_gate_rows(sidecar)], f"surface {tier} posed skin", POSED_REMEDY
    )


def _fail_on(gates: list[SurfaceGate], where: str, remedy: str = "") -> None:
    failed = [g for g in gates if not g.passed]
    if failed:
        g = failed[0]
        more = f" (also failed: {', '.join(f.name for f in failed[1:])})" if len(failed) > 1 else ""
        detail = f": {g.detail}" if g.detail else ""
        raise SurfaceRejectedError(
            f"{where}: gate {g.name} = {g.value:.4g} {g.unit}, "
            f"threshold {g.threshold:.4g} ({g.direction}){detail}{more}{remedy}"
        )


def _mesh_remedy(gates: list[SurfaceGate], certain: bool, refinement: int, spacing: float) -> str:
    """What the build tried for a failed mesh gate, and what the user can change (the gate names the
    place). A wrong genus gets no flips or splits (they cannot change it), and its detail already names
    the contacts to move, so widening a blend would be the wrong advice there."""
    where = f"refinement {refinement} at h = {spacing:.3g} m"
    if any(g.name == "euler" and not g.passed for g in gates):
        if certain:
            return (
                f" (at {where}; the field closes these handles at any lattice): move or shrink the parts "
                "named so they meet only at their joints"
            )
        return (
            f"; refining the lattice did not open the handles (the finest lattice tried, {where}, is "
            "reported): move or shrink the parts named so they meet only at their joints"
        )
    return (
        f"; flipping edges, splitting triangles toward the field and refining the lattice did not help "
        f"(the best lattice tried, {where}, is reported): a feature there is thinner or tighter than the "
        "lattice resolves; thicken the part named, or widen the blend k (or the gap) where it meets its "
        "neighbour"
    )


def surface_mesh_gates(
    rig: CompiledRig, ex: Extraction, rest_field: BodyField, skeleton: Skeleton, spacing: float
) -> tuple[list[SurfaceGate], ComponentPolicy]:
    """Every mesh gate at the pipeline's thresholds, plus the component policy's (one list for the
    build and bench/surface, so both judge a mesh the same way). When the euler gate fails, the policy
    carries the contacts that close the handles and the gate's detail names them."""
    names = skeleton.names
    policy = component_policy(ex.mesh, rig.slots, rig.graph, names)
    gates = mesh_gates(
        ex.mesh,
        length_scale=rig.body_scale,
        distance=rest_field.distance,
        gradient=rest_field.gradient,
        field=rest_field.field,
        expected_components=policy.expected,
        min_angle_bound_deg=MIN_ANGLE_P1_DEG,
        vertex_normal_max_deg=NORMAL_LIMITS[0],
        vertex_normal_p99_deg=NORMAL_LIMITS[1],
        face_normal_max_deg=NORMAL_LIMITS[2],
        face_normal_p99_deg=NORMAL_LIMITS[3],
        smooth=rest_field.smooth(CREASE_BAND_CELLS * spacing),
    )
    strays = f"components {list(policy.strays)} own no slot" if policy.strays else ""
    euler = next(g for g in gates if g.name == "euler")
    if not euler.passed:
        distances = rest_field.slot_distances(ex.mesh.vertices)
        found = handle_contacts(ex.mesh, distances, rest_field.distance, skeleton, rig.slots, rig.slot_parts)
        policy = replace(policy, handles=found)
        gates = [_name_parts(g, ex.mesh, policy, names) if g is euler else g for g in gates]
    gates = [g if g.passed or g.where is None else _name_part_at(g, rest_field, names) for g in gates]
    gates += [
        SurfaceGate("strayComponents", float(len(policy.strays)), 0.0, "components", "max", strays),
        SurfaceGate(
            "unownedSlots",
            float(len(policy.unowned_slots)),
            0.0,
            "slots",
            "max",
            ", ".join(policy.unowned_slots),
        ),
        SurfaceGate("unbracketedEdges", float(ex.unresolved_edges), 0.0, "vertices", "max"),
    ]
    return gates, policy


def _name_parts(
    gate: SurfaceGate, mesh: Mesh, policy: ComponentPolicy, names: tuple[str, ...]
) -> SurfaceGate:
    """The euler gate's detail rewritten to name the contacts that close the handles (the parts to move)
    and, failing that, the parts of every component that is not a sphere."""
    found = components(mesh)
    bad = [c for c in range(found.count) if int(found.euler[c]) != 2]
    culprits = [c for c in policy.handles if c.culprit]
    if culprits:
        genus = sum(float(found.genus[c]) for c in bad)
        detail = f"genus {genus:g}, expected 0 (the skeleton is a tree): " + "; ".join(
            c.describe() for c in culprits
        )
        return SurfaceGate(gate.name, gate.value, gate.threshold, gate.unit, gate.direction, detail)
    parts = []
    for c in bad:
        owned = ", ".join(n for n, o in zip(names, policy.owners, strict=True) if o == c)
        parts.append(f"genus {float(found.genus[c]):g} in the component of {owned}")
    return SurfaceGate(gate.name, gate.value, gate.threshold, gate.unit, gate.direction, "; ".join(parts))


def _name_part_at(gate: SurfaceGate, rest_field: BodyField, names: tuple[str, ...]) -> SurfaceGate:
    """A failed gate's detail with the part whose primitive is nearest the gate's worst point."""
    assert gate.where is not None
    slot = int(np.argmin(rest_field.slot_distances(np.asarray([gate.where]))[:, 0]))
    at = ", ".join(f"{v:.4g}" for v in gate.where)
    detail = "; ".join(x for x in (gate.detail, f"near {names[slot]} at ({at}) m") if x)
    return replace(gate, detail=detail)


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
    rig: CompiledRig, skeleton: Skeleton, tier: str, chosen: FieldBackend, why: str, progress: Progress
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
            attempt = _one_lattice(rig, skeleton, tier, chosen, why, progress, refinement)
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
    chosen: FieldBackend,
    why: str,
    progress: Progress,
    refinement: int,
) -> ValidatedMesh:
    """One lattice: sample, extract and gate (or, when ``_deferred``, only the genus)."""
    timings: dict[str, float] = {"sampling": 0.0, "extraction": 0.0, "validation": 0.0}
    rest_field = BodyField(rig.graph, rig.slots)
    grid = make_grid(rig.slots, rig.graph, tier, rig.slot_parts, refinement)
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
    gates, policy = surface_mesh_gates(rig, ex, rest_field, skeleton, grid.spacing)
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
        ex, gates, policy, failed = _remedied(
            rig, ex, gates, policy, failed, rest_field, skeleton, grid, progress, refine_next
        )
        timings["validation"] += time.perf_counter() - t
    return ex, gates, policy, failed


def _no_worse(failed: list[str], still: list[str]) -> bool:
    """Whether a remedy's mesh is kept: fewer gates fail, or the same number and none that passed before."""
    return len(still) < len(failed) or (len(still) == len(failed) and set(still) <= set(failed))


Remedy = tuple[Extraction, list[SurfaceGate], ComponentPolicy, list[str]]


def _remedied(
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

    def split(base: Extraction, flipped_too: int) -> Remedy | None:
        """``base`` split toward the field and gated against the current failures: the result if kept.
        While a p99 gate still fails, its tail is split too (subdivide.TAIL_MARKS) and kept if no worse."""
        best: Remedy | None = None
        against = failed
        for marks in ((MARK_VERTEX_DEG, MARK_FACE_DEG), TAIL_MARKS):
            if marks == TAIL_MARKS and not set(against) & P99_GATES:
                break
            candidate, added, declined = _split_toward_field(
                base if best is None else best[0], rest_field, marks
            )
            if not added:
                continue
            kept, result = _judged(rig, candidate, against, rest_field, skeleton, grid, refine_next)
            what = (
                "where the normals disagree"
                if marks != TAIL_MARKS
                else "where the normals pass the p99 bounds"
            )
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


def _spread_steep_weights(
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
        normal_limits=NORMAL_LIMITS,
        smooth=smooth,
    )
    partial = [g.name for g in normals if not g.passed]
    if not _may_be_no_worse(failed, partial) or (refine_next and set(partial) - P99_GATES):
        return False, (candidate, normals, ComponentPolicy(0, (), (), (), (), ()), partial)
    again, again_policy = surface_mesh_gates(rig, candidate, rest_field, skeleton, grid.spacing)
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


def build_surface(
    spec: CharacterSpec,
    rig: CompiledRig,
    *,
    tier: str = DEFAULT_TIER,
    backend: str = "auto",
    cache: SurfaceCache | None = None,
    progress: Progress = stderr_progress,
    strict: bool = True,
) -> SurfaceBuild:
    """The validated reference surface of one body at one tier (from the cache when it is there)."""
    extra: dict[str, object] = {"creaturegen": __version__, "sources": identity.source_digest()}
    compiler = identity.compiler_signature(rig, tier, extra)
    geometry = rig_signatures(rig).geometryDigest
    settings = identity.settings_digest(tier, extra)
    key = _Key(geometry, settings, extra)
    if cache is None:
        return _extract_surface(spec, rig, key, tier, backend, None, progress, strict)
    with cache.building(compiler, geometry, tier, settings):
        hit: CachedSurface | None = cache.lookup(compiler, geometry, tier, settings)
        if hit is not None:
            progress(f"cache hit {hit.folder}")
            cached = tuple(_gate_from_row(g) for g in _gate_rows(hit.sidecar))
            return SurfaceBuild(
                tier, dict(_sig_rows(hit.sidecar)), hit.asset, hit.sidecar, cached, True, hit.folder
            )
        return _extract_surface(spec, rig, key, tier, backend, cache, progress, strict)


@dataclass(frozen=True)
class _Key:
    """What the cold path needs of the lookup key (the compilerSignature is recomputed with the rest)."""

    geometry: str
    settings: str
    extra: dict[str, object]


def _extract_surface(
    spec: CharacterSpec,
    rig: CompiledRig,
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
    skeleton = build_skeleton(spec, rig)
    with start_pose_envelope(spec, rig, skeleton) as pending:
        return _extract_with(spec, rig, key, tier, backend, cache, progress, strict, pending, skeleton)


def _extract_with(
    spec: CharacterSpec,
    rig: CompiledRig,
    key: _Key,
    tier: str,
    backend: str,
    cache: SurfaceCache | None,
    progress: Progress,
    strict: bool,
    pending: PendingEnvelope,
    skeleton: Skeleton,
) -> SurfaceBuild:
    """``_extract_surface`` with its envelope under way."""
    geometry, settings, extra = key.geometry, key.settings, key.extra
    t0 = time.perf_counter()
    chosen, why = choose_backend(rig, backend, progress, tier)
    rest_field = BodyField(rig.graph, rig.slots)
    validated = validated_mesh(rig, skeleton, tier, chosen, why, progress)
    ex, gates, policy, grid = validated.extraction, validated.gates, validated.policy, validated.grid
    mesh, refinement, sampling, timings = ex.mesh, validated.refinement, validated.sampling, validated.timings
    t = time.perf_counter()
    envelope = pending.result()
    timings["envelope"] = time.perf_counter() - t
    progress(
        f"motion envelope: {len(envelope.runs)} runs × {envelope.ticks} ticks "
        f"({envelope.samples:,} poses measured; waited {timings['envelope']:.2f} s after the mesh)"
    )
    if policy.detached:
        progress(f"declared: {', '.join(policy.detached)} detached from the body (the field leaves a gap)")
    if strict:
        _fail_on(
            gates, f"surface {tier}", _mesh_remedy(gates, policy.handles_certain, refinement, grid.spacing)
        )

    t = time.perf_counter()
    still = envelope.still_joints(rig.body_scale)
    weights = skin_weights(mesh, rest_field, skeleton, still=still)
    if not weights.gate("weights.continuity").passed and not [g for g in gates if not g.passed]:
        ex, gates, policy, weights = _spread_steep_weights(
            rig, (ex, gates, policy, []), weights, rest_field, skeleton, grid, still, progress
        )
        mesh = ex.mesh
    gates += list(weights.gates)
    timings["weights"] = time.perf_counter() - t
    progress(f"skin weights: {weights.barrier_edges} barrier edges, {timings['weights']:.2f} s")
    if strict:
        _fail_on(list(weights.gates), f"surface {tier} skin weights")

    t = time.perf_counter()
    choice = deform.choose_deformation(
        mesh,
        weights.indices,
        weights.weights,
        rest_field,
        skeleton,
        rig.slots,
        rig.graph,
        rig.body_scale,
        limits={j.child: envelope.sweep_limits(j.child) for j in envelope.joints},
        limits_from="motion envelope (motion/envelope.py), widened by its margins",
        limits_at={j.child: j.worst_run for j in envelope.joints},
        corrector=deform.seam_corrector(
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
    timings["deformation"] = time.perf_counter() - t
    for joint in choice.joints:
        gates += [
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
    counts = {m: choice.methods.count(m) for m in deform.METHODS}
    progress(f"deformation per joint: {counts} in {timings['deformation']:.2f} s")

    t = time.perf_counter()
    found: CandidateSet | str
    colour: BakedColour | None = None
    contract: SkinContract | None = None
    skin_tol = TIERS[tier].skin
    if skin_tol is None:
        found = tier_candidates(spec, rig, tier, envelope)
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
        colour, departures = _skin_departures(
            rig, mesh, ex.normals, weights, skeleton, choice, envelope.poses
        )
        # ... and those the skin carries within the tier's tolerances evaluate nothing at all.
        in_field = region | field_vertices(departures, SKIN_ERROR_FACTOR * rig.body_scale, skin_tol)
        programs = np.where(in_field, 0, SKIN_PROGRAM).astype(np.int64)
        contract = skin_contract(departures, in_field, weights.indices[:, 0], rig, colour)
        correction_gates = [_never_worse(report)]
        progress(
            f"skin representation: {contract.field_vertices:,} of {contract.vertices:,} vertices evaluate "
            f"the field (correction region {int(region.sum()):,}); skin vertices depart at most "
            f"{contract.error / rig.body_scale:.2e} L (under {SUBPIXEL_PX} px up to "
            f"{contract.projected_px:.0f} px across L), normals p99 {contract.normal_deg[1]:.1f}°, "
            f"colour p99 ΔE {contract.delta_e[1]:.3f}"
        )
    else:
        correction_gates = [
            _never_worse(report),
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
    timings["correction"] = time.perf_counter() - t
    gates += correction_gates
    if strict:
        _fail_on(correction_gates, f"surface {tier} correction")

    t = time.perf_counter()
    pair = (weights.indices, weights.weights)
    quality = posed_quality(
        rig,
        mesh,
        pair,
        choice_skinner(mesh, ex.normals, pair, skeleton, choice),
        np.where(region & (programs != NO_PROGRAM), trust, 0.0),
        envelope.poses,
        envelope.pose_labels,
    )
    names = skeleton.names
    posed = posed_gates(quality, [names[s] for s in weights.indices[mesh.faces[:, 0], 0]])
    timings["posed"] = time.perf_counter() - t
    creases = max((p.creases for p in quality.poses), default=0)
    progress(
        f"posed skin over {len(quality.poses)} envelope poses: "
        + ", ".join(f"{g.name.removeprefix('posed.')} {g.value:g}" for g in posed)
        + f" (visible creases along the parts' hard union: {creases}) in {timings['posed']:.2f} s"
    )

    from .frames import radial_coordinates, rest_frames

    frames = rest_frames(rig, skeleton)
    dominant = weights.indices[:, 0]
    radial = np.zeros((mesh.vertex_count, 2))
    for s in range(rig.slot_count):
        rows = np.flatnonzero(dominant == s)
        if rows.size:
            length = float(np.linalg.norm(rig.slots[s, col.B] - rig.slots[s, col.A]))
            theta, along = radial_coordinates(mesh.vertices[rows], frames[s], length)
            radial[rows, 0], radial[rows, 1] = theta, along

    sig = identity.surface_signatures(rig, tier, mesh.faces, choice.methods, extra)
    signatures = {
        "compilerSignature": sig.compilerSignature,
        "topologySignature": sig.topologySignature,
        "geometryDigest": sig.geometryDigest,
    }
    asset = SurfaceAsset(
        positions=mesh.vertices.astype(np.float32),
        normals=ex.normals.astype(np.float32),
        indices=mesh.faces.reshape(-1).astype(np.uint32),
        slots=weights.indices.astype(np.uint16),
        weights=weights.weights.astype(np.float32),
        candidate=programs.astype(np.uint16),
        radial=radial.astype(np.float32),
        rest_frames=np.transpose(frames, (0, 2, 1)).astype(np.float32),
        skin=runtime_skin(weights.indices, weights.weights, choice, skeleton, region, programs, trust),
        cor_centers=np.where(
            (deform.vertex_methods(weights.indices, weights.weights, choice.methods, skeleton) == 2)[:, None],
            choice.centers,
            0.0,
        ).astype(np.float32),
        extras={"creaturegen": __version__, "tier": tier, **signatures},
        colour_slots=None if colour is None else colour.slots,
        colour_weights=None if colour is None else colour.weights,
    )
    sidecar: dict[str, object] = {
        "tier": tier,
        "signatures": signatures,
        "counts": {"vertices": mesh.vertex_count, "triangles": mesh.face_count, "slots": rig.slot_count},
        "grid": {
            "shape": list(grid.shape),
            "spacing": grid.spacing,
            "origin": list(grid.origin),
            "refinement": refinement,
            "limitedBy": grid.limited_by,
        },
        "sampling": sampling.as_dict(),
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
            "region": int(region.sum()),
            "skinOnlyError": worst_skin,
            "candidateNote": candidate_note,
        },
        "posed": {**quality.describe(), "gates": [g.as_dict() for g in posed]},
        "gates": [g.as_dict() for g in gates],
        "timings": timings,
    }
    if contract is not None and colour is not None:
        sidecar["skinRepresentation"] = contract.describe()
    folder = None
    if cache is not None:
        folder = cache.store(
            sig.compilerSignature, sig.topologySignature, geometry, tier, settings, asset, sidecar
        )
    timings["total"] = time.perf_counter() - t0
    return SurfaceBuild(tier, signatures, asset, sidecar, tuple(gates), False, folder, timings, found)


def _gate_rows(sidecar: dict[str, object]) -> list[dict[str, object]]:
    rows = sidecar.get("gates", [])
    assert isinstance(rows, list)
    return [{k: v for k, v in row.items() if k != "passed"} for row in rows]


def _gate_from_row(row: dict[str, object]) -> SurfaceGate:
    direction: Direction = "min" if row.get("direction") == "min" else "max"
    value, threshold = row["value"], row["threshold"]
    assert isinstance(value, int | float)
    assert isinstance(threshold, int | float)
    return SurfaceGate(
        str(row["name"]),
        float(value),
        float(threshold),
        str(row["unit"]),
        direction,
        str(row.get("detail", "")),
    )


def _sig_rows(sidecar: dict[str, object]) -> dict[str, str]:
    sig = sidecar.get("signatures", {})
    assert isinstance(sig, dict)
    return {str(k): str(v) for k, v in sig.items()}
