"""Choosing per joint which skinning to trust (seed step 6).

Three methods skin the reference mesh to the slots (surface/skinning.py says why: LBS collapses under
twist, DQ bulges under bend, CoR costs a precomputation). The choice is made per joint by posing only
that joint over a bend and a twist sweep, skinning the affected vertices with each method, and
measuring against the truth: the smooth-min field of the posed slot table (surface/sweep.py). The first
method (LBS, then DQ, then CoR) whose every gate passes over the whole sweep (surface/sweep_gates.py)
is chosen; if none passes, even with the seam corrected toward the posed field (:func:`seam_corrector`),
:class:`DeformationError` names the joint and the failed gates.

The data flows one way: skinning.py (the formulas) → joint_sets.py (what a sweep reads of the mesh) →
sweep.py (measure one joint) → sweep_gates.py (judge each method) → this module (choose, and the
:class:`DeformationChoice` the build stores and skins with).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..model.graph import BlendGraph
from ..model.rotations import Pose, posed_slots
from ..model.skeleton import Skeleton
from .correct import correct
from .field64 import BodyField
from .gates import SurfaceGate
from .joint_sets import JointSet, RestMesh, any_rows, rest_mesh
from .mesh import Mesh, unit_rows
from .skinning import Method, as_arrays, centers_of_rotation, cofactor
from .sweep import (
    BEND_MAX_DEG,
    SWEEP_STEPS,
    TWIST_MAX_DEG,
    Corrector,
    SweepMeasures,
    measure_sweep,
    sweep_poses,
)
from .sweep_gates import MethodSweep, method_sweeps

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]


class DeformationError(Exception):
    """No skinning method passes a joint's sweep; the message names the joint and the failed gates."""

    def __init__(
        self,
        joint: str,
        sweeps: Sequence[MethodSweep],
        bend_deg: float = 0.0,
        twist_deg: float = 0.0,
        corrected: Sequence[MethodSweep] = (),
        worst_run: str = "",
    ) -> None:
        self.joint = joint
        self.sweeps = tuple(sweeps)

        def listed(group: Sequence[MethodSweep]) -> str:
            return "; ".join(
                f"{s.method}: "
                + ", ".join(f"{g.name} {g.value:.4g} vs {g.threshold:.4g} {g.unit}" for g in s.failed)
                for s in group
            )

        failed = listed(sweeps)
        if corrected:
            failed += f"; tried with the seam corrected toward the field: {listed(corrected)}"
        where = f", most in the envelope run '{worst_run}'" if worst_run else ""
        reach = (
            f"; the motion turns this joint up to {bend_deg:.0f}° bend and {twist_deg:.0f}° twist (swept "
            f"with its margin{where}): a smaller turn (a shorter step or hop, a longer limb; on a slope, "
            "legs long enough to reach the ground under the whole body, which stays upright) or a thinner "
            "limb at the joint keeps it within what skinning can carry"
            if bend_deg or twist_deg
            else ""
        )
        super().__init__(f"{joint}: no skinning method passes the bend/twist sweep ({failed}){reach}")


@dataclass(frozen=True)
class JointChoice:
    """The method one joint gets, with every method's sweep so a report can say why."""

    joint: str  # the child slot's name: the joint is where it hangs from its parent
    parent: int
    child: int
    method: Method
    radius: float  # r_j, m: the child's radius at its pivot end
    scale: float  # s_j = max(r_j, pivot → nearest seam vertex), m: the unit of the joint's gates
    seam_vertices: int  # vertices weighted across the joint (the measured set)
    sweeps: tuple[MethodSweep, ...]  # every method measured, in preference order
    bend_max_deg: float  # the limits this joint was swept to
    twist_max_deg: float
    corrected: bool = False  # passed only with its seam corrected (choose_deformation's remedy)

    @property
    def gates(self) -> tuple[SurfaceGate, ...]:
        """The chosen method's gates, all passed."""
        return next(s.gates for s in self.sweeps if s.method == self.method)

    def describe(self) -> dict[str, object]:
        return {
            "joint": self.joint,
            "parent": self.parent,
            "child": self.child,
            "method": self.method,
            "radius": self.radius,
            "scale": self.scale,
            "seam_vertices": self.seam_vertices,
            "bend_max_deg": self.bend_max_deg,
            "twist_max_deg": self.twist_max_deg,
            "corrected": self.corrected,
            "sweeps": [s.describe() for s in self.sweeps],
        }


@dataclass(frozen=True)
class DeformationChoice:
    """Every joint's choice, and what :func:`~creaturegen.surface.skinning.skin` needs to apply it."""

    joints: tuple[JointChoice, ...]
    methods: tuple[Method, ...]  # per slot: its joint's method; roots "lbs"
    centers: F64  # (V, 3) CoR centres, for skinning.skin where a joint chose "cor"
    limits: str  # where the joints' sweep limits came from
    steps: int
    seconds: float

    def describe(self) -> dict[str, object]:
        return {
            "limits": self.limits,
            "steps": self.steps,
            "seconds": self.seconds,
            "methods": list(self.methods),
            "joints": [j.describe() for j in self.joints],
        }


def seam_corrector(
    mesh: Mesh,
    normals: F64,
    rest_slots: F64,
    graph: BlendGraph,
    trust: F64,
    gate: float,
    skeleton: Skeleton,
    indices: I64,
    weights: F64,
) -> Corrector:
    """The bounded correction of surface/correct.py applied to a joint sweep's seam: every seam vertex the
    skin leaves farther than ``gate`` from the posed field is corrected within its ``trust`` radius (the
    runtime corrects the same vertices: a joint chosen this way puts its whole seam in the correction
    region, surface/correction_region.py), with the full-mesh inversion check over the fans it moves."""

    def apply(child: int, js: JointSet, pose: Pose, seam: F64, maps: F64, is_lbs: bool) -> F64:
        q, t = pose.rotations[child], pose.translations[child]
        live = weights > 0
        rigid = any_rows(js.moving[indices] & live) & ~any_rows(~js.moving[indices] & live)
        full = mesh.vertices.copy()
        full[rigid] = mesh.vertices[rigid] @ q.T + t
        full[js.seam] = seam
        turned = normals.copy()
        turned[rigid] = normals[rigid] @ q.T
        rest_n = normals[js.seam]
        mapped = np.einsum("vij,vj->vi", cofactor(maps) if is_lbs else maps, rest_n)
        turned[js.seam] = unit_rows(mapped)
        field = BodyField(graph, posed_slots(rest_slots, pose))
        region = np.zeros(mesh.vertex_count, dtype=bool)
        region[js.seam] = np.abs(field.distance(seam)) > gate
        out, _ = correct(field, mesh, full, turned, region, trust)
        result: F64 = out[js.seam]
        return result

    return apply


@dataclass(frozen=True)
class _Body:
    """What every joint's sweep of one body reads, and the two steps of a sweep: measure, then judge."""

    rest: RestMesh
    indices: I64
    weights: F64
    skeleton: Skeleton
    rest_slots: F64
    graph: BlendGraph
    length_scale: float

    def sweep(
        self, child: int, poses: list[tuple[str, Pose]], corrector: Corrector | None = None
    ) -> tuple[SweepMeasures, tuple[MethodSweep, ...]]:
        """One joint's sweep over ``poses`` (its seam corrected by ``corrector`` when given), measured
        and judged method by method."""
        measured = measure_sweep(
            self.rest,
            self.indices,
            self.weights,
            self.skeleton,
            self.rest_slots,
            self.graph,
            self.length_scale,
            child,
            poses,
            corrector,
        )
        return measured, method_sweeps(measured, self.length_scale, self.rest.volume)


def _choose_joint(
    body: _Body,
    parent: int,
    child: int,
    poses: list[tuple[str, Pose]],
    limits: tuple[float, float],
    worst_run: str,
    corrector: Corrector | None,
) -> JointChoice:
    """The first method that passes the joint above ``child`` over ``poses`` (swept to ``limits``, bend
    and twist in degrees), by skinning alone or, failing that, with its seam corrected; else refused."""
    bend, twist = limits
    name = body.skeleton.names[child]
    result, sweeps = body.sweep(child, poses)
    chosen = next((s.method for s in sweeps if s.passed), None)
    corrected = False
    if chosen is None and corrector is not None:
        retry, retry_sweeps = body.sweep(child, poses, corrector)
        chosen = next((s.method for s in retry_sweeps if s.passed), None)
        if chosen is None:
            raise DeformationError(name, sweeps, bend, twist, retry_sweeps, worst_run)
        result, sweeps, corrected = retry, retry_sweeps, True
    if chosen is None:
        raise DeformationError(name, sweeps, bend, twist, worst_run=worst_run)
    return JointChoice(
        name,
        parent,
        child,
        chosen,
        result.radius,
        result.scale,
        result.seam_vertices,
        sweeps,
        bend,
        twist,
        corrected,
    )


def choose_deformation(
    mesh: Mesh,
    indices: npt.ArrayLike,
    weights: npt.ArrayLike,
    field_rest: BodyField,
    skeleton: Skeleton,
    rig_slots: F64,
    graph: BlendGraph,
    length_scale: float,
    *,
    bend_max_deg: float = BEND_MAX_DEG,
    twist_max_deg: float = TWIST_MAX_DEG,
    steps: int = SWEEP_STEPS,
    centers: F64 | None = None,
    limits: Mapping[int, tuple[float, float]] | None = None,
    limits_from: str = "",
    corrector: Corrector | None = None,
    limits_at: Mapping[int, str] | None = None,
) -> DeformationChoice:
    """Sweep every joint with every method and keep, per joint, the first method that passes every gate.

    Raises :class:`DeformationError` for the first joint no method can carry. ``field_rest`` is the rest
    body the mesh was extracted from; its slots must be ``rig_slots``. ``centers`` (from
    :func:`~creaturegen.surface.skinning.centers_of_rotation`) are computed when not given. ``limits``
    maps a joint's child slot to its (bend, twist) sweep limits in degrees (the measured motion envelope,
    motion/envelope.py); a joint not in it is swept to ``bend_max_deg`` and ``twist_max_deg``. A joint
    swept to zero never turns: every method reproduces it exactly and the cheapest is kept.
    ``limits_at`` names, per joint, the motion whose turn set its limits, for a refusal's message.

    Remedy before refusal: where no method passes by skinning alone and a ``corrector`` is given
    (:func:`seam_corrector`), the joint is swept again with every method's seam corrected toward the
    posed field as the shipped body corrects it, and the first method that passes then is kept, marked
    ``corrected`` (its seam joins the correction region). A thick hip's DQ bulge or CoR collapse that the
    correction pulls back is not what a user sees.
    """
    start = time.perf_counter()
    idx, w = as_arrays(indices, weights)
    if not np.array_equal(field_rest.slots, rig_slots):
        raise ValueError("field_rest must be the field of rig_slots")
    rest = rest_mesh(mesh, centers if centers is not None else centers_of_rotation(mesh, idx, w))
    body = _Body(rest, idx, w, skeleton, rig_slots, graph, length_scale)
    methods: list[Method] = ["lbs"] * len(skeleton.parent)
    joints = []
    for parent, child in skeleton.joints:
        bend, twist = (limits or {}).get(child, (bend_max_deg, twist_max_deg))
        worst = (limits_at or {}).get(child, "")
        poses = sweep_poses(skeleton, rig_slots, child, bend, twist, steps)
        joint = _choose_joint(body, parent, child, poses, (bend, twist), worst, corrector)
        methods[child] = joint.method
        joints.append(joint)
    where = limits_from or f"every joint {bend_max_deg:g}° bend, {twist_max_deg:g}° twist"
    return DeformationChoice(
        tuple(joints),
        tuple(methods),
        rest.centers,
        where,
        steps,
        time.perf_counter() - start,
    )
