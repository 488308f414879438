"""What ``creaturegen build`` prints about a build: the gates with their values and thresholds, posed-skin
warnings, mesh counts, the folder written and the package's packed size (``inspect --surface`` prints
the same surface gates).
"""

from __future__ import annotations

import json
from pathlib import Path

from .surface.build import SurfaceBuild
from .surface.sidecar import posed_gate_rows


def print_gates(build: SurfaceBuild) -> None:
    """Each surface gate: its value, unit, threshold and verdict."""
    for gate in build.gates:
        verdict = "pass" if gate.passed else "FAIL"
        relation = "<=" if gate.direction == "max" else ">="
        print(f"  gate {gate.name}: {gate.value:.4g} {gate.unit} ({relation} {gate.threshold:.4g}) {verdict}")


def print_surface_summary(build: SurfaceBuild) -> None:
    """Posed-skin gates that failed (recorded in the package, not enforced) and the mesh's counts."""
    for row in posed_gate_rows(build.sidecar):
        if not row.get("passed"):
            print(
                f"  warning: posed skin: {row['name']} = {row['value']:g} {row['unit']} ({row['detail']}); "
                "recorded in assets/surface.json, not enforced (--posed-gates refuse refuses the build)"
            )
    counts = build.sidecar["counts"]
    print(f"  mesh {counts}; " + ("cache hit" if build.cached else "extracted"))


def report_frost_build(folder: Path) -> None:
    """The frost build's gates (from its build-report.json), the history format chosen, the folder
    written and the package's packed size."""
    report = json.loads((folder / "build-report.json").read_text())
    for gate in report["gates"]:
        verdict = (
            "pass" if gate["status"] == "pass" else "fail, so this format is not used (a later one passed)"
        )
        print(f"  gate {gate['name']}: {gate['value']:.3g} (threshold {gate['threshold']:.3g}) {verdict}")
    print(f"  history format {report['historyFormat']['historyFormat']}")
    print(f"wrote {folder}/")
    report_pack_size(folder)


def report_creature_package(folder: Path, build: SurfaceBuild) -> None:
    """The creature package written (with its geometry digest) and its packed size."""
    digest = build.signatures["geometryDigest"]
    print(f"wrote {folder}/ (geometryDigest {digest[:12]})")
    report_pack_size(folder)


def report_pack_size(folder: Path) -> None:
    """The size ``npm pack`` gives the package (or why it could not be measured)."""
    from .emit.packsize import npm_pack_size

    size = npm_pack_size(folder)
    print(f"  {size if isinstance(size, str) else size.line()}")
