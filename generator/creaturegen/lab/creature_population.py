"""Parity gates on many bodies: no GPU pipelines and no buffers created by a burst of spawns that fills
the lab's first pose page and opens its second, one instanced draw per page and pass, and one tick and
frame of them all after reveal; and the genetics grid: 64 individuals (seeds 0..63) spawned in an 8×8 grid
and stepped, every one's GPU pose rows (its OKLab-mutated colours and the pose its size and gait genes
give) vs its Python reference, no two individuals alike; parity/grid.png shows them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from playwright.sync_api import Page

from ..creature import reference as cref
from ..creature.pose import POSE_ROWS, pose_rows, root_rows
from ..model import layout as col
from ..model.genome import slot_lab
from .creature_lab import LAB_POSITION, LAB_SEED, PARITY_TICK, rgba_image
from .creature_skin import POSITION_TOL
from .png import write_png
from .report import ParityReport

#: Bodies per pose page in the parity lab, and the spawn burst after reveal: instance 0 plus PAGE_SIZE
#: spawns fill page 0 and put one body on page 1, so the burst crosses a page boundary and the frame draws
#: two pages. Small on purpose: the one frame deforms every spawned body in software (SwiftShader took
#: 65 s for 51 beetles of 65,410 vertices), and a bigger page adds nothing the gates could see.
PAGE_SIZE = 8
SPAWNS = PAGE_SIZE
#: Pages the burst's bodies occupy. The lab holds one page more unless the genetics grid runs (its GRID_SIDE²
#: bodies need more): with exactly two pages the pages-in-use gate could not fail, since nine bodies need
#: both; a third page lets a spawn that spreads bodies over pages show (the preload warms every page, one
#: body each, so capacity costs time).
PAGES_IN_BURST = 2
SPARE_PAGES = 1
#: The genetics grid: side, first seed, spacing (body lengths) and the tick it is compared at.
GRID_SIDE = 8
GRID_SEED = 0
GRID_SPACING = 2.0
GRID_TICK = 24
#: The device calls that create a GPU object the counter gates count.
DEVICE_CREATIONS = (
    "createBuffer",
    "createRenderPipeline",
    "createRenderPipelineAsync",
    "createComputePipeline",
    "createComputePipelineAsync",
)
#: The culling layout: bodies spawned around body 0 on a grid this many body lengths apart, so that body
#: 0's portrait view misses some. Few on purpose: each is deformed several times, and a beetle's 65,410
#: vertices take about a second and a half each on SwiftShader.
CULL_BODIES = 4
CULL_SPACING = 6.0
#: Genome colours in the GPU rows vs Python: both round the same float64 value to float32, so exactly 0.
COLOUR_TOL = 0.0


def _reference_rows(ref: cref.PackageReference, tick: int) -> npt.NDArray[np.float64]:
    motion = cref.instance_motion(ref, LAB_SEED, tick, LAB_POSITION)
    colours = cref.instance_colours(ref, LAB_SEED)
    rows = pose_rows(ref.rig, motion.quats, motion.trans, colours, motion.size).reshape(-1)
    return np.concatenate([rows, root_rows(motion.root, size=motion.size).reshape(-1)])


def moves_every_tick(ref: cref.PackageReference) -> bool:
    """Whether the Python locomotion reference changes body 0's pose rows from one tick to the next (at the
    first tick and at the parity tick). A creature without locomotion stands still: after a body's first
    pre-pass the population has nothing to deform again, and the "only what moved" gates expect exactly
    that (found by build-many's parity jobs over generated creatures: they expected every tick to move
    body 0)."""
    return any(
        not np.array_equal(_reference_rows(ref, t), _reference_rows(ref, t + 1)) for t in (0, PARITY_TICK)
    )


def counter_gates(page: Page, report: ParityReport, moving: bool = True) -> None:
    page.evaluate("() => window.__lab.resetCounters()")
    # Spawn without drawing, then one tick and one frame of all of them: a pipeline built at draw time
    # would show up here too.
    page.evaluate(f"() => window.__lab.spawn(1000, {SPAWNS}, 1.5, false)")
    page.evaluate("() => window.__lab.stepTicks(1)")
    page.evaluate("() => window.__lab.finish()")
    after = page.evaluate("() => window.__lab.counters()")["sinceReveal"]
    pipelines = after["createRenderPipeline"] + after["createRenderPipelineAsync"]
    pipelines += after["createComputePipeline"] + after["createComputePipelineAsync"]
    report.gate(f"pipelines created by {SPAWNS} spawns after reveal", pipelines, 0, "pipelines")
    report.gate(f"buffers created by {SPAWNS} spawns after reveal", after["createBuffer"], 0, "buffers")
    telemetry = page.evaluate("() => window.__lab.telemetry()")
    drawn = page.evaluate("() => window.__lab.draws()")
    body_passes = [n for n in drawn["perPass"] if n > 0]
    pages = telemetry["pagesInUse"]
    report.gate(
        f"pose pages in use after {SPAWNS} spawns of pageSize {PAGE_SIZE}",
        pages,
        PAGES_IN_BURST,
        "pages",
        passed=pages == PAGES_IN_BURST,
    )
    # One instanced draw per page and pass, never one per body. A pass may draw fewer: it culls a page
    # whose bodies lie outside its frustum (the shadow camera covers body 0 only, and the burst's body on
    # page 1 stands 1.5 L away).
    report.gate(
        "body draw calls in a render pass beyond pages in use (encoder count)",
        float(max((n - pages for n in body_passes), default=pages)),
        0,
        "draws",
    )
    report.gate(
        "render passes drawing the bodies (display + shadow)",
        len(body_passes),
        2,
        "passes",
        passed=len(body_passes) >= 2,
    )
    moved_gates(page, report, telemetry, moving)
    report.measurements["population"] = {
        "bodyZeroMovesEveryTick": moving,
        "count": telemetry["count"],
        "pagesInUse": pages,
        "pages": telemetry["pages"],
        "drawsPerPass": drawn["perPass"],
        "lastFrameBytes": telemetry["stats"]["lastFrameBytes"],
        "spawnCost": page.evaluate("() => window.__lab.spawnCost()"),
        "sinceReveal": after,
    }
    page.evaluate("() => window.__lab.despawnAll([0])")


def moved_gates(page: Page, report: ParityReport, telemetry: dict[str, Any], moving: bool = True) -> None:
    """Only what moved: after a tick that moved every body (``telemetry``), a still frame, one spawn beside
    still bodies, and a tick with all bodies but one paused, the pre-pass ran exactly the bodies whose rows
    changed. Each frame deforms as few bodies as the gate needs (a beetle's body takes over a second on
    SwiftShader). ``moving`` (moves_every_tick): whether a tick moves body 0, which was deformed before the
    spawned bodies came; a still creature's tick deforms only the bodies never deformed yet."""
    moved = telemetry["stats"]["lastFrameDeformedBodies"]
    expected = telemetry["count"] - (0 if moving else 1)
    report.gate(
        "bodies deformed by a tick that moves every live body (pre-pass: all of them)"
        if moving
        else "bodies deformed by a tick of a still creature (pre-pass: the spawned bodies, never deformed)",
        abs(moved - expected),
        0,
        "bodies",
    )
    still = still_frame(page)
    report.gate(
        "bodies deformed by a frame in which no pose changed (pre-pass: only what moved)",
        still["stats"]["lastFrameDeformedBodies"] + still["stats"]["lastFrameDeformedVertices"],
        0,
        "bodies",
    )
    # One spawn beside bodies that stand still (no step): its page holds another body, so a pre-pass over
    # the page's changed range, or over every live body, runs more than the one that moved.
    page.evaluate("() => window.__lab.spawn(2000, 1, 1.5, true)")
    spawned = page.evaluate("() => window.__lab.telemetry()")["stats"]["lastFrameDeformedBodies"]
    report.gate(
        "bodies deformed by a frame whose only change is one spawn beside still bodies (only what moved)",
        abs(spawned - 1),
        0,
        "bodies",
    )
    # Every body but body 0 paused: one tick deforms body 0 alone and leaves a paused body's rows alone.
    held = page.evaluate("() => window.__lab.pauseAllBut([0])")
    before = page.evaluate(f"() => window.__lab.stagedPose({held[0]})")
    page.evaluate("() => window.__lab.stepTicks(1)")
    deformed = page.evaluate("() => window.__lab.telemetry()")["stats"]["lastFrameDeformedBodies"]
    one = 1 if moving else 0
    report.gate(
        "bodies deformed by a tick with every body but one paused, beyond that one"
        if moving
        else "bodies deformed by a tick of a still creature with every body but one paused",
        abs(deformed - one),
        0,
        "bodies",
        passed=deformed == one and page.evaluate(f"() => window.__lab.stagedPose({held[0]})") == before,
    )
    page.evaluate(f"() => window.__lab.resume({held})")


def cull_gates(page: Page, report: ParityReport, scale: float, moving: bool = True) -> None:
    """Culling by posed bounds (population.cullWith): bodies spread far beyond body 0's portrait view,
    culled to that view for a tick: only the bodies it sees are drawn and deformed; when culling stops, the
    bodies that moved while culled are deformed before they are drawn: what every body's pre-pass stored
    is the GPU body path at its current pose (``scale``: L). No GPU object is created by any of it.
    (Comparing two pictures instead was tried: in 3 of 7 runs two pictures of the same deform storage
    differed in about 1,500 pixels, at the bodies' shadows.)"""
    page.evaluate("() => window.__lab.despawnAll([0])")
    # Not drawn at spawn: the culled tick's flush is the first to see them.
    ids = [0, *page.evaluate(f"() => window.__lab.spawn(3000, {CULL_BODIES}, {CULL_SPACING}, false)")]
    page.evaluate("() => window.__lab.resetCounters()")
    page.evaluate("() => window.__lab.cullWith('portrait')")
    page.evaluate("() => window.__lab.stepTicks(1)")
    telemetry = page.evaluate("() => window.__lab.telemetry()")
    culled, live = telemetry["stats"], int(telemetry["count"])
    report.gate(
        f"bodies drawn in body 0's portrait view of {live} spread {CULL_SPACING} L apart (rest culled)",
        float(culled["lastFrameDrawnBodies"]),
        float(live),
        "bodies",
        passed=culled["lastFrameDrawnBodies"] + culled["lastFrameCulledBodies"] == live
        and 0 < culled["lastFrameCulledBodies"] < live,
    )
    # Every drawn body is new but body 0, which a still creature's tick leaves as it was deformed.
    drawn_new = culled["lastFrameDrawnBodies"] - (0 if moving else 1)
    report.gate(
        "bodies deformed by a culled tick beyond the bodies drawn (only what is seen)",
        abs(culled["lastFrameDeformedBodies"] - drawn_new),
        0,
        "bodies",
    )
    # No pose changes from here: the one flush after culling stops deforms exactly the bodies that moved
    # while they were culled.
    page.evaluate("() => window.__lab.cullWith('none')")
    page.evaluate("() => window.__lab.redraw()")
    back = page.evaluate("() => window.__lab.telemetry()")["stats"]
    report.gate(
        "bodies deformed when culling stops vs the bodies culled while they moved",
        abs(int(culled["lastFrameCulledBodies"]) - int(back["lastFrameDeformedBodies"])),
        0,
        "bodies",
    )
    created = page.evaluate("() => window.__lab.counters()")["sinceReveal"]
    report.gate(
        "pipelines and buffers created by culling on, a culled tick and culling off (device count)",
        sum(created[k] for k in DEVICE_CREATIONS),
        0,
        "objects",
    )
    worst = max(drawn_vs_body_path(page, i) for i in ids) / scale
    report.gate(
        f"drawn vertices of {len(ids)} bodies after culling vs the GPU body path at their pose",
        worst,
        POSITION_TOL,
        "L",
    )
    page.evaluate("() => window.__lab.despawnAll([0])")


def drawn_vs_body_path(page: Page, body: int) -> float:
    """The largest distance between what the pre-pass stored for ``body`` (its drawn vertices) and the
    same body path run at its current pose by the diagnostics kernel (both GPU readbacks, compared in the
    page: a beetle's two arrays are megabytes): a body drawn with a stale surface stands a tick away."""
    gap: float = page.evaluate(f"() => window.__lab.drawnGap({body})")
    return gap


def still_frame(page: Page) -> dict[str, Any]:
    """A frame that rewrites every body at the step it is already drawn at (stepTicks(0): no step, every
    row written again): nothing changed, so the pre-pass must run no body and the upload must be empty."""
    page.evaluate("() => window.__lab.stepTicks(0)")
    telemetry: dict[str, Any] = page.evaluate("() => window.__lab.telemetry()")
    return telemetry


def grid_gates(page: Page, ref: cref.PackageReference, package: Path, report: ParityReport) -> None:
    """The genetics grid: each individual's GPU pose rows against the Python reference spawned from the same
    seed and position (the colour rows alone at float32 rounding, all rows relative to L), and how far the
    individuals differ: colour (OKLab distance of the mean slot colour to the authored one), speed (pace gene
    and √size together) and size."""
    # Not drawn at spawn: the step's one upload and deform pre-pass draws all 64.
    bodies = page.evaluate(f"() => window.__lab.grid({GRID_SIDE}, {GRID_SEED}, {GRID_SPACING}, false)")
    page.evaluate(f"() => window.__lab.stepTicks({GRID_TICK})")
    scale = ref.rig.body_scale
    slots = ref.rig.slot_count
    worst_rows = worst_colour = 0.0
    colours, speeds, sizes = [], [], []
    for body in bodies:
        gpu = np.asarray(page.evaluate(f"() => window.__lab.readPose({body['id']})"), dtype=np.float32)
        seed = int(body["seed"])
        x, y, z = (float(c) for c in body["position"])
        motion = cref.instance_motion(ref, seed, GRID_TICK, (x, y, z))
        mine = cref.instance_colours(ref, seed)
        rows = np.concatenate(
            [
                pose_rows(ref.rig, motion.quats, motion.trans, mine, motion.size).reshape(-1),
                root_rows(motion.root, size=motion.size).reshape(-1),
            ]
        )
        got = gpu[: rows.size]
        worst_rows = max(worst_rows, float(np.abs(got - rows).max()) / scale)
        colour_rows = got[: slots * POSE_ROWS * 4].reshape(slots, POSE_ROWS, 4)[:, 2, 1:4]
        worst_colour = max(worst_colour, float(np.abs(colour_rows - np.asarray(mine, np.float32)).max()))
        colours.append(colour_rows.astype(np.float64).ravel())
        speeds.append(motion.data.speed / ref.motion.speed if ref.motion.speed > 0 else 1.0)
        sizes.append(motion.size)
    report.gate(
        f"genome colours of {len(bodies)} individuals: GPU pose rows vs Python (OKLab mutation)",
        worst_colour,
        COLOUR_TOL,
        "linear rgb",
    )
    report.gate(
        f"pose rows of {len(bodies)} individuals at tick {GRID_TICK}: GPU vs Python (size and gait genes)",
        worst_rows,
        1e-6,
        "L",
    )
    flat = np.asarray(colours)
    gaps = np.linalg.norm(flat[:, None, :] - flat[None, :, :], axis=2)[np.triu_indices(len(flat), 1)]
    genetics = ref.spec.genetics
    if genetics.hue or genetics.chroma or genetics.lightness:
        identical = int(np.count_nonzero(gaps == 0.0))
        report.gate("individuals with identical colours in the grid", identical, 0, "pairs")
    # How far the individuals stray: OKLab distance of each slot colour from the authored one.
    authored = np.asarray(slot_lab(ref.rig.slots[:, col.RGB]))
    shift = np.linalg.norm(np.asarray([slot_lab(c.reshape(-1, 3)) for c in flat]) - authored, axis=2)
    report.measurements["grid"] = {
        "bodies": len(bodies),
        "tick": GRID_TICK,
        "minColourGapLinear": float(gaps.min()),
        "oklabShift": {"median": float(np.median(shift)), "max": float(shift.max())},
        "speedRatio": [float(min(speeds)), float(max(speeds))],
        "size": [float(min(sizes)), float(max(sizes))],
    }
    shot = page.evaluate("() => window.__lab.capturePixels('grid')")
    write_png(package / "parity" / "grid.png", rgba_image(shot))
