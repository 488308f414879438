"""The shading controls (``population.setLook``: roughness, metalness, the distance view's range) are
uniforms: changing them draws a different picture and creates no GPU object.

The page renders the front view under the package's look, under other controls and under its look again,
counting the device's create* calls from the first change to the last capture. The gates: nothing created
(pipelines, shader modules, buffers, bind groups, textures), the changed picture differs from the first
over the body, and the restored one equals the first (the controls are all the change).
"""

from __future__ import annotations

import base64

import numpy as np
from playwright.sync_api import Page

from .report import ParityReport

#: Controls the gate switches to: far from the spec defaults (0.55, 0), inside setLook's ranges.
CHANGES = {"roughness": 0.12, "metalness": 0.8}
#: Mean |ΔRGB| over the body's pixels (0..255) the changed look must reach: a roughness and metalness this
#: far apart move the lit body by tens of levels; a control that does not reach the shader moves none.
CHANGED_MIN = 2.0


def look_gates(page: Page, report: ParityReport) -> None:
    got = page.evaluate("(c) => window.__lab.lookCheck(c)", CHANGES)
    created = {k: int(v) for k, v in got["created"].items()}
    report.gate(
        "GPU objects created by setLook (pipelines, shaders, buffers, bind groups, textures)",
        float(sum(created.values())),
        0.0,
        "objects",
    )
    h, w = int(got["height"]), int(got["width"])
    first, changed, restored = (
        np.frombuffer(base64.b64decode(x), dtype=np.uint8).reshape(h, w, 4)[..., :3].astype(np.int64)
        for x in got["rgba"]
    )
    body = np.abs(changed - first).sum(axis=2) > 0
    moved = float(np.abs(changed - first)[body].mean()) if body.any() else 0.0
    report.gate(
        f"front view under setLook({CHANGES}) vs the package's look: mean |ΔRGB| over changed pixels "
        "(at least)",
        moved,
        CHANGED_MIN,
        "levels",
        passed=moved >= CHANGED_MIN,
    )
    report.gate(
        "front view after setLook back vs before: pixels that differ",
        float(np.count_nonzero(np.abs(restored - first).sum(axis=2))),
        0.0,
        "pixels",
    )
    report.measurements["look"] = {
        "before": got["before"],
        "during": got["during"],
        "restored": got["restored"],
        "created": created,
        "changedPixels": int(body.sum()),
        "meanDeltaLevels": moved,
    }
