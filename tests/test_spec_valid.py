"""Valid specs: the six reference specs unchanged, our examples, and what the gate hands on."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import EXAMPLES, SHARED_REFERENCE_SPECS
from creaturegen.spec import CharacterSpec, FrostEffectSpec, load_spec, slugify, validate_bytes

EXAMPLE_FILES = sorted(EXAMPLES.rglob("*.json"))
REFERENCE_NAMES = ["biped", "flyer", "hexapod", "hopper", "quadruped", "swimmer"]
#: Slots per the rig rules (capsule/cone/sphere 1, rope = segments, leg 2), counted by hand from the files.
REFERENCE_SLOTS = {"biped": 7, "flyer": 4, "hexapod": 16, "hopper": 7, "quadruped": 16, "swimmer": 12}


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: str(p.relative_to(EXAMPLES)))
def test_example_validates_and_names_its_schema(path: Path) -> None:
    spec = load_spec(path)
    schema_ref = json.loads(path.read_text())["$schema"]
    expected = "character-spec.schema.json" if isinstance(spec, CharacterSpec) else "frost-effect.schema.json"
    assert schema_ref.endswith("schemas/" + expected)
    assert (path.parent / schema_ref).resolve().is_file()


@pytest.mark.parametrize("name", REFERENCE_NAMES)
def test_reference_spec_validates_unchanged(name: str) -> None:
    source = SHARED_REFERENCE_SPECS / f"{name}.json"
    if not source.is_file():
        pytest.fail(f"{source} is missing: the conformance specs must sit beside the checkout (../shared)")
    spec = load_spec(source)
    assert isinstance(spec, CharacterSpec)
    assert spec.kind == "creature"
    assert spec.slot_count == REFERENCE_SLOTS[name]
    ours = json.loads((EXAMPLES / "reference" / f"{name}.json").read_text())
    ours.pop("$schema")
    assert ours == json.loads(source.read_text()), "examples/reference must equal the conformance spec"


def test_examples_cover_tree_nary_and_every_frost_tier() -> None:
    specs = [load_spec(p) for p in EXAMPLE_FILES]
    modes = {s.blend.mode for s in specs if isinstance(s, CharacterSpec) and s.blend is not None}
    tiers = {s.tier.name for s in specs if isinstance(s, FrostEffectSpec)}
    assert modes == {"tree", "symmetric-nary"}
    assert tiers == {"full", "balanced", "budgeted"}


def test_hostile_name_is_accepted_verbatim_and_slugged() -> None:
    name = 'A "b" \\c</script>'
    data = {"name": name, "parts": [{"id": "body", "shape": "sphere", "r": 0.2}]}
    spec = validate_bytes(json.dumps(data).encode())
    assert spec.name == name
    assert slugify(spec.name) == "a-b-c-script"


def test_kind_defaults_to_creature_and_defaults_are_applied() -> None:
    spec = validate_bytes(b'{"name": "Blob", "parts": [{"id": "b", "shape": "sphere", "r": 1}]}')
    assert isinstance(spec, CharacterSpec)
    assert (spec.kind, spec.maxParts, spec.scale, spec.seed, spec.blend, spec.locomotion) == (
        "creature",
        64,
        1.0,
        0,
        None,
        None,
    )


def test_minimal_frost_spec_is_complete() -> None:
    spec = validate_bytes(b'{"kind": "frost", "name": "Pane", "tier": {"name": "budgeted"}}')
    assert isinstance(spec, FrostEffectSpec)
    assert spec.tier.resolved_history_scale == 0.25
    assert spec.history.visible.survivalPerSecond == 0.75  # measured default (README, "The frost effect")
    assert spec.tier.historyFormat == "auto"  # the quantisation gate picks the format at build time


def test_byte_order_mark_is_tolerated() -> None:
    data = b'\xef\xbb\xbf{"name": "Bom", "parts": [{"id": "b", "shape": "sphere", "r": 1}]}'
    assert validate_bytes(data).name == "Bom"
