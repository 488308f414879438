"""From two render instants to the piecewise-constant input intervals the law integrates.

dt always comes from a pair of instants, never from one timestamp or a frame counter. Equal instants mean no
elapsed interval (nothing runs). A forward interval longer than max_interval but at most catch_up is a
stalled frame: it is caught up as equal advances (``advance_instants``), so the pointer input queued during
the stall deposits in full. A reversed, non-finite or longer interval is a discontinuity: the declared
policy runs (reset clears the history, freeze keeps it and skips the interval), and the effect counts it;
nothing is clamped silently.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Literal

from .brush import Segment

Decision = Literal["advance", "none", "catch-up", "discontinuity"]


def classify_interval(previous: float, current: float, max_interval: float, catch_up: float) -> Decision:
    if not (math.isfinite(previous) and math.isfinite(current)):
        return "discontinuity"
    if current == previous:
        return "none"
    if current < previous:
        return "discontinuity"
    elapsed = current - previous
    if elapsed <= max_interval:
        return "advance"
    return "catch-up" if elapsed <= catch_up else "discontinuity"


def advance_instants(previous: float, current: float, max_interval: float) -> list[float]:
    """Where the advances of a caught-up interval end: ceil(elapsed / max_interval) equal pieces, the last
    ending exactly at ``current``. Written as the JS core writes it (same operations, same order), so both
    cut at bit-identical instants."""
    count = math.ceil((current - previous) / max_interval)
    return [previous + (current - previous) * i / count for i in range(1, count)] + [current]


@dataclass(frozen=True)
class Step:
    """dt seconds of constant input: the ``segments`` active throughout (one per stream at most; none is
    pure decay). A texel under several takes the largest coverage.

    A catch-up step (``age`` not None) is the part of one late segment that lay before ``previous``: the
    history decayed over those dt seconds and then ``age`` more; the law's catch_up applies the deposit.
    Late segments of different streams are caught up one after the other, which is exact wherever they do
    not cover one texel during one span (a stream's own segments never overlap).
    """

    dt: float
    segments: tuple[Segment, ...] = ()
    age: float | None = None

    @property
    def pointer_seconds(self) -> float:
        """Seconds of pointer input this step deposits, summed over its streams."""
        return self.dt * len(self.segments)


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
            steps.append(Step(dt=end - start, segments=(segment,), age=previous - end))
    return steps


def split_interval(previous: float, current: float, segments: list[Segment]) -> list[Step]:
    """Cut [previous, current) at every segment boundary inside it; each piece holds every segment active
    throughout it (a stream's segments are time-ordered and disjoint; streams may overlap).

    A segment that began before ``previous`` contributes only its overlap with this interval: the part
    before ``previous`` belonged to an earlier interval (or was dropped by a discontinuity).
    """
    cuts = {previous, current}
    for segment in segments:
        cuts.update(t for t in (segment.t0, segment.t1) if previous < t < current)
    ordered = sorted(cuts)
    steps: list[Step] = []
    for s0, s1 in itertools.pairwise(ordered):
        active = tuple(g for g in segments if g.t0 <= s0 and s1 <= g.t1 and g.t1 > g.t0)
        steps.append(Step(dt=s1 - s0, segments=active))
    return steps


def chunk_steps(steps: list[Step], max_steps: int, max_pairs: int) -> list[list[Step]]:
    """Dispatch-sized groups, in order: a group ends before it would hold more than ``max_steps`` steps
    or ``max_pairs`` (step, segment) pairs; each group ends in one storage write on the GPU."""
    chunks: list[list[Step]] = []
    pairs = 0
    for step in steps:
        if not chunks or len(chunks[-1]) == max_steps or pairs + len(step.segments) > max_pairs:
            chunks.append([])
            pairs = 0
        chunks[-1].append(step)
        pairs += len(step.segments)
    return chunks


def validate_segment(segment: Segment, last_end: float | None) -> str | None:
    """Why a queued segment is refused, or None: finite, and time-ordered and non-overlapping within its
    stream (``last_end``: where that stream's previous segment ended)."""
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


def too_many_streams(segment: Segment, pending: list[Segment], max_streams: int) -> str | None:
    """Why a segment is refused for the streams it would overlap, or None: at most ``max_streams`` other
    streams' queued segments may overlap its span (a step holds at most one segment per stream)."""
    others = {
        g.stream for g in pending if g.stream != segment.stream and g.t0 < segment.t1 and segment.t0 < g.t1
    }
    if len(others) >= max_streams:
        count, most = len(others), max_streams - 1
        return f"segment of stream {segment.stream} would overlap {count} other streams (at most {most})"
    return None
