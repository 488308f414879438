"""Radial frames: orthonormal, rotation-minimising along chains, and θ continuous through the posed
direction where a helper-axis rule switches branch (and the helper-axis rule shown to jump there)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt
import pytest

from conftest import EXAMPLES
from creaturegen.model import layout as col
from creaturegen.model.skeleton import Skeleton, build_skeleton
from creaturegen.rig import CompiledRig, compile_rig
from creaturegen.spec import CharacterSpec, load_spec
from creaturegen.surface.frames import (
    minimal_rotation,
    posed_frame,
    posed_frames,
    radial_coordinates,
    rest_frames,
    rest_frames_from,
    slot_radial,
    twisted,
)

F64 = npt.NDArray[np.float64]
CREATURES = [p for p in sorted(EXAMPLES.rglob("*.json")) if "frost" not in p.parts]
STEP_DEG = 0.5
UP = np.array([0.0, 1.0, 0.0])


def _rig(path: Path) -> tuple[CompiledRig, Skeleton]:
    spec = load_spec(path)
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    return rig, build_skeleton(spec, rig)


def _rotation_angle(r: F64) -> float:
    return float(np.arccos(np.clip((np.trace(r) - 1.0) / 2.0, -1.0, 1.0)))


def _wrap(angle: F64) -> F64:
    result: F64 = (angle + np.pi) % (2.0 * np.pi) - np.pi
    return result


def helper_axis_frame(a: F64, b: F64) -> F64:
    """The rule the seed forbids: world up as helper unless the limb is nearly vertical, then X."""
    t = (b - a) / np.linalg.norm(b - a)
    helper = np.array([1.0, 0.0, 0.0]) if abs(t @ UP) > 0.99 else UP
    n = helper - (helper @ t) * t
    n /= np.linalg.norm(n)
    frame = np.eye(4)
    frame[:3, 0], frame[:3, 1], frame[:3, 2], frame[:3, 3] = t, n, np.cross(t, n), a
    return frame


def _segment(a: F64, b: F64, r: float = 0.05) -> F64:
    row = np.zeros(col.WIDTH)
    row[col.A], row[col.B], row[col.RA], row[col.RB] = a, b, r, r
    return row


# --- rest frames -------------------------------------------------------------------------------------


@pytest.mark.parametrize("path", CREATURES, ids=lambda p: p.name)
def test_rest_frames_are_orthonormal_right_handed_and_follow_the_slots(path: Path) -> None:
    rig, skeleton = _rig(path)
    frames = rest_frames(rig, skeleton)
    assert frames.shape == (rig.slot_count, 4, 4)
    r = frames[:, :3, :3]
    assert np.abs(np.einsum("sji,sjk->sik", r, r) - np.eye(3)).max() < 1e-12
    assert np.abs(np.linalg.det(r) - 1.0).max() < 1e-12
    assert np.array_equal(frames[:, 3], np.tile([0.0, 0.0, 0.0, 1.0], (rig.slot_count, 1)))
    assert np.allclose(frames[:, :3, 3], rig.slots[:, col.A])
    axis = rig.slots[:, col.B] - rig.slots[:, col.A]
    length = np.linalg.norm(axis, axis=1)
    for s in range(rig.slot_count):
        if length[s] > 0:
            assert np.allclose(frames[s, :3, 0], axis[s] / length[s], atol=1e-12)
        else:  # a sphere takes its parent's frame (a root sphere +Z)
            p = skeleton.parent[s]
            expected = frames[p, :3, :3] if p >= 0 else None
            if expected is not None:
                assert np.allclose(frames[s, :3, :3], expected, atol=1e-12)
            else:
                assert np.allclose(frames[s, :3, 0], [0.0, 0.0, 1.0])


@pytest.mark.parametrize("path", CREATURES, ids=lambda p: p.name)
def test_every_joint_turns_by_the_minimal_rotation(path: Path) -> None:
    """Transport adds no twist: parent→child rotation angle equals the angle between the tangents."""
    rig, skeleton = _rig(path)
    frames = rest_frames(rig, skeleton)
    for parent, child in skeleton.joints:
        r0, r1 = frames[parent, :3, :3], frames[child, :3, :3]
        bend = float(np.arccos(np.clip(r0[:, 0] @ r1[:, 0], -1.0, 1.0)))
        assert abs(_rotation_angle(r1 @ r0.T) - bend) < 1e-7, (skeleton.names[parent], skeleton.names[child])


def test_rope_chain_on_a_helix_has_minimal_twist() -> None:
    """A non-planar chain (helix polyline): the transported frames turn only as much as the tangents
    do at every joint, while helper-axis frames on the same chain add twist on top."""
    k = np.arange(25)
    points = np.stack([np.cos(0.4 * k), 0.15 * k, np.sin(0.4 * k)], axis=1)
    slots = np.stack([_segment(points[j], points[j + 1]) for j in range(24)])
    parent = [-1, *range(23)]
    frames = rest_frames_from(slots, parent)
    bends, transported, helper = [], [], []
    naive = [helper_axis_frame(points[j], points[j + 1]) for j in range(24)]
    for j in range(23):
        r0, r1 = frames[j, :3, :3], frames[j + 1, :3, :3]
        bends.append(float(np.arccos(np.clip(r0[:, 0] @ r1[:, 0], -1.0, 1.0))))
        transported.append(_rotation_angle(r1 @ r0.T))
        helper.append(_rotation_angle(naive[j + 1][:3, :3] @ naive[j][:3, :3].T))
    assert np.allclose(transported, bends, atol=1e-9)
    assert sum(helper) > sum(bends) + 0.1  # the helper-axis frames twist on top of the bends
    # The frame's normal stays ⊥ the binormal of each bend plane's rotation axis component: the
    # normal's component along t0 × t1 is preserved (rotation about that axis).
    for j in range(23):
        t0, t1 = frames[j, :3, 0], frames[j + 1, :3, 0]
        axis = np.cross(t0, t1)
        assert abs(frames[j, :3, 1] @ axis - frames[j + 1, :3, 1] @ axis) < 1e-12


def test_reversal_turns_by_pi_about_the_normal() -> None:
    up, down = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])
    slots = np.stack([_segment(np.zeros(3), up), _segment(up, up + down)])
    frames = rest_frames_from(slots, [-1, 0])
    assert np.allclose(frames[1, :3, 0], [0.0, 0.0, -1.0])
    assert np.allclose(frames[1, :3, 1], frames[0, :3, 1])
    assert abs(np.linalg.det(frames[1, :3, :3]) - 1.0) < 1e-12


# --- posed frames and θ continuity ----------------------------------------------------------------


def _theta_sweep(frame_of: str, stop_deg: float = 150.0) -> F64:
    """θ of one skin point while the limb swings through vertical (where |t·up| > 0.99).

    The limb starts horizontal along +X and sweeps in a slightly tilted plane, so it passes within
    about 3.4° of straight up. The point rides with the limb by incremental minimal rotations (as an
    animated bone would carry it), independently of how any frame is computed. Frames: "transported"
    is the rest frame carried by one minimal rotation per pose; "incremental" carries the previous
    posed frame instead (no singularity at the rest tangent's reversal); "helper" is the forbidden rule.
    """
    a = np.zeros(3)
    rest = rest_frames_from(_segment(a, np.array([1.0, 0.0, 0.0]))[None], [-1])[0]
    theta0, radius = 0.3, 0.05
    point = 0.5 * rest[:3, 0] + radius * (np.cos(theta0) * rest[:3, 1] + np.sin(theta0) * rest[:3, 2])
    phis = np.radians(np.arange(0.0, stop_deg + STEP_DEG, STEP_DEG))
    directions = np.stack([np.cos(phis), np.sin(phis), np.full_like(phis, 0.06)], axis=1)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    directions[0] = rest[:3, 0]
    thetas = []
    previous = directions[0]
    frame = rest
    for d in directions:
        point = minimal_rotation(previous, d, rest[:3, 1]) @ point
        previous = d
        if frame_of == "transported":
            frame = posed_frame(rest, a, a + d)
        elif frame_of == "incremental":
            frame = posed_frame(frame, a, a + d)
        else:
            frame = helper_axis_frame(a, a + d)
        theta, _ = radial_coordinates(point, frame, 1.0)
        thetas.append(float(theta[0]))
    assert max(abs(d @ UP) for d in directions) > 0.99  # the sweep does cross the branch switch
    return np.asarray(thetas)


def test_theta_is_continuous_through_the_helper_axis_branch_switch() -> None:
    """One minimal rotation from rest per pose: θ moves by well under a step angle per step (it drifts
    slowly: the direct rotation from rest and the path the point took differ by holonomy)."""
    jumps = np.abs(_wrap(np.diff(_theta_sweep("transported"))))
    assert jumps.max() < 2.0 * np.radians(STEP_DEG), np.degrees(jumps.max())


def test_incremental_transport_keeps_theta_fixed_past_the_rest_reversal() -> None:
    """Carrying the previous posed frame instead of the rest frame follows the point exactly, also
    where the limb swings past the reversal of its rest direction."""
    thetas = _theta_sweep("incremental", stop_deg=220.0)
    assert np.abs(_wrap(thetas - thetas[0])).max() < 1e-9


def test_helper_axis_rule_jumps_there() -> None:
    """The same sweep with the forbidden rule: θ jumps by tens of degrees at the switch."""
    jumps = np.abs(_wrap(np.diff(_theta_sweep("helper"))))
    assert jumps.max() > 20.0 * np.radians(STEP_DEG), np.degrees(jumps.max())


def test_posed_frame_maps_the_tangent_and_keeps_the_rest_pose() -> None:
    rest = rest_frames_from(_segment(np.zeros(3), np.array([0.2, 0.5, -0.1]))[None], [-1])[0]
    a, b = rest[:3, 3], rest[:3, 3] + rest[:3, 0] * 0.7
    assert np.allclose(posed_frame(rest, a, b), rest, atol=1e-15)
    rng = np.random.default_rng(5)
    for _ in range(20):
        pa, d = rng.normal(size=3), rng.normal(size=3)
        f = posed_frame(rest, pa, pa + d)
        assert np.allclose(f[:3, 0], d / np.linalg.norm(d))
        assert np.allclose(f[:3, 3], pa)
        assert np.allclose(f[:3, :3].T @ f[:3, :3], np.eye(3))
        assert abs(np.linalg.det(f[:3, :3]) - 1.0) < 1e-12
    # Exact reversal: π about the rest normal, never a world axis.
    f = posed_frame(rest, a, a - rest[:3, 0])
    assert np.allclose(f[:3, 0], -rest[:3, 0])
    assert np.allclose(f[:3, 1], rest[:3, 1])


def test_twist_shifts_theta_by_the_twist_angle() -> None:
    rest = rest_frames_from(_segment(np.zeros(3), np.array([0.0, 0.0, 1.0]))[None], [-1])[0]
    point = np.array([[0.03, 0.04, 0.5]])
    theta0, t0 = radial_coordinates(point, rest, 1.0)
    for angle in (0.2, -1.0, 2.5):
        theta, t = radial_coordinates(point, twisted(rest, angle), 1.0)
        assert np.allclose(_wrap(theta - theta0), -angle)
        assert np.allclose(t, t0)
        posed = posed_frame(rest, np.zeros(3), np.array([0.0, 0.0, 1.0]), twist=angle)
        assert np.allclose(posed, twisted(rest, angle))


def test_radial_coordinates_recover_a_constructed_point() -> None:
    rest = rest_frames_from(_segment(np.array([1.0, 2.0, 3.0]), np.array([1.5, 2.0, 2.0]))[None], [-1])[0]
    length = float(np.sqrt(0.25 + 1.0))
    thetas = np.linspace(-3.0, 3.0, 7)
    ts = np.linspace(0.0, 1.0, 7)
    n, b, t = rest[:3, 1], rest[:3, 2], rest[:3, 0]
    points = (
        rest[:3, 3]
        + ts[:, None] * length * t
        + 0.07 * (np.cos(thetas)[:, None] * n + np.sin(thetas)[:, None] * b)
    )
    theta, along = radial_coordinates(points, np.broadcast_to(rest, (7, 4, 4)), np.full(7, length))
    assert np.allclose(theta, thetas)
    assert np.allclose(along, ts)


def test_posed_frames_of_a_rig_turn_spheres_with_their_parent() -> None:
    rig, skeleton = _rig(EXAMPLES / "beetle.json")
    rest = rest_frames(rig, skeleton)
    assert np.allclose(posed_frames(rest, rig.slots, skeleton.parent), rest, atol=1e-15)
    head = skeleton.names.index("part.head")
    shell = skeleton.parent[head]
    # Tilt the whole creature about X: every frame turns by the same rotation, the head sphere too.
    c, s = np.cos(0.4), np.sin(0.4)
    rot = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    posed = rig.slots.copy()
    posed[:, col.A] = rig.slots[:, col.A] @ rot.T
    posed[:, col.B] = rig.slots[:, col.B] @ rot.T
    frames = posed_frames(rest, posed, skeleton.parent)
    assert np.allclose(frames[shell, :3, :3], rot @ rest[shell, :3, :3])
    assert np.allclose(frames[head, :3, :3], frames[shell, :3, :3])
    for i in range(rig.slot_count):
        assert np.allclose(frames[i, :3, 0], rot @ rest[i, :3, 0])


def test_slot_radial_measures_segments_in_lengths_and_spheres_in_radii() -> None:
    rig, skeleton = _rig(EXAMPLES / "beetle.json")
    frames = rest_frames(rig, skeleton)
    head = skeleton.names.index("part.head")
    shell = skeleton.parent[head]
    centre, r = rig.slots[head, col.A], rig.slots[head, col.RA]
    a, b = rig.slots[shell, col.A], rig.slots[shell, col.B]
    points = np.stack([centre + 0.5 * r * frames[head, :3, 0], 0.25 * a + 0.75 * b])
    radial = slot_radial(points, frames, rig.slots, [head, shell])
    assert np.all(np.isfinite(radial))
    assert np.allclose(radial[:, 1], [0.5, 0.75])
    # radial_coordinates itself never divides by a zero length.
    _, t = radial_coordinates(points[:1], frames[head], 0.0)
    assert t[0] == 0.0
