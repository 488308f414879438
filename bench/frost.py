"""Frost benchmark on WebGPU/SwiftShader: tier costs, full-field vs dirty tiles, idle frames, history bytes.

Everything runs in headless Chromium through the frost lab page (web_lab/frost.html), on packages built
into a temporary folder by ``creaturegen build``, and every figure below is measured in this run:

* **tiers** (``examples/frost/frost-full.json``, switched with ``setTier``, so the tier is the only
  variable): ms per frame of update-only frames (the conformance stroke, full-field policy,
  ``timeFrames(draw=false)``), of update + render frames (``draw=true``) and of render-only frames (every
  ``update`` returns ``none``), the last once at the tier's blur scale and once with the blur's targets
  shrunk to 1x1 (the lab's ``setBlurScale``); their difference is the blur estimate.
* **sparse**: two specs derived from ``examples/frost/frost-budgeted.json`` that differ only in
  ``update.policy`` (full-field vs dirty-tiles), built side by side; a small dab replayed on both, texels
  and dispatches per frame from the per-frame reports, ms per frame from ``timeFrames``.
* **idle**: after a stroke, time advances in frames no longer than the package's maxInterval until the
  scheduler retires every tile; then idle frames are advanced and their dispatches counted from the reports
  (and from the effect's counters).
* **memory**: 2·W·H·bytesPerTexel derived here from the canvas and the tier's history scale, beside the
  history textures the effect allocated (``memory()``).

Variants run interleaved in rounds whose order rotates, after one warm-up round; ratios are medians over
rounds of ratios measured within a round. JSON goes to ``--out``; progress to stderr; a summary table to
stdout.

    python bench/frost.py --out bench/results/frost.json
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from benchlib import machine
from creaturegen.frost.brush import Segment
from creaturegen.frost.params import scaled_size
from creaturegen.frost.path import conformance_segments
from creaturegen.frost.plan import BYTES_PER_TEXEL
from creaturegen.lab.browser import READY_EXPRESSION, LabPage, launch_lab_page
from creaturegen.lab.frost_session import FrostLab
from creaturegen.lab.server import serve

REPO = Path(__file__).resolve().parents[1]
WEB_LAB = REPO / "generator" / "creaturegen" / "web_lab"
TIER_SPEC = REPO / "examples" / "frost" / "frost-full.json"
SPARSE_BASE_SPEC = REPO / "examples" / "frost" / "frost-budgeted.json"
TIERS = ("full", "balanced", "budgeted")
POLICIES = ("full-field", "dirty-tiles")

#: The sparse stroke: a small circle (radius in history UV) traced at the pointer rate, pressure 1.
DAB_START = 0.05
DAB_SECONDS = 0.1
DAB_RADIUS = 0.01
DAB_HZ = 240

#: Two pages share one browser in the sparse section: neither may be throttled as a background tab.
BROWSER_FLAGS = (
    "--disable-background-timer-throttling",
    "--disable-renderer-backgrounding",
    "--disable-backgrounding-occluded-windows",
)

#: Blur resolution scale of the reference render in the blur estimate: small enough for 1x1 targets.
MIN_BLUR_SCALE = 1e-6

NOTES = " ".join(
    [
        "SwiftShader runs WebGPU on the CPU: absolute times describe this host's CPU, not a GPU, and the",
        "ratios between tiers follow texel counts more closely than they would on a GPU, where fixed",
        "per-pass costs weigh more. Times include three's per-frame CPU work (uniform and bind group",
        "updates, command encoding). Update-only batches (timeFrames) run back to back in one task and",
        "await GPU completion once per batch, so CPU and GPU work of successive frames may overlap.",
        "Frames that render are timed one per animation frame (lab timeAnimationFrames), each from its",
        "update to its GPU completion: three advances its node frame once per animation-frame tick and the",
        "scene pass and the blur run once per node frame, so renders back to back in one task would",
        "repeat only the composite. The blur",
        "cannot be switched off in the package (every debug view is computed and the blur node runs before",
        "every render), and calling its passes outside a render re-runs the scene pass (a new node frame),",
        "so blur_estimate is render_only minus render_only_blur_1x1 (the same render with the blur node's",
        "resolution scale shrunk until both its targets are 1x1, lab helper setBlurScale): the blur's",
        "resolution-dependent cost, per round; the fixed cost of its two passes stays in both terms. A tier",
        "changes the history resolution and the blur resolution together (and, for refraction, only",
        "uniforms: the detail and Fresnel strengths), so the update figures follow the history scale and the",
        "blur estimate the blur scale; the scene pass and the composite run at the canvas size in every",
        "tier. Report texels are the threads the scheduler accounts for: W·H per full-field dispatch",
        "(its 8×8 workgroups launch threads_launched, the extent guard drops the rest) and tiles × tile",
        "area per tile dispatch (edge tiles counted whole). Memory 'allocated' is the size of the history",
        "textures the effect created (three StorageTexture objects backing the GPU textures), times the",
        "format's bytes per texel.",
    ]
)


# --- helpers -------------------------------------------------------------------------------------------


def _median(values: Sequence[float]) -> float:
    return float(statistics.median(values))


def _summary(values: Sequence[float]) -> dict[str, float]:
    return {"median": _median(values), "min": float(min(values)), "max": float(max(values))}


def parse_canvas(text: str) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WxH, e.g. 320x192 (got {text!r})") from None
    if w < 8 or h < 8:
        raise argparse.ArgumentTypeError(f"canvas must be at least 8x8 (got {text!r})")
    return w, h


def dab_segments(centre: tuple[float, float]) -> list[Segment]:
    """A small closed circle around ``centre``: the sparse stroke."""
    count = round(DAB_SECONDS * DAB_HZ)
    cu, cv = centre

    def point(k: int) -> tuple[float, float]:
        angle = 2.0 * math.pi * k / count
        return cu + DAB_RADIUS * math.cos(angle), cv + DAB_RADIUS * math.sin(angle)

    return [
        Segment(t0=DAB_START + k / DAB_HZ, t1=DAB_START + (k + 1) / DAB_HZ, start=point(k), end=point(k + 1))
        for k in range(count)
    ]


def stroke_instants(segments: Sequence[Segment], frames: int, fps: int) -> list[float]:
    """Frame instants from the stroke's first sample on, so every frame has work."""
    start = segments[0].t0
    return [start + k / fps for k in range(frames + 1)]


def build_packages(
    jobs: dict[str, tuple[Path, Path]], log: Callable[[str], None]
) -> dict[str, dict[str, Any]]:
    """``creaturegen build SPEC -o DIR`` for every job, in concurrent child processes, as a user runs it;
    returns each build report (with ``_folder``, the package folder)."""
    started = time.perf_counter()
    procs = {
        key: subprocess.Popen(
            [sys.executable, "-m", "creaturegen.cli", "build", str(spec), "-o", str(out_dir)],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        for key, (spec, out_dir) in jobs.items()
    }
    reports: dict[str, dict[str, Any]] = {}
    for key, proc in procs.items():
        output, _ = proc.communicate()
        spec, out_dir = jobs[key]
        if proc.returncode != 0:
            raise RuntimeError(f"creaturegen build {spec} failed:\n{output}")
        (folder,) = [p for p in out_dir.iterdir() if p.is_dir()]
        report: dict[str, Any] = json.loads((folder / "build-report.json").read_text())
        report["_folder"] = folder
        reports[key] = report
        log(f"  built {spec.name} -> {out_dir.name}/{folder.name}")
    log(f"  {len(jobs)} builds in {time.perf_counter() - started:.1f} s")
    return reports


class Bench:
    """One lab page: FrostLab plus the bench calls (timeFrames, setBlurScale, counters)."""

    def __init__(self, page: LabPage) -> None:
        if page.lab.get("error"):
            raise RuntimeError(f"frost lab page failed: {page.lab['error']}\n{page.transcript()}")
        self.page = page
        self.lab = FrostLab(page.page)

    def plan(self) -> dict[str, Any]:
        plan: dict[str, Any] = self.lab.call("() => window.__lab.plan")
        return plan

    def effect_counters(self) -> dict[str, Any]:
        effect: dict[str, Any] = self.lab.counters()["effect"]
        return effect

    def start(self, segments: list[Segment]) -> None:
        self.lab.reset()
        self.lab.queue(segments)

    def time_frames(self, instants: list[float], draw: bool, paced: bool = False) -> dict[str, float]:
        """Ms of the frames, and the dispatches/texels the effect counted while they ran.

        ``paced``: one frame per animation frame, each to GPU completion (``timeAnimationFrames``), so the
        once-per-frame nodes (scene pass, blur) run in every frame; otherwise back to back in one task,
        GPU completion awaited once (``timeFrames``): right for update-only frames, not for renders."""
        self.page.page.bring_to_front()  # a background tab may be throttled
        before = self.effect_counters()
        method = "timeAnimationFrames" if paced else "timeFrames"
        ms = float(self.lab.call(f"([i, d]) => window.__lab.{method}(i, {{ draw: d }})", [instants, draw]))
        after = self.effect_counters()
        return {
            "ms": ms,
            "dispatches": after["dispatches"] - before["dispatches"],
            "texels": after["texelsDispatched"] - before["texelsDispatched"],
        }

    def set_blur_scale(self, scale: float) -> dict[str, Any]:
        blur: dict[str, Any] = self.lab.call("(s) => window.__lab.setBlurScale(s)", scale)
        return blur

    def set_tier(self, name: str) -> list[int]:
        size: list[int] = self.lab.call("(t) => window.__lab.setTier(t)", name)
        return size

    def gpu_errors(self) -> list[str]:
        return self.lab.gpu_errors() + list(self.page.page_errors)


def frame_totals(reports: list[dict[str, Any]]) -> dict[str, Any]:
    frames = len(reports)
    dispatches = sum(r["dispatches"] for r in reports)
    texels = sum(r["texels"] for r in reports)
    return {
        "frames": frames,
        "dispatches_total": dispatches,
        "texels_total": texels,
        "dispatches_per_frame": dispatches / frames,
        "texels_per_frame": texels / frames,
        "frames_with_dispatch": sum(1 for r in reports if r["dispatches"] > 0),
        "decisions": sorted({r["decision"] for r in reports}),
    }


def memory_record(bench: Bench, canvas: tuple[int, int], history_scale: float) -> dict[str, Any]:
    memory: dict[str, Any] = bench.lab.call("() => window.__lab.memory()")
    info = bench.lab.info()
    w, h = scaled_size(canvas[0], canvas[1], history_scale)
    bpt = BYTES_PER_TEXEL[info["format"]]
    allocated = sum(tw * th for tw, th in memory["historyTextures"]) * memory["bytesPerTexel"]
    derived = 2 * w * h * bpt
    return {
        "history_format": info["format"],
        "history_size_derived": [w, h],
        "bytes_per_texel_derived": bpt,
        "history_bytes_derived": derived,
        "history_textures_allocated": memory["historyTextures"],
        "bytes_per_texel_effect": memory["bytesPerTexel"],
        "history_bytes_allocated": allocated,
        "history_bytes_effect_reports": memory["historyBytesDerived"],
        "derived_equals_allocated": derived == allocated,
        "structure_bytes": memory["structureBytes"],
    }


def threads_launched(policy: str, history: Sequence[int], plan: dict[str, Any], texels: int) -> int:
    """Threads one update dispatch launches for ``texels`` scheduler texels (workgroup rounding)."""
    params = plan["params"]
    if policy == "full-field":
        wx, wy = (int(n) for n in params["workgroup2d"])
        return math.ceil(history[0] / wx) * wx * math.ceil(history[1] / wy) * wy
    wl = int(params["workgroupLinear"])
    return math.ceil(texels / wl) * wl


# --- sections ------------------------------------------------------------------------------------------


def measure_tiers(
    bench: Bench, canvas: tuple[int, int], frames: int, fps: int, repeats: int, log: Callable[[str], None]
) -> dict[str, Any]:
    plan = bench.plan()
    stroke = conformance_segments()
    instants = stroke_instants(stroke, frames, fps)
    still = [instants[-1]] * (frames + 1)  # update() answers 'none': render-only frames

    def one(tier: str) -> dict[str, Any]:
        bench.set_tier(tier)  # also puts the tier's blur scale back
        bench.start(stroke)
        update = bench.time_frames(instants, draw=False)
        bench.start(stroke)
        frame = bench.time_frames(instants, draw=True, paced=True)
        render = bench.time_frames(still, draw=True, paced=True)
        tiny = bench.set_blur_scale(MIN_BLUR_SCALE)
        render_tiny = bench.time_frames(still, draw=True, paced=True)
        restored = bench.set_blur_scale(plan["tiers"][tier]["blurScale"])
        return {
            "update": update,
            "frame": frame,
            "render": render,
            "render_tiny_blur": render_tiny,
            "blur": {"ms": render["ms"] - render_tiny["ms"]},
            "blur_sizes": {"tier": restored["size"], "tiny": tiny["size"]},
        }

    rounds: list[dict[str, dict[str, Any]]] = []
    for r in range(1 + repeats):
        order = list(TIERS[r % 3 :] + TIERS[: r % 3])
        log(f"  tiers round {r}{' (warm-up)' if r == 0 else ''}: {' '.join(order)}")
        rounds.append({tier: one(tier) for tier in order})
    timed = rounds[1:]
    metrics = ("update", "frame", "render", "render_tiny_blur", "blur")

    results: dict[str, Any] = {}
    for tier in TIERS:
        size = bench.set_tier(tier)
        bench.start(stroke)
        reports = bench.lab.advance(instants)
        totals = frame_totals(reports)
        samples = {k: [rd[tier][k]["ms"] / frames for rd in timed] for k in metrics}
        scale = plan["tiers"][tier]
        results[tier] = {
            "history_scale": scale["historyScale"],
            "blur_scale": scale["blurScale"],
            "history_size": size,
            "blur_target_size": timed[-1][tier]["blur_sizes"]["tier"],
            "blur_target_size_tiny": timed[-1][tier]["blur_sizes"]["tiny"],
            "ms_per_frame": {
                "update_only": _summary(samples["update"]),
                "update_and_render": _summary(samples["frame"]),
                "render_only": _summary(samples["render"]),
                "render_only_blur_1x1": _summary(samples["render_tiny_blur"]),
                "blur_estimate": _summary(samples["blur"]),
            },
            "dense_stroke_reports": {**totals, "substeps": sorted({r["substeps"] for r in reports})},
            "timed_counts_match_reports": all(
                rd[tier][k]["dispatches"] == totals["dispatches_total"]
                and rd[tier][k]["texels"] == totals["texels_total"]
                for rd in timed
                for k in ("update", "frame")
            )
            and all(rd[tier][k]["dispatches"] == 0 for rd in timed for k in ("render", "render_tiny_blur")),
            "memory": memory_record(bench, canvas, scale["historyScale"]),
        }

    def relative(metric: str) -> dict[str, float]:
        return {
            tier: _median([rd[tier][metric]["ms"] / rd["full"][metric]["ms"] for rd in timed])
            for tier in TIERS
        }

    return {
        "spec": TIER_SPEC.relative_to(REPO).as_posix(),
        "package": plan["slug"],
        "policy": plan["params"]["policy"],
        "diffusivity": plan["params"]["diffusivity"],
        "history_format": plan["tier"]["historyFormat"],
        "stroke": "creaturegen.frost.path.conformance_segments(), frames from its first sample",
        "frames": frames,
        "fps": fps,
        "measured": {
            "update_only": "timeFrames(stroke instants, draw=false): history update (+ diffusion substeps), "
            "frames back to back, GPU completion awaited once per batch",
            "update_and_render": "timeAnimationFrames(stroke instants, draw=true): update + effect.render(), "
            "one frame per animation frame, each to GPU completion",
            "render_only": "timeAnimationFrames(constant instants, draw=true): update() returns 'none'; "
            "scene pass, blur at the tier's scale, composite",
            "render_only_blur_1x1": "render_only with the blur node's resolution scale set to "
            f"{MIN_BLUR_SCALE:g} (lab setBlurScale): both blur targets 1x1, everything else unchanged",
            "blur_estimate": "derived per round: render_only - render_only_blur_1x1, i.e. the blur's "
            "resolution-dependent cost; the fixed cost of its two (1x1) passes is not in it",
        },
        "results": results,
        "measured_ratios_relative_to_full": {
            "update_only": relative("update"),
            "update_and_render": relative("frame"),
            "render_only": relative("render"),
            "blur_estimate": relative("blur"),
        },
    }


def dab_centre(history: Sequence[int], tile: int) -> tuple[float, float]:
    """Centre of the first tile (of the dirty-tile grid) in history UV."""
    return min(tile, history[0]) / 2 / history[0], min(tile, history[1]) / 2 / history[1]


def idle_case(bench: Bench, segments: list[Segment], frames: int, fps: int) -> dict[str, Any]:
    """Stroke, decay until every tile retired, then idle frames; everything counted from the reports."""
    plan = bench.plan()
    params = plan["params"]
    instants = stroke_instants(segments, frames, fps)
    last_touch = max(s.t1 for s in segments)
    decay = min(params["visible"]["decay"], params["tilt"]["decay"])
    predicted = last_touch + math.log(1.0 / params["tolerance"]) / decay
    # The longest power-of-two frame within maxInterval, on its own grid: every interval is exact.
    step = 2.0 ** math.floor(math.log2(params["maxInterval"]))
    t = instants[-1]
    first = math.ceil(t / step)
    coarse = [t] + [
        k * step for k in range(first, math.ceil((predicted * 1.1 + 2.0) / step) + 1) if k * step > t
    ]
    bench.start(segments)
    stroke_reports = bench.lab.advance(instants)
    decay_reports = bench.lab.advance(coarse)
    reports = stroke_reports + decay_reports
    ends = instants[1:] + coarse[1:]
    retire_frames = [i for i, r in enumerate(reports) if r["retiredTiles"] > 0]
    active = [i for i, r in enumerate(reports) if r["dispatches"] > 0]
    t_idle = coarse[-1]
    idle_instants = [t_idle + k / fps for k in range(frames + 1)]
    before = bench.effect_counters()
    idle_reports = bench.lab.advance(idle_instants)
    after = bench.effect_counters()
    timed_instants = [idle_instants[-1] + k / fps for k in range(frames + 1)]
    timed = bench.time_frames(timed_instants, draw=False)
    return {
        "stroke_frames": len(stroke_reports),
        "decay_frame_seconds": step,
        "decay_frames": len(decay_reports),
        "retired_tiles_total": sum(r["retiredTiles"] for r in reports),
        "last_retire_at_s": ends[retire_frames[-1]] if retire_frames else None,
        "last_dispatch_at_s": ends[active[-1]] if active else None,
        "predicted_retire_at_s": predicted,
        "predicted_note": "last touch + ln(1/tolerance)/min(decay); measured on the frame grid above",
        "idle_frames": len(idle_reports),
        "idle_frame_seconds": 1 / fps,
        "idle_dispatches_per_frame_max": max(r["dispatches"] for r in idle_reports),
        "idle_dispatches_total": sum(r["dispatches"] for r in idle_reports),
        "idle_texels_total": sum(r["texels"] for r in idle_reports),
        "idle_decisions": sorted({r["decision"] for r in idle_reports}),
        "idle_counter_delta": {
            "dispatches": after["dispatches"] - before["dispatches"],
            "idleFrames": after["idleFrames"] - before["idleFrames"],
            "frames": after["frames"] - before["frames"],
        },
        "idle_ms_per_frame_update_only": timed["ms"] / frames,
        "idle_timed_dispatches": timed["dispatches"],
    }


def measure_sparse(
    benches: dict[str, Bench],
    canvas: tuple[int, int],
    frames: int,
    fps: int,
    repeats: int,
    log: Callable[[str], None],
) -> dict[str, Any]:
    plans = {p: b.plan() for p, b in benches.items()}
    tile = plans["dirty-tiles"]["params"]["tileSize"]
    scale = plans["dirty-tiles"]["params"]["historyScale"]
    history = scaled_size(canvas[0], canvas[1], scale)
    dab = dab_segments(dab_centre(history, tile))
    instants = stroke_instants(dab, frames, fps)

    rounds: list[dict[str, dict[str, Any]]] = []
    for r in range(1 + repeats):
        order = list(POLICIES[r % 2 :] + POLICIES[: r % 2])
        log(f"  sparse round {r}{' (warm-up)' if r == 0 else ''}: {' '.join(order)}")
        row = {}
        for policy in order:
            benches[policy].start(dab)
            row[policy] = benches[policy].time_frames(instants, draw=False)
        rounds.append(row)
    timed = rounds[1:]

    variants: dict[str, Any] = {}
    for policy, bench in benches.items():
        bench.start(dab)
        reports = bench.lab.advance(instants)
        totals = frame_totals(reports)
        info = bench.lab.info()
        sched_tile = list(history) if policy == "full-field" else [tile, tile]
        launched = sum(
            threads_launched(
                policy, info["historySize"], plans[policy], r["texels"] // max(1, r["dispatches"])
            )
            * r["dispatches"]
            for r in reports
            if r["dispatches"]
        )
        variants[policy] = {
            "package": plans[policy]["slug"],
            "history_size": info["historySize"],
            "scheduler_tile": sched_tile,
            "tile_grid": [math.ceil(history[0] / sched_tile[0]), math.ceil(history[1] / sched_tile[1])],
            **totals,
            "update_tiles_per_frame_max": max(r["updateTiles"] for r in reports),
            "threads_launched_total": launched,
            "ms_per_frame_update_only": _summary([rd[policy]["ms"] / frames for rd in timed]),
            "timed_counts_match_reports": all(
                rd[policy]["dispatches"] == totals["dispatches_total"]
                and rd[policy]["texels"] == totals["texels_total"]
                for rd in timed
            ),
            "memory": memory_record(bench, canvas, scale),
        }
    full, dirty = variants["full-field"], variants["dirty-tiles"]
    return {
        "base_spec": SPARSE_BASE_SPEC.relative_to(REPO).as_posix(),
        "differs_only_in": "update.policy",
        "stroke": {
            "kind": "dab: a closed circle at the centre of the first dirty tile",
            "centre_uv": list(dab_centre(history, tile)),
            "radius_uv": DAB_RADIUS,
            "t0": DAB_START,
            "t1": DAB_START + DAB_SECONDS,
            "pointer_hz": DAB_HZ,
            "segments": len(dab),
        },
        "frames": frames,
        "fps": fps,
        "variants": variants,
        "measured_ratios": {
            "texels_full_field_over_dirty_tiles": full["texels_total"] / max(1, dirty["texels_total"]),
            "threads_full_field_over_dirty_tiles": full["threads_launched_total"]
            / max(1, dirty["threads_launched_total"]),
            "ms_full_field_over_dirty_tiles": _median(
                [rd["full-field"]["ms"] / rd["dirty-tiles"]["ms"] for rd in timed]
            ),
        },
        "_dab": dab,
    }


def second_page(first: LabPage, url: str, timeout_s: float = 90.0) -> LabPage:
    """Another lab page in the same browser (Playwright's sync API cannot run two browsers at once)."""
    browser = first.page.context.browser
    assert browser is not None
    page = browser.new_page()
    second = LabPage(page=page, url=url, executable=first.executable, lab={})
    page.on("console", lambda m: second.console.append(f"[{m.type}] {m.text}"))
    page.on("pageerror", lambda e: second.page_errors.append(f"{e.name}: {e.message}"))
    page.goto(url, wait_until="load", timeout=timeout_s * 1000)
    page.wait_for_function(READY_EXPRESSION, timeout=timeout_s * 1000)
    second.lab = page.evaluate("() => window.__lab")
    return second


# --- driver --------------------------------------------------------------------------------------------


def environment(page: LabPage) -> dict[str, Any]:
    browser = page.page.context.browser
    return {
        **machine(),
        "chromium": str(page.executable),
        "chromium_version": browser.version if browser is not None else None,
    }


def device_record(bench: Bench) -> dict[str, Any]:
    info = bench.lab.info()
    return {k: info[k] for k in ("isWebGPUBackend", "adapter", "limits", "features")}


def table(report: dict[str, Any]) -> str:
    tiers = report["tiers"]
    rel = tiers["measured_ratios_relative_to_full"]
    canvas = "x".join(map(str, report["parameters"]["canvas"]))
    lines = [
        f"tiers ({tiers['package']}, {tiers['policy']}, canvas {canvas}, ms/frame medians;"
        " ×: cost relative to full, per-round medians)",
        f"{'tier':<10}{'history':>9}{'blur':>8}{'update':>8}{'×':>6}{'upd+rnd':>9}{'×':>6}"
        f"{'render':>8}{'×':>6}{'blur1x1':>8}{'blur est':>9}{'×':>6}{'hist B der/alloc':>20}",
    ]
    for tier in TIERS:
        r = tiers["results"][tier]
        ms, mem = r["ms_per_frame"], r["memory"]
        history, blur = ("x".join(map(str, r[k])) for k in ("history_size", "blur_target_size"))
        lines.append(
            f"{tier:<10}{history:>9}{blur:>8}"
            f"{ms['update_only']['median']:>8.2f}{rel['update_only'][tier]:>6.2f}"
            f"{ms['update_and_render']['median']:>9.2f}{rel['update_and_render'][tier]:>6.2f}"
            f"{ms['render_only']['median']:>8.2f}{rel['render_only'][tier]:>6.2f}"
            f"{ms['render_only_blur_1x1']['median']:>8.2f}{ms['blur_estimate']['median']:>9.2f}"
            f"{rel['blur_estimate'][tier]:>6.2f}"
            f"{mem['history_bytes_derived']:>10}/{mem['history_bytes_allocated']:<9}"
        )
    sparse = report["sparse"]
    lines.append(f"sparse dab ({sparse['base_spec']}, only update.policy differs; {sparse['frames']} frames)")
    lines.append(f"{'policy':<12}{'history':>9}{'tiles':>7}{'texels/fr':>11}{'disp/fr':>9}{'ms/fr':>8}")
    for policy in POLICIES:
        v = sparse["variants"][policy]
        lines.append(
            f"{policy:<12}{'x'.join(map(str, v['history_size'])):>9}{'x'.join(map(str, v['tile_grid'])):>7}"
            f"{v['texels_per_frame']:>11.0f}{v['dispatches_per_frame']:>9.2f}"
            f"{v['ms_per_frame_update_only']['median']:>8.3f}"
        )
    m = sparse["measured_ratios"]
    lines.append(
        f"full-field / dirty-tiles: texels {m['texels_full_field_over_dirty_tiles']:.2f}, "
        f"ms {m['ms_full_field_over_dirty_tiles']:.2f}"
    )
    lines.append(f"{'idle case':<32}{'retired at s':>13}{'pred s':>8}{'idle fr':>8}{'disp':>6}{'ms/fr':>8}")
    for case in report["idle"]:
        lines.append(
            f"{case['case']:<32}{case['last_retire_at_s'] or float('nan'):>13.2f}"
            f"{case['predicted_retire_at_s']:>8.2f}{case['idle_frames']:>8}{case['idle_dispatches_total']:>6}"
            f"{case['idle_ms_per_frame_update_only']:>8.3f}"
        )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--out", type=Path, default=REPO / "bench" / "results" / "frost.json")
    parser.add_argument("--canvas", type=parse_canvas, default=(320, 192), help="drawing buffer WxH")
    parser.add_argument("--repeats", type=int, default=3, help="timed rounds after one warm-up round")
    parser.add_argument("--frames", type=int, default=30, help="frames per timed batch")
    parser.add_argument("--fps", type=int, default=60, help="frame rate of the replayed strokes")
    args = parser.parse_args(argv)
    if args.repeats < 1 or args.frames < 1 or args.fps < 1:
        parser.error("--repeats, --frames and --fps must be at least 1")
    canvas: tuple[int, int] = args.canvas

    def log(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    started = time.perf_counter()
    errors: dict[str, list[str]] = {}
    with tempfile.TemporaryDirectory(prefix="creaturegen-bench-frost-") as tmp:
        out_root = Path(tmp)
        log("[1/4] building packages")
        jobs = {"tiers": (TIER_SPEC, out_root / "tiers")}
        (out_root / "specs").mkdir()
        for policy in POLICIES:
            spec = json.loads(SPARSE_BASE_SPEC.read_text())
            spec.setdefault("update", {})["policy"] = policy  # the only difference between the two
            path = out_root / "specs" / f"{policy}.json"
            path.write_text(json.dumps(spec, indent=2) + "\n")
            jobs[policy] = (path, out_root / policy)
        builds = build_packages(jobs, log)

        def url(base_url: str, key: str) -> str:
            slug = f"{key}/{builds[key]['_folder'].name}"
            return f"{base_url}frost.html?pkg={slug}&w={canvas[0]}&h={canvas[1]}"

        with serve(WEB_LAB, mounts={"out": out_root}) as base_url:
            log("[2/4] tiers (frost-full, setTier)")
            with launch_lab_page(url(base_url, "tiers"), extra_args=BROWSER_FLAGS) as page:
                bench = Bench(page)
                env = environment(page)
                device = device_record(bench)
                tiers = measure_tiers(bench, canvas, args.frames, args.fps, args.repeats, log)
                log("[3/4] idle after the conformance stroke (frost-full, authored tier)")
                bench.set_tier(bench.plan()["tier"]["name"])
                idle = [
                    {
                        "case": f"{tiers['package']} ({bench.plan()['tier']['name']}, full-field)",
                        "package": tiers["package"],
                        "policy": "full-field",
                        **idle_case(bench, conformance_segments(), args.frames, args.fps),
                    }
                ]
                errors["tiers"] = bench.gpu_errors()
            log("[4/4] sparse dab: full-field vs dirty-tiles (frost-budgeted)")
            with launch_lab_page(url(base_url, "full-field"), extra_args=BROWSER_FLAGS) as page_ff:
                page_dt = second_page(page_ff, url(base_url, "dirty-tiles"))
                benches = {"full-field": Bench(page_ff), "dirty-tiles": Bench(page_dt)}
                sparse = measure_sparse(benches, canvas, args.frames, args.fps, args.repeats, log)
                dab = sparse.pop("_dab")
                for policy, b in benches.items():
                    idle.append(
                        {
                            "case": f"budgeted dab ({policy})",
                            "package": sparse["variants"][policy]["package"],
                            "policy": policy,
                            **idle_case(b, dab, args.frames, args.fps),
                        }
                    )
                    errors[policy] = b.gpu_errors()

    report = {
        "benchmark": "frost",
        "environment": env,
        "device": device,
        "parameters": {
            "canvas": list(canvas),
            "repeats": args.repeats,
            "warmup_rounds": 1,
            "frames": args.frames,
            "fps": args.fps,
            "ratios": "median over rounds of the ratio of two variants timed in the same round; the variant "
            "order rotates every round",
            "builds": {
                key: {
                    "package": b["package"],
                    "specSha256": b["specSha256"],
                    "historyFormat": b["historyFormat"]["historyFormat"],
                    "policy": b["params"]["policy"],
                    "tileSize": b["params"]["tileSize"],
                }
                for key, b in builds.items()
            },
        },
        "tiers": tiers,
        "sparse": sparse,
        "idle": idle,
        "gpu_errors": errors,
        "notes": NOTES,
        "wall_seconds": time.perf_counter() - started,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n")
    print(table(report), flush=True)
    log(f"wrote {args.out} ({report['wall_seconds']:.1f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
