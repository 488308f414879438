"""The gallery's thumbnails: a CPU picture (preview.py) of each creature's first built tier, drawn on the
client from the package in OUT, redrawn only when the surface it shows changed (the file's name carries
the package's geometryDigest)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from ..creature.assets import surface_path
from ..rig import RigCompileError, compile_rig
from ..spec import CharacterSpec, SpecValidationError, validate_bytes
from .preview import write_preview
from .specs import BatchSpec

#: The tier a card's picture comes from when several were built.
PICTURE_TIERS = ("hero", "repeated", "distant")


def _picture(out: Path, spec: BatchSpec, record: dict[str, Any], folder: Path) -> str | None:
    digest = str(record.get("signatures", {}).get("geometryDigest", ""))[:12]
    name = f"{spec.id}-{digest}.png"
    target = folder / name
    if target.is_file():
        return name
    try:
        parsed = validate_bytes(spec.data, spec.path)
        if not isinstance(parsed, CharacterSpec):
            return None
        write_preview(compile_rig(parsed), surface_path(out / record["package"]), target)
    except (OSError, ValueError, KeyError, SpecValidationError, RigCompileError) as exc:
        print(f"  no picture for {spec.id}: {exc}", file=sys.stderr)
        return None
    return name


def draw_pictures(out: Path, specs: list[BatchSpec], records: list[dict[str, Any]]) -> dict[str, str]:
    """``{spec id: file name under OUT/pictures/}`` for every creature with a built package."""
    folder = out / "pictures"
    folder.mkdir(exist_ok=True)
    built: dict[str, dict[str, dict[str, Any]]] = {}
    for record in records:
        if record.get("status") == "built":
            built.setdefault(record["id"], {})[record["tier"]] = record
    pictures = {}
    for spec in specs:
        tiers = built.get(spec.id, {})
        first = [tiers[t] for t in PICTURE_TIERS if t in tiers]
        if spec.kind == "creature" and first:
            record = first[0]
            name = _picture(out, spec, record, folder)
            if name is not None:
                pictures[spec.id] = name
    return pictures
