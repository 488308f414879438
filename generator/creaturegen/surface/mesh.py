"""The triangle mesh every surface stage passes along: float64 vertices, int32 faces, nothing else.

Stages that add per-vertex data (normals, weights, candidate program index) return it beside the mesh
rather than growing this type, so a gate or a writer states exactly what it reads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

Vertices = npt.NDArray[np.float64]  # (V, 3)
Faces = npt.NDArray[np.int32]  # (F, 3), counter-clockwise seen from outside (outward normal)


@dataclass(frozen=True)
class Mesh:
    vertices: Vertices
    faces: Faces

    @property
    def vertex_count(self) -> int:
        return int(self.vertices.shape[0])

    @property
    def face_count(self) -> int:
        return int(self.faces.shape[0])

    def corners(self) -> npt.NDArray[np.float64]:
        """(F, 3, 3): the three corner positions of every face."""
        result: npt.NDArray[np.float64] = self.vertices[self.faces]
        return result

    def face_normals(self) -> npt.NDArray[np.float64]:
        """Unnormalised face normals (twice the area vector)."""
        c = self.corners()
        result: npt.NDArray[np.float64] = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
        return result

    def edges(self) -> npt.NDArray[np.int32]:
        """(3F, 2) directed half-edges in face order: (f0 v0→v1, f0 v1→v2, f0 v2→v0, f1 …)."""
        f = self.faces
        result: npt.NDArray[np.int32] = np.stack([f, np.roll(f, -1, axis=1)], axis=2).reshape(-1, 2)
        return result


def unit_rows(v: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Rows scaled to unit length; zero rows stay zero (no direction to give them)."""
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    result: npt.NDArray[np.float64] = v / np.where(n > 0, n, 1.0)
    return result


def angles_deg(u: npt.NDArray[np.float64], v: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Row-wise angle between vectors via atan2(|u×v|, u·v): accurate near 0° where acos is not."""
    result: npt.NDArray[np.float64] = np.degrees(
        np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.einsum("ij,ij->i", u, v))
    )
    return result
