"""Skinning the reference mesh to the slots, and choosing per joint which skinning to trust (seed step 6).

Why three methods and a sweep rather than one method everywhere:
- Linear blend skinning (LBS) averages matrices. It is exact for rigid regions and cheap, but a blend of
  two rotations is not a rotation: under twist the seam shrinks towards the bone (the candy wrapper) and
  under bend the elbow loses volume. Whether that matters depends on the joint's weights and range, so
  LBS is kept only where a bend/twist sweep shows it stays within the gates.
- Dual-quaternion skinning (DQ) blends rigid motions, so a joint rotation about a pivot stays a
  rotation about that pivot: no collapse, but the inside of a bend bulges. Quaternions q and −q are the
  same rotation; blending must first bring every influence into one hemisphere or a vertex can swing the
  long way round (or collapse where the sum cancels).
- Centre-of-rotation skinning (CoR, Le & Hodgins 2019) blends rotations as quaternions and takes the
  translation from LBS applied to one precomputed point per vertex, the point of the rest mesh whose
  weights look like the vertex's own. It removes both the collapse and most of the bulge, at the cost of
  a precomputation; it is the last resort.

The choice is made per joint by posing only that joint over a bend and a twist sweep, skinning the
affected vertices with each method, and measuring against the truth: the smooth-min field of the posed
slot table. The first method (LBS, then DQ, then CoR) whose every gate passes over the whole sweep is
chosen; if none passes, :class:`DeformationError` names the joint and the failed gates.

Conventions: a pose maps rest to posed, per slot ``x' = R_s x + t_s``; quaternions are ``(w, x, y, z)``;
angles of the public pose helpers are radians, sweep limits are degrees.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Final, Literal

import numpy as np
import numpy.typing as npt

from ..model import layout as col
from ..model.graph import BlendGraph
from ..model.rotations import (
    Pose,
    matrix_to_quaternion,
    posed_slots,
    quaternion_multiply,
    quaternion_to_matrix,
)
from ..model.skeleton import Skeleton, pose_joint, subtree
from . import topology
from .correct import correct
from .field64 import BodyField
from .gates import SurfaceGate
from .mesh import Mesh, angles_deg, unit_rows

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
Bools = npt.NDArray[np.bool_]
Method = Literal["lbs", "dq", "cor"]
#: Preference order: the cheapest method whose sweep passes wins.
METHODS: Final[tuple[Method, ...]] = ("lbs", "dq", "cor")

# --------------------------------------------------------------------------------------------- gates
# Two kinds of gate. The error a posed seam shows has two sources: the weights' transition (a vertex
# with 30 % of its weight on the parent lags 30 % of the rotation behind the child, whatever the method)
# and the method's blending. Measured over the examples at the default sweep, the first dominates
# (0.2 to 1.8·r_j near the joint for every method alike), so an absolute bound tight enough to see a
# method's artefact would reject every method. Hence:
# - absolute gates, every method: what any acceptable skin may do (surface_max, surface_p99,
#   joint_collapse). When no method meets them the joint is broken and the build fails;
# - relative gates: what a method adds on top of what the weights already cost, against the best of
#   the three at the same pose (surface_excess, every method; bulge_excess, DQ and CoR) or against DQ,
#   which moves every vertex rigidly (volume_loss, LBS). The split follows the seed: LBS is kept where
#   its twist/volume sweep passes, DQ and CoR are gated on their bulge and twist errors.
# Folds (dihedral increase, flipped faces) are measured and reported but not gated: at the default
# sweep every method folds the inner crease of most thin-limb joints (0.5 to 8 % of the seam faces,
# often more for DQ than for LBS), so a gate would reject every method; the correction pass checks
# inversions where they matter.

#: Sweep limits (degrees) of a joint the caller gives no limits for (the build gives every joint the
#: limits of the measured motion envelope, motion/envelope.py), and angle steps per sweep direction
#: (bend: ±e1, ±e2 about the pivot; twist: ± about the child's rest tangent).
BEND_MAX_DEG: Final = 60.0
TWIST_MAX_DEG: Final = 45.0
SWEEP_STEPS: Final = 3
# Lengths are in units of the joint scale s_j = max(r_j, D): r_j is the child's radius at its pivot end
# and D the distance from the pivot to the nearest seam vertex. D ≈ r_j for a knee; where the pivot is
# buried inside the parent (a hip, a tail fin) the seam turns on a longer lever, every method moves it
# further, and its artefacts grow with D as they grow with r_j elsewhere.
#: Largest side-aware surface error (see :func:`_joint_sweep`) near the joint, × s_j. A skinned joint off
#: the posed body by more than two of its own radii no longer reads as the same limb, and is far beyond
#: what the bounded correction pass (a fraction of the slot radius per vertex) can pull back.
SURFACE_MAX_FACTOR: Final = 2.0
#: Its 99th percentile, × s_j: the bulk of the joint ring must stay within one and a half radii.
SURFACE_P99_FACTOR: Final = 1.5
#: What a method may add over the best method at the same pose, × s_j, to the worst surface error and
#: to the worst outward error (bulge). A quarter radius is where a thinned or swollen joint starts to
#: read as a different shape next to the alternative.
EXCESS_FACTOR: Final = 0.25
#: Volume a method loses against DQ at the same pose (ΔV_dq − ΔV, whole mesh), × the joint volume
#: 4/3·π·r_j²·s_j (the joint ball, stretched along the lever). DQ moves every seam vertex rigidly, so the
#: weights' lag and any overlap change its volume exactly as they change the others'; what remains is
#: the volume a blend gives up by contracting vertices towards the pivot, LBS's elbow and candy-wrapper
#: loss. Half the joint ball is a limb thinned by a tenth of its radius over three and a half radii,
#: about where the thinning becomes visible. (The posed body's own volume change would be the better
#: reference, but integrating the field per pose costs more than the whole sweep.)
VOLUME_FACTOR: Final = 0.5
#: Smallest ratio posed/rest of a seam vertex's distance to the pivot, over the vertices nearest the
#: pivot. A joint rotation keeps every distance to its pivot (DQ reproduces that exactly); LBS's blend
#: of two rotations shortens it to cos(θ/2) at a 50/50 seam. 0.8 admits LBS up to a relative rotation
#: of ~74° (the default 60° bend: 0.87) and rejects the 90° candy wrapper (cos 45° ≈ 0.71).
COLLAPSE_MIN: Final = 0.8
#: The joint region the surface gates read: seam vertices within this many r_j (rest distance to the
#: pivot) of the seam vertex nearest the pivot. Farther seam vertices only show the weights' lag.
JOINT_REACH: Final = 1.0
#: Vertices within this many r_j of the nearest seam vertex form the cross-section the collapse gate reads.
COLLAPSE_REACH: Final = 0.5
#: A seam face counts for the fold measures only where it can be seen: no seam corner deeper inside the
#: posed body than this × r_j. Folds buried in a bent crease or inside another part are hidden.
#: (Approximate: the middle sheet of a fold lies within the depth too.)
VISIBLE_DEPTH: Final = 0.1
#: CoR similarity width σ (Le & Hodgins use 0.1) and the bins per weight axis of its approximation.
COR_SIGMA: Final = 0.1
COR_BINS: Final = 50
#: Rows of the (vertices × weight bins) similarity block evaluated at once.
COR_CHUNK: Final = 4096


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


# ---------------------------------------------------------------------------------------------- poses


def _dual_quaternions(pose: Pose) -> tuple[F64, F64]:
    """Per slot real part q and dual part ½·(0, t)·q."""
    real = matrix_to_quaternion(pose.rotations)
    pure = np.concatenate([np.zeros((pose.slot_count, 1)), pose.translations], axis=1)
    return real, 0.5 * quaternion_multiply(pure, real)


def _hemisphere(quaternions: F64, weights: F64) -> tuple[F64, int]:
    """Signs (V, K) that bring each influence into the hemisphere of the vertex's dominant influence.

    The dominant (largest-weight) influence is the reference because its rotation is the one the vertex
    mostly follows. Once every influence has a non-negative dot with it, the weighted sum has a dot of at
    least the dominant weight with it, so the sum can never cancel and the blend takes the short way.
    Where two influences tie, either reference gives the same rotation (the blend only changes sign).
    Returns the signs and how many influences with nonzero weight had to be flipped.
    """
    dominant = np.argmax(weights, axis=1)
    reference = quaternions[np.arange(quaternions.shape[0]), dominant]
    dots = np.einsum("vkc,vc->vk", quaternions, reference)
    flipped = dots < 0
    return np.where(flipped, -1.0, 1.0), int(np.count_nonzero(flipped & (weights > 0)))


# ------------------------------------------------------------------------------------------- skinning


@dataclass(frozen=True)
class Skinned:
    positions: F64  # (V, 3)
    normals: F64  # (V, 3) unit
    flips: int  # influences brought into the dominant hemisphere (0 for LBS)


def _lbs(vertices: F64, indices: I64, weights: F64, pose: Pose) -> tuple[F64, F64]:
    """Positions and the blended 3×3 part Σ wᵢRᵢ.

    Written as ``v + Σ wᵢ((Rᵢ − I)v + tᵢ)`` so the rest pose returns the rest vertices bit for bit,
    whatever the rounding of Σ wᵢ.
    """
    delta = np.einsum("vk,vkij->vij", weights, (pose.rotations - np.eye(3))[indices])
    shift = np.einsum("vk,vki->vi", weights, pose.translations[indices])
    positions = vertices + np.einsum("vij,vj->vi", delta, vertices) + shift
    matrices = delta + weights.sum(axis=1)[:, None, None] * np.eye(3)
    return positions, matrices


def _cofactor(m: F64) -> F64:
    """det(M)·M⁻ᵀ: maps normals like M⁻ᵀ without dividing by a determinant that may vanish."""
    result: F64 = np.stack(
        [
            np.cross(m[:, :, 1], m[:, :, 2]),
            np.cross(m[:, :, 2], m[:, :, 0]),
            np.cross(m[:, :, 0], m[:, :, 1]),
        ],
        axis=2,
    )
    return result


def _dq(vertices: F64, indices: I64, weights: F64, pose: Pose) -> tuple[F64, F64, int]:
    """Positions, the blended rotation per vertex and the hemisphere flips."""
    real, dual = _dual_quaternions(pose)
    qr, qd = real[indices], dual[indices]
    signs, flips = _hemisphere(qr, weights)
    sw = weights * signs
    br = np.einsum("vk,vkc->vc", sw, qr)
    bd = np.einsum("vk,vkc->vc", sw, qd)
    norm = np.linalg.norm(br, axis=1, keepdims=True)
    br, bd = br / norm, bd / norm
    conj = br * np.array([1.0, -1.0, -1.0, -1.0])
    translation = 2.0 * quaternion_multiply(bd, conj)[:, 1:]
    rotation = quaternion_to_matrix(br)
    return np.einsum("vij,vj->vi", rotation, vertices) + translation, rotation, flips


def _cor(vertices: F64, indices: I64, weights: F64, pose: Pose, centers: F64) -> tuple[F64, F64, int]:
    """QLERP rotation about the vertex's centre p*, which itself moves by LBS.

    ``v' = R(v − p*) + LBS(p*)`` is evaluated as ``Rv + [(p* − Rp*) + Σ wᵢ((Rᵢ − I)p* + tᵢ)]`` so the
    rest pose (R = I, every Rᵢ = I, tᵢ = 0) returns the rest vertices bit for bit.
    """
    q = matrix_to_quaternion(pose.rotations)[indices]
    signs, flips = _hemisphere(q, weights)
    blended = unit_rows(np.einsum("vk,vkc->vc", weights * signs, q))
    rotation = quaternion_to_matrix(blended)
    delta = np.einsum("vk,vkij->vij", weights, (pose.rotations - np.eye(3))[indices])
    shift = np.einsum("vk,vki->vi", weights, pose.translations[indices])
    moved_center = np.einsum("vij,vj->vi", delta, centers) + shift
    translation = (centers - np.einsum("vij,vj->vi", rotation, centers)) + moved_center
    return np.einsum("vij,vj->vi", rotation, vertices) + translation, rotation, flips


def _any_rows(x: Bools) -> Bools:
    result: Bools = np.asarray(np.any(x, axis=1), dtype=bool)
    return result


def _all_rows(x: Bools) -> Bools:
    result: Bools = np.asarray(np.all(x, axis=1), dtype=bool)
    return result


def _as_arrays(indices: npt.ArrayLike, weights: npt.ArrayLike) -> tuple[I64, F64]:
    return np.asarray(indices, dtype=np.int64), np.asarray(weights, dtype=np.float64)


def skin_lbs(
    vertices: F64, normals: F64, indices: npt.ArrayLike, weights: npt.ArrayLike, pose: Pose
) -> Skinned:
    """Linear blend skinning; normals by the cofactor (inverse-transpose) of the blended matrix."""
    idx, w = _as_arrays(indices, weights)
    positions, matrices = _lbs(vertices, idx, w, pose)
    return Skinned(positions, unit_rows(np.einsum("vij,vj->vi", _cofactor(matrices), normals)), 0)


def skin_dq(
    vertices: F64, normals: F64, indices: npt.ArrayLike, weights: npt.ArrayLike, pose: Pose
) -> Skinned:
    """Dual-quaternion skinning with per-vertex antipodality handling; normals by the blended rotation."""
    idx, w = _as_arrays(indices, weights)
    positions, rotation, flips = _dq(vertices, idx, w, pose)
    return Skinned(positions, unit_rows(np.einsum("vij,vj->vi", rotation, normals)), flips)


def skin_cor(
    vertices: F64,
    normals: F64,
    indices: npt.ArrayLike,
    weights: npt.ArrayLike,
    pose: Pose,
    centers: F64,
) -> Skinned:
    """Optimised-centre-of-rotation skinning; ``centers`` from :func:`centers_of_rotation`."""
    idx, w = _as_arrays(indices, weights)
    positions, rotation, flips = _cor(vertices, idx, w, pose, centers)
    return Skinned(positions, unit_rows(np.einsum("vij,vj->vi", rotation, normals)), flips)


def vertex_areas(mesh: Mesh) -> F64:
    """A third of every incident triangle's area: the lumped measure of the vertex quadrature."""
    area = 0.5 * np.linalg.norm(mesh.face_normals(), axis=1)
    result: F64 = np.asarray(
        np.bincount(mesh.faces.reshape(-1), np.repeat(area / 3.0, 3), minlength=mesh.vertex_count),
        dtype=np.float64,
    )
    return result


def centers_of_rotation(
    mesh: Mesh,
    indices: npt.ArrayLike,
    weights: npt.ArrayLike,
    *,
    sigma: float = COR_SIGMA,
    bins: int = COR_BINS,
) -> F64:
    """Per-vertex centre of rotation p*ᵢ = ∫ s(wᵢ, w(x)) x dA / ∫ s(wᵢ, w(x)) dA (Le & Hodgins 2019).

    The similarity is s(wᵢ, w) = Σ_{j<k} wᵢⱼwᵢₖ wⱼwₖ exp(−(wᵢⱼwₖ − wᵢₖwⱼ)²/σ²): only points sharing a pair
    of influences with the vertex contribute, most when the pair's weights stand in the same ratio.
    Approximations, both far below what the skinning can show:
    - the surface integral uses the vertices with their lumped areas instead of triangle centroids with
      interpolated weights (the quadrature of the mesh itself);
    - for each influence pair (j, k) the contributing vertices are binned on a ``bins × bins`` grid of
      (wⱼ, wₖ); a bin contributes its total mass, first moment and mass-averaged weights. The bin width
      (0.02 by default) moves the exponent's argument by at most ~0.02·(wⱼ + wₖ), small against σ = 0.1.
    That turns the O(V²) integral into O(V·bins) per influence pair. A vertex with a single influence
    has no similar point; it moves rigidly anyway, so its centre is left at the vertex itself.
    """
    idx, w = _as_arrays(indices, weights)
    vertices = mesh.vertices
    if idx.ndim != 2 or idx.shape[1] < 2:
        return vertices.copy()
    areas = vertex_areas(mesh)
    numerator = np.zeros((mesh.vertex_count, 3))
    denominator = np.zeros(mesh.vertex_count)
    slot_count = int(idx.max()) + 1 if idx.size else 1
    rows_list, j_list, k_list, wj_list, wk_list = [], [], [], [], []
    for a, b in itertools.combinations(range(idx.shape[1]), 2):
        use = (w[:, a] > 0) & (w[:, b] > 0) & (idx[:, a] != idx[:, b])
        swap = idx[use, a] > idx[use, b]
        rows_list.append(np.flatnonzero(use))
        j_list.append(np.where(swap, idx[use, b], idx[use, a]))
        k_list.append(np.where(swap, idx[use, a], idx[use, b]))
        wj_list.append(np.where(swap, w[use, b], w[use, a]))
        wk_list.append(np.where(swap, w[use, a], w[use, b]))
    rows, wj, wk = np.concatenate(rows_list), np.concatenate(wj_list), np.concatenate(wk_list)
    pair = np.concatenate(j_list) * slot_count + np.concatenate(k_list)
    order = np.argsort(pair, kind="stable")
    rows, wj, wk, pair = rows[order], wj[order], wk[order], pair[order]
    starts = np.flatnonzero(np.r_[True, pair[1:] != pair[:-1]]) if pair.size else np.zeros(0, np.int64)
    ends = np.r_[starts[1:], pair.size]
    for s, e in zip(starts, ends, strict=True):
        v, gj, gk = rows[s:e], wj[s:e], wk[s:e]
        mass = areas[v] * gj * gk
        cell = np.minimum((gj * bins).astype(np.int64), bins) * (bins + 1) + np.minimum(
            (gk * bins).astype(np.int64), bins
        )
        _, inverse = np.unique(cell, return_inverse=True)
        inverse = inverse.reshape(-1)
        total = np.bincount(inverse, mass)
        keep = total > 0
        m_bin = total[keep]
        safe = np.where(keep, total, 1.0)
        wj_bin = (np.bincount(inverse, mass * gj) / safe)[keep]
        wk_bin = (np.bincount(inverse, mass * gk) / safe)[keep]
        x_bin = np.stack([np.bincount(inverse, mass * vertices[v, c]) for c in range(3)], axis=1)[keep]
        for c0 in range(0, v.size, COR_CHUNK):
            cj, ck = gj[c0 : c0 + COR_CHUNK], gk[c0 : c0 + COR_CHUNK]
            similar = np.exp(-np.square((cj[:, None] * wk_bin - ck[:, None] * wj_bin) / sigma))
            scale = (cj * ck)[:, None]
            numerator[v[c0 : c0 + COR_CHUNK]] += scale * (similar @ x_bin)
            denominator[v[c0 : c0 + COR_CHUNK]] += scale[:, 0] * (similar @ m_bin)
    centers = vertices.copy()
    ok = denominator > 0
    centers[ok] = numerator[ok] / denominator[ok, None]
    return centers


def skin(
    vertices: F64,
    normals: F64,
    indices: npt.ArrayLike,
    weights: npt.ArrayLike,
    pose: Pose,
    methods: Sequence[Method],
    skeleton: Skeleton,
    centers: F64 | None = None,
) -> Skinned:
    """Each vertex by the method of its joint (see :func:`vertex_methods`)."""
    idx, w = _as_arrays(indices, weights)
    per_vertex = vertex_methods(idx, w, methods, skeleton)
    positions = np.empty_like(vertices)
    out_normals = np.empty_like(normals)
    flips = 0
    for method in METHODS:
        rows = np.flatnonzero(per_vertex == METHODS.index(method))
        if rows.size == 0:
            continue
        if method == "lbs":
            part = skin_lbs(vertices[rows], normals[rows], idx[rows], w[rows], pose)
        elif method == "dq":
            part = skin_dq(vertices[rows], normals[rows], idx[rows], w[rows], pose)
        else:
            if centers is None:
                raise ValueError("CoR skinning needs the centres of rotation")
            part = skin_cor(vertices[rows], normals[rows], idx[rows], w[rows], pose, centers[rows])
        positions[rows], out_normals[rows] = part.positions, part.normals
        flips += part.flips
    return Skinned(positions, out_normals, flips)


def slot_depths(skeleton: Skeleton) -> I64:
    """Joints between each slot and its root: how deep in the limb chain a slot hangs."""
    depth = np.zeros(len(skeleton.parent), dtype=np.int64)
    for slot in range(depth.size):
        p = skeleton.parent[slot]
        while p >= 0:
            depth[slot] += 1
            p = skeleton.parent[p]
    return depth


def vertex_methods(
    indices: npt.ArrayLike, weights: npt.ArrayLike, methods: Sequence[Method], skeleton: Skeleton
) -> I64:
    """Index into :data:`METHODS` per vertex: the method of the deepest slot the vertex is weighted on.

    A seam vertex between a parent and a child belongs to the child's joint (the deeper slot), which is
    the joint whose sweep measured it; a vertex on one slot alone moves rigidly, so any method serves.
    A vertex weighted across two joints at once (a segment shorter than its blend bands) takes the
    deeper joint's method; that joint's sweep measured it too, though not under the other joint's pose.
    Roots carry "lbs" in ``methods``; their vertices only blend through a child's joint.
    """
    idx, w = _as_arrays(indices, weights)
    depth = slot_depths(skeleton)[idx]
    depth = np.where(w > 0, depth, -1)
    deepest = idx[np.arange(idx.shape[0]), np.argmax(depth, axis=1)]
    codes = np.array([METHODS.index(m) for m in methods], dtype=np.int64)
    result: I64 = codes[deepest]
    return result


# --------------------------------------------------------------------------------------------- sweeps


@dataclass(frozen=True)
class Measurement:
    """A worst value over the sweep that informs but does not decide."""

    name: str
    value: float
    unit: str
    pose: str  # the sweep pose where it was reached

    def as_dict(self) -> dict[str, object]:
        return {"name": self.name, "value": self.value, "unit": self.unit, "pose": self.pose}


@dataclass(frozen=True)
class MethodSweep:
    """One method's worst case over one joint's sweep."""

    method: Method
    gates: tuple[SurfaceGate, ...]
    measurements: tuple[Measurement, ...]
    # Hemisphere flips summed over the sweep's poses (DQ, CoR), counted on the two-influence form: zero
    # unless a sweep angle passes 180°, since the identity and a rotation below 180° share a hemisphere.
    flips: int

    @property
    def passed(self) -> bool:
        return all(g.passed for g in self.gates)

    @property
    def failed(self) -> tuple[SurfaceGate, ...]:
        return tuple(g for g in self.gates if not g.passed)

    def describe(self) -> dict[str, object]:
        return {
            "method": self.method,
            "passed": self.passed,
            "flips": self.flips,
            "gates": [g.as_dict() for g in self.gates],
            "measurements": [m.as_dict() for m in self.measurements],
        }


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
    """Every joint's choice, and what :func:`skin` needs to apply it."""

    joints: tuple[JointChoice, ...]
    methods: tuple[Method, ...]  # per slot: its joint's method; roots "lbs"
    centers: F64  # (V, 3) CoR centres, for :func:`skin` where a joint chose "cor"
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


@dataclass(frozen=True)
class _Rest:
    """What every joint's sweep reads of the rest mesh, computed once."""

    vertices: F64
    faces: I64
    triple: F64  # (F,) a·(b×c) per face: 6× its signed volume contribution
    volume: float
    face_normals: F64  # (F, 3) unit
    edge_faces: I64  # (E, 2) the two faces of each manifold edge
    rest_dihedral: F64  # (E,) degrees
    centers: F64


def _triple(c: F64) -> F64:
    result: F64 = np.einsum("ij,ij->i", c[:, 0], np.cross(c[:, 1], c[:, 2]))
    return result


def edge_faces(faces: I64) -> I64:
    """(E, 2) the two faces of each edge used by exactly two: the pairs whose crease the folds measure."""
    table = topology.edge_table(faces)
    order = np.argsort(table.edge_of_half, kind="stable")
    counts = np.bincount(table.edge_of_half, minlength=table.edges.shape[0])
    first = np.r_[0, np.cumsum(counts)[:-1]]
    manifold = np.flatnonzero(counts == 2)
    result: I64 = np.stack([order[first[manifold]] // 3, order[first[manifold] + 1] // 3], axis=1)
    return result


def sweep_poses(
    skeleton: Skeleton,
    rest_slots: F64,
    child: int,
    bend_max_deg: float = BEND_MAX_DEG,
    twist_max_deg: float = TWIST_MAX_DEG,
    steps: int = SWEEP_STEPS,
) -> list[tuple[str, Pose]]:
    """The labelled poses of one joint's sweep: ``steps`` angles up to each limit, both signs, bending
    about both axes of :func:`joint_frame` and twisting about the tangent."""
    bends = np.radians(np.linspace(0.0, bend_max_deg, steps + 1)[1:]) if bend_max_deg > 0 else np.zeros(0)
    twists = np.radians(np.linspace(0.0, twist_max_deg, steps + 1)[1:]) if twist_max_deg > 0 else np.zeros(0)
    poses = []
    for axis, sign, angle in itertools.product((0, 1), (1.0, -1.0), bends):
        label = f"bend e{axis + 1} {sign * math.degrees(angle):+.0f}°"
        poses.append((label, pose_joint(skeleton, rest_slots, child, axis, sign * angle, 0.0)))
    for sign, angle in itertools.product((1.0, -1.0), twists):
        label = f"twist {sign * math.degrees(angle):+.0f}°"
        poses.append((label, pose_joint(skeleton, rest_slots, child, 0, 0.0, sign * angle)))
    return poses


def _far(slots: F64, drop: Bools, length_scale: float) -> F64:
    """The slot table with ``drop`` slots parked far away: the field of the others through the same graph.

    A parked leaf saturates every smooth-min it meets (poly: |Δd| ≥ k returns the exact min; LSE: its
    term underflows to 0), so the result is the graph evaluated without it.
    """
    out = slots.copy()
    far = float(np.abs(slots[:, col.A]).max()) + 1e3 * length_scale
    out[drop, 0:3] = far
    out[drop, 4:7] = far
    return out


@dataclass(frozen=True)
class _JointSet:
    """One joint's vertex and face sets, in the numbering its sweep uses.

    Vertex classes: seam (weight on both sides of the joint: skinned per method), rigid (weight on the
    moving subtree alone: moved by the joint's transform under every method), static (the rest).
    Face classes for the volume: seam faces (a seam corner), rigid faces (rigid corners only: their
    volume change has a closed form) and mixed faces (rigid and static corners, no seam; only where a
    weight barrier cuts the mesh).
    """

    moving: Bools  # (S,) the child's subtree
    seam: I64  # (n,) global ids of the seam vertices
    moving_weight: F64  # (n,) each seam vertex's total weight on the subtree
    rigid_area: F64  # (3,) Σ (b − a)×(c − a) over rigid faces
    local: I64  # global ids of the non-seam corners of seam and mixed faces
    local_rigid: Bools  # which of them are rigid
    seam_faces: I64  # (Fs, 3) corners: seam number where the corner is a seam vertex, else local number
    corner_seam: Bools  # (Fs, 3)
    seam_triple: F64  # (Fs,) rest triple products
    seam_normals: F64  # (Fs, 3) rest unit normals
    edges: I64  # (E, 2) adjacent seam faces, seam-face numbering
    rest_dihedral: F64  # (E,) degrees
    mixed_faces: I64  # (Fm, 3) local numbering
    mixed_triple: F64


def _joint_set(rest: _Rest, indices: I64, weights: F64, skeleton: Skeleton, child: int) -> _JointSet:
    moving = subtree(skeleton, child)
    live = weights > 0
    on_moving: Bools = moving[indices] & live
    seam: Bools = _any_rows(on_moving) & _any_rows(~moving[indices] & live)
    rigid: Bools = _any_rows(on_moving) & ~seam
    corner_seam: Bools = seam[rest.faces]
    seam_face: Bools = _any_rows(corner_seam)
    corner_rigid: Bools = rigid[rest.faces]
    rigid_face: Bools = _all_rows(corner_rigid)
    mixed_face: Bools = _any_rows(corner_rigid) & ~rigid_face & ~seam_face
    c = rest.vertices[rest.faces[rigid_face]]
    local = np.unique(
        np.concatenate([rest.faces[seam_face][~corner_seam[seam_face]], rest.faces[mixed_face].ravel()])
    )
    remap = np.full(rest.vertices.shape[0], -1, dtype=np.int64)
    remap[local] = np.arange(local.size)
    rank = np.full(rest.vertices.shape[0], -1, dtype=np.int64)
    rank[seam] = np.arange(int(seam.sum()))
    seam_corners = rest.faces[seam_face]
    number = np.full(rest.faces.shape[0], -1, dtype=np.int64)
    number[seam_face] = np.arange(int(seam_face.sum()))
    keep: Bools = _all_rows(seam_face[rest.edge_faces])
    return _JointSet(
        moving=moving,
        seam=np.flatnonzero(seam),
        moving_weight=np.where(on_moving[seam], weights[seam], 0.0).sum(axis=1),
        rigid_area=np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]).sum(axis=0),
        local=local,
        local_rigid=rigid[local],
        seam_faces=np.where(corner_seam[seam_face], rank[seam_corners], remap[seam_corners]),
        corner_seam=corner_seam[seam_face],
        seam_triple=rest.triple[seam_face],
        seam_normals=rest.face_normals[seam_face],
        edges=number[rest.edge_faces[keep]],
        rest_dihedral=rest.rest_dihedral[keep],
        mixed_faces=remap[rest.faces[mixed_face]],
        mixed_triple=rest.triple[mixed_face],
    )


#: Moves one method's seam positions as the shipped body would: (joint child, its vertex sets, the pose,
#: skinned seam positions (n, 3), each seam vertex's 3×3 normal map (the blended matrix for LBS, whose
#: normals take its cofactor, else the blended rotation), whether that map is LBS's) → positions.
_Corrector = Callable[[int, _JointSet, Pose, F64, F64, bool], F64]


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
) -> _Corrector:
    """The bounded correction of surface/correct.py applied to a joint sweep's seam: every seam vertex the
    skin leaves farther than ``gate`` from the posed field is corrected within its ``trust`` radius (the
    runtime corrects the same vertices: a joint chosen this way puts its whole seam in the correction
    region, surface/build.py), with the full-mesh inversion check over the fans it moves."""

    def apply(child: int, js: _JointSet, pose: Pose, seam: F64, maps: F64, is_lbs: bool) -> F64:
        q, t = pose.rotations[child], pose.translations[child]
        live = weights > 0
        rigid = _any_rows(js.moving[indices] & live) & ~_any_rows(~js.moving[indices] & live)
        full = mesh.vertices.copy()
        full[rigid] = mesh.vertices[rigid] @ q.T + t
        full[js.seam] = seam
        turned = normals.copy()
        turned[rigid] = normals[rigid] @ q.T
        rest_n = normals[js.seam]
        mapped = np.einsum("vij,vj->vi", _cofactor(maps) if is_lbs else maps, rest_n)
        turned[js.seam] = unit_rows(mapped)
        field = BodyField(graph, posed_slots(rest_slots, pose))
        region = np.zeros(mesh.vertex_count, dtype=bool)
        region[js.seam] = np.abs(field.distance(seam)) > gate
        out, _ = correct(field, mesh, full, turned, region, trust)
        result: F64 = out[js.seam]
        return result

    return apply


@dataclass(frozen=True)
class _SweepResult:
    sweeps: tuple[MethodSweep, ...]
    seam_vertices: int
    scale: float


def _joint_sweep(
    rest: _Rest,
    indices: I64,
    weights: F64,
    skeleton: Skeleton,
    rest_slots: F64,
    graph: BlendGraph,
    length_scale: float,
    child: int,
    poses: list[tuple[str, Pose]],
    corrector: _Corrector | None = None,
) -> _SweepResult:
    """Every method over one joint's poses, measured on the vertices weighted across the joint.

    With a ``corrector``, every method's seam is first moved as the shipped body moves it: skinned, then
    corrected toward the posed field (surface/correct.py) where the skin misses it (the remedy of
    :func:`choose_deformation` for a joint no method carries by skinning alone).

    A joint pose moves the subtree by one transform and leaves the rest, so a seam vertex's influences
    reduce exactly to two, "static" (weight 1 − w) and "moving" (w): LBS is linear in the weights and
    DQ/QLERP sum equal quaternions, so skinning the two-influence form gives the same positions at half
    the cost. Vertices on the subtree alone move rigidly under every method and only enter the volume.

    Surface error of a seam vertex near the joint: d_posed where it lies outside the posed body
    (visible); where it lies inside, the smaller of −d_posed and its distance to its own side's surface
    (the moving subtree posed, or the static rest, by which side holds most of its weight). The second
    term forgives a limb that passes into another part, which the sweep's blind poses do and no skinning
    can undo: a sheet inside the body on its own limb's surface is hidden, while a collapsed joint is
    inside both.
    """
    js = _joint_set(rest, indices, weights, skeleton, child)
    n = js.seam.size
    radius = float(rest_slots[child, col.RA])
    pivot = skeleton.pivot[child]
    seam_v = rest.vertices[js.seam]
    pair = np.broadcast_to(np.array([0, 1], dtype=np.int64), (n, 2))
    pair_w = np.stack([1.0 - js.moving_weight, js.moving_weight], axis=1)
    reach = np.linalg.norm(seam_v - pivot, axis=1)
    closest = float(reach.min()) if n else 0.0
    joint = np.flatnonzero(reach <= closest + JOINT_REACH * radius)
    ring = reach[joint] <= closest + COLLAPSE_REACH * radius
    # The faces the fold measures read: every seam corner in the joint region.
    in_joint = np.zeros(n, dtype=bool)
    in_joint[joint] = True
    joint_rank = np.cumsum(in_joint) - 1
    fold: Bools = _all_rows(~js.corner_seam | in_joint[np.where(js.corner_seam, js.seam_faces, 0)])
    fold_faces = np.flatnonzero(fold)
    rest_normals = js.seam_normals[fold]
    edge_keep: Bools = _all_rows(fold[js.edges])
    fold_edges = (np.cumsum(fold) - 1)[js.edges[edge_keep]]
    fold_dihedral = js.rest_dihedral[edge_keep]
    fold_corner_seam = js.corner_seam[fold]
    fold_corner_rank = joint_rank[np.where(fold_corner_seam, js.seam_faces[fold], 0)]
    visible_depth = VISIBLE_DEPTH * radius
    v_local = rest.vertices[js.local]
    seam_index = np.where(js.corner_seam, js.seam_faces, 0)
    local_index = np.where(js.corner_seam, 0, js.seam_faces)
    rigid_local = np.flatnonzero(js.local_rigid)

    count = len(poses)
    bulge = np.zeros((count, 3))
    volume = np.zeros((count, 3))
    collapse = np.ones((count, 3))
    dihedral = np.zeros((count, 3))
    flipped = np.zeros((count, 3))
    flips = np.zeros(3, dtype=np.int64)
    d_joint = np.zeros((count, 3, joint.size))
    posed_near = np.zeros((count, 3, joint.size, 3))
    in_rest_frame = np.zeros((count, 3, joint.size, 3))
    for p, (_, pose) in enumerate(poses):
        q, t = pose.rotations[child], pose.translations[child]
        two = Pose(np.stack([np.eye(3), q]), np.stack([np.zeros(3), t]))
        base = v_local.copy()
        base[rigid_local] = v_local[rigid_local] @ q.T + t
        # Rigid faces: (Qa + t)·((Qb + t)×(Qc + t)) = a·(b×c) + t·Q((b − a)×(c − a)).
        fixed = float(t @ (q @ js.rigid_area))
        fixed += float((_triple(base[js.mixed_faces]) - js.mixed_triple).sum())
        lbs, lbs_m = _lbs(seam_v, pair, pair_w, two)
        dq, dq_r, flips_dq = _dq(seam_v, pair, pair_w, two)
        cor, cor_r, flips_cor = _cor(seam_v, pair, pair_w, two, rest.centers[js.seam])
        flips[1] += flips_dq
        flips[2] += flips_cor
        stacked = np.stack([lbs, dq, cor])  # (3, n, 3)
        if corrector is not None:
            rotations = (lbs_m, dq_r, cor_r)
            stacked = np.stack(
                [corrector(child, js, pose, stacked[k], rotations[k], k == 0) for k in range(3)]
            )
        near = stacked[:, joint]
        d = BodyField(graph, posed_slots(rest_slots, pose)).distance(near.reshape(-1, 3)).reshape(3, -1)
        d_joint[p] = d
        posed_near[p] = near
        in_rest_frame[p] = (near - t) @ q
        turned_normals = rest_normals @ q.T
        base_corners = base[local_index]
        for k in range(3):
            corners = np.where(js.corner_seam[..., None], stacked[k][seam_index], base_corners)
            volume[p, k] = (float((_triple(corners) - js.seam_triple).sum()) + fixed) / 6.0
            if joint.size == 0:
                continue
            bulge[p, k] = max(float(d[k].max()), 0.0)
            collapse[p, k] = float((np.linalg.norm(near[k][ring] - pivot, axis=1) / reach[joint][ring]).min())
            c = corners[fold_faces]
            normals = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
            corner_d = np.where(fold_corner_seam, d[k][fold_corner_rank], np.inf)
            visible = corner_d.min(axis=1) >= -visible_depth
            shown = visible[fold_edges].all(axis=1)
            if shown.any():
                e = fold_edges[shown]
                turn = angles_deg(normals[e[:, 0]], normals[e[:, 1]]) - fold_dihedral[shown]
                dihedral[p, k] = max(float(turn.max()), 0.0)
            against = (np.einsum("ij,ij->i", normals, rest_normals) < 0) & (
                np.einsum("ij,ij->i", normals, turned_normals) < 0
            )
            flipped[p, k] = float(np.count_nonzero(against & visible))

    surface_max = np.zeros((count, 3))
    surface_p99 = np.zeros((count, 3))
    if joint.size:
        inside = d_joint < 0
        side = np.broadcast_to(js.moving_weight[joint] >= 0.5, d_joint.shape)
        own = np.full(d_joint.shape, np.inf)
        # The moving subtree moves rigidly, so its posed field at x is its rest field at Qᵀ(x − t); the
        # static side does not move. Both sides are then one call each over the whole sweep.
        for mask, drop, points in (
            (inside & side, ~js.moving, in_rest_frame),
            (inside & ~side, js.moving, posed_near),
        ):
            if mask.any():
                field = BodyField(graph, _far(rest_slots, drop, length_scale))
                own[mask] = np.abs(field.distance(points[mask]))
        error = np.where(inside, np.minimum(-d_joint, own), d_joint)
        surface_max = error.max(axis=2)
        surface_p99 = np.percentile(error, 99, axis=2)

    labels = [label for label, _ in poses]
    # The joint's scale: its radius, or the lever from the pivot to the seam where the pivot is buried
    # inside the parent (a hip), since every method's displacement, and so its artefacts, grows with the
    # lever as much as with the radius.
    scale = max(radius, closest)
    r_l = scale / length_scale
    ball = 4.0 / 3.0 * math.pi * radius**2 * scale
    # The relative gates compare a method with the best of the methods that could be chosen instead: those
    # that keep the joint at every pose of the sweep by their own gates (no collapse, and for LBS no more
    # volume lost than VOLUME_FACTOR of the joint ball). A collapsed or deflated joint hugs the posed body
    # from inside (vertices pulled towards the pivot), so measuring DQ's or CoR's surface error and bulge
    # against it charged them for not collapsing, and a method that collapses at some pose is no
    # alternative at any other (thick hips of wolves and elephants, knees on slopes, on the corpus).
    keeps = collapse >= COLLAPSE_MIN
    keeps[:, 0] &= (volume[:, 1] - volume[:, 0]) <= VOLUME_FACTOR * ball
    keeps = np.broadcast_to(keeps.all(axis=0), keeps.shape)
    sweeps = []
    for k, method in enumerate(METHODS):

        def worst(values: F64, low: bool = False, k: int = k) -> tuple[float, str]:
            return _worst(values[:, k], labels, low)

        common = (
            _gate("surface_max", worst(surface_max / length_scale), SURFACE_MAX_FACTOR * r_l, "L"),
            _gate("surface_p99", worst(surface_p99 / length_scale), SURFACE_P99_FACTOR * r_l, "L"),
            _gate(
                "surface_excess", worst(_excess(surface_max, keeps) / length_scale), EXCESS_FACTOR * r_l, "L"
            ),
            _gate("joint_collapse", worst(collapse, low=True), COLLAPSE_MIN, "ratio", "min"),
        )
        # The seed's split: LBS stands or falls by its twist (collapse) and volume sweep; DQ and CoR,
        # whose blended rotation keeps a pivot rotation's radii, by their bulge.
        specific = (
            _gate(
                "volume_loss",
                worst((volume[:, 1:2] - volume) / rest.volume),
                VOLUME_FACTOR * ball / rest.volume,
                "V_rest",
            )
            if method == "lbs"
            else _gate("bulge_excess", worst(_excess(bulge, keeps) / length_scale), EXCESS_FACTOR * r_l, "L")
        )
        measurements = tuple(
            Measurement(name, *worst(values), unit)
            for name, values, unit in (
                ("bulge", bulge / length_scale, "L"),
                ("volume_change", np.abs(volume) / rest.volume, "V_rest"),
                ("dihedral_increase", dihedral, "deg"),
                ("flipped_faces", flipped, "faces"),
            )
        )
        gates = (*common, specific)
        sweeps.append(MethodSweep(method, gates, measurements, int(flips[k])))
    return _SweepResult(tuple(sweeps), n, scale)


def _worst(column: F64, labels: Sequence[str], low: bool = False) -> tuple[float, str]:
    """The worst value over the sweep's poses and the pose's label."""
    if column.size == 0:
        return (1.0 if low else 0.0), ""
    p = int(np.argmin(column) if low else np.argmax(column))
    return float(column[p]), labels[p]


def _excess(values: F64, keeps: Bools | None = None) -> F64:
    """(P, 3) per pose, each method's value above the best (smallest) of the methods marked in ``keeps``
    at that pose (the methods that keep the joint over the whole sweep), or of all three where none is."""
    if keeps is None:
        keeps = np.ones(values.shape, dtype=bool)
    usable = np.where(keeps.any(axis=1, keepdims=True), keeps, True)
    best = np.where(usable, values, np.inf).min(axis=1, keepdims=True)
    result: F64 = np.maximum(values - best, 0.0)
    return result


def _gate(
    name: str, worst: tuple[float, str], threshold: float, unit: str, direction: Literal["max", "min"] = "max"
) -> SurfaceGate:
    return SurfaceGate(name, worst[0], threshold, unit, direction, worst[1])


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
    corrector: _Corrector | None = None,
    limits_at: Mapping[int, str] | None = None,
) -> DeformationChoice:
    """Sweep every joint with every method and keep, per joint, the first method that passes every gate.

    Raises :class:`DeformationError` for the first joint no method can carry. ``field_rest`` is the rest
    body the mesh was extracted from; its slots must be ``rig_slots``. ``centers`` (from
    :func:`centers_of_rotation`) are computed when not given. ``limits`` maps a joint's child slot to its
    (bend, twist) sweep limits in degrees (the measured motion envelope, motion/envelope.py); a joint not
    in it is swept to ``bend_max_deg`` and ``twist_max_deg``. A joint swept to zero never turns: every
    method reproduces it exactly and the cheapest is kept. ``limits_at`` names, per joint, the motion
    whose turn set its limits, for a refusal's message.

    Remedy before refusal: where no method passes by skinning alone and a ``corrector`` is given
    (:func:`seam_corrector`), the joint is swept again with every method's seam corrected toward the
    posed field as the shipped body corrects it, and the first method that passes then is kept, marked
    ``corrected`` (its seam joins the correction region). A thick hip's DQ bulge or CoR collapse that the
    correction pulls back is not what a user sees.
    """
    start = time.perf_counter()
    idx, w = _as_arrays(indices, weights)
    if not np.array_equal(field_rest.slots, rig_slots):
        raise ValueError("field_rest must be the field of rig_slots")
    faces = mesh.faces.astype(np.int64)
    corners = mesh.vertices[faces]
    triple = _triple(corners)
    face_normals = unit_rows(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]))
    pairs = edge_faces(faces)
    rest = _Rest(
        vertices=mesh.vertices,
        faces=faces,
        triple=triple,
        volume=float(triple.sum()) / 6.0,
        face_normals=face_normals,
        edge_faces=pairs,
        rest_dihedral=angles_deg(face_normals[pairs[:, 0]], face_normals[pairs[:, 1]]),
        centers=centers if centers is not None else centers_of_rotation(mesh, idx, w),
    )
    methods: list[Method] = ["lbs"] * len(skeleton.parent)
    joints = []
    for parent, child in skeleton.joints:
        bend, twist = (limits or {}).get(child, (bend_max_deg, twist_max_deg))
        worst = (limits_at or {}).get(child, "")
        poses = sweep_poses(skeleton, rig_slots, child, bend, twist, steps)
        result = _joint_sweep(rest, idx, w, skeleton, rig_slots, graph, length_scale, child, poses)
        sweeps = result.sweeps
        chosen = next((s.method for s in sweeps if s.passed), None)
        corrected = False
        if chosen is None and corrector is not None:
            retry = _joint_sweep(
                rest, idx, w, skeleton, rig_slots, graph, length_scale, child, poses, corrector
            )
            chosen = next((s.method for s in retry.sweeps if s.passed), None)
            if chosen is None:
                raise DeformationError(skeleton.names[child], sweeps, bend, twist, retry.sweeps, worst)
            result, sweeps, corrected = retry, retry.sweeps, True
        if chosen is None:
            raise DeformationError(skeleton.names[child], sweeps, bend, twist, worst_run=worst)
        methods[child] = chosen
        radius = float(rig_slots[child, col.RA])
        joints.append(
            JointChoice(
                skeleton.names[child],
                parent,
                child,
                chosen,
                radius,
                result.scale,
                result.seam_vertices,
                sweeps,
                bend,
                twist,
                corrected,
            )
        )
    where = limits_from or f"every joint {bend_max_deg:g}° bend, {twist_max_deg:g}° twist"
    return DeformationChoice(
        tuple(joints),
        tuple(methods),
        rest.centers,
        where,
        steps,
        time.perf_counter() - start,
    )
