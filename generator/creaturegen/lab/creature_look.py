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
import numpy.typing as npt
from playwright.sync_api import Page

from ..creature import reference as cref
from ..creature.pose import as_pose
from ..motion.simulate import Motion
from ..surface.correction_region import SKIN_PROGRAM
from .creature_lab import b64_floats
from .report import ParityReport

#: Controls the gate switches to: far from the spec defaults (0.55, 0), inside setLook's ranges.
CHANGES = {"roughness": 0.12, "metalness": 0.8}
#: The occlusion the gate switches on: four taps reaching 0.08 L along each normal.
AO_TAPS, AO_RADIUS = 4, 0.08
AO_CHANGES: dict[str, float] = {"aoTaps": AO_TAPS, "aoRadius": AO_RADIUS}
#: Per-vertex occlusion, GPU (albedo on / albedo off) vs numpy at the drawn points: float32 taps of the
#: field against float64 ones, and the albedo's own float32 rounding in the ratio.
AO_TOL = 1e-3
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


def occlusion_gates(page: Page, ref: cref.PackageReference, motion: Motion, report: ParityReport) -> None:
    """The field's self-occlusion (look.aoTaps): switched on by setLook, every field vertex's stored albedo
    is its unoccluded one times numpy's occlusion at the drawn point and normal (creature/reference.py
    self_occlusion), no vertex moves, no GPU object is created, and switching it off restores the albedo."""
    got = page.evaluate("(c) => window.__lab.aoCheck(c)", AO_CHANGES)
    created = {k: int(v) for k, v in got["created"].items()}
    report.gate(
        "GPU objects created by setLook of the self-occlusion (and its re-deform)",
        float(sum(created.values())),
        0.0,
        "objects",
    )

    def read(state: dict[str, str], key: str) -> npt.NDArray[np.float64]:
        return b64_floats(state[key]).reshape(-1, 3).astype(np.float64)

    off, on, back = (read(got[k], "colour") for k in ("off", "on", "back"))
    position = read(got["on"], "position")
    moved = float(np.abs(position - read(got["off"], "position")).max()) / ref.rig.body_scale
    report.gate("drawn vertices moved by the self-occlusion", moved, 0.0, "L")
    program = b64_floats(got["on"]["program"]).astype(np.int64)
    field = program != SKIN_PROGRAM
    table = cref.posed_table(ref, as_pose(motion.quats, motion.trans), motion.size)
    gradient = np.asarray(cref.field_at(ref, table, position, motion.size).gradient, dtype=np.float64)
    expected = cref.self_occlusion(ref, table, position, gradient, motion.size, AO_TAPS, AO_RADIUS)
    channel = off.argmax(axis=1)
    rows = np.arange(len(off))
    lit = field & (off[rows, channel] > 0.02)  # the ratio of a near-black albedo says little
    measured = on[rows, channel] / np.where(lit, off[rows, channel], 1.0)
    error = float(np.abs(measured - expected)[lit].max()) if lit.any() else float("inf")
    report.gate(
        f"self-occlusion ({AO_TAPS} taps to {AO_RADIUS} L): GPU albedo ratio vs numpy",
        error,
        AO_TOL,
        "",
    )
    report.gate(
        "albedo after the self-occlusion is switched off vs before",
        float(np.abs(back - off).max()),
        0.0,
        "",
    )
    report.measurements["selfOcclusion"] = {
        **AO_CHANGES,
        "vertices": int(lit.sum()),
        "dispatches": int(got["dispatches"]),
        "minOcclusion": float(expected[field].min()),
        "meanOcclusion": float(expected[field].mean()),
        "occludedShare": float((expected[field] < 0.99).mean()),
        "maxErrorVsNumpy": error,
    }


def look_and_occlusion(page: Page, ref: cref.PackageReference, motion: Motion, report: ParityReport) -> None:
    """The look group: the material's uniforms, then the pre-pass's self-occlusion."""
    look_gates(page, report)
    occlusion_gates(page, ref, motion, report)
