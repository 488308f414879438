"""Smoke test of bench/frost_strokes.py: a tiny canvas, one round, 1 and 8 strokes; JSON structure and
measured counts only (binning evaluates fewer texel-steps than the unbinned loop once strokes sit in
different tiles), never timings."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from conftest import json_numbers, load_bench


@pytest.mark.browser
def test_frost_strokes_benchmark_smoke(tmp_path: Path) -> None:
    bench = load_bench("frost_strokes")
    out = tmp_path / "strokes.json"
    args = ["--out", str(out), "--canvas", "192x128", "--repeats", "1", "--frames", "6", "--strokes", "1,8"]
    assert bench.main(args) == 0
    report = json.loads(out.read_text())
    assert set(report["policies"]) == {"dirty-tiles", "full-field"}
    bad = [(where, x) for where, x in json_numbers(report) if not math.isfinite(x)]
    assert not bad, bad
    for policy, cases in report["policies"].items():
        assert [c["strokes"] for c in cases] == [1, 8], policy
        for case in cases:
            binned, unbinned = case["variants"]["binned"], case["variants"]["unbinned"]
            assert binned["gpu_errors"] == [], policy
            assert unbinned["gpu_errors"] == [], policy
            assert binned["frames_timed"] == unbinned["frames_timed"] == 6
            assert 0 < binned["texel_steps_per_active_frame"] <= unbinned["texel_steps_per_active_frame"]
        eight = cases[1]["variants"]
        assert (
            eight["binned"]["texel_steps_per_active_frame"]
            < eight["unbinned"]["texel_steps_per_active_frame"]
        )
