"""Build a frost package: plan → templates + assets + build-report.json → out/<slug>/ (atomically).

build-report.json stays beside the package as build diagnostics; package.json's ``files`` leaves it out of
what ``npm pack`` publishes.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

from ..emit.render import render_folder, to_json
from ..emit.writer import PackageFile, header_text, write_package
from ..spec.frost import FrostEffectSpec
from .plan import build_plan


def build_report(plan: dict[str, Any]) -> dict[str, Any]:
    return {
        "//": header_text(str(plan["specSha256"])),
        "kind": "frost",
        "name": plan["name"],
        "package": plan["slug"],
        "compilerVersion": plan["version"],
        "specSha256": plan["specSha256"],
        "historyFormat": plan["tier"],
        "structureSha256": plan["structure"]["sha256"],
        "memory": plan["memory"],
        "params": plan["params"],
        "debugViews": plan["debugViews"],
        "structure": plan["structure"],
        "assets": plan["assets"],
        "mainScreenPeriod": plan["refraction"]["mainScreenPeriod"],
        "gates": plan["gates"],
    }


def build_frost(spec: FrostEffectSpec, spec_bytes: bytes, out_root: Path) -> Path:
    """Write the package and return its folder. Nothing is written if any step raises."""
    spec_sha256 = hashlib.sha256(spec_bytes).hexdigest()
    built = build_plan(spec, spec_sha256)
    files = render_folder("frost", built.plan, spec_sha256)
    structure_asset = f"assets/{built.plan['assets']['structure']['file']}"
    files.append(PackageFile(structure_asset, built.structure_file.data))
    files.append(PackageFile("build-report.json", (to_json(build_report(built.plan)) + "\n").encode()))
    return write_package(out_root, str(built.plan["slug"]), files)
