"""Frost parity gates on the declared policies: once converged, frames dispatch nothing (counted by the
package, per frame); equal instants do nothing, a reversed interval runs the declared discontinuity
policy and a stalled frame the declared catch-up (frost_history.stalled_frame_gate); a resize follows the
declared policy (clear → zeros; preserve-remap → the numpy bilinear remap of the GPU history read back
just before).
"""

from __future__ import annotations

import numpy as np

from ..frost.formats import HALF_FLOAT_TOLERANCE
from ..frost.params import FrostParams
from ..frost.path import conformance_segments, frame_instants
from ..frost.reference import remap_bilinear
from .frost_history import stalled_frame_gate
from .frost_session import FrostLab
from .report import ParityReport


def idle_and_time_gates(lab: FrostLab, params: FrostParams, report: ParityReport) -> None:
    lab.reset()
    lab.queue(conformance_segments())
    slowest = min(c.decay for c in params.channels)
    settle = float(np.log(1.0 / params.tolerance) / max(slowest, 1e-9)) + 2.0
    step = min(0.5, params.max_interval)
    instants = [k * step for k in range(int(settle / step) + 4)]
    reports = lab.advance(instants)
    tail = reports[-3:]
    idle_dispatches = sum(int(r["dispatches"]) for r in tail)
    report.gate("dispatches per idle frame after convergence", idle_dispatches, 0, "dispatches")
    retired_at = next((i for i, r in enumerate(reports) if r["retiredTiles"] > 0), None)
    report.measurements["idleAfterSeconds"] = None if retired_at is None else instants[retired_at + 1]
    report.gate("converged history is exactly zero", float(np.abs(lab.history()).max()), 0.0, "history units")
    t = instants[-1]
    none = lab.update(t, t)
    report.gate(
        "equal instants dispatch nothing",
        int(none["dispatches"]),
        0,
        "dispatches",
        passed=none["decision"] == "none" and none["dispatches"] == 0,
    )
    lab.reset()
    lab.queue(conformance_segments()[:10])
    lab.advance([0.0, 0.05, 0.1])
    before = float(np.abs(lab.history()).max())
    reversed_report = lab.update(0.1, 0.05)
    after = float(np.abs(lab.history()).max())
    expected_after = 0.0 if params.discontinuity == "reset" else before
    report.gate(
        f"reversed interval runs the {params.discontinuity} policy",
        abs(after - expected_after),
        0.0,
        "history units",
        passed=reversed_report["decision"] == "discontinuity" and after == expected_after and before > 0,
    )
    stalled_frame_gate(lab, params, report)


def resize_gate(lab: FrostLab, params: FrostParams, report: ParityReport, canvas: tuple[int, int]) -> None:
    lab.reset()
    lab.queue(conformance_segments())
    lab.advance(frame_instants(60, 0.5))
    before = lab.history()
    new_canvas = (canvas[0] * 3 // 4, canvas[1] * 5 // 4)
    result = lab.call("([w, h]) => window.__lab.resize(w, h, 1)", list(new_canvas))
    after = lab.history()
    if params.resize_policy == "clear":
        expected = np.zeros_like(after)
    else:
        expected = remap_bilinear(before, after.shape[1], after.shape[0])
    error = float(np.abs(after - expected).max())
    report.gate(f"resize follows {params.resize_policy}", error, HALF_FLOAT_TOLERANCE, "history units")
    report.measurements["resize"] = {"from": list(before.shape[1::-1]), "to": result["historySize"]}
    lab.call("([w, h]) => window.__lab.resize(w, h, 1)", list(canvas))
