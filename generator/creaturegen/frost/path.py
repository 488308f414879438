"""The conformance pointer path: one scripted stroke that the format gate, the GPU parity test, the lab
and the benchmark all replay, so their numbers describe the same input.

An S-shaped stroke across the pane, sampled like a 240 Hz pointer with varying pressure, then a pause in
which the frost grows back. Positions are history UV (origin top-left, v down); times are seconds.
"""

from __future__ import annotations

import math

from .brush import Segment

STROKE_START = 0.05
STROKE_SECONDS = 0.6
POINTER_HZ = 240
DURATION = 1.5
FRAME_RATES = (30, 60, 120)


def stroke_point(s: float) -> tuple[float, float]:
    """Point at stroke parameter s in [0, 1]."""
    return 0.15 + 0.7 * s, 0.5 + 0.22 * math.sin(2.0 * math.pi * s)


def conformance_segments(slowdown: int = 1) -> list[Segment]:
    """The stroke; ``slowdown`` > 1 draws the same shape that many times slower (for pictures)."""
    count = round(STROKE_SECONDS * POINTER_HZ) * slowdown
    segments = []
    for k in range(count):
        s0, s1 = k / count, (k + 1) / count
        segments.append(
            Segment(
                t0=STROKE_START + k / POINTER_HZ,
                t1=STROKE_START + (k + 1) / POINTER_HZ,
                start=stroke_point(s0),
                end=stroke_point(s1),
                pressure0=0.6 + 0.4 * math.sin(math.pi * s0),
                pressure1=0.6 + 0.4 * math.sin(math.pi * s1),
            )
        )
    return segments


def frame_instants(fps: int, duration: float = DURATION) -> list[float]:
    """Render instants k/fps; computed from the integer k so 30, 60 and 120 FPS share exact instants."""
    return [k / fps for k in range(round(duration * fps) + 1)]
