"""The frost parity job: a built package on WebGPU (SwiftShader, headless Chromium) against the numpy
reference, gate by gate, written to ``<package>/parity/report.json`` with PNG readbacks beside it.

Every GPU value comes from readback; every reference value from creaturegen.frost.reference, driven by
the params the package was built with (build-report.json). Gates:

- history parity: the conformance stroke at 30, 60 and 120 FPS; GPU vs numpy (rounding like the
  package's storage format) within half-float tolerance at every texel and channel;
- frame-rate invariance: GPU 30 vs GPU 120 within the numpy float64 30-vs-120 difference plus the same
  tolerance; numpy float64 30 vs 120 ≤ 1e-12 for the law (diffusion off; with diffusion on its
  operator-splitting difference is reported, not hidden);
- idle: once converged, frames dispatch nothing (counted by the package, per frame);
- time policy: equal instants do nothing; a reversed interval runs the declared policy;
- resize: the declared policy (clear → zeros; preserve-remap → the numpy bilinear remap of the GPU
  history read back just before);
- structure texels: the structure and normal textures read back from the GPU (one textureLoad per texel)
  equal, code for code, the numpy decode of the package's structure file (the runtime inflates it and
  derives the normals in JavaScript; creaturegen.frost.structure_file does the same in numpy);
- mirrored wrap: the structure view read back around a wrap line is symmetric and matches the numpy
  mirrored-repeat bilinear sample of the shipped data (the package's structure file, decoded by
  creaturegen.frost.structure_file as the runtime decodes it); a plain-repeat prediction does not;
- debug views: all of them render, switching creates no pipeline, no GPU validation error anywhere.
"""

from __future__ import annotations

import base64
import dataclasses
import json
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import numpy.typing as npt

from ..frost.formats import HALF_FLOAT_TOLERANCE, replay
from ..frost.params import FrostParams, params_from_plan
from ..frost.path import FRAME_RATES, STROKE_SECONDS, STROKE_START, conformance_segments, frame_instants
from ..frost.reference import STORAGE_OF_FORMAT, Storage, remap_bilinear
from ..frost.structure_file import decode_structure_file
from .browser import launch_lab_page
from .frost_session import FrostLab
from .png import write_png
from .report import ParityReport
from .server import WEB_LAB, serve

DEFAULT_CANVAS = (160, 96)
COMPOSITION_TOLERANCE = 1e-12
#: 8-bit output codes allowed between the GPU's filtered sample and numpy's (sub-texel weight precision).
PIXEL_CODES = 3
#: The pictures draw the conformance stroke this many times slower, so the thawed path is plain to see.
PICTURE_SLOWDOWN = 4

Array = npt.NDArray[np.float64]


def reference_replay(params: FrostParams, size: tuple[int, int], fps: int, storage: Storage) -> Array:
    return replay(params, fps, storage, size).state


def srgb_encode(linear: Array) -> Array:
    x = np.clip(linear, 0.0, 1.0)
    return np.asarray(np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055))


def sample_bilinear(channel: Array, s: Array, t: Array, mirrored: bool) -> Array:
    """Texture lookup at normalised coords (s, t) with mirrored-repeat or repeat addressing, per tap."""
    n = channel.shape[0]

    def wrap(i: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
        if not mirrored:
            return np.asarray(np.mod(i, n), dtype=np.int64)
        m = np.mod(i, 2 * n)
        return np.asarray(np.where(m < n, m, 2 * n - 1 - m), dtype=np.int64)

    x, y = s * n - 0.5, t * n - 0.5
    x0, y0 = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    fx, fy = x - x0, y - y0
    top = channel[wrap(y0)][:, wrap(x0)] * (1 - fx) + channel[wrap(y0)][:, wrap(x0 + 1)] * fx
    bottom = channel[wrap(y0 + 1)][:, wrap(x0)] * (1 - fx) + channel[wrap(y0 + 1)][:, wrap(x0 + 1)] * fx
    return np.asarray(top * (1 - fy[:, None]) + bottom * fy[:, None])


@contextmanager
def open_lab(package: Path, canvas: tuple[int, int]) -> Iterator[FrostLab]:
    url_path = f"frost.html?pkg={package.name}&w={canvas[0]}&h={canvas[1]}"
    with serve(WEB_LAB, mounts={"out": package.parent}) as base, launch_lab_page(base + url_path) as lab_page:
        error = lab_page.lab.get("error")
        if error:
            raise RuntimeError(f"frost lab failed for {package.name}: {error}\n{lab_page.transcript()}")
        yield FrostLab(lab_page.page)


def _history_gates(lab: FrostLab, params: FrostParams, report: ParityReport) -> None:
    info = lab.info()
    size = (int(info["historySize"][0]), int(info["historySize"][1]))
    storage = STORAGE_OF_FORMAT[info["format"]]
    gpu: dict[int, Array] = {}
    exact: dict[int, Array] = {}
    for fps in FRAME_RATES:
        gpu[fps] = lab.replay(conformance_segments(), frame_instants(fps))
        expected = reference_replay(params, size, fps, storage)
        exact[fps] = reference_replay(params, size, fps, "float64")
        error = float(np.abs(gpu[fps] - expected).max())
        report.gate(f"GPU vs numpy history at {fps} FPS", error, HALF_FLOAT_TOLERANCE, "history units")
        report.measurements[f"peakThaw{fps}"] = float(expected[..., 0].max())
    slow, fast = min(FRAME_RATES), max(FRAME_RATES)
    numpy_rates = float(np.abs(exact[slow] - exact[fast]).max())
    gpu_rates = float(np.abs(gpu[slow] - gpu[fast]).max())
    report.measurements["numpyFloat64RateDifference"] = numpy_rates
    report.gate(
        f"GPU {slow} vs {fast} FPS history", gpu_rates, numpy_rates + HALF_FLOAT_TOLERANCE, "history units"
    )
    law = dataclasses.replace(params, diffusivity=0.0)
    law_rates = float(
        np.abs(
            reference_replay(law, size, slow, "float64") - reference_replay(law, size, fast, "float64")
        ).max()
    )
    report.gate(
        f"numpy float64 {slow} vs {fast} FPS (law)", law_rates, COMPOSITION_TOLERANCE, "history units"
    )
    report.measurements["historySize"] = list(size)
    report.measurements["format"] = info["format"]


def _idle_and_time_gates(lab: FrostLab, params: FrostParams, report: ParityReport) -> None:
    lab.reset()
    lab.queue(conformance_segments())
    slowest = min(c.decay for c in params.channels)
    settle = float(np.log(1.0 / params.tolerance) / max(slowest, 1e-9)) + 2.0
    step = min(0.5, params.max_interval)
    instants = [k * step for k in range(int(settle / step) + 4)]
    reports = lab.advance(instants)
    tail = reports[-3:]
    idle_dispatches = sum(int(r["dispatches"]) for r in tail)
    report.gate("dispatches per idle frame after convergence", idle_dispatches, 0, "dispatches")
    retired_at = next((i for i, r in enumerate(reports) if r["retiredTiles"] > 0), None)
    report.measurements["idleAfterSeconds"] = None if retired_at is None else instants[retired_at + 1]
    report.gate("converged history is exactly zero", float(np.abs(lab.history()).max()), 0.0, "history units")
    t = instants[-1]
    none = lab.update(t, t)
    report.gate(
        "equal instants dispatch nothing",
        int(none["dispatches"]),
        0,
        "dispatches",
        passed=none["decision"] == "none" and none["dispatches"] == 0,
    )
    lab.reset()
    lab.queue(conformance_segments()[:10])
    lab.advance([0.0, 0.05, 0.1])
    before = float(np.abs(lab.history()).max())
    reversed_report = lab.update(0.1, 0.05)
    after = float(np.abs(lab.history()).max())
    expected_after = 0.0 if params.discontinuity == "reset" else before
    report.gate(
        f"reversed interval runs the {params.discontinuity} policy",
        abs(after - expected_after),
        0.0,
        "history units",
        passed=reversed_report["decision"] == "discontinuity" and after == expected_after and before > 0,
    )


def _resize_gate(lab: FrostLab, params: FrostParams, report: ParityReport, canvas: tuple[int, int]) -> None:
    lab.reset()
    lab.queue(conformance_segments())
    lab.advance(frame_instants(60, 0.5))
    before = lab.history()
    new_canvas = (canvas[0] * 3 // 4, canvas[1] * 5 // 4)
    result = lab.call("([w, h]) => window.__lab.resize(w, h, 1)", list(new_canvas))
    after = lab.history()
    if params.resize_policy == "clear":
        expected = np.zeros_like(after)
    else:
        expected = remap_bilinear(before, after.shape[1], after.shape[0])
    error = float(np.abs(after - expected).max())
    report.gate(f"resize follows {params.resize_policy}", error, HALF_FLOAT_TOLERANCE, "history units")
    report.measurements["resize"] = {"from": list(before.shape[1::-1]), "to": result["historySize"]}
    lab.call("([w, h]) => window.__lab.resize(w, h, 1)", list(canvas))


def shipped_structure(package: Path) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
    """The structure and normal maps of a built package, decoded from its shipped structure file."""
    layout = json.loads((package / "build-report.json").read_text())["assets"]["structure"]
    return decode_structure_file((package / "assets" / layout["file"]).read_bytes(), layout)


def _structure_gate(lab: FrostLab, package: Path, report: ParityReport) -> None:
    structure, normals = shipped_structure(package)
    raw = lab.call("() => window.__lab.readStructure()")
    n = int(raw["resolution"])
    for key, expected in (("structure", structure), ("normals", normals)):
        gpu = np.frombuffer(base64.b64decode(raw[key]), dtype=np.uint8)
        gpu = gpu.reshape(n, n, 4)
        error = int(np.abs(gpu.astype(np.int16) - expected.astype(np.int16)).max())
        report.gate(f"GPU {key} texels vs numpy decode of the shipped file", error, 0, "8-bit codes")


def _mirror_gate(lab: FrostLab, package: Path, report: ParityReport, canvas: tuple[int, int]) -> None:
    plan = json.loads((package / "build-report.json").read_text())
    data, _ = shipped_structure(package)
    period = canvas[0] / 2
    lab.call("(p) => window.__lab.setControl('mainScreenPeriod', p)", period)
    shot = lab.capture("structure").astype(np.float64)
    lab.call("(p) => window.__lab.setControl('mainScreenPeriod', p)", float(plan["mainScreenPeriod"]))
    width, height = canvas
    s = np.asarray((np.arange(width) + 0.5) / period, dtype=np.float64)
    t = np.asarray((np.arange(height) + 0.5) / period, dtype=np.float64)
    channel = data[..., 0].astype(np.float64) / 255.0
    mirrored = np.round(srgb_encode(sample_bilinear(channel, s, t, mirrored=True)) * 255.0)
    repeated = np.round(srgb_encode(sample_bilinear(channel, s, t, mirrored=False)) * 255.0)
    grey = shot[..., 0]
    wrap = width // 2
    band = slice(wrap - 6, wrap + 6)
    mirror_error = float(np.abs(grey[:, band] - mirrored[:, band]).max())
    repeat_error = float(np.abs(grey[:, band] - repeated[:, band]).max())
    symmetry = float(np.abs(grey[:, wrap - 6 : wrap][:, ::-1] - grey[:, wrap : wrap + 6]).max())
    report.gate(
        "structure view vs numpy mirrored-repeat sample (wrap band)", mirror_error, PIXEL_CODES, "8-bit codes"
    )
    report.gate("mirror symmetry across the wrap line", symmetry, PIXEL_CODES, "8-bit codes")
    report.gate(
        "plain-repeat prediction is rejected at the wrap line",
        repeat_error,
        PIXEL_CODES,
        "8-bit codes",
        passed=repeat_error > PIXEL_CODES,
    )


def _views_gate(lab: FrostLab, package: Path, report: ParityReport) -> None:
    folder = package / "parity"
    lab.reset()
    lab.queue(conformance_segments(PICTURE_SLOWDOWN))
    lab.advance(frame_instants(60, STROKE_START + STROKE_SECONDS * PICTURE_SLOWDOWN + 0.1))
    write_png(folder / "final.png", lab.capture("final"))
    warm = lab.counters()["device"]
    views: list[str] = lab.info()["debugViews"]
    for view in views:
        write_png(folder / f"view-{view}.png", lab.capture(view))
    after = lab.counters()["device"]
    created = sum(
        after[k] - warm[k]
        for k in (
            "createRenderPipeline",
            "createComputePipeline",
            "createRenderPipelineAsync",
            "createComputePipelineAsync",
        )
    )
    report.gate("pipelines created while switching debug views", created, 0, "pipelines")
    report.measurements["debugViews"] = views


GATE_GROUPS = ("history", "idle", "resize", "structure", "mirror", "views")


def run_frost_parity(
    package: Path, canvas: tuple[int, int] = DEFAULT_CANVAS, groups: tuple[str, ...] = GATE_GROUPS
) -> ParityReport:
    """Run the frost gates (all groups by default) for one built package; writes parity/report.json and
    PNGs into it. GPU validation errors are always gated."""
    package = package.resolve()
    build_report = json.loads((package / "build-report.json").read_text())
    params = params_from_plan(build_report["params"])
    report = ParityReport(package=package.name)
    with open_lab(package, canvas) as lab:
        report.measurements["adapter"] = lab.info()["adapter"]
        if "history" in groups:
            _history_gates(lab, params, report)
        if "idle" in groups:
            _idle_and_time_gates(lab, params, report)
        if "resize" in groups:
            _resize_gate(lab, params, report, canvas)
        if "structure" in groups:
            _structure_gate(lab, package, report)
        if "mirror" in groups:
            _mirror_gate(lab, package, report, canvas)
        if "views" in groups:
            _views_gate(lab, package, report)
        errors = lab.gpu_errors()
        report.gate("GPU validation errors", len(errors), 0, "errors")
        report.measurements["gpuErrors"] = errors[:20]
        report.measurements["counters"] = lab.counters()["effect"]
    (package / "parity").mkdir(exist_ok=True)
    (package / "parity" / "report.json").write_text(
        json.dumps(report.as_dict(), indent=2, sort_keys=True) + "\n"
    )
    return report
