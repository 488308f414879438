"""Posed quality (surface/posed.py): the enclosure count behind the visibility rule against the field's
own inside/outside, the rigid-pair shortcut against a whole-body motion, a joint bent within what LBS
carries against one bent past it, and a planted defect (a ring of skin bound to the wrong bone) that
every posed gate must catch."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pytest

from conftest import rest_surface
from creaturegen.model.rotations import Pose, rotation_matrix
from creaturegen.model.skeleton import Skeleton, build_skeleton, pose_joint
from creaturegen.rig import CompiledRig
from creaturegen.surface import deform, posed
from creaturegen.surface.field64 import BodyField
from creaturegen.surface.mesh import Mesh
from creaturegen.surface.weights import skin_weights
from test_surface_deform import CHAIN

F64 = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Chain:
    rig: CompiledRig
    skeleton: Skeleton
    mesh: Mesh
    normals: F64
    indices: npt.NDArray[np.int32]
    weights: F64

    def skinner(
        self, indices: npt.NDArray[np.int32] | None = None, weights: F64 | None = None
    ) -> posed.Skinner:
        """LBS at every joint, with the chain's own weights or planted ones."""
        pair = (self.indices if indices is None else indices, self.weights if weights is None else weights)
        choice = deform.DeformationChoice((), ("lbs", "lbs"), np.zeros_like(self.mesh.vertices), "", 0, 0.0)
        return posed.choice_skinner(self.mesh, self.normals, pair, self.skeleton, choice)

    def quality(self, skin: posed.Skinner, pose: Pose, label: str) -> posed.PosedQuality:
        none = np.zeros(self.mesh.vertex_count)
        return posed.posed_quality(
            self.rig, self.mesh, (self.indices, self.weights), skin, none, [pose], [label]
        )

    def bend(self, degrees: float) -> Pose:
        return pose_joint(self.skeleton, self.rig.slots, 1, 0, math.radians(degrees), 0.0)


@pytest.fixture(scope="module")
def chain(tmp_path_factory: pytest.TempPathFactory) -> Chain:
    path = tmp_path_factory.mktemp("spec") / "chain.json"
    path.write_text(json.dumps(CHAIN))
    s = rest_surface(path, "repeated")
    skeleton = build_skeleton(s.spec, s.rig)
    weights = skin_weights(s.extraction.mesh, s.field, skeleton)
    return Chain(s.rig, skeleton, s.extraction.mesh, s.extraction.normals, weights.indices, weights.weights)


def _failed(quality: posed.PosedQuality, chain: Chain) -> set[str]:
    return {g.name for g in posed.posed_gates(quality, ["chain"] * chain.mesh.face_count) if not g.passed}


def _brute_winding(mesh: Mesh, point: F64) -> int:
    """Signed crossings of the same ray with every face, by Moller-Trumbore: no grid, no projection."""
    c = mesh.corners()
    u = posed.RAY
    e1, e2 = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    h = np.cross(u, e2)
    a = np.einsum("ij,ij->i", e1, h)
    s = point - c[:, 0]
    b1 = np.einsum("ij,ij->i", s, h) / a
    q = np.cross(s, e1)
    b2 = (q @ u) / a
    t = np.einsum("ij,ij->i", e2, q) / a
    hit = (b1 >= 0) & (b2 >= 0) & (b1 + b2 <= 1) & (t > 0)
    # Counted by which way the face's outward normal points along the ray (leaving: +1).
    return int(np.sign(np.cross(e1, e2)[hit] @ u).sum())


def test_winding_numbers_agree_with_a_brute_force_count_and_the_field(chain: Chain) -> None:
    """The binned ray count against a count over every face, and against an independent inside test:
    the field's sign, away from the surface by more than this coarse mesh cuts its corners."""
    rng = np.random.default_rng(7)
    lo, hi = chain.mesh.vertices.min(axis=0) - 0.05, chain.mesh.vertices.max(axis=0) + 0.05
    points = rng.uniform(lo, hi, size=(20_000, 3))
    winding = posed.winding_numbers(chain.mesh, points)
    brute = np.array([_brute_winding(chain.mesh, p) for p in points[:2000]])
    np.testing.assert_array_equal(winding[:2000], brute)
    d = BodyField(chain.rig.graph, chain.rig.slots).distance(points)
    clear = np.abs(d) > 0.03 * chain.rig.body_scale
    assert clear.sum() > 5_000
    assert (d[clear] < 0).sum() > 100
    np.testing.assert_array_equal(winding[clear] != 0, d[clear] < 0)
    assert set(np.unique(winding)) <= {0, 1}, "a closed, outward mesh winds once around its inside"


def test_a_face_behind_another_sheet_is_not_seen() -> None:
    """Two nested closed boxes: every face of the inner one is enclosed by the outer, so none is seen;
    every face of the outer one is."""
    cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=np.float64)
    faces = np.array(
        [
            *([0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1]),
            *([2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]),
        ]
    )
    outer = cube * 3.0 - 1.0
    inner = cube * 0.5 + 0.25
    mesh = Mesh(np.concatenate([outer, inner]), np.concatenate([faces, faces + 8]))
    normals = mesh.face_normals()
    seen = posed.seen(mesh, np.arange(mesh.face_count), normals)
    np.testing.assert_array_equal(seen, np.arange(mesh.face_count) < 12)


def test_rest_and_a_rigid_motion_of_the_whole_body_show_nothing(chain: Chain) -> None:
    skin = chain.skinner()
    rotation = rotation_matrix([0.3, 1.0, -0.2], 1.1)
    for pose in (Pose.identity(2), Pose.rigid(2, rotation, [0.4, -0.2, 0.9])):
        q = chain.quality(skin, pose, "rigid").poses[0]
        # One transform moves every face: no pair's placement changed, so none is tested.
        assert (q.inverted, q.folds, q.crossing, q.creases, q.candidate_pairs) == (0, 0, 0, 0, 0)


def test_a_bend_within_what_lbs_carries_passes_and_one_past_it_fails(chain: Chain) -> None:
    """LBS carries the chain's joint to 120° with no visible fault; at 150° its inner crease collapses
    onto itself and folds out of the body's band (the skinning sweep would not choose LBS there)."""
    skin = chain.skinner()
    for degrees in (45.0, 90.0, 120.0):
        q = chain.quality(skin, chain.bend(degrees), f"bend {degrees}")
        assert q.poses[0].candidate_pairs > 0, "a bend changes the placement of faces across the joint"
        assert not _failed(q, chain), q.poses[0]
    q = chain.quality(skin, chain.bend(150.0), "bend 150")
    assert "posed.folds" in _failed(q, chain), q.poses[0]


def test_skin_bound_to_the_wrong_bone_fails_every_posed_gate(chain: Chain) -> None:
    """A ring around the middle of the upper capsule bound wholly to the lower one: a 60° bend swings
    the ring out of the body, its faces fold and cross the skin around them where they show, and the
    failed gates name the part and the pose; at 90° the ring turns over and its faces flip too."""
    ring = np.abs(chain.mesh.vertices[:, 1] - 0.25) < 0.05
    assert ring.sum() >= 8
    indices, weights = chain.indices.copy(), chain.weights.copy()
    indices[ring] = 0
    indices[ring, 0] = 1
    weights[ring] = 0.0
    weights[ring, 0] = 1.0
    planted = chain.skinner(indices, weights)
    q = chain.quality(planted, chain.bend(60.0), "bend 60")
    gates = {g.name: g for g in posed.posed_gates(q, ["part.upper"] * chain.mesh.face_count)}
    assert {n for n, g in gates.items() if not g.passed} == {"posed.folds", "posed.selfIntersections"}, q
    assert "part.upper" in gates["posed.folds"].detail
    assert "'bend 60'" in gates["posed.folds"].detail
    assert "posed.inverted" in _failed(chain.quality(planted, chain.bend(90.0), "bend 90"), chain)
    # The same bend with the chain's own weights shows none of it.
    assert not _failed(chain.quality(chain.skinner(), chain.bend(60.0), "bend 60"), chain)


def test_the_band_tells_a_crease_of_the_hard_union_from_skin_off_the_body(chain: Chain) -> None:
    """Points on a part's surface inside the body's fillet lie in the band; a point outside the body or
    sunk into a part by more than the tolerance does not."""
    field = BodyField(chain.rig.graph, chain.rig.slots)
    tol = posed.BAND_TOL * chain.rig.body_scale
    r = 0.08
    points = np.array(
        [
            [r, 0.25, 0.0],  # on the upper capsule's side: the body's surface
            [r + 3 * tol, 0.25, 0.0],  # outside the body
            [r - 3 * tol, 0.25, 0.0],  # sunk into the upper capsule
        ]
    )
    np.testing.assert_array_equal(posed.off_band(field, points, tol), [False, True, True])


def test_pruning_moved_together_subtrees_keeps_exactly_the_wanted_pairs(chain: Chain) -> None:
    """candidate_pairs with groups skips whole subtrees of the BVH whose faces moved together; the pairs
    it keeps are exactly those of a full traversal with the same-group pairs dropped afterwards."""
    from creaturegen.surface.intersect import candidate_pairs, refit, triangle_boxes, triangle_bvh

    pose = chain.bend(70.0)
    positions, _ = chain.skinner()(pose)
    posed_mesh = Mesh(positions, chain.mesh.faces)
    groups = posed._rigid_groups((chain.indices, chain.weights), chain.mesh.faces, pose)
    assert (groups >= 0).any()
    assert (groups < 0).any()
    tree = refit(triangle_bvh(chain.mesh, leaf_size=2), *triangle_boxes(posed_mesh.corners()))

    def pairs(g: npt.NDArray[np.int64] | None) -> set[tuple[int, int]]:
        return {
            (min(a, b), max(a, b))
            for i, j in candidate_pairs(tree, posed_mesh.faces, g)
            for a, b in zip(i.tolist(), j.tolist(), strict=True)
        }

    everything = pairs(None)
    wanted = {(a, b) for a, b in everything if groups[a] < 0 or groups[a] != groups[b]}
    assert pairs(groups) == wanted
    assert 0 < len(wanted) < len(everything)
