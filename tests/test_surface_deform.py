"""Skinning methods (LBS, DQ, CoR) and the per-joint deformation choice of seed step 6.

Exactness is tested on identities no skinning method may break (rest pose, a rigid motion of the whole
body); the choice is tested on the failure each method exists to avoid (LBS's candy wrapper under a 90°
twist) and on the reference creatures, each of whose joints must receive a method.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest

from conftest import EXAMPLES, rest_surface
from creaturegen.model import layout as col
from creaturegen.model.rotations import Pose, posed_slots, rotation_matrix
from creaturegen.model.skeleton import Skeleton, build_skeleton, pose_joint, subtree
from creaturegen.rig import CompiledRig
from creaturegen.surface import deform, skinning, sweep_gates
from creaturegen.surface.field64 import BodyField
from creaturegen.surface.mesh import Mesh
from creaturegen.surface.sweep import sweep_poses
from creaturegen.surface.weights import skin_weights

F64 = npt.NDArray[np.float64]

#: Two equal capsules end to end along y: the textbook joint (its pivot at (0, 0.5, 0)).
CHAIN: dict[str, Any] = {
    "name": "Capsule Chain",
    "seed": 1,
    "scale": 1,
    "locomotion": {"type": "none"},
    "parts": [
        {"id": "upper", "shape": "capsule", "a": [0, 0, 0], "b": [0, 0.5, 0], "r": 0.08, "color": "#8ec7a4"},
        {
            "id": "lower",
            "shape": "capsule",
            "parent": "upper",
            "a": [0, 0.5, 0],
            "b": [0, 1.0, 0],
            "r": 0.08,
            "color": "#8ec7a4",
        },
    ],
}
#: Small reference creatures: every joint kind (buried hips, knees, rope tails, heads, wings) in a few
#: seconds.
EXAMPLE_NAMES = ["reference/biped.json", "moth.json", "reference/hopper.json"]


@dataclass(frozen=True)
class Body:
    rig: CompiledRig
    skeleton: Skeleton
    field: BodyField
    mesh: Mesh
    normals: F64
    indices: npt.NDArray[np.int32]
    weights: F64

    @property
    def length(self) -> float:
        return self.rig.body_scale

    def choose(self, **kwargs: Any) -> deform.DeformationChoice:
        rig = self.rig
        return deform.choose_deformation(
            self.mesh,
            self.indices,
            self.weights,
            self.field,
            self.skeleton,
            rig.slots,
            rig.graph,
            rig.body_scale,
            **kwargs,
        )


def _body(path: Path) -> Body:
    s = rest_surface(path, "repeated")
    ex = s.extraction
    skeleton = build_skeleton(s.spec, s.rig)
    weights = skin_weights(ex.mesh, s.field, skeleton)
    return Body(s.rig, skeleton, s.field, ex.mesh, ex.normals, weights.indices, weights.weights)


@pytest.fixture(scope="module")
def chain(tmp_path_factory: pytest.TempPathFactory) -> Body:
    path = tmp_path_factory.mktemp("spec") / "chain.json"
    path.write_text(json.dumps(CHAIN))
    return _body(path)


@pytest.fixture(scope="module")
def biped() -> Body:
    return _body(EXAMPLES / "reference" / "biped.json")


@pytest.fixture(scope="module")
def examples() -> dict[str, tuple[Body, deform.DeformationChoice]]:
    out = {}
    for name in EXAMPLE_NAMES:
        body = _body(EXAMPLES / name)
        out[name] = (body, body.choose())
    return out


def _skin(method: str, body: Body, pose: Pose, centers: F64) -> skinning.Skinned:
    v, n, i, w = body.mesh.vertices, body.normals, body.indices, body.weights
    if method == "lbs":
        return skinning.skin_lbs(v, n, i, w, pose)
    if method == "dq":
        return skinning.skin_dq(v, n, i, w, pose)
    return skinning.skin_cor(v, n, i, w, pose, centers)


def _signed_volume(vertices: F64, faces: npt.NDArray[np.int32]) -> float:
    c = vertices[faces]
    return float(np.einsum("ij,ij->i", c[:, 0], np.cross(c[:, 1], c[:, 2])).sum() / 6.0)


# ---------------------------------------------------------------------------------------- exactness


@pytest.mark.parametrize("method", skinning.METHODS)
def test_identity_pose_reproduces_rest_exactly(biped: Body, method: str) -> None:
    centers = skinning.centers_of_rotation(biped.mesh, biped.indices, biped.weights)
    skinned = _skin(method, biped, Pose.identity(biped.rig.slot_count), centers)
    np.testing.assert_array_equal(skinned.positions, biped.mesh.vertices)
    np.testing.assert_allclose(skinned.normals, biped.normals, rtol=0, atol=1e-15)
    assert skinned.flips == 0


@pytest.mark.parametrize("method", skinning.METHODS)
def test_rigid_motion_of_the_whole_body_is_reproduced_by_every_method(biped: Body, method: str) -> None:
    rotation = rotation_matrix([1.0, 2.0, 3.0], math.radians(137.0))
    translation = np.array([0.3, -1.2, 0.7])
    pose = Pose.rigid(biped.rig.slot_count, rotation, translation)
    centers = skinning.centers_of_rotation(biped.mesh, biped.indices, biped.weights)
    skinned = _skin(method, biped, pose, centers)
    expected = biped.mesh.vertices @ rotation.T + translation
    np.testing.assert_allclose(skinned.positions, expected, rtol=0, atol=1e-12 * biped.length)
    np.testing.assert_allclose(skinned.normals, biped.normals @ rotation.T, rtol=0, atol=1e-12)


def test_pose_joint_turns_the_subtree_about_its_pivot_and_leaves_the_rest(biped: Body) -> None:
    skeleton, rest = biped.skeleton, biped.rig.slots
    knee = skeleton.names.index("part.leg-right[1]")
    hip = skeleton.parent[knee]
    pose = pose_joint(skeleton, rest, hip, 0, math.radians(40.0), math.radians(25.0))
    posed = posed_slots(rest, pose)
    moved = subtree(skeleton, hip)
    assert np.flatnonzero(moved).tolist() == sorted([hip, knee])
    np.testing.assert_array_equal(posed[~moved], rest[~moved])
    for columns in (col.RA, col.RB, col.K, col.RGB):
        np.testing.assert_array_equal(posed[:, columns], rest[:, columns])
    pivot = skeleton.pivot[hip]
    np.testing.assert_allclose(pose.rotations[hip] @ pivot + pose.translations[hip], pivot, atol=1e-15)
    # A pure twist spins the child about its own axis: its ends, both on the axis, stay put.
    twist = posed_slots(rest, pose_joint(skeleton, rest, hip, 1, 0.0, math.radians(70.0)))
    np.testing.assert_allclose(twist[hip, col.A], rest[hip, col.A], atol=1e-14)
    np.testing.assert_allclose(twist[hip, col.B], rest[hip, col.B], atol=1e-14)


def test_sweep_volume_matches_skinning_the_whole_mesh(chain: Body) -> None:
    """The sweep skins only the seam (two influences) and moves the rest rigidly in closed form."""
    choice = chain.choose()
    joint = choice.joints[0]
    rest_volume = _signed_volume(chain.mesh.vertices, chain.mesh.faces)
    poses = sweep_poses(chain.skeleton, chain.rig.slots, joint.child)
    for sweep in joint.sweeps:
        direct = max(
            abs(
                _signed_volume(_skin(sweep.method, chain, pose, choice.centers).positions, chain.mesh.faces)
                - rest_volume
            )
            for _, pose in poses
        )
        measured = next(m for m in sweep.measurements if m.name == "volume_change")
        assert measured.value == pytest.approx(direct / rest_volume, rel=1e-9, abs=1e-15)


# ------------------------------------------------------------------------------------ method traits


def test_candy_wrapper_twist_fails_lbs_collapse_and_dq_passes(chain: Body) -> None:
    choice = chain.choose(bend_max_deg=0.0, twist_max_deg=90.0)
    (joint,) = choice.joints
    lbs, dq, _ = joint.sweeps
    collapse = {s.method: next(g for g in s.gates if g.name == "joint_collapse") for s in joint.sweeps}
    assert not collapse["lbs"].passed
    # A 50/50 seam twisted by 90° keeps cos(45°) of its radius under LBS.
    assert collapse["lbs"].value == pytest.approx(math.cos(math.radians(45.0)), abs=0.02)
    assert collapse["dq"].value == pytest.approx(1.0, abs=1e-9)
    assert not lbs.passed
    assert dq.passed
    assert joint.method == "dq"
    assert choice.methods[joint.child] == "dq"
    # The same joint at a small twist keeps LBS: the choice follows the sweep, not a fixed rule.
    assert chain.choose(bend_max_deg=0.0, twist_max_deg=20.0).joints[0].method == "lbs"


def test_dq_antipodality_keeps_a_200_degree_blend_continuous(chain: Body) -> None:
    """Upper turned +100°, lower −100° about the joint: the two rotations are 200° apart, so their
    quaternions lie in opposite hemispheres and must be flipped to blend the short way."""
    pivot = chain.skeleton.pivot[1]
    axis = np.array([1.0, 0.0, 0.0])
    rotations = np.stack([rotation_matrix(axis, math.radians(a)) for a in (100.0, -100.0)])
    pose = Pose(rotations, pivot - rotations @ pivot)
    skinned = skinning.skin_dq(chain.mesh.vertices, chain.normals, chain.indices, chain.weights, pose)
    assert skinned.flips > 0
    # Every blend of rotations about the pivot is a rotation about it: no vertex collapses.
    np.testing.assert_allclose(
        np.linalg.norm(skinned.positions - pivot, axis=1),
        np.linalg.norm(chain.mesh.vertices - pivot, axis=1),
        rtol=1e-12,
    )
    # One vertex across the whole weight range, through the dominance switch at s = 0.5.
    s = np.linspace(0.0, 1.0, 1001)
    point = pivot + np.array([0.0, 0.0, 0.08])
    path = skinning.skin_dq(
        np.tile(point, (s.size, 1)),
        np.tile([0.0, 0.0, 1.0], (s.size, 1)),
        np.tile([0, 1], (s.size, 1)),
        np.stack([1.0 - s, s], axis=1),
        pose,
    ).positions
    steps = np.linalg.norm(np.diff(path, axis=0), axis=1)
    short_way = math.radians(160.0) * 0.08
    # Continuous (normalised-linear blending runs at most ~1.3x the mean speed mid-way) and along the
    # 160° arc, not the 200° one.
    assert steps.max() < 1.5 * short_way / steps.size
    assert steps.sum() == pytest.approx(short_way, rel=1e-3)
    # The 50/50 blend sits at the 180° rotation (the short way), not back at rest (the long way).
    halfway = pivot + rotation_matrix(axis, math.pi) @ (point - pivot)
    np.testing.assert_allclose(path[500], halfway, atol=1e-12)


def test_centers_of_rotation_sit_on_the_joint_axis(chain: Body) -> None:
    centers = skinning.centers_of_rotation(chain.mesh, chain.indices, chain.weights)
    blended = (chain.weights > 0).sum(axis=1) > 1
    assert blended.any()
    offset = centers[blended] - chain.skeleton.pivot[1]
    radial = np.linalg.norm(offset[:, [0, 2]], axis=1)
    assert radial.max() < 0.25 * 0.08  # on the y axis, well inside the limb
    single = ~blended
    np.testing.assert_array_equal(centers[single], chain.mesh.vertices[single])


def test_skin_applies_each_vertex_its_joint_method(biped: Body) -> None:
    slot_count = biped.rig.slot_count
    pose = pose_joint(biped.skeleton, biped.rig.slots, 1, 0, math.radians(50.0), math.radians(20.0))
    centers = skinning.centers_of_rotation(biped.mesh, biped.indices, biped.weights)
    for method in skinning.METHODS:
        mixed = skinning.skin(
            biped.mesh.vertices,
            biped.normals,
            biped.indices,
            biped.weights,
            pose,
            [method] * slot_count,
            biped.skeleton,
            centers,
        )
        alone = _skin(method, biped, pose, centers)
        np.testing.assert_array_equal(mixed.positions, alone.positions)


# ------------------------------------------------------------------------------------------- choice


def test_no_passing_method_fails_naming_the_joint_and_gate(
    chain: Body, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sweep_gates, "SURFACE_MAX_FACTOR", 0.0)
    with pytest.raises(deform.DeformationError, match=r"part\.lower.*surface_max") as info:
        chain.choose()
    assert info.value.joint == "part.lower"
    assert all(not s.passed for s in info.value.sweeps)


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_every_example_joint_gets_a_method(
    examples: dict[str, tuple[Body, deform.DeformationChoice]], name: str
) -> None:
    body, choice = examples[name]
    assert [(j.parent, j.child) for j in choice.joints] == body.skeleton.joints
    assert len(choice.methods) == body.rig.slot_count
    for joint in choice.joints:
        assert joint.method in skinning.METHODS
        assert choice.methods[joint.child] == joint.method
        assert joint.joint == body.skeleton.names[joint.child]
        assert all(g.passed for g in joint.gates)
    json.dumps(choice.describe())
    # The chosen methods skin a sweep pose to finite positions and unit normals.
    _, child = body.skeleton.joints[0]
    pose = pose_joint(body.skeleton, body.rig.slots, child, 1, math.radians(45.0), 0.0)
    skinned = skinning.skin(
        body.mesh.vertices,
        body.normals,
        body.indices,
        body.weights,
        pose,
        choice.methods,
        body.skeleton,
        choice.centers,
    )
    assert np.isfinite(skinned.positions).all()
    np.testing.assert_allclose(np.linalg.norm(skinned.normals, axis=1), 1.0, atol=1e-12)


def test_choice_never_returns_lbs_where_its_sweep_failed(
    examples: dict[str, tuple[Body, deform.DeformationChoice]], chain: Body
) -> None:
    choices = [choice for _, choice in examples.values()]
    choices.append(chain.choose(bend_max_deg=0.0, twist_max_deg=90.0))
    for choice in choices:
        for joint in choice.joints:
            sweeps = {s.method: s for s in joint.sweeps}
            first = next(m for m in skinning.METHODS if sweeps[m].passed)
            assert joint.method == first
            assert (joint.method == "lbs") == sweeps["lbs"].passed


def test_relative_gates_compare_with_a_method_that_keeps_the_joint() -> None:
    """A collapsed LBS joint hugs the posed body from inside; DQ's bulge and surface error are measured
    against the best method that keeps the joint (here CoR), not against the collapsed one. (The sweep
    marks a method once for the whole sweep: one that collapses at some pose is no alternative.)"""
    values = np.array([[0.001, 0.010, 0.006], [0.002, 0.003, 0.004]])
    keeps = np.array([[False, True, True], [True, True, True]])
    excess = sweep_gates._excess(values, keeps)
    assert excess[0].tolist() == pytest.approx([0.0, 0.004, 0.0])
    assert excess[1].tolist() == pytest.approx([0.0, 0.001, 0.002])
    # Where no method keeps the joint, all three stay the reference (the absolute gates fail them).
    assert np.array_equal(sweep_gates._excess(values, np.zeros_like(keeps)), sweep_gates._excess(values))


def test_a_refused_joint_says_how_far_the_motion_turns_it() -> None:
    error = deform.DeformationError("part.leg-front-right[0]", [], 125.8, 15.9)
    assert "part.leg-front-right[0]" in str(error)
    assert "126° bend and 16° twist" in str(error)
    assert "shorter step" in str(error)
    assert "turns this joint" not in str(deform.DeformationError("part.x", []))
    # The run whose turn set the sweep is named: a leg crushed on the slope is not a step too long.
    on_slope = deform.DeformationError(
        "part.leg[0]", [], 173.0, 180.0, worst_run="slope authored heading 180°"
    )
    assert "most in the envelope run 'slope authored heading 180°'" in str(on_slope)
    assert "on a slope, legs long enough to reach the ground" in str(on_slope)


def _corrector(body: Body) -> Any:
    from creaturegen.surface.correction_region import SKIN_ERROR_FACTOR, vertex_trust

    return deform.seam_corrector(
        body.mesh,
        body.normals,
        body.rig.slots,
        body.rig.graph,
        vertex_trust(body.rig, body.mesh, body.normals, body.indices),
        SKIN_ERROR_FACTOR * body.length,
        body.skeleton,
        body.indices.astype(np.int64),
        body.weights,
    )


def test_a_joint_the_skin_alone_cannot_carry_passes_with_its_seam_corrected(
    chain: Body, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The remedy before refusal: a surface bound that every method's skin misses by a few hundredths of L
    (the chain's knee: 0.034 to 0.040 L at the sweep's extremes) and the corrected seam meets (0.005 L:
    the correction pulls the bulge back onto the posed field). The joint is kept, marked corrected, and
    its whole seam joins the correction region the runtime corrects."""
    from creaturegen.surface.correction_region import correction_sweep, seam

    monkeypatch.setattr(sweep_gates, "SURFACE_MAX_FACTOR", 0.25)
    with pytest.raises(deform.DeformationError):
        chain.choose()
    choice = chain.choose(corrector=_corrector(chain))
    (joint,) = choice.joints
    assert joint.corrected
    assert all(g.passed for g in joint.gates)
    surface_max = next(g for g in joint.gates if g.name == "surface_max")
    assert surface_max.value <= surface_max.threshold < 0.034
    assert choice.describe()["joints"][0]["corrected"] is True  # type: ignore[index]
    pair = (chain.indices, chain.weights)
    region, *_ = correction_sweep(
        chain.rig,
        chain.mesh,
        chain.normals,
        pair,
        chain.skeleton,
        choice,
        np.zeros(chain.mesh.vertex_count, dtype=np.int64),
    )
    on_seam = seam(chain.skeleton, pair, joint.child)
    assert on_seam.any()
    assert np.all(region[on_seam])


def test_a_joint_even_the_correction_cannot_carry_names_both_tries(
    chain: Body, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sweep_gates, "SURFACE_MAX_FACTOR", 0.0)
    with pytest.raises(
        deform.DeformationError, match=r"part\.lower.*tried with the seam corrected.*surface_max"
    ):
        chain.choose(corrector=_corrector(chain))


def test_the_sweep_skins_its_seam_exactly_as_the_whole_mesh(biped: Body) -> None:
    """correction_sweep skins only a seam and its one-ring (a 2 k-vertex seam on a 325 k-vertex body paid
    for every vertex at every pose). Those rows must be the whole-mesh skin's, bit for bit, for every
    method, and the ring must hold every corner of a face that touches the seam (``correct`` reads them)."""
    from creaturegen.surface.correction_region import _skin_near, seam

    pair = (biped.indices, biped.weights)
    choice = biped.choose()
    pose = pose_joint(biped.skeleton, biped.rig.slots, 1, 0, math.radians(50.0), math.radians(20.0))
    on_seam = seam(biped.skeleton, pair, 1)
    assert 0 < np.count_nonzero(on_seam) < biped.mesh.vertex_count // 2
    for method in skinning.METHODS:
        methods = [method] * biped.rig.slot_count
        every = skinning.skin(
            biped.mesh.vertices, biped.normals, *pair, pose, methods, biped.skeleton, choice.centers
        )
        near = _skin_near(
            biped.mesh, biped.normals, pair, pose, replace(choice, methods=methods), biped.skeleton, on_seam
        )
        fans = biped.mesh.faces[on_seam[biped.mesh.faces].any(axis=1)].reshape(-1)
        np.testing.assert_array_equal(near.positions[fans], every.positions[fans])
        np.testing.assert_array_equal(near.normals[fans], every.normals[fans])
        far = np.ones(biped.mesh.vertex_count, dtype=bool)
        far[fans] = False
        np.testing.assert_array_equal(near.positions[far], biped.mesh.vertices[far])
