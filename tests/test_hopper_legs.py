"""A hopper on two hind legs (issue 22): the spec takes 0 or 2 leg parts, and the legs plant, fold, push off,
tuck and land with the hop (motion/hop.py hop_legs; the JS core's parity and the motion gates run on
tests/fixtures/kangaroo.json through conftest.MOTION_FIXTURES)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from creaturegen.model.skeleton import build_skeleton
from creaturegen.motion import quat as vq
from creaturegen.motion.data import LegData, MotionData
from creaturegen.motion.gait import home
from creaturegen.motion.hop import hop_at
from creaturegen.motion.providers import builtin_supports, to_local, to_world
from creaturegen.motion.rig import build_motion
from creaturegen.motion.root import to_local_root, to_world_root
from creaturegen.motion.simulate import Motion
from creaturegen.rig import compile_rig
from creaturegen.spec import CharacterSpec, SpecValidationError, load_spec, validate_bytes

FIXTURES = Path(__file__).parent / "fixtures"
KANGAROO = FIXTURES / "kangaroo.json"
TICKS = 600


def _document(legs: int) -> dict[str, Any]:
    """The kangaroo with its first ``legs`` leg parts (copies of the left leg past two)."""
    document: dict[str, Any] = json.loads(KANGAROO.read_text())
    leg_parts = [p for p in document["parts"] if p["shape"] == "leg"]
    others = [p for p in document["parts"] if p["shape"] != "leg"]
    extra = [dict(leg_parts[0], id=f"leg-extra-{i}") for i in range(max(0, legs - len(leg_parts)))]
    document["parts"] = others + (leg_parts + extra)[:legs]
    return document


def _motion_data(document: dict[str, Any]) -> MotionData:
    spec = validate_bytes(json.dumps(document).encode())
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    return build_motion(spec, rig, build_skeleton(spec, rig))


@pytest.mark.parametrize("legs", [0, 2])
def test_a_hopper_takes_no_legs_or_two(legs: int) -> None:
    spec = validate_bytes(json.dumps(_document(legs)).encode())
    assert isinstance(spec, CharacterSpec)
    assert sum(p.shape == "leg" for p in spec.parts) == legs


@pytest.mark.parametrize("legs", [1, 3, 4])
def test_a_hopper_refuses_other_leg_counts_and_says_which_legs(legs: int) -> None:
    with pytest.raises(SpecValidationError) as caught:
        validate_bytes(json.dumps(_document(legs)).encode())
    assert [str(e) for e in caught.value.errors] == [
        "locomotion.type: hopper needs 0 or 2 leg parts (2: the two hind legs it hops on, as a kangaroo's "
        f"or a frog's), the spec has {legs}"
    ]


def test_the_kangaroo_is_a_hopper_on_two_hind_legs_under_the_rear_of_its_body() -> None:
    spec = load_spec(KANGAROO)
    assert isinstance(spec, CharacterSpec)
    assert spec.locomotion is not None
    assert spec.locomotion.type == "hopper"
    parts = {p.id: p for p in spec.parts}
    assert {p.shape for p in spec.parts} >= {"capsule", "sphere", "rope", "leg"}
    legs = [p for p in spec.parts if p.shape == "leg"]
    assert len(legs) == 2
    body = parts["body"]
    assert body.a is not None
    assert body.b is not None
    for leg in legs:
        assert leg.parent == "body"
        assert leg.hip is not None
        assert leg.hip[2] < 0.5 * (body.b[2] - body.a[2]), "hips under the rear half of the body"
    assert any(p.shape == "rope" and p.parent == "body" for p in spec.parts), "a tail"


def _drawn(motion: Motion, leg: LegData) -> tuple[list[float], list[float], list[float]]:
    """Hip, knee and foot of ``leg`` as its slot transforms draw them (creature frame)."""

    def moved(slot: int, x: vq.Point) -> list[float]:
        r = vq.rotate(motion.quats[slot], x)
        return [r[k] + motion.trans[slot][k] for k in range(3)]

    return moved(leg.upper, leg.hip), moved(leg.upper, leg.knee), moved(leg.lower, leg.foot)


def _knee_deg(hip: list[float], knee: list[float], foot: list[float]) -> float:
    u = [hip[k] - knee[k] for k in range(3)]
    v = [foot[k] - knee[k] for k in range(3)]
    c = sum(u[k] * v[k] for k in range(3)) / (vq.length(u) * vq.length(v))
    return math.degrees(math.acos(min(1.0, max(-1.0, c))))


def _phase(motion: Motion, n: int) -> str:
    d = motion.d
    m = n % d.hop_cycle
    for name, length in (("idle", d.hop_idle), ("crouch", d.crouch), ("air", d.air)):
        if m < length:
            return name
        m -= length
    return "land"


@pytest.mark.parametrize("support", list(builtin_supports()))
def test_the_kangaroos_feet_stay_planted_on_the_ground_and_leave_it_in_the_air(support: str) -> None:
    """Idle, crouch and landing: both feet planted, the drawn foot on its plant point in the support frame
    (drift ≤ 1e-12 leg lengths, never clamped by the IK). In the air: both feet lifted, on the take-off
    plant at the first air tick and above the support after it. The knees fold in the crouch and the
    landing (the body sinks on them), stretch at the push-off and fold further in the tuck."""
    data = _motion_data(json.loads(KANGAROO.read_text()))
    motion = Motion(data, support=builtin_supports()[support], seed=7)
    d = motion.d
    assert d.dip > 0.0
    drift, lowest_air, planted_air = 0.0, math.inf, 0
    knees: dict[str, list[float]] = {}
    for n in range(1, TICKS + 1):
        motion.step()
        phase = _phase(motion, n)
        frame = motion.support.frame(n * d.dt)
        # The individual's legs (seed 7's size gene scales the authored ones).
        for leg, foot in zip(motion.data.legs, motion.feet, strict=True):
            hip, knee, drawn = _drawn(motion, leg)
            span = leg.a + leg.b
            at = to_local(frame, to_world_root(motion.root, drawn))
            knees.setdefault(phase, []).append(_knee_deg(hip, knee, drawn))
            if phase != "air":
                assert foot.planted, f"{support} tick {n} ({phase}): foot of {leg.part} lifted"
                target = to_local_root(motion.root, to_world(frame, foot.p))
                reach = vq.distance(target, leg.hip)
                assert leg.reach_min < reach < leg.reach_max, f"{support} tick {n}: IK clamped"
                drift = max(drift, vq.distance(at, foot.p) / span)
            else:
                assert not foot.planted, f"{support} tick {n}: foot of {leg.part} planted in the air"
                if n == foot.n0:
                    assert vq.distance(at, foot.s) / span <= 1e-12
                    planted_air += 1
                else:
                    lowest_air = min(lowest_air, at[1])
    ranges = {p: (min(a), max(a)) for p, a in knees.items()}
    idle = ranges["idle"]
    print(
        f"kangaroo on {support}: planted drift {drift:.2e} leg lengths, lowest airborne foot "
        f"{lowest_air:.4f} m, knee angle (deg) "
        + ", ".join(f"{p} {lo:.1f}..{hi:.1f}" for p, (lo, hi) in ranges.items())
    )
    assert drift <= 1e-12, f"{support}: a planted foot drifts {drift:.3g} leg lengths"
    assert planted_air > 0, "no take-off was seen"
    assert lowest_air > 0.0, f"{support}: an airborne foot touches the support ({lowest_air:.3g} m)"
    # They really fold: the crouch and the landing bend the knee by more than 10° below its idle angle, the
    # tuck folds it further, and the push-off stretches it past its idle angle.
    for phase in ("crouch", "land"):
        assert ranges[phase][0] < idle[0] - 10.0, f"{support}: the knees do not fold in the {phase}"
    assert ranges["air"][0] < min(ranges["crouch"][0], ranges["land"][0]), f"{support}: no tuck"
    assert ranges["air"][1] > idle[1] + 10.0, f"{support}: the legs do not stretch at the push-off"


@pytest.mark.parametrize("support", ["flat", "rotating"])
def test_the_landing_plant_is_where_the_hop_lands(support: str) -> None:
    """The landing plant a foot reaches for (known at take-off in closed form) is where it is planted at the
    landing tick, and it is exactly the rest foot under the landed body; it lies about a hop ahead of the
    take-off plant (the path is a circle, so a foot beside the path travels a little more or less)."""
    data = _motion_data(json.loads(KANGAROO.read_text()))
    motion = Motion(data, support=builtin_supports()[support], seed=7)
    d, hops = motion.d, 0
    while hops < 4:
        motion.step()
        if not motion.feet[0].planted and motion.tick == motion.feet[0].n0:
            aimed = [list(f.t) for f in motion.feet]
            start = [list(f.s) for f in motion.feet]
            motion.step_ticks(d.air)
            assert _phase(motion, motion.tick) == "land"
            frame = motion.support.frame(motion.tick * d.dt)
            for leg, foot, where, was in zip(motion.data.legs, motion.feet, aimed, start, strict=True):
                assert foot.planted
                assert foot.p == where
                assert foot.p == home(leg, frame, motion.root)
                assert 0.9 < math.dist(was, where) / motion.data.hop_length < 1.1
            hops += 1


def test_a_hopper_without_legs_does_not_sink() -> None:
    """The dip is the legs' (0 without them): the legless hopper's root keeps its closed form."""
    spec = load_spec(Path(__file__).parents[1] / "examples" / "reference" / "hopper.json")
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    motion = Motion(build_motion(spec, rig, build_skeleton(spec, rig)))
    assert motion.d.dip == 0.0
    for n in range(motion.d.hop_cycle):
        _, lift, _ = hop_at(motion.data, motion.d, n)
        if _phase(motion, n) != "air":
            assert lift == 0.0
            assert math.copysign(1.0, lift) == 1.0
