"""From two render instants to the piecewise-constant input intervals the law integrates.

dt always comes from a pair of instants, never from one timestamp or a frame counter. Equal instants mean no
elapsed interval (nothing runs). A reversed, non-finite or over-long interval is a discontinuity: the
declared policy runs (reset clears the history, freeze keeps it and skips the interval), and the effect
counts it; nothing is clamped silently.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Literal

from .brush import Segment

Decision = Literal["advance", "none", "discontinuity"]


def classify_interval(previous: float, current: float, max_interval: float) -> Decision:
    if not (math.isfinite(previous) and math.isfinite(current)):
        return "discontinuity"
    if current == previous:
        return "none"
    if current < previous or current - previous > max_interval:
        return "discontinuity"
    return "advance"


@dataclass(frozen=True)
class Step:
    """dt seconds of constant input: ``segment`` deposits throughout, or None for pure decay.

    A catch-up step (``age`` not None) is the part of a late segment that lay before ``previous``: the
    history decayed over those dt seconds and then ``age`` more; the law's catch_up applies the deposit.
    """

    dt: float
    segment: Segment | None
    age: float | None = None


def late_steps(previous: float, segments: list[Segment], origin: float) -> list[Step]:
    """Catch-up steps for segments queued since the last update whose span began before ``previous``.

    The missed part is [max(t0, origin), min(t1, previous)]: ``origin`` is where the history's timeline
    starts (the first update's previous instant, or the instant a discontinuity ended), so nothing from
    before a reset or a dropped interval is deposited. Chronological, as the segments are.
    """
    steps: list[Step] = []
    for segment in segments:
        start, end = max(segment.t0, origin), min(segment.t1, previous)
        if end > start:
            steps.append(Step(dt=end - start, segment=segment, age=previous - end))
    return steps


def split_interval(previous: float, current: float, segments: list[Segment]) -> list[Step]:
    """Cut [previous, current) at every segment boundary inside it; segments are time-ordered, disjoint.

    A segment that began before ``previous`` contributes only its overlap with this interval: the part
    before ``previous`` belonged to an earlier interval (or was dropped by a discontinuity).
    """
    cuts = {previous, current}
    for segment in segments:
        cuts.update(t for t in (segment.t0, segment.t1) if previous < t < current)
    ordered = sorted(cuts)
    steps: list[Step] = []
    for s0, s1 in itertools.pairwise(ordered):
        active = next((g for g in segments if g.t0 <= s0 and s1 <= g.t1 and g.t1 > g.t0), None)
        steps.append(Step(dt=s1 - s0, segment=active))
    return steps


def chunk_steps(steps: list[Step], max_steps: int) -> list[list[Step]]:
    """Dispatch-sized groups; each group ends in one storage write on the GPU."""
    return [steps[i : i + max_steps] for i in range(0, len(steps), max_steps)]


def validate_segment(segment: Segment, last_end: float | None) -> str | None:
    """Why a queued segment is refused, or None: one pointer stream, time-ordered and non-overlapping."""
    values = (segment.t0, segment.t1, *segment.start, *segment.end, segment.pressure0, segment.pressure1)
    if not all(math.isfinite(v) for v in values):
        return "segment values must be finite"
    if segment.t1 < segment.t0:
        return f"segment ends ({segment.t1}) before it starts ({segment.t0})"
    if last_end is not None and segment.t0 < last_end:
        return f"segment starts at {segment.t0}, before the previous one ended ({last_end})"
    if not (0.0 <= segment.pressure0 <= 1.0 and 0.0 <= segment.pressure1 <= 1.0):
        return "pressures must lie in [0, 1]"
    return None
