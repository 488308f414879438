"""Local subdivision toward the field: the remedy for mesh-normal gates where the surface bends within a cell.

A blend fillet (a small part sunk into a bigger one, a leg meeting a hip with a small k) turns the true
normal within one or two lattice cells. Marching cubes samples it at the lattice's pitch everywhere, so
the triangles there chord across the bend and their normals (and their vertices' area-weighted normals)
depart from the field's by tens of degrees. A √2 finer lattice halves that chord everywhere at eight
times the sampling cost, and can change the topology elsewhere (two parts a finer lattice separates).

This module halves it only where the normals disagree: the longest edge of a marked triangle gets a
midpoint, moved onto the zero set along its ends' normals, and the split is closed by Rivara's
longest-edge refinement (a neighbour that shares a split edge splits its own longest edge too, so no
T-junction is left and no angle falls below half its parent's). The surface stays closed and manifold
with the same Euler characteristic (each split adds a vertex, three edges and two faces). Existing
vertices do not move. The mesh gates judge the result as they judged the lattice's.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .gates import FACE_NORMAL_P99_DEG, VERTEX_NORMAL_P99_DEG, vertex_normals
from .mesh import Mesh, angles_deg, unit_rows

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
FieldFn = Callable[[F64], tuple[F64, F64]]

#: Vertices whose area-weighted normal departs from ∇d by more than this are marked (degrees): twice
#: the p99 bound of surface/gates.py, so the tail that decides the p99 gate is refined and the bulk is not.
MARK_VERTEX_DEG = 10.0
#: Faces whose normal departs from ∇d at the centroid by more than this are marked (degrees).
MARK_FACE_DEG = 20.0
#: The marks of a second pass, run only when a p99 gate still fails after the first: the p99 bounds
#: themselves, so the whole tail above them is split. Seed 187's head at hero kept vertex p99 at 5.36° with
#: marks at 10°/20° (nothing left past them) and reached 3.99° with these, +28 % vertices, where the next
#: lattice (+100 %) opened a handle.
TAIL_MARKS = (VERTEX_NORMAL_P99_DEG, FACE_NORMAL_P99_DEG)
#: Rounds at most: a longest-edge split halves a triangle, so two rounds halve the chord across a fillet;
#: eight take a one-cell fillet to a sixteenth of a cell (the fixture of tests/test_subdivide.py needs them).
LEVELS = 8
#: Newton steps for a midpoint along its edge's normal line, clamped to MAX_MOVE of the edge's length; a
#: midpoint counts as arrived within PROJECT_TOL of the edge's length of the zero set.
NEWTON_STEPS = 6
PROJECT_TOL = 1e-3
#: Below this |∇d · direction| the line runs along the surface: no Newton step is taken.
SLOPE_FLOOR = 0.1
#: Closures taken again without the marked faces around midpoints that did not arrive, before the round
#: gives up (each retry only shrinks the marked set).
RETRIES = 12
#: Ends whose normals are further apart than this (cos 150°) face apart across a thin part: their mean
#: points nowhere useful. A blend crease that the lattice cuts across can turn 120-125° within one edge
#: (seed 81's leg joint at hero); its bisector is still the way to the fillet, so the bound sits past that.
OPPOSED_COS = -0.866
#: How far a midpoint may travel along its line, in edge lengths: the depth below the chord of a V whose
#: sides' normals are OPPOSED_COS apart, (l/2)·tan(θ/2) for the angle θ between them (1.87 l at 150°).
#: A tighter clamp stopped midpoints short of the fillet on exactly the creases the bound above admits:
#: seed 88's hips at hero, normals 130° apart, fillet 0.55 l below the chord (refused with 0.5 l).
MAX_MOVE = 0.5 * math.sqrt((1.0 - OPPOSED_COS) / (1.0 + OPPOSED_COS))


def normal_departures(mesh: Mesh, gradient: Callable[[F64], F64]) -> tuple[F64, F64]:
    """(vertex, face) angles in degrees between the mesh normals and ∇d (at vertices and centroids)."""
    vertex = angles_deg(vertex_normals(mesh), gradient(mesh.vertices))
    face = angles_deg(mesh.face_normals(), gradient(mesh.corners().mean(axis=1)))
    return vertex, face


def _edge_keys(faces: I64, count: int) -> I64:
    """(F, 3) undirected key of edge k of each face (corner k to corner k+1)."""
    a, b = faces, np.roll(faces, -1, axis=1)
    result: I64 = np.minimum(a, b) * count + np.maximum(a, b)
    return result


def _longest(vertices: F64, faces: I64, keys: I64) -> I64:
    """(F,) which edge of each face is its longest; ties go to the smaller edge key, so two faces
    sharing an edge agree on its rank (the closure below relies on one global order of edges)."""
    c = vertices[faces]
    length = np.linalg.norm(np.roll(c, -1, axis=1) - c, axis=2)
    order = np.lexsort((keys.ravel(), -length.ravel()))  # longest first, then smaller key
    rank = np.empty(order.size, dtype=np.int64)
    rank[order] = np.arange(order.size)
    result: I64 = np.argmin(rank.reshape(faces.shape), axis=1)
    return result


def _close_marks(keys: I64, longest: I64, marked: I64) -> npt.NDArray[np.bool_]:
    """(F, 3) split flags: the marked edges, closed so that every face with a split edge splits its
    longest edge too (Rivara's longest-edge refinement: the children's angles stay bounded below by
    half the parent's, where repeated green bisection would grind a fillet into slivers)."""
    rows = np.arange(keys.shape[0])
    while True:
        split = np.isin(keys, marked)
        missing = split.any(axis=1) & ~split[rows, longest]
        if not missing.any():
            return split
        marked = np.union1d(marked, keys[missing, longest[missing]])


def _midpoints(start: F64, end: F64, field: FieldFn) -> tuple[F64, npt.NDArray[np.bool_], F64]:
    """Each edge's midpoint moved onto the zero set along the mean of its ends' unit normals (Newton on
    the distance along that line), and whether it arrived (not where the ends face apart: the mean of
    two opposed normals points nowhere), and ∇d there. Moving along the ends' normals, not along ∇d
    at the midpoint, keeps the point over its own chord: inside a concave fillet ∇d points at one of the
    two sheets, and following it would slide the point sideways and fold its triangles."""
    chord = 0.5 * (start + end)
    length = np.linalg.norm(end - start, axis=1)
    ends = unit_rows(field(start)[1]), unit_rows(field(end)[1])
    direction = unit_rows(ends[0] + ends[1])
    t = np.zeros(chord.shape[0])
    for _ in range(NEWTON_STEPS):
        d, g = field(chord + t[:, None] * direction)
        slope = np.einsum("ij,ij->i", g, direction)
        step = np.where(np.abs(slope) > SLOPE_FLOOR, d / np.where(slope == 0.0, 1.0, slope), 0.0)
        t = np.clip(t - step, -MAX_MOVE * length, MAX_MOVE * length)
    moved = chord + t[:, None] * direction
    d, g = field(moved)
    ok = (np.abs(d) <= PROJECT_TOL * length) & (np.einsum("ij,ij->i", ends[0], ends[1]) > OPPOSED_COS)
    return moved, ok, g


@dataclass(frozen=True)
class _Split:
    """One round of splits, with what the next round can reuse: the faces carried over whole come first
    in the new face list, and ∇d at the new vertices is known from their projection."""

    mesh: Mesh
    added: int
    declined: int
    whole: npt.NDArray[np.bool_]  # (F,) old faces carried over unchanged
    gradient: F64  # (added, 3) ∇d at the new vertices
    fresh_gradient: F64  # ∇d at the centroids of the new faces (after the whole ones)


def split_faces(mesh: Mesh, marked_faces: I64, field: FieldFn) -> tuple[Mesh, int, int]:
    """The mesh with the longest edge of every face in ``marked_faces`` split at its zero-set midpoint,
    closed by longest-edge refinement (no T-junction is left); returns (mesh, vertices added, marked
    faces declined). A midpoint that cannot reach the zero set (an edge across a crease or a thin tip)
    is never left on its chord, where it would stand off the surface as a spike, nor kept where a
    triangle around it would face against ∇d: the marked faces around it are declined and the closure
    is taken again without them."""
    done = _split(mesh, marked_faces, field)
    return done.mesh, done.added, done.declined


def _split(mesh: Mesh, marked_faces: I64, field: FieldFn) -> _Split:
    faces = mesh.faces.astype(np.int64)
    vertices = mesh.vertices
    count = vertices.shape[0]
    keys = _edge_keys(faces, count)
    longest = _longest(vertices, faces, keys)
    marked = np.unique(marked_faces)
    stuck = np.zeros(count, dtype=bool)
    unchanged = _Split(
        mesh, 0, int(marked.size), np.ones(faces.shape[0], dtype=bool), np.zeros((0, 3)), np.zeros((0, 3))
    )
    for _ in range(RETRIES):
        split = _close_marks(keys, longest, np.unique(keys[marked, longest[marked]]))
        edges = np.unique(keys[split])
        if edges.size == 0:
            return unchanged
        mids, ok, at_mids = _midpoints(vertices[edges // count], vertices[edges % count], field)
        if ok.all():
            new_faces, whole = _assemble(faces, keys, longest, split, edges, count)
            fresh = new_faces[np.count_nonzero(whole) :]
            refined = np.concatenate([vertices, mids])
            corners = refined[fresh]
            at_fresh = field(corners.mean(axis=1))[1]
            normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
            folded = np.einsum("ij,ij->i", normal, at_fresh) <= 0.0
            if not folded.any():
                mesh_out = Mesh(refined, new_faces.astype(mesh.faces.dtype))
                declined = int(np.unique(marked_faces).size - marked.size)
                return _Split(mesh_out, int(edges.size), declined, whole, at_mids, at_fresh)
            # A midpoint carried into a narrow crease can fold the triangles around it: decline its edge.
            folding = np.unique(fresh[folded][fresh[folded] >= count]) - count
            ok[folding] = False
        # Decline the marked faces around the stuck ends, one ring wider on every retry: a closure can
        # reach a stuck edge from a marked face a few triangles away (along its longest-edge path).
        stuck[edges[~ok] // count] = True
        stuck[edges[~ok] % count] = True
        stuck[faces[stuck[faces].any(axis=1)].ravel()] = True
        marked = marked[~stuck[faces[marked]].any(axis=1)]
    return unchanged


def _assemble(
    faces: I64, keys: I64, longest: I64, split: npt.NDArray[np.bool_], edges: I64, count: int
) -> tuple[I64, npt.NDArray[np.bool_]]:
    """The new face list (faces kept whole first) and which old faces were kept whole, for the split
    flags of a closed marking; the midpoint of ``edges[i]`` is vertex ``count + i``."""
    rows = np.arange(faces.shape[0])
    mid = np.where(split, count + np.searchsorted(edges, keys), -1)  # (F, 3) midpoint of edge k, or -1
    # Rotate every face so its longest edge comes first: (a, b) longest, c opposite, m its midpoint;
    # p splits (b, c) and q splits (c, a) where those are split too.
    turn = (longest[:, None] + np.arange(3)) % 3
    v, m, s = faces[rows[:, None], turn], mid[rows[:, None], turn], split[rows[:, None], turn]
    a, b, c, mab, p, q = v[:, 0], v[:, 1], v[:, 2], m[:, 0], m[:, 1], m[:, 2]
    whole = ~s[:, 0]
    out = [faces[whole]]
    left = s[:, 0] & ~s[:, 2]  # (a, m, c) stays whole
    right = s[:, 0] & ~s[:, 1]  # (m, b, c) stays whole
    out.append(np.stack((a, mab, c), axis=1)[left])
    out.append(np.stack((mab, b, c), axis=1)[right])
    two = s[:, 0] & s[:, 2]
    out += [np.stack((a, mab, q), axis=1)[two], np.stack((mab, c, q), axis=1)[two]]
    two = s[:, 0] & s[:, 1]
    out += [np.stack((mab, b, p), axis=1)[two], np.stack((mab, p, c), axis=1)[two]]
    return np.concatenate(out), whole


def subdivide_to_field(
    mesh: Mesh,
    field: FieldFn,
    levels: int = LEVELS,
    marks: tuple[float, float] = (MARK_VERTEX_DEG, MARK_FACE_DEG),
) -> tuple[Mesh, int, int]:
    """Up to ``levels`` rounds of ``split_faces`` on the faces whose normal, or a corner's, departs from
    the field past the marking angles ``marks`` (vertex, face; degrees); returns (mesh, vertices added,
    marked faces declined). Vertices never move and whole faces keep their centroids, so ∇d is evaluated
    only at what a round made new."""
    added = declined = 0
    at_vertices = field(mesh.vertices)[1]
    at_centroids = field(mesh.corners().mean(axis=1))[1]
    for _ in range(levels):
        vertex = angles_deg(vertex_normals(mesh), at_vertices)
        face = angles_deg(mesh.face_normals(), at_centroids)
        bad_vertex = vertex > marks[0]
        marked = np.flatnonzero((face > marks[1]) | bad_vertex[mesh.faces].any(axis=1))
        if marked.size == 0:
            break
        done = _split(mesh, marked, field)
        added += done.added
        declined += done.declined
        if done.added == 0:
            break
        mesh = done.mesh
        at_vertices = np.concatenate([at_vertices, done.gradient])
        at_centroids = np.concatenate([at_centroids[done.whole], done.fresh_gradient])
    return mesh, added, declined


def analytic_normals(mesh: Mesh, gradient: Callable[[F64], F64]) -> F64:
    """Unit ∇d at every vertex (what Extraction.normals holds for the lattice's vertices)."""
    return unit_rows(gradient(mesh.vertices))
