"""The ``creaturegen`` command line: validate specs, export schemas, build packages.

Exit codes: 0 success, 2 invalid input (bad spec, bad arguments). Nothing is written when a spec is invalid.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Sequence
from pathlib import Path

from . import __version__
from .spec import SpecError, SpecValidationError, load_spec
from .spec.schema import stale_schemas, write_schemas
from .spec.summary import summarize

EXIT_OK = 0
EXIT_INVALID = 2

_LINE_COLUMN = re.compile(r"^\d+:\d+$")


def format_error(source: str, error: SpecError) -> str:
    """``file: part.body.r: message``, or compiler style ``file:3:14: message`` for JSON syntax."""
    if _LINE_COLUMN.match(error.path):
        return f"{source}:{error.path}: {error.message}"
    return f"{source}: {error.path}: {error.message}"


def _validate(args: argparse.Namespace) -> int:
    failures: list[dict[str, str]] = []
    for name in args.specs:
        try:
            spec = load_spec(Path(name))
        except SpecValidationError as exc:
            failures += [{"file": name, **e.as_dict()} for e in exc.errors]
            if not args.json:
                for error in exc.errors:
                    print(format_error(name, error), file=sys.stderr)
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


def _build(args: argparse.Namespace) -> int:
    try:
        spec = load_spec(Path(args.spec))
    except SpecValidationError as exc:
        for error in exc.errors:
            print(format_error(args.spec, error), file=sys.stderr)
        return EXIT_INVALID
    print(f"{args.spec}: ok")
    print("\n".join(summarize(spec)))
    print(f"note: the package emitter is not implemented yet; nothing was written to {args.out}/")
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="creaturegen",
        description="Compile JSON creature and frost specs into Three.js r185 WebGPU/TSL npm packages.",
        epilog="Exit codes: 0 ok, 2 invalid spec or arguments. Errors name their place, e.g. part.body.r.",
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

    build = commands.add_parser("build", help="validate a spec and build its package into out/<slug>/")
    build.add_argument("spec", metavar="SPEC")
    build.add_argument("-o", "--out", default="out", help="output folder (default: out)")
    build.set_defaults(run=_build)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    code: int = args.run(args)
    return code


if __name__ == "__main__":
    sys.exit(main())
