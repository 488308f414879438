"""Smoke test of bench/field.py: one small example, tiny counts, JSON structure only (never timings)."""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from conftest import EXAMPLES, REPO


def _load_bench() -> ModuleType:
    spec = importlib.util.spec_from_file_location("bench_field", REPO / "bench" / "field.py")
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up while the class is created
    spec.loader.exec_module(module)
    return module


def _numbers(value: Any, path: str = "") -> Iterator[tuple[str, float]]:
    if isinstance(value, bool):
        return
    if isinstance(value, int | float):
        yield path, float(value)
    elif isinstance(value, dict):
        for key, item in value.items():
            yield from _numbers(item, f"{path}.{key}")
    elif isinstance(value, list):
        for i, item in enumerate(value):
            yield from _numbers(item, f"{path}[{i}]")


def test_field_benchmark_writes_finite_positive_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bench = _load_bench()
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

    numbers = list(_numbers(report))
    assert len(numbers) > 30
    bad = [(where, x) for where, x in numbers if not (math.isfinite(x) and x > 0)]
    assert not bad, bad

    err = capsys.readouterr().err
    assert "[1/1] flyer.json" in err
    assert "7P/Ku" in err
