"""Import layering (issue 26): the package writer never reaches the lab. The lab runs built packages and
renders their pictures; the command line hands the renderer to the writer (creature/build.py), so no
module of creature/, nor anything it imports, imports lab/."""

from __future__ import annotations

import pytest

from creaturegen.codedigest import PACKAGE_ROOT, code_closure

CREATURE_MODULES = sorted(
    f"creaturegen.creature.{p.stem}" for p in (PACKAGE_ROOT / "creature").glob("*.py") if p.stem != "__init__"
)


@pytest.mark.parametrize("module", CREATURE_MODULES)
def test_the_package_writer_does_not_reach_the_lab(module: str) -> None:
    reached = sorted(m for m in code_closure(module) if m.startswith("creaturegen.lab"))
    assert not reached, f"{module} imports, directly or not, {reached}"


def test_the_lab_still_builds_on_the_creature_package() -> None:
    """The scan sees imports at all: the lab's parity job does import creature/."""
    assert "creaturegen.creature.reference" in code_closure("creaturegen.lab.creature_parity")
