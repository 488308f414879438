"""Smoke test of bench/crowd.py: 16 hopper bodies over pages of 4, one frame per scenario; the JSON's
structure and what it measured (the crowd draws fewer bodies than the whole grid and deforms only its
moving seen ones, every scenario keeps one draw per page in use), never a time or the target's outcome."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from conftest import json_numbers, load_bench

BODIES = 16
PAGE_SIZE = 4


@pytest.mark.browser
def test_crowd_benchmark_smoke(tmp_path: Path) -> None:
    bench = load_bench("crowd")
    runtime = load_bench("runtime")
    out = tmp_path / "crowd.json"
    package = tmp_path / "out" / runtime.HOPPER_SLUG  # missing: the bench builds the hopper there
    args = [str(package), "--out", str(out), "--bodies", str(BODIES), "--page-size", str(PAGE_SIZE)]
    assert bench.main([*args, "--frames", "1", "--repeats", "1", "--in-view", "0.5"]) == 0

    report = json.loads(out.read_text())
    assert report["benchmark"] == "crowd"
    assert report["adapter"]["architecture"] == "swiftshader"
    assert report["gpu_errors"] == []
    bad = [(where, x) for where, x in json_numbers(report) if not math.isfinite(x)]
    assert not bad, bad
    scenarios = report["scenarios"]
    everyone, unculled, crowd = scenarios["all"], scenarios["all-unculled"], scenarios["crowd"]
    for scenario in (everyone, unculled):
        assert scenario["drawn_bodies_per_frame"] == [BODIES]
        assert scenario["deformed_bodies_per_frame"] == [BODIES]
        assert scenario["body_draw_calls_per_frame"] == [BODIES // PAGE_SIZE]
    seen = report["crowd_framing"]["seen"]
    assert 0.5 * BODIES <= seen < BODIES
    assert crowd["setup"]["paused"] == BODIES // 2
    (drawn,) = crowd["drawn_bodies_per_frame"]
    assert drawn == seen
    # Only the seen bodies that were not paused are deformed.
    (deformed,) = crowd["deformed_bodies_per_frame"]
    assert 0 < deformed < drawn
    assert crowd["body_draw_calls_per_frame"][0] <= BODIES // PAGE_SIZE
    (target,) = report["targets"]
    assert target["target"] == bench.TARGET
    assert target["value"] == report["scenarios"]["ratio_crowd_over_all"]["median"]
    assert target["met"] == (target["value"] <= target["target"])
