"""The baked frost structure maps: determinism, value ranges, flat and mirror-safe normals, seed and branches.

The maps are data shipped with every package, so these pin what the shader relies on (layout, ranges,
normals at the mirrored border) and what content-hash sharing relies on (same spec, same bytes).
"""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from creaturegen.frost.structure import StructureMaps, generate_structure, to_float
from creaturegen.spec.frost import Structure

#: One 8-bit step of the ``0.5 + 0.5·n`` encoding, in decoded units.
STEP = 2.0 / 255.0


def bake(**fields: object) -> StructureMaps:
    return generate_structure(Structure.model_validate({"resolution": 64, **fields}))


@pytest.fixture(scope="module")
def default_256() -> StructureMaps:
    return generate_structure(Structure(resolution=256))


def test_same_spec_bakes_the_same_bytes() -> None:
    first = bake(seed=11, resolution=128)
    second = bake(seed=11, resolution=128)
    np.testing.assert_array_equal(first.structure, second.structure)
    np.testing.assert_array_equal(first.normals, second.normals)
    assert first.sha256 == second.sha256


def test_another_seed_bakes_other_crystals() -> None:
    first = bake(seed=1, resolution=128)
    second = bake(seed=2, resolution=128)
    assert first.sha256 != second.sha256
    density_1 = to_float(first)[0][..., 0].ravel()
    density_2 = to_float(second)[0][..., 0].ravel()
    assert abs(np.corrcoef(density_1, density_2)[0, 1]) < 0.3


def test_sha256_is_the_digest_of_the_shipped_bytes(default_256: StructureMaps) -> None:
    expected = hashlib.sha256(default_256.structure.tobytes() + default_256.normals.tobytes()).hexdigest()
    assert default_256.sha256 == expected
    assert generate_structure(Structure(resolution=256)).sha256 == expected


@pytest.mark.parametrize("resolution", [64, 256])
def test_layout_and_ranges(resolution: int) -> None:
    maps = generate_structure(Structure.model_validate({"resolution": resolution, "seed": 3}))
    assert (maps.resolution, maps.seed) == (resolution, 3)
    for array in (maps.structure, maps.normals):
        assert array.shape == (resolution, resolution, 4)
        assert array.dtype == np.uint8
        assert not array.flags.writeable
    assert np.all(maps.structure[..., 3] == 255)

    structure, normals = to_float(maps)
    assert structure.dtype == normals.dtype == np.float32
    density = structure[..., 0]
    assert density.min() < 0.2
    assert density.max() > 0.8
    assert density.std() > 0.1
    assert structure.min() >= 0.0
    assert structure.max() <= 1.0
    assert normals.min() >= -1.0
    assert normals.max() <= 1.0


def test_thickness_is_smooth_next_to_the_crystals(default_256: StructureMaps) -> None:
    structure = to_float(default_256)[0]

    def roughness(channel: np.ndarray) -> float:
        return float(np.abs(np.diff(channel, axis=0)).mean() + np.abs(np.diff(channel, axis=1)).mean())

    assert roughness(structure[..., 1]) < 0.1 * roughness(structure[..., 0])
    assert structure[..., 1].std() > 0.1  # smooth, not constant


def test_normals_decode_within_the_unit_disc(default_256: StructureMaps) -> None:
    normals = to_float(default_256)[1]
    for xy in (normals[..., 0:2], normals[..., 2:4]):
        length = np.hypot(xy[..., 0], xy[..., 1])
        assert length.max() <= 1.0 + STEP
        assert length.max() > 0.2  # the relief is actually there


def test_zero_strength_bakes_flat_normals() -> None:
    maps = bake(normalStrength=0.0)
    assert np.all(maps.normals == 128)


def test_border_normals_meet_their_mirror_image(default_256: StructureMaps) -> None:
    """MirroredRepeatWrapping cannot flip a normal's sign, so the component across each border is ~0."""
    normals = to_float(default_256)[1]
    tolerance = STEP + 1e-6
    for channel in (0, 2):  # x across the left and right border columns
        assert np.abs(normals[:, [0, -1], channel]).max() <= tolerance
        assert np.abs(normals[:, 1:-1, channel]).max() > 0.1
    for channel in (1, 3):  # y across the bottom and top border rows
        assert np.abs(normals[[0, -1], :, channel]).max() <= tolerance
        assert np.abs(normals[1:-1, :, channel]).max() > 0.1


def test_more_branches_grow_more_frost() -> None:
    few = to_float(bake(branches=3, resolution=128))[0][..., 0]
    many = to_float(bake(branches=12, resolution=128))[0][..., 0]
    assert np.abs(few - many).mean() > 0.05
    assert many.mean() > few.mean()


def test_resolution_resamples_the_same_crystals() -> None:
    coarse = to_float(bake(resolution=128))[0]
    fine = to_float(bake(resolution=256))[0].reshape(128, 2, 128, 2, 4).mean(axis=(1, 3))
    assert np.corrcoef(coarse[..., 0].ravel(), fine[..., 0].ravel())[0, 1] > 0.6
    assert np.corrcoef(coarse[..., 1].ravel(), fine[..., 1].ravel())[0, 1] > 0.95


def test_crystals_narrower_than_four_texels_are_refused() -> None:
    with pytest.raises(ValueError, match="crystalScale"):
        bake(crystalScale=17.0)


def test_to_float_method_matches_the_function(default_256: StructureMaps) -> None:
    for method, function in zip(default_256.to_float(), to_float(default_256), strict=True):
        np.testing.assert_array_equal(method, function)
