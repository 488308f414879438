"""The typed records behind core/data.js (model/record.py, motion/data.py, creature/runtime.py) and the
TypeScript interfaces core/index.d.ts renders from them (emit/tstypes.py).

What must hold: every field of every record CREATURE holds is declared in the shipped index.d.ts under its
JSON key with the TypeScript type of its Python type; no interface of that data is written by hand beside
the rendered ones; a record's JSON is its fields in order under camelCase keys; the gene and size tables
name fields that exist; and the build's number hygiene (no -0, nothing non-finite) reaches nested records.
"""

from __future__ import annotations

import dataclasses
import re
import typing
from dataclasses import dataclass
from typing import Annotated, Literal

import pytest

from conftest import EXAMPLES
from creaturegen.creature import runtime
from creaturegen.creature.runtime import CreatureData, data_declarations
from creaturegen.emit import tstypes
from creaturegen.emit.render import environment
from creaturegen.model.record import JsonRecord, TsName, attribute_name, finite_record, json_name
from creaturegen.model.skeleton import build_skeleton
from creaturegen.motion import data as motion_data
from creaturegen.motion.data import LegData, MotionData
from creaturegen.motion.rig import GAIT_GENES, SIZED_FIELDS, build_motion
from creaturegen.resources import templates_dir
from creaturegen.rig import compile_rig
from creaturegen.spec import CharacterSpec, load_spec


@dataclass(frozen=True, slots=True)
class _Inner(JsonRecord):
    """An inner record."""

    value: float


@dataclass(frozen=True, slots=True)
class _Sample(JsonRecord):
    """A record with one field of every kind the renderer knows. Its docstring is long enough that the
    comment must wrap onto more than one line of the rendered declaration, as JSDoc does."""

    flag: bool
    count: int
    """How many."""
    ratio: float
    label: str
    kind: Literal["a", "b"]
    named: Annotated[str, TsName("SomeUnion")]
    point: Annotated[tuple[float, float, float], TsName("Vec3")]
    pair: tuple[int, str]
    values: tuple[float, ...]
    nested_lists: tuple[tuple[str, ...], ...]
    table: dict[str, float]
    maybe: int | None
    inner: _Inner
    inners: tuple[_Inner, ...]
    listed: list[int]


def test_python_types_render_as_their_typescript_types() -> None:
    text = tstypes.interface(_Sample)
    members = dict(re.findall(r"^  readonly (\w+): (.+);$", text, re.M))
    assert members == {
        "flag": "boolean",
        "count": "number",
        "ratio": "number",
        "label": "string",
        "kind": '"a" | "b"',
        "named": "SomeUnion",
        "point": "Vec3",
        "pair": "readonly [number, string]",
        "values": "readonly number[]",
        "nestedLists": "readonly (readonly string[])[]",
        "table": "Readonly<Record<string, number>>",
        "maybe": "number | null",
        "inner": "_Inner",
        "inners": "readonly _Inner[]",
        "listed": "readonly number[]",
    }
    assert "  /** How many. */\n  readonly count: number;" in text
    assert text.startswith("/**\n * A record with one field of every kind")
    assert text.endswith("}")
    assert tstypes.reachable(_Sample) == [_Inner, _Sample], "parts are declared before the whole"


def test_a_type_the_renderer_does_not_know_is_an_error() -> None:
    with pytest.raises(TypeError, match="no TypeScript type"):
        tstypes.ts_type(set[int])


def _interfaces(text: str) -> dict[str, dict[str, str]]:
    """Interface name → member → TypeScript type, from declarations as emit/tstypes.py writes them."""
    found: dict[str, dict[str, str]] = {}
    for name, body in re.findall(r"^export interface (\w+) \{\n(.*?)^\}", text, re.M | re.S):
        found[name] = dict(re.findall(r"^  readonly (\w+): (.+);$", body, re.M))
    return found


#: Records CREATURE holds, with what a hand-checked sample of their fields must be declared as.
EXPECTED = {
    "CreatureData": {
        "specSha256": "string",
        "signatures": "CreatureSignatures",
        "tier": "TierName",
        "slots": "readonly (readonly number[])[]",
        "genetics": "ColourGenetics",
        "slotLab": "readonly Vec3[]",
        "motion": "MotionData",
        "tiers": "readonly TierData[]",
    },
    "TierData": {"tier": "TierName", "signatures": "CreatureSignatures", "mesh": "MeshCounts"},
    "MotionData": {
        "type": "LocomotionType",
        "hz": "number",
        "legs": "readonly LegData[]",
        "ropes": "readonly RopeData[]",
        "wings": "readonly WingData[]",
        "pivot": "readonly Vec3[]",
        "constants": "MotionConstants",
        "ropeGround": "boolean",
        "genes": "MotionGenes",
        "lengths": "SizedFields",
    },
    "LegData": {"part": "string", "upper": "number", "hip": "Vec3", "reachMin": "number"},
    "RopeData": {"slots": "readonly number[]", "rest": "readonly Vec3[]", "radius": "readonly number[]"},
    "WingData": {"slot": "number", "amplitude": "number"},
    "MotionConstants": {"hopCrouchS": "number", "ropeBendLimitDeg": "number"},
    "MotionGenes": {"fields": "readonly (readonly string[])[]"},
    "SizedFields": {"legs": "readonly string[]"},
    "ColourGenetics": {"hueRad": "number"},
    "CorrectionData": {"earlyOut": "number"},
    "MeshCounts": {"triangles": "number"},
    "LookData": {"roughness": "number", "aoTaps": "number", "distanceRange": "number"},
}


def test_every_field_of_every_record_is_declared_with_its_type() -> None:
    """The rendered declarations hold one interface per record CREATURE holds, and each interface exactly
    the record's fields, under their JSON keys, typed as the renderer types their Python hints; the sample
    in EXPECTED pins those types independently of the renderer."""
    declared = _interfaces(data_declarations())
    records = tstypes.reachable(CreatureData)
    assert set(declared) == {cls.__name__ for cls in records} == set(EXPECTED)
    for cls in records:
        hints = tstypes.record_hints(cls)
        members = declared[cls.__name__]
        assert list(members) == [json_name(f.name) for f in dataclasses.fields(cls)], cls.__name__
        for name, hint in hints.items():
            assert members[json_name(name)] == tstypes.ts_type(hint), f"{cls.__name__}.{name}"
        for member, ts in EXPECTED[cls.__name__].items():
            assert members[member] == ts, f"{cls.__name__}.{member}"


def test_the_shipped_declarations_are_the_rendered_ones() -> None:
    """core/index.d.ts prints the rendered interfaces and declares none of them a second time; the types
    they name (the unions, Vec3, CreatureSignatures) are declared there."""
    plan = {"types": {"debugMode": ["off"], "tierName": ["hero"], "locomotionType": ["none"]}}
    plan["types"]["declarations"] = data_declarations()  # type: ignore[assignment]
    text = environment(templates_dir("creature")).get_template("core/index.d.ts.j2").render(plan=plan)
    assert data_declarations() in text
    for cls in tstypes.reachable(CreatureData):
        assert text.count(f"export interface {cls.__name__} ") == 1, cls.__name__
    for name in ("DebugMode", "TierName", "LocomotionType", "Vec3"):
        assert re.search(rf"^export type {name} = ", text, re.M), name
    assert "export interface CreatureSignatures {" in text
    assert "export const CREATURE: CreatureData;" in text


def test_field_docs_are_the_attribute_docstrings() -> None:
    docs = tstypes.field_docs(LegData)
    assert docs["upper"] == "Slot of the thigh (hip to knee)."
    assert "hip" not in docs
    assert tstypes.class_doc(MotionData).startswith("CREATURE.motion:")
    assert "/** Fixed steps per second. */" in tstypes.interface(MotionData)


def _motion(name: str) -> MotionData:
    spec = load_spec(EXAMPLES / name)
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    return build_motion(spec, rig, build_skeleton(spec, rig))


def test_a_records_json_is_its_fields_in_order_under_camel_case_keys() -> None:
    data = _motion("reference/hopper.json")
    shipped = data.to_json()
    assert list(shipped) == [json_name(f.name) for f in dataclasses.fields(MotionData)]
    assert list(shipped)[:6] == ["type", "hz", "speed", "bodyScale", "groundY", "centreY"]
    legs = shipped["legs"]
    assert isinstance(legs, list)
    assert all(isinstance(leg, dict) and list(leg) == list(legs[0]) for leg in legs)
    assert shipped["constants"] == {json_name(k): v for k, v in dataclasses.asdict(data.constants).items()}
    assert all(isinstance(x, list) and len(x) == 3 for x in typing.cast(list[object], shipped["pivot"]))
    for key in ("stepLengthSpec", "groundY", "hopCrouchS", "ropeBendLimitDeg", "specSha256", "reachMin"):
        assert json_name(attribute_name(key)) == key


def test_gene_and_size_tables_name_numeric_fields() -> None:
    """The shipped tables name fields by JSON key, which motion/express.py reads by attribute: each must be
    a field of its record, and a number or numbers."""
    records = {"speeds": MotionData, "top": MotionData, "legs": LegData}
    records |= {"ropes": motion_data.RopeData, "wings": motion_data.WingData}
    for group, names in SIZED_FIELDS.to_json().items():
        hints = tstypes.record_hints(records[group])
        assert isinstance(names, list)
        for key in names:
            assert isinstance(key, str)
            ts = tstypes.ts_type(hints[attribute_name(key)])
            assert ts in ("number", "Vec3", "readonly number[]", "readonly Vec3[]"), (group, key)
    top = tstypes.record_hints(MotionData)
    for groups in GAIT_GENES.values():
        for key in (k for group in groups for k in group):
            assert tstypes.ts_type(top[attribute_name(key)]) == "number", key


def test_finite_record_reaches_nested_records() -> None:
    data = _motion("reference/biped.json")
    leg = data.legs[0]
    signed = dataclasses.replace(data, legs=(dataclasses.replace(leg, hip=(-0.0, leg.hip[1], leg.hip[2])),))
    clean = finite_record(signed, "motion")
    assert str(clean.legs[0].hip[0]) == "0.0"
    broken = dataclasses.replace(data, legs=(dataclasses.replace(leg, tuck=float("nan")),))
    with pytest.raises(ValueError, match=r"motion\.legs\[0\]\.tuck: nan is not a finite number"):
        finite_record(broken, "motion")


def test_records_are_frozen() -> None:
    data = _motion("reference/biped.json")
    with pytest.raises(dataclasses.FrozenInstanceError):
        data.speed = 1.0  # type: ignore[misc]
    assert runtime.CreatureData.__dataclass_params__.frozen  # type: ignore[attr-defined]
