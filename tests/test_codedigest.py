"""The digest of a stage's code (codedigest.py): what it covers, and that prose never counts while code
does, checked on a copy of the package edited three ways."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from creaturegen.codedigest import PACKAGE_ROOT, code_closure, code_digest, memo_key
from creaturegen.surface.identity import SURFACE_ENTRY

ENVELOPE = "creaturegen.motion.envelope"


@pytest.fixture
def copy(tmp_path: Path) -> Path:
    root = tmp_path / "creaturegen"
    shutil.copytree(PACKAGE_ROOT, root, ignore=shutil.ignore_patterns("__pycache__", "templates", "web_lab"))
    return root


def test_the_surface_runs_its_own_closure_and_not_the_package_writer_or_the_lab() -> None:
    closure = set(code_closure(SURFACE_ENTRY))
    assert {
        "creaturegen.surface.build",
        "creaturegen.surface.posed",  # imported by build
        "creaturegen.surface.frames",  # imported inside a function
        "creaturegen.motion.envelope",
        "creaturegen.model.genome",
        "creaturegen.field",  # a package's __init__ runs before its modules
    } <= closure
    for outside in ("creaturegen.lab.picture", "creaturegen.creature.build", "creaturegen.cli"):
        assert outside not in closure
    assert not any(
        m.startswith(("creaturegen.lab", "creaturegen.emit", "creaturegen.frost")) for m in closure
    )
    assert set(code_closure(ENVELOPE)) < closure


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, f"{old!r} not in {path}"
    path.write_text(text.replace(old, new, 1))


def test_prose_keeps_the_digest_and_code_changes_it(copy: Path) -> None:
    before = {e: code_digest(e, copy) for e in (SURFACE_ENTRY, ENVELOPE)}
    genome = copy / "model" / "genome.py"
    # A comment, a docstring and a blank line in a module both stages run: nothing changes.
    _edit(genome, "HUE_DRAW: Final = 3", "# a comment\n\nHUE_DRAW: Final = 3  # and another")
    text = genome.read_text()
    start = text.index('"""') + 3
    genome.write_text(text[:start] + "Reworded. " + text[start:])
    # Code in a module neither stage imports: nothing changes.
    _edit(
        copy / "lab" / "picture.py",
        "from __future__ import annotations",
        "from __future__ import annotations\nX = 1",
    )
    assert {e: code_digest(e, copy) for e in before} == before
    # One constant in a module both run: both change.
    _edit(genome, "HUE_DRAW: Final = 3", "HUE_DRAW: Final = 4")
    after = {e: code_digest(e, copy) for e in before}
    assert all(after[e] != before[e] for e in before)


def test_a_module_only_the_surface_runs_keeps_the_envelope_digest(copy: Path) -> None:
    before = {e: code_digest(e, copy) for e in (SURFACE_ENTRY, ENVELOPE)}
    _edit(copy / "surface" / "posed.py", "FOLD_DEG: Final = 90.0", "FOLD_DEG: Final = 91.0")
    assert code_digest(SURFACE_ENTRY, copy) != before[SURFACE_ENTRY]
    assert code_digest(ENVELOPE, copy) == before[ENVELOPE]


def test_the_memo_gives_the_computed_digest_and_forgets_an_edited_file(copy: Path, tmp_path: Path) -> None:
    """Builds remember each module's result by its exact bytes (the parse costs 0.6 s a build): a memo
    hit is the computed digest, any edited byte is parsed again, and a damaged memo entry is ignored."""
    memo = tmp_path / "memo"
    plain = code_digest(SURFACE_ENTRY, copy)
    assert code_digest(SURFACE_ENTRY, copy, memo) == plain  # written
    entries = sorted(memo.glob("*.json"))
    assert len(entries) == len(code_closure(SURFACE_ENTRY, copy))
    assert code_digest(SURFACE_ENTRY, copy, memo) == plain  # read back
    # Damaged entries are recomputed, not believed.
    entries[0].write_text("{not json")
    entries[1].write_text('{"digest": 1, "imports": []}')
    assert code_digest(SURFACE_ENTRY, copy, memo) == plain
    # A code edit misses the memo and changes the digest exactly as without it.
    _edit(copy / "surface" / "posed.py", "FOLD_DEG: Final = 90.0", "FOLD_DEG: Final = 91.0")
    assert code_digest(SURFACE_ENTRY, copy, memo) == code_digest(SURFACE_ENTRY, copy) != plain
    # A planted wrong entry for posed.py's current bytes is believed: the memo is keyed by those bytes.
    key = memo_key("creaturegen.surface.posed", (copy / "surface" / "posed.py").read_bytes())
    (memo / f"{key}.json").write_text('{"digest": "planted", "imports": []}')
    assert code_digest(SURFACE_ENTRY, copy, memo) != code_digest(SURFACE_ENTRY, copy)
