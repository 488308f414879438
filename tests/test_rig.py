"""Rig compile: rest layout rules, scale, default k, colours, canonical order and compile errors."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from conftest import EXAMPLES
from creaturegen.model import layout as col
from creaturegen.rig import RigCompileError, compile_rig
from creaturegen.rig.colour import srgb_channel_to_linear
from creaturegen.spec import CharacterSpec, load_spec, validate_bytes

CREATURES = [p for p in sorted(EXAMPLES.rglob("*.json")) if "frost" not in p.parts]


def _spec(data: dict[str, Any]) -> CharacterSpec:
    spec = validate_bytes(json.dumps(data).encode())
    assert isinstance(spec, CharacterSpec)
    return spec


def _raw(name: str) -> dict[str, Any]:
    data: dict[str, Any] = json.loads((EXAMPLES / name).read_text())
    return data


def _rows(rig: Any, part: str) -> np.ndarray:
    return rig.slots[[i for i, p in enumerate(rig.slot_parts) if p == part]]


@pytest.mark.parametrize("path", CREATURES, ids=lambda p: p.name)
def test_every_example_compiles_to_its_slot_count(path: Path) -> None:
    spec = load_spec(path)
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    assert rig.slot_count == spec.slot_count
    assert rig.slots.shape == (spec.slot_count, col.WIDTH)
    assert np.isfinite(rig.slots).all()
    used = [c for op in rig.graph.ops for c in op.children] + list(rig.graph.roots)
    every = [("slot", i) for i in range(rig.slot_count)] + [("op", i) for i in range(len(rig.graph.ops))]
    assert sorted((r.kind, r.index) for r in used) == sorted(every)  # a forest: each used exactly once
    assert all(c.index < i for i, op in enumerate(rig.graph.ops) for c in op.children if c.kind == "op")


def test_child_coordinates_accumulate_parent_anchors() -> None:
    rig = compile_rig(_spec(_raw("reference/biped.json")))
    head = _rows(rig, "head")[0]
    neck = _rows(rig, "neck")[0]
    # body.a = (0, 0.34, 0) is the anchor; head offset (0, 0.96, 0.03);
    # neck a (0, 0.74, 0), b (0, 0.96, 0.02).
    np.testing.assert_allclose(head[col.A], [0, 1.30, 0.03], atol=1e-15)
    np.testing.assert_allclose(neck[col.A], [0, 1.08, 0], atol=1e-15)
    np.testing.assert_allclose(neck[col.B], [0, 1.30, 0.02], atol=1e-15)


def test_leg_rest_layout_has_exact_bone_lengths_and_planted_foot() -> None:
    spec = _spec(_raw("reference/biped.json"))
    rig = compile_rig(spec)
    upper, lower = _rows(rig, "leg-left")
    assert math.isclose(float(np.linalg.norm(upper[col.B] - upper[col.A])), 0.45, rel_tol=1e-14)
    assert math.isclose(float(np.linalg.norm(lower[col.B] - lower[col.A])), 0.46, rel_tol=1e-14)
    assert abs(lower[col.B][1]) < 1e-15  # hip at y = 0.56 is within 0.95 reach: the foot rests on y = 0
    assert upper[col.B][2] > upper[col.A][2]  # the knee bends forward (+Z)


def test_rope_rest_layout_trails_backward_and_tapers() -> None:
    rig = compile_rig(_spec(_raw("reference/quadruped.json")))
    tail = _rows(rig, "tail")
    assert len(tail) == 6
    lengths = np.linalg.norm(tail[:, col.B] - tail[:, col.A], axis=1)
    np.testing.assert_allclose(lengths, 0.92 / 6, rtol=1e-12)
    assert (np.diff(tail[:, col.A][:, 2]) < 0).all()
    np.testing.assert_allclose(tail[0, col.RA], 0.055)
    np.testing.assert_allclose(tail[-1, col.RB], 0.055 * 0.55, rtol=1e-14)


def test_scale_multiplies_every_length_radius_and_k() -> None:
    data = _raw("lizard.json")
    base = compile_rig(_spec(data))
    data["scale"] = 2.0
    doubled = compile_rig(_spec(data))
    np.testing.assert_array_equal(doubled.slots[:, : col.K + 1], 2.0 * base.slots[:, : col.K + 1])
    np.testing.assert_array_equal(doubled.slots[:, col.RGB], base.slots[:, col.RGB])
    assert [op.k for op in doubled.graph.ops] == [2.0 * op.k for op in base.graph.ops]


def test_default_k_is_0_6_r_capped_by_kcap() -> None:
    rig = compile_rig(_spec(_raw("reference/hexapod.json")))
    assert _rows(rig, "antenna-left")[0, col.K] == 0.001
    assert _rows(rig, "head")[0, col.K] == pytest.approx(0.6 * 0.135, rel=1e-15)


def test_colours_are_decoded_from_srgb_exactly_once() -> None:
    rig = compile_rig(_spec(_raw("reference/biped.json")))
    body = _rows(rig, "body")[0]
    expected = [srgb_channel_to_linear(int(h, 16) / 255) for h in ("7f", "9b", "d6")]
    assert body[col.RGB].tolist() == expected
    assert 0.2 < expected[0] < 0.22  # 0x7f is 0.498 in sRGB and about 0.212 linear


def test_default_colour_applies_to_parts_without_one() -> None:
    data = {"name": "Plain", "parts": [{"id": "b", "shape": "sphere", "r": 1}]}
    rig = compile_rig(_spec(data))
    assert rig.slots[0, col.RGB].tolist() == [srgb_channel_to_linear(0x9A / 255)] * 3


def _blob(**node: Any) -> dict[str, Any]:
    return {
        "name": "Blob",
        "parts": [
            {"id": "x", "shape": "sphere", "r": 0.2},
            {"id": "y", "shape": "sphere", "r": 0.2, "offset": [0.3, 0, 0]},
        ],
        "blend": {
            "mode": "tree",
            "roots": [{"node": "n"}],
            "nodes": [{"id": "n", "left": {"part": "x"}, "right": {"part": "y"}, "k": 0.1, **node}],
        },
    }


def test_k_that_overflows_when_scaled_is_named() -> None:
    data = _blob(k=1e306)
    data["scale"] = 1000
    with pytest.raises(RigCompileError) as caught:
        compile_rig(_spec(data))
    assert [str(e) for e in caught.value.errors] == [
        "blend.nodes.n.k: blend width inf is not a positive finite number once scaled"
    ]


def test_k_that_swallows_the_body_is_named() -> None:
    with pytest.raises(RigCompileError) as caught:
        compile_rig(_spec(_blob(k=5.0)))
    assert [str(e) for e in caught.value.errors] == [
        "blend.nodes.n.k: blend width 5 m exceeds 4x the body size (0.7 m)"
    ]


def test_nested_cone_ends_are_named() -> None:
    data = {
        "name": "Nest",
        "parts": [{"id": "c", "shape": "cone", "a": [0, 0, 0], "b": [0, 0.1, 0], "r": 0.3, "r2": 0.1}],
    }
    with pytest.raises(RigCompileError) as caught:
        compile_rig(_spec(data))
    assert [str(e) for e in caught.value.errors] == [
        "part.c.r2: the end spheres nest (|ra - rb| = 0.2 >= length 0.1); use a sphere or a longer segment"
    ]
