"""Progress lines of the surface stage: its steps are the slow part of a build, so each one says what it did.

A callable rather than logging: the CLI prints to stderr, the corpus collects lines per build, tests keep
them to assert on.
"""

from __future__ import annotations

import sys
from collections.abc import Callable

Progress = Callable[[str], None]


def stderr_progress(message: str) -> None:
    """The CLI's default: one indented line on stderr per step, flushed so a long build shows its pace."""
    print(f"  surface: {message}", file=sys.stderr, flush=True)
