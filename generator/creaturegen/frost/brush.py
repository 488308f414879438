"""Pointer segments and the swept-capsule brush, on the history grid.

Grid conventions shared with the GPU kernels (the package README repeats them):
- History UV has its origin at the top-left texel corner, u right, v down: the same orientation as
  three's ``screenUV`` on WebGPU. Texel (i, j) is column i, row j; its centre is ((i + ½)/W, (j + ½)/H).
- Distances are measured in history-height units: u is scaled by the aspect W/H, so a brush is round on
  screen whatever the history's shape, and the aspect always comes from the history texture itself.
- A segment's coverage is the whole swept capsule from start to end, held for the segment's time span with
  the average of its two pressures. Holding one coverage over the span is what keeps the input piecewise
  constant in time, so the closed-form law composes exactly however frames cut the span.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .law import Array

U32 = npt.NDArray[np.uint32]

#: Channel salts of the deposit-noise hash (R visible, A tilt).
NOISE_SALT = (0x68E31DA4, 0xB5297A4D)


@dataclass(frozen=True)
class Segment:
    """One pointer move between two timestamped samples; positions in history UV, pressures in [0, 1].

    ``stream`` names the pointer it came from (a finger, a pen, a mouse: attachPointer uses the pointerId):
    segments of one stream are time-ordered and disjoint, segments of different streams may overlap in
    time (several strokes at once), and a texel under several of them at once takes the largest coverage.
    """

    t0: float
    t1: float
    start: tuple[float, float]
    end: tuple[float, float]
    pressure0: float = 1.0
    pressure1: float = 1.0
    stream: int = 0

    @property
    def pressure(self) -> float:
        return 0.5 * (self.pressure0 + self.pressure1)


def pointer_uv(ndc_x: float, ndc_y: float) -> tuple[float, float]:
    """NDC in [−1, 1] with y up to history UV (v down)."""
    return 0.5 * (ndc_x + 1.0), 0.5 * (1.0 - ndc_y)


def pcg_hash(value: U32) -> U32:
    """PCG-RXS-M-XS 32-bit hash; wraps mod 2^32 exactly like WGSL u32 arithmetic."""
    state = value * np.uint32(747796405) + np.uint32(2891336453)
    word = ((state >> ((state >> np.uint32(28)) + np.uint32(4))) ^ state) * np.uint32(277803737)
    return np.asarray((word >> np.uint32(22)) ^ word, dtype=np.uint32)


def texel_noise(width: int, height: int, seed: int, channel: int) -> Array:
    """Static per-texel noise in [0, 1): 24 hash bits, exact in float32 on both sides."""
    with np.errstate(over="ignore"):
        salt = pcg_hash(np.array([seed ^ NOISE_SALT[channel]], dtype=np.uint32))
        cols = pcg_hash(np.arange(width, dtype=np.uint32) + salt)
        rows = np.arange(height, dtype=np.uint32)[:, None]
        hashed = pcg_hash(rows + cols[None, :])
    return np.asarray((hashed >> np.uint32(8)).astype(np.float64) / float(1 << 24))


def smoothstep(edge0: float, edge1: float, x: Array) -> Array:
    t = np.clip((x - edge0) / (edge1 - edge0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def capsule_distance(segment: Segment, width: int, height: int) -> Array:
    """Distance from every texel centre to the segment, in history-height units (aspect-corrected)."""
    aspect = width / height
    px = ((np.arange(width) + 0.5) / width * aspect)[None, :]
    py = ((np.arange(height) + 0.5) / height)[:, None]
    ax, ay = segment.start[0] * aspect, segment.start[1]
    dx, dy = segment.end[0] * aspect - ax, segment.end[1] - ay
    length2 = dx * dx + dy * dy
    t = np.zeros((height, width)) if length2 <= 0.0 else ((px - ax) * dx + (py - ay) * dy) / length2
    t = np.clip(t, 0.0, 1.0)
    return np.asarray(np.hypot(px - ax - t * dx, py - ay - t * dy))


def coverage(
    segment: Segment, width: int, height: int, radius: float, softness: float, thinning: Array
) -> Array:
    """Brush coverage b in [0, 1]: capsule falloff times average pressure times (1 − thinning).

    ``thinning`` is the channel's noise amplitude times :func:`texel_noise`; it roughens the visible edge
    and is small on the tilt channel, whose deposit is the smoother one.
    """
    distance = capsule_distance(segment, width, height)
    falloff = 1.0 - smoothstep(radius * (1.0 - softness), radius, distance)
    return np.asarray(segment.pressure * falloff * (1.0 - thinning))
