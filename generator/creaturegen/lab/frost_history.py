"""Frost parity gates on the history: the GPU history read back against the numpy reference
(creaturegen.frost.reference, rounding like the package's storage format, within the format's tolerance at
every texel and channel), fed the way the package is fed.

- history parity: the conformance stroke at 30, 60 and 120 FPS, and at several instants during it;
- late arrival: the stroke's segments queued only once their end sample arrived (as attachPointer delivers
  them): GPU vs numpy fed the same way, numpy late vs in advance ≤ 1e-12 (the catch-up is exact for the
  law), and the pointer time deposited equals the stroke's duration;
- a stalled frame (run with the time-policy gates): the late-arriving stroke with one frame stalled past
  maxInterval during it: the declared catch-up (or discontinuity) runs as numpy's does, the history
  matches, and a caught-up stroke deposits in full;
- several strokes at once: the GPU's binned update vs numpy's unbinned one, and the bins' work per frame;
- frame-rate invariance: GPU 30 vs GPU 120 within the numpy float64 30-vs-120 difference plus the same
  tolerance; numpy float64 30 vs 120 ≤ 1e-12 for the law (diffusion off; with diffusion on its
  operator-splitting difference is reported, not hidden).
"""

from __future__ import annotations

import dataclasses
import itertools
from typing import Any

import numpy as np
import numpy.typing as npt

from ..frost.brush import Segment
from ..frost.formats import HALF_FLOAT_TOLERANCE, replay
from ..frost.params import FrostParams
from ..frost.path import FRAME_RATES, STROKE_SECONDS, STROKE_START, conformance_segments, frame_instants
from ..frost.reference import STORAGE_OF_FORMAT, FrameReport, FrostReference, Storage
from ..spec.messages import number
from .frost_session import FrostLab
from .report import ParityReport

COMPOSITION_TOLERANCE = 1e-12
#: GPU vs numpy tolerance per history format. rgba16float: one half-float ulp on [0.5, 1) (the format's own
#: rounding, which the numpy reference applies at every store too). rgba32float: the float32 store is
#: simulated as well, so what remains is the GPU's exp() (a few float32 ulps) over a few hundred stores:
#: 2^-16 bounds that with room (measured ~2e-6); one tolerance for both would let a float32 history be
#: 30x worse than it is unnoticed.
FORMAT_TOLERANCE = {"rgba16float": HALF_FLOAT_TOLERANCE, "rgba32float": 2.0**-16}
#: Where in the conformance stroke the GPU history is compared as well (fractions of the stroke), at 60 FPS:
#: at the final instant, after the stroke, channels G and B are exactly 0 in every example.
STROKE_CHECKPOINTS = (0.25, 0.5, 0.75, 1.0)
#: Strokes of the several-at-once check: crossing wipes of their own streams, staggered in time.
STROKES_AT_ONCE = 8

Array = npt.NDArray[np.float64]


def reference_replay(params: FrostParams, size: tuple[int, int], fps: int, storage: Storage) -> Array:
    return replay(params, fps, storage, size).state


def history_gates(lab: FrostLab, params: FrostParams, report: ParityReport) -> None:
    info = lab.info()
    size, storage, tolerance = _history_context(lab)
    gpu: dict[int, Array] = {}
    exact: dict[int, Array] = {}
    for fps in FRAME_RATES:
        gpu[fps] = lab.replay(conformance_segments(), frame_instants(fps))
        expected = reference_replay(params, size, fps, storage)
        exact[fps] = reference_replay(params, size, fps, "float64")
        error = float(np.abs(gpu[fps] - expected).max())
        report.gate(f"GPU vs numpy history at {fps} FPS", error, tolerance, "history units")
        report.measurements[f"peakThaw{fps}"] = float(expected[..., 0].max())
    _during_stroke_gate(lab, params, report, size, storage, tolerance)
    slow, fast = min(FRAME_RATES), max(FRAME_RATES)
    numpy_rates = float(np.abs(exact[slow] - exact[fast]).max())
    gpu_rates = float(np.abs(gpu[slow] - gpu[fast]).max())
    report.measurements["numpyFloat64RateDifference"] = numpy_rates
    report.gate(
        f"GPU {slow} vs {fast} FPS history", gpu_rates, numpy_rates + HALF_FLOAT_TOLERANCE, "history units"
    )
    law = dataclasses.replace(params, diffusivity=0.0)
    law_rates = float(
        np.abs(
            reference_replay(law, size, slow, "float64") - reference_replay(law, size, fast, "float64")
        ).max()
    )
    report.gate(
        f"numpy float64 {slow} vs {fast} FPS (law)", law_rates, COMPOSITION_TOLERANCE, "history units"
    )
    report.measurements["historySize"] = list(size)
    report.measurements["format"] = info["format"]


def _history_context(lab: FrostLab) -> tuple[tuple[int, int], Storage, float]:
    """The GPU history's size, the numpy storage that rounds like its format, and that format's tolerance."""
    info = lab.info()
    size = (int(info["historySize"][0]), int(info["historySize"][1]))
    return size, STORAGE_OF_FORMAT[info["format"]], FORMAT_TOLERANCE[info["format"]]


def late_arrival_gates(lab: FrostLab, params: FrostParams, report: ParityReport) -> None:
    """The "late" group: segments queued as a real pointer delivers them (``_late_arrival_gate``)."""
    _late_arrival_gate(lab, params, report, *_history_context(lab))


def strokes_at_once_gates(lab: FrostLab, params: FrostParams, report: ParityReport) -> None:
    """The "strokes" group: several strokes at once through the binned update (``_strokes_at_once_gate``)."""
    _strokes_at_once_gate(lab, params, report, *_history_context(lab))


def strokes_at_once(count: int, seconds: float = 0.5, pieces: int = 8) -> list[Segment]:
    """``count`` streams wiping at once: stroke k runs from (0.1, v_k) to (0.9, 1 − v_k) and back (the
    strokes cross near the middle, so texels there sit under several at once, and the way back re-enters
    bins it thawed on the way out, partway through a frame), starting k·20 ms apart; in time order, as
    pointers deliver them."""

    def at(v: float, f: float) -> tuple[float, float]:
        there = 1.0 - abs(1.0 - 2.0 * f)  # 0 → 1 → 0
        return (0.1 + 0.8 * there, v + (1 - 2 * v) * there)

    segments = []
    for k in range(count):
        v = 0.15 + 0.7 * k / max(count - 1, 1)
        t0 = 0.02 * k
        for j in range(pieces):
            a, b = j / pieces, (j + 1) / pieces
            segments.append(Segment(t0 + seconds * a, t0 + seconds * b, at(v, a), at(v, b), stream=k + 1))
    return sorted(segments, key=lambda g: (g.t0, g.stream))


def _strokes_at_once_gate(
    lab: FrostLab,
    params: FrostParams,
    report: ParityReport,
    size: tuple[int, int],
    storage: Storage,
    tolerance: float,
) -> None:
    """Several pointers at once (streams that overlap in time and cross in space): the GPU's binned update
    vs numpy's unbinned one (a texel under several strokes takes the largest coverage); the bins' entries
    and law evaluations per frame vs schedule.bin_steps (JS StepBins and Python count alike); and the
    pointer time deposited, over the strokes' summed durations."""
    lab.reset()
    segments = strokes_at_once(STROKES_AT_ONCE)
    reference = FrostReference(params, size[0], size[1], storage)
    for segment in segments:
        reference.queue(segment)
    before = lab.counters()["effect"]["pointerSeconds"]
    lab.queue(segments)
    instants = [k / 60 for k in range(46)]
    reports = lab.advance(instants)
    for previous, current in itertools.pairwise(instants):
        reference.update(previous, current)
    expected = reference.counters.history[-len(reports) :]
    report.gate(
        f"GPU vs numpy history, {STROKES_AT_ONCE} strokes at once (60 FPS)",
        float(np.abs(lab.history() - reference.state).max()),
        tolerance,
        "history units",
    )
    mismatched = sum(
        int(r["binEntries"]) != e.bin_entries or int(r["texelSteps"]) != e.texel_steps
        for r, e in zip(reports, expected, strict=True)
    )
    report.gate("frames whose bin entries or law evaluations differ from numpy's", mismatched, 0, "frames")
    duration = sum(g.t1 - g.t0 for g in segments)
    ratio = (lab.counters()["effect"]["pointerSeconds"] - before) / duration
    report.gate(
        f"pointer time deposited / summed duration, {STROKES_AT_ONCE} strokes at once",
        abs(ratio - 1.0),
        1e-9,
        "|ratio - 1|",
    )
    entries = sum(int(r["binEntries"]) for r in reports)
    steps = sum(int(r["texelSteps"]) for r in reports)
    unbinned = sum(e.unbinned_texel_steps for e in expected)
    report.measurements["strokesAtOnce"] = {
        "strokes": STROKES_AT_ONCE,
        "binEntries": entries,
        "texelSteps": steps,
        "unbinnedTexelSteps": unbinned,
        "peakThaw": float(reference.state[..., 0].max()),
    }


def _during_stroke_gate(
    lab: FrostLab,
    params: FrostParams,
    report: ParityReport,
    size: tuple[int, int],
    storage: Storage,
    tolerance: float,
) -> None:
    """The history read back at several instants during the stroke, against numpy fed the same frames."""
    lab.reset()
    lab.queue(conformance_segments())
    reference = FrostReference(params, size[0], size[1], storage)
    for segment in conformance_segments():
        reference.queue(segment)
    instants = frame_instants(60)
    last = 0  # chunks share their end instant: advance() updates between consecutive instants it is given
    worst = 0.0
    channels = np.zeros(4)
    for fraction in STROKE_CHECKPOINTS:
        until = STROKE_START + fraction * STROKE_SECONDS
        upto = max(i for i, t in enumerate(instants) if t <= until + 1e-12)
        step = instants[last : upto + 1]
        lab.advance(step)
        for previous, current in itertools.pairwise(step):
            reference.update(previous, current)
        last = upto
        gpu = lab.history()
        worst = max(worst, float(np.abs(gpu - reference.state).max()))
        channels = np.maximum(channels, np.abs(reference.state).reshape(-1, 4).max(axis=0))
    report.gate(
        f"GPU vs numpy history during the stroke ({len(STROKE_CHECKPOINTS)} instants, 60 FPS)",
        worst,
        tolerance,
        "history units",
    )
    report.measurements["duringStrokeChannelMax"] = channels.tolist()


def _deliver_late(
    lab: FrostLab, references: list[FrostReference], instants: list[float]
) -> tuple[list[dict[str, Any]], list[FrameReport]]:
    """Feed the conformance stroke as a real pointer delivers it, to the GPU and to each reference: each
    segment queued only when its end sample has arrived (before the first update reaching t1). Returns the
    GPU's frame reports and the first reference's."""
    pending = conformance_segments()
    gpu: list[dict[str, Any]] = []
    cpu: list[FrameReport] = []
    for previous, current in itertools.pairwise(instants):
        arrived = [g for g in pending if g.t1 <= current]
        pending = pending[len(arrived) :]
        if arrived:
            lab.queue(arrived)
        for target in references:
            for segment in arrived:
                target.queue(segment)
        cpu.append(references[0].update(previous, current))
        for target in references[1:]:
            target.update(previous, current)
        gpu.append(lab.update(previous, current))
    return gpu, cpu


def _late_arrival_gate(
    lab: FrostLab,
    params: FrostParams,
    report: ParityReport,
    size: tuple[int, int],
    storage: Storage,
    tolerance: float,
) -> None:
    """The conformance stroke delivered as a real pointer delivers it (``_deliver_late``), so most segments
    overlap an instant already rendered. GPU vs numpy fed the same way; numpy float64 fed late vs fed in
    advance (the catch-up is exact for the law); and the pointer time deposited on the GPU, over the
    stroke's duration."""
    lab.reset()
    reference = FrostReference(params, size[0], size[1], storage)
    exact = FrostReference(dataclasses.replace(params, diffusivity=0.0), size[0], size[1], "float64")
    advance_known = FrostReference(dataclasses.replace(params, diffusivity=0.0), size[0], size[1], "float64")
    for segment in conformance_segments():
        advance_known.queue(segment)
    before = lab.counters()["effect"]["pointerSeconds"]
    instants = frame_instants(60)
    _deliver_late(lab, [reference, exact], instants)
    for previous, current in itertools.pairwise(instants):
        advance_known.update(previous, current)
    gpu = lab.history()
    report.gate(
        "GPU vs numpy history, segments arriving late (60 FPS)",
        float(np.abs(gpu - reference.state).max()),
        tolerance,
        "history units",
    )
    report.gate(
        "numpy float64 late arrival vs segments known in advance (law)",
        float(np.abs(exact.state - advance_known.state).max()),
        COMPOSITION_TOLERANCE,
        "history units",
    )
    ratio = (lab.counters()["effect"]["pointerSeconds"] - before) / STROKE_SECONDS
    report.gate(
        "pointer time deposited / stroke duration, segments arriving late",
        abs(ratio - 1.0),
        1e-9,
        "|ratio - 1|",
    )
    report.measurements["lateArrival"] = {
        "pointerTimeRatio": ratio,
        "lateSteps": sum(r.late_steps for r in reference.counters.history),
    }


def stall_seconds(params: FrostParams) -> float:
    """How long the stalled-frame gate stalls a frame: 2.5 advances where catch-up is on (at most catchUp),
    otherwise twice maxInterval (a discontinuity)."""
    if params.catch_up > params.max_interval:
        return min(params.catch_up, 2.5 * params.max_interval)
    return 2.0 * params.max_interval


def stalled_frame_gate(lab: FrostLab, params: FrostParams, report: ParityReport) -> None:
    """The late-arriving stroke at 60 FPS with one frame stalled during it (a hitch under load): the GPU's
    decision and advances equal numpy's, its history matches numpy's, and with catch-up on the whole stroke
    still deposits (pointer time / stroke duration = 1). Part of the time-policy gates ("idle" group)."""
    size, storage, tolerance = _history_context(lab)
    lab.reset()
    reference = FrostReference(params, size[0], size[1], storage)
    instants = frame_instants(60)
    stalled = next(i for i, t in enumerate(instants) if t >= STROKE_START + 0.05)
    resumed = instants[stalled] + stall_seconds(params)
    timeline = instants[: stalled + 1] + [resumed + k / 60 for k in range(6)]
    before = lab.counters()["effect"]["pointerSeconds"]
    gpu_reports, cpu_reports = _deliver_late(lab, [reference], timeline)
    gpu_frame, cpu_frame = gpu_reports[stalled], cpu_reports[stalled]
    expected = "catch-up" if params.catch_up > params.max_interval else "discontinuity"
    stall = number(resumed - instants[stalled])
    report.gate(
        f"a frame stalled {stall} s runs {expected} (GPU decision, advances as numpy)",
        abs(int(gpu_frame["advances"]) - cpu_frame.advances),
        0,
        "advances",
        passed=gpu_frame["decision"] == cpu_frame.decision == expected
        and gpu_frame["advances"] == cpu_frame.advances,
    )
    report.gate(
        "GPU vs numpy history after a stalled frame",
        float(np.abs(lab.history() - reference.state).max()),
        tolerance,
        "history units",
    )
    ratio = (lab.counters()["effect"]["pointerSeconds"] - before) / STROKE_SECONDS
    if expected == "catch-up":
        report.gate(
            "pointer time deposited / stroke duration, a frame stalled during it",
            abs(ratio - 1.0),
            1e-9,
            "|ratio - 1|",
        )
    report.measurements["stalledFrame"] = {
        "seconds": resumed - instants[stalled],
        "decision": gpu_frame["decision"],
        "advances": gpu_frame["advances"],
        "pointerTimeRatio": ratio,
    }
