"""TypeScript interfaces rendered from the frozen records that ship as JSON (model/record.py).

The package's core/index.d.ts declares the shapes of core/data.js (CREATURE and its motion data). Written
by hand they were a second definition of what the Python records already state, and drifted the moment a
field was added on one side only; rendered from the records, a field is declared exactly when it ships.

Python type → TypeScript: ``bool`` → ``boolean``, ``int`` and ``float`` → ``number``, ``str`` →
``string``, ``None`` → ``null``, ``Literal`` → a union of its JSON values, ``tuple[X, ...]`` (or a list) →
``readonly X[]``, a fixed tuple → a readonly tuple, ``dict[str, X]`` → ``Readonly<Record<string, X>>``, a
union → a union, a record → its interface (rendered too), and ``Annotated[..., TsName(name)]`` → ``name``.
Every member is ``readonly`` (the data is frozen) and named by its JSON key; the class docstring and the
field's attribute docstring (the string right below it) become the JSDoc comments.
"""

from __future__ import annotations

import ast
import dataclasses
import inspect
import itertools
import json
import textwrap
import types
import typing
from collections.abc import Iterator

from ..model.record import JsonRecord, TsName, json_name

#: Widest line of a rendered comment (indent included), as the hand-written declarations wrap.
WIDTH = 110


def ts_type(hint: object) -> str:
    """The TypeScript type of a resolved Python type hint (see the module docstring)."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin is typing.Annotated:
        named = [m.name for m in getattr(hint, "__metadata__", ()) if isinstance(m, TsName)]
        return named[0] if named else ts_type(args[0])
    simple = {bool: "boolean", int: "number", float: "number", str: "string", type(None): "null"}
    if isinstance(hint, type) and hint in simple:
        return simple[hint]
    if isinstance(hint, type) and issubclass(hint, JsonRecord):
        return hint.__name__
    if origin is typing.Literal:
        return " | ".join(json.dumps(a) for a in args)
    if origin in (typing.Union, types.UnionType):
        return " | ".join(ts_type(a) for a in args)
    if (origin is tuple and len(args) == 2 and args[1] is Ellipsis) or origin is list:
        return f"readonly {_operand(ts_type(args[0]))}[]"
    if origin is tuple:
        return "readonly [" + ", ".join(ts_type(a) for a in args) + "]"
    if origin is dict:
        return f"Readonly<Record<{ts_type(args[0])}, {ts_type(args[1])}>>"
    raise TypeError(f"no TypeScript type for {hint!r}")


def _operand(ts: str) -> str:
    """``ts`` parenthesised where an array suffix would bind to its last part only."""
    return f"({ts})" if " " in ts else ts


def record_hints(cls: type[JsonRecord]) -> dict[str, object]:
    """Field → resolved type hint (``Annotated`` kept), in field order."""
    hints = typing.get_type_hints(cls, include_extras=True)
    return {f.name: hints[f.name] for f in dataclasses.fields(cls)}


def field_docs(cls: type[JsonRecord]) -> dict[str, str]:
    """Field → its attribute docstring (the string literal right below the field in the class body)."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    body = tree.body[0].body if isinstance(tree.body[0], ast.ClassDef) else []
    docs: dict[str, str] = {}
    for stmt, after in itertools.pairwise(body):
        if (
            isinstance(stmt, ast.AnnAssign)
            and isinstance(stmt.target, ast.Name)
            and isinstance(after, ast.Expr)
            and isinstance(after.value, ast.Constant)
            and isinstance(after.value.value, str)
        ):
            docs[stmt.target.id] = inspect.cleandoc(after.value.value)
    return docs


def class_doc(cls: type[JsonRecord]) -> str:
    """The class docstring (empty where the class has none: a dataclass makes up its signature)."""
    doc = cls.__dict__.get("__doc__")
    if not isinstance(doc, str) or doc.startswith(f"{cls.__name__}("):
        return ""
    return inspect.cleandoc(doc)


def jsdoc(text: str, indent: str = "") -> list[str]:
    """A JSDoc comment of ``text`` (reST double backquotes made Markdown's single ones), on one line where
    it fits, else wrapped to WIDTH."""
    text = " ".join(text.replace("``", "`").replace("*/", "*\\/").split())
    if not text:
        return []
    one = f"{indent}/** {text} */"
    if len(one) <= WIDTH:
        return [one]
    lines = textwrap.wrap(text, WIDTH - len(indent) - 3, break_long_words=False, break_on_hyphens=False)
    return [f"{indent}/**", *(f"{indent} * {line}" for line in lines), f"{indent} */"]


def interface(cls: type[JsonRecord]) -> str:
    """``export interface <Class> { ... }``: one readonly member per field, named by its JSON key."""
    docs = field_docs(cls)
    lines = [*jsdoc(class_doc(cls)), f"export interface {cls.__name__} {{"]
    for name, hint in record_hints(cls).items():
        lines += jsdoc(docs.get(name, ""), "  ")
        lines.append(f"  readonly {json_name(name)}: {ts_type(hint)};")
    return "\n".join([*lines, "}"])


def _records_in(hint: object) -> Iterator[type[JsonRecord]]:
    """The records a type hint mentions, in the order they appear (``TsName`` hides its type)."""
    if typing.get_origin(hint) is typing.Annotated and any(
        isinstance(m, TsName) for m in getattr(hint, "__metadata__", ())
    ):
        return
    if isinstance(hint, type) and issubclass(hint, JsonRecord):
        yield hint
    for arg in typing.get_args(hint):
        yield from _records_in(arg)


def reachable(*roots: type[JsonRecord]) -> list[type[JsonRecord]]:
    """``roots`` and every record their fields mention, each after the records it mentions (the order the
    hand-written declarations kept: parts before the whole)."""
    seen: list[type[JsonRecord]] = []

    def visit(cls: type[JsonRecord]) -> None:
        if cls in seen:
            return
        for hint in record_hints(cls).values():
            for record in _records_in(hint):
                visit(record)
        seen.append(cls)

    for root in roots:
        visit(root)
    return seen


def declarations(*roots: type[JsonRecord]) -> str:
    """The interfaces of ``roots`` and every record they reach, blank-line separated."""
    return "\n\n".join(interface(cls) for cls in reachable(*roots))
