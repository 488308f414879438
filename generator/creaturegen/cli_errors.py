"""Exit codes of the ``creaturegen`` command line and its error lines, shared by every command.

Exit codes: 0 success, 1 a parity gate failed, 2 invalid input (bad spec, bad arguments), 3 a valid spec
that a build gate refuses (a surface gate, a grid too fine, a deformation sweep, or fewer than N identities
of ``--population N`` passing). Nothing is written with 2 or 3. The two are kept apart because they call
for different fixes: 2 means the spec or the command line is wrong as written; 3 means the spec is well
formed but its geometry cannot be certified, so the creature's shape (not its syntax) has to change.
"""

from __future__ import annotations

import sys

from .spec import SpecError, format_error

EXIT_OK = 0
EXIT_GATE_FAILED = 1
EXIT_INVALID = 2
EXIT_REFUSED = 3


def print_errors(source: str, errors: list[SpecError]) -> None:
    for error in errors:
        print(format_error(source, error), file=sys.stderr)
