"""The frost parity job: a built package on WebGPU (SwiftShader, headless Chromium) against the numpy
reference, gate by gate, written to ``<package>/parity/report.json`` with PNG readbacks beside it.

Every GPU value comes from readback; every reference value from creaturegen.frost.reference, driven by
the params the package was built with (build-report.json). Gates:

- history parity: the conformance stroke at 30, 60 and 120 FPS; GPU vs numpy (rounding like the
  package's storage format) within half-float tolerance at every texel and channel;
- late arrival: the stroke's segments queued only once their end sample arrived (as attachPointer delivers
  them): GPU vs numpy fed the same way, numpy late vs in advance ≤ 1e-12 (the catch-up is exact for the
  law), and the pointer time deposited equals the stroke's duration;
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
- debug views: all of them render, switching creates no pipeline, no GPU validation error anywhere;
- a visible trail (composite readback, OKLab, L in [0, 1]): a one-second wipe at ordinary speed (0.7 of the
  pane's width per second, 120 Hz pointer, pressure 1, 60 FPS) changes the trail's pixels by a median
  ΔE ≥ 0.05 against the same pixels before the stroke and against the same pixels of a run whose stroke
  went elsewhere (untouched pane at the same instant); afterwards the trail frosts over again (median
  ΔE against before < 0.01) within the declared regrowth time (thaw 1 → 5 %, ln 20 / λ).

This module opens the lab and runs the groups in order, then writes the report; the gates live in
frost_history.py (history, late arrival, strokes at once, frame rates), frost_policies.py (idle, time,
resize), frost_texels.py (structure texels, mirrored wrap), frost_views.py (debug views) and
frost_trail.py (the visible trail).
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from ..frost.params import params_from_plan
from .browser import launch_lab_page
from .frost_history import history_gates, late_arrival_gates, strokes_at_once_gates
from .frost_policies import idle_and_time_gates, resize_gate
from .frost_session import FrostLab
from .frost_texels import mirror_gate, structure_gate
from .frost_trail import trail_gates
from .frost_views import views_gate
from .report import ParityReport, adapter_gate, console_problems
from .server import WEB_LAB, serve

DEFAULT_CANVAS = (160, 96)


@contextmanager
def open_lab(package: Path, canvas: tuple[int, int]) -> Iterator[FrostLab]:
    url_path = f"frost.html?pkg={package.name}&w={canvas[0]}&h={canvas[1]}"
    with serve(WEB_LAB, mounts={"out": package.parent}) as base, launch_lab_page(base + url_path) as lab_page:
        error = lab_page.lab.get("error")
        if error:
            raise RuntimeError(f"frost lab failed for {package.name}: {error}\n{lab_page.transcript()}")
        yield FrostLab(lab_page.page, lab_page.console, lab_page.page_errors)


#: "history": the conformance stroke at 30/60/120 FPS and during it; "late": segments arriving late;
#: "strokes": several strokes at once (frost_history). A planted-defect test runs only the group it targets.
GATE_GROUPS = ("history", "late", "strokes", "idle", "resize", "structure", "mirror", "views", "trail")


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
        adapter_gate(report, report.measurements["adapter"])
        if "history" in groups:
            history_gates(lab, params, report)
        if "late" in groups:
            late_arrival_gates(lab, params, report)
        if "strokes" in groups:
            strokes_at_once_gates(lab, params, report)
        if "idle" in groups:
            idle_and_time_gates(lab, params, report)
        if "resize" in groups:
            resize_gate(lab, params, report, canvas)
        if "structure" in groups:
            structure_gate(lab, package, report)
        if "mirror" in groups:
            mirror_gate(lab, package, report, canvas)
        if "views" in groups:
            views_gate(lab, package, report)
        if "trail" in groups:
            trail_gates(lab, params, report, canvas)
        errors = lab.gpu_errors()
        report.gate("GPU validation errors", len(errors), 0, "errors")
        report.measurements["gpuErrors"] = errors[:20]
        console = console_problems(lab.console) + list(lab.page_errors)
        report.gate("console errors and warnings (pipeline compiles included)", len(console), 0, "lines")
        report.measurements["consoleProblems"] = console[:20]
        report.measurements["counters"] = lab.counters()["effect"]
    (package / "parity").mkdir(exist_ok=True)
    (package / "parity" / "report.json").write_text(
        json.dumps(report.as_dict(), indent=2, sort_keys=True) + "\n"
    )
    return report
