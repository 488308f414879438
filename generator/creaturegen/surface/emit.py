"""The surface's files inside a creature package: assets/surface.glb, assets/surface.json, build-report.json.

The package must be byte-identical for the same spec and version, so what goes in carries no measured
times and no word of which sampling backend ran (the backend cannot change the mesh: surface/sampling.py
settles every sign in float64). Those measurements stay in the cache sidecar and the build's output.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from ..emit.render import to_json
from ..emit.writer import PackageFile, header_text, write_package
from ..spec import slugify
from .asset import glb_bytes, sidecar_bytes
from .build import SurfaceBuild

#: Sidecar entries that vary from run to run on the same input.
VOLATILE = ("timings",)
VOLATILE_SAMPLING = ("backend", "choice", "seconds")
VOLATILE_DEFORMATION = ("seconds",)


def stable_sidecar(sidecar: dict[str, object]) -> dict[str, object]:
    out = {k: v for k, v in sidecar.items() if k not in VOLATILE}
    for key, drop in (("sampling", VOLATILE_SAMPLING), ("deformation", VOLATILE_DEFORMATION)):
        value = out.get(key)
        if isinstance(value, dict):
            out[key] = {k: v for k, v in value.items() if k not in drop}
    return out


def surface_files(name: str, spec_bytes: bytes, build: SurfaceBuild) -> list[PackageFile]:
    spec_sha = hashlib.sha256(spec_bytes).hexdigest()
    sidecar = stable_sidecar(build.sidecar)
    report = {
        "//": header_text(spec_sha),
        "kind": "creature",
        "name": name,
        "package": slugify(name),
        "specSha256": spec_sha,
        "surface": {
            "tier": build.tier,
            "signatures": build.signatures,
            "gates": [g.as_dict() for g in build.gates],
            "passed": build.passed,
        },
        "emitter": "surface only; the creature runtime (core/, tsl/, index.js) is not emitted yet",
    }
    return [
        PackageFile("assets/surface.glb", glb_bytes(build.asset, name=slugify(name))),
        PackageFile("assets/surface.json", sidecar_bytes(sidecar)),
        PackageFile("build-report.json", (to_json(report) + "\n").encode()),
    ]


def write_surface_package(out_root: Path, name: str, spec_bytes: bytes, build: SurfaceBuild) -> Path:
    return write_package(out_root, slugify(name), surface_files(name, spec_bytes, build))
