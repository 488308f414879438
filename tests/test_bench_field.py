"""Smoke test of bench/field.py: one small example, tiny counts, JSON structure only (never timings)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from conftest import EXAMPLES, json_numbers, load_bench


def test_field_benchmark_writes_finite_positive_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bench = load_bench("field")
    out = tmp_path / "field.json"
    example = EXAMPLES / "reference" / "flyer.json"
    assert bench.main(["--points", "300", "--repeats", "1", "--out", str(out), str(example)]) == 0

    report = json.loads(out.read_text())
    assert {"environment", "parameters", "results", "notes"} <= report.keys()
    assert {"python", "numpy", "cpu_count", "platform"} <= report["environment"].keys()
    assert report["parameters"]["points"] == 300
    assert report["parameters"]["repeats"] == 1
    assert isinstance(report["notes"], str)
    assert report["notes"]
    (result,) = report["results"]
    assert result["example"] == "reference/flyer.json"
    assert result["points"] == 300
    assert set(result["variants"]) == set(bench.VARIANTS)
    for variant in result["variants"].values():
        assert {"seconds_median", "points_per_second", "leaf_evaluations_per_second"} <= variant.keys()
    assert {
        "candidates_speedup_vs_full",
        "fd_over_analytic",
        "combined_full_fd_over_candidates_analytic",
    } <= result["measured_ratios"].keys()
    model = result["cost_model"]
    assert set(model["predicted_leaf_evaluations"]) == {"S0", "S1", "S2"}
    assert (
        model["predicted_forbidden_over_snap_7P_over_k_used"] == 7 * result["slot_count_P"] / result["k_used"]
    )

    numbers = list(json_numbers(report))
    assert len(numbers) > 30
    bad = [(where, x) for where, x in numbers if not (math.isfinite(x) and x > 0)]
    assert not bad, bad

    err = capsys.readouterr().err
    assert "[1/1] flyer.json" in err
    assert "7P/Ku" in err
