"""Edge flips toward the field (surface/flips.py): a quad split along the diagonal that cuts across a fold
is flipped to the diagonal the fold runs along, and a flip that gains nothing is not made."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from creaturegen.surface.flips import flip_to_field
from creaturegen.surface.mesh import Mesh, angles_deg

F64 = npt.NDArray[np.float64]

#: A unit square folded along its diagonal b-d: a, b, d flat, c lifted.
A, B, C, D = 0, 1, 2, 3
VERTICES = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.8], [0.0, 1.0, 0.0]])
FLAT = np.array([0.0, 0.0, 1.0])
TILTED = np.cross(VERTICES[C] - VERTICES[B], VERTICES[D] - VERTICES[B])
TILTED = TILTED / np.linalg.norm(TILTED)


def fold_gradient(points: F64) -> F64:
    """The folded surface's normal: flat on a's side of the line b-d (x + y < 1), tilted beyond it."""
    beyond = points[:, 0] + points[:, 1] > 1.0
    return np.where(beyond[:, None], TILTED, FLAT)


def _angles(mesh: Mesh) -> F64:
    c = mesh.vertices[mesh.faces]
    normal = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    return angles_deg(normal, fold_gradient(c.mean(axis=1)))


def test_a_triangulation_across_the_fold_is_flipped_along_it() -> None:
    across = Mesh(VERTICES, np.array([[A, B, C], [A, C, D]], dtype=np.int32))
    assert _angles(across).max() > 20.0
    flipped, count = flip_to_field(across, fold_gradient)
    assert count == 1
    assert {frozenset(f) for f in flipped.faces.tolist()} == {frozenset((A, B, D)), frozenset((B, C, D))}
    assert _angles(flipped).max() < 1e-9
    assert flipped.faces.dtype == across.faces.dtype
    np.testing.assert_array_equal(flipped.vertices, across.vertices)
    # Orientation kept: every face still faces along the field.
    assert np.all(_angles(flipped) < 90.0)


def test_a_triangulation_along_the_fold_is_left_alone() -> None:
    along = Mesh(VERTICES, np.array([[A, B, D], [B, C, D]], dtype=np.int32))
    flipped, count = flip_to_field(along, fold_gradient)
    assert count == 0
    np.testing.assert_array_equal(flipped.faces, along.faces)
