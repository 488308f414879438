"""Frost under a real pointer: Playwright drags the mouse over the lab page's canvas at real event rates
while the page plays on requestAnimationFrame with uneven frame times. The page wires the pointer through
the package's own ``attachPointer`` and logs, in order, every segment it accepted and every update it ran;
numpy replays that log and the GPU history must match it, and the pointer time the effect deposited must be
the whole drag (segments that arrive after the frame instant they overlap are caught up, not dropped).

Default spec (``{"kind": "frost", "name": ...}``), so this also exercises the shipped defaults."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from conftest import run_cli
from creaturegen.frost.brush import Segment
from creaturegen.frost.formats import HALF_FLOAT_TOLERANCE
from creaturegen.frost.params import params_from_plan
from creaturegen.frost.reference import STORAGE_OF_FORMAT, FrostReference
from creaturegen.lab.frost_parity import open_lab

CANVAS = (240, 144)
#: Busy work (ms) the page adds after successive frames, cycled: frame intervals from ~16 to ~50 ms.
STALLS_MS = [0, 14, 3, 30, 0, 8, 22, 0, 5]


@pytest.fixture(scope="module")
def default_package(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("frost-pointer")
    spec = folder / "pane.json"
    spec.write_text(json.dumps({"kind": "frost", "name": "Pointer Pane"}))
    result = run_cli("build", str(spec), "-o", str(folder / "out"))
    assert result.returncode == 0, result.stderr
    return folder / "out" / "pointer-pane"


def segment_of(data: dict[str, Any]) -> Segment:
    return Segment(
        t0=data["t0"],
        t1=data["t1"],
        start=(data["start"][0], data["start"][1]),
        end=(data["end"][0], data["end"][1]),
        pressure0=data["pressure0"],
        pressure1=data["pressure1"],
        stream=data.get("stream", 0),
    )


def drop_late_pointer_seconds(log: list[dict[str, Any]]) -> float:
    """Pointer seconds the runtime deposited before late segments were caught up: per update only the
    overlap of the queued segments with [previous, current]."""
    queued: list[Segment] = []
    total = 0.0
    for entry in log:
        if entry["kind"] == "segment":
            queued.append(segment_of(entry["segment"]))
        elif entry["kind"] == "update" and entry["current"] > entry["previous"]:
            p, c = entry["previous"], entry["current"]
            total += sum(max(0.0, min(g.t1, c) - max(g.t0, p)) for g in queued)
            queued = [g for g in queued if g.t1 > c]
    return total


def drag(page: Any, box: dict[str, float]) -> None:
    """Down, a wavy path of moves (each with intermediate steps, short pauses between them), up."""

    def at(s: float) -> tuple[float, float]:
        x = box["x"] + box["width"] * (0.15 + 0.7 * s)
        y = box["y"] + box["height"] * (0.5 + 0.25 * math.sin(2.0 * math.pi * s))
        return x, y

    page.mouse.move(*at(0.0))
    page.mouse.down()
    waypoints = 12
    for k in range(1, waypoints + 1):
        page.mouse.move(*at(k / waypoints), steps=6)
    page.wait_for_timeout(150)  # a held pause before release: the pointer keeps thawing where it rests
    page.mouse.up()


@pytest.mark.browser
def test_real_pointer_drag_deposits_its_whole_duration_and_matches_numpy(default_package: Path) -> None:
    params = params_from_plan(json.loads((default_package / "build-report.json").read_text())["params"])
    with open_lab(default_package, CANVAS) as lab:
        page = lab.page
        lab.call("() => { window.__lab.resetHistory(); window.__lab.startRecording(); }")
        lab.call("(s) => window.__lab.play({ stallMs: s })", STALLS_MS)
        page.wait_for_function("() => window.__lab.playedFrames > 6")
        box = page.locator("#canvas").bounding_box()
        assert box is not None
        drag(page, box)
        start = lab.call("() => window.__lab.playedFrames")
        page.wait_for_function(f"() => window.__lab.playedFrames > {start + 8}")
        lab.call("() => window.__lab.pause()")
        page.wait_for_timeout(100)  # let a frame already scheduled find the loop paused
        log: list[dict[str, Any]] = lab.call("() => window.__lab.stopRecording()")
        gpu = lab.history()
        counters = lab.counters()["effect"]
        info = lab.info()
        assert lab.gpu_errors() == []

    presses = {e["kind"]: e["t"] for e in log if e["kind"] in ("pointerdown", "pointerup")}
    segments = [segment_of(e["segment"]) for e in log if e["kind"] == "segment"]
    updates = [e for e in log if e["kind"] == "update"]
    duration = presses["pointerup"] - presses["pointerdown"]
    frame_dts = [u["current"] - u["previous"] for u in updates]
    assert len(segments) >= 40, len(segments)
    assert duration > 0.3, duration
    assert max(frame_dts) > 1.8 * min(frame_dts), "frame times were meant to be uneven"
    # The segments chain from the press to the release with no gap.
    assert segments[0].t0 == presses["pointerdown"]
    assert segments[-1].t1 == presses["pointerup"]
    assert all(a.t1 == b.t0 for a, b in itertools.pairwise(segments))
    late = sum(int(u["report"]["lateSteps"]) for u in updates)
    assert late > 0, "no segment arrived after the instant it overlaps: the test did not exercise catch-up"

    # numpy replays the page's log, in order, with the package's storage rounding.
    storage = STORAGE_OF_FORMAT[info["format"]]
    width, height = int(info["historySize"][0]), int(info["historySize"][1])
    reference = FrostReference(params, width, height, storage)
    for entry in log:
        if entry["kind"] == "segment":
            reference.queue(segment_of(entry["segment"]))
        elif entry["kind"] == "update":
            reference.update(entry["previous"], entry["current"])
    error = float(np.abs(gpu - reference.state).max())
    assert error <= HALF_FLOAT_TOLERANCE, error
    assert float(gpu[..., 0].max()) > 0.5  # the drag thawed the pane visibly

    # All of the pointer's time was deposited (to one frame's rounding), on the GPU and in numpy alike.
    ratio = counters["pointerSeconds"] / duration
    tolerance = min(frame_dts) / duration
    assert abs(ratio - 1.0) <= tolerance, (ratio, tolerance)
    assert abs(reference.counters.pointer_seconds - counters["pointerSeconds"]) <= 1e-9
    before = drop_late_pointer_seconds(log) / duration
    print(
        f"pointer time deposited: {ratio:.6f} of the drag ({duration:.3f} s, {len(segments)} segments, "
        f"{len(updates)} frames of {min(frame_dts) * 1e3:.1f}-{max(frame_dts) * 1e3:.1f} ms, "
        f"{late} catch-up steps); without catch-up it would be {before:.3f}; "
        f"GPU vs numpy {error:.2e}"
    )
