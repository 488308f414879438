"""Smoke test of bench/frost.py: a tiny canvas, one round, JSON structure and measured properties only
(idle frames dispatch nothing, dirty tiles dispatch fewer texels than full-field); never timings."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from conftest import json_numbers, load_bench

#: 192x128: the budgeted history (x0.25) is 48x32, two 32-texel tiles, so a dab in one tile dispatches
#: fewer texels than the whole field (at 96x64 the history fits in one tile and would not).
CANVAS = (192, 128)
FRAMES = 5


@pytest.mark.browser
def test_frost_benchmark_smoke(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bench = load_bench("frost")
    out = tmp_path / "frost.json"
    canvas = f"{CANVAS[0]}x{CANVAS[1]}"
    args = ["--out", str(out), "--canvas", canvas, "--repeats", "1", "--frames", str(FRAMES)]
    assert bench.main(args) == 0

    report = json.loads(out.read_text())
    assert {"environment", "device", "parameters", "tiers", "sparse", "idle", "gpu_errors", "notes"} <= set(
        report
    )
    assert report["device"]["isWebGPUBackend"] is True
    assert report["device"]["adapter"]["architecture"] == "swiftshader"
    assert report["parameters"]["canvas"] == list(CANVAS)
    assert report["parameters"]["repeats"] == 1
    assert report["parameters"]["frames"] == FRAMES
    assert all(errors == [] for errors in report["gpu_errors"].values()), report["gpu_errors"]
    bad = [(where, x) for where, x in json_numbers(report) if not math.isfinite(x)]
    assert not bad, bad

    # Tiers: one package, three tiers, the history shrinking with the tier's scale.
    tiers = report["tiers"]
    assert set(tiers["results"]) == set(bench.TIERS)
    expected_history = {"full": [192, 128], "balanced": [96, 64], "budgeted": [48, 32]}
    for name, result in tiers["results"].items():
        assert result["history_size"] == expected_history[name]
        assert set(result["ms_per_frame"]) == {
            "update_only",
            "update_and_render",
            "render_only",
            "render_only_blur_1x1",
            "blur_estimate",
        }
        assert result["blur_target_size_tiny"] == [1, 1]
        assert result["timed_counts_match_reports"] is True
        assert result["dense_stroke_reports"]["frames_with_dispatch"] == FRAMES
        memory = result["memory"]
        assert memory["derived_equals_allocated"] is True
        w, h = expected_history[name]
        assert memory["history_bytes_derived"] == 2 * w * h * memory["bytes_per_texel_derived"]
    for ratios in tiers["measured_ratios_relative_to_full"].values():
        assert set(ratios) == set(bench.TIERS)
        assert ratios["full"] == 1.0

    # Sparse dab: specs differing only in update.policy; dirty tiles dispatch fewer texels (a property of
    # the scheduler, read from the per-frame reports).
    sparse = report["sparse"]
    assert sparse["differs_only_in"] == "update.policy"
    full, dirty = sparse["variants"]["full-field"], sparse["variants"]["dirty-tiles"]
    assert full["history_size"] == dirty["history_size"] == [48, 32]
    assert dirty["tile_grid"] == [2, 1]
    assert full["frames_with_dispatch"] == dirty["frames_with_dispatch"] == FRAMES
    assert 0 < dirty["texels_total"] < full["texels_total"]
    assert sparse["measured_ratios"]["texels_full_field_over_dirty_tiles"] > 1
    assert full["timed_counts_match_reports"] is True
    assert dirty["timed_counts_match_reports"] is True

    # Idle: every tile retired, then idle frames dispatch nothing (counted, not assumed).
    assert [case["policy"] for case in report["idle"]] == ["full-field", "full-field", "dirty-tiles"]
    for case in report["idle"]:
        assert case["retired_tiles_total"] >= 1
        assert case["last_retire_at_s"] is not None
        assert case["idle_frames"] == FRAMES
        assert case["idle_decisions"] == ["advance"]
        assert case["idle_dispatches_per_frame_max"] == 0
        assert case["idle_dispatches_total"] == 0
        assert case["idle_texels_total"] == 0
        assert case["idle_counter_delta"] == {"dispatches": 0, "idleFrames": FRAMES, "frames": FRAMES}
        assert case["idle_timed_dispatches"] == 0

    captured = capsys.readouterr()
    assert "[4/4] sparse dab" in captured.err
    assert "blur est" in captured.out
    assert "full-field / dirty-tiles" in captured.out
