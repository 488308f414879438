"""The ``creaturegen`` command line: validate specs, export schemas, build packages.

This module parses the arguments (cli_args.py) and runs the command: ``build`` in cli_build.py (what it
prints in cli_report.py), the others in cli_commands.py. Exit codes (cli_errors.py, which says why 2 and
3 are kept apart): 0 success, 1 a parity gate failed, 2 invalid input (bad spec, bad arguments), 3 a valid
spec that a build gate refuses. Nothing is written with 2 or 3.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

from .cli_args import build_parser
from .cli_errors import EXIT_INVALID, EXIT_REFUSED


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
