"""Batch benchmark (issue 28): ``creaturegen build-many`` throughput on this machine, side by side in one run.

Generated corpus specs (seeds 0 .. N-1) at every tier, each run through the command line as a user runs it:
1. the local pool with 1 worker, then 2, each from an empty surface cache and an empty output folder;
2. a Dask cluster of 2 local worker processes (packages returned as bytes), also from empty;
3. a rebuild: the 2-worker run's results and packages removed, its surface cache kept (what a compiler
   change outside the surface code costs: the surface cache's hit rate);
4. a resume: the same command again (every job skipped);
5. the parity stage alone on the hero packages, with 1 and then 2 Chromium jobs at a time.
Figures come from each run's OUT/index.json (``run``: wall time, jobs per minute, surface cache hits).

    python bench/batch.py --seeds 6 --out bench/results/batch.json
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from benchlib import REPO, machine


def _run(args: list[str], env: dict[str, str]) -> dict[str, Any]:
    command = [sys.executable, "-m", "creaturegen.cli", "build-many", *args, "--no-pictures"]
    done = subprocess.run(command, capture_output=True, text=True, env=env, check=False, cwd=REPO)
    if done.returncode not in (0, 1):
        raise SystemExit(
            f"build-many failed ({done.returncode}):\n{done.stdout[-2000:]}{done.stderr[-2000:]}"
        )
    out = Path(args[args.index("-o") + 1])
    index = json.loads((out / "index.json").read_text())
    run = dict(index["run"])
    records = index["results"]
    run["built"] = sum(1 for r in records if r["status"] == "built")
    run["refused"] = sum(1 for r in records if r["status"] == "refused")
    by_tier: dict[str, list[float]] = {}
    for r in records:
        if not r.get("skipped") and r["status"] == "built":
            by_tier.setdefault(r["tier"], []).append(r["seconds"])
    run["medianJobSeconds"] = {t: sorted(v)[len(v) // 2] for t, v in sorted(by_tier.items())}
    sizes = sorted(
        sum(f.stat().st_size for f in folder.rglob("*") if f.is_file())
        for folder in (out / "packages").iterdir()
    )
    run["packageBytes"] = {"median": sizes[len(sizes) // 2], "total": sum(sizes)} if sizes else {}
    run["specsPerMinute"] = round(60.0 * len(index["specs"]) / run["wallSeconds"], 3) if run["ran"] else None
    print(f"  {' '.join(args[-6:])}: {json.dumps({k: run[k] for k in ('wallSeconds', 'ran', 'skipped')})}")
    return run


def _cluster_address(workers: int) -> tuple[Any, str]:
    from distributed import LocalCluster

    cluster = LocalCluster(
        n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=40
    )
    return cluster, str(cluster.scheduler_address)


def _ratios(runs: dict[str, Any]) -> dict[str, float]:
    """Wall-time ratios of runs measured side by side in this run (those that ran)."""
    pairs = {
        "localSpeedup2vs1": ("local1", "local2"),
        "daskVsLocal2": ("dask2", "local2"),
        "rebuildVsCold2": ("rebuild2", "local2"),
        "paritySpeedup2vs1": ("parity1", "parity2"),
    }
    return {
        name: round(runs[a]["wallSeconds"] / runs[b]["wallSeconds"], 3)
        for name, (a, b) in pairs.items()
        if a in runs and b in runs
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, default=6)
    parser.add_argument("--tiers", default="hero,repeated,distant")
    parser.add_argument("--parity-packages", type=int, default=3, help="0: no parity stage")
    parser.add_argument("--specs", nargs="*", help="these spec files instead of generated ones")
    parser.add_argument("--no-dask", action="store_true", help="skip the Dask cluster run")
    parser.add_argument("--out", default="bench/results/batch.json")
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="creaturegen-bench-batch-"))
    specs = work / "specs"
    if args.specs:
        specs.mkdir()
        for path in args.specs:
            shutil.copy(path, specs / Path(path).name)
    else:
        command = [
            sys.executable,
            "-m",
            "creaturegen.cli",
            "random",
            "--count",
            str(args.seeds),
            "-o",
            str(specs),
        ]
        subprocess.run(command, check=True, capture_output=True)
    base = {**os.environ, "CREATUREGEN_PICTURE": "off"}
    runs: dict[str, Any] = {}
    tiers = ["--tiers", args.tiers]
    for workers in (1, 2):
        env = {**base, "CREATUREGEN_CACHE": str(work / f"cache-{workers}")}
        runs[f"local{workers}"] = _run(
            [str(specs), "-o", str(work / f"out-{workers}"), *tiers, "--jobs", str(workers)], env
        )
    if not args.no_dask:
        cluster, address = _cluster_address(2)
        try:
            env = {**base, "CREATUREGEN_CACHE": str(work / "cache-dask")}
            # The workers were started by this process: they get the empty cache through --cache.
            dask = [str(specs), "-o", str(work / "out-dask"), *tiers, "--scheduler", address]
            runs["dask2"] = _run([*dask, "--cache", env["CREATUREGEN_CACHE"]], env)
        finally:
            cluster.close()
    env = {**base, "CREATUREGEN_CACHE": str(work / "cache-2")}
    shutil.rmtree(work / "out-2" / "results")
    shutil.rmtree(work / "out-2" / "packages")
    runs["rebuild2"] = _run([str(specs), "-o", str(work / "out-2"), *tiers, "--jobs", "2"], env)
    runs["resume2"] = _run([str(specs), "-o", str(work / "out-2"), *tiers, "--jobs", "2"], env)
    hero = sorted(specs.glob("*.json"))[: args.parity_packages]
    for jobs in (1, 2) if hero else ():
        out = work / f"parity-{jobs}"
        shutil.copytree(work / "out-2", out)
        named = [str(p) for p in hero]
        runs[f"parity{jobs}"] = _run(
            [*named, "-o", str(out), "--tiers", "hero", "--parity", "--parity-jobs", str(jobs)], env
        )
    result = {
        "machine": machine(),
        "seeds": None if args.specs else args.seeds,
        "specs": len(list(specs.glob("*.json"))),
        "tiers": args.tiers.split(","),
        "runs": runs,
        "ratios": _ratios(runs),
    }
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(result, indent=1, sort_keys=True))
    print(json.dumps(result["ratios"]))
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
