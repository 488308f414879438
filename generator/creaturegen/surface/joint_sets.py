"""What a joint sweep reads of the mesh: the rest mesh once, and per joint its vertex and face classes.

Every joint of a body is swept (surface/sweep.py) against the same rest mesh, so its faces' volume
terms, normals and creases are computed once (:class:`RestMesh`). A joint pose moves only its child's
subtree, so each joint's sweep then needs only the vertices weighted across the joint (its seam), the
faces they touch and a closed form for the faces that move rigidly (:class:`JointSet`). Kept apart from
the sweep's measurements because the seam correction (surface/deform.py) reads the same sets.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..model.skeleton import Skeleton, subtree
from . import topology
from .mesh import Mesh, angles_deg, unit_rows

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
Bools = npt.NDArray[np.bool_]


def any_rows(x: Bools) -> Bools:
    """Per row, whether any entry is set (typed, for the per-corner and per-influence masks)."""
    result: Bools = np.asarray(np.any(x, axis=1), dtype=bool)
    return result


def all_rows(x: Bools) -> Bools:
    """Per row, whether every entry is set."""
    result: Bools = np.asarray(np.all(x, axis=1), dtype=bool)
    return result


@dataclass(frozen=True)
class RestMesh:
    """What every joint's sweep reads of the rest mesh, computed once."""

    vertices: F64
    faces: I64
    triple: F64  # (F,) a·(b×c) per face: 6× its signed volume contribution
    volume: float
    face_normals: F64  # (F, 3) unit
    edge_faces: I64  # (E, 2) the two faces of each manifold edge
    rest_dihedral: F64  # (E,) degrees
    centers: F64


def face_triples(c: F64) -> F64:
    """a·(b×c) per triangle of corners (F, 3, 3): 6× its signed volume contribution."""
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


def rest_mesh(mesh: Mesh, centers: F64) -> RestMesh:
    """The rest mesh's per-face terms every joint's sweep reads; ``centers`` are the CoR centres."""
    faces = mesh.faces.astype(np.int64)
    corners = mesh.vertices[faces]
    triple = face_triples(corners)
    face_normals = unit_rows(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]))
    pairs = edge_faces(faces)
    return RestMesh(
        vertices=mesh.vertices,
        faces=faces,
        triple=triple,
        volume=float(triple.sum()) / 6.0,
        face_normals=face_normals,
        edge_faces=pairs,
        rest_dihedral=angles_deg(face_normals[pairs[:, 0]], face_normals[pairs[:, 1]]),
        centers=centers,
    )


@dataclass(frozen=True)
class JointSet:
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


def joint_set(rest: RestMesh, indices: I64, weights: F64, skeleton: Skeleton, child: int) -> JointSet:
    """The vertex and face classes of the joint above ``child`` (see :class:`JointSet`)."""
    moving = subtree(skeleton, child)
    live = weights > 0
    on_moving: Bools = moving[indices] & live
    seam: Bools = any_rows(on_moving) & any_rows(~moving[indices] & live)
    rigid: Bools = any_rows(on_moving) & ~seam
    corner_seam: Bools = seam[rest.faces]
    seam_face: Bools = any_rows(corner_seam)
    corner_rigid: Bools = rigid[rest.faces]
    rigid_face: Bools = all_rows(corner_rigid)
    mixed_face: Bools = any_rows(corner_rigid) & ~rigid_face & ~seam_face
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
    keep: Bools = all_rows(seam_face[rest.edge_faces])
    return JointSet(
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
