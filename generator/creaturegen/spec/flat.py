"""Flat views of the tagged unions (parts by ``shape``, locomotion by ``type``), for error messages only.

A tagged union reports a part whose shape is unknown as one error and a part with a known shape under a
tag segment of its location, with pydantic's own wording for a field the shape lacks or does not accept.
The gate re-checks such an item against its flat model instead: every field of every member, all optional
but the tag and the common ones, so each field's own error (a wrong type, a bound) reads and is placed as
in any other object, and the shape and type rules (creature_rules.py) say which fields a shape or type
requires and accepts. The flat models are built from the union members; only the order in which they
list an item's errors is written here.
"""

from __future__ import annotations

from functools import cache
from typing import Annotated, Any

from pydantic import BaseModel, ValidationError, create_model
from pydantic.fields import FieldInfo
from pydantic_core import ErrorDetails

from .character import (
    COMMON_PART_FIELDS,
    LOCOMOTION_MODELS,
    PART_MODELS,
    LocomotionType,
    Shape,
)
from .types import StrictModel

#: Order in which the flat part model checks its fields (and so lists an item's errors): the order of the
#: one part model before the union. A field of a member missing here is checked after these.
PART_FIELD_ORDER = (
    "id",
    "shape",
    "parent",
    "a",
    "b",
    "offset",
    "r",
    "r2",
    "k",
    "kCap",
    "color",
    "segments",
    "length",
    "taper",
    "hip",
    "upper",
    "lower",
    "phase",
    "flap",
)
LOCOMOTION_FIELD_ORDER = (
    "type",
    "tickRate",
    "speed",
    "stepLength",
    "stepHeight",
    "hopLength",
    "hopHeight",
    "altitude",
    "radius",
    "buoyancy",
    "undulation",
)

#: A location in the document: keys and list indices from the root.
Loc = tuple[str | int, ...]


def _flat(
    name: str,
    members: tuple[type[StrictModel], ...],
    tag: str,
    tag_type: object,
    required: tuple[str, ...],
    order: tuple[str, ...],
) -> type[BaseModel]:
    """One model with every field of ``members`` (each as its first member declares it), in ``order``: the
    tag as ``tag_type``, the ``required`` fields that every member requires required, the rest optional."""
    infos: dict[str, FieldInfo] = {}
    for member in members:
        for field, info in member.model_fields.items():
            infos.setdefault(field, info)
    ranked = sorted(infos, key=lambda f: order.index(f) if f in order else len(order))
    fields: dict[str, Any] = {}
    for field in ranked:
        info = infos[field]
        annotation: Any = Annotated[(info.annotation, *info.metadata)] if info.metadata else info.annotation
        if field == tag:
            fields[field] = (tag_type, ...)
        elif field in required and info.is_required():
            fields[field] = (annotation, ...)
        else:
            fields[field] = (annotation | None, None)
    model: type[BaseModel] = create_model(name, __base__=StrictModel, **fields)
    return model


@cache
def flat_part() -> type[BaseModel]:
    """Every part field, as one model: id and shape required, the rest optional."""
    return _flat("FlatPart", PART_MODELS, "shape", Shape, COMMON_PART_FIELDS, PART_FIELD_ORDER)


@cache
def flat_locomotion() -> type[BaseModel]:
    """Every locomotion field, as one model: type required, the rest optional."""
    return _flat("FlatLocomotion", LOCOMOTION_MODELS, "type", LocomotionType, (), LOCOMOTION_FIELD_ORDER)


def union_item(loc: Loc) -> Loc | None:
    """The location of the part or locomotion object an error of the creature model lies in, if any."""
    if len(loc) >= 2 and loc[0] == "parts" and isinstance(loc[1], int):
        return loc[:2]
    if loc and loc[0] == "locomotion":
        return loc[:1]
    return None


def flat_errors(raw: dict[str, Any], item: Loc) -> list[ErrorDetails]:
    """The errors of one part or the locomotion checked against its flat model, located from the root."""
    model = flat_locomotion() if item == ("locomotion",) else flat_part()
    value: Any = raw
    for key in item:
        value = value[key]
    try:
        model.model_validate(value)
    except ValidationError as exc:
        found = exc.errors(include_url=False)
        return [{**err, "loc": (*item, *err["loc"])} for err in found]
    return []


def unfold_unions(
    raw: dict[str, Any], found: list[ErrorDetails]
) -> tuple[list[ErrorDetails], list[ErrorDetails]]:
    """Replace the union errors of each part and of the locomotion by its flat errors, in place of the
    item's first error. Returns (errors, held back): the union errors of an item whose flat model finds
    nothing are held back, because the shape and type rules report them (a missing or foreign field)."""
    by_item: dict[Loc, list[ErrorDetails]] = {}
    for err in found:
        item = union_item(err["loc"])
        if item is not None:
            by_item.setdefault(item, []).append(err)
    out: list[ErrorDetails] = []
    held: list[ErrorDetails] = []
    for err in found:
        item = union_item(err["loc"])
        if item is None:
            out.append(err)
            continue
        union = by_item.pop(item, None)
        if union is None:
            continue
        flat = flat_errors(raw, item)
        out += flat
        if not flat:
            # Drop the tag segment pydantic puts after the item: ('parts', 0, 'capsule', 'a').
            cut = len(item) + 1
            held += [{**e, "loc": (*item, *e["loc"][cut:])} for e in union]
    return out, held
