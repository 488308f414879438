"""Smoke test of bench/motion.py on the hopper (a rope creature): JSON structure and measured properties
(every number finite, the rope fit over three configurations of increasing work, allocation counted over
the requested steps), never timings."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from conftest import build_example, json_numbers, load_bench


def test_motion_benchmark_smoke(
    creature_out: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bench = load_bench("motion")
    package = build_example("reference/hopper.json", creature_out)
    out = tmp_path / "motion.json"
    args = [
        str(package),
        "--out",
        str(out),
        "--bodies",
        "2",
        "--warm",
        "10",
        "--ticks",
        "20",
        "--rounds",
        "2",
    ]
    assert bench.main([*args, "--alloc-steps", "50"]) == 0

    report = json.loads(out.read_text())
    assert {"benchmark", "environment", "parameters", "results", "notes", "wall_seconds"} <= set(report)
    bad = [(where, x) for where, x in json_numbers(report) if not math.isfinite(x)]
    assert not bad, bad
    (result,) = report["results"]
    assert result["type"] == "hopper"
    assert result["step"]["median"] > 0
    assert len(result["step"]["samples"]) == 2
    assert result["allocation"]["steps"] == 50
    one = result["step"]["perStep"]
    assert one["steps"] == 2 * 20
    assert 0 < one["p50"] <= one["p95"] <= one["max"]
    live = result["live"]
    assert live["bodies"] == 2
    assert len(live["checkpoints"]) == 6
    assert live["peakLiveBytes"] == max(live["checkpoints"]) > 0  # two bodies hold state
    assert live["perBodyBytes"] == live["peakLiveBytes"] / 2
    rope = result["rope"]
    segments = sum(r["segments"] for r in result["ropes"])
    assert [c["work"] for c in rope["configs"]] == [s * p * segments for s, p in ((1, 2), (2, 4), (4, 8))]
    assert "| hopper-squash-core | hopper |" in capsys.readouterr().out
