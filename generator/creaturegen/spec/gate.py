"""The one validation gate: bytes in, a validated spec or every error out.

Order: size, UTF-8, JSON syntax (line:column), duplicate keys and non-finite numbers anywhere, the kind,
field validation, then the kind's cross-field rules. Everything after the syntax check runs to the end
and reports every error, one per place, in a stable order.
"""

from __future__ import annotations

import json
import math
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from .character import CharacterSpec
from .creature_rules import check_creature
from .errors import WHOLE_SPEC, SpecError, SpecValidationError, shown
from .flat import unfold_unions
from .frost import FrostEffectSpec
from .messages import describe
from .places import place
from .types import RULE_ERROR

#: Specs are ~15-250 lines; anything past this is a mistake or an attack, refused before parsing.
MAX_SPEC_BYTES = 1 << 20
#: Errors listed per spec: a generated spec with 70,000 unknown fields needs the first few to be fixed,
#: not 70,000 did-you-mean searches (9 s); the rest are counted in one last line.
MAX_ERRORS = 200

Spec = CharacterSpec | FrostEffectSpec

#: ``kind`` -> model; a missing ``kind`` means a creature so the reference specs validate unchanged.
KINDS: dict[str, type[CharacterSpec] | type[FrostEffectSpec]] = {
    "creature": CharacterSpec,
    "frost": FrostEffectSpec,
}


class _Object(dict[str, Any]):
    """A JSON object that remembers keys written twice (json.loads would silently keep the last)."""

    duplicates: list[str]


def _object_hook(pairs: list[tuple[str, Any]]) -> _Object:
    obj = _Object()
    obj.duplicates = []
    for key, value in pairs:
        if key in obj:
            obj.duplicates.append(key)
        obj[key] = value
    return obj


def _scan(value: object, loc: tuple[str | int, ...] = ()) -> Iterator[tuple[tuple[str | int, ...], str]]:
    """Problems JSON lets through but a spec must not have: repeated keys and NaN/Infinity anywhere."""
    if isinstance(value, _Object):
        for key in sorted(set(value.duplicates)):
            yield (*loc, key), "key written more than once"
        for key, item in value.items():
            yield from _scan(item, (*loc, key))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            yield from _scan(item, (*loc, i))
    elif isinstance(value, float) and not math.isfinite(value):
        yield loc, f"must be a finite number (got {shown(value)})"


def _vocabulary(model: type[BaseModel]) -> set[str]:
    """Every field name a spec kind knows, for did-you-mean hints on unknown fields."""
    names: set[str] = set()
    todo: list[type[BaseModel]] = [model]
    while todo:
        current = todo.pop()
        for name, info in current.model_fields.items():
            names.add(info.alias or name)
            todo += [t for t in _model_types(info.annotation) if t not in todo and t is not current]
    return names


def _model_types(annotation: object) -> list[type[BaseModel]]:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    args = getattr(annotation, "__args__", ()) or ()
    meta = getattr(annotation, "__origin__", None)
    found = [t for a in args for t in _model_types(a)]
    return found + (_model_types(meta) if meta is not None and meta is not annotation else [])


def json_type(value: object) -> str:
    """JSON's name for a parsed value's type, for messages about the document's shape."""
    names = {list: "an array", str: "a string", bool: "a boolean", type(None): "null", dict: "an object"}
    return names.get(type(value), "a number")


def parse(data: bytes) -> tuple[object, list[SpecError]]:
    """Decode and parse; syntax errors are placed as ``line:column``."""
    if len(data) > MAX_SPEC_BYTES:
        return None, [
            SpecError(WHOLE_SPEC, f"is {len(data)} bytes; specs are limited to {MAX_SPEC_BYTES} bytes")
        ]
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        return None, [SpecError(WHOLE_SPEC, f"is not UTF-8 text (byte {exc.start})")]
    try:
        return json.loads(text.removeprefix("\ufeff"), object_pairs_hook=_object_hook), []
    except json.JSONDecodeError as exc:
        return None, [SpecError(f"{exc.lineno}:{exc.colno}", f"invalid JSON: {exc.msg}")]
    except RecursionError:
        return None, [SpecError(WHOLE_SPEC, "is nested too deeply")]


def check(raw: object) -> tuple[Spec | None, list[SpecError]]:
    """Validate a parsed document; returns the spec only when there is no error."""
    if not isinstance(raw, dict):
        return None, [SpecError(WHOLE_SPEC, f"must be a JSON object (got {json_type(raw)})")]
    kind = raw.get("kind", "creature")
    model = KINDS.get(kind) if isinstance(kind, str) else None
    if model is None:
        return None, [SpecError("kind", f"must be one of {', '.join(KINDS)} (got {shown(kind)})")]
    errors = [SpecError(place(raw, loc), message) for loc, message in _scan(raw)]
    spec: Spec | None = None
    hidden = 0
    held: list[SpecError] = []
    try:
        spec = model.model_validate(raw)
    except ValidationError as exc:
        vocabulary = _vocabulary(model)
        found = exc.errors(include_url=False)
        if model is CharacterSpec:
            found, union_only = unfold_unions(raw, found)
            held = [SpecError(place(raw, e["loc"]), describe(e, vocabulary)) for e in union_only[:MAX_ERRORS]]
        # Each message may search the vocabulary for a near name: only the ones that are shown are made.
        room = max(MAX_ERRORS - len(errors), 0)
        hidden += max(len(found) - room, 0)
        for err in found[:room]:
            where = place(raw, err["loc"])
            message = str(err["msg"]) if err["type"] == RULE_ERROR else describe(err, vocabulary)
            errors.append(SpecError(where, message))
    if model is CharacterSpec:
        errors += check_creature(raw)
    # A union error no flat model nor rule explains is still an error: a refusal always names one.
    unique = _first_per_place(errors or held)
    hidden += max(len(unique) - MAX_ERRORS, 0)
    unique = unique[:MAX_ERRORS]
    if hidden:
        unique.append(SpecError(WHOLE_SPEC, f"{hidden} more errors not shown; fix the ones above first"))
    return (spec if not unique else None), unique


def _first_per_place(errors: list[SpecError]) -> list[SpecError]:
    """Keep one message per place: the earliest check that complained is the most basic one."""
    seen: set[str] = set()
    out = []
    for error in errors:
        if error.path not in seen:
            seen.add(error.path)
            out.append(error)
    return out


def validate_bytes(data: bytes, source: str = "<spec>") -> Spec:
    """The gate. Raises SpecValidationError carrying every error found."""
    raw, errors = parse(data)
    if not errors:
        spec, errors = check(raw)
        if spec is not None:
            return spec
    raise SpecValidationError(errors, source)


def read_spec_bytes(path: Path) -> bytes:
    """A spec file's bytes: a regular file, read no further than one byte past the limit (a device such as
    /dev/zero would otherwise be read without end, a FIFO nobody writes would hang)."""
    try:
        info = path.stat()
        if not stat.S_ISREG(info.st_mode):
            raise SpecValidationError([SpecError(WHOLE_SPEC, "is not a regular file")], str(path))
        if info.st_size > MAX_SPEC_BYTES:
            message = f"is {info.st_size} bytes; specs are limited to {MAX_SPEC_BYTES} bytes"
            raise SpecValidationError([SpecError(WHOLE_SPEC, message)], str(path))
        with path.open("rb") as handle:
            return handle.read(MAX_SPEC_BYTES + 1)
    except OSError as exc:
        raise SpecValidationError(
            [SpecError(WHOLE_SPEC, f"cannot be read: {exc.strerror or exc}")], str(path)
        ) from exc


def load_spec(path: Path) -> Spec:
    """Read (read_spec_bytes) and validate a spec file."""
    return validate_bytes(read_spec_bytes(path), str(path))
