"""Edge flips where a triangle cuts across the field's curvature: a remedy for the mesh-normal gates.

Marching cubes connects the zero-set points of one lattice cell by a fixed table, so where a blend fillet
or a small part bends the surface within a cell or two, a triangle can span the bend along the wrong
diagonal: its normal then departs from the field's by tens of degrees while the vertices lie exactly on
the zero set. Flipping that edge (the quad's other diagonal) moves no vertex and keeps the surface closed
and manifold, with the same vertex, edge and face counts (so the same Euler characteristic); it only
chooses the triangulation that follows the field. The mesh gates then judge the result unchanged.

A flip is kept only when it lowers the worse of its two faces' normal angles (face normal against the
field's gradient at the face centroid) by at least MIN_GAIN_DEG, both new faces face along the gradient,
the new diagonal is not already an edge, and the smallest interior angle of the pair does not fall below
the pair's before (the mesh's angle gate stays as it was).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from .mesh import Mesh, angles_deg

F64 = npt.NDArray[np.float64]
GradientFn = Callable[[F64], F64]

#: Faces whose normal departs from the field's by more than this are the flips' candidates (degrees).
CANDIDATE_DEG = 20.0
#: Least improvement of the pair's worse angle that a flip must bring (degrees).
MIN_GAIN_DEG = 1.0
#: Passes over the candidates (a flip can make its neighbour's flip worthwhile).
PASSES = 4


def _face_angles(vertices: F64, faces: npt.NDArray[np.int64], gradient: GradientFn) -> tuple[F64, F64]:
    """(angle in degrees to the field gradient at the centroid, unnormalised normal) per face."""
    c = vertices[faces]
    normal = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    return angles_deg(normal, gradient(c.mean(axis=1))), normal


def _min_angle(vertices: F64, faces: npt.NDArray[np.int64]) -> F64:
    """Smallest interior angle of each face, degrees."""
    c = vertices[faces]
    out = np.full(faces.shape[0], 180.0)
    for k in range(3):
        u = c[:, (k + 1) % 3] - c[:, k]
        v = c[:, (k + 2) % 3] - c[:, k]
        out = np.minimum(out, angles_deg(u, v))
    return out


def flip_to_field(mesh: Mesh, gradient: GradientFn) -> tuple[Mesh, int]:
    """The mesh with edges flipped where the other diagonal follows the field better, and the flip count."""
    vertices = mesh.vertices
    faces = mesh.faces.astype(np.int64).copy()
    flipped = 0
    for _ in range(PASSES):
        angle, _ = _face_angles(vertices, faces, gradient)
        bad = np.flatnonzero(angle > CANDIDATE_DEG)
        if bad.size == 0:
            break
        # Directed edge (a, b) → the face holding it; the twin (b, a) is the neighbour across it.
        directed = {}
        for f, (a, b, c) in enumerate(faces.tolist()):
            directed[(a, b)] = f
            directed[(b, c)] = f
            directed[(c, a)] = f
        touched: set[int] = set()
        done = 0
        for f in bad.tolist():
            if f in touched:
                continue
            best: tuple[float, int, npt.NDArray[np.int64], npt.NDArray[np.int64]] | None = None
            row = faces[f].tolist()
            for k in range(3):
                a, b, c = row[k], row[(k + 1) % 3], row[(k + 2) % 3]
                g = directed.get((b, a))
                if g is None or g in touched:
                    continue
                other = faces[g].tolist()
                d = next(x for x in other if x != a and x != b)
                if (c, d) in directed or (d, c) in directed or c == d:
                    continue
                old = np.array([row, other])
                new = np.array([[a, d, c], [b, c, d]])
                old_angle, _ = _face_angles(vertices, old, gradient)
                new_angle, normal = _face_angles(vertices, new, gradient)
                if np.any(np.linalg.norm(normal, axis=1) == 0.0) or np.any(new_angle >= 90.0):
                    continue
                gain = float(old_angle.max() - new_angle.max())
                if gain < MIN_GAIN_DEG or _min_angle(vertices, new).min() < _min_angle(vertices, old).min():
                    continue
                if best is None or gain > best[0]:
                    best = (gain, g, new, old)
            if best is None:
                continue
            _, g, new, old = best
            for face in old.tolist():
                for k in range(3):
                    directed.pop((face[k], face[(k + 1) % 3]), None)
            faces[f], faces[g] = new[0], new[1]
            for h, face in ((f, new[0].tolist()), (g, new[1].tolist())):
                for k in range(3):
                    directed[(face[k], face[(k + 1) % 3])] = h
            touched.update((f, g))
            done += 1
        flipped += done
        if done == 0:
            break
    return Mesh(vertices, faces.astype(mesh.faces.dtype)), flipped
