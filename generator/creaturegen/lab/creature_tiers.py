"""Parity gates of a package that ships several tiers (``creaturegen build --tier hero,distant``): bodies
moved between tiers by their size on screen, as a crowd does it.

- **the tier rule**: the lab's tier walk (a camera dollying from near to far and back past a row of
  bodies, ``population.chooseTiers`` every frame) against the Python reference (creature/lod.py): every
  body's size on screen recomputed from what the choice read (the camera's view matrix and fov, the body's
  posed-bounds centre and size gene), and every tier replayed from the first frame with ``choose_tier``
  and the ceilings the build wrote (build-report.json ``tiers``), not the package's data;
- **no GPU object** created by the walk's tier moves (device count);
- **what a moved body draws**: after the walk (the camera near: every body back in the finest tier; every
  other body idles, paused, so only the move can have deformed it) each
  body's deform storage against the GPU body path at its pose;
- **silhouettes**: one body drawn by each coarser tier against the finest, as masks in one three-quarter
  view: the farthest disagreeing pixel from the other mask, in pixels at the coarser tier's ceiling size,
  within the two tiers' promised half pixels (each tier's ``projectedSizeMaxPx`` is where its surface
  stays within 0.5 px of the field) plus one pixel of rasterisation at the rendered size.
"""

from __future__ import annotations

import base64
import json
from pathlib import Path
from typing import Any

import numpy as np
from playwright.sync_api import Page

from ..creature.assets import REPORT_PATH
from ..creature.lod import choose_tier, projected_size_px
from ..surface.skin_tier import SUBPIXEL_PX
from .creature_population import DEVICE_CREATIONS, drawn_vs_body_path
from .creature_skin import POSITION_TOL
from .creature_views import shadow_mismatch
from .png import write_png
from .report import ParityReport

#: Relative difference allowed between the page's size on screen and the reference's (float64 both:
#: only the order of a few operations differs).
SIZE_REL_TOL = 1e-9
#: Frames and bodies of the walk, and its nearest and farthest camera, × L.
WALK_FRAMES, WALK_BODIES, WALK_NEAR, WALK_FAR = 24, 6, 1.5, 24.0
#: The mask target's side in pixels (the body several times its coarser tier's ceiling size across).
MASK_SIZE = 256


def shipped_ceilings(package: Path) -> dict[str, float]:
    """{tier: projectedSizeMaxPx} of every tier the build report says the package ships."""
    report: Any = json.loads((package / REPORT_PATH).read_text(encoding="utf-8"))
    return {str(t["tier"]): float(t["projectedSizeMaxPx"]) for t in report.get("tiers", [])}


def reference_walk(
    frames: list[dict[str, Any]], length: float, ceilings: dict[str, float], first: str
) -> dict[str, Any]:
    """The walk replayed by creature/lod.py: per body, the size from the recorded view and the tier chosen
    from the previous frame's (the spawn tier ``first`` before the first frame); worst size error and the
    frames whose tier differs from the page's."""
    current: dict[int, str] = {}
    worst = 0.0
    mismatches: list[dict[str, Any]] = []
    moves = {"finer": 0, "coarser": 0}
    order = ["distant", "repeated", "hero"]
    for index, frame in enumerate(frames):
        view = np.asarray(frame["view"], dtype=np.float64).reshape(4, 4).T  # column-major elements
        for body in frame["bodies"]:
            centre = np.append(np.asarray(body["centre"], dtype=np.float64), 1.0)
            depth = -float((view @ centre)[2])
            size = projected_size_px(
                length * float(body["size"]),
                depth,
                float(frame["height"]),
                fov_deg=float(frame["fov"]),
                zoom=float(frame["zoom"]),
            )
            worst = max(worst, abs(size - float(body["sizePx"])) / max(size, 1e-12))
            before = current.get(int(body["id"]), first)
            tier = choose_tier(size, before, ceilings)
            if tier != before:
                moves["finer" if order.index(tier) > order.index(before) else "coarser"] += 1
            current[int(body["id"])] = tier
            if tier != body["tier"]:
                mismatches.append(
                    {
                        "frame": index,
                        "id": body["id"],
                        "page": body["tier"],
                        "reference": tier,
                        "sizePx": size,
                    }
                )
    return {"sizeRelError": worst, "mismatches": mismatches, "moves": moves}


def tier_gates(page: Page, package: Path, report: ParityReport, length: float, tick: int) -> None:
    """The tier rule, the device count and the moved bodies' surfaces over a walk, then the silhouettes
    (module docstring). ``length``: L. Leaves instance 0 alone, as the lab spawns it (in the finest tier,
    spawned at population tick 0), at population tick ``tick``."""
    tiers = page.evaluate("() => window.__lab.tierInfo()")
    names = [t["name"] for t in tiers]
    ceilings = shipped_ceilings(package)
    report.measurements["tiers"] = tiers
    page.evaluate("() => window.__lab.resetCounters()")
    walk = page.evaluate(
        f"() => window.__lab.tierWalk({WALK_FRAMES}, {WALK_BODIES}, {WALK_NEAR}, {WALK_FAR})"
    )
    created = page.evaluate("() => window.__lab.counters()")["sinceReveal"]
    replay = reference_walk(walk["frames"], length, {n: ceilings[n] for n in names}, names[0])
    report.gate(
        f"body sizes on screen over a {WALK_FRAMES}-frame walk vs creature/lod.py (relative)",
        replay["sizeRelError"],
        SIZE_REL_TOL,
        "",
    )
    report.gate(
        f"tiers chosen over the walk ({WALK_BODIES} bodies × {WALK_FRAMES} frames) "
        "vs creature/lod.py choose_tier",
        len(replay["mismatches"]),
        0,
        "choices",
    )
    moved = int(walk["stats"]["tierMoves"])
    report.gate(
        "tier moves the walk made, finer and coarser (each direction exercised)",
        float(moved),
        float(replay["moves"]["finer"] + replay["moves"]["coarser"]),
        "moves",
        passed=replay["moves"]["finer"] > 0
        and replay["moves"]["coarser"] > 0
        and moved == replay["moves"]["finer"] + replay["moves"]["coarser"],
    )
    report.gate(
        "pipelines and buffers created by the walk's tier moves (device count)",
        sum(created[k] for k in DEVICE_CREATIONS),
        0,
        "objects",
    )
    report.measurements["tierWalkCreated"] = {k: created[k] for k in DEVICE_CREATIONS}
    ids = [int(b["id"]) for b in walk["frames"][-1]["bodies"]] if walk["frames"] else []
    back = (
        [int(b["id"]) for b in walk["frames"][-1]["bodies"] if b["tier"] == names[0]]
        if walk["frames"]
        else []
    )
    worst = max((drawn_vs_body_path(page, i) for i in back), default=float("inf")) / length
    report.gate(
        f"drawn vertices of {len(back)} of {len(ids)} bodies moved back to {names[0]} vs the GPU body path",
        worst,
        POSITION_TOL,
        "L",
    )
    report.measurements["tierWalk"] = {
        "frames": len(walk["frames"]),
        "moves": replay["moves"],
        "mismatches": replay["mismatches"][:10],
    }
    silhouette_gates(page, package, report, names, ceilings)
    page.evaluate("() => window.__lab.despawnAll([])")
    page.evaluate("() => window.__lab.seekTick(0)")
    page.evaluate("() => window.__lab.spawn(1, 1, 1.5, false)")
    page.evaluate(f"() => window.__lab.seekTick({tick})")


def silhouette_gates(
    page: Page, package: Path, report: ParityReport, names: list[str], ceilings: dict[str, float]
) -> None:
    """Body 0 drawn by the finest tier and by each coarser one (module docstring)."""
    page.evaluate("() => window.__lab.despawnAll([])")
    page.evaluate("() => window.__lab.spawn(1, 1, 1.5, true)")
    shot = page.evaluate(f"() => window.__lab.tierSilhouettes({json.dumps(names)}, {MASK_SIZE})")
    size = int(shot["size"])
    masks = {}
    for name in names:
        rgba = np.frombuffer(base64.b64decode(shot["masks"][name]), np.uint8).reshape(size, size, 4)
        write_png(package / "parity" / f"tier-{name}.png", rgba)
        masks[name] = rgba[..., :3].max(axis=2) > 127
    finest = names[0]
    scale = float(shot["sizePx"])
    for name in names[1:]:
        worst, count = shadow_mismatch(masks[finest], masks[name])
        # Both tiers' half pixels at the coarser ceiling, plus one pixel of rasterisation at this size.
        bound = SUBPIXEL_PX * (1.0 + ceilings[name] / ceilings[finest]) + ceilings[name] / scale
        report.gate(
            f"silhouette of the {name} tier vs the {finest} tier, px at the {name} ceiling "
            f"({ceilings[name]:.0f} px; drawn at {scale:.0f} px)",
            worst * ceilings[name] / scale,
            bound,
            "px",
            passed=worst * ceilings[name] / scale <= bound and bool(masks[name].any()),
        )
        report.measurements[f"silhouette.{name}"] = {
            "disagreeingPixels": count,
            "pixels": int(masks[name].sum()),
            "finestPixels": int(masks[finest].sum()),
        }
