"""Skin weights: every gate passes on real creatures, and the barrier gate fails when the barrier is off.

The examples cover legs touching the shell (beetle), knees buried in the body and a rope tail
(quadruped), a long tapering rope tail with legs (lizard) and wings (moth); the tangled beetle fixture
has legs touching each other. The barrier counter-example is the pincer fixture: two claws, siblings
under one body, whose tips touch.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from conftest import EXAMPLES, rest_surface
from creaturegen.model.skeleton import Skeleton, build_skeleton
from creaturegen.motion.compiled import compile_creature
from creaturegen.spec import CharacterSpec, load_spec
from creaturegen.surface.field64 import BodyField
from creaturegen.surface.mesh import Mesh
from creaturegen.surface.weights import LEAKAGE_MAX, SkinWeights, neighbour_matrix, skin_weights

EXAMPLE_NAMES = ["beetle.json", "reference/quadruped.json", "lizard.json", "moth.json"]

#: A body with two claws whose tips meet (x = ±0.03 at the tips, r = 0.05): skeleton non-neighbours in
#: contact. Its surface is a torus; tests/test_surface_handles.py checks the euler gate names the claws.
PINCER = Path(__file__).parent / "fixtures" / "pincer.json"
#: The beetle example before its legs were spread: on each side the legs touch each other.
TANGLED = Path(__file__).parent / "fixtures" / "tangled-beetle.json"


@dataclass(frozen=True)
class Surface:
    mesh: Mesh
    field: BodyField
    skeleton: Skeleton


def _surface(path: Path, tier: str) -> Surface:
    s = rest_surface(path, tier)
    return Surface(s.extraction.mesh, s.field, build_skeleton(s.spec, s.rig))


@cache
def example(name: str) -> Surface:
    """A spec under examples/, or an absolute path (the fixtures), at the repeated tier."""
    return _surface(EXAMPLES / name, "repeated")


@cache
def weights_of(name: str) -> SkinWeights:
    s = example(name)
    return skin_weights(s.mesh, s.field, s.skeleton)


@cache
def pincer() -> Surface:
    return _surface(PINCER, "hero")


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_every_gate_passes(name: str) -> None:
    w = weights_of(name)
    failed = [f"{g.name}={g.value:.4g} (threshold {g.threshold}) {g.detail}" for g in w.gates if not g.passed]
    assert not failed, failed
    names = {g.name for g in w.gates}
    assert names == {
        "weights.partition",
        "weights.nonnegative",
        "weights.influences",
        "weights.barrier_leakage",
        "weights.continuity",
        "weights.handle_coverage",
    }


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_layout_and_partition_of_unity(name: str) -> None:
    w = weights_of(name)
    v = example(name).mesh.vertex_count
    s = example(name).field.slots.shape[0]
    assert w.indices.shape == (v, 4)
    assert w.weights.shape == (v, 4)
    assert w.indices.dtype.kind == "i"
    assert w.weights.dtype == np.float64
    assert ((w.indices >= 0) & (w.indices < s)).all()
    assert np.abs(w.weights.sum(axis=1) - 1.0).max() <= 1e-12
    assert (w.weights >= 0.0).all()
    # Largest first; unused influences repeat the dominant slot with weight 0.
    assert (np.diff(w.weights, axis=1) <= 0.0).all()
    unused = w.weights == 0.0
    assert (w.indices[unused] == np.broadcast_to(w.indices[:, :1], w.indices.shape)[unused]).all()
    # Handles are pinned: weight exactly 1 on their slot.
    pinned = w.handle >= 0
    assert (w.indices[pinned, 0] == w.handle[pinned]).all()
    assert (w.weights[pinned, 0] == 1.0).all()


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_every_surface_slot_has_handles(name: str) -> None:
    w = weights_of(name)
    s = example(name).field.slots.shape[0]
    owned = np.bincount(w.owner, minlength=s)
    pinned = np.bincount(w.handle[w.handle >= 0], minlength=s)
    assert ((owned == 0) | (pinned > 0)).all(), [
        example(name).skeleton.names[i] for i in np.flatnonzero(pinned == 0)
    ]
    # A buried slot (no owned vertex) carries no weight anywhere.
    dense = w.dense(s)
    for slot in np.flatnonzero(owned == 0):
        assert dense[:, slot].max() == 0.0


def test_partition_of_unity_survives_heavy_pruning() -> None:
    s = example("reference/quadruped.json")
    w = skin_weights(s.mesh, s.field, s.skeleton, max_influences=2)
    assert w.indices.shape[1] == 2
    assert w.gate("weights.partition").passed
    assert w.gate("weights.influences").value <= 2
    assert np.abs(w.weights.sum(axis=1) - 1.0).max() <= 1e-12
    assert (w.weights >= 0.0).all()


def test_beetle_contacts_are_cut_apart() -> None:
    """At rest the tangled beetle's legs on one side touch each other (siblings under the shell) and its
    antennae touch the shell (their grandparent): none of these pairs are skeleton neighbours."""
    s = example(str(TANGLED))
    w = weights_of(str(TANGLED))
    near = neighbour_matrix(s.skeleton)
    edges = np.sort(s.mesh.edges(), axis=1)
    a, b = w.owner[edges[:, 0]], w.owner[edges[:, 1]]
    touching = {
        (s.skeleton.names[i], s.skeleton.names[j]) for i, j in zip(a, b, strict=True) if not near[i, j]
    }
    assert ("part.antenna-left", "part.shell") in touching | {(y, x) for x, y in touching}
    assert any(
        "leg-mid-left" in x and "leg-front-left" in y for x, y in touching | {(y, x) for x, y in touching}
    )
    assert w.barrier_edges > 0
    foreign = ~near[w.owner[:, None], w.indices] & (w.weights > 0.0)
    assert not foreign.any()


def test_removing_the_barrier_fails_the_leakage_gate() -> None:
    s = pincer()
    near = neighbour_matrix(s.skeleton)
    left, right = s.skeleton.names.index("part.claw-left"), s.skeleton.names.index("part.claw-right")
    assert not near[left, right], "the claws must be skeleton non-neighbours for this test to mean anything"

    kept = skin_weights(s.mesh, s.field, s.skeleton)
    assert kept.barrier_edges > 0, "the claw tips must touch"
    assert kept.passed, [(g.name, g.value) for g in kept.gates if not g.passed]
    assert kept.gate("weights.barrier_leakage").value <= LEAKAGE_MAX

    leaky = skin_weights(s.mesh, s.field, s.skeleton, barrier=False)
    gate = leaky.gate("weights.barrier_leakage")
    assert not gate.passed
    assert gate.value > 0.1
    # The leak is the other claw's weight at the touching tips.
    dense = leaky.dense(s.field.slots.shape[0])
    assert dense[leaky.owner == left, right].max() > 0.1
    assert dense[leaky.owner == right, left].max() > 0.1


def test_weights_are_deterministic() -> None:
    s = example("moth.json")
    a = skin_weights(s.mesh, s.field, s.skeleton)
    b = skin_weights(s.mesh, s.field, s.skeleton)
    assert np.array_equal(a.indices, b.indices)
    assert np.array_equal(a.weights, b.weights)


def test_rejects_zero_influences() -> None:
    s = pincer()
    with pytest.raises(ValueError, match="max_influences"):
        skin_weights(s.mesh, s.field, s.skeleton, max_influences=0)


def _planted_gates(s: Surface, still: frozenset[int]) -> dict[str, float]:
    """The weight gates of one-hot weights on each vertex's owner: a hard seam between every two parts."""
    from creaturegen.surface.weights import _gates, motion_groups, undirected_edges

    v = s.mesh.vertex_count
    owner = np.argmin(s.field.slot_distances(s.mesh.vertices), axis=0).astype(np.int32)
    indices = np.repeat(owner[:, None], 4, axis=1).astype(np.int32)
    weights = np.zeros((v, 4))
    weights[:, 0] = 1.0
    gates = _gates(
        undirected_edges(s.mesh),
        np.zeros(v, dtype=bool),
        indices,
        weights,
        owner,
        owner,
        neighbour_matrix(s.skeleton),
        s.skeleton,
        [],
        0,
        motion_groups(s.skeleton, still),
    )
    return {g.name: g.value for g in gates}


def test_continuity_reads_seams_between_parts_that_move_apart() -> None:
    """A hard seam between two parts that move relative to each other still fails the gate; the same seam
    between parts the motion never turns apart (one transform in every pose, so no skinning method can
    show it) does not count."""
    from creaturegen.surface.weights import CONTINUITY_MAX, motion_groups

    s = example("lizard.json")
    children = frozenset(child for _, child in s.skeleton.joints)
    assert motion_groups(s.skeleton, frozenset()).tolist() == list(range(s.field.slots.shape[0]))
    assert len(set(motion_groups(s.skeleton, children).tolist())) == 1  # one root, every joint still
    moving = _planted_gates(s, frozenset())["weights.continuity"]
    assert moving == 1.0 > CONTINUITY_MAX
    assert _planted_gates(s, children)["weights.continuity"] == 0.0
    # Only the head's joints still: the seams of the legs and the tail still fail.
    head = frozenset(c for p, c in s.skeleton.joints if s.skeleton.names[c] in ("part.head", "part.snout"))
    assert head
    assert _planted_gates(s, head)["weights.continuity"] == 1.0


def test_the_build_reads_still_joints_from_the_motion() -> None:
    """The lizard's head and snout never turn against the body in its gait; its legs and tail do."""
    from creaturegen.motion.envelope import pose_envelope
    from creaturegen.rig import compile_rig
    from creaturegen.spec import load_spec

    spec = load_spec(EXAMPLES / "lizard.json")
    rig = compile_rig(spec)
    skeleton = build_skeleton(spec, rig)
    still = {skeleton.names[c] for c in pose_envelope(compile_creature(spec)).still_joints(rig.body_scale)}
    assert {"part.head", "part.snout"} <= still
    assert not any(name.startswith(("part.leg", "part.tail")) for name in still)


STEEP_ROPE = Path(__file__).parent / "fixtures" / "steep-rope-hopper.json"


def test_a_steep_weight_rim_is_split_before_the_build_refuses(monkeypatch: pytest.MonkeyPatch) -> None:
    """Generated seed 142 (`creaturegen random --seed 142`), a hopper whose 4-segment rope tail is about as
    thick as a segment is long: tail[0]'s handle is a small island between the body's and tail[1]'s, and
    the harmonic weight falls from 1 to 0.6 across one edge at its rim (0.4006 against the gate's 0.4).
    The build splits the triangles along the steepest edges and keeps the split mesh, every gate passing;
    without that remedy the same build is refused, naming the gate and the two tail segments."""
    from creaturegen.surface import build as surface_build
    from creaturegen.surface import remedies
    from creaturegen.surface.refusal import SurfaceRejectedError

    spec = load_spec(STEEP_ROPE)
    assert isinstance(spec, CharacterSpec)
    said: list[str] = []
    built = surface_build.build_surface(compile_creature(spec), backend="numpy", progress=said.append)
    assert [g.name for g in built.gates if not g.passed] == []
    continuity = next(g for g in built.gates if g.name == "weights.continuity")
    assert continuity.value < 0.4
    assert any("split where a weight drops" in line for line in said), said
    monkeypatch.setattr(remedies, "WEIGHT_SPLIT_ROUNDS", 0)
    with pytest.raises(SurfaceRejectedError, match=r"weights\.continuity = 0\.40.*part\.tail"):
        surface_build.build_surface(compile_creature(spec), backend="numpy", progress=lambda _: None)
