"""End-to-end smoke test of the lab path: web_lab/smoke.html in headless Chromium, WebGPU on SwiftShader.

This proves the pieces every parity test stands on: three 0.185.1 resolves through the import map,
WebGPURenderer gets a real WebGPU backend (not the silent WebGL2 fallback) on the software adapter,
and a TSL compute kernel's output comes back through GPU readback. The expected numbers are
computed here with numpy, independently of the page's own JavaScript check.

Nothing here skips: a missing browser or a missing node_modules is a failed setup, not a pass.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest

from creaturegen.lab import browser
from creaturegen.lab.browser import find_chromium, launch_lab_page
from creaturegen.lab.server import serve

REPO_ROOT = Path(__file__).resolve().parents[1]
WEB_LAB = REPO_ROOT / "generator" / "creaturegen" / "web_lab"
THREE_VERSION = "0.185.1"

# Mirrors web_lab/smoke.js: out[i] = sin(i * 0.01) * i + 1 over N float32 elements.
N = 1024
SCALE = np.float32(0.01)
# WGSL only promises sin() to an absolute 2^-11 (SwiftShader measured about 1.9e-4); the kernel
# multiplies sin by i, so element i may be off by 2^-11 * i, plus a few float32 ulps of rounding.
SIN_ABS_ERR = 2.0**-11
ROUNDING_ULPS = 4


@dataclass(frozen=True)
class SmokeRun:
    lab: dict[str, Any]
    page_errors: list[str]
    console: list[str]
    transcript: str

    @property
    def smoke(self) -> dict[str, Any]:
        error = self.lab.get("error")
        assert error is None, f"page reported an error: {error}\n{self.transcript}"
        smoke = self.lab.get("smoke")
        assert isinstance(smoke, dict), f"window.__lab.smoke is missing\n{self.transcript}"
        return smoke


def expected_values(count: int) -> npt.NDArray[np.float32]:
    """The smoke formula evaluated in float32 on the CPU, step by step like the kernel."""
    i = np.arange(count, dtype=np.float32)
    return np.asarray(np.sin(i * SCALE) * i + np.float32(1), dtype=np.float32)


def tolerance(count: int, expected: npt.NDArray[np.float32]) -> npt.NDArray[np.float64]:
    i = np.arange(count, dtype=np.float64)
    return np.asarray(SIN_ABS_ERR * i + ROUNDING_ULPS * np.spacing(np.abs(expected)), dtype=np.float64)


@pytest.fixture(scope="module")
def smoke_run() -> Iterator[SmokeRun]:
    # Fail, never skip: CI must not go green because the browser or three is absent.
    three_manifest = WEB_LAB / "node_modules" / "three" / "package.json"
    if not three_manifest.is_file():
        pytest.fail(f"{three_manifest} is missing: run `make setup` (npm ci in web_lab/)")
    installed = json.loads(three_manifest.read_text(encoding="utf-8"))["version"]
    assert installed == THREE_VERSION, f"web_lab has three {installed}, not {THREE_VERSION}: run `make setup`"

    with serve(WEB_LAB) as base_url, launch_lab_page(base_url + "smoke.html") as lab_page:
        yield SmokeRun(
            lab=lab_page.lab,
            page_errors=list(lab_page.page_errors),
            console=list(lab_page.console),
            transcript=lab_page.transcript(),
        )


@pytest.mark.browser
def test_smoke_runs_on_webgpu_backend_with_swiftshader(smoke_run: SmokeRun) -> None:
    smoke = smoke_run.smoke
    assert smoke["isWebGPUBackend"] is True, f"three fell back to WebGL2\n{smoke_run.transcript}"
    assert smoke["architecture"] == "swiftshader", (
        f"adapter architecture {smoke['architecture']!r} from {smoke['architectureSource']}\n"
        f"{smoke_run.transcript}"
    )


@pytest.mark.browser
def test_smoke_reports_no_gpu_or_page_errors(smoke_run: SmokeRun) -> None:
    smoke = smoke_run.smoke
    assert smoke["gpuErrors"] == [], smoke_run.transcript
    assert smoke_run.page_errors == [], smoke_run.transcript
    console_errors = [line for line in smoke_run.console if line.startswith("[error]")]
    assert console_errors == [], smoke_run.transcript


@pytest.mark.browser
def test_smoke_readback_matches_numpy_float32(smoke_run: SmokeRun) -> None:
    smoke = smoke_run.smoke
    assert smoke["count"] == N
    gpu_all = np.asarray(smoke["allValues"], dtype=np.float64)
    gpu_first = np.asarray(smoke["values"], dtype=np.float64)
    assert gpu_all.shape == (N,)
    assert gpu_first.tolist() == gpu_all[:16].tolist(), "values must be the first 16 of allValues"
    # Values published from a Float32Array must be exact float32 numbers.
    assert np.array_equal(gpu_all.astype(np.float32).astype(np.float64), gpu_all)

    expected = expected_values(N)
    tol = tolerance(N, expected)
    err = np.abs(gpu_all - expected.astype(np.float64))

    first = slice(0, 16)
    assert np.all(err[first] <= tol[first]), (
        f"first 16: gpu={gpu_first.tolist()}\nexpected={expected[first].tolist()}\nerr={err[first].tolist()}"
    )
    worst = int(np.argmax(err / tol))
    assert np.all(err <= tol), (
        f"element {worst}: gpu={gpu_all[worst]!r} expected={float(expected[worst])!r} "
        f"err={err[worst]:.3g} > tol={tol[worst]:.3g}"
    )
    # The page ran its own check against the same bound; both must agree that it holds.
    assert smoke["maxErrOverBound"] <= 1.0


def test_find_chromium_rejects_a_missing_override(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    missing = tmp_path / "no-such-chromium"
    monkeypatch.setenv(browser.CHROMIUM_ENV, str(missing))
    with pytest.raises(RuntimeError, match="is not an executable file"):
        find_chromium()
