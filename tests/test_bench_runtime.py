"""Smoke test of bench/runtime.py: the hopper built into a temporary folder, two small populations over two
pages, one frame per material; JSON structure and measured properties (draws per pass equal the pages in
use, upload bytes equal the bodies' pose rows, the baseline computes the shipped field), never timings."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from conftest import json_numbers, load_bench

#: Two bodies per page: one body fills one page, three bodies two pages (two draws per pass).
BODIES = (1, 3)
CAPACITY = 4
PAGE_SIZE = 2
SPAWNS = 4


def _positive_finite(x: object) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x) and x > 0


@pytest.mark.browser
def test_runtime_benchmark_smoke(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bench = load_bench("runtime")
    out = tmp_path / "runtime.json"
    package = tmp_path / "out" / bench.HOPPER_SLUG  # missing: the bench builds the hopper there
    args = [
        str(package),
        "--out",
        str(out),
        "--bodies",
        ",".join(map(str, BODIES)),
        "--capacity",
        str(CAPACITY),
        "--page-size",
        str(PAGE_SIZE),
        "--frames",
        "1",
        "--repeats",
        "1",
        "--spawns",
        str(SPAWNS),
        "--field-repeats",
        "2",
        "--field-copies",
        "1",
    ]
    assert bench.main(args) == 0

    report = json.loads(out.read_text())
    assert {"benchmark", "environment", "parameters", "results", "notes", "wall_seconds"} <= set(report)
    assert report["benchmark"] == "runtime"
    assert report["parameters"]["bodies"] == list(BODIES)
    bad = [(where, x) for where, x in json_numbers(report) if not math.isfinite(x)]
    assert not bad, bad

    (result,) = report["results"]
    assert result["package"] == bench.HOPPER_SLUG
    assert result["built_by_this_run"] is True
    assert result["gpu_errors"] == []
    device = result["device"]
    assert device["isWebGPUBackend"] is True
    assert device["adapter"]["architecture"] == "swiftshader"

    # The seed's workload tuple, read from the package and measured in the page.
    workload = result["workload"]
    assert {"slots", "K", "vertices", "triangles", "tier", "bodies", "pages", "canvas"} <= set(workload)
    assert workload["bodies"] == list(BODIES)
    assert workload["pages"] == [math.ceil(n / PAGE_SIZE) for n in BODIES]
    assert workload["canvas"] == [192, 144]
    assert workload["slots"] == result["build_report_workload"]["slots"]
    assert workload["K"] == result["build_report_workload"]["K"]
    assert workload["vertices"] == result["build_report_workload"]["vertices"]
    assert workload["shadow_passes"] == [0]
    built = result["build_report_workload"]
    assert workload["visible_instances"] == [[n] for n in BODIES]
    assert (workload["S"], workload["influences"]) == (built["S"], built["influences"])
    assert 1 <= workload["influences"] <= 4
    assert sum(workload["skinning_methods"].values()) == workload["vertices"]
    assert workload["outline_mode"] == "none"
    assert workload["render_extent"] == [192, 144]
    assert workload["sample_count"] == 0  # the bench's renderer: antialias off
    model = result["model"]
    assert model["predicted_ratio_7P_over_K"] == 7 * workload["slots"] / workload["K"]

    # Populations: one draw per page in use in every pass, every live body drawn, uploads = pose rows.
    pose_bytes = result["build_report_workload"]["poseBytesPerBody"]
    assert [p["bodies"] for p in result["populations"]] == list(BODIES)
    for population in result["populations"]:
        n = population["bodies"]
        pages = math.ceil(n / PAGE_SIZE)
        assert population["live_bodies"] == n
        assert population["pages_in_use"] == pages
        draws = population["draws"]
        assert draws["draws_per_pass_equal_pages_in_use"] is True
        assert draws["body_draw_calls_per_pass"] == [[pages]]
        assert draws["body_draw_calls_per_frame"] == [pages]
        assert draws["instances_drawn_per_frame"] == [n]
        uploads = population["upload_bytes_per_frame"]
        assert uploads["min"] == uploads["max"] == uploads["derived"] == n * pose_bytes
        for variant in bench.VARIANTS:
            timing = population["variants"][variant]
            assert timing["frames"] == 1
            assert _positive_finite(timing["ms"]["p50"])
            assert timing["ms"]["p50"] <= timing["ms"]["p95"]
            assert _positive_finite(timing["cpu_ms"]["p50"])
        first = population["first_frame_ms"]
        assert set(first) == {*bench.VARIANTS, "first_visible"}
        assert first["first_visible"] == first["shipped"]
        assert all(_positive_finite(first[v]) for v in bench.VARIANTS)
        assert _positive_finite(population["ratio_baseline_over_shipped"]["median"])
        assert _positive_finite(population["ratio_shipped_over_lbs"]["median"])
        assert _positive_finite(population["ratio_ao_over_shipped"]["median"])

    marginal = result["marginal_ms_per_body"]
    for variant in bench.VARIANTS:
        assert math.isfinite(marginal[variant]["slope"])
        assert math.isfinite(marginal[variant]["intercept"])
    # The plain-LBS baseline beside the shipped body: the bar as a target (met or not, measured).
    (target,) = result["targets"]
    assert target["target"] == bench.LBS_TARGET
    assert target["value"] == marginal["ratio_shipped_over_lbs"]
    assert target["met"] == (target["value"] is not None and target["value"] <= bench.LBS_TARGET)

    # The baseline evaluates the same field: equal distances, central-difference gradients along the
    # analytic ones (a measured property of the two kernels, read back from the GPU).
    field = result["field_queries"]
    assert field["points"] == workload["vertices"]
    check = field["check"]
    assert check["maxAbsDistanceOverBodyScale"] < 1e-5
    assert check["gradientsCompared"] > 0.9 * field["points"]
    assert check["gradientAngleDeg"]["median"] < 1.0
    for variant in bench.FIELD_VARIANTS:
        assert _positive_finite(field["ms_per_dispatch"][variant]["p50"])
    assert _positive_finite(field["measured_ratio_baseline_over_shipped"])

    spawn = result["spawn"]
    assert spawn["samples"] == SPAWNS
    assert spawn["max_ms"] >= spawn["median_ms"] >= 0
    assert _positive_finite(spawn["timer_resolution_ms"])

    captured = capsys.readouterr()
    assert "population of 3" in captured.err
    assert "predicted 7P/K" in captured.out
