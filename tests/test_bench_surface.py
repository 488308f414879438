"""Smoke test of bench/surface.py: the biped at the distant tier, one round; JSON structure and measured
properties (the band samples fewer nodes than a dense pass, both backends give one sign lattice, the mesh
is closed and manifold), never timings."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from conftest import json_numbers, load_bench

#: Gates that hold by construction of the sign-lattice mesher (surface/extract.py) at any resolution.
COMBINATORIAL_GATES = ("watertight", "edgeManifold", "vertexManifold", "winding", "degenerate")


def _positive_finite(x: object) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x) and x > 0


def test_surface_benchmark_smoke(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bench = load_bench("surface")
    out = tmp_path / "surface.json"
    args = ["--examples", "reference/biped.json", "--tiers", "distant", "--repeats", "1", "--out", str(out)]
    assert bench.main(args) == 0

    report = json.loads(out.read_text())
    assert {"environment", "parameters", "results", "notes"} <= report.keys()
    env = report["environment"]
    assert {"platform", "cpu_count", "wgpu_adapter"} <= env.keys()
    assert report["parameters"]["tiers"] == ["distant"]
    assert report["parameters"]["repeats"] == 1
    assert report["parameters"]["examples"] == ["reference/biped.json"]
    bad = [(where, x) for where, x in json_numbers(report) if not math.isfinite(x)]
    assert not bad, bad

    (result,) = report["results"]
    assert result["example"] == "reference/biped.json"
    (tier,) = result["tiers"]
    assert tier["tier"] == "distant"
    assert "error" not in tier

    # The lattice: the narrow band evaluates fewer nodes than a dense pass would.
    lattice = tier["lattice"]
    nx, ny, nz = lattice["shape"]
    assert lattice["dense_nodes"] == nx * ny * nz
    assert lattice["coarse_samples"] > 0
    assert 0 < lattice["fine_samples"] < lattice["dense_nodes"]
    assert lattice["fine_over_dense"] == lattice["fine_samples"] / lattice["dense_nodes"]
    assert 0 < lattice["blocks_active"] <= lattice["blocks_total"]

    # Sampling: numpy always; wgpu where an adapter exists. Every timed dense pass agrees with the band.
    wgpu_available = env["wgpu_adapter"]["available"]
    sampling, ratios = tier["sampling"], tier["measured_ratios"]
    assert tier["dense_backend"] in (("numpy", "wgpu") if wgpu_available else ("numpy",))
    timed = ["numpy", "wgpu"] if wgpu_available else ["numpy"]
    for name in timed:
        s = sampling[name]
        assert _positive_finite(s["band_seconds_best"])
        assert len(s["band_seconds_all"]) == 1
        assert 0 < s["band_seconds_in_backend"] <= s["band_seconds_best"]
        assert 0 < s["band_fraction_in_backend"] <= 1
        assert s["band_sign_lattice_equals_numpy"] is True
        assert _positive_finite(s["dense_seconds_best"])  # biped distant is far below the numpy limit
        assert s["dense_null_reason"] is None
        assert s["dense_sign_mismatches_outside_settle_band"] == 0
        assert _positive_finite(s["dense_over_band"])
    assert _positive_finite(ratios["dense_fastest_over_band_fastest"])
    if wgpu_available:
        assert _positive_finite(ratios["band_numpy_over_wgpu"])
        assert _positive_finite(ratios["dense_numpy_over_wgpu"])
        assert isinstance(env["wgpu_adapter"]["summary"], str)
    else:
        assert sampling["wgpu"] is None
        assert ratios["band_numpy_over_wgpu"] is None
        assert result["wgpu_unavailable_reason"]

    # Extraction and validation: a closed manifold mesh; the gate list is reported whole and consistent.
    extraction, validation = tier["extraction"], tier["validation"]
    assert extraction["vertices"] > 0
    assert extraction["triangles"] > 0
    assert extraction["unresolved_edges"] == 0
    assert _positive_finite(extraction["seconds"])
    assert _positive_finite(validation["seconds"])
    gates = {g["name"]: g for g in validation["gates"]}
    assert len(gates) == validation["gates_total"]
    assert {*COMBINATORIAL_GATES, "components", "inverted", "surfaceToZeroSet", "strayComponents"} <= set(
        gates
    )
    assert validation["failed"] == [name for name, g in gates.items() if not g["passed"]]
    assert validation["all_passed"] is (not validation["failed"])
    assert validation["gates_passed"] == validation["gates_total"] - len(validation["failed"])
    for name in COMBINATORIAL_GATES:
        assert gates[name]["passed"], gates[name]

    captured = capsys.readouterr()
    assert "[1/1] reference/biped.json" in captured.err
    assert "distant:" in captured.err
    assert "band np s" in captured.out
    assert "reference/biped.json" in captured.out
