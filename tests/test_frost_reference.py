"""The frost history's Python side: closed-form law, brush, timeline, tile scheduler, numpy reference and the
quantisation gate that picks the history storage format."""

from __future__ import annotations

import dataclasses
import itertools
import math
from functools import cache

import numpy as np
import pytest

from conftest import EXAMPLES
from creaturegen.frost import formats, law, path
from creaturegen.frost.brush import Segment, capsule_distance, coverage, pcg_hash, texel_noise
from creaturegen.frost.formats import (
    HALF_FLOAT_TOLERANCE,
    FormatGate,
    FormatRefusedError,
    choose_format,
    measure_format,
)
from creaturegen.frost.params import DIFFUSION_STABILITY, FrostParams, frost_params
from creaturegen.frost.reference import STATE_CHANNELS, FrostReference, remap_bilinear
from creaturegen.frost.schedule import TileScheduler, bin_steps, diffusion_substeps, texel_box
from creaturegen.frost.timeline import (
    Step,
    advance_instants,
    chunk_steps,
    classify_interval,
    late_steps,
    split_interval,
    validate_segment,
)
from creaturegen.spec import FrostEffectSpec, load_spec

FROST_EXAMPLES = ("frost-full", "frost-balanced", "frost-budgeted")
#: Small on purpose: every property tested here is per texel, not per grid size.
GRID = (48, 32)


@cache
def params_of(example: str) -> FrostParams:
    spec = load_spec(EXAMPLES / "frost" / f"{example}.json")
    assert isinstance(spec, FrostEffectSpec)
    return frost_params(spec)


def replay_states(params: FrostParams, fps: int, storage: str = "float64") -> tuple[FrostReference, dict]:
    """Replay the conformance path; also snapshot the state channels at the instants k/30 s."""
    reference = FrostReference(params, *GRID, storage)  # type: ignore[arg-type]
    for segment in path.conformance_segments():
        reference.queue(segment)
    snapshots = {}
    for k, (previous, current) in enumerate(itertools.pairwise(path.frame_instants(fps)), start=1):
        reference.update(previous, current)
        if (k * 30) % fps == 0:
            snapshots[k * 30 // fps] = reference.state[..., STATE_CHANNELS].copy()
    return reference, snapshots


# --------------------------------------------------------------------------------------------------- law


def test_law_two_half_steps_equal_one_step() -> None:
    rng = np.random.default_rng(1)
    x = rng.uniform(0.0, 1.0, 500)
    b = rng.uniform(0.0, 1.0, 500)
    for decay, fill, dt in zip(
        rng.uniform(0, 3, 20), rng.uniform(0, 8, 20), rng.uniform(0, 0.2, 20), strict=True
    ):
        once = law.advance(x, b, dt, decay, fill)
        twice = law.advance(law.advance(x, b, dt / 2, decay, fill), b, dt / 2, decay, fill)
        np.testing.assert_allclose(twice, once, rtol=0, atol=1e-15)
        assert np.any(once != x)


def test_law_reaches_equilibrium() -> None:
    x = np.linspace(0.0, 1.0, 11)
    decay, fill, b = 0.7, 3.0, 0.4
    expected = fill * b / (decay + fill * b)
    np.testing.assert_allclose(law.advance(x, b, 200.0, decay, fill), expected, rtol=0, atol=1e-14)


def test_law_zero_rate_keeps_state_exactly() -> None:
    x = np.random.default_rng(2).uniform(0.0, 1.0, 100)
    out = law.advance(x, 0.0, 5.0, 0.0, 4.0)
    np.testing.assert_array_equal(out, x)
    assert not np.any(np.isnan(out))


def test_law_no_decay_with_coverage_tends_to_one() -> None:
    x = np.array([0.0, 0.3, 0.9])
    np.testing.assert_allclose(law.advance(x, 0.5, 100.0, 0.0, 2.0), 1.0, rtol=0, atol=1e-12)
    # and it moves towards 1 monotonically
    short = law.advance(x, 0.5, 0.1, 0.0, 2.0)
    assert np.all(short > x)
    assert np.all(short < 1.0)


def test_law_pure_decay() -> None:
    rng = np.random.default_rng(3)
    x = rng.uniform(0.0, 1.0, 100)
    for decay, dt in ((0.16, 0.033), (1.05, 0.5), (3.0, 2.0)):
        np.testing.assert_allclose(law.advance(x, 0.0, dt, decay, 5.3), x * math.exp(-decay * dt), rtol=1e-15)


# ------------------------------------------------------------------------------------------------- brush


def pcg_reference(value: int) -> int:
    """PCG-RXS-M-XS in plain Python integers, masked to 32 bits after every wrapping operation."""
    state = (value * 747796405 + 2891336453) & 0xFFFFFFFF
    word = (((state >> ((state >> 28) + 4)) ^ state) * 277803737) & 0xFFFFFFFF
    return ((word >> 22) ^ word) & 0xFFFFFFFF


def test_pcg_hash_matches_integer_reference() -> None:
    rng = np.random.default_rng(4)
    values = [0, 1, 2, 0xFFFFFFFF, 0x80000000, 0x68E31DA4, *rng.integers(0, 2**32, 300).tolist()]
    hashed = pcg_hash(np.array(values, dtype=np.uint32))
    assert hashed.dtype == np.uint32
    assert hashed.tolist() == [pcg_reference(v) for v in values]
    assert len(set(hashed.tolist())) == len(set(values))


def test_texel_noise_range_and_float32_exact() -> None:
    for channel in (0, 1):
        noise = texel_noise(40, 24, seed=11, channel=channel)
        assert noise.shape == (24, 40)
        assert noise.min() >= 0.0
        assert noise.max() < 1.0
        scaled = noise * 2.0**24
        np.testing.assert_array_equal(scaled, np.floor(scaled))
        np.testing.assert_array_equal(noise.astype(np.float32).astype(np.float64), noise)
        assert noise.std() > 0.2  # roughly uniform, not constant
    assert not np.array_equal(texel_noise(40, 24, 11, 0), texel_noise(40, 24, 11, 1))
    assert not np.array_equal(texel_noise(40, 24, 11, 0), texel_noise(40, 24, 12, 0))


def test_texel_noise_matches_integer_reference() -> None:
    seed, salt = 11, 0x68E31DA4
    noise = texel_noise(6, 5, seed, 0)
    salted = pcg_reference(seed ^ salt)
    for j in range(5):
        for i in range(6):
            col = pcg_reference((i + salted) & 0xFFFFFFFF)
            assert noise[j, i] == (pcg_reference((j + col) & 0xFFFFFFFF) >> 8) / 2**24


def test_capsule_distance_is_aspect_corrected() -> None:
    width, height = 64, 32
    i0, j0 = 30, 15
    centre = ((i0 + 0.5) / width, (j0 + 0.5) / height)
    distance = capsule_distance(Segment(0.0, 1.0, centre, centre), width, height)
    assert distance[j0, i0] == pytest.approx(0.0, abs=1e-15)
    for k in range(1, 10):
        horizontal, vertical = distance[j0, i0 + k], distance[j0 + k, i0]
        assert horizontal == pytest.approx(vertical, abs=1e-14), k
        assert vertical == pytest.approx(k / height, abs=1e-14)
        assert distance[j0 - k, i0 - k] == pytest.approx(math.hypot(k, k) / height, abs=1e-14)


def test_capsule_distance_of_a_swept_segment() -> None:
    width, height = 60, 30
    start, end = (0.25, 0.5), (0.75, 0.5)
    distance = capsule_distance(Segment(0.0, 1.0, start, end), width, height)
    row = int(0.5 * height)  # texel centre v = 15.5/30, just below the segment
    offset = (row + 0.5) / height - 0.5
    inside = [i for i in range(width) if 0.25 <= (i + 0.5) / width <= 0.75]
    np.testing.assert_allclose(distance[row, inside], abs(offset), atol=1e-14)
    # beyond the end cap the distance grows like a disc around the end point
    i = width - 1
    expected = math.hypot(((i + 0.5) / width - 0.75) * width / height, offset)
    assert distance[row, i] == pytest.approx(expected, abs=1e-14)


def test_coverage_radius_centre_and_average_pressure() -> None:
    width, height, radius, softness = 64, 32, 0.2, 0.5
    thinning = 0.3 * texel_noise(width, height, 5, 0)
    i0, j0 = 20, 16
    centre = ((i0 + 0.5) / width, (j0 + 0.5) / height)
    point = Segment(0.0, 1.0, centre, centre, pressure0=0.2, pressure1=0.8)
    cov = coverage(point, width, height, radius, softness, thinning)
    distance = capsule_distance(point, width, height)
    assert np.all(cov[distance >= radius] == 0.0)
    assert np.count_nonzero(distance >= radius) > 0
    assert cov[j0, i0] == pytest.approx(0.5 * (1.0 - thinning[j0, i0]), abs=1e-15)
    inner = distance <= radius * (1.0 - softness)
    np.testing.assert_allclose(cov[inner], 0.5 * (1.0 - thinning[inner]), atol=1e-15)
    assert np.all(cov >= 0.0)
    assert np.all(cov <= 1.0)
    # the average of the two pressures holds over the whole capsule, at both ends alike
    end = ((i0 + 10.5) / width, (j0 + 0.5) / height)
    swept = coverage(Segment(0.0, 1.0, centre, end, 0.0, 1.0), width, height, radius, softness, thinning)
    assert swept[j0, i0] == pytest.approx(0.5 * (1.0 - thinning[j0, i0]), abs=1e-15)
    assert swept[j0, i0 + 10] == pytest.approx(0.5 * (1.0 - thinning[j0, i0 + 10]), abs=1e-15)


# ---------------------------------------------------------------------------------------------- timeline


@pytest.mark.parametrize(
    ("previous", "current", "expected"),
    [
        (1.0, 1.0, "none"),
        (0.0, 0.0, "none"),
        (1.0, 0.5, "discontinuity"),
        (math.nan, 1.0, "discontinuity"),
        (0.0, math.nan, "discontinuity"),
        (0.0, math.inf, "discontinuity"),
        (-math.inf, 0.0, "discontinuity"),
        (0.0, 1.5, "catch-up"),
        (0.0, 4.0, "catch-up"),
        (0.0, 4.5, "discontinuity"),
        (0.0, 1.0, "advance"),
        (2.0, 2.0 + 1 / 60, "advance"),
    ],
)
def test_classify_interval(previous: float, current: float, expected: str) -> None:
    assert classify_interval(previous, current, 1.0, 4.0) == expected
    off = "discontinuity" if expected == "catch-up" else expected  # catchUp <= maxInterval: catch-up is off
    assert classify_interval(previous, current, 1.0, 1.0) == off


@pytest.mark.parametrize(("previous", "current"), [(0.1, 2.6), (1 / 3, 1 / 3 + 1.0000001), (7.25, 11.0)])
def test_advance_instants_cut_a_stall_into_equal_advances(previous: float, current: float) -> None:
    ends = advance_instants(previous, current, 1.0)
    assert len(ends) == math.ceil(current - previous)
    assert ends[-1] == current
    pieces = np.diff([previous, *ends])
    assert np.all(pieces > 0)
    assert np.all(pieces <= 1.0 + 1e-15)
    np.testing.assert_allclose(pieces, (current - previous) / len(ends), rtol=1e-12)


def test_a_stalled_frame_deposits_the_whole_stroke_as_ordinary_frames_would() -> None:
    """A frame stalled 2.5 s during the stroke, its segments arriving late (as attachPointer queues them):
    caught up as 3 advances, it is bit for bit the run whose frames were at the advances' ends, and the
    whole stroke deposits. Switched off (catchUp = maxInterval) the same stall drops the queued input."""

    def run(params: FrostParams, instants: list[float]) -> FrostReference:
        reference = FrostReference(params, *GRID)
        pending = path.conformance_segments()
        for previous, current in itertools.pairwise(instants):
            arrived = [g for g in pending if g.t1 <= current]
            pending = pending[len(arrived) :]
            for segment in arrived:
                reference.queue(segment)
            reference.update(previous, current)
        return reference

    params = params_of("frost-full")
    assert (params.max_interval, params.catch_up) == (1.0, 4.0)  # the defaults
    head = [k / 60 for k in range(7)]
    stalled = run(params, [*head, 0.1 + 2.5, 2.7])
    frame = stalled.counters.history[6]
    assert (frame.decision, frame.advances) == ("catch-up", 3)
    assert stalled.counters.catch_ups == 1
    assert stalled.counters.discontinuities == 0
    assert stalled.counters.frames == 8
    assert stalled.counters.pointer_seconds == pytest.approx(path.STROKE_SECONDS, abs=1e-12)
    frames = run(params, [*head, *advance_instants(0.1, 2.6, 1.0), 2.7])
    np.testing.assert_array_equal(stalled.state, frames.state)
    assert stalled.counters.pointer_seconds == frames.counters.pointer_seconds

    off = run(dataclasses.replace(params, catch_up=params.max_interval), [*head, 0.1 + 2.5, 2.7])
    assert off.counters.history[6].decision == "discontinuity"
    assert off.counters.pointer_seconds < 0.1 * path.STROKE_SECONDS


def test_split_interval_cuts_at_segment_boundaries() -> None:
    a = Segment(0.1, 0.2, (0.1, 0.1), (0.2, 0.1))
    b = Segment(0.25, 0.3, (0.2, 0.1), (0.3, 0.1))
    c = Segment(0.3, 0.5, (0.3, 0.1), (0.4, 0.1))
    steps = split_interval(0.15, 0.4, [a, b, c])
    assert [s.segments for s in steps] == [(a,), (), (b,), (c,)]
    assert [s.dt for s in steps] == pytest.approx([0.05, 0.05, 0.05, 0.1], abs=1e-15)
    assert math.fsum(s.dt for s in steps) == pytest.approx(0.4 - 0.15, abs=1e-15)
    # an interval inside one segment is a single step of that segment
    inner = split_interval(0.35, 0.45, [a, b, c])
    assert len(inner) == 1
    assert inner[0].segments == (c,)
    assert inner[0].dt == pytest.approx(0.1, abs=1e-15)
    # no segments at all: pure decay
    assert split_interval(0.0, 0.5, []) == [Step(0.5)]


def test_split_interval_conformance_path_sums_exactly() -> None:
    segments = path.conformance_segments()
    for fps in path.FRAME_RATES:
        for previous, current in itertools.pairwise(path.frame_instants(fps)):
            steps = split_interval(previous, current, segments)
            assert all(s.dt > 0 for s in steps)
            assert math.fsum(s.dt for s in steps) == pytest.approx(current - previous, abs=1e-15)
            start = previous
            for step in steps:
                end = start + step.dt
                middle = 0.5 * (start + end)
                covering = [g for g in segments if g.t0 <= middle < g.t1]
                if step.dt < 1e-12:
                    pass  # a sliver between a frame instant and a boundary one ulp away: either side is right
                elif not step.segments:
                    assert not covering, (fps, start)
                else:
                    assert covering == list(step.segments), (fps, start)
                    assert step.segments[0].t0 <= start + 1e-12
                    assert end <= step.segments[0].t1 + 1e-12
                start = end


def test_chunk_steps_sizes() -> None:
    steps = [Step(0.01)] * 35
    assert [len(c) for c in chunk_steps(steps, 16, 256)] == [16, 16, 3]
    assert [len(c) for c in chunk_steps(steps[:16], 16, 256)] == [16]
    assert chunk_steps([], 16, 256) == []
    assert [s for chunk in chunk_steps(steps, 7, 256) for s in chunk] == steps


def test_chunk_steps_end_before_too_many_pairs() -> None:
    """Several strokes at once put several segments in a step: a chunk also ends at ``max_pairs``."""
    g = Segment(0.0, 1.0, (0.1, 0.1), (0.2, 0.1))
    steps = [Step(0.01, (g,) * 5)] * 7
    assert [len(c) for c in chunk_steps(steps, 16, 12)] == [2, 2, 2, 1]
    assert [len(c) for c in chunk_steps(steps, 16, 5)] == [1] * 7
    assert [s for chunk in chunk_steps(steps, 16, 12) for s in chunk] == steps


def test_split_interval_keeps_every_stream_active() -> None:
    """Two pointers at once: each piece holds every segment active throughout it."""
    a = Segment(0.0, 0.3, (0.1, 0.1), (0.2, 0.1), stream=1)
    b = Segment(0.1, 0.4, (0.5, 0.5), (0.6, 0.5), stream=2)
    steps = split_interval(0.0, 0.5, [a, b])
    assert [s.segments for s in steps] == [(a,), (a, b), (b,), ()]
    assert sum(s.pointer_seconds for s in steps) == pytest.approx(0.6)


def test_validate_segment() -> None:
    good = Segment(0.0, 0.1, (0.1, 0.1), (0.2, 0.2), 0.5, 1.0)
    assert validate_segment(good, None) is None
    assert validate_segment(good, 0.0) is None
    assert "before the previous" in str(validate_segment(good, 0.05))
    assert "before it starts" in str(validate_segment(Segment(0.2, 0.1, (0, 0), (0, 0)), None))
    assert "finite" in str(validate_segment(Segment(0.0, math.nan, (0, 0), (0, 0)), None))
    assert "finite" in str(validate_segment(Segment(0.0, 0.1, (math.inf, 0), (0, 0)), None))
    assert "pressures" in str(validate_segment(Segment(0.0, 0.1, (0, 0), (0, 0), 1.5, 1.0), None))
    assert "pressures" in str(validate_segment(Segment(0.0, 0.1, (0, 0), (0, 0), 1.0, -0.1), None))


# ---------------------------------------------------------------------------------------------- schedule


def test_full_field_idles_after_convergence() -> None:
    params = params_of("frost-full")
    assert params.policy == "full-field"
    assert params.idle_when_converged
    scheduler = TileScheduler(params, 48, 32)
    stroke = Segment(0.0, 0.1, (0.3, 0.5), (0.6, 0.5))
    first = scheduler.plan([Step(0.1, (stroke,))], 0.1, 0)
    assert first.update == (0,)
    assert first.retire == ()
    updates, retires = [], []
    for _ in range(200):
        plan = scheduler.plan([Step(1.0)], 1.0, 0)
        updates.append(plan.update)
        retires.append(plan.retire)
    retired_at = [k for k, r in enumerate(retires) if r]
    assert len(retired_at) == 1
    k = retired_at[0]
    assert retires[k] == (0,)
    # the slower channel needs ln(1/tol)/λ seconds to fall under the tolerance
    slowest = min(c.decay for c in params.channels)
    assert k + 1 == math.ceil(math.log(1.0 / params.tolerance) / slowest - 1e-9)
    assert all(u == (0,) for u in updates[:k])
    assert all(u == () for u in updates[k:])
    # a brush wakes it again
    assert scheduler.plan([Step(0.1, (stroke,))], 0.1, 0).update == (0,)


def test_full_field_reference_idles_with_zero_dispatches() -> None:
    params = dataclasses.replace(params_of("frost-full"), diffusivity=0.0)
    reference = FrostReference(params, 16, 8)
    reference.queue(Segment(0.0, 0.1, (0.2, 4.5 / 8), (0.8, 4.5 / 8)))  # along a row of texel centres
    reference.update(0.0, 0.1)
    assert reference.state[..., 0].max() > 0.1
    instants = [0.1 + 0.5 * k for k in range(220)]
    reports = [reference.update(a, b) for a, b in itertools.pairwise(instants)]
    assert reference.counters.discontinuities == 0
    retired = [k for k, r in enumerate(reports) if r.retired_tiles]
    assert len(retired) == 1
    after = reports[retired[0] + 1 :]
    assert after
    assert all(r.update_tiles == 0 and r.dispatches == 0 and r.texels == 0 for r in after)
    assert not np.any(reference.state)


def test_full_field_without_idle_updates_every_frame() -> None:
    params = dataclasses.replace(params_of("frost-full"), idle_when_converged=False)
    scheduler = TileScheduler(params, 48, 32)
    for _ in range(150):
        plan = scheduler.plan([Step(1.0)], 1.0, 0)
        assert plan.update == (0,)
        assert plan.retire == ()


def test_dirty_tiles_update_only_near_the_stroke() -> None:
    params = params_of("frost-balanced")
    assert params.policy == "dirty-tiles"
    width, height = 128, 64
    scheduler = TileScheduler(params, width, height)
    assert (scheduler.tiles_x, scheduler.tiles_y) == (8, 4)
    stroke = Segment(0.0, 0.05, (0.1, 0.2), (0.15, 0.2))
    plan = scheduler.plan([Step(0.05, (stroke,))], 0.05, 0)
    assert plan.update
    assert len(plan.update) < 8 * 4 // 2
    mask = plan.mask(plan.update, width, height)
    thinning = np.zeros((height, width))
    for channel in params.channels:
        reached = coverage(stroke, width, height, channel.radius, params.softness, thinning) > 0
        assert np.all(mask[reached]), "a tile the brush reaches was not updated"
    # every updated tile lies within the brush reach (plus one texel) of the stroke
    distance = capsule_distance(stroke, width, height)
    for tile in plan.update:
        tile_mask = plan.mask((tile,), width, height)
        assert distance[tile_mask].min() <= params.brush_reach + 1.5 / height, tile
    assert len(plan.update) == len(set(plan.update))


def test_dirty_tiles_retire_once_per_tile() -> None:
    params = params_of("frost-balanced")
    scheduler = TileScheduler(params, 128, 64)
    segments = [
        Segment(0.05 * k, 0.05 * (k + 1), (0.1 + 0.1 * k, 0.3), (0.2 + 0.1 * k, 0.5)) for k in range(6)
    ]
    touched: set[int] = set()
    for segment in segments:
        touched.update(scheduler.plan([Step(0.05, (segment,))], 0.05, 0).update)
    retired: list[int] = []
    for _ in range(40):
        plan = scheduler.plan([Step(1.0)], 1.0, 0)
        assert not set(plan.retire) & set(plan.update)
        retired.extend(plan.retire)
    assert sorted(retired) == sorted(touched)
    assert len(retired) == len(set(retired))
    assert not scheduler.live.any()


@pytest.mark.parametrize("example", ["frost-balanced", "frost-full"])
def test_tile_bounds_never_underestimate(example: str) -> None:
    """Dirty tiles vs an every-texel-every-frame run: no content ever lives outside the live tiles."""
    params = dataclasses.replace(params_of(example), policy="dirty-tiles", tile_size=8)
    exhaustive = dataclasses.replace(params, policy="full-field", idle_when_converged=False)
    width, height = 48, 32
    dirty = FrostReference(params, width, height)
    full = FrostReference(exhaustive, width, height)
    for segment in path.conformance_segments():
        dirty.queue(segment)
        full.queue(segment)
    geometry = dirty.scheduler
    assert (geometry.tile_width, geometry.tile_height, geometry.tiles_x, geometry.tiles_y) == (8, 8, 6, 4)
    instants = path.frame_instants(60, duration=1.5)
    live_counts = []
    for previous, current in itertools.pairwise(instants):
        dirty_report = dirty.update(previous, current)
        full.update(previous, current)
        scheduler = dirty.scheduler
        live = scheduler.live
        live_counts.append(dirty_report.update_tiles)
        mask = np.kron(live, np.ones((8, 8), dtype=bool))
        assert not np.any(dirty.state[~mask]), current
        truth = full.state[..., STATE_CHANNELS]
        for ty, tx in itertools.product(range(4), range(6)):
            block = truth[ty * 8 : ty * 8 + 8, tx * 8 : tx * 8 + 8]
            for index in range(2):
                assert block[..., index].max() <= scheduler.bounds[index, ty, tx] + 1e-12, (current, ty, tx)
            if not live[ty, tx]:
                assert block.max() <= params.tolerance
        np.testing.assert_allclose(dirty.state[..., STATE_CHANNELS], truth, rtol=0, atol=params.tolerance)
    assert max(live_counts) > 0
    if params.diffusivity == 0.0:
        # without diffusion nothing spreads: the tiles far from the stroke are never dispatched
        assert max(live_counts) < 24


def test_diffusion_substeps_stable_and_minimal() -> None:
    assert diffusion_substeps(0.0, 1.0, 1080) == 0
    assert diffusion_substeps(1e-5, 0.0, 1080) == 0
    rng = np.random.default_rng(6)
    cases = [(2e-5, 1 / 30, 1080), (2e-5, 1.0, 1080), (1e-3, 1 / 60, 540), (0.25, 1.0, 1)]
    random = (10 ** rng.uniform(-7, -2, 200), rng.uniform(0.001, 1.0, 200), rng.integers(8, 2160, 200))
    cases += list(zip(*random, strict=True))
    for diffusivity, dt, height in cases:
        n = diffusion_substeps(float(diffusivity), float(dt), int(height))
        number = diffusivity * dt * height * height
        assert n >= 1
        assert number / n <= DIFFUSION_STABILITY, (diffusivity, dt, height, n)
        assert diffusivity * (dt / n) * height * height <= DIFFUSION_STABILITY * (1 + 1e-15)
        if n > 1:
            assert number / (n - 1) > DIFFUSION_STABILITY, (diffusivity, dt, height, n)


# --------------------------------------------------------------------------------------------- reference


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_frame_rate_independence_without_diffusion(example: str) -> None:
    params = dataclasses.replace(params_of(example), diffusivity=0.0)
    runs = {fps: replay_states(params, fps) for fps in path.FRAME_RATES}
    final30, snaps30 = runs[30]
    assert final30.state[..., 0].max() > 0.05  # the stroke left a mark
    assert final30.counters.discontinuities == 0
    for fps in (60, 120):
        final, snaps = runs[fps]
        worst = float(np.abs(final.state - final30.state).max())
        assert worst <= 1e-12, f"{example} {fps} FPS final state differs from 30 FPS by {worst:.3g}"
        assert snaps.keys() == snaps30.keys()
        for k, snap in snaps30.items():
            diff = float(np.abs(snaps[k] - snap).max())
            assert diff <= 1e-12, f"{example} {fps} FPS at {k}/30 s differs by {diff:.3g}"


def test_diffusion_operator_splitting_is_small() -> None:
    params = params_of("frost-full")
    assert params.diffusivity > 0
    slow = replay_states(params, 30)[0].state
    fast = replay_states(params, 120)[0].state
    difference = float(np.abs(slow - fast).max())
    assert 0.0 < difference < 1e-3, f"30 vs 120 FPS with diffusion differ by {difference:.3g}"


def test_float16_storage_is_representable() -> None:
    reference, _ = replay_states(params_of("frost-balanced"), 60, "float16")
    state = reference.state
    assert state.max() > 0.05
    np.testing.assert_array_equal(state.astype(np.float16).astype(np.float64), state)
    exact, _ = replay_states(params_of("frost-balanced"), 60, "float64")
    assert not np.array_equal(exact.state, state)
    assert np.abs(exact.state - state).max() < 0.01


def stroked_reference(discontinuity: str) -> FrostReference:
    params = dataclasses.replace(
        params_of("frost-full"),
        discontinuity=discontinuity,  # type: ignore[arg-type]
        diffusivity=0.0,
    )
    reference = FrostReference(params, *GRID)
    reference.queue(Segment(0.0, 0.2, (0.2, 0.5), (0.8, 0.5)))
    reference.queue(Segment(0.3, 0.4, (0.2, 0.2), (0.8, 0.2)))
    reference.update(0.0, 0.2)
    assert reference.state[..., 0].max() > 0.1
    return reference


@pytest.mark.parametrize("bad", [0.1, math.nan, math.inf, 5.0])
def test_discontinuity_reset_clears(bad: float) -> None:
    reference = stroked_reference("reset")
    report = reference.update(0.2, bad)
    assert report.decision == "discontinuity"
    assert not np.any(reference.state)
    assert reference.counters.discontinuities == 1
    assert reference.counters.frames == 2
    assert reference.pending == []
    assert not reference.scheduler.live.any()


def test_discontinuity_freeze_keeps_state() -> None:
    reference = stroked_reference("freeze")
    before = reference.state.copy()
    report = reference.update(0.2, math.nan)
    assert report.decision == "discontinuity"
    np.testing.assert_array_equal(reference.state, before)
    assert reference.counters.discontinuities == 1
    assert reference.pending == []  # the queued stroke belonged to the dropped interval
    # after the freeze, pure decay continues from the kept state
    reference.update(10.0, 10.5)
    np.testing.assert_allclose(
        reference.state[..., 0], before[..., 0] * math.exp(-reference.params.visible.decay * 0.5), rtol=1e-12
    )


def test_equal_instants_change_nothing() -> None:
    reference = stroked_reference("reset")
    before = reference.state.copy()
    counters = dataclasses.replace(reference.counters, history=list(reference.counters.history))
    pending = list(reference.pending)
    report = reference.update(0.2, 0.2)
    assert report.decision == "none"
    assert report.dispatches == 0
    np.testing.assert_array_equal(reference.state, before)
    assert reference.counters == counters
    assert reference.pending == pending


def test_resize_clear_zeros() -> None:
    params = dataclasses.replace(params_of("frost-full"), resize_policy="clear")
    reference = FrostReference(params, *GRID)
    reference.queue(Segment(0.0, 0.2, (0.2, 0.5), (0.8, 0.5)))
    reference.update(0.0, 0.2)
    assert reference.state.max() > 0.1
    reference.resize(40, 20)
    assert reference.state.shape == (20, 40, 4)
    assert not np.any(reference.state)
    assert not reference.scheduler.live.any()


def linear_ramp(width: int, height: int) -> np.ndarray:
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    ramp = 0.1 + 0.5 * u[None, :] + 0.3 * v[:, None]
    return np.repeat(ramp[..., None], 4, axis=2) * np.array([1.0, 0.5, 0.25, 0.8])


def test_remap_bilinear_of_linear_ramp_is_exact_inside() -> None:
    old = linear_ramp(48, 32)
    for width, height in ((96, 64), (30, 20), (61, 17)):
        new = remap_bilinear(old, width, height)
        expected = linear_ramp(width, height)
        x = (np.arange(width) + 0.5) / width * 48 - 0.5
        y = (np.arange(height) + 0.5) / height * 32 - 0.5
        inside = ((y >= 0) & (y <= 31))[:, None] & ((x >= 0) & (x <= 47))[None, :]
        assert inside.sum() > 0.8 * width * height
        np.testing.assert_allclose(new[inside], expected[inside], rtol=0, atol=1e-14)


def test_resize_preserve_remap_reproduces_ramp() -> None:
    params = params_of("frost-full")
    assert params.resize_policy == "preserve-remap"
    reference = FrostReference(params, 48, 32)
    reference.queue(Segment(0.0, 0.1, (0.3, 0.5), (0.6, 0.5)))
    reference.update(0.0, 0.1)
    reference.state = linear_ramp(48, 32)
    reference.resize(96, 64)
    expected = linear_ramp(96, 64)
    interior = (slice(1, -1), slice(1, -1))
    np.testing.assert_allclose(reference.state[interior], expected[interior], rtol=0, atol=1e-14)
    assert reference.scheduler.live.all()
    assert reference.scheduler.bounds.max() == 1.0


# ----------------------------------------------------------------------------------------------- formats


@cache
def gate(example: str, fmt: str) -> FormatGate:
    """measure_format is four replays; each (example, format) is measured once per test session."""
    return measure_format(params_of(example), fmt)


@pytest.fixture
def cached_gates(monkeypatch: pytest.MonkeyPatch) -> None:
    by_params = {params_of(name): name for name in FROST_EXAMPLES}
    monkeypatch.setattr(formats, "measure_format", lambda params, fmt: gate(by_params[params], fmt))


def test_measure_format_drift_on_frost_full() -> None:
    half = gate("frost-full", "rgba16float")
    single = gate("frost-full", "rgba32float")
    assert half.drift > HALF_FLOAT_TOLERANCE, half
    assert not half.passed
    assert single.drift < HALF_FLOAT_TOLERANCE, single
    assert single.passed
    assert set(half.per_rate) == set(path.FRAME_RATES)
    assert half.drift == max(half.per_rate.values())
    assert half.as_dict()["status"] == "fail"
    assert single.as_dict()["status"] == "pass"


@pytest.mark.usefixtures("cached_gates")
def test_choose_format_auto() -> None:
    chosen, gates = choose_format(params_of("frost-full"), "auto")
    assert chosen == "rgba32float"
    assert [g.format for g in gates] == ["rgba16float", "rgba32float"]
    chosen, gates = choose_format(params_of("frost-balanced"), "auto")
    assert chosen == "rgba16float"
    assert [g.format for g in gates] == ["rgba16float"]
    assert gates[0].passed


@pytest.mark.usefixtures("cached_gates")
def test_choose_format_explicit_failure_is_an_error() -> None:
    with pytest.raises(FormatRefusedError, match="auto"):
        choose_format(params_of("frost-full"), "rgba16float")
    chosen, gates = choose_format(params_of("frost-full"), "rgba32float")
    assert chosen == "rgba32float"
    assert [g.format for g in gates] == ["rgba32float"]


def replay_arriving_late(params: FrostParams, fps: int) -> FrostReference:
    """The conformance path as a real pointer delivers it: each segment is queued only once its end sample
    has arrived, i.e. before the first update whose current instant reaches t1; most overlap an instant
    that has already been rendered."""
    reference = FrostReference(params, *GRID)
    pending = list(path.conformance_segments())
    for previous, current in itertools.pairwise(path.frame_instants(fps)):
        while pending and pending[0].t1 <= current:
            reference.queue(pending.pop(0))
        reference.update(previous, current)
    return reference


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_late_segments_are_caught_up_exactly(example: str) -> None:
    # A segment known only after the instant it overlaps still deposits its whole span: the decay-only
    # part is turned into the deposit exactly, so late arrival at 30, 60 and 120 FPS gives the history of
    # the segments all known in advance, and the pointer time deposited is the stroke's duration.
    params = dataclasses.replace(params_of(example), diffusivity=0.0)
    known, _ = replay_states(params, 60)
    for fps in path.FRAME_RATES:
        late = replay_arriving_late(params, fps)
        worst = float(np.abs(late.state - known.state).max())
        assert worst <= 1e-12, f"{example} late arrival at {fps} FPS differs by {worst:.3g}"
        assert sum(r.late_steps for r in late.counters.history) > 0
        assert late.counters.pointer_seconds == pytest.approx(path.STROKE_SECONDS, abs=1e-12)


def test_catch_up_turns_decay_into_deposit_then_decay() -> None:
    x0 = np.array([0.0, 0.2, 0.7, 1.0])
    b = np.array([0.0, 0.3, 1.0, 0.6])
    decay, fill, tau, age = 0.4, 5.0, 0.07, 0.13
    decayed = law.advance(law.advance(x0, 0.0, tau, decay, fill), 0.0, age, decay, fill)
    exact = law.advance(law.advance(x0, b, tau, decay, fill), 0.0, age, decay, fill)
    assert np.abs(law.catch_up(decayed, b, tau, age, decay, fill) - exact).max() <= 1e-15
    # a = 0 (no decay, no coverage) keeps x.
    assert law.catch_up(x0, 0.0, tau, age, 0.0, fill).tolist() == x0.tolist()


def test_late_steps_clip_to_the_origin_and_to_previous() -> None:
    early = Segment(t0=0.1, t1=0.3, start=(0.2, 0.5), end=(0.4, 0.5))
    spanning = Segment(t0=0.3, t1=0.6, start=(0.4, 0.5), end=(0.6, 0.5))
    steps = late_steps(0.5, [early, spanning], origin=0.2)
    assert [(s.segments[0], s.dt, s.age) for s in steps] == [
        (early, pytest.approx(0.1), pytest.approx(0.2)),
        (spanning, pytest.approx(0.2), 0.0),
    ]
    assert late_steps(0.5, [early], origin=0.35) == []


def test_segments_from_before_a_discontinuity_deposit_nothing() -> None:
    params = dataclasses.replace(params_of("frost-budgeted"), discontinuity="freeze", diffusivity=0.0)
    reference = FrostReference(params, *GRID)
    reference.update(0.0, 0.1)
    reference.update(0.1, 5.0)  # longer than maxInterval: a discontinuity; the timeline restarts at 5.0
    reference.queue(Segment(t0=4.0, t1=4.9, start=(0.3, 0.5), end=(0.7, 0.5)))
    reference.update(5.0, 5.1)
    assert float(np.abs(reference.state).max()) == 0.0
    assert reference.counters.pointer_seconds == 0.0


# ---------------------------------------------------------------------------------- several strokes at once


def _strokes(stream: int, v: float, t0: float = 0.0) -> list[Segment]:
    """A 0.6 s left-to-right wipe at height v in six segments of one stream."""
    return [
        Segment(t0 + 0.1 * k, t0 + 0.1 * (k + 1), (0.2 + 0.1 * k, v), (0.3 + 0.1 * k, v), stream=stream)
        for k in range(6)
    ]


def _replay(params: FrostParams, segments: list[Segment], fps: int = 30) -> FrostReference:
    reference = FrostReference(params, *GRID)
    for segment in sorted(segments, key=lambda g: (g.t0, g.stream)):
        reference.queue(segment)
    instants = [k / fps for k in range(round(0.8 * fps) + 1)]
    for previous, current in itertools.pairwise(instants):
        reference.update(previous, current)
    return reference


def test_two_strokes_at_once_each_leave_their_own_trail() -> None:
    """Two pointers wiping at the same time, far apart: each half of the pane holds exactly what that
    stroke alone leaves (the step holds both segments and a texel takes the larger coverage, which is
    the only one there); pointer time counts both streams."""
    params = dataclasses.replace(params_of("frost-budgeted"), diffusivity=0.0)
    top, bottom = _strokes(1, 0.25), _strokes(2, 0.75)
    both = _replay(params, top + bottom)
    alone_top, alone_bottom = _replay(params, top), _replay(params, bottom)
    half = GRID[1] // 2
    assert np.array_equal(both.state[:half], alone_top.state[:half])
    assert np.array_equal(both.state[half:], alone_bottom.state[half:])
    assert float(both.state[..., 0].max()) > 0.1
    assert both.counters.pointer_seconds == pytest.approx(1.2, abs=1e-12)


def test_two_streams_on_one_path_equal_one_stream() -> None:
    """max(b, b) = b: a second pointer retracing the first at the same instants adds nothing."""
    params = dataclasses.replace(params_of("frost-budgeted"), diffusivity=0.0)
    twice = _replay(params, _strokes(1, 0.5) + _strokes(2, 0.5))
    once = _replay(params, _strokes(1, 0.5))
    assert np.array_equal(twice.state, once.state)


def test_a_stream_may_not_overlap_itself_and_streams_are_capped() -> None:
    params = dataclasses.replace(params_of("frost-budgeted"), max_streams=3)
    reference = FrostReference(params, *GRID)
    reference.queue(Segment(0.0, 0.2, (0.1, 0.1), (0.2, 0.1), stream=1))
    with pytest.raises(ValueError, match="before the previous one ended"):
        reference.queue(Segment(0.1, 0.3, (0.1, 0.1), (0.2, 0.1), stream=1))
    reference.queue(Segment(0.1, 0.3, (0.1, 0.1), (0.2, 0.1), stream=2))
    reference.queue(Segment(0.1, 0.3, (0.1, 0.1), (0.2, 0.1), stream=3))
    with pytest.raises(ValueError, match="would overlap 3 other streams"):
        reference.queue(Segment(0.15, 0.3, (0.1, 0.1), (0.2, 0.1), stream=4))
    reference.queue(Segment(0.3, 0.4, (0.1, 0.1), (0.2, 0.1), stream=4))  # after the others: fine


def test_bins_count_every_pair_whose_box_reaches_them() -> None:
    """Entries per bin against a brute-force count over texel boxes, and the overflow rule: a chunk past
    the bin capacity is one bin with every pair (the unbinned cost), never a truncated list."""
    params = params_of("frost-budgeted")
    w, h = GRID
    rng = np.random.default_rng(7)
    steps = []
    for _ in range(5):
        segments = []
        for stream in range(4):
            a, b = rng.uniform(0, 1, 2), rng.uniform(0, 1, 2)
            segments.append(
                Segment(0.0, 1.0, (float(a[0]), float(a[1])), (float(b[0]), float(b[1])), stream=stream)
            )
        steps.append(Step(0.01, tuple(segments)))
    bins = bin_steps(steps, params, w, h)
    size = params.tile_size
    expected = np.zeros(bins.entries.shape, dtype=np.int64)
    for step in steps:
        for segment in step.segments:
            box = texel_box(segment, step.dt, params.brush_reach, w, h)
            assert box is not None
            for b in range(expected.size):
                by, bx = divmod(b, bins.bins_x)
                if (
                    bx * size <= box[2]
                    and box[0] < (bx + 1) * size
                    and by * size <= box[3]
                    and box[1] < (by + 1) * size
                ):
                    expected[b] += 1
    assert not bins.single
    assert np.array_equal(bins.entries, expected)
    update = np.ones((h, w), dtype=bool)
    assert bins.texel_steps(update) < update.sum() * 20  # binning skips what an unbinned loop evaluates
    small = bin_steps(steps, dataclasses.replace(params, bin_capacity=int(expected.sum()) - 1), w, h)
    assert small.single
    assert small.total == 20
    assert small.texel_steps(update) == update.sum() * 20
