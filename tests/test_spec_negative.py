"""Bad specs: each fixture must produce exactly the pinned errors, in order, and nothing else.

The expectations live in fixtures/invalid/expected.txt (``== name`` then one ``path: message`` per line)
so a reviewer reads the whole error vocabulary in one file.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import run_cli
from creaturegen.spec import MAX_SPEC_BYTES, SpecValidationError, load_spec, validate_bytes

FIXTURES = Path(__file__).parent / "fixtures" / "invalid"


def _expected() -> dict[str, list[str]]:
    cases: dict[str, list[str]] = {}
    current: list[str] = []
    for line in (FIXTURES / "expected.txt").read_text(encoding="utf-8").splitlines():
        if line.startswith("== "):
            current = cases.setdefault(line[3:], [])
        elif line:
            current.append(line)
    return cases


EXPECTED = _expected()


def _errors(data: bytes) -> list[str]:
    with pytest.raises(SpecValidationError) as caught:
        validate_bytes(data)
    return [str(e) for e in caught.value.errors]


def test_every_fixture_has_expectations() -> None:
    on_disk = {p.stem for p in FIXTURES.glob("*.json")}
    assert on_disk == set(EXPECTED)
    assert len(on_disk) >= 25


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_fixture_errors_are_exact(name: str) -> None:
    assert _errors((FIXTURES / f"{name}.json").read_bytes()) == EXPECTED[name]


def test_many_errors_are_collected_in_one_pass() -> None:
    assert len(EXPECTED["many-errors-at-once"]) == 4


def test_five_megabyte_spec_is_refused_before_parsing(tmp_path: Path) -> None:
    spec = {"name": "Huge", "parts": [{"id": "body", "shape": "sphere", "r": 0.2}], "pad": "x" * (5 << 20)}
    path = tmp_path / "huge.json"
    path.write_text(json.dumps(spec))
    size = path.stat().st_size
    with pytest.raises(SpecValidationError) as caught:
        load_spec(path)
    assert [str(e) for e in caught.value.errors] == [
        f"spec: is {size} bytes; specs are limited to {MAX_SPEC_BYTES} bytes"
    ]


def test_missing_file_is_a_spec_error(tmp_path: Path) -> None:
    with pytest.raises(SpecValidationError) as caught:
        load_spec(tmp_path / "absent.json")
    assert [str(e) for e in caught.value.errors] == ["spec: cannot be read: No such file or directory"]


def test_error_places_follow_ids_not_array_order() -> None:
    """The same mistake is reported at the same place whatever the order of the parts."""
    spec = json.loads((FIXTURES / "negative-radius.json").read_text())
    spec["parts"].reverse()
    assert _errors(json.dumps(spec).encode()) == EXPECTED["negative-radius"]


def test_cli_reports_every_error_and_exits_2(tmp_path: Path) -> None:
    path = FIXTURES / "many-errors-at-once.json"
    done = run_cli("validate", str(path), cwd=tmp_path)
    assert done.returncode == 2
    assert done.stdout == ""
    assert done.stderr.splitlines() == [f"{path}: {line}" for line in EXPECTED["many-errors-at-once"]]
    assert list(tmp_path.iterdir()) == []


def test_cli_json_output_lists_path_and_message() -> None:
    path = FIXTURES / "malformed-json.json"
    done = run_cli("validate", "--json", str(path))
    assert done.returncode == 2
    assert json.loads(done.stdout) == [
        {"file": str(path), "path": "5:3", "message": "invalid JSON: Expecting value"}
    ]


def test_cli_prints_json_syntax_errors_compiler_style() -> None:
    path = FIXTURES / "malformed-json.json"
    done = run_cli("validate", str(path))
    assert done.stderr.strip() == f"{path}:5:3: invalid JSON: Expecting value"


def test_build_of_an_invalid_spec_writes_nothing(tmp_path: Path) -> None:
    out = tmp_path / "out"
    done = run_cli("build", str(FIXTURES / "parent-cycle.json"), "-o", str(out))
    assert done.returncode == 2
    assert "part.body.parent: parent cycle body -> head -> body" in done.stderr
    assert not out.exists()
