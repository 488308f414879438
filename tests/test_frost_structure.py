"""The baked frost structure maps: determinism, value ranges, flat and mirror-safe normals, seed and branches;
the shipped structure file: lossless round trip, filters chosen by size, refusal of a foreign file.

The maps are data shipped with every package, so these pin what the shader relies on (layout, ranges,
normals at the mirrored border) and what content-hash sharing relies on (same spec, same bytes).
"""

from __future__ import annotations

import hashlib
import zlib

import numpy as np
import pytest

from creaturegen.frost.structure import (
    NormalScale,
    StructureMaps,
    derive_normals,
    generate_structure,
    normal_scales,
    to_float,
)
from creaturegen.frost.structure_file import (
    CHOICE_LEVEL,
    FILTERS,
    PLANES,
    decode_structure_file,
    encode_structure,
    filter_plane,
    unfilter_plane,
)
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
    assert maps.detail.shape == (resolution, resolution)
    assert maps.detail.dtype == np.uint8
    assert not maps.detail.flags.writeable
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


def test_normals_are_derived_from_the_8bit_heights(default_256: StructureMaps) -> None:
    """The normal map is a function of what the package ships (H in structure B, the detail height D)."""
    derived = derive_normals(
        default_256.structure[..., 2], default_256.detail, default_256.main, default_256.fine
    )
    np.testing.assert_array_equal(derived, default_256.normals)
    flat = derive_normals(
        default_256.structure[..., 2], default_256.detail, NormalScale(1, 0.0), NormalScale(1, 0.0)
    )
    assert np.all(flat == 128)


def test_normal_derivation_is_the_documented_formula() -> None:
    """One texel by hand: central difference over the spacing, normalise, encode 0.5 + 0.5·n, round
    half up."""
    height = np.zeros((8, 8), dtype=np.uint8)
    height[3, 5] = 200  # row 3 (v), column 5 (u)
    how = NormalScale(spacing=1, scale=0.01)
    normals = derive_normals(height, height, how, how)

    def code(nx: float) -> float:
        return float(np.floor((0.5 + 0.5 * (nx * (1.0 / np.sqrt(nx * nx + 1.0)))) * 255.0 + 0.5))

    expected = code(-0.01 * (200 - 0))  # at (row 3, column 4): −scale · (h[u + 1] − h[u − 1])
    assert normals[3, 4, 0] == expected == 13
    assert normals[3, 4, 1] == 128
    assert normals[3, 6, 0] == code(-0.01 * (0 - 200)) == 242  # the mirror slope on the other side
    assert normals[2, 5, 1] == expected  # v: h[v + 1] − h[v − 1] at row 2


def test_slope_spacing_follows_the_band_limit() -> None:
    """Half the height's band limit in texels: one texel up to 512 (main) / 1024 (detail), wider beyond,
    with the per-code scale shrinking so the relief stays the same at every resolution."""
    spacings = {}
    for resolution in (64, 256, 512, 1024, 2048):
        main, fine = normal_scales(Structure.model_validate({"resolution": resolution, "crystalScale": 6}))
        spacings[resolution] = (main.spacing, fine.spacing)
        assert main.scale * main.spacing * 256 / resolution == pytest.approx(5.0 / 510.0)
        assert fine.scale * fine.spacing * 256 / resolution == pytest.approx(1.5 / 510.0)
    assert spacings == {64: (1, 1), 256: (1, 1), 512: (1, 1), 1024: (2, 1), 2048: (4, 2)}


@pytest.mark.parametrize("name", FILTERS)
def test_filters_invert_exactly(name: str) -> None:
    rng = np.random.default_rng(5)
    plane = rng.integers(0, 256, size=(33, 47), dtype=np.uint8)
    residual = filter_plane(plane, name)
    assert residual.dtype == np.uint8
    np.testing.assert_array_equal(unfilter_plane(residual, name), plane)


def test_gradient_filter_predicts_a_plane_exactly() -> None:
    """left + above − above-left is exact on any affine ramp (mod 256): only the first row and column
    remain."""
    y, x = np.mgrid[0:16, 0:16]
    plane = ((3 * x + 7 * y + 11) % 256).astype(np.uint8)
    residual = filter_plane(plane, "gradient")
    assert np.all(residual[1:, 1:] == 0)
    assert np.any(residual[0, :] != 0)


@pytest.mark.parametrize(
    "fields", [{}, {"normalStrength": 0.0}, {"seed": 9, "branches": 3, "resolution": 128}]
)
def test_structure_file_round_trips_exactly(fields: dict[str, object]) -> None:
    maps = bake(**fields)
    packed = encode_structure(maps)
    structure, normals = decode_structure_file(packed.data, packed.layout("x.bin"))
    np.testing.assert_array_equal(structure, maps.structure)
    np.testing.assert_array_equal(normals, maps.normals)
    assert hashlib.sha256(structure.tobytes() + normals.tobytes()).hexdigest() == maps.sha256


def test_structure_file_is_deterministic_and_a_plain_zlib_stream(default_256: StructureMaps) -> None:
    first = encode_structure(default_256)
    second = encode_structure(generate_structure(Structure(resolution=256)))
    assert first.data == second.data
    assert (
        first.data[0] == 0x78
    )  # zlib header (deflate, 32 KiB window): what DecompressionStream('deflate') reads
    payload = zlib.decompress(first.data)
    assert len(payload) == len(PLANES) * 256 * 256
    assert zlib.adler32(payload) == first.adler32
    layout = first.layout("f.bin")
    assert layout["bytes"] == len(first.data)
    assert layout["filters"] == list(first.filters)
    assert layout["normals"] == {"main": default_256.main.as_plan(), "detail": default_256.fine.as_plan()}


def test_each_plane_uses_its_smallest_filter(default_256: StructureMaps) -> None:
    packed = encode_structure(default_256)
    planes = [default_256.structure[..., c] for c in range(3)] + [default_256.detail]
    for plane, chosen in zip(planes, packed.filters, strict=True):
        sizes = {
            name: len(zlib.compress(filter_plane(np.ascontiguousarray(plane), name).tobytes(), CHOICE_LEVEL))
            for name in FILTERS
        }
        assert sizes[chosen] == min(sizes.values()), (chosen, sizes)
    assert len(set(packed.filters)) > 1  # the planes differ: one filter would not suit them all


def test_structure_file_is_much_smaller_than_the_raw_maps(default_256: StructureMaps) -> None:
    packed = encode_structure(default_256)
    raw = default_256.structure.nbytes + default_256.normals.nbytes
    assert len(packed.data) < raw / 3


def test_decode_refuses_another_packages_file(default_256: StructureMaps) -> None:
    mine = encode_structure(default_256)
    other = encode_structure(bake(seed=99, resolution=256))
    with pytest.raises(ValueError, match="not this package's file"):
        decode_structure_file(other.data, mine.layout("x.bin"))
    with pytest.raises(ValueError, match="not this package's file"):
        decode_structure_file(mine.data[:-1] + b"\x00", mine.layout("x.bin"))
