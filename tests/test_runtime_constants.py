"""Constants of the runtime's own code live in the JS modules they describe, not in core/data.js.

The pose and deform layouts, the candidate codes, the LCG and the debug views are the same for every
creature and every build: each JS module exports its own (``export const NAME = value;``) and the Python
side keeps its twin for the reference and the plan's workload figures. These tests read the modules'
sources and pin every pair equal, show that a planted mismatch is caught, and check that CREATURE no longer
echoes any of them.
"""

from __future__ import annotations

import json
import re

import pytest

from creaturegen.creature.lod import HYSTERESIS, TIER_ORDER
from creaturegen.creature.plan import DEBUG_MODES, DEFORM_STRIDE
from creaturegen.creature.pose import POSE_ROWS
from creaturegen.creature.runtime import CreatureData
from creaturegen.lab.creature_shell import SHELL_CAP_RINGS, SHELL_RADIAL, SHELL_SNAP_STEPS, SHELL_TIERS
from creaturegen.model.lcg import LCG_A, LCG_C
from creaturegen.model.record import json_name
from creaturegen.resources import templates_dir
from creaturegen.surface.correction_region import NO_PROGRAM, SKIN_PROGRAM

#: (module of the package, exported name, the Python value it must equal).
PINNED: tuple[tuple[str, str, object], ...] = (
    ("core/pose.js", "POSE_ROWS", POSE_ROWS),
    ("core/lcg.js", "LCG_A", LCG_A),
    ("core/lcg.js", "LCG_C", LCG_C),
    ("tsl/deform.js", "DEFORM_STRIDE", DEFORM_STRIDE),
    ("tsl/body.js", "NO_PROGRAM", NO_PROGRAM),
    ("tsl/body.js", "SKIN_PROGRAM", SKIN_PROGRAM),
    ("tsl/material.js", "DEBUG_MODES", list(DEBUG_MODES)),
    ("core/lod.js", "TIER_ORDER", list(TIER_ORDER)),
    ("core/lod.js", "TIER_HYSTERESIS", HYSTERESIS),
    ("tsl/shell.js", "SHELL_TIERS", list(SHELL_TIERS)),
    ("tsl/shell.js", "SHELL_RADIAL", list(SHELL_RADIAL)),
    ("tsl/shell.js", "SHELL_CAP_RINGS", list(SHELL_CAP_RINGS)),
    ("tsl/shell.js", "SHELL_SNAP_STEPS", list(SHELL_SNAP_STEPS)),
)

#: CreatureData fields that were these constants: none may come back.
MOVED = ("pose_rows", "lcg", "no_program", "skin_program", "debug_modes", "deform_stride")


def js_constant(source: str, name: str) -> object:
    """The value of ``export const NAME = value;`` in ``source``: an integer or decimal literal, or a frozen
    array of string literals (``Object.freeze(['a', 'b'])``)."""
    found = re.findall(rf"^export const {name} = (.+);$", source, re.M)
    if len(found) != 1:
        raise AssertionError(f"{name}: {len(found)} `export const {name} = …;` lines")
    value = found[0]
    if re.fullmatch(r"-?\d+", value):
        return int(value)
    if re.fullmatch(r"-?\d+\.\d+", value):
        return float(value)
    frozen = re.fullmatch(r"Object\.freeze\((\[[^\]]*\])\)", value)
    if frozen is None:
        raise AssertionError(f"{name}: not a number or a frozen array of strings: {value}")
    return json.loads(frozen.group(1).replace("'", '"'))


def mismatches(sources: dict[str, str]) -> list[str]:
    """Every pinned constant whose JS value differs from its Python twin."""
    return [
        f"{path} {name} = {js_constant(sources[path], name)!r}, Python has {value!r}"
        for path, name, value in PINNED
        if js_constant(sources[path], name) != value
    ]


def _sources() -> dict[str, str]:
    root = templates_dir("creature")
    return {path: (root / path).read_text() for path, _, _ in PINNED}


def test_every_runtime_constant_is_the_python_one() -> None:
    assert mismatches(_sources()) == []


@pytest.mark.parametrize(("path", "name", "value"), PINNED)
def test_a_planted_mismatch_is_caught(path: str, name: str, value: object) -> None:
    sources = _sources()
    planted = "Object.freeze(['off'])" if isinstance(value, list) else repr(value + 1)
    line = re.compile(rf"^(export const {name} = ).+;$", re.M)
    sources[path], count = line.subn(rf"\g<1>{planted};", sources[path])
    assert count == 1
    assert [m.split(" = ")[0] for m in mismatches(sources)] == [f"{path} {name}"]


def test_a_missing_or_computed_constant_is_an_error() -> None:
    with pytest.raises(AssertionError, match="0 `export const"):
        js_constant("export const OTHER = 3;\n", "DEFORM_STRIDE")
    with pytest.raises(AssertionError, match="not a number"):
        js_constant("export const DEFORM_STRIDE = CREATURE.deformStride;\n", "DEFORM_STRIDE")


def test_creature_data_does_not_echo_the_runtime_constants() -> None:
    fields = set(CreatureData.__dataclass_fields__)
    assert not fields & set(MOVED)
    for path in {p for p, _, _ in PINNED}:
        source = (templates_dir("creature") / path).read_text()
        for name in MOVED:
            assert f"CREATURE.{json_name(name)}" not in source, (path, name)
            assert f"data.{json_name(name)}" not in source, (path, name)


def test_set_look_ranges_are_the_spec_ones() -> None:
    """tsl/material.js LOOK_RANGES (what setLook accepts) against the spec's Look model (what a spec may
    say): the same controls, bounds and open or closed lower ends."""
    from annotated_types import Ge, Gt, Le

    from creaturegen.spec.character import Look

    source = (templates_dir("creature") / "tsl/material.js").read_text()
    (body,) = re.findall(r"^export const LOOK_RANGES = Object\.freeze\(\{(.+)\}\);$", source, re.M)
    js = {
        name: (float(lo), float(hi), closed == "true")
        for name, lo, hi, closed in re.findall(r"(\w+): \[([\d.]+), ([\d.]+), (true|false)\]", body)
    }
    spec = {}
    for name, info in Look.model_fields.items():
        bounds = {type(m): m for m in info.metadata}
        low = bounds[Ge].ge if Ge in bounds else bounds[Gt].gt
        spec[name] = (float(low), float(bounds[Le].le), Ge in bounds)
    assert js == spec
    (integers,) = re.findall(r"^export const LOOK_INTEGERS = Object\.freeze\((\[.*\])\);$", source, re.M)
    whole = sorted(name for name, info in Look.model_fields.items() if info.annotation is int)
    assert sorted(json.loads(integers.replace("'", '"'))) == whole == ["aoTaps"]
