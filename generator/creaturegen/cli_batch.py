"""``creaturegen build-many``: many specs at several tiers, with their parity jobs, on a local pool or a
Dask cluster (batch/). Exit 0 when every job ended in a record (a refusal or an invalid spec is a record,
named in OUT/index.json), 1 when a parity gate failed or a job was lost, timed out or crashed, 2 for bad
arguments (nothing is built).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .batch.run import BatchOptions, build_many
from .batch.specs import BatchInputError
from .candidates import TIERS
from .cli_errors import EXIT_GATE_FAILED, EXIT_INVALID, EXIT_OK


def _tiers(text: str) -> tuple[str, ...]:
    tiers = tuple(t for t in text.split(",") if t)
    unknown = [t for t in tiers if t not in TIERS]
    if unknown or not tiers:
        raise argparse.ArgumentTypeError(f"unknown tier {unknown[0]!r}" if unknown else "no tier named")
    return tiers


def add_build_many(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    many = commands.add_parser(
        "build-many",
        help="build many specs at several tiers (local pool or Dask cluster), with an index and a gallery",
        description="Build every spec named (files, or folders searched for .json) at every tier asked for; "
        "one failing spec never stops the batch. OUT/index.json holds every result (package, refusal with "
        "its gate and parts, time), OUT/index.html is the gallery; a rerun skips every job whose package "
        "and signatures are in place.",
    )
    many.add_argument("specs", nargs="+", metavar="SPEC_OR_DIR")
    many.add_argument("-o", "--out", default="out/bestiary", help="output folder (default: out/bestiary)")
    many.add_argument("--tiers", type=_tiers, default=tuple(TIERS), help="default: hero,repeated,distant")
    many.add_argument("--parity", action="store_true", help="also run each built package's parity job")
    many.add_argument("--jobs", type=int, default=0, help="local builds at a time (default: the CPUs)")
    many.add_argument("--parity-jobs", type=int, default=1, help="local parity jobs at a time (default 1)")
    many.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        help="run on this Dask distributed scheduler (pip install 'creaturegen[cluster]'); parity tasks "
        "need workers started with --resources chromium=1",
    )
    many.add_argument(
        "--transfer",
        choices=("auto", "shared", "bytes"),
        default="auto",
        help="shared: workers write packages into OUT (one file system); bytes: packages come back to this "
        "process (default: shared locally, bytes with --scheduler)",
    )
    many.add_argument(
        "--cache",
        help="surface cache folder for every build, or 'private' for a fresh one per build (cold times); "
        "default: each worker's own ($CREATUREGEN_CACHE or ~/.cache/creaturegen)",
    )
    many.add_argument("--posed-gates", choices=("report", "refuse"), default="report")
    many.add_argument("--timeout", type=float, default=900.0, help="seconds per build or parity job")
    many.add_argument("--attempts", type=int, default=3, help="tries of a job whose worker died (default 3)")
    many.add_argument("--no-pictures", action="store_true", help="skip the gallery's thumbnails")
    many.set_defaults(run=build_many_command)


def build_many_command(args: argparse.Namespace) -> int:
    if args.jobs < 0 or args.parity_jobs < 1 or args.attempts < 1 or args.timeout <= 0:
        print("--jobs, --parity-jobs, --attempts and --timeout must be positive", file=sys.stderr)
        return EXIT_INVALID
    if args.parity and args.scheduler is None:
        from .cli_commands import lab_missing

        missing = lab_missing()
        if missing is not None:
            print(f"--parity: {missing}", file=sys.stderr)
            return EXIT_INVALID
    options = BatchOptions(
        tiers=args.tiers,
        parity=args.parity,
        jobs=args.jobs,
        parity_jobs=args.parity_jobs,
        scheduler=args.scheduler,
        transfer=args.transfer,
        cache=args.cache,
        posed_gates=args.posed_gates,
        timeout=args.timeout,
        attempts=args.attempts,
        pictures=not args.no_pictures,
    )
    out = Path(args.out)
    try:
        index = build_many(args.specs, out, options)
    except BatchInputError as exc:
        print(f"creaturegen build-many: {exc}", file=sys.stderr)
        return EXIT_INVALID
    except (RuntimeError, OSError) as exc:  # the cluster cannot be reached, or lacks the extra
        where = "--scheduler" if args.scheduler else "build-many"
        print(f"creaturegen {where}: {exc}", file=sys.stderr)
        return EXIT_INVALID
    for tier, s in index["summary"].items():
        parity = f", parity {s['parityPassed']}/{s['parityRun']} passed" if s["parityRun"] else ""
        print(
            f"  {tier}: {s['built']}/{s['specs']} built, median {s['medianSeconds']:.1f} s, "
            f"max {s['maxSeconds']:.1f} s{parity}; not built: {s['causes'] or 'none'}"
        )
    print(f"wrote {out / 'index.json'} and {out / 'index.html'}")
    bad = [
        r
        for r in index["results"]
        if r["status"] in ("error", "lost", "timeout")
        or (r.get("parity") or {}).get("status") not in (None, "passed")
    ]
    return EXIT_GATE_FAILED if bad else EXIT_OK
