"""Pipeline benchmark: `creaturegen build` of every creature example at a base revision and at this
working tree, side by side in one run (issue 26: the one-way pipeline must not make builds slower).

Each revision runs from its own git worktree (the base) or this checkout (the head) with the same
interpreter and libraries; each build gets a fresh, empty surface cache (``cold``: extraction, gates,
skin sweeps, posed quality, emission) and is then repeated on that cache (``warm``: what is left when
the surface comes from the cache: rig, motion, envelope, candidates, plan, emission). The order of the
two revisions alternates from one example to the next, so a machine that slows down over the run
burdens both. No README picture (it times Chromium, not the pipeline).

    python bench/pipeline.py --base f30375d --out bench/results/pipeline.json

The default base, f30375d, is the last commit before issue 26's restructuring (the posed-skin
measurement it timed was already in); the README reports the figures of the latest run.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from benchlib import REPO, machine

#: The last commit before issue 26's restructuring.
DEFAULT_BASE = "f30375d"
EXAMPLES = [
    *sorted(str(p.relative_to(REPO)) for p in (REPO / "examples" / "reference").glob("*.json")),
    "examples/beetle.json",
    "examples/lizard.json",
    "examples/moth.json",
]


def worktree(base: str, root: Path) -> Path:
    """A detached worktree of ``base`` under ``root`` (removed by :func:`drop_worktree`)."""
    folder = root / f"base-{base}"
    subprocess.run(
        ["git", "worktree", "add", "--detach", "--force", str(folder), base],
        cwd=REPO,
        check=True,
        capture_output=True,
    )
    return folder


def drop_worktree(folder: Path) -> None:
    subprocess.run(["git", "worktree", "remove", "--force", str(folder)], cwd=REPO, capture_output=True)


def timed_build(checkout: Path, spec: str, cache: Path, out: Path) -> tuple[float, int]:
    """Seconds of one `creaturegen build` of ``spec`` from ``checkout``'s sources, and its exit code."""
    env = {
        **os.environ,
        "PYTHONPATH": str(checkout / "generator"),
        "CREATUREGEN_CACHE": str(cache),
        "CREATUREGEN_PICTURE": "off",
    }
    # The console script's entry point, imported from the checkout on PYTHONPATH.
    entry = "import sys; from creaturegen.cli import main; sys.exit(main())"
    command = [sys.executable, "-c", entry, "build", str(REPO / spec), "-o", str(out), "--picture", "off"]
    start = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode not in (0, 3):
        raise RuntimeError(f"{checkout}: build of {spec} exited {done.returncode}:\n{done.stderr[-2000:]}")
    return seconds, done.returncode


def measure(checkout: Path, spec: str, scratch: Path) -> dict[str, Any]:
    cache = Path(tempfile.mkdtemp(dir=scratch, prefix="cache-"))
    out = Path(tempfile.mkdtemp(dir=scratch, prefix="out-"))
    cold, code = timed_build(checkout, spec, cache, out)
    shutil.rmtree(out)
    out.mkdir()
    warm, warm_code = timed_build(checkout, spec, cache, out)
    shutil.rmtree(cache)
    shutil.rmtree(out)
    return {"cold_s": round(cold, 3), "warm_s": round(warm, 3), "exit": code, "warm_exit": warm_code}


def geometric_mean(values: list[float]) -> float:
    return math.exp(sum(math.log(v) for v in values) / len(values)) if values else float("nan")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", default=DEFAULT_BASE, help=f"base revision (default {DEFAULT_BASE})")
    parser.add_argument("--examples", nargs="*", default=EXAMPLES, help="creature specs (default: all)")
    parser.add_argument("--out", default=str(REPO / "bench" / "results" / "pipeline.json"))
    args = parser.parse_args()
    scratch = Path(tempfile.mkdtemp(prefix="cg-pipeline-"))
    base_checkout = worktree(args.base, scratch)
    rows: list[dict[str, Any]] = []
    try:
        for index, spec in enumerate(args.examples):
            order = [("base", base_checkout), ("head", REPO)]
            if index % 2:
                order.reverse()
            row: dict[str, Any] = {"example": spec}
            for name, checkout in order:
                row[name] = measure(checkout, spec, scratch)
            for phase in ("cold_s", "warm_s"):
                row[f"{phase[:-2]}_ratio"] = round(row["head"][phase] / row["base"][phase], 3)
            rows.append(row)
            print(
                f"{spec:<34} cold {row['base']['cold_s']:7.2f} s -> {row['head']['cold_s']:7.2f} s "
                f"(x{row['cold_ratio']:.3f})   warm {row['base']['warm_s']:6.2f} s -> "
                f"{row['head']['warm_s']:6.2f} s (x{row['warm_ratio']:.3f})",
                flush=True,
            )
    finally:
        drop_worktree(base_checkout)
        shutil.rmtree(scratch, ignore_errors=True)
    same_exit = [r for r in rows if r["base"]["exit"] == r["head"]["exit"]]
    result = {
        "benchmark": "pipeline",
        "machine": machine(),
        "base": args.base,
        "head": "working tree",
        "rows": rows,
        "summary": {
            "examples": len(rows),
            "same_outcome": len(same_exit),
            "cold_ratio_geomean": round(geometric_mean([r["cold_ratio"] for r in same_exit]), 3),
            "warm_ratio_geomean": round(geometric_mean([r["warm_ratio"] for r in same_exit]), 3),
            "cold_total_s": {
                side: round(sum(r[side]["cold_s"] for r in rows), 2) for side in ("base", "head")
            },
            "warm_total_s": {
                side: round(sum(r[side]["warm_s"] for r in rows), 2) for side in ("base", "head")
            },
        },
    }
    path = Path(args.out)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    summary = result["summary"]
    print(
        f"cold x{summary['cold_ratio_geomean']:.3f}, warm x{summary['warm_ratio_geomean']:.3f} "
        f"(head / base, geometric mean over {summary['same_outcome']} examples); {path}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
