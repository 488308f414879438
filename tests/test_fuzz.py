"""Property-based fuzzing of the spec gate and the CLI's input handling (tests/fuzz_specs.py strategies).

Every generated document, a valid example mutated at random places or random JSON, in four encodings
(pretty, compact, ASCII-escaped with lone surrogates, with a BOM), must end in a spec or in named errors:
each a non-empty one-line place and message that print as UTF-8, never a traceback. ``make fuzz`` runs
the same property over FUZZ_EXAMPLES cases (50,000 by default); ``make test`` over a fixed 2,000.
The fixed hostile cases below are the ones an outside fuzzer found (issue 25), kept as regressions.
"""

from __future__ import annotations

import copy
import json
import os
import time
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from creaturegen.cli import main
from creaturegen.spec import validate_bytes
from creaturegen.spec.errors import SpecError, SpecValidationError
from fuzz_specs import EXAMPLES, documents, encode, unusable

EXAMPLES_RUN = int(os.environ.get("FUZZ_EXAMPLES", "2000"))
REPO = Path(__file__).resolve().parent.parent


def _assert_usable(error: SpecError) -> None:
    assert not unusable(error.path, error.message), f"an error nobody can act on: {str(error)!r}"


@settings(
    max_examples=EXAMPLES_RUN,
    deadline=None,
    database=None,
    derandomize=True,
    suppress_health_check=list(HealthCheck),
)
@given(documents, st.integers(0, 3))
def test_gate_names_every_error(doc: Any, style: int) -> None:
    errors: list[SpecError] = []
    try:
        validate_bytes(encode(doc, style), "<fuzz>")
    except SpecValidationError as exc:
        errors = exc.errors or [SpecError("", "a refusal without any error")]
    for error in errors:
        _assert_usable(error)


def _chain(n: int) -> dict[str, Any]:
    base = json.loads((REPO / "examples/reference/hopper.json").read_text())
    first = base["parts"][0]
    parts = [
        {**copy.deepcopy(first), "id": f"p{i}", **({"parent": f"p{i - 1}"} if i else {})} for i in range(n)
    ]
    for part in parts[1:]:
        part.pop("a", None)
        part.pop("b", None)
        part["offset"] = [0.1, 0, 0]
    return {**base, "parts": parts}


def _blend_loop(n: int) -> dict[str, Any]:
    base = json.loads((REPO / "examples/lizard.json").read_text())
    nodes = [
        {"id": f"n{i}", "left": {"node": f"n{(i + 1) % n}"}, "right": {"part": "head"}, "k": 0.05}
        for i in range(n)
    ]
    return {**base, "blend": {"mode": "tree", "roots": [{"node": "n0"}], "nodes": nodes}}


HOSTILE: dict[str, bytes] = {
    "huge integer coordinate": json.dumps(
        {**json.loads((REPO / "examples/reference/hopper.json").read_text()), "scale": 10**400}
    ).encode(),
    "locomotion type object": b'{"name": "x", "locomotion": {"type": {}}, "parts": []}',
    "part id array": b'{"name": "x", "parts": [{"id": []}]}',
    "lone surrogate key": b'{"name": "x", "\\ud800": 1}',
    "lone surrogate name": b'{"name": "\\udfffx", "parts": []}',
    "BOM": b"\xef\xbb\xbf" + (REPO / "examples/reference/hopper.json").read_bytes(),
    "parent chain of 4000": json.dumps(_chain(4000)).encode(),
    "blend loop of 5000": json.dumps(_blend_loop(5000)).encode(),
    "deep nesting": b"[" * 100_000 + b"]" * 100_000,
    "markup name": json.dumps(
        {
            **json.loads((REPO / "examples/reference/hopper.json").read_text()),
            "name": "</script><script>alert(1)</script>",
        }
    ).encode(),
}


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_hostile_input_is_named_quickly(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = tmp_path / "spec.json"
    spec.write_bytes(HOSTILE[case])
    start = time.perf_counter()
    code = main(["validate", str(spec)])
    seconds = time.perf_counter() - start
    err = capsys.readouterr().err
    assert code in (0, 2), err
    assert "Traceback" not in err
    for line in err.splitlines():
        assert line.startswith(str(spec)), f"an error line without its file and place: {line!r}"
    # Not a timing assertion on the product: a loose bound that only an exploding algorithm crosses.
    assert seconds < 30, f"{case}: validation took {seconds:.1f} s"


@pytest.mark.parametrize("target", ["/dev/zero", "fifo", "folder"])
def test_unreadable_inputs_are_refused(
    target: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = Path(target)
    if target == "fifo":
        path = tmp_path / "fifo"
        os.mkfifo(path)
    elif target == "folder":
        path = tmp_path
    assert main(["validate", str(path)]) == 2
    assert "is not a regular file" in capsys.readouterr().err


@pytest.mark.parametrize("where", ["a file", "below a file"])
def test_output_at_a_file_is_one_line(where: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    out = blocker if where == "a file" else blocker / "sub"
    spec = next(p for p in EXAMPLES if p.name == "frost-budgeted.json")
    assert main(["build", str(spec), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "cannot write" in err
    assert "Traceback" not in err
    assert blocker.read_text() == "x"


def _extreme(example: str, change: str) -> dict[str, Any]:
    doc = json.loads((REPO / "examples" / "reference" / example).read_text())
    target, field, value = change.split(" ")
    holder = {"locomotion": doc["locomotion"], "spec": doc}.get(target, doc["parts"][0])
    holder[field] = float(value)
    return doc


#: Valid values at the edge of float range that crashed builds (issue 25), each now a named refusal:
#: (example, change, exit code, the place the message must name).
EXTREMES = [
    ("quadruped.json", "locomotion stepHeight 1e308", 2, "locomotion.stepHeight"),
    ("hopper.json", "locomotion hopHeight 1e308", 2, "locomotion.hopHeight"),
    ("hopper.json", "spec scale 1000", 3, "locomotion: one hopper cycle lasts"),
    ("hopper.json", "part r 1e308", 2, "part.core"),
    ("hopper.json", "part r 1e-300", 2, "part.core.r"),
]


@pytest.mark.filterwarnings("error")  # a numpy warning would reach the user's terminal
@pytest.mark.parametrize(("example", "change", "code", "named"), EXTREMES)
def test_extreme_valid_values_are_refused_by_name(
    example: str, change: str, code: int, named: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(_extreme(example, change)))
    out = tmp_path / "out"
    assert main(["build", str(spec), "--picture", "off", "-o", str(out)]) == code
    err = capsys.readouterr().err
    assert named in err
    assert "Traceback" not in err
    assert "Warning" not in err
    assert not out.exists() or not any(out.iterdir())
