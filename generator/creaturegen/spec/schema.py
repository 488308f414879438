"""JSON Schemas exported from the pydantic models, for editors and for AI spec writers.

The checked-in copies under schemas/ are generated; a test fails when they drift from the models.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from .character import CharacterSpec
from .colors import COLOR_JSON_SCHEMA
from .frost import FrostEffectSpec

SCHEMA_FILES: dict[str, type[CharacterSpec] | type[FrostEffectSpec]] = {
    "character-spec.schema.json": CharacterSpec,
    "frost-effect.schema.json": FrostEffectSpec,
}


#: Where the colour's schema lives once: every part shape has a ``color``, and pydantic inlines an
#: annotated type at each use (the CSS names as an enum and as an any-case pattern, in each part shape).
COLOR_REF = "#/$defs/Color"


def _shared_colour(node: Any) -> tuple[Any, bool]:
    """``node`` with every inlined colour schema replaced by a reference to ``$defs/Color``; and whether
    any was."""
    if node == COLOR_JSON_SCHEMA:
        return {"$ref": COLOR_REF}, True
    if isinstance(node, dict):
        pairs = [(key, _shared_colour(value)) for key, value in node.items()]
        return {key: value for key, (value, _) in pairs}, any(found for _, (_, found) in pairs)
    if isinstance(node, list):
        items = [_shared_colour(value) for value in node]
        return [value for value, _ in items], any(found for _, found in items)
    return node, False


def schema_of(model: type[CharacterSpec] | type[FrostEffectSpec], filename: str) -> dict[str, Any]:
    schema, shared = _shared_colour(model.model_json_schema(by_alias=True, mode="validation"))
    if shared:
        schema.setdefault("$defs", {})["Color"] = COLOR_JSON_SCHEMA
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "$id": filename, **schema}


def render_schemas() -> dict[str, str]:
    """File name -> text, byte-stable (sorted keys, fixed indent, trailing newline)."""
    return {
        name: json.dumps(schema_of(model, name), indent=2, sort_keys=True, ensure_ascii=False) + "\n"
        for name, model in SCHEMA_FILES.items()
    }


def write_schemas(folder: Path) -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for name, text in render_schemas().items():
        path = folder / name
        path.write_text(text, encoding="utf-8")
        written.append(path)
    return written


def stale_schemas(folder: Path) -> list[str]:
    """Names of checked-in schema files that differ from what the models export now."""
    return [
        name
        for name, text in render_schemas().items()
        if not (folder / name).is_file() or (folder / name).read_text(encoding="utf-8") != text
    ]
