"""The size gene is a similarity of the certified body: measured on built packages with the reference code
paths (pose rows, skinning, the posed field), so spawning a larger or smaller individual needs no new mesh.

If any part of the path missed the size (a blend width, a radius, a centre of rotation, the colour
kernel's floor), the field at the scaled vertices would not be the scaled field and these fail. The GPU
applies the same size (tsl/body.js); the creature parity job compares its skinning, correction and field
for the lab's instance 0, whose seed draws a size other than 1 (checked below).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from conftest import build_example
from creaturegen.creature import reference as cref
from creaturegen.creature.pose import as_pose, pose_rows
from creaturegen.lab.creature_lab import LAB_SEED, PARITY_TICK
from creaturegen.model.genome import draw_genome
from creaturegen.model.rotations import Pose
from creaturegen.motion.express import individual_size
from creaturegen.motion.providers import AnalyticWater
from creaturegen.motion.simulate import Motion

#: float64 agreement of the scaled body with the unit body scaled, relative to the body's length.
SIMILAR = 1e-12


@pytest.fixture(params=["reference/hopper.json", "reference/quadruped.json"])
def package(request: pytest.FixtureRequest, creature_out: Path) -> Path:
    return build_example(str(request.param), creature_out)


def _triangle_normals(points: np.ndarray, faces: np.ndarray) -> np.ndarray:
    a, b, c = (points[faces[:, i]] for i in range(3))
    result: np.ndarray = np.cross(b - a, c - a)
    return result


def test_an_individual_of_any_size_is_the_certified_body_scaled(package: Path) -> None:
    ref = cref.load_reference(package)
    scale = ref.rig.body_scale
    genes = ref.motion.genes.size
    assert genes > 0.0
    # The unit body's pose at the parity tick (size gene 0), and the pose of the same body at size s.
    unit = Motion(
        ref.motion, water=AnalyticWater(), seed=LAB_SEED, genome=dataclasses.replace(draw_genome(1), size=0.0)
    )
    unit.step_ticks(PARITY_TICK)
    assert unit.size == 1.0
    unit_pose = as_pose(unit.quats, unit.trans)
    unit_table = cref.posed_table(ref, unit_pose)
    unit_skin = cref.skinned_reference(ref, unit_pose)
    unit_field = cref.field_at(ref, unit_table, unit_skin)
    faces = np.asarray(ref.asset.indices, dtype=np.int64).reshape(-1, 3)
    unit_normals = _triangle_normals(unit_skin, faces)
    for size in (1.0 - genes, 1.0 + genes):
        pose = Pose(unit_pose.rotations, unit_pose.translations * size)
        table = cref.posed_table(ref, pose, size)
        skin = cref.skinned_reference(ref, pose, size)
        where = f"{package.name} size {size}"
        assert np.abs(skin - size * unit_skin).max() <= SIMILAR * scale, f"{where}: skinning is not similar"
        field = cref.field_at(ref, table, skin, size)
        # Surface error relative to the individual's own length: the certified body's, exactly.
        error = np.abs(field.distance / size - unit_field.distance).max()
        assert error <= SIMILAR * scale, f"{where}: surface error differs by {error / scale:.3g} L"
        assert np.allclose(field.color, unit_field.color, rtol=0.0, atol=1e-12), f"{where}: colour differs"
        assert np.abs(field.gradient - unit_field.gradient).max() <= SIMILAR, f"{where}: normals differ"
        # Signed Jacobians keep their sign: every triangle faces the way it faced on the unit body.
        normals = _triangle_normals(skin, faces)
        flipped = int(np.count_nonzero((normals * unit_normals).sum(axis=1) <= 0.0))
        assert flipped == 0, f"{where}: {flipped} triangles turned over"
        # The pose rows hold exactly the scaled table (ends, radii and blend widths).
        rows = pose_rows(ref.rig, unit.quats, pose.translations.tolist(), None, size)
        assert np.allclose(rows[:, 0, :3], table[:, 0:3], atol=1e-6 * scale)
        assert np.allclose(rows[:, 0, 3], table[:, 3], atol=1e-6 * scale)
        assert np.allclose(rows[:, 2, 0], table[:, 8], atol=1e-6 * scale)


def test_the_lab_instance_draws_a_size_other_than_one(package: Path) -> None:
    """The parity job's skin, correction and field gates run on instance 0 (LAB_SEED): a size of exactly 1
    there would leave the GPU's size path unchecked."""
    ref = cref.load_reference(package)
    size = individual_size(ref.motion, draw_genome(LAB_SEED))
    assert abs(size - 1.0) > 0.01
    assert cref.instance_motion(ref, LAB_SEED, 0, (0.0, 0.0, 0.0)).size == size
