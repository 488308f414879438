"""Posed quality: the shipped skin at the motion envelope's whole-body poses, checked as the rest mesh is.

The rest mesh is gated on its orientation against the field (``inverted``) and on self-intersections
(surface/gates.py). Skinning and the bounded correction then move every vertex, and the joint sweeps
(surface/sweep.py) only measure one joint turned at a time, on its own seam. Here the mesh as the
runtime draws it (each vertex skinned by its joint's method, the correction-region vertices corrected
toward the posed field within their trust radius) is taken to each pose of the envelope
(motion/envelope.py: poses of real cycles, every joint turned at once, chosen by farthest-point
selection) and its faults are found:

- **inverted faces** (flips): the face's posed normal against the posed field's gradient at its
  centroid (the rest gate's test, at the pose); a fold that doubles the skin over itself flips its
  middle sheet;
- **folded edges**: manifold edges whose two faces turn past ``FOLD_DEG`` from each other where at rest
  they did not;
- **crossings**: pairs of faces sharing no vertex that cross, decided exactly (surface/intersect.py).
  Only pairs whose relative placement the pose changed are tested: two faces whose every vertex is
  bound wholly to slots the pose moves by one rigid transform keep their rest placement, where the rest
  gate found no crossing.

**Visibility.** A fault counts only where it can be seen. Every skin folds the inner crease of a bent
joint and sinks a limb into the body it touches; those sheets lie inside the volume the posed mesh
encloses, behind another sheet from every viewpoint. A face is seen when the point just outside it
(along the posed field's outward gradient) lies outside that volume: its winding number, counted along a
ray, is 0. A fold or crossing counts when all its faces are seen.

**The band.** Where a limb swings against the body, the field rounds their junction with the blend's
fillet; a skin carries the parts rigidly and shows their hard union there instead, with a crease, a
crossing or a wrinkle along the junction. The field bounds that: between the body's surface (d = 0) and
the hard union of its posed parts (min of the primitive distances = 0) lies only fillet material. A
visible fold or crossing whose faces all lie in that band (within ``BAND_TOL``) shows the parts' own
shape, without their fillet: it is reported as a crease. One with a face off the band shows what the
body does not have (skin outside the body, or sunk into a part) and is gated, as is every visible flip.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from ..field.primitives import primitive_distance
from ..model.rotations import Pose, posed_slots
from ..model.skeleton import Skeleton
from ..rig import CompiledRig
from . import deform, joint_sets, skinning
from .correct import correct
from .field64 import BodyField
from .gates import DISTANCE_TOL, SurfaceGate
from .intersect import (
    BVH,
    PAIR_CHUNK,
    candidate_pairs,
    normal_signs,
    refit,
    triangle_boxes,
    triangle_bvh,
    triangle_pairs,
)
from .mesh import Mesh, angles_deg, unit_rows

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
Bools = npt.NDArray[np.bool_]

#: Angle between two adjacent faces' normals past which the surface doubles back on itself: beyond a
#: right angle the edge is a crease sharper than any the rest mesh's normal gates admit.
FOLD_DEG: Final = 90.0
#: How far off the band (body surface .. hard union of its parts) a fault's face may lie, × L: the
#: rest mesh's own distance tolerance to the zero set (surface/gates.py DISTANCE_TOL).
BAND_TOL: Final = DISTANCE_TOL


@dataclass(frozen=True)
class PoseQuality:
    """What one pose shows where it can be seen."""

    label: str
    inverted: int  # visible faces whose posed normal · ∇d ≤ 0
    folds: int  # visible folded edges with a face off the band (see the module docstring)
    crossing: int  # visible crossing pairs with a face off the band
    creases: int  # visible folded edges and crossing pairs inside the band: the hard union's crease
    candidate_pairs: int  # pairs tested exactly
    fold_deg: float  # largest turn between the faces of a visible folded edge (0: none)
    hidden: int  # faces some fault involves that no viewpoint sees
    fault: tuple[int, ...]  # the faces of one gated fault (the first flip, else fold, else crossing)


@dataclass(frozen=True)
class PosedQuality:
    poses: tuple[PoseQuality, ...]
    faces: int

    def worst(self, key: str) -> PoseQuality | None:
        return max(self.poses, key=lambda p: getattr(p, key), default=None)

    def describe(self) -> dict[str, object]:
        return {
            "faces": self.faces,
            "foldDeg": FOLD_DEG,
            "bandTolerance": BAND_TOL,
            "poses": [
                {
                    "label": p.label,
                    "inverted": p.inverted,
                    "folds": p.folds,
                    "crossing": p.crossing,
                    "creases": p.creases,
                    "candidatePairs": p.candidate_pairs,
                    "foldDeg": round(p.fold_deg, 3),
                    "hidden": p.hidden,
                }
                for p in self.poses
            ],
        }


#: Positions and normals (V, 3) of every vertex skinned to a pose, each by its joint's method.
Skinner = Callable[[Pose], tuple[F64, F64]]


def choice_skinner(
    mesh: Mesh,
    normals: F64,
    weights: tuple[npt.NDArray[np.int32], F64],
    skeleton: Skeleton,
    choice: deform.DeformationChoice,
) -> Skinner:
    """The build's skin: :func:`skinning.skin` with the chosen methods."""

    def skin(pose: Pose) -> tuple[F64, F64]:
        s = skinning.skin(
            mesh.vertices, normals, weights[0], weights[1], pose, choice.methods, skeleton, choice.centers
        )
        return s.positions, s.normals

    return skin


def shipped_pose(
    rig: CompiledRig, mesh: Mesh, skin: Skinner, radius: F64, pose: Pose
) -> tuple[F64, BodyField]:
    """The vertices as the runtime draws them at ``pose`` (skin, then the correction where ``radius`` >
    0), and the posed field they are measured against."""
    positions, skinned_normals = skin(pose)
    field = BodyField(rig.graph, posed_slots(rig.slots, pose))
    region = radius > 0
    if region.any():
        positions, _ = correct(field, mesh, positions, skinned_normals, region, radius)
    return positions, field


#: The ray the enclosure test casts: any fixed direction counts the winding number of a closed mesh;
#: an irrational-looking one makes a ray through an edge or a vertex (counted twice or not at all) as
#: unlikely as it can be.
RAY: Final = np.array([0.2718281828, 0.9238795325, 0.2679491924]) / np.linalg.norm(
    [0.2718281828, 0.9238795325, 0.2679491924]
)
#: How far outside a face its visibility probe sits, × the face's shortest edge: off the face by far
#: more than rounding, nearer than any other sheet a sound mesh puts beside it.
PROBE_OFFSET: Final = 0.01


def winding_numbers(mesh: Mesh, points: F64) -> I64:
    """(Q,) the winding number of the closed ``mesh`` around each point: signed crossings of a ray from
    it along RAY. Faces are binned by their projection on the plane across the ray into a uniform grid,
    so each point meets only the faces over its cell."""
    q = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if q.shape[0] == 0 or mesh.face_count == 0:
        return np.zeros(q.shape[0], dtype=np.int64)
    e1 = np.cross(RAY, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(RAY, e1)
    basis = np.stack([e1, e2, RAY], axis=1)
    c = mesh.corners() @ basis  # (F, 3 corners, (x, y, height))
    p = q @ basis
    lo, hi = c[:, :, :2].min(axis=1), c[:, :, :2].max(axis=1)
    origin = lo.min(axis=0)
    extent = float(np.max(hi.max(axis=0) - origin))
    cell = max(float(np.median(hi - lo)) * 2.0, extent / 4096.0, 1e-12)
    cells = int(extent / cell) + 2
    first = np.floor((lo - origin) / cell).astype(np.int64)
    last = np.floor((hi - origin) / cell).astype(np.int64)
    # Only faces over a cell some point falls in can be crossed by its ray: bin those alone.
    qc = np.floor((p[:, :2] - origin) / cell).astype(np.int64)
    wanted = np.zeros((cells, cells), dtype=bool)
    inside = np.all((qc >= 0) & (qc < cells), axis=1)
    wanted[qc[inside, 0], qc[inside, 1]] = True
    covered = np.cumsum(np.cumsum(np.pad(wanted, ((1, 0), (1, 0))), axis=0, dtype=np.int32), axis=1)
    f0, f1 = np.clip(first, 0, cells - 1), np.clip(last, 0, cells - 1) + 1
    hits = covered[f1[:, 0], f1[:, 1]] - covered[f0[:, 0], f1[:, 1]] - covered[f1[:, 0], f0[:, 1]]
    hits += covered[f0[:, 0], f0[:, 1]]
    near = np.flatnonzero(hits > 0)
    c, first, last = c[near], first[near], last[near]
    span = last - first + 1
    count = span[:, 0] * span[:, 1]
    face = np.repeat(np.arange(c.shape[0]), count)
    k = np.arange(face.size) - np.repeat(np.cumsum(count) - count, count)
    cx = first[face, 0] + k % span[face, 0]
    cy = first[face, 1] + k // span[face, 0]
    key = cx * cells + cy
    order = np.argsort(key, kind="stable")
    key, face = key[order], face[order]
    qkey = np.where(inside, qc[:, 0] * cells + qc[:, 1], -1)
    start = np.searchsorted(key, qkey, side="left")
    stop = np.where(inside, np.searchsorted(key, qkey, side="right"), start)
    per = stop - start
    query = np.repeat(np.arange(q.shape[0]), per)
    f = face[np.repeat(start, per) + (np.arange(query.size) - np.repeat(np.cumsum(per) - per, per))]
    a, b, d = c[f, 0], c[f, 1], c[f, 2]
    x = p[query]

    def cross2(u: F64, v: F64, w: F64) -> F64:
        result: F64 = (v[:, 0] - u[:, 0]) * (w[:, 1] - u[:, 1]) - (v[:, 1] - u[:, 1]) * (w[:, 0] - u[:, 0])
        return result

    area = cross2(a, b, d)
    wa, wb, wd = cross2(b, d, x), cross2(d, a, x), cross2(a, b, x)
    sign = np.sign(area)
    within = (area != 0) & (wa * sign >= 0) & (wb * sign >= 0) & (wd * sign >= 0)
    height = (wa * a[:, 2] + wb * b[:, 2] + wd * d[:, 2]) / np.where(area != 0, area, 1.0)
    hit = within & (height > x[:, 2])
    result: I64 = np.bincount(query[hit], weights=sign[hit], minlength=q.shape[0]).round().astype(np.int64)
    return result


def seen(posed: Mesh, faces: I64, outward: F64) -> Bools:
    """(len(faces),) whether each face can be seen: the point just outside it, along the posed field's
    outward direction, lies outside the volume the posed mesh encloses (winding number 0). A point the
    mesh encloses is behind some sheet from every viewpoint."""
    if faces.size == 0:
        return np.zeros(0, dtype=bool)
    corners = posed.corners()[faces]
    shortest = np.min(np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2), axis=1)
    probe = corners.mean(axis=1) + PROBE_OFFSET * shortest[:, None] * unit_rows(outward[faces])
    result: Bools = winding_numbers(posed, probe) == 0
    return result


def _rigid_groups(
    weights: tuple[npt.NDArray[np.int32], F64], faces: npt.NDArray[np.integer], pose: Pose
) -> I64:
    """(F,) a face's rigid group at ``pose``: the class of slots sharing one transform that binds every
    corner wholly, or −1 where a corner blends transforms (a seam)."""
    table = np.concatenate([pose.rotations.reshape(-1, 9), pose.translations], axis=1)
    _, klass = np.unique(table, axis=0, return_inverse=True)
    klass = klass.reshape(-1)
    idx, w = weights
    live = w > 0
    first = klass[idx[:, 0]]
    same = np.all(~live | (klass[idx] == first[:, None]), axis=1)
    vertex_group = np.where(same, first, -1)
    corner = vertex_group[faces]
    one = (corner[:, 0] == corner[:, 1]) & (corner[:, 0] == corner[:, 2])
    result: I64 = np.where(one, corner[:, 0], -1)
    return result


def _crossings(posed: Mesh, groups: I64, rest_bvh: BVH) -> tuple[I64, int]:
    """(crossing pairs (N, 2), pairs tested) among the faces the pose moved relative to each other; the
    rest mesh's tree refitted to the pose serves as the broad phase, and the exact plane signs are
    taken only for the faces some candidate pair holds."""
    corners = posed.corners()
    tree = refit(rest_bvh, *triangle_boxes(corners))
    batches = list(candidate_pairs(tree, posed.faces, groups))
    found = [np.zeros((0, 2), dtype=np.int64)]
    if not batches:
        return found[0], 0
    i = np.concatenate([b[0] for b in batches])
    j = np.concatenate([b[1] for b in batches])
    faces, local = np.unique(np.concatenate([i, j]), return_inverse=True)
    signs, _ = normal_signs(corners[faces])
    flat = np.all(signs == 0, axis=1)
    li, lj = local[: i.size], local[i.size :]
    keep = ~flat[li] & ~flat[lj]
    i, j, li = i[keep], j[keep], li[keep]
    for s in range(0, i.size, PAIR_CHUNK):
        bi, bj = i[s : s + PAIR_CHUNK], j[s : s + PAIR_CHUNK]
        verdict = triangle_pairs(corners[bi], corners[bj], signs[li[s : s + PAIR_CHUNK]])
        hit = verdict.hit & ~verdict.coplanar
        found.append(np.stack([bi[hit], bj[hit]], axis=1))
    return np.concatenate(found), int(i.size)


def off_band(field: BodyField, points: F64, tolerance: float) -> Bools:
    """(P,) points off the band between the posed body's surface and its parts' hard union: outside the
    body (d > tolerance) or inside some part deeper than tolerance. Inside the band lies the blends'
    fillet material; a skin crease there shows the parts' hard union where the field rounds it."""
    if points.shape[0] == 0:
        return np.zeros(0, dtype=bool)
    d = field.distance(points)
    used = np.unique(
        [r.index for op in field.graph.ops for r in op.children if r.kind == "slot"]
        + [r.index for r in field.graph.roots if r.kind == "slot"]
    )
    hard = primitive_distance(field.slots[used], points).min(axis=0)
    result: Bools = (d > tolerance) | (hard < -tolerance)
    return result


def pose_quality(
    rig: CompiledRig,
    mesh: Mesh,
    weights: tuple[npt.NDArray[np.int32], F64],
    skin: Skinner,
    radius: F64,
    pose: Pose,
    label: str,
    edges: I64,
    rest_turn: F64,
    rest_bvh: BVH,
) -> PoseQuality:
    positions, field = shipped_pose(rig, mesh, skin, radius, pose)
    posed = Mesh(positions, mesh.faces)
    centroids = posed.corners().mean(axis=1)
    _, g = field.field(centroids)
    face_n = posed.face_normals()
    inverted = np.flatnonzero(np.einsum("ij,ij->i", face_n, g) <= 0)
    turn = angles_deg(unit_rows(face_n[edges[:, 0]]), unit_rows(face_n[edges[:, 1]]))
    fold_edge = (turn > FOLD_DEG) & (rest_turn <= FOLD_DEG)
    folded = edges[fold_edge]
    pairs, tested = _crossings(posed, _rigid_groups(weights, mesh.faces, pose), rest_bvh)
    # Visibility and the band are asked only of the faces some fault involves.
    involved = np.unique(np.concatenate([inverted, folded.reshape(-1), pairs.reshape(-1)]))
    visible = np.zeros(mesh.face_count, dtype=bool)
    visible[involved] = seen(posed, involved, g)
    off = np.zeros(mesh.face_count, dtype=bool)
    off[involved] = off_band(field, centroids[involved], BAND_TOL * rig.body_scale)
    inverted = inverted[visible[inverted]]
    shown_folds = visible[folded].all(axis=1)
    shown_pairs = visible[pairs].all(axis=1)
    bad_folds = folded[shown_folds & off[folded].any(axis=1)]
    bad_pairs = pairs[shown_pairs & off[pairs].any(axis=1)]
    creases = (
        int(np.count_nonzero(shown_folds) + np.count_nonzero(shown_pairs))
        - bad_folds.shape[0]
        - bad_pairs.shape[0]
    )
    fault = next(
        (f for f in (inverted[:1], bad_folds[:1].reshape(-1), bad_pairs[:1].reshape(-1)) if f.size),
        inverted[:0],
    )
    return PoseQuality(
        label,
        int(inverted.size),
        int(bad_folds.shape[0]),
        int(bad_pairs.shape[0]),
        creases,
        tested,
        float(turn[fold_edge][shown_folds].max(initial=0.0)),
        int(involved.size - np.count_nonzero(visible[involved])),
        tuple(int(f) for f in fault),
    )


def posed_quality(
    rig: CompiledRig,
    mesh: Mesh,
    weights: tuple[npt.NDArray[np.int32], F64],
    skin: Skinner,
    radius: F64,
    poses: Sequence[Pose],
    labels: Sequence[str],
) -> PosedQuality:
    """Every envelope pose measured (see the module docstring); ``radius`` is the runtime's correction
    trust radius per vertex (zero outside the correction region)."""
    edges = joint_sets.edge_faces(mesh.faces.astype(np.int64))
    rest_n = unit_rows(mesh.face_normals())
    rest_turn = angles_deg(rest_n[edges[:, 0]], rest_n[edges[:, 1]])
    tree = triangle_bvh(mesh)
    measured = tuple(
        pose_quality(rig, mesh, weights, skin, radius, pose, label, edges, rest_turn, tree)
        for pose, label in zip(poses, labels, strict=True)
    )
    return PosedQuality(measured, mesh.face_count)


def posed_gates(quality: PosedQuality, face_parts: Sequence[str]) -> list[SurfaceGate]:
    """Visible flips, and visible folds and crossings off the band, worst pose each: none may show. A
    failed gate names the parts its fault lies on (``face_parts``: each face's part) and the pose."""
    gates = []
    for key, name, unit, what in (
        ("inverted", "posed.inverted", "faces", "visible faces whose posed normal · ∇d ≤ 0"),
        ("folds", "posed.folds", "edges", f"visible edges folded past {FOLD_DEG:.0f}° off the body's band"),
        ("crossing", "posed.selfIntersections", "pairs", "visible crossing face pairs off the body's band"),
    ):
        worst = quality.worst(key)
        value = float(getattr(worst, key)) if worst else 0.0
        detail = what
        if worst and value:
            parts = " and ".join(dict.fromkeys(face_parts[f] for f in worst.fault))
            detail = f"{what}; worst in the envelope pose '{worst.label}', on {parts}"
        gates.append(SurfaceGate(name, value, 0.0, unit, "max", detail))
    return gates
