"""The pose envelope (motion/envelope.py): measured from the creature's own motion, taken modulo rigid body
motion, widened by stated margins, and holding for individuals it never sampled."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from conftest import CREATURE_EXAMPLES, MOTION_FIXTURES, spec_file
from creaturegen.model import layout as col
from creaturegen.model.skeleton import Skeleton, build_skeleton
from creaturegen.motion import envelope
from creaturegen.motion.compiled import compile_creature
from creaturegen.motion.data import MotionData
from creaturegen.motion.providers import AnalyticWater
from creaturegen.motion.rig import ROPE_BEND_LIMIT_DEG, build_motion
from creaturegen.motion.simulate import Motion
from creaturegen.rig import CompiledRig, compile_rig
from creaturegen.spec import CharacterSpec
from creaturegen.spec.gate import load_spec

#: Spawn seeds of the individuals checked against the envelope (none is a corner or a heading seed).
RANDOM_SEEDS = (101, 2024, 77777)


def _load(name: str) -> tuple[CharacterSpec, CompiledRig, MotionData, Skeleton]:
    spec = load_spec(spec_file(name))
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    skeleton = build_skeleton(spec, rig)
    return spec, rig, build_motion(spec, rig, skeleton), skeleton


@pytest.mark.parametrize("name", [*CREATURE_EXAMPLES, *MOTION_FIXTURES])
def test_random_individuals_stay_inside_the_widened_envelope(name: str) -> None:
    """Individuals the envelope never stepped (random seeds: their own genomes and headings) on every support
    stay inside what the sweeps certify: each slot within its excursion ball, each joint within its swept
    bend and twist. The corners alone are not enough (a random individual goes past them); the margins
    are what this checks."""
    spec, rig, data, skeleton = _load(name)
    env = envelope.pose_envelope(compile_creature(spec))
    assert env.samples > 0
    assert env.ticks >= 240
    runs = [
        (f"{support} seed {seed}", envelope.individual(data, provider, seed))
        for support, provider in envelope.envelope_supports(data).items()
        for seed in RANDOM_SEEDS
    ]
    seen = envelope.measure_envelope(data, rig.slots, skeleton, runs)
    slack = seen.slot_displacement / np.maximum(env.slot_excursion, 1e-300)
    moving = env.slot_displacement > 0.0
    ratio = seen.slot_displacement[moving] / env.slot_displacement[moving]
    print(f"{name}: random/corner displacement max {np.max(ratio, initial=0.0):.3f}")
    assert np.all(seen.slot_displacement[~moving] <= 1e-12 * rig.body_scale)
    assert np.all(slack[moving] <= 1.0), f"{name}: a slot leaves its ball by ×{slack.max():.3f}"
    for joint in seen.joints:
        bend, twist = env.sweep_limits(joint.child)
        where = skeleton.names[joint.child]
        assert joint.bend_deg <= max(bend, envelope.STILL_DEG), (
            f"{name} {where}: bend {joint.bend_deg:.2f}° > swept {bend:.2f}°"
        )
        assert joint.twist_deg <= max(twist, envelope.STILL_DEG), (
            f"{name} {where}: twist {joint.twist_deg:.2f}° > {twist:.2f}°"
        )


def test_rigid_body_motion_is_taken_out_and_a_flap_moves_its_wing_by_its_chord() -> None:
    """The flyer banks its whole body, which moves no slot relative to another: the body's displacement is
    zero. A wing flapping by ±A about its root moves its tip by at most 2·|b − a|·sin(A/2), and a whole
    flap cycle reaches it."""
    spec, _rig, data, _ = _load("reference/flyer.json")
    env = envelope.pose_envelope(compile_creature(spec))
    root = data.roots[0]
    assert env.slot_displacement[root] <= 1e-12
    for wing in data.wings:
        slot = wing.slot
        chord = 2.0 * wing.length * math.sin(wing.amplitude / 2.0)
        assert 0.98 * chord <= env.slot_displacement[slot] <= chord * (1.0 + 1e-12), (slot, chord)
    assert any(j.bend_deg > 0.0 for j in env.joints)
    assert all(j.pivot_drift < 1e-12 for j in env.joints), "a wing turns about its root"


def test_ropes_keep_their_length_and_bend_limit() -> None:
    """The follow-the-leader pass holds every segment at its rest length and every bend within the limit
    (the swimmer's tail touches no ground, so nothing overrides it); relaxation passes alone left the tail
    stretched and bent past the limit."""
    _, _, data, _ = _load("reference/swimmer.json")
    motion = Motion(data, water=AnalyticWater(), seed=3)
    worst_len, worst_bend = 0.0, 0.0
    for _ in range(600):
        motion.step()
        for rope, nodes in zip(motion.data.ropes, motion.nodes, strict=True):  # the individual's size
            seg = rope.segment
            dirs = [np.subtract(b, a) for a, b in itertools.pairwise(nodes)]
            worst_len = max(worst_len, max(abs(float(np.linalg.norm(d)) - seg) / seg for d in dirs))
            for u, v in itertools.pairwise(dirs):
                cos = float(u @ v) / float(np.linalg.norm(u) * np.linalg.norm(v))
                worst_bend = max(worst_bend, math.degrees(math.acos(min(1.0, cos))))
    print(f"swimmer: segment length error {worst_len:.2e}, worst bend {worst_bend:.4f}°")
    assert worst_len < 1e-12
    assert worst_bend <= ROPE_BEND_LIMIT_DEG + 1e-6


def test_the_disk_copy_is_the_measured_envelope_bit_for_bit() -> None:
    spec, rig, data, _skeleton = _load("reference/hopper.json")
    env = envelope.pose_envelope(compile_creature(spec))
    copy = envelope._from_json(envelope._to_json(env))
    assert copy.joints == env.joints
    # Each turning joint names the run where it turns most (a refusal's message repeats it).
    turning = [j for j in env.joints if max(j.bend_deg, j.twist_deg) > envelope.STILL_DEG]
    assert turning
    assert all(j.worst_run in env.runs for j in turning)
    assert copy.runs == env.runs
    assert copy.pose_labels == env.pose_labels
    assert np.array_equal(copy.slot_displacement, env.slot_displacement)
    for a, b in zip(copy.poses, env.poses, strict=True):
        assert np.array_equal(a.rotations, b.rotations)
        assert np.array_equal(a.translations, b.translations)
    # The hopper's squash is the root transform's, applied after the field: it moves no slot, so the body
    # slot (a root) stays put while the tail swings.
    assert env.slot_displacement[data.roots[0]] == 0.0
    tail = [s for s, part in enumerate(rig.slot_parts) if part == "counter-tail"]
    assert np.all(env.slot_displacement[tail] > 0.0)
    assert rig.slots[tail[0], col.RA] > 0.0


def test_worker_processes_do_not_change_the_envelope(monkeypatch: pytest.MonkeyPatch) -> None:
    """Runs stepped by forked workers come back in run order with the very floats stepped in-process."""
    _spec, rig, data, skeleton = _load("reference/flyer.json")
    measured = []
    for workers in ("1", "3"):
        monkeypatch.setenv(envelope.WORKERS_ENV, workers)
        measured.append(envelope._to_json(envelope.measure_envelope(data, rig.slots, skeleton)))
    assert envelope.envelope_workers(2) == 2  # at most one process per run
    assert measured[0] == measured[1]


def test_a_started_envelope_is_the_measured_one_and_stops_when_left(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """The surface stage starts the envelope's workers before it extracts the mesh and waits afterwards:
    the result is the envelope measured in one go, and a build that leaves early (a mesh gate refused)
    leaves no worker running."""
    monkeypatch.setenv("CREATUREGEN_CACHE", str(tmp_path))
    monkeypatch.setenv(envelope.WORKERS_ENV, "2")
    spec, rig, data, skeleton = _load("reference/flyer.json")
    with envelope.start_pose_envelope(compile_creature(spec)) as pending:
        pool = pending._pool
        assert pool is not None, "two workers were asked for: the runs step in forked processes"
        workers = list(pool._pool)
        started = envelope._to_json(pending.result())
    assert started == envelope._to_json(envelope.measure_envelope(data, rig.slots, skeleton))
    assert not any(w.is_alive() for w in workers)

    monkeypatch.setenv("CREATUREGEN_CACHE", str(tmp_path / "other"))
    with envelope.start_pose_envelope(compile_creature(spec)) as pending:
        workers = list(pending._pool._pool)
    assert not any(w.is_alive() for w in workers), (
        "workers outlived a build that never asked for the envelope"
    )
