"""The checked-in JSON Schemas are exports of the models, and they agree with the gate on the examples."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

from conftest import EXAMPLES, REPO
from creaturegen.spec.schema import render_schemas, stale_schemas

SCHEMAS = REPO / "schemas"
INVALID = Path(__file__).parent / "fixtures" / "invalid"


def test_checked_in_schemas_are_fresh() -> None:
    assert stale_schemas(SCHEMAS) == [], "run `make schemas` and commit the result"


def test_export_is_byte_stable() -> None:
    assert render_schemas() == render_schemas()


def _validator(path: Path) -> jsonschema.protocols.Validator:
    schema = json.loads(path.read_text())
    cls = jsonschema.validators.validator_for(schema)
    cls.check_schema(schema)
    return cls(schema)


@pytest.mark.parametrize("path", sorted(EXAMPLES.rglob("*.json")), ids=lambda p: p.name)
def test_examples_conform_to_the_exported_schema(path: Path) -> None:
    data = json.loads(path.read_text())
    schema_file = (path.parent / data["$schema"]).resolve()
    errors = list(_validator(schema_file).iter_errors(data))
    assert errors == []


@pytest.mark.parametrize(
    "name",
    [
        "cone-missing-r2",
        "field-not-used-by-shape",
        "unknown-field",
        "bad-colour",
        "locomotion-field-not-used",
        "locomotion-null-field",
    ],
)
def test_exported_schema_rejects_what_the_gate_rejects(name: str) -> None:
    """Editors using the schema see per-shape and per-type rules too, not only field types."""
    data = json.loads((INVALID / f"{name}.json").read_text())
    assert list(_validator(SCHEMAS / "character-spec.schema.json").iter_errors(data)) != []


def test_the_colour_schema_is_defined_once_and_referenced_by_every_part_shape() -> None:
    """Every part shape has a colour; its schema (the CSS names as an enum and as an any-case pattern)
    lives in $defs once."""
    schema = json.loads(render_schemas()["character-spec.schema.json"])
    text = json.dumps(schema)
    assert text.count('"aliceblue"') == 1
    shapes = [name for name in schema["$defs"] if name.endswith("Part")]
    assert len(shapes) == 5
    for name in shapes:
        colour = schema["$defs"][name]["properties"]["color"]
        assert {"$ref": "#/$defs/Color"} in colour["anyOf"], name
