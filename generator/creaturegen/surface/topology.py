"""Combinatorial and shape checks on a triangle mesh: manifoldness, winding, components, genus, quality.

Why these and not a library: the gates must name *what* is wrong (how many boundary edges, which vertex
pinches two sheets) rather than answer a single "is_watertight", and they must run on ~1e5 faces in a
fraction of a second, so everything is a sort/unique/bincount over the half-edge table in numpy.

Conventions: an *edge* is an unordered vertex pair, a *half-edge* the directed pair a face walks
(Mesh.edges order: face f owns half-edges 3f, 3f+1, 3f+2), a *corner* is (face, local vertex 0..2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from .mesh import Mesh

I64 = npt.NDArray[np.int64]
F64 = npt.NDArray[np.float64]
Bools = npt.NDArray[np.bool_]


@dataclass(frozen=True)
class EdgeTable:
    """Unique undirected edges and, for every half-edge, which edge it belongs to."""

    edges: I64  # (E, 2) vertex pairs with edges[:, 0] < edges[:, 1] (or equal for a repeated index)
    edge_of_half: I64  # (3F,) edge id of each half-edge
    forward: Bools  # (3F,) whether the half-edge runs from the smaller to the larger vertex index
    valence: I64  # (E,) faces using each edge (a face listing an edge twice counts twice)


@dataclass(frozen=True)
class EdgeReport:
    edge_count: int
    boundary_edges: int  # used by exactly one face: a hole
    nonmanifold_edges: int  # used by more than two faces: sheets meeting at an edge
    winding_violations: int  # edges whose half-edges do not pair up in opposite directions

    @property
    def watertight(self) -> bool:
        return self.boundary_edges == 0 and self.nonmanifold_edges == 0


@dataclass(frozen=True)
class Components:
    count: int
    face_labels: I64  # (F,)
    vertex_labels: I64  # (V,) smallest label among a vertex's faces; -1 for a vertex no face uses
    vertices: I64  # (C,) vertices per component
    edges: I64  # (C,)
    faces: I64  # (C,)

    @property
    def euler(self) -> I64:
        """χ = V − E + F per component: 2 for a closed sphere-like sheet, 0 for a torus."""
        result: I64 = self.vertices - self.edges + self.faces
        return result

    @property
    def genus(self) -> F64:
        """(2 − χ)/2 per component; only an integer for a closed orientable component."""
        result: F64 = (2.0 - self.euler.astype(np.float64)) / 2.0
        return result


def edge_table(faces: npt.NDArray[np.integer]) -> EdgeTable:
    """One np.unique over sorted half-edge keys; every edge-based check below reads this table."""
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    half = np.stack([f, np.roll(f, -1, axis=1)], axis=2).reshape(-1, 2)
    lo = half.min(axis=1)
    hi = half.max(axis=1)
    span = int(hi.max()) + 1 if hi.size else 1
    keys = lo * span + hi
    unique_keys, edge_of_half, valence = np.unique(keys, return_inverse=True, return_counts=True)
    edges = np.stack([unique_keys // span, unique_keys % span], axis=1)
    return EdgeTable(
        edges=edges.astype(np.int64),
        edge_of_half=edge_of_half.reshape(-1).astype(np.int64),
        forward=half[:, 0] < half[:, 1],
        valence=valence.astype(np.int64),
    )


def edge_report(mesh: Mesh, table: EdgeTable | None = None) -> EdgeReport:
    """Watertight needs valence 2 everywhere; consistent winding needs the two uses to run opposite ways.

    For an edge of valence k the half-edges must split as evenly as k allows (k/2 each way), which for
    k = 2 is exactly "one forward, one backward"; boundary edges carry no winding information.
    """
    t = table if table is not None else edge_table(mesh.faces)
    forward = np.bincount(t.edge_of_half, weights=t.forward, minlength=t.valence.size).astype(np.int64)
    backward = t.valence - forward
    imbalance = np.abs(forward - backward)
    winding_bad = (t.valence >= 2) & (imbalance > t.valence % 2)
    return EdgeReport(
        edge_count=int(t.valence.size),
        boundary_edges=int(np.count_nonzero(t.valence == 1)),
        nonmanifold_edges=int(np.count_nonzero(t.valence > 2)),
        winding_violations=int(np.count_nonzero(winding_bad)),
    )


def corner_fans(mesh: Mesh, table: EdgeTable | None = None) -> I64:
    """Fan label of every corner (3F, face-major): corners at one vertex whose faces are joined across
    edges incident to that vertex share a label; a vertex has as many labels as it has fans."""
    t = table if table is not None else edge_table(mesh.faces)
    f = np.asarray(mesh.faces, dtype=np.int64)
    nf = f.shape[0]
    corner = np.arange(3 * nf, dtype=np.int64).reshape(nf, 3)
    # Half-edge 3f+i runs from corner (f, i) to corner (f, i+1); both ends touch the edge.
    start_corner = corner.reshape(-1)
    end_corner = np.roll(corner, -1, axis=1).reshape(-1)
    vertex = np.concatenate([f.reshape(-1), np.roll(f, -1, axis=1).reshape(-1)])
    corners = np.concatenate([start_corner, end_corner])
    edges = np.concatenate([t.edge_of_half, t.edge_of_half])
    order = np.lexsort((edges, vertex))
    v_sorted, e_sorted, c_sorted = vertex[order], edges[order], corners[order]
    same = (v_sorted[1:] == v_sorted[:-1]) & (e_sorted[1:] == e_sorted[:-1])
    a, b = c_sorted[:-1][same], c_sorted[1:][same]
    n = 3 * nf
    graph = coo_matrix((np.ones(a.size, dtype=np.int8), (a, b)), shape=(n, n)).tocsr()
    _, fan = connected_components(graph, directed=False)
    result: I64 = fan.astype(np.int64)
    return result


def vertex_fans(mesh: Mesh, table: EdgeTable | None = None) -> I64:
    """Number of fans (corner groups joined across shared edges) at each vertex; manifold means one.

    Two corners at vertex v belong to the same fan when their faces share an edge incident to v. Two
    cones touching at their apexes, or two sheets sharing a single vertex, give that vertex two fans even
    though every edge is fine, which is why this check exists beside the edge checks.
    """
    fan = corner_fans(mesh, table)
    n = max(fan.size, 1)
    fan_vertex = np.asarray(mesh.faces, dtype=np.int64).reshape(-1)
    pairs = np.unique(fan_vertex * n + fan)
    counts: I64 = np.bincount(pairs // n, minlength=mesh.vertex_count).astype(np.int64)
    return counts


def nonmanifold_vertices(mesh: Mesh, table: EdgeTable | None = None) -> I64:
    """Used vertices whose corners form more than one fan."""
    result: I64 = np.flatnonzero(vertex_fans(mesh, table) > 1).astype(np.int64)
    return result


def components(mesh: Mesh, table: EdgeTable | None = None) -> Components:
    """Faces joined through shared edges (a pinch vertex does not join), with V, E, F per component.

    V counts the distinct vertices a component's faces use, so an unreferenced vertex changes no χ and a
    vertex shared by two components counts once in each.
    """
    t = table if table is not None else edge_table(mesh.faces)
    f = np.asarray(mesh.faces, dtype=np.int64)
    nf = f.shape[0]
    face_of_half = np.repeat(np.arange(nf, dtype=np.int64), 3)
    order = np.argsort(t.edge_of_half, kind="stable")
    e_sorted, f_sorted = t.edge_of_half[order], face_of_half[order]
    same = e_sorted[1:] == e_sorted[:-1]
    a, b = f_sorted[:-1][same], f_sorted[1:][same]
    graph = coo_matrix((np.ones(a.size, dtype=np.int8), (a, b)), shape=(nf, nf)).tocsr()
    count, labels = connected_components(graph, directed=False)
    labels = labels.astype(np.int64)

    vertex_labels = np.full(mesh.vertex_count, np.iinfo(np.int64).max, dtype=np.int64)
    np.minimum.at(vertex_labels, f.reshape(-1), np.repeat(labels, 3))
    vertex_labels[vertex_labels == np.iinfo(np.int64).max] = -1

    span = max(mesh.vertex_count, 1)
    vert_pairs = np.unique(np.repeat(labels, 3) * span + f.reshape(-1))
    vertices = np.bincount(vert_pairs // span, minlength=count)
    edge_label = np.zeros(t.valence.size, dtype=np.int64)
    edge_label[t.edge_of_half] = np.repeat(labels, 3)
    edges = np.bincount(edge_label, minlength=count)
    faces = np.bincount(labels, minlength=count)
    return Components(
        count=int(count),
        face_labels=labels,
        vertex_labels=vertex_labels,
        vertices=vertices.astype(np.int64),
        edges=edges.astype(np.int64),
        faces=faces.astype(np.int64),
    )


def face_areas(mesh: Mesh) -> F64:
    result: F64 = 0.5 * np.linalg.norm(mesh.face_normals(), axis=1)
    return result


def degenerate_faces(mesh: Mesh, area_eps: float) -> Bools:
    """Faces that carry no usable normal: area below area_eps, or a vertex index listed twice.

    The repeated-index test is separate because such a face has exactly zero area yet also corrupts the
    edge table (it lists one edge twice), and a caller reading the mask should see it regardless of eps.
    """
    f = mesh.faces
    repeated = (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 2] == f[:, 0])
    result: Bools = repeated | (face_areas(mesh) < area_eps)
    return result


def min_angles_deg(mesh: Mesh) -> F64:
    """Smallest interior angle of every face, in degrees (0 for a degenerate face).

    atan2(|u×v|, u·v) rather than acos of a normalised dot: it stays accurate for the tiny angles that
    matter here, where acos loses half the digits.
    """
    c = mesh.corners()
    angles = np.empty((c.shape[0], 3), dtype=np.float64)
    for i in range(3):
        u = c[:, (i + 1) % 3] - c[:, i]
        v = c[:, (i + 2) % 3] - c[:, i]
        angles[:, i] = np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.einsum("ij,ij->i", u, v))
    result: F64 = np.degrees(angles.min(axis=1))
    return result


def min_angle_percentile_deg(angles: F64, percentile: float = 1.0) -> float:
    """A low percentile of ``min_angles_deg`` rather than the minimum: one sliver should not decide, a
    sliver tail should."""
    return float(np.percentile(angles, percentile)) if angles.size else 180.0 / 3.0


def duplicate_faces(mesh: Mesh) -> I64:
    """(k, 2) face pairs over the same vertex set in either orientation (each later copy vs the first)."""
    f = np.sort(np.asarray(mesh.faces, dtype=np.int64), axis=1)
    _, first, inverse = np.unique(f, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    ids = np.arange(f.shape[0], dtype=np.int64)
    head = first[inverse]
    later = ids != head
    result: I64 = np.stack([head[later], ids[later]], axis=1).astype(np.int64)
    return result
