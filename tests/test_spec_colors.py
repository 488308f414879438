"""Colours: #rrggbb, #rgb and the CSS named colours are accepted and normalised to #rrggbb at the gate."""

from __future__ import annotations

import json
import re
from typing import Any

import jsonschema
import numpy as np
import pytest

from conftest import EXAMPLES, REPO, missing_setup
from creaturegen.rig import compile_rig
from creaturegen.spec import CharacterSpec, FrostEffectSpec, SpecValidationError, validate_bytes
from creaturegen.spec.colors import CSS_NAMED_COLORS

THREE_COLOR_JS = (
    REPO / "generator" / "creaturegen" / "web_lab" / "node_modules" / "three" / "src" / "math" / "Color.js"
)


def _creature(color: object) -> dict[str, Any]:
    return {"name": "Dot", "parts": [{"id": "body", "shape": "sphere", "r": 0.2, "color": color}]}


def _color_of(color: object) -> str | None:
    spec = validate_bytes(json.dumps(_creature(color)).encode())
    assert isinstance(spec, CharacterSpec)
    return spec.parts[0].color


def _errors(color: object) -> list[str]:
    with pytest.raises(SpecValidationError) as caught:
        validate_bytes(json.dumps(_creature(color)).encode())
    return [str(e) for e in caught.value.errors]


def test_the_148_css_level_4_names_with_both_grey_spellings() -> None:
    assert len(CSS_NAMED_COLORS) == 148
    assert CSS_NAMED_COLORS["gray"] == CSS_NAMED_COLORS["grey"] == "#808080"
    assert CSS_NAMED_COLORS["rebeccapurple"] == "#663399"
    assert all(re.fullmatch(r"#[0-9a-f]{6}", v) for v in CSS_NAMED_COLORS.values())


def test_the_names_mean_what_three_js_means() -> None:
    """Same table as three's Color.NAMES, so a name is the same colour in the lab and in a user's scene."""
    if not THREE_COLOR_JS.is_file():
        missing_setup("web_lab/node_modules is not installed")
    block = re.search(r"_colorKeywords = \{(.*?)\};", THREE_COLOR_JS.read_text(), re.S)
    assert block is not None
    three = {
        name: "#" + hex6.lower() for name, hex6 in re.findall(r"'([a-z]+)': 0x([0-9A-Fa-f]{6})", block[1])
    }
    assert three == CSS_NAMED_COLORS


@pytest.mark.parametrize(
    ("written", "normalised"),
    [
        ("#7f9bd6", "#7f9bd6"),
        ("#7F9BD6", "#7F9BD6"),  # six digits stay exactly as written: existing builds are byte-identical
        ("#abc", "#aabbcc"),
        ("#F0a", "#FF00aa"),
        ("crimson", "#dc143c"),
        ("Crimson", "#dc143c"),
        ("DARKSLATEGREY", "#2f4f4f"),
        ("gray", "#808080"),
        ("grey", "#808080"),
    ],
)
def test_colours_are_normalised_to_rrggbb(written: str, normalised: str) -> None:
    assert _color_of(written) == normalised


@pytest.mark.parametrize(
    ("written", "message"),
    [
        ("#12345", 'part.body.color: must be a #rrggbb or #rgb colour (got "#12345")'),
        ("#ggg", 'part.body.color: must be a #rrggbb or #rgb colour (got "#ggg")'),
        (
            "blu",
            'part.body.color: must be a #rrggbb or #rgb colour or a CSS colour name (got "blu"); '
            "did you mean 'blue'?",
        ),
        (
            "LightGoldenRodYelow",
            "part.body.color: must be a #rrggbb or #rgb colour or a CSS colour name "
            "(got \"LightGoldenRodYelow\"); did you mean 'lightgoldenrodyellow'?",
        ),
        (
            "transparent",
            'part.body.color: must be a #rrggbb or #rgb colour or a CSS colour name (got "transparent")',
        ),
        ("", 'part.body.color: must be a #rrggbb or #rgb colour or a CSS colour name (got "")'),
        (255, "part.body.color: must be a string (got 255)"),
    ],
)
def test_bad_colours_name_their_place(written: object, message: str) -> None:
    assert _errors(written) == [message]


def test_frost_tint_takes_the_same_colours() -> None:
    spec = validate_bytes(b'{"kind": "frost", "name": "Pane", "composite": {"tint": "AliceBlue"}}')
    assert isinstance(spec, FrostEffectSpec)
    assert spec.composite.tint == "#f0f8ff"


def test_named_and_hex_colours_compile_to_the_same_rig() -> None:
    """Downstream sees only #rrggbb: a spec written with names compiles to exactly the hex spec's rig."""
    data = json.loads((EXAMPLES / "reference" / "biped.json").read_text())
    named = json.loads(json.dumps(data))
    for part in named["parts"]:
        part["color"] = "peru"
    hexed = json.loads(json.dumps(data))
    for part in hexed["parts"]:
        part["color"] = "#cd853f"
    rigs = []
    for doc in (named, hexed):
        spec = validate_bytes(json.dumps(doc).encode())
        assert isinstance(spec, CharacterSpec)
        rigs.append(compile_rig(spec))
    assert np.array_equal(rigs[0].slots, rigs[1].slots)


def _schema_validator() -> jsonschema.protocols.Validator:
    schema = json.loads((REPO / "schemas" / "character-spec.schema.json").read_text())
    return jsonschema.validators.validator_for(schema)(schema)


@pytest.mark.parametrize("color", ["#abc", "#aabbcc", "Crimson", "rebeccapurple", "GREY"])
def test_schema_accepts_what_the_gate_accepts(color: str) -> None:
    assert list(_schema_validator().iter_errors(_creature(color))) == []


@pytest.mark.parametrize("color", ["#12345", "blu", "transparent", "crimson "])
def test_schema_rejects_what_the_gate_rejects(color: str) -> None:
    assert list(_schema_validator().iter_errors(_creature(color))) != []


def test_examples_keep_their_colour_strings() -> None:
    """Every example's colours already are #rrggbb and reach the model unchanged."""
    for path in sorted(EXAMPLES.rglob("*.json")):
        raw = json.loads(path.read_text())
        spec = validate_bytes(path.read_bytes())
        if isinstance(spec, CharacterSpec):
            assert [p.get("color") for p in raw["parts"]] == [p.color for p in spec.parts]
