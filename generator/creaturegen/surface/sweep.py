"""Measuring one joint's sweep: the joint alone turned over a bend and a twist range, every method's seam
against the truth, the smooth-min field of the posed slot table.

Measuring is kept apart from judging: this module turns one joint's poses into per-pose, per-method
numbers (:class:`SweepMeasures`); surface/sweep_gates.py reads them against the gates, and
surface/deform.py keeps the first method that passes. The measurement is where the time goes (a field
evaluation per pose and method), so it only skins and measures the vertices a joint pose deforms, in
the two-influence form (see :func:`measure_sweep`).

Conventions: a pose maps rest to posed, per slot ``x' = R_s x + t_s``; angles of the public pose helpers
are radians, sweep limits are degrees.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from ..model import layout as col
from ..model.graph import BlendGraph
from ..model.rotations import Pose, posed_slots
from ..model.skeleton import Skeleton, pose_joint
from .field64 import BodyField
from .joint_sets import JointSet, RestMesh, all_rows, face_triples, joint_set
from .mesh import angles_deg
from .skinning import cor_blend, dq_blend, lbs_blend

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
Bools = npt.NDArray[np.bool_]

#: Sweep limits (degrees) of a joint the caller gives no limits for (the build gives every joint the
#: limits of the measured motion envelope, motion/envelope.py), and angle steps per sweep direction
#: (bend: ±e1, ±e2 about the pivot; twist: ± about the child's rest tangent).
BEND_MAX_DEG: Final = 60.0
TWIST_MAX_DEG: Final = 45.0
SWEEP_STEPS: Final = 3
#: The joint region the surface gates read: seam vertices within this many r_j (rest distance to the
#: pivot) of the seam vertex nearest the pivot. Farther seam vertices only show the weights' lag.
JOINT_REACH: Final = 1.0
#: Vertices within this many r_j of the nearest seam vertex form the cross-section the collapse gate reads.
COLLAPSE_REACH: Final = 0.5
#: A seam face counts for the fold measures only where it can be seen: no seam corner deeper inside the
#: posed body than this × r_j. Folds buried in a bent crease or inside another part are hidden.
#: (Approximate: the middle sheet of a fold lies within the depth too.)
VISIBLE_DEPTH: Final = 0.1

#: Moves one method's seam positions as the shipped body would: (joint child, its vertex sets, the pose,
#: skinned seam positions (n, 3), each seam vertex's 3×3 normal map (the blended matrix for LBS, whose
#: normals take its cofactor, else the blended rotation), whether that map is LBS's) → positions.
Corrector = Callable[[int, JointSet, Pose, F64, F64, bool], F64]


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
class SweepMeasures:
    """One joint's sweep measured: per pose (rows, labelled) and method (columns, in METHODS order)."""

    labels: tuple[str, ...]  # the poses'
    surface_max: F64  # (P, 3) m: the largest side-aware surface error near the joint
    surface_p99: F64  # (P, 3) m: its 99th percentile
    bulge: F64  # (P, 3) m: the largest outward distance to the posed field near the joint
    volume: F64  # (P, 3) m³: the whole mesh's volume change
    collapse: F64  # (P, 3) smallest posed/rest distance to the pivot over the joint's cross-section
    dihedral: F64  # (P, 3) degrees: the largest visible crease increase
    flipped: F64  # (P, 3) visible seam faces turned against both their rest and their turned normal
    flips: I64  # (3,) hemisphere flips summed over the poses
    seam_vertices: int  # vertices weighted across the joint (the measured set)
    radius: float  # r_j, m: the child's radius at its pivot end
    scale: float  # s_j = max(r_j, pivot → nearest seam vertex), m


@dataclass(frozen=True)
class _Region:
    """Where one joint's sweep skins and measures, fixed over its poses."""

    js: JointSet
    child: int
    radius: float
    pivot: F64  # (3,)
    seam_v: F64  # (n, 3) rest seam vertices
    pair: I64  # (n, 2) the two-influence form: static 0, moving 1
    pair_w: F64  # (n, 2) its weights
    seam_centers: F64  # (n, 3) the seam's CoR centres
    reach: F64  # (n,) rest distance to the pivot
    closest: float  # the nearest seam vertex's
    joint: I64  # seam numbers of the joint region the surface gates read
    ring: Bools  # of ``joint``: the cross-section the collapse gate reads
    v_local: F64  # rest positions of the js.local corners
    rigid_local: I64  # which of them move rigidly
    seam_index: I64  # (Fs, 3) seam number of each seam-face corner (0 where not a seam vertex)
    local_index: I64  # (Fs, 3) local number of each seam-face corner (0 where a seam vertex)


def _region(rest: RestMesh, js: JointSet, skeleton: Skeleton, rest_slots: F64, child: int) -> _Region:
    """The joint above ``child``'s seam in its two-influence form, its joint region and collapse ring."""
    n = js.seam.size
    radius = float(rest_slots[child, col.RA])
    pivot = skeleton.pivot[child]
    seam_v = rest.vertices[js.seam]
    reach = np.linalg.norm(seam_v - pivot, axis=1)
    closest = float(reach.min()) if n else 0.0
    joint = np.flatnonzero(reach <= closest + JOINT_REACH * radius)
    return _Region(
        js=js,
        child=child,
        radius=radius,
        pivot=pivot,
        seam_v=seam_v,
        pair=np.broadcast_to(np.array([0, 1], dtype=np.int64), (n, 2)),
        pair_w=np.stack([1.0 - js.moving_weight, js.moving_weight], axis=1),
        seam_centers=rest.centers[js.seam],
        reach=reach,
        closest=closest,
        joint=joint,
        ring=reach[joint] <= closest + COLLAPSE_REACH * radius,
        v_local=rest.vertices[js.local],
        rigid_local=np.flatnonzero(js.local_rigid),
        seam_index=np.where(js.corner_seam, js.seam_faces, 0),
        local_index=np.where(js.corner_seam, 0, js.seam_faces),
    )


@dataclass(frozen=True)
class _Folds:
    """The seam faces the fold measures read (every seam corner in the joint region) and their creases."""

    faces: I64  # seam-face numbers
    rest_normals: F64  # (Ff, 3) rest unit normals
    edges: I64  # (Ef, 2) adjacent fold faces, fold-face numbering
    rest_dihedral: F64  # (Ef,) degrees
    corner_seam: Bools  # (Ff, 3)
    corner_rank: I64  # (Ff, 3) joint-region number of each seam corner
    visible_depth: float  # m


def _folds(region: _Region) -> _Folds:
    """The fold faces of the joint region (see :class:`_Folds`)."""
    js = region.js
    in_joint = np.zeros(js.seam.size, dtype=bool)
    in_joint[region.joint] = True
    joint_rank = np.cumsum(in_joint) - 1
    fold: Bools = all_rows(~js.corner_seam | in_joint[np.where(js.corner_seam, js.seam_faces, 0)])
    edge_keep: Bools = all_rows(fold[js.edges])
    corner_seam = js.corner_seam[fold]
    return _Folds(
        faces=np.flatnonzero(fold),
        rest_normals=js.seam_normals[fold],
        edges=(np.cumsum(fold) - 1)[js.edges[edge_keep]],
        rest_dihedral=js.rest_dihedral[edge_keep],
        corner_seam=corner_seam,
        corner_rank=joint_rank[np.where(corner_seam, js.seam_faces[fold], 0)],
        visible_depth=VISIBLE_DEPTH * region.radius,
    )


def _skin_seam(region: _Region, pose: Pose, corrector: Corrector | None) -> tuple[F64, int, int]:
    """(3, n, 3) the seam skinned by each method in the two-influence form, corrected where a
    ``corrector`` is given, and the DQ and CoR hemisphere flips."""
    child = region.child
    q, t = pose.rotations[child], pose.translations[child]
    two = Pose(np.stack([np.eye(3), q]), np.stack([np.zeros(3), t]))
    seam_v, pair, pair_w = region.seam_v, region.pair, region.pair_w
    lbs, lbs_m = lbs_blend(seam_v, pair, pair_w, two)
    dq, dq_r, flips_dq = dq_blend(seam_v, pair, pair_w, two)
    cor, cor_r, flips_cor = cor_blend(seam_v, pair, pair_w, two, region.seam_centers)
    stacked = np.stack([lbs, dq, cor])  # (3, n, 3)
    if corrector is not None:
        rotations = (lbs_m, dq_r, cor_r)
        stacked = np.stack(
            [corrector(child, region.js, pose, stacked[k], rotations[k], k == 0) for k in range(3)]
        )
    return stacked, flips_dq, flips_cor


def _fold_measure(folds: _Folds, corners: F64, d: F64, turned_normals: F64) -> tuple[float, float]:
    """One method's visible crease increase (degrees) and visible flipped faces at one pose; ``corners``
    are its posed seam-face corners and ``d`` its joint region's posed field distances."""
    dihedral = 0.0
    c = corners[folds.faces]
    normals = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    corner_d = np.where(folds.corner_seam, d[folds.corner_rank], np.inf)
    visible = corner_d.min(axis=1) >= -folds.visible_depth
    shown = visible[folds.edges].all(axis=1)
    if shown.any():
        e = folds.edges[shown]
        turn = angles_deg(normals[e[:, 0]], normals[e[:, 1]]) - folds.rest_dihedral[shown]
        dihedral = max(float(turn.max()), 0.0)
    against = (np.einsum("ij,ij->i", normals, folds.rest_normals) < 0) & (
        np.einsum("ij,ij->i", normals, turned_normals) < 0
    )
    return dihedral, float(np.count_nonzero(against & visible))


@dataclass(frozen=True)
class _PoseRow:
    """One pose of the sweep measured, per method."""

    volume: F64  # (3,)
    bulge: F64  # (3,)
    collapse: F64  # (3,)
    dihedral: F64  # (3,)
    flipped: F64  # (3,)
    flips_dq: int
    flips_cor: int
    d: F64  # (3, J) posed field distance of the joint region
    near: F64  # (3, J, 3) the joint region posed
    in_rest_frame: F64  # (3, J, 3) the same taken back by the child's transform


def _measure_pose(
    region: _Region,
    folds: _Folds,
    graph: BlendGraph,
    rest_slots: F64,
    pose: Pose,
    corrector: Corrector | None,
) -> _PoseRow:
    """Every method's seam at one pose: the whole mesh's volume change (the seam skinned, the rigid side
    in closed form), and in the joint region the bulge, collapse and folds against the posed field."""
    js, joint = region.js, region.joint
    q, t = pose.rotations[region.child], pose.translations[region.child]
    base = region.v_local.copy()
    base[region.rigid_local] = region.v_local[region.rigid_local] @ q.T + t
    # Rigid faces: (Qa + t)·((Qb + t)×(Qc + t)) = a·(b×c) + t·Q((b − a)×(c − a)).
    fixed = float(t @ (q @ js.rigid_area))
    fixed += float((face_triples(base[js.mixed_faces]) - js.mixed_triple).sum())
    stacked, flips_dq, flips_cor = _skin_seam(region, pose, corrector)
    near = stacked[:, joint]
    d = BodyField(graph, posed_slots(rest_slots, pose)).distance(near.reshape(-1, 3)).reshape(3, -1)
    turned_normals = folds.rest_normals @ q.T
    base_corners = base[region.local_index]
    volume, bulge, dihedral, flipped = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    collapse = np.ones(3)
    for k in range(3):
        corners = np.where(js.corner_seam[..., None], stacked[k][region.seam_index], base_corners)
        volume[k] = (float((face_triples(corners) - js.seam_triple).sum()) + fixed) / 6.0
        if joint.size == 0:
            continue
        bulge[k] = max(float(d[k].max()), 0.0)
        radii = np.linalg.norm(near[k][region.ring] - region.pivot, axis=1)
        collapse[k] = float((radii / region.reach[joint][region.ring]).min())
        dihedral[k], flipped[k] = _fold_measure(folds, corners, d[k], turned_normals)
    return _PoseRow(volume, bulge, collapse, dihedral, flipped, flips_dq, flips_cor, d, near, (near - t) @ q)


def _surface_error(
    region: _Region,
    graph: BlendGraph,
    rest_slots: F64,
    length_scale: float,
    d_joint: F64,
    posed_near: F64,
    in_rest_frame: F64,
) -> tuple[F64, F64]:
    """(P, 3) the worst and the 99th percentile of the side-aware surface error (see :func:`measure_sweep`)
    over the joint region, from its posed field distances and positions (P, 3, J[, 3])."""
    js = region.js
    inside = d_joint < 0
    side = np.broadcast_to(js.moving_weight[region.joint] >= 0.5, d_joint.shape)
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
    return error.max(axis=2), np.percentile(error, 99, axis=2)


def measure_sweep(
    rest: RestMesh,
    indices: I64,
    weights: F64,
    skeleton: Skeleton,
    rest_slots: F64,
    graph: BlendGraph,
    length_scale: float,
    child: int,
    poses: list[tuple[str, Pose]],
    corrector: Corrector | None = None,
) -> SweepMeasures:
    """Every method over one joint's poses, measured on the vertices weighted across the joint.

    With a ``corrector``, every method's seam is first moved as the shipped body moves it: skinned, then
    corrected toward the posed field (surface/correct.py) where the skin misses it (the remedy of
    :func:`~creaturegen.surface.deform.choose_deformation` for a joint no method carries by skinning alone).

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
    region = _region(rest, joint_set(rest, indices, weights, skeleton, child), skeleton, rest_slots, child)
    folds = _folds(region)
    size = region.joint.size
    count = len(poses)
    bulge = np.zeros((count, 3))
    volume = np.zeros((count, 3))
    collapse = np.ones((count, 3))
    dihedral = np.zeros((count, 3))
    flipped = np.zeros((count, 3))
    flips = np.zeros(3, dtype=np.int64)
    d_joint = np.zeros((count, 3, size))
    posed_near = np.zeros((count, 3, size, 3))
    in_rest_frame = np.zeros((count, 3, size, 3))
    for p, (_, pose) in enumerate(poses):
        row = _measure_pose(region, folds, graph, rest_slots, pose, corrector)
        volume[p], bulge[p], collapse[p] = row.volume, row.bulge, row.collapse
        dihedral[p], flipped[p] = row.dihedral, row.flipped
        flips[1] += row.flips_dq
        flips[2] += row.flips_cor
        d_joint[p], posed_near[p], in_rest_frame[p] = row.d, row.near, row.in_rest_frame
    surface_max = np.zeros((count, 3))
    surface_p99 = np.zeros((count, 3))
    if size:
        surface_max, surface_p99 = _surface_error(
            region, graph, rest_slots, length_scale, d_joint, posed_near, in_rest_frame
        )
    # The joint's scale: its radius, or the lever from the pivot to the seam where the pivot is buried
    # inside the parent (a hip), since every method's displacement, and so its artefacts, grows with the
    # lever as much as with the radius.
    scale = max(region.radius, region.closest)
    return SweepMeasures(
        labels=tuple(label for label, _ in poses),
        surface_max=surface_max,
        surface_p99=surface_p99,
        bulge=bulge,
        volume=volume,
        collapse=collapse,
        dihedral=dihedral,
        flipped=flipped,
        flips=flips,
        seam_vertices=region.js.seam.size,
        radius=region.radius,
        scale=scale,
    )
