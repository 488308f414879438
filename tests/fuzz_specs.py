"""Hypothesis strategies for hostile spec documents: valid examples mutated at random places, and random
JSON. Shared by tests/test_fuzz.py (a fixed budget in `make test`) and `make fuzz` (a long run)."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

from hypothesis import strategies as st

REPO = Path(__file__).resolve().parent.parent
EXAMPLES = sorted(
    [
        *REPO.glob("examples/*.json"),
        *REPO.glob("examples/reference/*.json"),
        *REPO.glob("examples/frost/*.json"),
    ]
)
BASES = [json.loads(p.read_text()) for p in EXAMPLES]

#: Strings people and attackers write: markup, paths, control characters, lone surrogates, huge ones.
HOSTILE_TEXT = [
    "",
    " ",
    "a\nb",
    "\x00",
    "\t\r\x1b[31m",
    "</script><script>alert(1)</script>",
    "[x](javascript:alert(1))",
    "../../etc/passwd",
    "/abs/path",
    "C:\\\\win",
    "\ud800",
    "\udfff",
    "ü" * 3,
    "x" * 5000,
    "${x}",
    "{{ plan }}",
    "`rm -rf`",
]
NUMBERS = [0, -1, 1, 10**30, -(10**30), 10**400, 1e308, -1e308, 5e-324, 1e-300, 0.5, 3, 1000, 2**53, -0.0]

scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.sampled_from(NUMBERS),
    st.integers(),
    st.floats(allow_nan=False, allow_infinity=False),
    st.sampled_from(HOSTILE_TEXT),
    st.text(max_size=20),
)
json_values = st.recursive(
    scalars,
    lambda children: st.one_of(
        st.lists(children, max_size=5), st.dictionaries(st.text(max_size=12), children, max_size=5)
    ),
    max_leaves=20,
)


def _paths(value: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    out = [prefix]
    if isinstance(value, dict):
        for k, v in value.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            out += _paths(v, (*prefix, i))
    return out


def _set(doc: Any, path: tuple[Any, ...], value: Any) -> Any:
    if not path:
        return value
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    parent[path[-1]] = value
    return doc


def _delete(doc: Any, path: tuple[Any, ...]) -> Any:
    if not path:
        return doc
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    del parent[path[-1]]
    return doc


@st.composite
def mutated_specs(draw: st.DrawFn) -> Any:
    """An example spec with 1-4 mutations: a value replaced, a key deleted, a list item duplicated, a key
    added, or a part's parent pointed at another part (loops, chains)."""
    doc = copy.deepcopy(draw(st.sampled_from(BASES)))
    for _ in range(draw(st.integers(1, 4))):
        paths = _paths(doc)
        path = draw(st.sampled_from(paths))
        action = draw(st.sampled_from(["replace", "delete", "duplicate", "add", "parent"]))
        if action == "replace":
            doc = _set(doc, path, draw(json_values))
        elif action == "delete" and path:
            doc = _delete(doc, path)
        elif action == "duplicate" and path:
            parent = doc
            for key in path[:-1]:
                parent = parent[key]
            if isinstance(parent, list):
                parent.append(copy.deepcopy(parent[path[-1]]))
        elif action == "add":
            target = doc
            for key in path:
                target = target[key]
            if isinstance(target, dict):
                target[draw(st.sampled_from(["id", "parent", "x", "kind", "type", *HOSTILE_TEXT[:6]]))] = (
                    draw(json_values)
                )
        elif action == "parent" and isinstance(doc, dict) and isinstance(doc.get("parts"), list):
            parts = [p for p in doc["parts"] if isinstance(p, dict)]
            if parts:
                part = draw(st.sampled_from(parts))
                other = draw(st.sampled_from(parts))
                part["parent"] = other.get("id")
    return doc


documents = st.one_of(mutated_specs(), json_values)


def encode(doc: Any, style: int) -> bytes:
    """JSON text as editors write it (pretty, compact, with a BOM), surrogates passed through."""
    text = json.dumps(doc, indent=2 if style == 0 else None, ensure_ascii=style == 2)
    data = text.encode("utf-8", "surrogatepass")
    return b"\xef\xbb\xbf" + data if style == 3 else data


def unusable(path: str, message: str) -> bool:
    """An error a person or model cannot act on: no place, control characters or line breaks, or text that
    cannot be printed as UTF-8 (a lone surrogate)."""
    line = f"{path}: {message}"
    try:
        line.encode("utf-8")
    except UnicodeEncodeError:
        return True
    return not path or any(ord(c) < 32 for c in line)
