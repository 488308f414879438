"""The files of a creature package beside its code: where each one lives and what exactly ships.

The surface asset is named ``assets/<slug>-<digest[:12]>.glb``, the digest of its geometry and of the
program tapes it carries (surface/glb.py), because consumers merge assets: a bundler or a copy step
that puts every package's ``assets/`` into one folder of a site must never let one creature's mesh or
programs stand in for another's (two packages that both shipped ``assets/surface.glb`` did exactly
that: the quadruped silently drew the hopper's body; two tiers of one body share a mesh, not their
programs). Python tools find the file through
:func:`surface_path`, never by spelling the name, so the rule has one definition here.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..model.record import JsonRecord

#: Folder of the package's data files, relative to the package root.
ASSET_DIR = "assets"
#: The spec the package was built from (the parity job rebuilds the Python reference from it).
SPEC_PATH = f"{ASSET_DIR}/spec.json"
#: The surface build's sidecar (gates, counts): a build diagnostic, kept beside the package, never shipped.
SIDECAR_PATH = f"{ASSET_DIR}/surface.json"
#: The build report: diagnostics beside the package, not part of what npm publishes.
REPORT_PATH = "build-report.json"
#: The README picture (rendered by the lab, lab/picture.py), shipped when the build made one.
PICTURE_PATH = f"{ASSET_DIR}/preview.png"
#: Hex digits of the asset digest in the file's name: 48 bits, unique across any realistic site.
DIGEST_DIGITS = 12


def surface_file(slug: str, geometry_digest: str, program_digest: str) -> str:
    """The .glb's file name: the package slug, its geometry and its programs, so merged asset folders
    never collide."""
    for key, digest in (("geometryDigest", geometry_digest), ("programDigest", program_digest)):
        if len(digest) < DIGEST_DIGITS or not all(c in "0123456789abcdef" for c in digest):
            raise ValueError(f"{key}: expected lowercase hex, got {digest!r}")
    both = hashlib.sha256(f"{geometry_digest}:{program_digest}".encode("ascii")).hexdigest()
    return f"{slug}-{both[:DIGEST_DIGITS]}.glb"


@dataclass(frozen=True, slots=True)
class AssetNames(JsonRecord):
    """One surface file: its name, its path in the package, and the URL relative to a module one folder
    below the root (tsl/, core/), the static literal of its ``new URL(..., import.meta.url)``."""

    surface_file: str
    surface_path: str
    surface_url: str


def asset_plan(slug: str, geometry_digest: str, program_digest: str) -> AssetNames:
    """What templates print about the assets: the file name, its path in the package, and the URL
    relative to a module one folder below the root (tsl/, core/), as the one static literal of the
    ``new URL(..., import.meta.url)`` expression that asset-aware bundlers look for."""
    name = surface_file(slug, geometry_digest, program_digest)
    return AssetNames(name, f"{ASSET_DIR}/{name}", f"../{ASSET_DIR}/{name}")


#: The code and docs every package ships (package.json "files"; npm adds package.json and README.md).
CODE_FILES = ("index.js", "index.d.ts", "core/", "tsl/", "examples/", "README.md")


def shipped_files(surfaces: list[str], picture: str | None) -> list[str]:
    """package.json ``files``: what runs and what the README shows, nothing else (``surfaces``: every
    shipped tier's .glb). The build report and the surface sidecar are diagnostics of the build; they
    stay in the folder and are never published."""
    return [*CODE_FILES, *surfaces, SPEC_PATH, *([picture] if picture else [])]


def surface_path(package: Path) -> Path:
    """The surface .glb of a built package: named by its build report, or the one .glb of ``assets/``
    when the report is absent (an installed copy, which ships no diagnostics)."""
    report = package / REPORT_PATH
    if report.is_file():
        assets: Any = json.loads(report.read_text(encoding="utf-8")).get("assets", {})
        relative = assets.get("surface") if isinstance(assets, dict) else None
        if isinstance(relative, str):
            named = package / relative
            if not named.is_file():
                raise FileNotFoundError(f"{package}: {REPORT_PATH} names a missing {relative}")
            return named
    found = sorted((package / ASSET_DIR).glob("*.glb"))
    if len(found) > 1:
        # Several tiers ship: the first named in core/data.js (the finest) is the package's surface.
        named = package / ASSET_DIR / _data_surface_file(package)
        if named.is_file():
            return named
    if len(found) != 1:
        raise FileNotFoundError(f"{package}: expected one surface .glb in {ASSET_DIR}/, found {len(found)}")
    return found[0]


def _data_surface_file(package: Path) -> str:
    """CREATURE.surfaceFile as an installed package's core/data.js holds it ("" when unreadable)."""
    try:
        text = (package / "core" / "data.js").read_text(encoding="utf-8")
        start = text.index("Object.freeze(") + len("Object.freeze(")
        data: Any = json.loads(text[start : text.rindex(");")])
    except (OSError, ValueError):
        return ""
    name = data.get("surfaceFile") if isinstance(data, dict) else None
    return name if isinstance(name, str) else ""


def shipped_spec(spec_bytes: bytes) -> bytes:
    """The spec as the package ships it: the input bytes, unless the input names a ``$schema``. That
    reference is relative to the author's checkout and resolves to nothing inside the package, so it is
    dropped and the rest written back in the author's key order (the same spec: ``$schema`` is no input
    to the compiler)."""
    document = json.loads(spec_bytes)
    if not isinstance(document, dict) or "$schema" not in document:
        return spec_bytes
    document.pop("$schema")
    return (json.dumps(document, indent=2, ensure_ascii=False, allow_nan=False) + "\n").encode("utf-8")
