"""Drive the frost lab page from Python: replay pointer paths, read the GPU history back, capture views.

Every GPU number here comes from the page through readback (``readHistory`` copies the history texture
into a storage buffer on the GPU and maps it; ``capturePixels`` reads a render target). The numpy
reference is never consulted on this side.
"""

from __future__ import annotations

import base64
from dataclasses import asdict
from typing import Any

import numpy as np
import numpy.typing as npt
from playwright.sync_api import Page

from ..frost.brush import Segment


def segment_json(segment: Segment) -> dict[str, Any]:
    data = asdict(segment)
    data["start"], data["end"] = list(segment.start), list(segment.end)
    return data


class FrostLab:
    """Thin typed wrapper over ``window.__lab`` of web_lab/frost.html."""

    def __init__(
        self, page: Page, console: list[str] | None = None, page_errors: list[str] | None = None
    ) -> None:
        self.page = page
        # The page's console transcript since launch, appended to as the page logs (browser.LabPage).
        self.console = console if console is not None else []
        self.page_errors = page_errors if page_errors is not None else []

    def call(self, expression: str, argument: Any = None) -> Any:
        return self.page.evaluate(expression, argument)

    def info(self) -> dict[str, Any]:
        info: dict[str, Any] = self.call("() => window.__lab.info()")
        return info

    def reset(self) -> None:
        self.call("() => window.__lab.resetHistory()")

    def queue(self, segments: list[Segment]) -> None:
        self.call("(s) => window.__lab.queuePointerSegments(s)", [segment_json(s) for s in segments])

    def advance(self, instants: list[float]) -> list[dict[str, Any]]:
        reports: list[dict[str, Any]] = self.call("(i) => window.__lab.advance(i)", instants)
        return reports

    def update(self, previous: float, current: float) -> dict[str, Any]:
        report: dict[str, Any] = self.call("([p, c]) => window.__lab.update(p, c)", [previous, current])
        return report

    def history(self) -> npt.NDArray[np.float64]:
        """The latest history as (H, W, 4) float64 (exact float32 values from the GPU)."""
        raw = self.call("() => window.__lab.readHistory()")
        data = np.asarray(raw["data"], dtype=np.float64)
        return data.reshape(raw["height"], raw["width"], 4)

    def replay(self, segments: list[Segment], instants: list[float]) -> npt.NDArray[np.float64]:
        self.reset()
        self.queue(segments)
        self.advance(instants)
        return self.history()

    def capture(self, view: str = "final") -> npt.NDArray[np.uint8]:
        shot = self.call("(v) => window.__lab.capturePixels(v)", view)
        rgba = np.frombuffer(base64.b64decode(shot["rgba"]), dtype=np.uint8)
        return rgba.reshape(shot["height"], shot["width"], 4)

    def gpu_errors(self) -> list[str]:
        self.call("() => window.__lab.finish()")
        errors: list[str] = self.call("() => window.__lab.errors")
        return errors

    def counters(self) -> dict[str, Any]:
        counters: dict[str, Any] = self.call("() => window.__lab.counters()")
        return counters
