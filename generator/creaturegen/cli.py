"""The ``creaturegen`` command line: validate specs, export schemas, build packages.

Exit codes: 0 success, 1 a parity gate failed, 2 invalid input (bad spec, bad arguments), 3 a valid spec
that a build gate refuses (a surface gate, a grid too fine, a deformation sweep, or fewer than N identities
of ``--population N`` passing). Nothing is written with 2 or 3. The two are kept apart because they call
for different fixes: 2 means the spec or the command line is wrong as written; 3 means the spec is well
formed but its geometry cannot be certified, so the creature's shape (not its syntax) has to change.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import __version__
from .candidates import TIERS, describe_candidates
from .creature.assets import PICTURE_PATH
from .creature.build import build_creature
from .creature.morphology import identity_genes, variant_bytes
from .emit import PackageWriteError
from .field.sampler import sample
from .frost.build import build_frost
from .frost.formats import FormatRefusedError
from .lab.picture import picture_unavailable, render_picture
from .rig import CompiledRig, RigCompileError, compile_rig
from .rig.report import describe_rig
from .spec import CharacterSpec, SpecError, SpecValidationError, load_spec, slugify, validate_bytes
from .spec.schema import stale_schemas, write_schemas
from .spec.summary import summarize
from .surface.asset import SurfaceCache
from .surface.backends import BACKENDS, BackendChoiceError
from .surface.build import (
    DEFAULT_TIER,
    SurfaceBuild,
    SurfaceRejectedError,
    build_surface,
    posed_gate_rows,
    refuse_posed,
)
from .surface.deform import DeformationError
from .surface.grid import GridTooFineError

EXIT_OK = 0
EXIT_GATE_FAILED = 1
EXIT_INVALID = 2
EXIT_REFUSED = 3

_LINE_COLUMN = re.compile(r"^\d+:\d+$")


def format_error(source: str, error: SpecError) -> str:
    """``file: part.body.r: message``, or compiler style ``file:3:14: message`` for JSON syntax."""
    if _LINE_COLUMN.match(error.path):
        return f"{source}:{error.path}: {error.message}"
    return f"{source}: {error.path}: {error.message}"


def print_errors(source: str, errors: list[SpecError]) -> None:
    for error in errors:
        print(format_error(source, error), file=sys.stderr)


def _validate(args: argparse.Namespace) -> int:
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


def _schema(args: argparse.Namespace) -> int:
    folder = Path(args.out)
    if args.check:
        stale = stale_schemas(folder)
        for name in stale:
            print(f"{folder / name}: stale; run `creaturegen schema --out {folder}`", file=sys.stderr)
        return EXIT_INVALID if stale else EXIT_OK
    for path in write_schemas(folder):
        print(f"wrote {path}")
    return EXIT_OK


def _positive_int(text: str) -> int:
    """argparse type of --population: a whole number in [1, 64] (argparse then exits 2 naming the option)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number (got {text!r})") from None
    if not 1 <= value <= 64:
        raise argparse.ArgumentTypeError(f"must be between 1 and 64 (got {value})")
    return value


def _build(args: argparse.Namespace) -> int:
    source = Path(args.spec)
    try:
        data = source.read_bytes()
    except OSError as exc:
        print_errors(args.spec, [SpecError("spec", f"cannot be read: {exc.strerror}")])
        return EXIT_INVALID
    try:
        spec = validate_bytes(data, args.spec)
    except SpecValidationError as exc:
        print_errors(args.spec, exc.errors)
        return EXIT_INVALID
    print(f"{args.spec}: ok")
    print("\n".join(summarize(spec)))
    if isinstance(spec, CharacterSpec):
        return _build_creature(args, spec, data)
    if args.population != 1:
        print_errors(args.spec, [SpecError("--population", "applies to creature specs only")])
        return EXIT_INVALID
    print(
        "==> frost: quantisation gate (30/60/120 FPS replays per storage format), structure maps", flush=True
    )
    try:
        folder = build_frost(spec, data, Path(args.out))
    except FormatRefusedError as exc:
        print_errors(args.spec, [SpecError("tier.historyFormat", str(exc))])
        return EXIT_REFUSED
    except PackageWriteError as exc:
        print(f"{args.spec}: cannot write the package: {exc}", file=sys.stderr)
        return EXIT_INVALID
    report = json.loads((folder / "build-report.json").read_text())
    for gate in report["gates"]:
        verdict = (
            "pass" if gate["status"] == "pass" else "fail, so this format is not used (a later one passed)"
        )
        print(f"  gate {gate['name']}: {gate['value']:.3g} (threshold {gate['threshold']:.3g}) {verdict}")
    print(f"  history format {report['historyFormat']['historyFormat']}")
    print(f"wrote {folder}/")
    _report_pack_size(folder)
    return EXIT_OK


def _surface(name: str, spec: CharacterSpec, rig: CompiledRig, tier: str, backend: str) -> SurfaceBuild | int:
    """The surface at ``tier``, or the exit code of its failure, printed naming the gate, part or option:
    EXIT_REFUSED when a gate refuses the geometry, EXIT_INVALID when ``--backend`` cannot be used."""
    try:
        return build_surface(spec, rig, tier=tier, backend=backend, cache=SurfaceCache())
    except (SurfaceRejectedError, GridTooFineError, DeformationError) as exc:
        print_errors(name, [SpecError(f"surface.{tier}", str(exc))])
        return EXIT_REFUSED
    except BackendChoiceError as exc:
        print_errors(name, [SpecError("--backend", str(exc))])
        return EXIT_INVALID


def _print_gates(build: SurfaceBuild) -> None:
    for gate in build.gates:
        verdict = "pass" if gate.passed else "FAIL"
        relation = "<=" if gate.direction == "max" else ">="
        print(f"  gate {gate.name}: {gate.value:.4g} {gate.unit} ({relation} {gate.threshold:.4g}) {verdict}")


@dataclass(frozen=True)
class _Identity:
    """One geometry identity ready to write: its spec (and the JSON bytes it ships), rig and surface."""

    name: str
    spec: CharacterSpec
    data: bytes
    rig: CompiledRig
    build: SurfaceBuild


def _identity(args: argparse.Namespace, name: str, spec: CharacterSpec, data: bytes) -> _Identity | int:
    """Compile, extract and gate one identity; on failure the exit code (errors printed, naming the gate or
    part): EXIT_INVALID for a rig the spec cannot compile to, EXIT_REFUSED for a surface gate."""
    try:
        rig = compile_rig(spec)
    except RigCompileError as exc:
        print_errors(name, exc.errors)
        return EXIT_INVALID
    steps = "narrow-band sampling, extraction, gates, skin weights, deformation sweeps"
    print(f"==> surface {args.tier}: {steps}")
    build = _surface(name, spec, rig, args.tier, args.backend)
    if isinstance(build, int):
        return build
    _print_gates(build)
    if args.posed_gates == "refuse":
        try:
            refuse_posed(build.sidecar, args.tier)
        except SurfaceRejectedError as exc:
            print_errors(name, [SpecError(f"surface.{args.tier}", str(exc))])
            return EXIT_REFUSED
    for row in posed_gate_rows(build.sidecar):
        if not row.get("passed"):
            print(
                f"  warning: posed skin: {row['name']} = {row['value']:g} {row['unit']} ({row['detail']}); "
                "recorded in assets/surface.json, not enforced (--posed-gates refuse refuses the build)"
            )
    counts = build.sidecar["counts"]
    print(f"  mesh {counts}; " + ("cache hit" if build.cached else "extracted"))
    return _Identity(name, spec, data, rig, build)


#: Morphology variants drawn per identity asked for before --population gives up.
DRAWS_PER_IDENTITY = 4


def _identities(args: argparse.Namespace, spec: CharacterSpec, data: bytes) -> list[_Identity] | int:
    """The authored identity and, with ``--population N``, N - 1 morphology variants (creature/morphology.py).
    A variant that fails validation or a surface gate is rejected (the reason printed) and the next index is
    drawn, so identity names follow draw indices. On failure the exit code: the authored identity's own
    (EXIT_INVALID or EXIT_REFUSED), EXIT_INVALID when the name leaves no room for identity suffixes, and
    EXIT_REFUSED when N identities do not pass within DRAWS_PER_IDENTITY·N draws (the authored spec is
    valid and built; its variants are what the gates refused)."""
    authored = _identity(args, args.spec, spec, data)
    if isinstance(authored, int):
        return authored
    out = [authored]
    document = json.loads(data)
    bound = spec.genetics.morphology
    index = 0
    while len(out) < args.population and index < DRAWS_PER_IDENTITY * args.population:
        index += 1
        name = f"{args.spec} (identity m{index})"
        genes = identity_genes(spec.seed, index)
        scaled = ", ".join(f"{g} x{1.0 + bound * v:.3f}" for g, v in genes.items())
        print(f"==> identity m{index} ({len(out) + 1} of {args.population}): {scaled}")
        variant_data = variant_bytes(document, index, bound)
        try:
            variant = validate_bytes(variant_data, name)
        except SpecValidationError as exc:
            print_errors(name, exc.errors)
            variant = None
        if isinstance(variant, CharacterSpec) and slugify(variant.name) in {
            slugify(o.spec.name) for o in out
        }:
            print_errors(
                name,
                [SpecError("name", "too long for an identity suffix: the slugs of the identities collide")],
            )
            return EXIT_INVALID
        one = _identity(args, name, variant, variant_data) if isinstance(variant, CharacterSpec) else None
        if not isinstance(one, _Identity):
            print(f"  identity m{index} rejected (above); drawing the next")
            continue
        out.append(one)
    if len(out) < args.population:
        print(
            f"{args.spec}: only {len(out)} of {args.population} identities passed every gate "
            f"in {index} draws; nothing was written (lower genetics.morphology or --population)",
            file=sys.stderr,
        )
        return EXIT_REFUSED
    return out


def _build_creature(args: argparse.Namespace, spec: CharacterSpec, data: bytes) -> int:
    identities = _identities(args, spec, data)
    if isinstance(identities, int):
        return identities
    print("==> package: candidate program tapes, locomotion data, templates")
    picture = args.picture == "on"
    if args.picture == "auto":
        reason = picture_unavailable()
        picture = reason is None
        if reason is not None:
            print(f"  no README picture: the lab cannot run here ({reason}); --picture off to silence this")
    if picture:
        print(f"==> picture: {PICTURE_PATH} rendered by the lab (headless Chromium, WebGPU on SwiftShader)")
    for one in identities:
        try:
            render = render_picture if picture else None
            folder = build_creature(one.spec, one.rig, one.data, one.build, Path(args.out), render)
        except PackageWriteError as exc:
            print(f"{one.name}: cannot write the package: {exc}", file=sys.stderr)
            return EXIT_INVALID
        except RuntimeError as exc:
            if not picture:
                raise
            print(
                f"{one.name}: cannot render the README picture ({exc}); it was not written.", file=sys.stderr
            )
            print("  build without it: --picture off", file=sys.stderr)
            return EXIT_GATE_FAILED
        digest = one.build.signatures["geometryDigest"]
        print(f"wrote {folder}/ (geometryDigest {digest[:12]})")
        _report_pack_size(folder)
    return EXIT_OK


def _report_pack_size(folder: Path) -> None:
    from .emit.packsize import npm_pack_size

    size = npm_pack_size(folder)
    print(f"  {size if isinstance(size, str) else size.line()}")


def _compiled(name: str) -> tuple[CharacterSpec, CompiledRig] | None:
    """Validate and compile a creature spec, printing every error when that fails."""
    try:
        spec = load_spec(Path(name))
        if not isinstance(spec, CharacterSpec):
            print_errors(name, [SpecError("kind", "must be creature for this command")])
            return None
        return spec, compile_rig(spec)
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


def _probe(args: argparse.Namespace) -> int:
    compiled = _compiled(args.spec)
    if compiled is None:
        return EXIT_INVALID
    rig = compiled[1]
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


def _inspect(args: argparse.Namespace) -> int:
    compiled = _compiled(args.spec)
    if compiled is None:
        return EXIT_INVALID
    spec, rig = compiled
    report = describe_rig(rig)
    tiers = tuple(t for t in args.tiers.split(",") if t)
    unknown = [t for t in tiers if t not in TIERS]
    if unknown:
        print(f"--tiers: unknown tier {unknown[0]!r} (known: {', '.join(TIERS)})", file=sys.stderr)
        return EXIT_INVALID
    print(f"==> candidate programs for tiers {', '.join(tiers)}", file=sys.stderr)
    report["candidates"] = describe_candidates(spec, rig, tiers)
    surface = None
    if args.surface:
        print(f"==> surface {args.surface}", file=sys.stderr)
        found = _surface(args.spec, spec, rig, args.surface, args.backend)
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
        _print_gates(surface)
    return EXIT_OK


def _lab_missing() -> str | None:
    """Why the lab cannot run from this install (Playwright absent, three not installable), else None."""
    from .resources import MissingResourceError, lab_modules, playwright_missing

    missing = playwright_missing()
    if missing is None:
        try:
            lab_modules(install=True)
        except MissingResourceError as exc:
            missing = str(exc)
    return missing


def _parity(args: argparse.Namespace) -> int:
    missing = _lab_missing()
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


def _random(args: argparse.Namespace) -> int:
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


def _lab(args: argparse.Namespace) -> int:
    from .resources import MissingResourceError, lab_modules

    try:
        lab_modules(install=True)
    except MissingResourceError as exc:
        print(f"creaturegen lab: {exc}", file=sys.stderr)
        return EXIT_INVALID
    from .lab import server

    argv = ["--root", str(server.WEB_LAB), "--out", args.out, "--host", args.host, "--port", str(args.port)]
    return server.main(argv)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="creaturegen",
        description="Compile JSON creature and frost specs into Three.js r185 WebGPU/TSL npm packages.",
        epilog="Exit codes: 0 ok, 1 a parity gate failed, 2 invalid spec or arguments (errors name it), "
        "3 a valid spec that a build gate refuses (the gate is named). Nothing is written with 2 or 3.",
    )
    parser.add_argument("--version", action="version", version=f"creaturegen {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    validate = commands.add_parser("validate", help="check specs; print every error, one per line")
    validate.add_argument("specs", nargs="+", metavar="SPEC", help="spec files (.json)")
    validate.add_argument("--json", action="store_true", help="print errors as [{file, path, message}]")
    validate.add_argument("-v", "--verbose", action="store_true", help="print a summary of each valid spec")
    validate.set_defaults(run=_validate)

    schema = commands.add_parser("schema", help="export the JSON Schemas of both spec kinds")
    schema.add_argument("--out", default="schemas", help="folder to write (default: schemas)")
    schema.add_argument("--check", action="store_true", help="exit 2 if the files there are stale")
    schema.set_defaults(run=_schema)

    probe = commands.add_parser("probe", help="evaluate the rest-pose field of a creature at points")
    probe.add_argument("spec", metavar="SPEC")
    probe.add_argument("--points", required=True, help="JSON array of [x, y, z] or a .npy of shape (P, 3)")
    probe.add_argument("--json", action="store_true", help='print {"distance", "gradient", "color"}')
    probe.set_defaults(run=_probe)

    inspect = commands.add_parser("inspect", help="print slots, the blend program and the signatures")
    inspect.add_argument("spec", metavar="SPEC")
    inspect.add_argument("--json", action="store_true", help="machine-readable report")
    inspect.add_argument(
        "--tiers", default=",".join(TIERS), help="candidate tiers to build (default: hero,repeated,distant)"
    )
    inspect.add_argument(
        "--surface",
        metavar="TIER",
        choices=tuple(TIERS),
        help="also build the reference surface and print its gates",
    )
    inspect.add_argument(
        "--backend", default="auto", choices=("auto", *BACKENDS), help="surface sampling backend"
    )
    inspect.set_defaults(run=_inspect)

    build = commands.add_parser("build", help="validate a spec and build its package into out/<slug>/")
    build.add_argument("spec", metavar="SPEC")
    build.add_argument("-o", "--out", default="out", help="output folder (default: out)")
    build.add_argument(
        "--tier",
        default=DEFAULT_TIER,
        choices=tuple(TIERS),
        help=f"creature surface tier (default {DEFAULT_TIER})",
    )
    build.add_argument(
        "--backend",
        default="auto",
        choices=("auto", *BACKENDS),
        help="surface sampling backend: auto (the faster, measured), numpy or wgpu",
    )
    build.add_argument(
        "--picture",
        default=os.environ.get("CREATUREGEN_PICTURE", "auto"),
        choices=("auto", "on", "off"),
        help="creature packages: render the README picture in the lab before committing the package "
        "(auto: when Chromium and web_lab/node_modules are there; default $CREATUREGEN_PICTURE or auto)",
    )
    build.add_argument(
        "--posed-gates",
        default="report",
        choices=("report", "refuse"),
        help="creature specs: what a visible flip, fold or crossing of the skin at a pose of the motion "
        "envelope does (surface/posed.py): report it (default; recorded in the package's surface.json "
        "and printed) or refuse the build, naming the parts and the pose",
    )
    build.add_argument(
        "--population",
        type=_positive_int,
        default=1,
        metavar="N",
        help="creature specs: N (1..64) geometry identities, the authored one and N-1 morphology variants "
        "within genetics.morphology (each its own package <slug>-m<i>, extracted and gated; a variant "
        "failing a gate is replaced by the next draw; no package is written before all N passed)",
    )
    build.set_defaults(run=_build)

    parity = commands.add_parser(
        "parity", help="run built packages in the lab and diff against the reference"
    )
    parity.add_argument(
        "packages", nargs="+", metavar="PKG", help="package folders, e.g. out/frost-pane-full"
    )
    parity.add_argument("--canvas", default="160x96", help="frost lab canvas size WxH (default: 160x96)")
    parity.add_argument(
        "--debug-pictures",
        action="store_true",
        help="creature packages: also write the distance, normals and candidates views as PNGs",
    )
    parity.set_defaults(run=_parity)

    rand = commands.add_parser(
        "random",
        help="write plausible random creature specs (the corpus generator), one file per seed",
        description="Draw plausible creature specs from seeds: every locomotion type, scales 0.1 to 5, "
        "4 to 24 parts, eyes, ears, horns, necks, rope tails, tapered and thick limbs, 8-legged walkers, "
        "default blends, explicit trees and n-ary groups. The same seed gives the same file.",
    )
    rand.add_argument("--seed", type=int, default=0, help="first seed (default 0)")
    rand.add_argument("--count", type=int, default=1, help="specs to write, seeds seed..seed+count-1")
    rand.add_argument("--locomotion", metavar="TYPE", help="pin the locomotion type (default: drawn)")
    rand.add_argument("-o", "--out", default="out/random", help="folder to write (default: out/random)")
    rand.set_defaults(run=_random)

    lab = commands.add_parser("lab", help="serve the web lab on a fixed port and print the URLs")
    lab.add_argument("--out", default="out", help="built packages, served at /out/ (default: out)")
    lab.add_argument("--host", default="127.0.0.1", help="bind address (default: 127.0.0.1)")
    lab.add_argument("--port", type=int, default=8765, help="port (default: 8765)")
    lab.set_defaults(run=_lab)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    from .motion.derived import MotionRangeError
    from .resources import MissingResourceError

    args = build_parser().parse_args(argv)
    try:
        code: int = args.run(args)
    except MissingResourceError as exc:  # a broken install: say what is missing, write nothing
        print(f"creaturegen: {exc}", file=sys.stderr)
        return EXIT_INVALID
    except MotionRangeError as exc:  # a valid spec whose motion cannot be stepped: refused by name
        print(f"{getattr(args, 'spec', 'creaturegen')}: {exc}", file=sys.stderr)
        return EXIT_REFUSED
    return code


if __name__ == "__main__":
    sys.exit(main())
