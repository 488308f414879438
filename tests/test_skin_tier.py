"""The skin representation of the lower tiers (surface/skin_tier.py): baked colour weights, which vertices
evaluate the field, and the contract the build reports; each property is checked against an independent
computation or a planted defect."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from conftest import EXAMPLES
from creaturegen.candidates import TIERS
from creaturegen.candidates.regions import SkinTolerance
from creaturegen.creature.plan import _projected_size_max_px
from creaturegen.field.floors import floors_for
from creaturegen.field.sampler import sample_graph
from creaturegen.model import layout as col
from creaturegen.model.graph import BlendGraph, Ref
from creaturegen.motion.compiled import compile_creature
from creaturegen.rig import CompiledRig, compile_rig
from creaturegen.spec import CharacterSpec, load_spec
from creaturegen.surface.asset import SurfaceAsset
from creaturegen.surface.build import SurfaceBuild, build_surface
from creaturegen.surface.correction_region import SKIN_PROGRAM
from creaturegen.surface.glb import glb_bytes, parse_glb
from creaturegen.surface.mesh_gates import mesh_limits
from creaturegen.surface.sidecar import gate_from_row, gate_rows
from creaturegen.surface.skin_tier import (
    MAX_REPORTED_PX,
    SUBPIXEL_PX,
    Departures,
    baked_colour,
    baked_rgb,
    field_vertices,
    skin_contract,
)

#: One slot on its own: its plain distance, for an independent count of the leaves that tint a point.
LEAF = BlendGraph((), (Ref("slot", 0),))


@cache
def _compiled(name: str) -> tuple[CharacterSpec, CompiledRig]:
    spec = load_spec(EXAMPLES / name)
    assert isinstance(spec, CharacterSpec)
    return spec, compile_rig(spec)


@cache
def _built(name: str, tier: str) -> SurfaceBuild:
    spec, _rig = _compiled(name)
    return build_surface(compile_creature(spec), tier=tier, backend="numpy", progress=lambda _: None)


def test_baked_colour_is_the_kernel_truncated_to_four_leaves() -> None:
    """Where at most four leaves tint a point, the baked colour is the field's colour; elsewhere it departs
    by exactly the reported truncation, measured here from the field's own sampler."""
    _, rig = _compiled("reference/quadruped.json")
    k_floor = floors_for(rig.body_scale).k_floor
    points = np.random.default_rng(3).uniform(
        rig.slots[:, col.A].min(0), rig.slots[:, col.A].max(0), (4000, 3)
    )
    baked = baked_colour(rig, points, k_floor)
    assert baked.slots.shape == baked.weights.shape == (4000, 4)
    assert np.all(baked.weights >= 0)
    np.testing.assert_allclose(baked.weights.sum(axis=1), 1.0, atol=1e-6)
    assert int(baked.slots.max()) < rig.slot_count
    full = sample_graph(rig.graph, rig.slots, points, k_floor).color
    mine = baked_rgb(baked.slots, baked.weights, rig.slots[:, col.RGB])
    error = np.abs(mine - full).max(axis=1)
    assert float(error.max()) == pytest.approx(baked.truncation, rel=1e-5)
    assert 0.0 < baked.truncation < 0.5  # the quadruped has more than four colours within reach
    d = np.stack(
        [sample_graph(LEAF, rig.slots[[j]], points, k_floor).distance for j in range(rig.slot_count)]
    )
    width = np.maximum(rig.slots[:, col.K], k_floor)[:, None]
    w = np.exp(-(d - d.min(axis=0)) / width)  # (S, P), the kernel's weights from plain leaf distances
    left_out = np.sort(w, axis=0)[:-4].sum(axis=0) / w.sum(axis=0)
    spread = float(np.ptp(rig.slots[:, col.RGB], axis=0).max())
    # Dropping weight share ω and renormalising moves a colour by at most 2·ω·spread.
    assert np.all(error <= 2.0 * left_out * spread + 1e-12)
    assert float(error[left_out < 1e-9].max(initial=0.0)) < 1e-8


def _departures(error: list[float], angle: list[float], delta_e: list[float]) -> Departures:
    return Departures(1, np.array(error), np.array(angle), np.array(delta_e))


def test_a_departure_equal_to_its_tolerance_stays_skin() -> None:
    tol = SkinTolerance(10.0, 0.02)
    dep = _departures([0.5, 0.5, 0.5, 0.51, 0.0], [10.0, 10.01, 0.0, 0.0, 0.0], [0.02, 0.0, 0.0201, 0.0, 0.0])
    assert field_vertices(dep, 0.5, tol).tolist() == [False, True, True, True, False]


def test_the_contract_is_measured_over_skin_vertices_only() -> None:
    _, rig = _compiled("reference/hopper.json")
    colour = baked_colour(rig, rig.slots[:5, col.A], floors_for(rig.body_scale).k_floor)
    dep = _departures([0.001, 0.05, 0.0, 0.002, 0.0], [1.0, 80.0, 2.0, 3.0, 0.0], [0.0, 0.5, 0.01, 0.0, 0.0])
    field = np.array([False, True, False, False, False])
    owner = np.arange(5, dtype=np.int32)
    contract = skin_contract(dep, field, owner, rig, colour)
    assert contract.field_vertices == 1
    assert contract.error == 0.002  # the field vertex's 0.05 is not the skin's
    assert contract.worst_part == f"part.{rig.slot_parts[3]}"
    assert contract.projected_px == pytest.approx(SUBPIXEL_PX * rig.body_scale / 0.002)
    assert contract.normal_deg[2] == 3.0
    assert contract.delta_e[2] == 0.01
    rigid = skin_contract(_departures([0.0] * 5, [0.0] * 5, [0.0] * 5), field, owner, rig, colour)
    assert rigid.projected_px == MAX_REPORTED_PX


def test_a_lower_tier_build_evaluates_the_field_only_where_the_skin_departs() -> None:
    built = _built("reference/hopper.json", "distant")
    asset = built.asset
    program = np.asarray(asset.candidate)
    trust = np.asarray(asset.skin)[:, 1]
    in_field = program == 0
    assert set(np.unique(program).tolist()) == {0, SKIN_PROGRAM}
    skin = built.sidecar["skinRepresentation"]
    assert isinstance(skin, dict)
    assert skin["fieldVertices"] == int(in_field.sum())
    assert 0 < in_field.sum() < 0.5 * asset.vertex_count
    # Every corrected vertex evaluates the field; no skin vertex is corrected.
    assert np.all(in_field[trust > 0])
    assert np.all(trust[~in_field] == 0)
    tol = TIERS["distant"].skin
    assert tol is not None
    assert skin["normalAngleDeg"]["max"] <= tol.normal_deg
    assert skin["deltaEOklab"]["max"] <= tol.delta_e
    # The hero tier keeps the field everywhere and ships no baked colour.
    hero = _built("reference/hopper.json", "hero").asset
    assert hero.colour_slots is None
    assert int(np.asarray(hero.candidate).max()) < SKIN_PROGRAM


def test_a_distant_body_draws_a_mesh_of_its_own_fidelity() -> None:
    """The distant tier's mesh is judged at the distant tier's limits (surface/mesh_gates.py mesh_limits),
    so it stays on a coarser lattice than the hero's (it refined to the hero's 6,458 vertices before), and
    the sidecar says up to which size on screen it stays subpixel."""
    distant, hero = _built("reference/hopper.json", "distant"), _built("reference/hopper.json", "hero")
    assert distant.asset.vertex_count < 0.35 * hero.asset.vertex_count
    limits = mesh_limits("distant")
    gates = {g.name: g for g in map(gate_from_row, gate_rows(distant.sidecar))}
    assert all(g.passed for g in gates.values()), [g for g in gates.values() if not g.passed]
    for name in ("surfaceToZeroSet", "zeroSetToMesh"):
        assert gates[name].threshold == limits.distance
    assert gates["vertexNormalAngleP99"].threshold == limits.normals[1]
    error = distant.sidecar["surfaceError"]
    assert isinstance(error, dict)
    worst = max(gates[n].value for n in ("surfaceToZeroSet", "zeroSetToMesh"))
    assert error["distanceMax"] == worst
    assert error["projectedSizeMaxPx"] == pytest.approx(SUBPIXEL_PX / worst)
    hero_error = hero.sidecar["surfaceError"]
    assert isinstance(hero_error, dict)
    assert hero_error["projectedSizeMaxPx"] > error["projectedSizeMaxPx"]
    # CREATURE.projectedSizeMaxPx: the smaller of the mesh's and the skin's subpixel sizes.
    skin = distant.sidecar["skinRepresentation"]
    assert isinstance(skin, dict)
    shipped = _projected_size_max_px(distant.sidecar)
    assert shipped == min(error["projectedSizeMaxPx"], skin["projectedSizeMaxPx"])
    assert _projected_size_max_px(hero.sidecar) == hero_error["projectedSizeMaxPx"] > shipped


def test_the_baked_colour_survives_the_glb() -> None:
    asset = _built("reference/hopper.json", "distant").asset
    assert asset.colour_slots is not None
    assert asset.colour_weights is not None
    again = parse_glb(glb_bytes(asset, name="hopper"))
    assert again == asset
    assert again.colour_weights is not None
    np.testing.assert_array_equal(again.colour_weights, asset.colour_weights)


def test_colour_weights_come_in_pairs_and_sum_to_one() -> None:
    asset = _built("reference/hopper.json", "distant").asset
    fields = {name: getattr(asset, name) for name in SurfaceAsset.__dataclass_fields__}
    with pytest.raises(ValueError, match="both or neither"):
        SurfaceAsset(**{**fields, "colour_weights": None})
    bad = np.array(asset.colour_weights)
    bad[0] = (0.5, 0.5, 0.5, 0.0)
    with pytest.raises(ValueError, match="colour_weights: must be non-negative and sum to 1"):
        SurfaceAsset(**{**fields, "colour_weights": bad})
