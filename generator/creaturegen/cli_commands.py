"""The commands of ``creaturegen`` other than ``build`` (cli_build.py): validate, schema, probe, inspect,
parity, random and lab. Each takes the parsed arguments and returns its exit code (cli_errors.py).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import numpy as np

from .candidates import TIERS, describe_candidates
from .cli_build import surface_or_exit
from .cli_errors import EXIT_GATE_FAILED, EXIT_INVALID, EXIT_OK, print_errors
from .cli_report import print_gates
from .field.sampler import sample
from .motion.compiled import compile_creature
from .rig import RigCompileError, compile_rig
from .rig.report import describe_rig
from .spec import CharacterSpec, SpecError, SpecValidationError, load_spec
from .spec.schema import stale_schemas, write_schemas
from .spec.summary import summarize

#: What a command compiles a spec to: the rig alone (probe) or the whole compiled creature (inspect).
T = TypeVar("T")


def validate_command(args: argparse.Namespace) -> int:
    failures: list[dict[str, str]] = []
    for name in args.specs:
        try:
            spec = load_spec(Path(name))
        except SpecValidationError as exc:
            failures += [{"file": name, **e.as_dict()} for e in exc.errors]
            if not args.json:
                print_errors(name, exc.errors)
            continue
        if not args.json:
            print(f"{name}: ok")
            if args.verbose:
                print("\n".join(summarize(spec)))
    if args.json:
        print(json.dumps(failures, indent=2))
    return EXIT_INVALID if failures else EXIT_OK


def schema_command(args: argparse.Namespace) -> int:
    folder = Path(args.out)
    if args.check:
        stale = stale_schemas(folder)
        for name in stale:
            print(f"{folder / name}: stale; run `creaturegen schema --out {folder}`", file=sys.stderr)
        return EXIT_INVALID if stale else EXIT_OK
    for path in write_schemas(folder):
        print(f"wrote {path}")
    return EXIT_OK


def _compiled(name: str, compile_spec: Callable[[CharacterSpec], T]) -> T | None:
    """Validate a creature spec and compile it with ``compile_spec`` (the rig alone, or the whole
    compiled creature), printing every error when either fails."""
    try:
        spec = load_spec(Path(name))
        if not isinstance(spec, CharacterSpec):
            print_errors(name, [SpecError("kind", "must be creature for this command")])
            return None
        return compile_spec(spec)
    except (SpecValidationError, RigCompileError) as exc:
        print_errors(name, exc.errors)
        return None


def read_points(path: Path) -> np.ndarray:
    """Points as a JSON array of [x, y, z] or a .npy of shape (P, 3); ValueError says what is wrong."""
    try:
        raw = np.load(path, allow_pickle=False) if path.suffix == ".npy" else json.loads(path.read_text())
        points = np.asarray(raw, dtype=np.float64)
    except (OSError, ValueError, TypeError) as exc:
        raise ValueError(f"cannot read points ({exc})") from exc
    if points.ndim != 2 or points.shape[1] != 3 or not np.isfinite(points).all():
        raise ValueError("must be an array of [x, y, z] with finite numbers")
    return points


def probe_command(args: argparse.Namespace) -> int:
    rig = _compiled(args.spec, compile_rig)
    if rig is None:
        return EXIT_INVALID
    try:
        points = read_points(Path(args.points))
    except ValueError as exc:
        print(f"{args.points}: {exc}", file=sys.stderr)
        return EXIT_INVALID
    field = sample(rig, points)
    result = {
        "distance": field.distance.tolist(),
        "gradient": field.gradient.tolist(),
        "color": field.color.tolist(),
    }
    if args.json:
        print(json.dumps(result))
    else:
        for p, d, g, c in zip(points, result["distance"], result["gradient"], result["color"], strict=True):
            print(f"p={p.tolist()} d={d:.9g} grad={[round(x, 9) for x in g]} rgb={[round(x, 6) for x in c]}")
    return EXIT_OK


def inspect_command(args: argparse.Namespace) -> int:
    creature = _compiled(args.spec, compile_creature)
    if creature is None:
        return EXIT_INVALID
    rig = creature.rig
    report = describe_rig(rig)
    tiers = tuple(t for t in args.tiers.split(",") if t)
    unknown = [t for t in tiers if t not in TIERS]
    if unknown:
        print(f"--tiers: unknown tier {unknown[0]!r} (known: {', '.join(TIERS)})", file=sys.stderr)
        return EXIT_INVALID
    print(f"==> candidate programs for tiers {', '.join(tiers)}", file=sys.stderr)
    report["candidates"] = describe_candidates(creature, tiers)
    surface = None
    if args.surface:
        print(f"==> surface {args.surface}", file=sys.stderr)
        found = surface_or_exit(args.spec, creature, args.surface, args.backend)
        if isinstance(found, int):
            return found
        surface = found
        report["surface"] = {
            "tier": surface.tier,
            "signatures": surface.signatures,
            "counts": surface.sidecar["counts"],
            "gates": [g.as_dict() for g in surface.gates],
        }
    if args.json:
        print(json.dumps(report, indent=2, sort_keys=True))
        return EXIT_OK
    print(f"{rig.slot_count} slots, body scale L = {rig.body_scale:.6g} m, {len(rig.graph.ops)} blend ops")
    for slot in report["slots"]:
        print(f"  slot {slot['index']:>2} {slot['class']:<9} {slot['kernel']:<15} part {slot['part']}")
    for name, value in report["signatures"].items():
        print(f"  {name} {value}")
    for tier, summary in report["candidates"].items():
        if summary["status"] in ("rejected", "skin"):
            print(f"  candidates {tier}: {summary['status']}: {summary['reason']}")
        else:
            print(
                f"  candidates {tier}: K = {summary['kUsed']} (authored {summary['kAuthored']}), "
                f"{summary['regions']} regions, {summary['distinctPrograms']} distinct programs, "
                f"sweep {summary['sweep']['points']} points: "
                + ", ".join(f"{g['name']} {g['value']:.3g}/{g['threshold']:.3g}" for g in summary["gates"])
            )
    if surface is not None:
        print(f"  surface {surface.tier}: {surface.sidecar['counts']}")
        print_gates(surface)
    return EXIT_OK


def lab_missing() -> str | None:
    """Why the lab cannot run from this install (Playwright absent, three not installable), else None."""
    from .resources import MissingResourceError, lab_modules, playwright_missing

    missing = playwright_missing()
    if missing is None:
        try:
            lab_modules(install=True)
        except MissingResourceError as exc:
            missing = str(exc)
    return missing


def parity_command(args: argparse.Namespace) -> int:
    missing = lab_missing()
    if missing is not None:
        print(f"creaturegen parity: {missing}", file=sys.stderr)
        return EXIT_INVALID
    # Imported here: Playwright is only needed by this command, not by validate/build.
    from .lab.frost_parity import run_frost_parity

    canvas = tuple(int(v) for v in args.canvas.lower().split("x"))
    failed = 0
    for name in args.packages:
        package = Path(name)
        report_path = package / "build-report.json"
        if not report_path.is_file():
            print(
                f"{name}: not a built package (no build-report.json); run `creaturegen build` first",
                file=sys.stderr,
            )
            return EXIT_INVALID
        kind = json.loads(report_path.read_text()).get("kind")
        if kind not in ("frost", "creature"):
            print(f"{name}: unknown package kind {kind!r}", file=sys.stderr)
            return EXIT_INVALID
        print(f"==> parity {package.name}: headless Chromium, WebGPU on SwiftShader", flush=True)
        if kind == "creature":
            from .lab.creature_parity import run_creature_parity

            report = run_creature_parity(package, debug_pictures=args.debug_pictures)
        else:
            report = run_frost_parity(package, (canvas[0], canvas[1]))
        for gate in report.gates:
            value, threshold = gate["value"], gate["threshold"]
            print(f"  {gate['status']:4} {gate['name']}: {value:.4g} (threshold {threshold:.4g})")
        print(f"  wrote {package / 'parity' / 'report.json'} and PNGs")
        failed += not report.passed
    return EXIT_GATE_FAILED if failed else EXIT_OK


def random_command(args: argparse.Namespace) -> int:
    from .corpus.random import LOCOMOTION_WEIGHTS
    from .corpus.run import write_specs

    if args.locomotion is not None and args.locomotion not in LOCOMOTION_WEIGHTS:
        known = ", ".join(LOCOMOTION_WEIGHTS)
        print(f"--locomotion: unknown type {args.locomotion!r} (known: {known})", file=sys.stderr)
        return EXIT_INVALID
    if args.count < 1:
        print(f"--count: must be at least 1 (got {args.count})", file=sys.stderr)
        return EXIT_INVALID
    seeds = range(args.seed, args.seed + args.count)
    for path in write_specs(Path(args.out), seeds, args.locomotion):
        print(f"wrote {path}")
    return EXIT_OK


def lab_command(args: argparse.Namespace) -> int:
    from .resources import MissingResourceError, lab_modules

    try:
        lab_modules(install=True)
    except MissingResourceError as exc:
        print(f"creaturegen lab: {exc}", file=sys.stderr)
        return EXIT_INVALID
    from .lab import server

    argv = ["--root", str(server.WEB_LAB), "--out", args.out, "--host", args.host, "--port", str(args.port)]
    return server.main(argv)
