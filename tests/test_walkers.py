"""Walkers with any even number of legs: the ``octopod`` (8 legs) and the generic ``walker`` (2, 4, 6 or 8)
validate, export to the schema, and compile to the motion data of the named walkers."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import jsonschema
import pytest

from conftest import REPO
from creaturegen.model.skeleton import build_skeleton
from creaturegen.motion.data import MotionData
from creaturegen.motion.rig import WALKERS, build_motion
from creaturegen.rig import compile_rig
from creaturegen.spec import CharacterSpec, SpecValidationError, load_spec, validate_bytes
from creaturegen.spec.character import LEG_COUNTS, WALKER_LEG_COUNTS

SPIDER = Path(__file__).parent / "fixtures" / "spider.json"


def _spider(kind: str, legs: int = 8) -> dict[str, Any]:
    """The spider fixture as ``kind`` on its front ``legs`` legs."""
    document: dict[str, Any] = json.loads(SPIDER.read_text())
    kept = [p["id"] for p in document["parts"] if p["shape"] == "leg"][:legs]
    document["parts"] = [p for p in document["parts"] if p["shape"] != "leg" or p["id"] in kept]
    document["locomotion"]["type"] = kind
    return document


def _errors(document: dict[str, Any]) -> list[str]:
    with pytest.raises(SpecValidationError) as caught:
        validate_bytes(json.dumps(document).encode())
    return [str(e) for e in caught.value.errors]


def _motion(document: dict[str, Any]) -> MotionData:
    spec = validate_bytes(json.dumps(document).encode())
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    return build_motion(spec, rig, build_skeleton(spec, rig))


def test_the_spider_is_an_eight_legged_octopod_with_body_abdomen_and_head() -> None:
    spec = load_spec(SPIDER)
    assert isinstance(spec, CharacterSpec)
    assert spec.locomotion is not None
    assert spec.locomotion.type == "octopod"
    assert {p.id for p in spec.parts if p.shape != "leg"} == {"body", "abdomen", "head"}
    legs = [p for p in spec.parts if p.shape == "leg"]
    assert len(legs) == 8
    # Alternating tetrapods: neighbours along a side and across the body lift half a cycle apart.
    assert sorted({p.phase for p in legs}) == [0.0, 0.5]
    assert sum(p.phase == 0.0 for p in legs) == 4


def test_walker_types_share_one_gait() -> None:
    assert WALKERS == ("biped", "quadruped", "hexapod", "octopod", "walker")
    assert LEG_COUNTS["octopod"] == 8
    assert "walker" not in LEG_COUNTS
    assert WALKER_LEG_COUNTS == (2, 4, 6, 8)


@pytest.mark.parametrize("legs", WALKER_LEG_COUNTS)
def test_a_walker_takes_any_even_leg_count_from_2_to_8(legs: int) -> None:
    spec = validate_bytes(json.dumps(_spider("walker", legs)).encode())
    assert isinstance(spec, CharacterSpec)
    assert sum(p.shape == "leg" for p in spec.parts) == legs


@pytest.mark.parametrize("legs", [0, 1, 3, 5, 7])
def test_a_walker_refuses_other_leg_counts(legs: int) -> None:
    assert _errors(_spider("walker", legs)) == [
        f"locomotion.type: walker needs an even number of leg parts from 2 to 8, the spec has {legs}"
    ]


def test_a_walker_refuses_more_than_eight_legs() -> None:
    document = _spider("walker")
    extra = [dict(p, id=p["id"] + "-extra") for p in document["parts"] if p["shape"] == "leg"][:2]
    document["parts"] += extra
    assert _errors(document) == [
        "locomotion.type: walker needs an even number of leg parts from 2 to 8, the spec has 10"
    ]


def test_an_octopod_needs_eight_legs() -> None:
    assert _errors(_spider("octopod", 6)) == ["locomotion.type: octopod needs 8 leg parts, the spec has 6"]


@pytest.mark.parametrize("kind", ["octopod", "walker"])
def test_walkers_take_the_walking_fields_only(kind: str) -> None:
    document = _spider(kind)
    document["locomotion"]["hopHeight"] = 0.2
    del document["locomotion"]["stepHeight"]
    assert _errors(document) == [
        f"locomotion.stepHeight: required for type {kind}",
        f"locomotion.hopHeight: not used by type {kind}",
    ]


def test_a_walker_spider_compiles_to_the_octopods_motion_data_but_for_its_type() -> None:
    """What lets the JS parity test run the walker type on the octopod's package (tests/test_motion.py)."""
    octopod, walker = _motion(_spider("octopod")), _motion(_spider("walker"))
    assert walker.type == "walker"
    assert replace(walker, type="octopod") == octopod
    assert octopod.genes.fields == (("speed", "stepLength"), ("stepHeight",))
    assert octopod.rope_ground is True


@pytest.mark.parametrize("kind", ["octopod", "walker"])
def test_the_exported_schema_knows_the_walker_types(kind: str) -> None:
    schema = json.loads((REPO / "schemas" / "character-spec.schema.json").read_text())
    validator = jsonschema.validators.validator_for(schema)(schema)
    assert list(validator.iter_errors(_spider(kind))) == []
    document = _spider(kind)
    document["locomotion"]["hopHeight"] = 0.2
    assert list(validator.iter_errors(document)) != []
