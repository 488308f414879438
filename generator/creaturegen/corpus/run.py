"""``make corpus``: build a fixed corpus of generated creatures at every tier and report what happened.

The corpus is a batch (batch/, ``creaturegen build-many``) over generated specs: each (spec, tier) is one
``creaturegen build`` in its own process, exactly as a user runs it (exit code, stderr message, wall
time), with a private surface cache so every time is a cold build. Results are kept under
``OUT/results/`` keyed by the spec's bytes, the tier and a digest of the compiler's own source and
templates: a rerun after an unrelated change rebuilds nothing, a compiler change rebuilds everything, and
the report always holds the figures of the code it was run with. ``OUT/report.json`` holds per spec and tier
the status, time, exit code, the failed gate with its value and threshold, and the parts the message names;
``OUT/index.html`` is the batch's gallery, a card per creature with its picture and its result per tier.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from ..batch.results import compiler_digest
from ..batch.run import BatchOptions, build_many
from ..batch.task import PRIVATE_CACHE
from ..candidates import TIERS
from .random import random_creature

#: The fixed corpus of ``make corpus``: seeds 0 .. COUNT - 1.
DEFAULT_COUNT = 200
#: Per-build wall limit; a build past it is recorded as a timeout (the acceptance asks max ≤ 60 s cold).
BUILD_TIMEOUT_S = 600.0


def write_specs(folder: Path, seeds: Iterable[int], locomotion: str | None = None) -> list[Path]:
    """One ``seed-NNNNN.json`` per seed (pretty-printed, as a person would save it); a file already holding
    the same text is left alone."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for seed in seeds:
        spec = random_creature(seed, locomotion)
        path = folder / f"seed-{seed:05d}.json"
        text = json.dumps(spec, indent=2) + "\n"
        if not path.is_file() or path.read_text() != text:
            path.write_text(text)
        paths.append(path)
    return paths


def run_corpus(
    out: Path, seeds: Sequence[int], tiers: Sequence[str], jobs: int, pictures: bool = True
) -> dict[str, Any]:
    """Build every (seed, tier) not already measured with this compiler, cold; write report.json (the
    batch's index with the seeds) and the gallery index.html."""
    spec_paths = write_specs(out / "specs", seeds)
    options = BatchOptions(
        tiers=tuple(tiers), jobs=jobs, cache=PRIVATE_CACHE, timeout=BUILD_TIMEOUT_S, pictures=pictures
    )
    index = build_many([str(p) for p in spec_paths], out, options)
    report = {
        "creaturegen": index["creaturegen"],
        "compilerDigest": compiler_digest(),
        "seeds": [min(seeds), max(seeds)] if seeds else [],
        "tiers": list(tiers),
        "summary": index["summary"],
        "run": index["run"],
        "specs": index["specs"],
        "results": index["results"],
    }
    (out / "report.json").write_text(json.dumps(report, indent=1, sort_keys=True))
    return report


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m creaturegen.corpus",
        description="Build a fixed corpus of generated creatures at every tier; write report.json and a "
        "gallery (index.html).",
    )
    parser.add_argument("-o", "--out", default="out/corpus", help="output folder (default: out/corpus)")
    parser.add_argument(
        "--count", type=int, default=DEFAULT_COUNT, help="specs, seeds 0..count-1 (default 200)"
    )
    parser.add_argument("--first", type=int, default=0, help="first seed (default 0)")
    parser.add_argument("--tiers", default=",".join(TIERS), help="tiers (default hero,repeated,distant)")
    parser.add_argument(
        "--jobs", type=int, default=os.cpu_count() or 1, help="builds at a time (default: cores)"
    )
    parser.add_argument("--no-pictures", action="store_true", help="skip the gallery thumbnails")
    args = parser.parse_args(argv)
    tiers = [t for t in args.tiers.split(",") if t]
    unknown = [t for t in tiers if t not in TIERS]
    if unknown or args.count < 1:
        print(
            f"--tiers: unknown tier {unknown[0]!r}" if unknown else "--count: must be >= 1", file=sys.stderr
        )
        return 2
    out = Path(args.out)
    report = run_corpus(
        out, range(args.first, args.first + args.count), tiers, args.jobs, not args.no_pictures
    )
    for tier, s in report["summary"].items():
        print(
            f"  {tier}: {s['built']}/{s['specs']} built ({100 * s['rate']:.1f} %), "
            f"median {s['medianSeconds']:.1f} s, max {s['maxSeconds']:.1f} s; refusals {s['causes']}"
        )
    print(f"wrote {out / 'report.json'} and {out / 'index.html'}")
    return 0
