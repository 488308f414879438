"""Locomotion core benchmark in Node: CPU cost per creature per fixed step for each locomotion type, rope
cost against substeps × passes × segments, and allocation in steady state.

For every package (default: one built example per locomotion type, built into ``--packages-dir`` with
``creaturegen build`` when missing), ``bench/motion.mjs`` imports the package's own ``core/`` in Node and
measures, in this run:

* **step cost**: ``--bodies`` creatures (seeds 1..N, flat ground, the analytic water for a swimmer) after
  ``--warm`` steps each; ``--rounds`` rounds of ``--ticks`` steps of every body; the median µs per
  creature per step (min and max beside it);
* **allocation**: one creature after 20000 warm-up steps, then five windows of ``--alloc-steps`` steps,
  each after a full collection (``--expose-gc``): V8 heap growth (``heapUsed``) and the garbage
  collections a ``gc`` PerformanceObserver saw start inside the window. The cleanest window (fewest
  collections, then least growth) is reported, every window beside it. Node runs with
  ``--no-concurrent-recompilation`` so the optimised step lands at the same point whatever the load. Zero
  bytes per step and no collection is the contract; bytes per step understate the rate when a collection
  ran in the window;
* **ropes** (creatures with ropes): the step cost with the ropes removed and at several (substeps, passes),
  and the least-squares µs per unit of rope work (substeps · passes · segments).

JSON goes to ``--out``, progress to stderr, a table to stdout.

    python bench/motion.py --out bench/results/motion.json
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from benchlib import machine
from creaturegen.spec import load_spec, slugify

REPO = Path(__file__).resolve().parents[1]
WORKER = REPO / "bench" / "motion.mjs"
#: One example per locomotion type, plus the two other rope creatures (spec path under examples/).
DEFAULT_EXAMPLES = (
    "reference/biped.json",
    "reference/quadruped.json",
    "reference/hexapod.json",
    "reference/hopper.json",
    "reference/flyer.json",
    "reference/swimmer.json",
    "lizard.json",
    "moth.json",
)


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def ensure_package(spec: Path, packages: Path) -> Path:
    """The built package of ``spec`` under ``packages`` (built with `creaturegen build` when missing)."""
    loaded = load_spec(spec)
    folder = packages / slugify(loaded.name)
    if (folder / "core" / "index.js").is_file():
        return folder
    log(f"  building {spec.relative_to(REPO)} into {packages}")
    started = time.perf_counter()
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "creaturegen.cli",
            "build",
            str(spec),
            "-o",
            str(packages),
            "--picture",
            "off",
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    if proc.returncode != 0 or not (folder / "core" / "index.js").is_file():
        raise RuntimeError(f"creaturegen build {spec} failed:\n{proc.stdout}{proc.stderr}")
    log(f"  built {folder.name} in {time.perf_counter() - started:.1f} s")
    return folder


def measure(package: Path, options: dict[str, Any]) -> dict[str, Any]:
    node = shutil.which("node")
    if node is None:
        raise SystemExit("bench/motion needs node on PATH")
    proc = subprocess.run(
        [
            node,
            "--expose-gc",
            "--no-concurrent-recompilation",
            str(WORKER),
            str(package / "core" / "index.js"),
            json.dumps(options),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    if proc.returncode != 0:
        raise RuntimeError(f"{package.name}: bench/motion.mjs failed:\n{proc.stderr}")
    result: dict[str, Any] = json.loads(proc.stdout)
    return result


def table(results: list[dict[str, Any]]) -> str:
    lines = [
        "| package | type | slots | µs/step (median) | step p50 | step p95 | step max | bytes/step | GCs "
        "| live kB/body | rope µs per substep·pass·segment |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        rope = f"{r['rope']['usPerUnit']:.3f}" if "rope" in r else "-"
        one = r["step"]["perStep"]
        lines.append(
            f"| {r['package']} | {r['type']} | {r['slots']} | {r['step']['median']:.2f} | {one['p50']:.2f} | "
            f"{one['p95']:.2f} | {one['max']:.2f} | {r['allocation']['bytesPerStep']:.1f} | "
            f"{r['allocation']['collections']} | {r['live']['perBodyBytes'] / 1024:.1f} | {rope} |"
        )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument(
        "packages", nargs="*", type=Path, help="built creature packages (default: the examples)"
    )
    parser.add_argument(
        "--packages-dir", type=Path, default=REPO / "out", help="where missing examples are built"
    )
    parser.add_argument("--out", type=Path, default=REPO / "bench" / "results" / "motion.json")
    parser.add_argument("--bodies", type=int, default=32)
    parser.add_argument("--warm", type=int, default=300, help="steps before anything is measured")
    parser.add_argument("--ticks", type=int, default=300, help="steps of every body per timed round")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--alloc-steps", type=int, default=3000)
    args = parser.parse_args(argv)
    for name in ("bodies", "warm", "ticks", "rounds", "alloc_steps"):
        if getattr(args, name) < 1:
            parser.error(f"--{name.replace('_', '-')} must be at least 1")
    started = time.perf_counter()
    packages = list(args.packages) or [
        ensure_package(REPO / "examples" / name, args.packages_dir) for name in DEFAULT_EXAMPLES
    ]
    options = {
        "bodies": args.bodies,
        "warm": args.warm,
        "ticks": args.ticks,
        "rounds": args.rounds,
        "allocSteps": args.alloc_steps,
    }
    results = []
    for package in packages:
        if not (package / "core" / "index.js").is_file():
            raise SystemExit(f"{package}: not a built creature package (no core/index.js)")
        log(f"==> {package.name}")
        results.append(measure(package, options))
    report = {
        "benchmark": "motion",
        "environment": machine(),
        "parameters": options,
        "results": results,
        "notes": (
            "Node runs each package's own core/ (the code the population calls per fixed step). Step cost is "
            "wall time per creature per step, median of rounds, and p50/p95/max of single steps of the whole "
            "population (perStep, µs per creature); allocation is V8 heapUsed growth over the "
            "steps after a full collection, with the collections a gc PerformanceObserver saw; live is the "
            "bodies' heap after full collections (peak over checkpoints, per body); rope cost is "
            "the step cost minus the same creature without ropes, fitted against substeps*passes*segments."
        ),
        "wall_seconds": time.perf_counter() - started,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n")
    print(table(results))
    log(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
