"""What ``npm pack`` of a written package weighs: the figure a user sees before publishing it.

npm decides what ships (``files``, always-included README and package.json), so the real ``npm pack
--dry-run --json`` is asked when npm is installed; without npm the build says so rather than guessing.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import Any


@dataclass(frozen=True)
class PackSize:
    files: int
    packed_bytes: int
    unpacked_bytes: int

    def line(self) -> str:
        return (
            f"npm pack: {self.files} files, {self.packed_bytes / 1024:.1f} kB packed, "
            f"{self.unpacked_bytes / 1024:.1f} kB unpacked"
        )


def npm_json(stdout: str) -> Any:
    """The JSON document of an ``npm … --json`` run: npm may print config warnings around it (seen with
    an unknown key in a user's .npmrc), so decoding starts at the document and ignores what follows."""
    start = min((i for i in (stdout.find("["), stdout.find("{")) if i >= 0), default=-1)
    if start < 0:
        raise ValueError("npm printed no JSON")
    value, _ = json.JSONDecoder().raw_decode(stdout[start:])
    return value


def npm_pack_size(folder: Path) -> PackSize | str:
    """The dry-run figures of ``npm pack`` in ``folder``, or why they could not be had."""
    npm = shutil.which("npm")
    if npm is None:
        return "npm pack size not measured: npm is not installed"
    done = subprocess.run(
        [npm, "pack", "--dry-run", "--json", "--ignore-scripts"],
        cwd=folder,
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    try:
        entry = npm_json(done.stdout)[0]
        return PackSize(int(entry["entryCount"]), int(entry["size"]), int(entry["unpackedSize"]))
    except (ValueError, KeyError, IndexError, TypeError):
        return f"npm pack size not measured: npm pack --dry-run failed ({done.stderr.strip()[-200:]})"
