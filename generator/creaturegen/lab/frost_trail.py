"""Frost parity gates on a visible trail (composite readback, OKLab, L in [0, 1]): a one-second wipe at
ordinary speed (0.7 of the pane's width per second, 120 Hz pointer, pressure 1, 60 FPS) changes the
trail's pixels by a median ΔE against the same pixels before the stroke and against the same pixels of a
run whose stroke went elsewhere (untouched pane at the same instant), figures reported for every package
and held to ≥ 0.05 at the defaults by tests/test_frost_parity.py; afterwards the trail frosts over again
(median ΔE against before < 0.01) within the declared regrowth time (thaw 1 → 5 %, ln 20 / λ), a gate.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..frost.brush import Segment
from ..frost.law import regrowth_seconds
from ..frost.params import FrostParams
from ..rig.colour import linear_to_oklab
from .frost_session import FrostLab
from .report import ParityReport

#: Visible-trail gates: median OKLab ΔE (L in [0, 1]) a trail must reach, and the level it falls back under.
TRAIL_DELTA_E = 0.05
REGROWN_DELTA_E = 0.01
WIPE_START = 0.5
WIPE_SECONDS = 1.0
WIPE_FROM, WIPE_TO = 0.15, 0.85
WIPE_HZ = 120
WIPE_FPS = 60

Array = npt.NDArray[np.float64]


def wipe_segments(v: float) -> list[Segment]:
    """A one-second horizontal wipe at history height v: ordinary speed, mouse-rate samples, pressure 1."""
    count = round(WIPE_SECONDS * WIPE_HZ)
    span = WIPE_TO - WIPE_FROM
    return [
        Segment(
            t0=WIPE_START + k / WIPE_HZ,
            t1=WIPE_START + (k + 1) / WIPE_HZ,
            start=(WIPE_FROM + span * k / count, v),
            end=(WIPE_FROM + span * (k + 1) / count, v),
        )
        for k in range(count)
    ]


def oklab_of_capture(rgba: npt.NDArray[np.uint8]) -> Array:
    """8-bit sRGB-encoded readback to OKLab (L in [0, 1])."""
    c = rgba[..., :3].astype(np.float64) / 255.0
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return np.asarray(linear_to_oklab(linear))


def trail_pixels(canvas: tuple[int, int], v: float, radius: float) -> npt.NDArray[np.bool_]:
    """Pixels within half the visible brush radius of the wipe line, away from its two ends."""
    width, height = canvas
    u = (np.arange(width) + 0.5) / width
    y = (np.arange(height) + 0.5) / height
    inner = (u > WIPE_FROM + 0.1) & (u < WIPE_TO - 0.1)
    near = np.abs(y - v) <= 0.5 * radius
    return np.asarray(near[:, None] & inner[None, :])


def trail_gates(lab: FrostLab, params: FrostParams, report: ParityReport, canvas: tuple[int, int]) -> None:
    v_trail, v_elsewhere = 0.42, 0.8
    mask = trail_pixels(canvas, v_trail, params.visible.radius)
    step = 1.0 / WIPE_FPS
    stroke_end = WIPE_START + WIPE_SECONDS
    frames = [k * step for k in range(round((stroke_end + step) / step) + 1)]
    start_frame = round(WIPE_START / step)

    def run(v: float) -> tuple[Array, Array]:
        lab.reset()
        lab.queue(wipe_segments(v))
        lab.advance(frames[: start_frame + 1])
        before = oklab_of_capture(lab.capture("final"))
        lab.advance(frames[start_frame:])
        return before, oklab_of_capture(lab.capture("final"))

    _, untouched = run(v_elsewhere)
    before, after = run(v_trail)
    vs_before = float(np.median(np.linalg.norm(after - before, axis=-1)[mask]))
    vs_untouched = float(np.median(np.linalg.norm(after - untouched, axis=-1)[mask]))
    declared = regrowth_seconds(params.visible.decay)
    # Let the trail refreeze, sampling the composite every 0.25 s up to the declared time (and a little past
    # it, so a miss is measured rather than cut off).
    t, regrown_after = frames[-1], None
    curve: list[list[float]] = []
    while t < frames[-1] + 1.5 * declared + 0.5:
        lab.advance([t + k * 0.05 for k in range(6)])
        t += 0.25
        delta = float(
            np.median(np.linalg.norm(oklab_of_capture(lab.capture("final")) - before, axis=-1)[mask])
        )
        curve.append([round(t - stroke_end, 4), delta])
        if delta < REGROWN_DELTA_E:
            regrown_after = t - stroke_end
            break
    # How visible a trail is depends on the look the spec chose (a spec may want a subtle veil): the
    # figures are reported for every package, and the defaults are held to TRAIL_DELTA_E by
    # tests/test_frost_parity.py. Frosting over within the declared time is the law's: a gate for all.
    report.gate(
        f"trail frosts over again (median dE < {REGROWN_DELTA_E}) within the declared regrowth time",
        float("inf") if regrown_after is None else regrown_after,
        declared,
        "seconds after the stroke",
    )
    report.measurements["trail"] = {
        "pixels": int(mask.sum()),
        "deltaEVsBefore": vs_before,
        "deltaEVsUntouched": vs_untouched,
        "visibleAtDefaultsBar": TRAIL_DELTA_E,
        "regrownAfterSeconds": regrown_after,
        "declaredRegrowthSeconds": declared,
        "deltaECurve": curve,
    }
