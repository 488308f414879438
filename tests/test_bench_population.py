"""Smoke test of bench/population.py: the hopper's population CPU side in Node with 64 bodies, a few
frames; the JSON's structure and what the scenarios did (paused bodies not deformed, culled bodies
neither drawn nor deformed), never a time or an allocation figure."""

from __future__ import annotations

import json
import math
from pathlib import Path

from conftest import build_example, json_numbers, load_bench

BODIES = 64
PAGE_SIZE = 16


def test_population_benchmark_smoke(creature_out: Path, tmp_path: Path) -> None:
    bench = load_bench("population")
    package = build_example("reference/hopper.json", creature_out)
    out = tmp_path / "population.json"
    sizes = ["--bodies", str(BODIES), "--page-size", str(PAGE_SIZE), "--in-view", "0.25"]
    frames = ["--warm-frames", "5", "--frames", "5", "--alloc-warm", "20", "--alloc-frames", "10"]
    assert bench.main([str(package), "--out", str(out), *sizes, *frames]) == 0

    report = json.loads(out.read_text())
    assert report["benchmark"] == "population"
    assert report["bodies"] == BODIES
    assert report["pages"] == BODIES // PAGE_SIZE
    assert 1 <= report["deformKernelsPerPage"] <= 3  # skin only, field, corrected
    bad = [(where, x) for where, x in json_numbers(report) if not math.isfinite(x)]
    assert not bad, bad
    s = report["scenarios"]
    assert s["moving"]["drawnBodies"] == s["moving"]["deformedBodies"] == BODIES
    assert s["half-paused"]["drawnBodies"] == BODIES
    assert s["half-paused"]["deformedBodies"] == BODIES // 2
    culled = s["culled-moving"]["drawnBodies"]
    assert 0 < culled < BODIES
    assert s["culled-moving"]["deformedBodies"] == culled
    assert 0 < s["culled-half-paused"]["deformedBodies"] < culled
    for scenario in s.values():
        assert scenario["usPerBodyPerFrame"]["p50"] > 0
        assert scenario["dispatchesPerFrame"] <= report["deformKernelsPerPage"] * BODIES // PAGE_SIZE
    assert {w["scenario"] for w in report["allocation"]} == {"moving", "culled-half-paused"}
    assert all(len(w["windows"]) == len(w["long"]["windows"]) == 5 for w in report["allocation"])
    assert all(w["long"]["frames"] == 3 * w["frames"] for w in report["allocation"])
    assert len(report["targets"]) == 4
    assert all(isinstance(t["met"], bool) for t in report["targets"])


def test_population_benchmark_walks_a_two_tier_crowd(creature_out: Path, tmp_path: Path) -> None:
    """A package shipping hero and distant: the tier-walk scenario (chooseTiers every frame under a
    dollying camera) moves bodies between the tiers and has its allocation window probed."""
    bench = load_bench("population")
    package = build_example("reference/hopper.json", creature_out, "hero,distant")
    out = tmp_path / "population.json"
    sizes = ["--bodies", str(BODIES), "--page-size", str(PAGE_SIZE)]
    frames = ["--warm-frames", "60", "--frames", "60", "--alloc-warm", "20", "--alloc-frames", "10"]
    assert bench.main([str(package), "--out", str(out), *sizes, *frames]) == 0
    report = json.loads(out.read_text())
    assert [t["name"] for t in report["tiers"]] == ["hero", "distant"]
    walk = report["scenarios"]["tier-walk"]
    assert walk["tierMoves"] > 0
    assert sum(walk["bodiesPerTier"].values()) == BODIES
    assert "tier-walk" in {w["scenario"] for w in report["allocation"]}
    assert any("tier-walk" in t["name"] for t in report["targets"])
