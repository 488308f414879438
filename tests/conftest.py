"""Shared paths for the test suite."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
#: The six conformance specs live beside the checkout (CI clones with shared/ beside it).
SHARED_REFERENCE_SPECS = REPO.parent / "shared" / "reference-specs"


@pytest.fixture
def repo() -> Path:
    return REPO


def run_cli(*args: str, cwd: Path = REPO) -> subprocess.CompletedProcess[str]:
    """The installed command line in a child process, as a user runs it."""
    return subprocess.run(
        [sys.executable, "-m", "creaturegen.cli", *args], capture_output=True, text=True, check=False, cwd=cwd
    )
