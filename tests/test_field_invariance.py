"""Renaming ids or permuting the parts array changes nothing; regrouping changes the topology.

Bit-identical means np.array_equal on float64 output, not a tolerance: the program order comes from
structure and geometry only (rig/graph.py), so the same floating-point operations run in the same order.
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from conftest import EXAMPLES
from creaturegen.field.primitives import primitive_field
from creaturegen.field.sampler import evaluate_ops, sample
from creaturegen.rig import CompiledRig, compile_rig
from creaturegen.rig.signatures import signatures
from creaturegen.spec import CharacterSpec, validate_bytes

CREATURES = [p for p in sorted(EXAMPLES.rglob("*.json")) if "frost" not in p.parts]
POINTS = 10_000


def _compile(data: dict[str, Any]) -> CompiledRig:
    spec = validate_bytes(json.dumps(data).encode())
    assert isinstance(spec, CharacterSpec)
    return compile_rig(spec)


def _points(rig: CompiledRig, count: int = POINTS, seed: int = 1) -> np.ndarray:
    """Points in the padded rest AABB: half uniform, half pulled toward slot surfaces."""
    rng = np.random.default_rng(seed)
    s = rig.slots
    lo = np.minimum(s[:, 0:3], s[:, 4:7]).min(axis=0) - 0.3 * rig.body_scale
    hi = np.maximum(s[:, 0:3], s[:, 4:7]).max(axis=0) + 0.3 * rig.body_scale
    uniform = rng.uniform(lo, hi, size=(count // 2, 3))
    slot = rng.integers(0, len(s), size=count - count // 2)
    t = rng.uniform(0, 1, size=(len(slot), 1))
    centre = s[slot, 0:3] * (1 - t) + s[slot, 4:7] * t
    direction = rng.normal(size=(len(slot), 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    radius = (s[slot, 3] * (1 - t[:, 0]) + s[slot, 7] * t[:, 0]) * rng.uniform(0.7, 1.3, size=len(slot))
    return np.vstack([uniform, centre + direction * radius[:, None]])


def _renamed(data: dict[str, Any]) -> dict[str, Any]:
    """Every part and node id replaced consistently by an unrelated one."""
    out = copy.deepcopy(data)

    def new(old: str) -> str:
        return "r" + hashlib.sha256(old.encode()).hexdigest()[:10]

    for part in out["parts"]:
        part["id"] = new(part["id"])
        if "parent" in part:
            part["parent"] = new(part["parent"])
    blend = out.get("blend")
    if blend:
        refs = list(blend["roots"])
        for node in blend.get("nodes", []) + blend.get("groups", []):
            node["id"] = new(node["id"])
            refs += node.get("members", []) + [node[k] for k in ("left", "right") if k in node]
        for ref in refs:
            for key in ("part", "node"):
                if key in ref:
                    ref[key] = new(ref[key])
    return out


def _shuffled(data: dict[str, Any], seed: int) -> dict[str, Any]:
    out = copy.deepcopy(data)
    order = np.random.default_rng(seed).permutation(len(out["parts"]))
    out["parts"] = [out["parts"][i] for i in order]
    return out


@pytest.mark.parametrize("path", CREATURES, ids=lambda p: p.name)
def test_rename_and_permute_are_bit_identical(path: Path) -> None:
    data = json.loads(path.read_text())
    base = _compile(data)
    other = _compile(_shuffled(_renamed(data), seed=7))
    points = _points(base)
    a, b = sample(base, points), sample(other, points)
    assert np.array_equal(a.distance, b.distance)
    assert np.array_equal(a.gradient, b.gradient)
    assert np.array_equal(a.color, b.color)
    sa, sb = signatures(base), signatures(other)
    assert (sa.topologySignature, sa.geometryDigest) == (sb.topologySignature, sb.geometryDigest)
    assert sa.compilerSignature == sb.compilerSignature


@pytest.mark.parametrize("path", CREATURES, ids=lambda p: p.name)
def test_name_and_colours_change_no_signature(path: Path) -> None:
    data = json.loads(path.read_text())
    changed = copy.deepcopy(data)
    changed["name"] = "Something Else Entirely"
    for part in changed["parts"]:
        part["color"] = "#123456"
    sa, sb = signatures(_compile(data)), signatures(_compile(changed))
    assert sa == sb


def test_regrouping_the_tree_changes_the_topology() -> None:
    data = json.loads((EXAMPLES / "lizard.json").read_text())
    regrouped = copy.deepcopy(data)
    nodes = {n["id"]: n for n in regrouped["blend"]["nodes"]}
    # ((body, tail), face) becomes ((body, face), tail): same parts, same widths, other grouping.
    nodes["trunk"]["right"] = {"node": "face"}
    nodes["torso"]["left"], nodes["torso"]["right"] = {"node": "trunk"}, {"part": "tail"}
    sa, sb = signatures(_compile(data)), signatures(_compile(regrouped))
    assert sa.topologySignature != sb.topologySignature
    assert sa.compilerSignature == sb.compilerSignature


def test_moving_a_part_changes_only_the_geometry_digest() -> None:
    data = json.loads((EXAMPLES / "lizard.json").read_text())
    moved = copy.deepcopy(data)
    moved["parts"][1]["offset"][1] += 0.01
    sa, sb = signatures(_compile(data)), signatures(_compile(moved))
    assert sa.topologySignature == sb.topologySignature
    assert sa.geometryDigest != sb.geometryDigest


def test_signatures_are_sha256_hex() -> None:
    sig = signatures(_compile(json.loads((EXAMPLES / "beetle.json").read_text())))
    for value in (sig.compilerSignature, sig.topologySignature, sig.geometryDigest):
        assert len(value) == 64
        int(value, 16)


@pytest.mark.parametrize("path", CREATURES, ids=lambda p: p.name)
def test_every_blend_node_stays_within_its_bound(path: Path) -> None:
    """poly: min − k/4 ≤ smin ≤ min; lse: min − k·log N ≤ smin ≤ min, at every point for every node."""
    rig = _compile(json.loads(path.read_text()))
    points = _points(rig, 4000, seed=3)
    d_slots, g_slots = primitive_field(rig.slots, points)
    checked = 0
    for op, value in zip(rig.graph.ops, evaluate_ops(rig.graph, d_slots, g_slots), strict=True):
        low = value.operands.min(axis=0)
        depth = op.k / 4 if op.kernel == "poly" else op.k * math.log(len(op.children))
        slack = 1e-12 * rig.body_scale
        assert (value.distance <= low + slack).all(), op.place
        assert (value.distance >= low - depth - slack).all(), op.place
        checked += 1
    assert checked == len(rig.graph.ops)
