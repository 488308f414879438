"""Choose the history storage format by measurement: the quantisation gate.

A history texel is rounded every time the GPU stores it, i.e. once per frame (more with chunks and
diffusion substeps). With slow decay the per-frame change is only a few units in the last place of a
half float, and round-to-nearest then drifts systematically: the same pointer path replayed at 120 FPS
ends measurably away from the 30 FPS replay. The gate replays the conformance path in the numpy reference
with each format's rounding at 30, 60 and 120 FPS and measures that drift against the unrounded float64
history. "auto" picks the most compact format whose drift stays within the half-float tolerance; an
explicitly requested format that fails is a build error, never a silent downgrade.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .params import FrostParams
from .path import FRAME_RATES, conformance_segments, frame_instants
from .reference import STORAGE_OF_FORMAT, FrostReference, Storage

#: One half-float ulp on [0.5, 1): the resolution of an RGBA16F history near full thaw. The parity tests
#: hold the GPU to this, so a format must first hold itself to it across frame rates.
HALF_FLOAT_TOLERANCE = 2.0**-11

#: Compact first: "auto" takes the first that passes.
FORMAT_ORDER = ("rgba16float", "rgba32float")

#: Small on purpose: drift is a per-texel property of the law and the frame rate, not of the grid size.
GATE_GRID = (64, 40)


@dataclass(frozen=True)
class FormatGate:
    format: str
    drift: float
    threshold: float
    per_rate: dict[int, float]

    @property
    def passed(self) -> bool:
        return self.drift <= self.threshold

    def as_dict(self) -> dict[str, Any]:
        return {
            "name": f"quantisation drift ({self.format})",
            "value": self.drift,
            "threshold": self.threshold,
            "unit": "history units",
            "status": "pass" if self.passed else "fail",
            "perFrameRate": {str(k): v for k, v in self.per_rate.items()},
        }


def replay(
    params: FrostParams, fps: int, storage: Storage, grid: tuple[int, int] = GATE_GRID
) -> FrostReference:
    """The conformance path through the reference at one frame rate."""
    reference = FrostReference(params, grid[0], grid[1], storage)
    for segment in conformance_segments():
        reference.queue(segment)
    instants = frame_instants(fps)
    for previous, current in itertools.pairwise(instants):
        reference.update(previous, current)
    return reference


def measure_format(params: FrostParams, fmt: str) -> FormatGate:
    # Diffusion's operator splitting is first order in dt by design; it is measured separately, so the
    # gate isolates what the storage format adds.
    law_only = replace(params, diffusivity=0.0)
    exact = replay(law_only, max(FRAME_RATES), "float64").state
    per_rate = {
        fps: float(np.abs(replay(law_only, fps, STORAGE_OF_FORMAT[fmt]).state - exact).max())
        for fps in FRAME_RATES
    }
    return FormatGate(fmt, max(per_rate.values()), HALF_FLOAT_TOLERANCE, per_rate)


class FormatRefusedError(Exception):
    """No storage format holds the history to the tolerance: the build refuses (exit 3) by name."""


def choose_format(params: FrostParams, requested: str) -> tuple[str, list[FormatGate]]:
    """The format to ship and the gates measured on the way; FormatRefusedError when the requested format,
    or under "auto" every format, fails its gate (a format that fails is never shipped)."""
    if requested != "auto":
        gate = measure_format(params, requested)
        if not gate.passed:
            raise FormatRefusedError(
                f"{requested} drifts {gate.drift:.3g} between 30, 60 and 120 FPS on the conformance path "
                f'(limit {gate.threshold:.3g}); use "auto" or "rgba32float", or a faster decay'
            )
        return requested, [gate]
    gates = []
    for fmt in FORMAT_ORDER:
        gate = measure_format(params, fmt)
        gates.append(gate)
        if gate.passed:
            return fmt, gates
    worst = ", ".join(f"{g.format} drifts {g.drift:.3g}" for g in gates)
    raise FormatRefusedError(
        f"no history storage format holds the conformance path within {gates[-1].threshold:.3g} between 30, "
        f"60 and 120 FPS ({worst}): use a faster decay (history.visible.survivalPerSecond) or fewer substeps"
    )
