"""The specs of a batch: the files and folders named on the command line, read once and validated on the
client, so an invalid spec is recorded once (not once per tier) and workers receive bytes, not paths (a
worker on another machine has no copy of the user's folder).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..spec import (
    CharacterSpec,
    SpecValidationError,
    format_error,
    read_spec_bytes,
    slugify,
    validate_bytes,
)


class BatchInputError(ValueError):
    """A path on the command line that names no spec: one line, exit 2, nothing built."""


@dataclass(frozen=True)
class BatchSpec:
    """One input spec. ``id`` is unique in the batch: the package slug, ``-2``, ``-3`` … when two specs
    share a name (two files of one bestiary both called "Beetle"), so their packages never overwrite."""

    id: str
    path: str
    data: bytes
    kind: str  # "creature", "frost" or "invalid"
    name: str
    errors: tuple[str, ...] = ()
    info: dict[str, object] = field(default_factory=dict, compare=False, hash=False)


def spec_files(named: Sequence[str], exclude: Path | None = None) -> list[Path]:
    """Every ``.json`` under the named folders (sorted, hidden folders and ``exclude`` left out) and every
    named file, each once, in the order named."""
    out: list[Path] = []
    seen: set[Path] = set()
    skip = exclude.resolve() if exclude is not None else None
    for name in named:
        path = Path(name)
        if path.is_dir():
            found = [
                p
                for p in sorted(path.rglob("*.json"))
                if not any(part.startswith(".") for part in p.relative_to(path).parts)
                and (skip is None or not p.resolve().is_relative_to(skip))
            ]
            if not found:
                raise BatchInputError(f"{name}: a folder with no .json spec in it")
        elif path.exists():
            found = [path]
        else:
            raise BatchInputError(f"{name}: no such file or folder")
        for p in found:
            if p.resolve() not in seen:
                seen.add(p.resolve())
                out.append(p)
    return out


def _read(path: Path) -> tuple[bytes, str, str, tuple[str, ...], dict[str, object]]:
    """(bytes, kind, display name, errors, card info) of one file."""
    source = str(path)
    data = b""
    try:
        data = read_spec_bytes(path)
        spec = validate_bytes(data, source)
    except SpecValidationError as exc:
        return data, "invalid", path.stem, tuple(format_error(source, e) for e in exc.errors), {}
    if isinstance(spec, CharacterSpec):
        info: dict[str, object] = {
            "locomotion": spec.locomotion.type if spec.locomotion else "none",
            "parts": len(spec.parts),
            "scale": spec.scale,
            "blend": spec.blend.mode if spec.blend else "default",
        }
        return data, "creature", spec.name, (), info
    return data, "frost", spec.name, (), {}


def load_batch(files: Sequence[Path]) -> list[BatchSpec]:
    """The batch's specs, with unique ids in input order."""
    taken: dict[str, int] = {}
    out = []
    for path in files:
        data, kind, name, errors, info = _read(path)
        base = slugify(name) or slugify(path.stem) or "spec"
        taken[base] = taken.get(base, 0) + 1
        unique = base if taken[base] == 1 else f"{base}-{taken[base]}"
        while unique in taken and unique != base:
            taken[base] += 1
            unique = f"{base}-{taken[base]}"
        taken.setdefault(unique, 1)
        out.append(BatchSpec(unique, str(path), data, kind, name, errors, info))
    return out
