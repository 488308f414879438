"""The structure file a frost package ships: four 8-bit planes, each row-filtered, in one zlib stream.

Why this format. A package used to ship the two RGBA8 maps raw (8·N² bytes; 2 MiB at N = 512). Only four
of those eight channels carry information: the structure's alpha is constant and the normal map is a pure
function of the heights (structure.py ``derive_normals``). So the file holds the planes density, thickness,
height ``H`` and detail height ``D`` (4·N² bytes before compression), and the runtime derives the normals.
Measured on examples/frost/frost-full.json (N = 512, zlib level 9): the raw maps 697 kB + 782 kB
compressed, the best PNG-style filter on the normals still 411 kB; the four planes, each with its best
filter, 410 kB in one stream (density 182 kB, thickness 26 kB, height 69 kB, detail height 128 kB alone).
Each plane's filter is chosen at build time by compressing it every way (smooth planes like the gradient
predictor, sharp crystal arms like plain left differences); one filter for all planes gives 419 kB.

Why zlib. Browsers inflate it natively and exactly (``DecompressionStream('deflate')``: Chromium, Firefox
113+, Safari 16.4+), unlike image decoders, which may premultiply alpha or convert colour. zlib carries no
timestamp (gzip would), so one spec gives one file; its Adler-32 trailer lets the runtime refuse a file
that is not this package's before inflating it.

Layout of the inflated payload: plane after plane in ``PLANES`` order, each N rows of N bytes, row 0 =
texture ``v = 0``. Filters (bytes mod 256; texels outside the plane read as 0, as in PNG):
``none`` r = x; ``sub`` r = x − left; ``up`` r = x − above; ``gradient`` r = x − (left + above − above-left).
"""

from __future__ import annotations

import hashlib
import zlib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, TypeAlias

import numpy as np
import numpy.typing as npt

from .structure import NormalScale, StructureMaps, derive_normals

__all__ = ["FILTERS", "PLANES", "ZLIB_LEVEL", "StructureFile", "decode_structure_file", "encode_structure"]

U8: TypeAlias = npt.NDArray[np.uint8]
I16: TypeAlias = npt.NDArray[np.int16]

#: The planes, in file order; the runtime builds structure RGBA = (density, thickness, height, 255).
PLANES = ("density", "thickness", "height", "detailHeight")
#: Row filters a plane may use (the runtime knows exactly these).
FILTERS = ("none", "sub", "up", "gradient")
#: Fixed, so one spec compresses to one file on one zlib build.
ZLIB_LEVEL = 9
#: Filters are ranked at this level: it ranks them as level 9 does on the example planes at 10× less time
#: (level 9 spends seconds per candidate on the smooth planes of a 2048 bake).
CHOICE_LEVEL = 6


@dataclass(frozen=True)
class StructureFile:
    """The compressed file and what the runtime needs to check and decode it."""

    data: bytes
    resolution: int
    filters: tuple[str, ...]
    main: NormalScale
    fine: NormalScale

    @property
    def sha256(self) -> str:
        return hashlib.sha256(self.data).hexdigest()

    @property
    def adler32(self) -> int:
        """Adler-32 of the inflated payload: the last four bytes of the zlib stream, big-endian."""
        return int.from_bytes(self.data[-4:], "big")

    def layout(self, file_name: str) -> dict[str, Any]:
        """The plan's description of this file (plain JSON data; core/structure-file.js reads it)."""
        return {
            "file": file_name,
            "bytes": len(self.data),
            "adler32": self.adler32,
            "sha256": self.sha256,
            "resolution": self.resolution,
            "planes": list(PLANES),
            "filters": list(self.filters),
            "normals": {"main": self.main.as_plan(), "detail": self.fine.as_plan()},
        }


def _neighbours(plane: I16) -> tuple[I16, I16, I16]:
    """Left, above and above-left of every texel, 0 outside the plane."""
    left = np.zeros_like(plane)
    left[:, 1:] = plane[:, :-1]
    above = np.zeros_like(plane)
    above[1:, :] = plane[:-1, :]
    corner = np.zeros_like(plane)
    corner[1:, 1:] = plane[:-1, :-1]
    return left, above, corner


def filter_plane(plane: U8, name: str) -> U8:
    """The residual bytes of ``plane`` under filter ``name`` (see the module docstring)."""
    x = plane.astype(np.int16)
    left, above, corner = _neighbours(x)
    prediction = {
        "none": np.zeros_like(x),
        "sub": left,
        "up": above,
        "gradient": left + above - corner,
    }[name]
    residual: U8 = np.mod(x - prediction, 256).astype(np.uint8)
    return residual


def unfilter_plane(residual: U8, name: str) -> U8:
    """Invert ``filter_plane``: running sums mod 256 (uint8 accumulation wraps).

    The gradient filter factors into two sums: with ``d[y, x] = p[y, x] − p[y, x − 1]`` the predictor gives
    ``d[y, x] = r[y, x] + d[y − 1, x]``, so ``d`` sums ``r`` down the columns and ``p`` sums ``d`` along rows.
    """
    if name == "none":
        return residual.copy()
    if name == "sub":
        return np.cumsum(residual, axis=1, dtype=np.uint8)
    if name == "up":
        return np.cumsum(residual, axis=0, dtype=np.uint8)
    if name == "gradient":
        return np.cumsum(np.cumsum(residual, axis=0, dtype=np.uint8), axis=1, dtype=np.uint8)
    raise ValueError(f"unknown structure-file filter {name!r} (known: {', '.join(FILTERS)})")


def _planes(maps: StructureMaps) -> list[U8]:
    return [maps.structure[..., 0], maps.structure[..., 1], maps.structure[..., 2], maps.detail]


def best_filter(plane: U8) -> tuple[str, U8]:
    """The filter whose residual compresses smallest at ``CHOICE_LEVEL`` (ties: the first in ``FILTERS``)."""
    candidates = [(name, filter_plane(plane, name)) for name in FILTERS]
    sizes = [len(zlib.compress(residual.tobytes(), CHOICE_LEVEL)) for _, residual in candidates]
    return candidates[sizes.index(min(sizes))]


def encode_structure(maps: StructureMaps) -> StructureFile:
    """Filter each plane the way it compresses best and deflate them together."""
    chosen = [best_filter(np.ascontiguousarray(plane)) for plane in _planes(maps)]
    payload = b"".join(residual.tobytes() for _, residual in chosen)
    return StructureFile(
        data=zlib.compress(payload, ZLIB_LEVEL),
        resolution=maps.resolution,
        filters=tuple(name for name, _ in chosen),
        main=maps.main,
        fine=maps.fine,
    )


def decode_structure_file(data: bytes, layout: Mapping[str, Any]) -> tuple[U8, U8]:
    """The structure and normal maps (N × N × 4 each) a shipped file decodes to, as the runtime builds them.

    ``layout`` is the plan's ``assets.structure``. This is the Python twin of core/structure-file.js; the
    parity job reads the shipped file through it, so what it compares is what the GPU was given.
    """
    n = int(layout["resolution"])
    if len(data) != int(layout["bytes"]) or int.from_bytes(data[-4:], "big") != int(layout["adler32"]):
        raise ValueError("structure file does not match its layout (size, Adler-32): not this package's file")
    payload = np.frombuffer(zlib.decompress(data), dtype=np.uint8)
    if payload.size != len(PLANES) * n * n:
        raise ValueError(f"structure file inflates to {payload.size} bytes, expected {len(PLANES) * n * n}")
    residuals = payload.reshape(len(PLANES), n, n)
    density, thickness, height, detail = (
        unfilter_plane(residual, name) for residual, name in zip(residuals, layout["filters"], strict=True)
    )
    structure = np.stack([density, thickness, height, np.full_like(density, 255)], axis=-1)
    scales = layout["normals"]
    main = NormalScale(int(scales["main"]["spacing"]), float(scales["main"]["scale"]))
    fine = NormalScale(int(scales["detail"]["spacing"]), float(scales["detail"]["scale"]))
    return structure, derive_normals(height, detail, main, fine)
