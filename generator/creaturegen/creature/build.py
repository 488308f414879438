"""Build a creature package: plan → templates + assets + build-report.json → out/<slug>/ (atomically)."""

from __future__ import annotations

import dataclasses
import hashlib
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ..emit.render import render_folder, to_json
from ..emit.writer import PackageFile, header_text, write_package
from ..motion.compiled import CompiledCreature
from ..spec import slugify
from ..surface.build import SurfaceBuild
from ..surface.emit import stable_sidecar
from ..surface.glb import glb_bytes, sidecar_bytes
from ..surface.sidecar import posed_gate_rows
from .assets import PICTURE_PATH, REPORT_PATH, SIDECAR_PATH, SPEC_PATH, shipped_files, shipped_spec
from .package_plan import PackagePlan
from .plan import TierBuild, build_plan


def _tier_rows(tiers: Sequence[TierBuild]) -> list[dict[str, Any]]:
    """The build report's line per shipped tier: its file, its size and whether its gates passed."""
    return [
        {
            "tier": t.data.tier,
            "surface": t.assets.surface_path,
            "vertices": t.data.mesh.vertices,
            "projectedSizeMaxPx": t.data.projected_size_max_px,
            "passed": t.surface.passed,
            "posedGates": posed_gate_rows(t.surface.sidecar),
        }
        for t in tiers
    ]


def build_report(
    plan: PackagePlan, surface: SurfaceBuild, tiers: Sequence[TierBuild] = ()
) -> dict[str, object]:
    return {
        "//": header_text(plan.spec_sha256),
        "kind": "creature",
        "name": plan.name,
        "package": plan.slug,
        "compilerVersion": plan.version,
        "specSha256": plan.spec_sha256,
        "signatures": plan.signatures,
        "tier": plan.tier,
        "workload": plan.workload.to_json(),
        "methods": plan.methods,
        "debugModes": list(plan.types.debug_mode),
        "candidateNote": plan.runtime.candidate_note,
        "surface": {
            "passed": surface.passed,
            "counts": surface.sidecar.get("counts"),
            # Recorded, not enforced (surface/posed.py; `creaturegen build --posed-gates refuse`).
            "posedGates": posed_gate_rows(surface.sidecar),
        },
        # Where the package's files are: Python tools read the asset path here (creature/assets.py).
        "assets": {"surface": plan.assets.surface_path, "spec": SPEC_PATH, "sidecar": SIDECAR_PATH},
        "gates": list(plan.gates),
        # Every tier the package ships, finest first (the fields above are the first's).
        "tiers": _tier_rows(tiers),
    }


def creature_files(
    creature: CompiledCreature,
    spec_bytes: bytes,
    surface: SurfaceBuild,
    picture: bool = False,
    more: Sequence[SurfaceBuild] = (),
) -> list[PackageFile]:
    """Every file of the package but the picture; with ``picture`` the README shows PICTURE_PATH. ``more``:
    the surfaces of coarser tiers shipped beside ``surface`` (one .glb each)."""
    spec_sha256 = hashlib.sha256(spec_bytes).hexdigest()
    built = build_plan(creature, surface, spec_sha256, more)
    shown = PICTURE_PATH if picture else None
    files_list = shipped_files([t.assets.surface_path for t in built.tiers], shown)
    plan = dataclasses.replace(built.plan, picture=shown, files=tuple(files_list))
    files = render_folder("creature", plan.to_json(), spec_sha256)
    # The spec (minus an unresolvable $schema): the parity job rebuilds the Python reference from it.
    files.append(PackageFile(SPEC_PATH, shipped_spec(spec_bytes)))
    for tier in built.tiers:
        glb = glb_bytes(tier.surface.asset, name=plan.slug, program=tier.program)
        files.append(PackageFile(tier.assets.surface_path, glb))
    sidecar = {"//": header_text(spec_sha256), **stable_sidecar(surface.sidecar)}
    files.append(PackageFile(SIDECAR_PATH, sidecar_bytes(sidecar)))
    files.append(
        PackageFile(REPORT_PATH, (to_json(build_report(plan, surface, built.tiers)) + "\n").encode())
    )
    return files


#: Renders a staged package folder (not yet committed) to the README picture's PNG bytes.
PictureRenderer = Callable[[Path], bytes]


def build_creature(
    creature: CompiledCreature,
    spec_bytes: bytes,
    surface: SurfaceBuild,
    out_root: Path,
    render: PictureRenderer | None = None,
    more: Sequence[SurfaceBuild] = (),
) -> Path:
    """Write the package and return its folder. With ``render`` (the lab's, lab/picture.py, handed in by
    the command line) the staged package is rendered into PICTURE_PATH before it is committed; ``more``
    are coarser tiers' surfaces shipped beside ``surface``. Nothing is written if any step raises."""
    files = creature_files(creature, spec_bytes, surface, render is not None, more)
    slug = slugify(creature.spec.name)
    if render is None:
        return write_package(out_root, slug, files, None)
    draw = render

    def add_picture(staging: Path) -> list[PackageFile]:
        return [PackageFile(PICTURE_PATH, draw(staging))]

    return write_package(out_root, slug, files, add_picture)
