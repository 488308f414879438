"""Locomotion: the Python reference's gates on every example and support surface, determinism, refused
tiers, and the generated JS core against the reference (node --test) on every example.
"""

from __future__ import annotations

import itertools
import json
import math
import re
import subprocess
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from conftest import (
    CREATURE_EXAMPLES,
    MOTION_FIXTURES,
    PARITY_EXAMPLES,
    REPO,
    TEST_FULL,
    build_example,
    node,
    run_node_tests,
    spec_file,
)
from creaturegen.model.record import field_value
from creaturegen.model.skeleton import build_skeleton
from creaturegen.motion import quat as vq
from creaturegen.motion.data import MotionData
from creaturegen.motion.envelope import corner_genomes
from creaturegen.motion.parity import motion_reference
from creaturegen.motion.providers import (
    SWIMMER_CHANNELS,
    AnalyticWater,
    RotatingPlatform,
    builtin_supports,
    closest_point,
    to_local,
    to_world,
)
from creaturegen.motion.rig import WALKERS, build_motion
from creaturegen.motion.root import to_local_root
from creaturegen.motion.simulate import Motion, TierRefusedError
from creaturegen.motion.state import Gates
from creaturegen.rig import compile_rig
from creaturegen.spec import CharacterSpec
from creaturegen.spec.gate import load_spec, validate_bytes

TICKS = 1000
#: The examples and the motion fixtures (the eight-legged spider, the kangaroo: a hopper on two legs): every
#: gate and the JS core parity run on each.
MOTION_SPECS = [*CREATURE_EXAMPLES, *MOTION_FIXTURES]
#: The specs whose locomotion core is checked in Node (JS vs Python, allocation): every one in ``make
#: test-full``; in ``make test`` the browser-parity subset (every locomotion family), the beetle (the
#: compiler-thread probe's subject) and the spider (an octopod). See ``motion_core`` for which core runs.
PACKAGE_MOTION_SUBSET = [*PARITY_EXAMPLES, "beetle.json", "fixtures/spider.json"]
PACKAGE_MOTION_SPECS = MOTION_SPECS if TEST_FULL else PACKAGE_MOTION_SUBSET
#: The package whose core carries another spec's motion data in ``make test`` (built for parity anyway).
CORE_HOST = "reference/hopper.json"


def motion_core(name: str, creature_out: Path, tmp_path: Path) -> Path:
    """The core/index.js the Node checks run for ``name``: its own built package where the suite builds
    that anyway (the parity subset; every spec under ``make test-full``), else CORE_HOST's core with this
    spec's motion data and body scale in ``CREATURE``. The motion modules are the same files in every
    package and data.js's motion is ``MotionData.to_json()`` (the first Node check asserts it for every real
    package), so this runs the same code on the same data without extracting a surface (the beetle's
    65,410 vertices, the spider's) that no motion check draws."""
    if TEST_FULL or name in PARITY_EXAMPLES:
        return build_example(name, creature_out) / "core" / "index.js"
    spec = load_spec(spec_file(name))
    carried = {"motion": motion_data(name).to_json(), "bodyScale": compile_rig(spec).body_scale}
    return wrapped_core(
        build_example(CORE_HOST, creature_out),
        tmp_path / f"{Path(name).stem}-core.mjs",
        f"export const CREATURE = {{ ...real.CREATURE, ...{json.dumps(carried)} }};\n",
    )


def motion_data(name: str) -> MotionData:
    spec = load_spec(spec_file(name))
    rig = compile_rig(spec)
    return build_motion(spec, rig, build_skeleton(spec, rig))


def run(data: MotionData, support: str, ticks: int = TICKS) -> Motion:
    motion = Motion(data, support=builtin_supports()[support], water=AnalyticWater(), seed=7)
    motion.step_ticks(ticks)
    return motion


def assert_gates(where: str, g: Gates, data: MotionData, ticks: int) -> None:
    """Every locomotion gate of one run (``ticks`` fixed steps); prints the worst values."""
    kind = data.type
    print(
        f"{where}: drift {g.plant_drift:.2e} ik {g.ik_residual:.2e} drawn {g.drawn_foot:.2e} "
        f"clamped {g.clamped_ticks} steps {g.steps} rope {g.rope_anchor:.2e} swim {g.swim_tracking:.4f}m "
        f"apex {g.apex_error:.2e} m squash@apex {g.apex_squash!r} both-swing {g.both_swing_ticks} "
        f"fewest planted {g.fewest_planted} of {len(data.legs)}"
    )
    assert g.plant_drift <= 1e-9, f"{where}: planted-foot drift {g.plant_drift:.3g} x leg length"
    assert g.ik_residual <= 1e-12, f"{where}: IK length residual {g.ik_residual:.3g}"
    assert g.drawn_foot <= 1e-9, f"{where}: drawn foot vs IK foot {g.drawn_foot:.3g}"
    assert g.rope_anchor <= 1e-12, f"{where}: rope anchor error {g.rope_anchor:.3g} x L"
    if kind in WALKERS:
        assert g.steps > 0, f"{where}: no foot ever stepped"
        assert g.planted_samples > 0
        assert g.clamped_ticks <= 0.01 * len(data.legs) * ticks, f"{where}: {g.clamped_ticks} clamped"
        # One phase group swings at a time: with alternating groups half the feet are always down (the
        # biped one, a trotting quadruped two, tripods three, the spider's tetrapods four).
        half = len(data.legs) // 2
        assert g.fewest_planted >= half, f"{where}: only {g.fewest_planted} feet planted on some tick"
    if kind == "biped":
        assert g.both_swing_ticks == 0, f"{where}: both feet in swing on {g.both_swing_ticks} ticks"
    if kind == "hopper":
        assert g.apex_error <= 1e-9, f"{where}: hop apex height error {g.apex_error:.3g} m"
        assert g.apex_squash == 1.0, f"{where}: squash at the apex tick is {g.apex_squash!r}"
        assert g.squash_det <= 4e-16, f"{where}: squash determinant off by {g.squash_det:.3g}"
        if data.legs:
            # Its legs take off with every hop and are planted (and drift-gated) between hops.
            assert g.steps > 0, f"{where}: the legs never left the ground"
            assert g.planted_samples > 0, f"{where}: no planted foot was measured"
    if kind == "swimmer":
        assert 0.0 < g.swim_tracking < 0.09, f"{where}: swim tracking {g.swim_tracking:.3g} m after 2 s"


@pytest.mark.parametrize("name", MOTION_SPECS)
def test_gates_on_every_support(name: str) -> None:
    """Also prints each support's worst values: `pytest tests/test_motion.py -k gates -s` shows them."""
    data = motion_data(name)
    for support in builtin_supports():
        assert_gates(f"{name} on {support}", run(data, support).gates, data, TICKS)


CORNER_TICKS = 600


@pytest.mark.parametrize("name", MOTION_SPECS)
def test_gates_hold_at_the_corners_of_the_gene_box(name: str) -> None:
    """Every individual a spawn can draw moves within the gates: each gait gene and the size gene at -1 and
    at +1 (the bounds of the box every genome lies in), on flat ground. Scaling speed alone, or step length
    alone, failed here (a foot lagging past its reach before its window opened); the pace gene scales them
    together."""
    data = motion_data(name)
    assert data.genes.jitter > 0.0
    assert data.genes.size > 0.0
    corners = corner_genomes(data)[1:]
    assert len(corners) == 2 ** (len(data.genes.fields) + 1)
    for label, genome in corners:
        motion = Motion(data, water=AnalyticWater(), genome=genome)
        fields = [f for group in data.genes.fields for f in group]
        assert any(field_value(motion.data, f) != field_value(data, f) for f in fields), (
            f"{name}: {label} changed nothing"
        )
        assert motion.size == 1.0 + data.genes.size * genome.size
        motion.step_ticks(CORNER_TICKS)
        assert_gates(f"{name} {label}", motion.gates, motion.data, CORNER_TICKS)


#: Spawn seeds checked between the corners: any genome, not only the box's corners, must keep the gates.
BETWEEN_SEEDS = range(100, 116)


@pytest.mark.parametrize("name", MOTION_SPECS)
def test_gates_hold_for_spawned_genomes_between_the_corners(name: str) -> None:
    """Whole ticks quantise swing and stance, so an individual between the corners can land where no corner
    does: a stance that filled its windows exactly made a foot miss its lift by a hair and lag past its
    reach for a whole cycle (found at size +8% on the quadruped; derived.py now keeps a tick to spare)."""
    data = motion_data(name)
    for seed in BETWEEN_SEEDS:
        motion = Motion(data, water=AnalyticWater(), seed=seed)
        motion.step_ticks(CORNER_TICKS)
        assert_gates(f"{name} seed {seed} (size {motion.size:.4f})", motion.gates, motion.data, CORNER_TICKS)


@pytest.mark.parametrize("support", ["translating", "rotating", "slope"])
def test_support_velocity_and_acceleration_describe_the_moving_frame(support: str) -> None:
    """The represented point velocity and acceleration agree with the frame's motion (central differences
    of a support-fixed point, step 1e-4 s), and the closest point lies on the support plane."""
    provider = builtin_supports()[support]
    p, t, h = [1.3, 0.2, -0.7], 2.5, 1e-4
    local = to_local(provider.frame(t), p)
    at = [to_world(provider.frame(t + k * h), local) for k in (-1, 0, 1)]
    velocity = [(at[2][i] - at[0][i]) / (2 * h) for i in range(3)]
    accel = [(at[2][i] - 2 * at[1][i] + at[0][i]) / (h * h) for i in range(3)]
    assert max(abs(a - b) for a, b in zip(velocity, provider.velocity(t, p), strict=True)) < 1e-7
    assert max(abs(a - b) for a, b in zip(accel, provider.acceleration(t, p), strict=True)) < 1e-5
    assert abs(to_local(provider.frame(t), closest_point(provider.frame(t), p))[1]) < 1e-15


def test_hop_air_time_is_physical_and_quantised() -> None:
    data = motion_data("reference/hopper.json")
    motion = Motion(data)
    d = motion.d
    assert d.air == 2 * d.half_air, "the apex is sampled exactly at a tick"
    air_s = d.air * d.dt
    # The individual's hop height (its gait gene scaled the authored one).
    ideal = 2.0 * (2.0 * motion.data.hop_height / d.g) ** 0.5
    assert abs(air_s - ideal) <= d.dt, (air_s, ideal)
    assert abs(d.apex - 0.5 * d.g * (d.half_air * d.dt) ** 2) < 1e-15


def test_gravity_is_never_scaled_by_creature_scale() -> None:
    small = motion_data("moth.json")  # scale 0.6
    assert Motion(small).d.g == pytest.approx(9.80665, abs=0.0)


@pytest.mark.parametrize(
    "name", ["reference/quadruped.json", "reference/hopper.json", "reference/swimmer.json"]
)
def test_seek_and_step_reach_the_same_state(name: str) -> None:
    data = motion_data(name)
    a = Motion(data, support=RotatingPlatform(), water=AnalyticWater(), seed=3)
    b = Motion(data, support=RotatingPlatform(), water=AnalyticWater(), seed=3)
    a.seek_tick(137)
    for _ in range(137):
        b.step()
    assert a.state_hash() == b.state_hash()
    b.step()
    assert a.state_hash() != b.state_hash()


def test_a_swimmer_without_a_required_channel_is_refused() -> None:
    data = motion_data("reference/swimmer.json")
    Motion(data, water=AnalyticWater())
    for missing in SWIMMER_CHANNELS:
        channels = tuple(c for c in AnalyticWater().channels if c != missing)
        with pytest.raises(TierRefusedError, match=missing):
            Motion(data, water=AnalyticWater(channels=channels))
    with pytest.raises(TierRefusedError, match="no WaterSurfaceProvider"):
        Motion(data)


ROPE_EXAMPLES = [n for n in CREATURE_EXAMPLES if motion_data(n).ropes]
#: Settling needs a body that holds still at speed 0; the hopper's hop cycle does not depend on speed, so
#: its rope is driven for ever (its ratio is printed, not gated).
SETTLING = [n for n in ROPE_EXAMPLES if motion_data(n).type != "hopper"]


def _rope_local(motion: Motion) -> list[list[float]]:
    return [to_local_root(motion.root, x) for rope in motion.nodes for x in rope]


@pytest.mark.parametrize("name", ROPE_EXAMPLES)
def test_ropes_settle_when_the_body_holds_still(name: str) -> None:
    """The lessons' gate: a rope released from its rest pose on a body standing still (speed 0) moves at
    4 s at less than 0.2 of its speed at 0.5 s (mean node speed relative to the body)."""
    data = replace(motion_data(name), speed=0.0)
    motion = Motion(data, water=AnalyticWater(), seed=1)
    hz, speeds = data.hz, {}
    prev = _rope_local(motion)
    for n in range(1, 4 * hz + 1):
        motion.step()
        cur = _rope_local(motion)
        if n in (hz // 2, 4 * hz):
            speeds[n / hz] = sum(math.dist(a, b) for a, b in zip(cur, prev, strict=True)) / len(cur) * hz
        prev = cur
    ratio = speeds[4.0] / speeds[0.5]
    print(f"{name}: rope speed 0.5 s {speeds[0.5]:.4f} m/s, 4 s {speeds[4.0]:.2e} m/s, ratio {ratio:.3g}")
    if name in SETTLING:
        assert ratio < 0.2, f"{name}: the rope has not settled: {ratio:.3g} of its 0.5 s speed at 4 s"


@pytest.mark.parametrize("name", ROPE_EXAMPLES)
def test_ropes_bend_without_folding_and_stay_above_the_ground(name: str) -> None:
    """The bend limit keeps consecutive segments from folding back (the hopper's tail folded 158° before
    it), and the rope nodes of creatures standing on the support stay above it by their radius."""
    data = motion_data(name)
    for support in ("flat", "slope"):
        motion = Motion(data, support=builtin_supports()[support], water=AnalyticWater(), seed=7)
        worst_cos, lowest = 1.0, math.inf
        for _ in range(TICKS):
            motion.step()
            frame = motion.support.frame(motion.tick * motion.d.dt)
            for rope, nodes in zip(data.ropes, motion.nodes, strict=True):
                dirs = [[b[k] - a[k] for k in range(3)] for a, b in itertools.pairwise(nodes)]
                for u, v in itertools.pairwise(dirs):
                    worst_cos = min(
                        worst_cos,
                        sum(x * y for x, y in zip(u, v, strict=True)) / math.hypot(*u) / math.hypot(*v),
                    )
                for r, x in zip(rope.radius[1:], nodes[1:], strict=True):
                    lowest = min(lowest, to_local(frame, x)[1] - r)
        bend = math.degrees(math.acos(worst_cos))
        print(f"{name} {support}: worst bend {bend:.1f} deg, lowest node clearance {lowest:.3g} m")
        assert bend < 90.0, f"{name} on {support}: a rope folds by {bend:.1f} deg"
        if data.rope_ground:
            assert lowest >= -1e-12 * data.body_scale, (
                f"{name} on {support}: a rope node sinks {-lowest:.3g} m"
            )


@pytest.mark.parametrize("name", MOTION_SPECS)
def test_no_slot_turns_by_a_flip_between_ticks(name: str) -> None:
    """No bone frame flips between ticks on the rotating platform: the skin follows the slots, so a frame
    that flips 180° about its own axis (as the hint-based leg frames did when a shin swung through the hint
    direction) would wring the mesh in one frame. Gated: each slot's twist about its own rest axis per
    tick < 60°, and every non-rope slot's whole turn per tick < 60°. A rope segment's swing is printed, not
    gated: its frame composes every turn up the chain, and the hopper's tail tip, held to its length and
    bend limit by the follow-the-leader pass, whips through close to 60° in the tick it lands."""
    spec = load_spec(spec_file(name))
    rig = compile_rig(spec)
    data = build_motion(spec, rig, build_skeleton(spec, rig))
    # Each slot's rest axis (a sphere has none: its whole turn is gated instead).
    ends = [[b - a for a, b in zip(row[0:3], row[4:7], strict=True)] for row in rig.slots.tolist()]
    axes = [vq.normalize(e) if vq.length(e) > 0.0 else [0.0, 0.0, 0.0] for e in ends]
    ropes = {s for rope in data.ropes for s in rope.slots}
    motion = Motion(data, support=RotatingPlatform(), water=AnalyticWater(), seed=7)
    twist = turn = swing = (0.0, 0, 0)
    prev = [list(q) for q in motion.quats]
    for _ in range(TICKS):
        motion.step()
        for s, (q0, q1) in enumerate(zip(prev, motion.quats, strict=True)):
            # The tick's turn in the slot's rest coordinates (q0's conjugate, then q1).
            local = vq.mul([-q0[0], -q0[1], -q0[2], q0[3]], q1)
            w = abs(local[3])
            along = abs(sum(local[k] * axes[s][k] for k in range(3)))
            twist = max(twist, (math.degrees(2.0 * math.atan2(along, w)), motion.tick, s))
            whole = (math.degrees(2.0 * math.acos(min(1.0, w))), motion.tick, s)
            if s in ropes:
                swing = max(swing, whole)
            else:
                turn = max(turn, whole)
        prev = [list(q) for q in motion.quats]
    print(
        f"{name}: per-tick twist {twist[0]:.1f} deg (slot {twist[2]}), "
        f"turn {turn[0]:.1f} deg (slot {turn[2]}), "
        f"rope swing {swing[0]:.1f} deg (slot {swing[2]}, tick {swing[1]})"
    )
    assert twist[0] < 60.0, f"{name}: slot {twist[2]} twists {twist[0]:.1f} deg at tick {twist[1]}"
    assert turn[0] < 60.0, f"{name}: slot {turn[2]} turns {turn[0]:.1f} deg at tick {turn[1]}"


def _walker_spider(legs: int) -> MotionData:
    """Motion data of the spider as a ``walker`` with its front ``legs`` legs (pairs front to back)."""
    document = json.loads(spec_file("fixtures/spider.json").read_text())
    kept = [p["id"] for p in document["parts"] if p["shape"] == "leg"][:legs]
    document["parts"] = [p for p in document["parts"] if p["shape"] != "leg" or p["id"] in kept]
    document["locomotion"]["type"] = "walker"
    spec = validate_bytes(json.dumps(document).encode())
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    return build_motion(spec, rig, build_skeleton(spec, rig))


@pytest.mark.parametrize("legs", [2, 4, 6, 8])
def test_walkers_with_every_even_leg_count_keep_the_gates(legs: int) -> None:
    """The generic walker on 2, 4, 6 and 8 of the spider's legs, on every support: the same gates as the
    named walkers, half its feet always planted."""
    data = _walker_spider(legs)
    assert data.type == "walker"
    assert len(data.legs) == legs
    assert data.groups == 2
    for support in builtin_supports():
        gates = run(data, support).gates
        assert_gates(f"walker on {legs} legs, {support}", gates, data, TICKS)
        assert gates.fewest_planted == legs // 2


def test_a_single_phase_group_lifts_every_foot_at_once() -> None:
    """Why the gate is there: the gait lifts one phase group at a time, so a walker whose legs all share a
    phase has every foot in the air at once (the spec does not forbid it; the gate shows it)."""
    spider = motion_data("fixtures/spider.json")
    data = replace(spider, legs=tuple(replace(leg, group=0) for leg in spider.legs), groups=1)
    assert run(data, "flat", 300).gates.fewest_planted == 0


def test_the_gates_can_fail() -> None:
    """A shin drawn 1 cm shorter than the IK solves for: the drawn foot leaves its plant, and both the
    drawn-foot and the planted-drift gates see it."""
    biped = motion_data("reference/biped.json")
    first = biped.legs[0]
    x, y, z = first.foot
    data = replace(biped, legs=(replace(first, foot=(x, y + 0.01, z)), *biped.legs[1:]))
    g = run(data, "flat", 200).gates
    assert g.drawn_foot > 1e-3
    assert g.plant_drift > 1e-3


@pytest.mark.parametrize("name", PACKAGE_MOTION_SPECS)
def test_js_core_matches_python(name: str, creature_out: Path, tmp_path: Path) -> None:
    core = motion_core(name, creature_out, tmp_path)
    data = motion_data(name)
    reference = {**motion_reference(data), "data": data.to_json()}
    path = tmp_path / "motion-reference.json"
    path.write_text(json.dumps(reference))
    env = {"MOTION_CORE": str(core), "MOTION_REFERENCE": str(path)}
    done = run_node_tests("motion_core.test.mjs", env)
    assert re.search(r"\bpass 6\b", done.stdout), done.stdout
    print(f"{name}: " + "; ".join(re.findall(r"^\S+ seed \d+: worst .*$", done.stdout, re.M)))


def test_js_core_matches_python_for_the_generic_walker_type(creature_out: Path, tmp_path: Path) -> None:
    """``"type": "walker"`` runs the same gait as the named walkers, in both languages. The spider as a
    walker compiles to the octopod's motion data but for its type (tests/test_walkers.py), so its package
    with the type relabelled (a module re-exporting the core) is what a walker spider builds; the JS core
    must still take it for a walker and match Python bit for bit."""
    spider = motion_core("fixtures/spider.json", creature_out, tmp_path)
    data = replace(motion_data("fixtures/spider.json"), type="walker")
    reference = {**motion_reference(data), "data": data.to_json()}
    path = tmp_path / "motion-reference.json"
    path.write_text(json.dumps(reference))
    relabelled = tmp_path / "walker-core.mjs"
    relabelled.write_text(
        f"import * as real from {json.dumps(spider.resolve().as_uri())};\n"
        f"export * from {json.dumps(spider.resolve().as_uri())};\n"
        "export const CREATURE = "
        "{ ...real.CREATURE, motion: { ...real.CREATURE.motion, type: 'walker' } };\n"
    )
    env = {"MOTION_CORE": str(relabelled), "MOTION_REFERENCE": str(path)}
    done = run_node_tests("motion_core.test.mjs", env)
    assert re.search(r"\bpass 6\b", done.stdout), done.stdout
    assert all(case["gates"]["steps"] > 0 for case in reference["cases"]), "the walker never stepped"
    print("walker spider: " + "; ".join(re.findall(r"^\S+ seed \d+: worst .*$", done.stdout, re.M)))


def wrapped_core(package: Path, path: Path, override: str) -> Path:
    """A module at ``path`` that re-exports the package's core (as ``real``) with ``override`` appended:
    an export of the same name there shadows the star export."""
    real = (package / "core" / "index.js").resolve().as_uri()
    path.write_text(
        f"import * as real from {json.dumps(real)};\nexport * from {json.dumps(real)};\n" + override
    )
    return path


#: Heap growth allowed over the measured steps: room for the probe's own bookkeeping (a few kB), far below
#: one boxed number per step (16 B × ALLOC_STEPS).
ALLOC_STEPS = 5000
ALLOC_SLACK_BYTES = 16384


def allocation_probe(core: Path, *v8_flags: str) -> dict[str, Any]:
    """bench/motion.mjs's allocation probe on ``core`` (a package's core/index.js), as the bench runs it:
    with ``--no-concurrent-recompilation``, so V8 optimises the step at points set by call counts and not
    when a background thread gets the CPU (the probe refuses to run without it)."""
    options = {"only": "allocation", "allocWarm": 20000, "allocSteps": ALLOC_STEPS}
    done = subprocess.run(
        [
            node(),
            "--expose-gc",
            "--no-concurrent-recompilation",
            *v8_flags,
            str(REPO / "bench" / "motion.mjs"),
            str(core),
            json.dumps(options),
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    result: dict[str, Any] = json.loads(done.stdout)
    return result


def windows(alloc: dict[str, Any]) -> str:
    return ", ".join(f"{w['heapGrowthBytes']} B / {w['collections']} GCs" for w in alloc["windows"])


@pytest.mark.parametrize("name", PACKAGE_MOTION_SPECS)
def test_steady_state_steps_do_not_allocate(name: str, creature_out: Path, tmp_path: Path) -> None:
    """V8 heap growth and garbage collections over 5000 steps of one creature after a 20000-step warm-up
    and a full collection (the cleanest of five windows: the steady state, not a late compilation)."""
    result = allocation_probe(motion_core(name, creature_out, tmp_path))
    alloc = result["allocation"]
    print(
        f"{name} ({result['type']}): {alloc['heapGrowthBytes']} bytes over {alloc['steps']} steps, "
        f"{alloc['collections']} GCs (windows: {windows(alloc)})"
    )
    assert alloc["collections"] == 0, f"{name}: collections in steady state (windows: {windows(alloc)})"
    assert alloc["heapGrowthBytes"] < ALLOC_SLACK_BYTES, (
        f"{name}: the step allocates ({alloc['bytesPerStep']:.1f} B/step; windows: {windows(alloc)})"
    )


def test_the_probe_does_not_depend_on_when_the_compiler_thread_runs(
    creature_out: Path, tmp_path: Path
) -> None:
    """A starved background compiler, simulated by delaying every concurrent compilation by a second, made
    the beetle's windows time unoptimised code (46 collections each, measured without the probe's flag);
    optimising on the main thread keeps the steady state clean whatever the machine's load."""
    core = motion_core("beetle.json", creature_out, tmp_path)
    delayed = allocation_probe(core, "--concurrent-recompilation-delay=1000")
    alloc = delayed["allocation"]
    print(f"beetle, compiler delayed 1 s: {windows(alloc)}")
    assert alloc["collections"] == 0, windows(alloc)
    assert alloc["heapGrowthBytes"] < ALLOC_SLACK_BYTES, windows(alloc)


def test_the_probe_catches_a_step_that_allocates(creature_out: Path, tmp_path: Path) -> None:
    """The quadruped's own core with one small array kept per step (dropped every 64): the probe must see
    it."""
    package = build_example("reference/quadruped.json", creature_out)
    planted = wrapped_core(
        package,
        tmp_path / "planted.mjs",
        "export function createMotion(...args) {\n"
        "  const motion = real.createMotion(...args);\n"
        "  const step = motion.step.bind(motion);\n"
        "  const kept = [];\n"
        "  motion.step = () => {\n"
        "    kept.push([kept.length]);\n"
        "    if (kept.length > 64) kept.length = 0;\n"
        "    return step();\n"
        "  };\n"
        "  return motion;\n"
        "}\n",
    )
    alloc = allocation_probe(planted)["allocation"]
    print(f"planted quadruped: {alloc['heapGrowthBytes']} B, {alloc['collections']} GCs ({windows(alloc)})")
    assert alloc["collections"] > 0 or alloc["heapGrowthBytes"] >= ALLOC_SLACK_BYTES, windows(alloc)
