"""The bounded correction: it pulls displaced vertices back to the field, within its trust radius, and
keeps the skinned position whenever a step cannot be trusted."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from conftest import EXAMPLES, rest_surface
from creaturegen.model import layout as col
from creaturegen.surface.correct import DEFAULT_BUDGET, correct, trust_radius
from creaturegen.surface.extract import Extraction
from creaturegen.surface.field64 import BodyField


@cache
def _surface(name: str) -> tuple[BodyField, Extraction, float, np.ndarray]:
    s = rest_surface(EXAMPLES / name, "distant")
    rig, field, ex = s.rig, s.field, s.extraction
    owner = np.argmin(field.slot_distances(ex.mesh.vertices), axis=0)
    radius = np.maximum(rig.slots[owner, col.RA], rig.slots[owner, col.RB])
    return field, ex, rig.body_scale, radius


def test_correction_reduces_the_residual_within_the_trust_radius() -> None:
    field, ex, _, radius = _surface("reference/biped.json")
    trust = trust_radius(ex.mesh, ex.normals, radius)
    rng = np.random.default_rng(7)
    offset = rng.uniform(-0.3, 0.3, ex.mesh.vertex_count) * trust
    skinned = ex.mesh.vertices + offset[:, None] * ex.normals
    region = np.ones(ex.mesh.vertex_count, dtype=bool)
    out, report = correct(field, ex.mesh, skinned, ex.normals, region, trust)
    assert report.residual_before > 0.1 * float(trust.min())
    assert report.residual_after <= report.residual_before
    assert report.residual_corrected < 0.01 * report.residual_before
    assert report.corrected > 0.95 * ex.mesh.vertex_count
    assert np.all(np.linalg.norm(out - skinned, axis=1) <= trust * (1 + 1e-9) * DEFAULT_BUDGET)
    assert report.trials <= DEFAULT_BUDGET * ex.mesh.vertex_count


def test_outside_the_region_nothing_moves() -> None:
    field, ex, _, radius = _surface("reference/biped.json")
    trust = trust_radius(ex.mesh, ex.normals, radius)
    skinned = ex.mesh.vertices + 0.2 * trust[:, None] * ex.normals
    region = np.zeros(ex.mesh.vertex_count, dtype=bool)
    region[::3] = True
    out, report = correct(field, ex.mesh, skinned, ex.normals, region, trust)
    assert np.array_equal(out[~region], skinned[~region])
    assert report.considered == int(region.sum())


def test_a_far_displacement_is_clamped_not_jumped() -> None:
    field, ex, _, radius = _surface("reference/biped.json")
    trust = trust_radius(ex.mesh, ex.normals, radius)
    skinned = ex.mesh.vertices + 5.0 * trust[:, None] * ex.normals
    region = np.ones(ex.mesh.vertex_count, dtype=bool)
    out, report = correct(field, ex.mesh, skinned, ex.normals, region, trust, budget=1)
    assert report.clamped > 0.9 * ex.mesh.vertex_count
    assert np.all(np.linalg.norm(out - skinned, axis=1) <= trust * (1 + 1e-9))


def test_converged_and_inverted_vertices_keep_the_skinned_position() -> None:
    field, ex, _, radius = _surface("reference/biped.json")
    trust = trust_radius(ex.mesh, ex.normals, radius)
    # Already on the surface: the residual early-out spends no trial and moves nothing.
    region = np.ones(ex.mesh.vertex_count, dtype=bool)
    out, report = correct(field, ex.mesh, ex.mesh.vertices.copy(), ex.normals, region, trust)
    assert report.trials == 0
    assert np.array_equal(out, ex.mesh.vertices)
    # Skinned normals that point inward make every accepted step fail the GPU's inversion proxy.
    skinned = ex.mesh.vertices + 0.2 * trust[:, None] * ex.normals
    out, report = correct(field, ex.mesh, skinned, -ex.normals, region, trust)
    assert report.corrected == 0
    assert report.rejected_inversion > 0
    assert np.array_equal(out, skinned)


@pytest.mark.parametrize("budget", [1, 2, 3])
def test_trials_never_exceed_the_shared_budget(budget: int) -> None:
    field, ex, _, radius = _surface("reference/biped.json")
    trust = trust_radius(ex.mesh, ex.normals, radius)
    rng = np.random.default_rng(3)
    skinned = ex.mesh.vertices + rng.uniform(-2, 2, (ex.mesh.vertex_count, 1)) * trust[:, None] * ex.normals
    region = np.ones(ex.mesh.vertex_count, dtype=bool)
    _, report = correct(field, ex.mesh, skinned, ex.normals, region, trust, budget=budget)
    assert report.trials <= budget * ex.mesh.vertex_count
    assert report.backtracks <= report.trials
