"""The argument parser of ``creaturegen``: one helper per command adds its options (help texts and
defaults) and the function it runs (cli_build.py, cli_commands.py); cli.py parses and dispatches.
"""

from __future__ import annotations

import argparse
import os

from . import __version__
from .candidates import DEFAULT_TIER, TIERS
from .cli_batch import add_build_many
from .cli_build import build_command
from .cli_commands import (
    inspect_command,
    lab_command,
    parity_command,
    probe_command,
    random_command,
    schema_command,
    validate_command,
)
from .surface.backends import BACKENDS


def _positive_int(text: str) -> int:
    """argparse type of --population: a whole number in [1, 64] (argparse then exits 2 naming the option)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number (got {text!r})") from None
    if not 1 <= value <= 64:
        raise argparse.ArgumentTypeError(f"must be between 1 and 64 (got {value})")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="creaturegen",
        description="Compile JSON creature and frost specs into Three.js r185 WebGPU/TSL npm packages.",
        epilog="Exit codes: 0 ok, 1 a parity gate failed, 2 invalid spec or arguments (errors name it), "
        "3 a valid spec that a build gate refuses (the gate is named). Nothing is written with 2 or 3.",
    )
    parser.add_argument("--version", action="version", version=f"creaturegen {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _add_validate(commands)
    _add_schema(commands)
    _add_probe(commands)
    _add_inspect(commands)
    _add_build(commands)
    add_build_many(commands)
    _add_parity(commands)
    _add_random(commands)
    _add_lab(commands)
    return parser


def _add_validate(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    validate = commands.add_parser("validate", help="check specs; print every error, one per line")
    validate.add_argument("specs", nargs="+", metavar="SPEC", help="spec files (.json)")
    validate.add_argument("--json", action="store_true", help="print errors as [{file, path, message}]")
    validate.add_argument("-v", "--verbose", action="store_true", help="print a summary of each valid spec")
    validate.set_defaults(run=validate_command)


def _add_schema(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    schema = commands.add_parser("schema", help="export the JSON Schemas of both spec kinds")
    schema.add_argument("--out", default="schemas", help="folder to write (default: schemas)")
    schema.add_argument("--check", action="store_true", help="exit 2 if the files there are stale")
    schema.set_defaults(run=schema_command)


def _add_probe(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    probe = commands.add_parser("probe", help="evaluate the rest-pose field of a creature at points")
    probe.add_argument("spec", metavar="SPEC")
    probe.add_argument("--points", required=True, help="JSON array of [x, y, z] or a .npy of shape (P, 3)")
    probe.add_argument("--json", action="store_true", help='print {"distance", "gradient", "color"}')
    probe.set_defaults(run=probe_command)


def _add_inspect(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
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
    inspect.set_defaults(run=inspect_command)


def shipped_tiers(text: str) -> tuple[str, ...]:
    """``--tier``: one tier or a comma list, finest first (TIERS' order) whatever order it is given in."""
    names = [t.strip() for t in text.split(",")]
    unknown = [t for t in names if t not in TIERS]
    if unknown:
        raise argparse.ArgumentTypeError(f"unknown tier {unknown[0]!r} (known: {', '.join(TIERS)})")
    if len(set(names)) != len(names):
        raise argparse.ArgumentTypeError(f"a tier named twice in {text!r}")
    return tuple(t for t in TIERS if t in names)


def _add_build(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    build = commands.add_parser("build", help="validate a spec and build its package into out/<slug>/")
    build.add_argument("spec", metavar="SPEC")
    build.add_argument("-o", "--out", default="out", help="output folder (default: out)")
    build.add_argument(
        "--tier",
        default=(DEFAULT_TIER,),
        type=shipped_tiers,
        metavar="TIER[,TIER...]",
        help=f"creature surface tier, or several (e.g. hero,distant: one .glb each in one package, and "
        f"bodies move between them by their size on screen); default {DEFAULT_TIER}",
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
    build.set_defaults(run=build_command)


def _add_parity(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
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
    parity.set_defaults(run=parity_command)


def _add_random(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
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
    rand.set_defaults(run=random_command)


def _add_lab(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    lab = commands.add_parser("lab", help="serve the web lab on a fixed port and print the URLs")
    lab.add_argument("--out", default="out", help="built packages, served at /out/ (default: out)")
    lab.add_argument("--host", default="127.0.0.1", help="bind address (default: 127.0.0.1)")
    lab.add_argument("--port", type=int, default=8765, help="port (default: 8765)")
    lab.set_defaults(run=lab_command)
