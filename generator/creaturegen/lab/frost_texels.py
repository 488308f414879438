"""Frost parity gates on the structure texture, against the package's shipped structure file:

- structure texels: the structure and normal textures read back from the GPU (one textureLoad per texel)
  equal, code for code, the numpy decode of the package's structure file (the runtime inflates it and
  derives the normals in JavaScript; creaturegen.frost.structure_file does the same in numpy);
- mirrored wrap: the structure view read back around a wrap line is symmetric and matches the numpy
  mirrored-repeat bilinear sample of the shipped data (the package's structure file, decoded by
  creaturegen.frost.structure_file as the runtime decodes it); a plain-repeat prediction does not.
"""

from __future__ import annotations

import base64
import json
from pathlib import Path

import numpy as np
import numpy.typing as npt

from ..frost.structure_file import decode_structure_file
from .frost_session import FrostLab
from .report import ParityReport

#: 8-bit output codes allowed between the GPU's filtered sample and numpy's (sub-texel weight precision).
PIXEL_CODES = 3

Array = npt.NDArray[np.float64]


def srgb_encode(linear: Array) -> Array:
    x = np.clip(linear, 0.0, 1.0)
    return np.asarray(np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055))


def sample_bilinear(channel: Array, s: Array, t: Array, mirrored: bool) -> Array:
    """Texture lookup at normalised coords (s, t) with mirrored-repeat or repeat addressing, per tap."""
    n = channel.shape[0]

    def wrap(i: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
        if not mirrored:
            return np.asarray(np.mod(i, n), dtype=np.int64)
        m = np.mod(i, 2 * n)
        return np.asarray(np.where(m < n, m, 2 * n - 1 - m), dtype=np.int64)

    x, y = s * n - 0.5, t * n - 0.5
    x0, y0 = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    fx, fy = x - x0, y - y0
    top = channel[wrap(y0)][:, wrap(x0)] * (1 - fx) + channel[wrap(y0)][:, wrap(x0 + 1)] * fx
    bottom = channel[wrap(y0 + 1)][:, wrap(x0)] * (1 - fx) + channel[wrap(y0 + 1)][:, wrap(x0 + 1)] * fx
    return np.asarray(top * (1 - fy[:, None]) + bottom * fy[:, None])


def shipped_structure(package: Path) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
    """The structure and normal maps of a built package, decoded from its shipped structure file."""
    layout = json.loads((package / "build-report.json").read_text())["assets"]["structure"]
    return decode_structure_file((package / "assets" / layout["file"]).read_bytes(), layout)


def structure_gate(lab: FrostLab, package: Path, report: ParityReport) -> None:
    structure, normals = shipped_structure(package)
    raw = lab.call("() => window.__lab.readStructure()")
    n = int(raw["resolution"])
    for key, expected in (("structure", structure), ("normals", normals)):
        gpu = np.frombuffer(base64.b64decode(raw[key]), dtype=np.uint8)
        gpu = gpu.reshape(n, n, 4)
        error = int(np.abs(gpu.astype(np.int16) - expected.astype(np.int16)).max())
        report.gate(f"GPU {key} texels vs numpy decode of the shipped file", error, 0, "8-bit codes")


def mirror_gate(lab: FrostLab, package: Path, report: ParityReport, canvas: tuple[int, int]) -> None:
    plan = json.loads((package / "build-report.json").read_text())
    data, _ = shipped_structure(package)
    period = canvas[0] / 2
    lab.call("(p) => window.__lab.setControl('mainScreenPeriod', p)", period)
    shot = lab.capture("structure").astype(np.float64)
    lab.call("(p) => window.__lab.setControl('mainScreenPeriod', p)", float(plan["mainScreenPeriod"]))
    width, height = canvas
    s = np.asarray((np.arange(width) + 0.5) / period, dtype=np.float64)
    t = np.asarray((np.arange(height) + 0.5) / period, dtype=np.float64)
    channel = data[..., 0].astype(np.float64) / 255.0
    mirrored = np.round(srgb_encode(sample_bilinear(channel, s, t, mirrored=True)) * 255.0)
    repeated = np.round(srgb_encode(sample_bilinear(channel, s, t, mirrored=False)) * 255.0)
    grey = shot[..., 0]
    wrap = width // 2
    band = slice(wrap - 6, wrap + 6)
    mirror_error = float(np.abs(grey[:, band] - mirrored[:, band]).max())
    repeat_error = float(np.abs(grey[:, band] - repeated[:, band]).max())
    symmetry = float(np.abs(grey[:, wrap - 6 : wrap][:, ::-1] - grey[:, wrap : wrap + 6]).max())
    report.gate(
        "structure view vs numpy mirrored-repeat sample (wrap band)", mirror_error, PIXEL_CODES, "8-bit codes"
    )
    report.gate("mirror symmetry across the wrap line", symmetry, PIXEL_CODES, "8-bit codes")
    report.gate(
        "plain-repeat prediction is rejected at the wrap line",
        repeat_error,
        PIXEL_CODES,
        "8-bit codes",
        passed=repeat_error > PIXEL_CODES,
    )
