"""The package README's picture: `creaturegen build --picture on` renders the staged package in the lab
(headless Chromium, WebGPU on SwiftShader) into assets/preview.png before committing it; the picture shows
the body, a rebuild is byte-identical (the picture included), `--picture off` leaves it out and says so,
and a picture that cannot be rendered fails the build with nothing written."""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

from conftest import EXAMPLES, REPO, run_cli
from creaturegen.lab.picture import PICTURE_PATH, PICTURE_SIZE
from creaturegen.spec import slugify

HOPPER = EXAMPLES / "reference" / "hopper.json"
SLUG = slugify(json.loads(HOPPER.read_text())["name"])


def _decode_png(data: bytes) -> np.ndarray:
    """RGBA8 non-interlaced PNG (what lab/png.py writes) to (H, W, 4), filter type 0 rows only."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        length = int.from_bytes(data[pos : pos + 4], "big")
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            width, height = int.from_bytes(body[:4], "big"), int.from_bytes(body[4:8], "big")
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = np.frombuffer(zlib.decompress(idat), dtype=np.uint8).reshape(height, 1 + 4 * width)
    assert (raw[:, 0] == 0).all()
    return raw[:, 1:].reshape(height, width, 4)


def _tree_digest(folder: Path) -> dict[str, str]:
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


@pytest.mark.browser
def test_build_renders_the_readme_picture_reproducibly(tmp_path: Path) -> None:
    first = run_cli("build", str(HOPPER), "-o", str(tmp_path / "a"), "--picture", "on")
    assert first.returncode == 0, first.stdout[-2000:] + first.stderr[-4000:]
    assert f"==> picture: {PICTURE_PATH}" in first.stdout
    package = tmp_path / "a" / SLUG
    rgba = _decode_png((package / PICTURE_PATH).read_bytes())
    assert rgba.shape == (PICTURE_SIZE[1], PICTURE_SIZE[0], 4)
    # The body fills a good part of the frame: pixels far from the background colour (the corner pixel).
    background = rgba[0, 0, :3].astype(int)
    body = np.abs(rgba[..., :3].astype(int) - background).sum(axis=2) > 60
    assert 0.05 < body.mean() < 0.9, body.mean()
    readme = (package / "README.md").read_text()
    assert f"]({PICTURE_PATH})" in readme
    second = run_cli("build", str(HOPPER), "-o", str(tmp_path / "b"), "--picture", "on")
    assert second.returncode == 0, second.stderr[-4000:]
    assert _tree_digest(package) == _tree_digest(tmp_path / "b" / SLUG)


def test_picture_off_builds_without_it_and_says_so(tmp_path: Path) -> None:
    result = run_cli("build", str(HOPPER), "-o", str(tmp_path), "--picture", "off")
    assert result.returncode == 0, result.stderr[-4000:]
    package = tmp_path / SLUG
    assert not (package / PICTURE_PATH).exists()
    readme = (package / "README.md").read_text()
    assert PICTURE_PATH in readme
    assert f"]({PICTURE_PATH})" not in readme


def test_a_picture_that_cannot_render_fails_the_build_and_writes_nothing(tmp_path: Path) -> None:
    env = {**os.environ, "CREATUREGEN_CHROMIUM": str(tmp_path / "no-such-chromium")}
    out = tmp_path / "out"
    result = subprocess.run(
        [sys.executable, "-m", "creaturegen.cli", "build", str(HOPPER), "-o", str(out), "--picture", "on"],
        capture_output=True,
        text=True,
        check=False,
        cwd=REPO,
        env=env,
    )
    assert result.returncode == 1, result.stdout + result.stderr
    assert "cannot render the README picture" in result.stderr
    assert "--picture off" in result.stderr
    assert not out.exists() or not any(out.iterdir())
