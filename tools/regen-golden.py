#!/usr/bin/env python3
"""Regenerate tests/golden/: the committed byte-for-byte record of generated packages.

    .venv/bin/python tools/regen-golden.py          # rebuild every case and rewrite its record (make golden)
    .venv/bin/python tools/regen-golden.py --check  # rebuild and compare only; exit 1 when stale

A record is ``tests/golden/<case>/package/<file>`` for every generated text file of the package, exactly
as built, plus ``tests/golden/<case>/binary-sha256.json`` naming the size and sha256 of each binary file
(the .glb), so the record stays reviewable and small. A file the build copies from its template verbatim
(the generated-code header, then the template's bytes) is not stored a second time: ``verbatim.json``
names it with its header line, and a build that stops copying it verbatim no longer matches the record.
So a hand edit to a plain JS template needs no new record; a rendered (``.j2``) file still does.
tests/test_creature_package.py rebuilds the package
and compares it with the record; the record changes legitimately whenever a template or the compiler
does, and then this script is the one command to run (review the diff, commit tests/golden/).

Builds go through the command line (``python -m creaturegen.cli build``), exactly as a user runs it; the
surface cache ($CREATUREGEN_CACHE) makes a rebuild take seconds. The record is built with ``--picture off``:
the README picture is a rendering whose pixels depend on the browser's software rasteriser build, so it
would tie the record to one Chromium; tests/test_creature_picture.py proves it reproducible on one machine.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
GOLDEN = REPO / "tests" / "golden"
#: case -> spec (relative to the repository); a case is a folder under tests/golden/.
CASES = {"creature-hopper": "examples/reference/hopper.json"}
PACKAGE = "package"
BINARY_MANIFEST = "binary-sha256.json"
VERBATIM_MANIFEST = "verbatim.json"
TEMPLATES = REPO / "generator" / "creaturegen" / "templates"
#: Files stored as they are; anything else is recorded by size and sha256.
TEXT_SUFFIXES = (".js", ".mjs", ".ts", ".md", ".json")
REGENERATE = "make golden"


def build(spec: Path, out: Path) -> Path:
    """Build ``spec`` into ``out`` with the command line; returns the package folder."""
    done = subprocess.run(
        [sys.executable, "-m", "creaturegen.cli", "build", str(spec), "-o", str(out), "--picture", "off"],
        capture_output=True,
        text=True,
        check=False,
        cwd=REPO,
    )
    if done.returncode != 0:
        raise RuntimeError(
            f"creaturegen build {spec} failed ({done.returncode}):\n{done.stdout}{done.stderr}"
        )
    folders = [p for p in out.iterdir() if p.is_dir()]
    if len(folders) != 1:
        raise RuntimeError(f"expected one package folder in {out}, found {[p.name for p in folders]}")
    return folders[0]


def binary_entry(content: bytes) -> dict[str, object]:
    return {"bytes": len(content), "sha256": hashlib.sha256(content).hexdigest()}


def _verbatim_header(content: bytes, template: Path) -> str | None:
    """The header line when ``content`` is ``template`` copied as it is (after an optional generated-code
    header line), else None."""
    if not template.is_file():
        return None
    source = template.read_bytes()
    if content == source:
        return ""
    first, _, rest = content.partition(b"\n")
    return first.decode() if rest == source and first.startswith(b"// Code generated") else None


def record(package: Path) -> dict[str, bytes]:
    """The record of a built package: ``{path under tests/golden/<case>/: bytes}``."""
    kind = json.loads((package / "build-report.json").read_text())["kind"]
    files: dict[str, bytes] = {}
    binaries: dict[str, object] = {}
    verbatim: dict[str, str] = {}
    for path in sorted(p for p in package.rglob("*") if p.is_file()):
        relative = path.relative_to(package).as_posix()
        content = path.read_bytes()
        if path.suffix in TEXT_SUFFIXES:
            header = _verbatim_header(content, TEMPLATES / kind / relative)
            if header is None:
                files[f"{PACKAGE}/{relative}"] = content
            else:
                verbatim[relative] = header
        else:
            binaries[relative] = binary_entry(content)
    note = f"Written by tools/regen-golden.py; run `{REGENERATE}` to update."
    manifest = {"//": note, "files": binaries}
    files[BINARY_MANIFEST] = (json.dumps(manifest, indent=2, sort_keys=True) + "\n").encode()
    copies = {"//": note + f" Each file is templates/{kind}/<path> after its header line.", "files": verbatim}
    files[VERBATIM_MANIFEST] = (json.dumps(copies, indent=2, sort_keys=True) + "\n").encode()
    return files


def stored(case: str) -> dict[str, bytes]:
    """The committed record of ``case`` (empty when there is none)."""
    folder = GOLDEN / case
    if not folder.is_dir():
        return {}
    return {
        p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()
    }


def differences(expected: dict[str, bytes], actual: dict[str, bytes]) -> list[str]:
    """One line per differing path: missing from the build, new in the build, or changed (first line)."""
    lines = []
    for path in sorted(set(expected) | set(actual)):
        if path not in actual:
            lines.append(f"{path}: in the record, not in the build")
        elif path not in expected:
            lines.append(f"{path}: in the build, not in the record")
        elif expected[path] != actual[path]:
            old, new = expected[path].split(b"\n"), actual[path].split(b"\n")
            at = next(
                (i for i, (a, b) in enumerate(zip(old, new, strict=False)) if a != b), min(len(old), len(new))
            )
            was = old[at][:120] if at < len(old) else b"<end of file>"
            now = new[at][:120] if at < len(new) else b"<end of file>"
            lines.append(f"{path}:{at + 1}: record {was!r}, build {now!r}")
    return lines


def write_record(case: str, files: dict[str, bytes]) -> Path:
    folder = GOLDEN / case
    if folder.exists():
        shutil.rmtree(folder)
    for relative, content in files.items():
        target = folder / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(content)
    return folder


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--check", action="store_true", help="compare only; exit 1 if a record is stale")
    parser.add_argument("cases", nargs="*", default=sorted(CASES), help=f"cases (default: {' '.join(CASES)})")
    args = parser.parse_args(argv)
    unknown = [c for c in args.cases if c not in CASES]
    if unknown:
        parser.error(f"unknown case(s) {unknown}; known: {sorted(CASES)}")
    stale = 0
    for case in args.cases:
        with tempfile.TemporaryDirectory(prefix="golden-") as tmp:
            files = record(build(REPO / CASES[case], Path(tmp)))
        if args.check:
            diff = differences(stored(case), files)
            stale += bool(diff)
            print(f"{case}: " + ("stale\n  " + "\n  ".join(diff) if diff else "up to date"))
        else:
            folder = write_record(case, files)
            print(f"wrote {folder.relative_to(REPO)}/ ({len(files)} files)")
    if stale:
        print(f"run `{REGENERATE}` if the changes are intended, and commit tests/golden/", file=sys.stderr)
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
