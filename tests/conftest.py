"""Shared paths for the test suite."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
#: The six conformance specs live beside the checkout (CI clones with shared/ beside it).
SHARED_REFERENCE_SPECS = REPO.parent / "shared" / "reference-specs"


@pytest.fixture
def repo() -> Path:
    return REPO
