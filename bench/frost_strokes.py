"""Frost history update under many strokes at once: binned vs unbinned, side by side in one run.

Each case queues N pointer streams wiping at once (N = 1, 8, 64 by default), each a short stroke in its own
cell of an 8 x 8 grid over the pane, and replays them at 60 FPS. Two lab pages load the same package: one with
the shipped binned update (a texel loops over the (step, segment) pairs its screen tile's bin holds), one with
``binning: false`` (every texel loops over every pair of the dispatch, the cost before binning). Per case and
variant: per-frame update ms to GPU completion (p50, p95; rounds alternate the variant order, after a warm-up
round), pairs, bin entries and law evaluations (texel-steps) per frame from the effect's own frame reports,
and updated tiles. The claim under test is the seed's: with overlapping events the cost is
Σ_t P_t·E_t over touched tiles t (texels × entries), not every updated texel × every event.

    python bench/frost_strokes.py [--out bench/results/frost_strokes.json] [--canvas 640x384]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from benchlib import machine
from creaturegen.frost.brush import Segment
from creaturegen.lab.browser import launch_lab_page
from creaturegen.lab.server import serve
from frost import BROWSER_FLAGS, Bench, build_packages, parse_canvas, second_page

REPO = Path(__file__).resolve().parents[1]
WEB_LAB = REPO / "generator" / "creaturegen" / "web_lab"
SPECS = {
    "dirty-tiles": REPO / "examples" / "frost" / "frost-balanced.json",
    "full-field": REPO / "examples" / "frost" / "frost-full.json",
}
STROKE_COUNTS = (1, 8, 64)
STROKE_SECONDS = 0.4
PIECES = 8
GRID = 8


def strokes(count: int) -> list[Segment]:
    """``count`` streams at once: stroke k wipes across cell k of an 8 x 8 grid (0.09 of the pane wide),
    all starting together; in time order, as pointers deliver them."""
    segments = []
    for k in range(count):
        cx, cy = (k % GRID + 0.5) / GRID, (k // GRID % GRID + 0.5) / GRID
        for j in range(PIECES):
            a, b = j / PIECES, (j + 1) / PIECES
            segments.append(
                Segment(
                    0.05 + STROKE_SECONDS * a,
                    0.05 + STROKE_SECONDS * b,
                    (cx - 0.045 + 0.09 * a, cy),
                    (cx - 0.045 + 0.09 * b, cy),
                    stream=k + 1,
                )
            )
    return sorted(segments, key=lambda g: (g.t0, g.stream))


def percentile(values: Sequence[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def measure(pages: dict[str, Bench], count: int, frames: int, repeats: int, log: Any) -> dict[str, Any]:
    segments = strokes(count)
    instants = [k / 60 for k in range(frames + 1)]
    per_frame: dict[str, list[float]] = {v: [] for v in pages}
    for r in range(1 + repeats):
        order = list(pages)[r % 2 :] + list(pages)[: r % 2]
        for variant in order:
            bench = pages[variant]
            bench.start(segments)
            ms = bench.lab.call("(i) => window.__lab.timeFramesEach(i)", instants)
            if r > 0:
                per_frame[variant] += [float(x) for x in ms]
        log(f"    {count} strokes, round {r}{' (warm-up)' if r == 0 else ''}: {' '.join(order)}")
    result: dict[str, Any] = {"strokes": count, "segments": len(segments), "variants": {}}
    for variant, bench in pages.items():
        bench.start(segments)
        reports = bench.lab.advance(instants)
        active = [r for r in reports if r["binEntries"] > 0]
        result["variants"][variant] = {
            "ms_per_frame_p50": statistics.median(per_frame[variant]),
            "ms_per_frame_p95": percentile(per_frame[variant], 0.95),
            "frames_timed": len(per_frame[variant]),
            "update_tiles_per_frame_max": max(r["updateTiles"] for r in reports),
            "bin_entries_per_active_frame": sum(r["binEntries"] for r in active) / max(1, len(active)),
            "texel_steps_per_active_frame": sum(r["texelSteps"] for r in active) / max(1, len(active)),
            "texels_per_active_frame": sum(r["texels"] for r in active) / max(1, len(active)),
            "gpu_errors": bench.gpu_errors(),
        }
    binned, unbinned = result["variants"]["binned"], result["variants"]["unbinned"]
    result["measured_ratios"] = {
        "texel_steps_unbinned_over_binned": unbinned["texel_steps_per_active_frame"]
        / max(1.0, binned["texel_steps_per_active_frame"]),
        "ms_p50_unbinned_over_binned": unbinned["ms_per_frame_p50"] / binned["ms_per_frame_p50"],
    }
    return result


def table(report: dict[str, Any]) -> str:
    lines = [
        f"frost strokes at once (canvas {'x'.join(map(str, report['parameters']['canvas']))}, update only, "
        "per-frame ms to GPU completion; texel-steps: law evaluations per frame with input)",
        f"{'policy':<12}{'strokes':>8}{'tiles':>7}{'entries':>9}{'texel-steps binned':>20}{'unbinned':>12}"
        f"{'ms p50/p95 binned':>20}{'unbinned':>16}{'× ms':>7}",
    ]
    for policy, cases in report["policies"].items():
        for case in cases:
            b, u = case["variants"]["binned"], case["variants"]["unbinned"]
            lines.append(
                f"{policy:<12}{case['strokes']:>8}{b['update_tiles_per_frame_max']:>7}"
                f"{b['bin_entries_per_active_frame']:>9.0f}{b['texel_steps_per_active_frame']:>20,.0f}"
                f"{u['texel_steps_per_active_frame']:>12,.0f}"
                f"{b['ms_per_frame_p50']:>11.2f} / {b['ms_per_frame_p95']:<6.2f}"
                f"{u['ms_per_frame_p50']:>8.2f} / {u['ms_per_frame_p95']:<6.2f}"
                f"{case['measured_ratios']['ms_p50_unbinned_over_binned']:>6.2f}"
            )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--out", type=Path, default=REPO / "bench" / "results" / "frost_strokes.json")
    parser.add_argument("--canvas", type=parse_canvas, default=(640, 384), help="drawing buffer WxH")
    parser.add_argument("--repeats", type=int, default=3, help="timed rounds after one warm-up round")
    parser.add_argument("--frames", type=int, default=30, help="frames per round (60 FPS instants)")
    parser.add_argument(
        "--strokes", default=",".join(map(str, STROKE_COUNTS)), help="stroke counts, comma-separated"
    )
    args = parser.parse_args(argv)
    counts = tuple(int(n) for n in args.strokes.split(","))
    if args.repeats < 1 or args.frames < 1 or not all(1 <= n <= GRID * GRID for n in counts):
        parser.error(f"--repeats and --frames must be at least 1, --strokes in 1..{GRID * GRID}")
    canvas: tuple[int, int] = args.canvas

    def log(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    started = time.perf_counter()
    policies: dict[str, list[dict[str, Any]]] = {}
    with tempfile.TemporaryDirectory(prefix="creaturegen-bench-strokes-") as tmp:
        out_root = Path(tmp)
        log("[1/2] building packages")
        builds = build_packages({key: (spec, out_root / key) for key, spec in SPECS.items()}, log)
        with serve(WEB_LAB, mounts={"out": out_root}) as base_url:
            log("[2/2] strokes at once, binned and unbinned pages side by side")
            for policy in SPECS:
                slug = f"{policy}/{builds[policy]['_folder'].name}"
                url = f"{base_url}frost.html?pkg={slug}&w={canvas[0]}&h={canvas[1]}"
                with launch_lab_page(url, extra_args=BROWSER_FLAGS) as page:
                    pages = {"binned": Bench(page), "unbinned": Bench(second_page(page, url + "&binning=0"))}
                    history = pages["binned"].lab.info()["historySize"]
                    log(f"  {policy}: history {history[0]}x{history[1]}")
                    policies[policy] = [
                        {"history": history, **measure(pages, n, args.frames, args.repeats, log)}
                        for n in counts
                    ]
    report = {
        "benchmark": "frost_strokes",
        "environment": machine(),
        "parameters": {
            "canvas": list(canvas),
            "frames": args.frames,
            "repeats": args.repeats,
            "warmup_rounds": 1,
            "strokes": list(counts),
            "stroke": f"{PIECES} segments over {STROKE_SECONDS} s, 0.09 of the pane wide, one per grid cell",
            "specs": {k: v.relative_to(REPO).as_posix() for k, v in SPECS.items()},
        },
        "policies": policies,
        "wall_seconds": time.perf_counter() - started,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n")
    print(table(report), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
