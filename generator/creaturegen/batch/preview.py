"""A small CPU picture of a built creature for the corpus gallery.

The package's own README picture is rendered by the lab in Chromium, which costs seconds per creature on
SwiftShader; a gallery of hundreds of creatures wants a thumbnail in milliseconds. This one splats the
extracted reference mesh's vertices (dense: a vertex per lattice edge crossing) with their analytic normals
and the field's rest colour, nearest last, in a three-quarter orthographic view. It shows the shape the
build certified; it is not evidence of the GPU path (the lab's picture and parity job are).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt

from ..field.sampler import sample
from ..lab.png import write_png
from ..rig import CompiledRig
from ..surface.glb import read_glb

#: View direction (towards the camera) and light direction, creature space (Y up, +Z forward).
VIEW = np.array([0.75, 0.45, 0.95])
LIGHT = np.array([0.4, 0.8, 0.45])
BACKGROUND = np.array([238, 240, 244], dtype=np.uint8)


def _basis() -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    back = VIEW / np.linalg.norm(VIEW)
    right = np.cross([0.0, 1.0, 0.0], back)
    right /= np.linalg.norm(right)
    up = np.cross(back, right)
    return right, up, back


def render_preview(rig: CompiledRig, glb: Path, size: int = 192) -> npt.NDArray[np.uint8]:
    """(size, size, 4) sRGB RGBA picture of the rest mesh stored in ``glb``."""
    asset = read_glb(glb)
    points = np.asarray(asset.positions, dtype=np.float64)
    normals = np.asarray(asset.normals, dtype=np.float64)
    colour = np.clip(sample(rig, points).color, 0.0, 1.0)
    right, up, back = _basis()
    x, y, depth = points @ right, points @ up, points @ back
    lo = np.array([x.min(), y.min()])
    span = float(max(x.max() - lo[0], y.max() - lo[1], 1e-9))
    margin = 0.06 * size
    scale = (size - 2 * margin) / span
    offset = (size - scale * np.array([x.max() - lo[0], y.max() - lo[1]])) / 2
    px = np.clip((offset[0] + (x - lo[0]) * scale).astype(np.int64), 0, size - 2)
    py = np.clip((size - 1 - offset[1] - (y - lo[1]) * scale).astype(np.int64), 0, size - 2)
    light = LIGHT / np.linalg.norm(LIGHT)
    shade = 0.35 + 0.65 * np.clip(normals @ light, 0.0, 1.0)
    linear = colour * shade[:, None]
    srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1 / 2.4) - 0.055)
    rgb = np.clip(np.round(srgb * 255.0), 0, 255).astype(np.uint8)
    image = np.empty((size, size, 4), dtype=np.uint8)
    image[..., :3] = BACKGROUND
    image[..., 3] = 255
    order = np.argsort(depth, kind="stable")  # farthest first: nearer splats overwrite
    rows = np.concatenate([py[order] + dy for dy in (0, 1) for _ in (0, 1)]).reshape(4, -1).T.reshape(-1)
    cols = np.concatenate([px[order] + dx for _ in (0, 1) for dx in (0, 1)]).reshape(4, -1).T.reshape(-1)
    image[rows, cols, :3] = np.repeat(rgb[order], 4, axis=0)
    return image


def write_preview(rig: CompiledRig, glb: Path, out: Path, size: int = 192) -> Path:
    return write_png(out, render_preview(rig, glb, size))
