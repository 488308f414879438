"""Frost parity gates on the debug views: all of them render (final.png and view-*.png beside the
report), none draws the final view or a single colour, and switching between them creates no pipeline.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt

from ..frost.path import STROKE_SECONDS, STROKE_START, conformance_segments, frame_instants
from .frost_session import FrostLab
from .png import write_png
from .report import ParityReport

#: The pictures draw the conformance stroke this many times slower, so the thawed path is plain to see.
PICTURE_SLOWDOWN = 4
#: Views of what the current frame deposits: blank after the stroke, so they are checked during it.
INSTANT_VIEWS = ("depositR", "depositA")


def views_gate(lab: FrostLab, package: Path, report: ParityReport) -> None:
    folder = package / "parity"
    lab.reset()
    lab.queue(conformance_segments(PICTURE_SLOWDOWN))
    lab.advance(frame_instants(60, STROKE_START + STROKE_SECONDS * PICTURE_SLOWDOWN + 0.1))
    final = lab.capture("final")
    write_png(folder / "final.png", final)
    warm = lab.counters()["device"]
    info = lab.info()
    views: list[str] = info["debugViews"]
    # A refraction term the spec turns off (strength 0) is legitimately one colour in its own view.
    refraction = info.get("refraction") or {}
    switched_off = {f"refract{t}" for t in ("Main", "Detail") if refraction.get(f"{t.lower()}Strength") == 0}
    same: list[str] = []
    blank: list[str] = []
    for view in views:
        picture = lab.capture(view)
        write_png(folder / f"view-{view}.png", picture)
        if view != "final" and np.array_equal(picture, final):
            same.append(view)
        if view not in INSTANT_VIEWS and view not in switched_off and _one_colour(picture):
            blank.append(view)
    # The deposit views show only the frame's own deposit, zero once the stroke has ended: seen mid-stroke.
    lab.reset()
    lab.queue(conformance_segments(PICTURE_SLOWDOWN))
    lab.advance(frame_instants(60, STROKE_START + 0.5 * STROKE_SECONDS * PICTURE_SLOWDOWN))
    blank += [view for view in INSTANT_VIEWS if view in views and _one_colour(lab.capture(view))]
    after = lab.counters()["device"]
    created = sum(
        after[k] - warm[k]
        for k in (
            "createRenderPipeline",
            "createComputePipeline",
            "createRenderPipelineAsync",
            "createComputePipelineAsync",
        )
    )
    report.gate("pipelines created while switching debug views", created, 0, "pipelines")
    # A switch that does not reach the shader draws the default view; a broken view draws one colour.
    report.gate(f"debug views identical to the final view {same}", len(same), 0, "views")
    report.gate(f"debug views of one colour {blank}", len(blank), 0, "views")
    report.measurements["debugViews"] = views


def _one_colour(picture: npt.NDArray[np.uint8]) -> bool:
    return bool((picture[..., :3] == picture[0, 0, :3]).all())
