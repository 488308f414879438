"""The command line as a user meets it: help, version, exit codes, summaries."""

from __future__ import annotations

from pathlib import Path

from conftest import EXAMPLES, REPO, run_cli
from creaturegen import __version__


def test_version() -> None:
    done = run_cli("--version")
    assert (done.returncode, done.stdout.strip()) == (0, f"creaturegen {__version__}")


def test_help_lists_commands_and_exit_codes() -> None:
    done = run_cli("--help")
    assert done.returncode == 0
    for word in ("validate", "schema", "build", "Exit codes"):
        assert word in done.stdout


def test_no_command_is_a_usage_error() -> None:
    assert run_cli().returncode == 2


def test_validate_many_files_ok() -> None:
    files = [str(p) for p in sorted(EXAMPLES.rglob("*.json"))]
    done = run_cli("validate", *files)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [f"{f}: ok" for f in files]


def test_one_bad_file_among_good_ones_fails_therun_cli() -> None:
    good = str(EXAMPLES / "lizard.json")
    bad = str(REPO / "tests" / "fixtures" / "invalid" / "k-exceeds-kcap.json")
    done = run_cli("validate", good, bad)
    assert done.returncode == 2
    assert done.stdout.strip() == f"{good}: ok"
    assert done.stderr.strip() == f"{bad}: part.head.k: must be <= kCap (0.05) (got 0.2)"


def test_build_prints_the_compiled_summary(tmp_path: Path) -> None:
    done = run_cli("build", str(EXAMPLES / "lizard.json"), "-o", str(tmp_path / "out"))
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert "creature 'Lizard Explicit Tree' -> package lizard-explicit-tree" in lines
    assert "  slots 17 of maxParts 64" in lines
    assert "  blend tree, 7 nodes, 1 root(s)" in lines


def test_schema_check_detects_staleness(tmp_path: Path) -> None:
    assert run_cli("schema", "--check", "--out", str(tmp_path)).returncode == 2
    assert run_cli("schema", "--out", str(tmp_path)).returncode == 0
    assert run_cli("schema", "--check", "--out", str(tmp_path)).returncode == 0
