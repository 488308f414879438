"""Frozen records that ship as JSON: the base of the typed data the build hands to the package.

The motion data and the creature plan's runtime data used to be untyped dicts read by string keys in a
dozen modules: a misspelt key was a KeyError at run time (or a silently missing field in core/data.js),
and the package's TypeScript declarations of the same shapes were written out a second time by hand. As
frozen dataclasses they are read by attribute (mypy checks every read), and emit/tstypes.py renders the
package's interfaces from the very same definitions.

The JSON a record writes is what the dicts were, byte for byte: each key is its field's name in camelCase
(the shipped JS reads camelCase; Python attributes are snake_case), in field order, each value as it is
(no coercion: an int stays an int, a float a float), nested records, tuples and lists as JSON objects and
arrays. A field's TypeScript type is its Python type's, unless ``Annotated`` with a :class:`TsName`.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import Field, dataclass
from typing import ClassVar, TypeVar

#: What ``json.dumps`` writes and ``json.loads`` reads back.
JsonValue = None | bool | int | float | str | list["JsonValue"] | dict[str, "JsonValue"]
JsonObject = dict[str, JsonValue]

R = TypeVar("R", bound="JsonRecord")


@dataclass(frozen=True)
class TsName:
    """``Annotated`` metadata: the field's TypeScript type is this declaration of the package's index.d.ts
    (a union rendered from its Python source, such as ``LocomotionType``, or a hand-written interface),
    not the structural rendering of its Python type (``str`` would lose the union's members)."""

    name: str


class JsonRecord:
    """Base of the frozen dataclasses that ship as JSON (see the module docstring). Subclasses are
    ``@dataclass(frozen=True, slots=True)``: immutable, so an individual's copy (motion/express.py) never
    aliases the authored data, and slotted, so the motion reference's per-tick reads stay cheap."""

    __slots__ = ()
    # Declared so that mypy sees every subclass as a dataclass (dataclasses.fields, replace).
    __dataclass_fields__: ClassVar[dict[str, Field[object]]]

    def to_json(self) -> JsonObject:
        """The record as the JSON object it ships as: camelCase keys in field order, values unchanged."""
        return {key: json_value(getattr(self, name)) for name, key in record_keys(type(self))}


def json_name(attribute: str) -> str:
    """The JSON key of a snake_case field: ``step_length_spec`` → ``stepLengthSpec``, ``ground_y`` →
    ``groundY``."""
    head, *rest = attribute.split("_")
    return head + "".join(part[:1].upper() + part[1:] for part in rest)


def attribute_name(key: str) -> str:
    """The field of a camelCase JSON key (the inverse of :func:`json_name`): the shipped data names fields
    by their keys (the gait genes and the sized fields), which the Python reference reads by attribute."""
    return re.sub(r"(?<!^)(?=[A-Z])", "_", key).lower()


#: record_keys' answers, by class (``functools.cache`` is not typed for class arguments).
_KEYS: dict[type[JsonRecord], tuple[tuple[str, str], ...]] = {}


def record_keys(cls: type[JsonRecord]) -> tuple[tuple[str, str], ...]:
    """(attribute, JSON key) of every field of ``cls``, in field order."""
    keys = _KEYS.get(cls)
    if keys is None:
        keys = _KEYS[cls] = tuple((f.name, json_name(f.name)) for f in dataclasses.fields(cls))
    return keys


def json_value(value: object) -> JsonValue:
    """``value`` as plain JSON data: records by :meth:`JsonRecord.to_json`, tuples as lists."""
    if isinstance(value, JsonRecord):
        return value.to_json()
    if value is None or isinstance(value, bool | int | float | str):
        return value
    if isinstance(value, tuple | list):
        return [json_value(v) for v in value]
    if isinstance(value, dict):
        return {str(k): json_value(v) for k, v in value.items()}
    raise TypeError(f"{type(value).__name__} is not JSON data")


def field_value(record: JsonRecord, key: str) -> object:
    """The value of the field whose JSON key is ``key`` (a KeyError names a key the record lacks)."""
    name = attribute_name(key)
    if name not in record.__dataclass_fields__:
        raise KeyError(f"{type(record).__name__} has no field {key!r}")
    value: object = getattr(record, name)
    return value


def finite_record(record: R, place: str) -> R:
    """``record`` with every -0.0 made 0.0, nested records and tuples included (JSON writes -0 as 0, and
    the two can differ downstream, e.g. in atan2); a non-finite number is a build bug, named by its
    ``place`` (``motion.legs[0].hip[1]``)."""
    changes = {
        name: _finite(getattr(record, name), f"{place}.{key}") for name, key in record_keys(type(record))
    }
    return dataclasses.replace(record, **changes)


def _finite(value: object, place: str) -> object:
    if isinstance(value, JsonRecord):
        return finite_record(value, place)
    if isinstance(value, tuple):
        return tuple(_finite(v, f"{place}[{i}]") for i, v in enumerate(value))
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"{place}: {value} is not a finite number")
        return value + 0.0
    return value


def replace_by_key(record: R, changes: dict[str, object]) -> R:
    """``record`` with the fields named by JSON key in ``changes`` replaced (the authored record is left
    as it is)."""
    for key in changes:
        field_value(record, key)  # a key the record lacks is an error, never a new attribute
    return dataclasses.replace(record, **{attribute_name(k): v for k, v in changes.items()})
