"""Skinning the reference mesh to the slots: three methods, and per vertex which one it takes.

Why three methods rather than one method everywhere:
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
  a precomputation (:func:`centers_of_rotation`); it is the last resort.

These are the float64 formulas the shipped runtime mirrors (templates/creature/tsl/skin.js) and the
reference re-skins with (creature/reference.py); which method each joint gets is chosen in
surface/deform.py by sweeping the joint (surface/sweep.py).

Conventions: a pose maps rest to posed, per slot ``x' = R_s x + t_s``; quaternions are ``(x, y, z, w)``
(model/rotations.py).
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final, Literal

import numpy as np
import numpy.typing as npt

from ..model.rotations import (
    CONJUGATE,
    Pose,
    matrix_to_quaternion,
    quaternion_dot,
    quaternion_multiply,
    quaternion_norm,
    quaternion_to_matrix,
)
from ..model.skeleton import Skeleton
from .mesh import Mesh, unit_rows

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
Method = Literal["lbs", "dq", "cor"]
#: Preference order: the cheapest method whose sweep passes wins.
METHODS: Final[tuple[Method, ...]] = ("lbs", "dq", "cor")

#: CoR similarity width σ (Le & Hodgins use 0.1) and the bins per weight axis of its approximation.
COR_SIGMA: Final = 0.1
COR_BINS: Final = 50
#: Rows of the (vertices × weight bins) similarity block evaluated at once.
COR_CHUNK: Final = 4096


# ---------------------------------------------------------------------------------------------- poses


def _dual_quaternions(pose: Pose) -> tuple[F64, F64]:
    """Per slot real part q and dual part ½·(t, 0)·q."""
    real = matrix_to_quaternion(pose.rotations)
    pure = np.concatenate([pose.translations, np.zeros((pose.slot_count, 1))], axis=1)
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
    dots = quaternion_dot(quaternions, reference[:, None, :])
    flipped = dots < 0
    return np.where(flipped, -1.0, 1.0), int(np.count_nonzero(flipped & (weights > 0)))


# ------------------------------------------------------------------------------------------- skinning
# The bare blends (positions and each vertex's normal map) are shared with the joint sweep
# (surface/sweep.py), which skins a seam's two-influence form, and with its seam correction
# (surface/deform.py), which maps the seam's normals as the shipped body does.


@dataclass(frozen=True)
class Skinned:
    """A skinned mesh (or rows of one): what every method returns, so callers mix methods per vertex."""

    positions: F64  # (V, 3)
    normals: F64  # (V, 3) unit
    flips: int  # influences brought into the dominant hemisphere (0 for LBS)


def lbs_blend(vertices: F64, indices: I64, weights: F64, pose: Pose) -> tuple[F64, F64]:
    """Positions and the blended 3×3 part Σ wᵢRᵢ.

    Written as ``v + Σ wᵢ((Rᵢ − I)v + tᵢ)`` so the rest pose returns the rest vertices bit for bit,
    whatever the rounding of Σ wᵢ.
    """
    delta = np.einsum("vk,vkij->vij", weights, (pose.rotations - np.eye(3))[indices])
    shift = np.einsum("vk,vki->vi", weights, pose.translations[indices])
    positions = vertices + np.einsum("vij,vj->vi", delta, vertices) + shift
    matrices = delta + weights.sum(axis=1)[:, None, None] * np.eye(3)
    return positions, matrices


def cofactor(m: F64) -> F64:
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


def dq_blend(vertices: F64, indices: I64, weights: F64, pose: Pose) -> tuple[F64, F64, int]:
    """Positions, the blended rotation per vertex and the hemisphere flips."""
    real, dual = _dual_quaternions(pose)
    qr, qd = real[indices], dual[indices]
    signs, flips = _hemisphere(qr, weights)
    sw = weights * signs
    br = np.einsum("vk,vkc->vc", sw, qr)
    bd = np.einsum("vk,vkc->vc", sw, qd)
    norm = quaternion_norm(br)[:, None]
    br, bd = br / norm, bd / norm
    translation = 2.0 * quaternion_multiply(bd, br * CONJUGATE)[:, :3]
    rotation = quaternion_to_matrix(br)
    return np.einsum("vij,vj->vi", rotation, vertices) + translation, rotation, flips


def cor_blend(vertices: F64, indices: I64, weights: F64, pose: Pose, centers: F64) -> tuple[F64, F64, int]:
    """QLERP rotation about the vertex's centre p*, which itself moves by LBS.

    ``v' = R(v − p*) + LBS(p*)`` is evaluated as ``Rv + [(p* − Rp*) + Σ wᵢ((Rᵢ − I)p* + tᵢ)]`` so the
    rest pose (R = I, every Rᵢ = I, tᵢ = 0) returns the rest vertices bit for bit.
    """
    q = matrix_to_quaternion(pose.rotations)[indices]
    signs, flips = _hemisphere(q, weights)
    summed = np.einsum("vk,vkc->vc", weights * signs, q)
    length = quaternion_norm(summed)[:, None]
    blended = summed / np.where(length > 0, length, 1.0)
    rotation = quaternion_to_matrix(blended)
    delta = np.einsum("vk,vkij->vij", weights, (pose.rotations - np.eye(3))[indices])
    shift = np.einsum("vk,vki->vi", weights, pose.translations[indices])
    moved_center = np.einsum("vij,vj->vi", delta, centers) + shift
    translation = (centers - np.einsum("vij,vj->vi", rotation, centers)) + moved_center
    return np.einsum("vij,vj->vi", rotation, vertices) + translation, rotation, flips


def as_arrays(indices: npt.ArrayLike, weights: npt.ArrayLike) -> tuple[I64, F64]:
    """Influence indices and weights as the int64/float64 arrays the blends index with."""
    return np.asarray(indices, dtype=np.int64), np.asarray(weights, dtype=np.float64)


def skin_lbs(
    vertices: F64, normals: F64, indices: npt.ArrayLike, weights: npt.ArrayLike, pose: Pose
) -> Skinned:
    """Linear blend skinning; normals by the cofactor (inverse-transpose) of the blended matrix."""
    idx, w = as_arrays(indices, weights)
    positions, matrices = lbs_blend(vertices, idx, w, pose)
    return Skinned(positions, unit_rows(np.einsum("vij,vj->vi", cofactor(matrices), normals)), 0)


def skin_dq(
    vertices: F64, normals: F64, indices: npt.ArrayLike, weights: npt.ArrayLike, pose: Pose
) -> Skinned:
    """Dual-quaternion skinning with per-vertex antipodality handling; normals by the blended rotation."""
    idx, w = as_arrays(indices, weights)
    positions, rotation, flips = dq_blend(vertices, idx, w, pose)
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
    idx, w = as_arrays(indices, weights)
    positions, rotation, flips = cor_blend(vertices, idx, w, pose, centers)
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
    idx, w = as_arrays(indices, weights)
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
    idx, w = as_arrays(indices, weights)
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
    idx, w = as_arrays(indices, weights)
    depth = slot_depths(skeleton)[idx]
    depth = np.where(w > 0, depth, -1)
    deepest = idx[np.arange(idx.shape[0]), np.argmax(depth, axis=1)]
    codes = np.array([METHODS.index(m) for m in methods], dtype=np.int64)
    result: I64 = codes[deepest]
    return result
