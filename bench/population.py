"""Population CPU benchmark in Node (issue 27, item 5): what a frame of a large creature population costs
the CPU, and whether its steady loop allocates.

``bench/population.mjs`` runs the package's own ``createCreaturePopulation`` in Node against a stand-in
renderer (it records compute dispatches and consumes the attributes' update ranges after each frame, as
three's backend does when it uploads them; no GPU work runs), with ``--bodies`` bodies (default 1024) in
pages of ``--page-size`` on a grid. Measured in this run:

* **cost**: µs per body per frame of ``update(1 / tickRate)`` (one fixed step per frame: the locomotion
  step, the render pose written into the staging copy, the change test, culling and the instance lists),
  p50/p95 over ``--frames`` frames after ``--warm-frames``, in four scenarios: every body moving; every
  other body paused; culled to a top-down camera that sees ``--in-view`` of the bodies, all moving; and
  culled with half paused;
* **allocation**: V8 heap growth and the garbage collections a ``gc`` PerformanceObserver saw start inside
  windows of ``--alloc-frames`` frames and of three times as many, each after a full collection, after a
  warm-up (the cleanest of five windows of each length reported, all beside it), for the moving and the
  culled-half-paused scenarios; bytes per frame are the growth of the long window less the short one's
  over the frames between them (the probe's own per-window cost cancels). Node runs
  with ``--no-concurrent-recompilation`` (as bench/motion.py).

The JSON's ``targets``: no collection and no heap growth per frame in the steady loop.

    python bench/population.py --out bench/results/population.json
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from benchlib import machine
from runtime import DEFAULT_PACKAGE, WEB_LAB, ensure_package

REPO = Path(__file__).resolve().parents[1]
WORKER = REPO / "bench" / "population.mjs"


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def run_worker(package: Path, options: dict[str, Any]) -> dict[str, Any]:
    """The worker on a copy of ``package`` beside a node_modules that resolves three (the lab's)."""
    with tempfile.TemporaryDirectory(prefix="cg-population-") as scratch:
        root = Path(scratch)
        shutil.copytree(package, root / "pkg")
        (root / "node_modules").symlink_to(WEB_LAB / "node_modules", target_is_directory=True)
        command = ["node", "--expose-gc", "--no-concurrent-recompilation", str(WORKER), str(root / "pkg")]
        done = subprocess.run([*command, json.dumps(options)], capture_output=True, text=True, check=False)
        if done.returncode != 0:
            raise RuntimeError(f"bench/population.mjs failed:\n{done.stderr[-3000:]}")
        result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
        return result


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("package", nargs="?", type=Path, default=DEFAULT_PACKAGE)
    parser.add_argument("--out", type=Path, default=REPO / "bench" / "results" / "population.json")
    parser.add_argument("--bodies", type=int, default=1024)
    parser.add_argument("--page-size", type=int, default=64)
    parser.add_argument("--in-view", type=float, default=0.10)
    parser.add_argument("--warm-frames", type=int, default=120)
    parser.add_argument("--frames", type=int, default=120)
    parser.add_argument("--alloc-warm", type=int, default=2000, help="frames before the windows (V8 settles)")
    parser.add_argument("--alloc-frames", type=int, default=300)
    args = parser.parse_args(argv)
    folder: Path = args.package.resolve()
    ensure_package(folder, log)
    options = {
        "bodies": args.bodies,
        "pageSize": args.page_size,
        "inView": args.in_view,
        "warmFrames": args.warm_frames,
        "frames": args.frames,
        "allocWarm": args.alloc_warm,
        "allocFrames": args.alloc_frames,
    }
    log(f"population CPU bench: {folder.name}, {args.bodies} bodies")
    result = run_worker(folder, options)
    targets = [
        {
            "name": f"garbage collections in a window of {w['frames']} frames ({w['scenario']})",
            "value": w["collections"],
            "target": 0,
            "met": w["collections"] == 0 and w["long"]["collections"] == 0,
        }
        for w in result["allocation"]
    ] + [
        {
            "name": f"heap growth per frame ({w['scenario']}), bytes",
            "value": w["bytesPerFrame"],
            "target": 0,
            "met": w["collections"] == 0 and w["long"]["collections"] == 0 and w["bytesPerFrame"] <= 0,
        }
        for w in result["allocation"]
    ]
    report = {"benchmark": "population", "machine": machine(), **result, "targets": targets}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    for name, s in result["scenarios"].items():
        cost = s["usPerBodyPerFrame"]
        print(
            f"{name:<20} {cost['p50']:7.2f} µs/body/frame (p95 {cost['p95']:.2f})  drawn {s['drawnBodies']}"
            f"  deformed {s['deformedBodies']}  dispatches {s['dispatchesPerFrame']:.1f}"
        )
    for t in targets:
        print(f"{'met ' if t['met'] else 'MISS'} {t['name']}: {t['value']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
