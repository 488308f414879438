"""Static crystalline structure and normal maps of the frost effect, baked once in numpy from a seed.

The shader never synthesises the crystal pattern: it samples two small data textures that this module
bakes, so the look is identical on every adapter and costs two fetches per fragment. Both are sampled
with ``MirroredRepeatWrapping`` and ``NoColorSpace`` (they hold data, not colour), so the maps need not
tile periodically; what they must do instead is meet their own mirror image without a seam, which is
why every neighbourhood operation here mirrors the grid at its borders (see ``_gradient``).

Layout (both ``uint8``, shape ``(N, N, 4)``, row-major, row 0 = texture ``v = 0``, column 0 = ``u = 0``;
a three.js ``DataTexture`` with ``flipY = false`` uploads row 0 first, so WebGPU sees it at ``v = 0``):

* ``structure``: R = crystal density ``S`` (1 = dense frost crystals), G = smooth low-frequency
  thickness (the height weight of the detail refraction), B = crystal height ``H`` (what the main
  normals are the slope of), A = 255.
* ``normals``: RG = main-scale normal xy of ``H``, BA = detail-scale normal xy of ``D``, a finer height
  (the crystal edges and the rime grain) that only the normals use; both encoded ``0.5 + 0.5·n`` with
  ``n_z = sqrt(1 − n_x² − n_y²)`` implied.

The normals are not shipped: they are a pure function of the 8-bit ``H`` and ``D`` (``derive_normals``), so
a package ships ``S``, thickness, ``H`` and ``D`` (structure_file.py) and the runtime derives the normal map
with the same float64 operations in the same order, which gives the same bytes (IEEE 754 rounds +, −, ×, ÷
and √ correctly in numpy and in JavaScript alike). Deriving from the 8-bit heights rather than from the
float heights costs about one normal code (RMS, measured) and halves what a package ships.

The pattern is a jittered-grid Voronoi tessellation (one crystal per cell, ``crystalScale`` cells across)
in which every crystal grows ``branches`` slightly curled dendrite arms from its nucleus, each arm
feathered with 60° side branches that shorten towards the tip, as ice ferns on a window pane do; grain
boundaries where crystals meet are faint ridges, and a fine rime grain fills the gaps. Random numbers
come from ``numpy.random.default_rng(structure.seed)`` alone, drawn in a fixed order and with fixed
shapes (independent of ``resolution`` and ``branches``), so the same spec always bakes the same bytes
and changing the resolution resamples the same crystals rather than growing new ones.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Any, TypeAlias

import numpy as np
import numpy.typing as npt

from creaturegen.spec.frost import Structure

__all__ = [
    "REFERENCE_TEXELS",
    "NormalScale",
    "StructureMaps",
    "derive_normals",
    "generate_structure",
    "normal_scales",
    "to_float",
]

F32: TypeAlias = npt.NDArray[np.float32]
F64: TypeAlias = npt.NDArray[np.float64]
U8: TypeAlias = npt.NDArray[np.uint8]
Floats: TypeAlias = npt.NDArray[np.floating[Any]]

#: Slopes are measured per 1/REFERENCE_TEXELS of the texture width, so ``normalStrength`` means the same
#: relief at every resolution (a 2048 bake is a finer sampling of the 256 one, not a flatter surface).
REFERENCE_TEXELS = 256

#: Relief, in reference texels, of a height span of 1 at ``normalStrength`` 1, for the main and the detail
#: height. Chosen so that at strength 1 about 5 % of texels tilt by more than ~20° (|n_xy| ≈ 0.35) at
#: every resolution; the refraction spec's main/detail strengths then set the actual screen offsets.
_MAIN_RELIEF = 5.0
_DETAIL_RELIEF = 1.5
#: Band limits (Gaussian sigma, in reference texels) of the main and the detail height: the main height
#: keeps the broad crystal bodies, the detail height the crystal edges.
_MAIN_BAND = 1.0
_DETAIL_BAND = 0.5
#: Most dendrite arms a spec admits (``Structure.branches`` ≤ 16); per-arm lengths are always drawn for
#: all of them so that ``branches`` changes the pattern without shifting the random stream.
_MAX_ARMS = 16
#: Side branches of ice dendrites leave the arm at 60° (hexagonal ice).
_SIDE_ANGLE = np.pi / 3.0
#: Rime grain lattice cells per crystal cell: the high-frequency part of the detail height.
_GRAIN_PER_CELL = 10.0
#: Most rime grain knots across the texture (the grain is finer than a texel beyond this anyway).
_GRAIN_MAX_KNOTS = 1024
#: Thickness lattice knots across the texture at least (the G channel's lowest useful frequency).
_THICKNESS_MIN_CELLS = 3.0
#: Texels per strip of the crystal pass: small enough that its temporaries stay in cache.
_STRIP_TEXELS = 1 << 16


@dataclass(frozen=True)
class NormalScale:
    """How one normal map follows from an 8-bit height plane (see ``derive_normals``).

    ``spacing``: texels between a texel and each neighbour its slope is differenced with, half the height's
    band limit: one texel differences of 8-bit heights are too coarse at high resolutions (the slope of a
    2048 bake moves by a fraction of a height code per texel), wider ones smooth what the band kept.
    ``scale``: normal xy per height code of difference, ``gain / (2 · 255 · spacing)``. Both reach the
    runtime through the plan, so the JavaScript twin multiplies by exactly this double.
    """

    spacing: int
    scale: float

    def as_plan(self) -> dict[str, Any]:
        return {"spacing": self.spacing, "scale": self.scale}


@dataclass(frozen=True, eq=False)
class StructureMaps:
    """The baked maps of one ``Structure`` spec; arrays are read-only so the hash stays true.

    ``detail`` is the 8-bit detail height ``D`` (N × N) the detail normals are derived from; ``main`` and
    ``fine`` say how each normal map is derived. ``sha256`` is the hex digest of
    ``structure.tobytes() + normals.tobytes()``, the texels the GPU samples. It is exact for one numpy
    build on one CPU family; vectorised transcendental functions may differ in the last ulp elsewhere,
    which can flip a rare byte, so compare hashes of shipped files, not of bakes made on different machines.
    """

    structure: U8
    normals: U8
    detail: U8
    main: NormalScale
    fine: NormalScale
    resolution: int
    seed: int
    sha256: str

    def to_float(self) -> tuple[F32, F32]:
        """Decoded copies: ``structure`` in [0, 1] and normal xy pairs in [−1, 1] (see ``to_float``)."""
        return to_float(self)


def to_float(maps: StructureMaps) -> tuple[F32, F32]:
    """Decode the bytes exactly as the shader does: ``structure / 255`` and ``normals / 255 · 2 − 1``.

    The reference simulation and the tests use this rather than the pre-quantisation floats so they
    see what the GPU sees, quantisation included.
    """
    structure = maps.structure.astype(np.float32) / np.float32(255.0)
    normals = maps.normals.astype(np.float32) * np.float32(2.0 / 255.0) - np.float32(1.0)
    return structure, normals


@dataclass(frozen=True)
class _Cells:
    """Per-grid-cell random draws, padded by one ring of neighbour cells (index = grid index + 1)."""

    jitter: F64  # (side, side, 2) nucleus position inside its grid cell, [0.15, 0.85)
    orientation: F64  # (side, side) direction of arm 0, radians
    curl: F64  # (side, side) radians of arm bend per crystal-cell unit of radius
    vigour: F64  # (side, side) peak density of the crystal
    arm_length: F64  # (side, side, _MAX_ARMS) in crystal-cell units
    arm_twist: F64  # (side, side, _MAX_ARMS) arm direction offset, in units of min(spacing, 0.75 rad)


def generate_structure(structure: Structure) -> StructureMaps:
    """Bake the structure and normal maps of ``structure`` (pure: same spec, same bytes).

    Arrays are ``uint8 (N, N, 4)`` with row 0 = texture ``v = 0`` (the bottom; upload with
    ``flipY = false``). See the module docstring for the channels. Raises ``ValueError`` when
    ``crystalScale`` exceeds ``resolution / 4``: a crystal narrower than four texels cannot show its
    arms, and the per-cell tables would grow with the square of the scale for nothing.
    """
    n = structure.resolution
    scale = float(structure.crystalScale)
    if scale > n / 4:
        raise ValueError(f"crystalScale {scale:g} leaves under 4 texels per crystal at resolution {n}")
    rng = np.random.default_rng(structure.seed)

    # Every random number is drawn here, in a fixed order and with shapes that depend only on the crystal
    # scale, so neither the resolution nor the branch count shifts the stream: a 2048 bake is a finer
    # sampling of the same crystals as the 256 one.
    side = int(np.ceil(scale)) + 2
    cells = _Cells(
        jitter=rng.uniform(0.15, 0.85, size=(side, side, 2)),
        orientation=rng.uniform(0.0, 2.0 * np.pi, size=(side, side)),
        curl=rng.uniform(-0.9, 0.9, size=(side, side)),
        vigour=rng.uniform(0.7, 1.0, size=(side, side)),
        arm_length=rng.uniform(0.45, 1.1, size=(side, side, _MAX_ARMS)),
        arm_twist=rng.uniform(-0.2, 0.2, size=(side, side, _MAX_ARMS)),
    )
    thickness_knots = int(np.ceil(max(_THICKNESS_MIN_CELLS, scale / 2.0)))
    thickness_lattice = rng.uniform(0.0, 1.0, size=(thickness_knots, thickness_knots))
    grain_knots = min(int(np.ceil(scale * _GRAIN_PER_CELL)), _GRAIN_MAX_KNOTS)
    grain_lattice = rng.uniform(0.0, 1.0, size=(grain_knots, grain_knots))

    texel = n / REFERENCE_TEXELS  # texels of this bake per reference texel
    grain = _spline(grain_lattice, n)
    density = _normalise(_crystals(n, scale, structure.branches, float(structure.ridgeSharpness), cells))
    density = _normalise(density + np.float32(0.12) * grain)
    # Thickness: the crystal density averaged over about half a crystal, plus a slow swell of its own.
    coarse = _block_mean(density, min(n, max(8, _pow2_at_least(2.0 * scale))))
    thickness = _normalise(0.55 * _spline(thickness_lattice, n) + 0.45 * _spline(coarse, n))
    # Both heights are band-limited in reference texels before they are differenced: the thinnest arms
    # are sub-texel at 256 and resolved at 2048, and without this the same spec would bake over twice as
    # steep normals at 2048 as at 256.
    height = _normalise(0.75 * _blur(density, _MAIN_BAND * texel) + 0.25 * thickness)
    # The detail map is tiled several times finer on screen, so it carries the crystal edges (the density
    # minus its local mean) and the rime grain rather than the broad crystal bodies.
    edges = _blur(density, _DETAIL_BAND * texel) - _blur(density, 0.08 * n / scale)
    detail = _normalise(edges + np.float32(0.35) * grain)

    rgba = np.empty((n, n, 4), dtype=np.uint8)
    rgba[..., 0] = _quantise(density)
    rgba[..., 1] = _quantise(thickness)
    rgba[..., 2] = _quantise(height)
    rgba[..., 3] = 255
    detail8 = _quantise(detail)
    main, fine = normal_scales(structure)
    normals = derive_normals(rgba[..., 2], detail8, main, fine)
    for array in (rgba, normals, detail8):
        array.flags.writeable = False
    digest = hashlib.sha256(rgba.tobytes() + normals.tobytes()).hexdigest()
    return StructureMaps(
        structure=rgba,
        normals=normals,
        detail=detail8,
        main=main,
        fine=fine,
        resolution=n,
        seed=structure.seed,
        sha256=digest,
    )


def normal_scales(structure: Structure) -> tuple[NormalScale, NormalScale]:
    """The main and the detail ``NormalScale`` of a spec.

    The gain is ``normalStrength`` times the relief times texels per reference texel, so slopes are per
    reference texel and the relief is the same at every resolution.
    """
    n = structure.resolution
    texel = n / REFERENCE_TEXELS
    strength = float(structure.normalStrength)
    scales = []
    for relief, band in ((_MAIN_RELIEF, _MAIN_BAND), (_DETAIL_RELIEF, _DETAIL_BAND)):
        spacing = max(1, int(band * texel / 2.0))
        gain = strength * relief * texel
        scales.append(NormalScale(spacing=spacing, scale=gain / (510.0 * spacing)))
    return scales[0], scales[1]


def derive_normals(height: U8, detail: U8, main: NormalScale, fine: NormalScale) -> U8:
    """The normal map (N × N × 4: main xy of ``height``, detail xy of ``detail``) of two 8-bit heights.

    Shipped packages run the same arithmetic in core/structure-file.js; both sides must perform the same
    float64 operations in the same order (each one rounded, no fused multiply-add), so do not reorder,
    regroup or vectorise differently here without changing the JavaScript in the same commit.
    """
    out = np.empty((*height.shape, 4), dtype=np.uint8)
    out[..., 0:2] = _normal_codes(height, main)
    out[..., 2:4] = _normal_codes(detail, fine)
    return out


def _normal_codes(height: U8, how: NormalScale) -> U8:
    """Encoded normal xy of the surface ``z = gain · height``: ``0.5 + 0.5·n``, rounded half up to 8 bits.

    The slope is a central difference over ``how.spacing`` texels, the grid mirrored about its border
    texels. Why ``mode="reflect"`` (whole-sample mirror, ``h[−k] = h[k]``) and not ``"symmetric"``
    (``h[−1] = h[0]``, the texels MirroredRepeatWrapping samples beyond the border): the normal map is
    itself sampled mirrored, and a mirrored normal map cannot flip the sign of its x (or y) component the
    way the mirrored surface's true normal does, so it meets its mirror image without a seam only where that
    component is zero. The whole-sample mirror makes the border columns' ``∂h/∂u`` and the border rows'
    ``∂h/∂v`` exactly zero (encoded 128). The price is a half-texel shift of the mirror axis, invisible here.
    """
    k = how.spacing
    padded = np.pad(height.astype(np.float64), k, mode="reflect")
    du = padded[k:-k, 2 * k :] - padded[k:-k, : -2 * k]
    dv = padded[2 * k :, k:-k] - padded[: -2 * k, k:-k]
    nx = -how.scale * du
    ny = -how.scale * dv
    inv = 1.0 / np.sqrt(nx * nx + ny * ny + 1.0)
    codes = np.empty((*height.shape, 2), dtype=np.uint8)
    # |n| < 1, so each code lands in [0, 255] without a clamp.
    codes[..., 0] = np.floor((0.5 + 0.5 * (nx * inv)) * 255.0 + 0.5)
    codes[..., 1] = np.floor((0.5 + 0.5 * (ny * inv)) * 255.0 + 0.5)
    return codes


def _crystals(n: int, scale: float, branches: int, sharpness: float, cells: _Cells) -> F32:
    """Crystal density over the whole texture, computed in strips of rows.

    Strips of about 64k texels keep every temporary in cache; the pattern is a pure function of the
    texel position, so strips join exactly.
    """
    coord = (np.arange(n, dtype=np.float64) + 0.5) * (scale / n)  # crystal-cell units
    grid = np.floor(coord).astype(np.intp)
    local = (coord - grid).astype(np.float32)  # position inside the texel's own grid cell, [0, 1)
    out = np.empty((n, n), dtype=np.float32)
    rows = max(1, _STRIP_TEXELS // n)
    for start in range(0, n, rows):
        stop = min(n, start + rows)
        out[start:stop] = _crystal_strip(
            local[start:stop], grid[start:stop], local, grid, branches, sharpness, cells
        )
    return out


def _crystal_strip(
    local_v: F32,
    grid_v: npt.NDArray[np.intp],
    local_u: F32,
    grid_u: npt.NDArray[np.intp],
    branches: int,
    sharpness: float,
    cells: _Cells,
) -> F32:
    """Crystal density of a strip: per-cell dendrites (arms, 60° side branches, nucleus), grain edges.

    The nearest nucleus (F1) and the second-nearest distance (F2) come from the 3×3 neighbouring jittered
    cells (``_nearest_nuclei``). Only the owning crystal's dendrite is drawn (``_dendrite``), so arms stop
    where neighbouring crystals begin, as growing crystals do when they meet.
    """
    own, dx, dy, best, second = _nearest_nuclei(local_v, grid_v, local_u, grid_u, cells)
    r = np.sqrt(best)
    gap = np.sqrt(second) - r  # F2 − F1: zero on the boundary between two crystals
    dendrite = _dendrite(own, dx, dy, r, branches, sharpness, cells)
    # Crystals are denser near their nucleus; the boundaries where crystals meet are faint ridges.
    body = np.float32(0.18) * np.clip(1.0 - r / np.float32(0.75), 0.0, 1.0)
    boundary = np.float32(0.35) * _ridge(gap / np.float32(0.05), sharpness)
    density: F32 = np.maximum(dendrite + body, boundary).astype(np.float32)
    return density


def _nearest_nuclei(
    local_v: F32,
    grid_v: npt.NDArray[np.intp],
    local_u: F32,
    grid_u: npt.NDArray[np.intp],
    cells: _Cells,
) -> tuple[npt.NDArray[np.intp], F32, F32, F32, F32]:
    """Per texel of a strip: the flat index of its owning (nearest) cell, the offset (dx, dy) from that
    cell's nucleus, and the squared distances F1² and F2² to the nearest and second-nearest nuclei.

    Nuclei stay within [0.15, 0.85] of their cell, so the 3×3 neighbouring jittered cells suffice. A
    texel's grid cell is separable (its column picks the cell column, its row the cell row), so per-cell
    values reach the texels through two 1-D ``take``s, and the nearest of the 9 candidates is carried as a
    one-byte offset code until the end.
    """
    side = cells.jitter.shape[0]
    lx = local_u[None, :]  # columns: u
    ly = local_v[:, None]  # rows: v
    jit_x = cells.jitter[..., 0].astype(np.float32)
    jit_y = cells.jitter[..., 1].astype(np.float32)
    shape = (local_v.shape[0], local_u.shape[0])

    best = np.full(shape, np.inf, dtype=np.float32)
    second = np.full(shape, np.inf, dtype=np.float32)
    code = np.zeros(shape, dtype=np.uint8)
    offsets = [(di, dj) for dj in (-1, 0, 1) for di in (-1, 0, 1)]
    for k, (di, dj) in enumerate(offsets):
        sx = jit_x.take(grid_v + (dj + 1), axis=0).take(grid_u + (di + 1), axis=1)
        sy = jit_y.take(grid_v + (dj + 1), axis=0).take(grid_u + (di + 1), axis=1)
        np.subtract(lx - np.float32(di), sx, out=sx)
        np.subtract(ly - np.float32(dj), sy, out=sy)
        d2 = sx * sx
        d2 += sy * sy
        # Second-nearest first: min(F2, max(F1, d)) is the new F2 whether or not d beats F1.
        np.minimum(second, np.maximum(best, d2), out=second)
        np.copyto(code, np.uint8(k), where=d2 < best)
        np.minimum(best, d2, out=best)

    step_u = np.array([di for di, _ in offsets], dtype=np.intp)[code]
    step_v = np.array([dj for _, dj in offsets], dtype=np.intp)[code]
    own = (grid_v[:, None] + step_v + 1) * side + (grid_u[None, :] + step_u + 1)
    dx = lx - (step_u + jit_x.ravel().take(own))
    dy = ly - (step_v + jit_y.ravel().take(own))
    return own, dx, dy, best, second


def _dendrite(
    own: npt.NDArray[np.intp],
    dx: F32,
    dy: F32,
    r: F32,
    branches: int,
    sharpness: float,
    cells: _Cells,
) -> F32:
    """The owning crystal's dendrite at each texel of a strip: ``branches`` curled, twisted arms feathered
    with 60° side branches, and the nucleus, scaled by the crystal's vigour."""
    # Arms: the angle to the nearest of `branches` evenly spaced, curled and twisted arm directions.
    sector = np.float32(2.0 * np.pi / branches)
    theta = np.arctan2(dy, dx)
    theta -= cells.orientation.astype(np.float32).ravel().take(own)
    theta -= cells.curl.astype(np.float32).ravel().take(own) * r
    arm = np.floor(theta / sector + np.float32(0.5))
    arm_index = own * _MAX_ARMS + np.mod(arm.astype(np.intp), branches)
    length = cells.arm_length.astype(np.float32).ravel().take(arm_index)
    # Twist at most ±0.15 rad: with few arms a fraction of the spacing would swing an arm so close to its
    # sector's edge that the side branches on that side are cut off.
    twist = cells.arm_twist.astype(np.float32).ravel().take(arm_index) * min(sector, np.float32(0.75))
    delta = theta - arm * sector - twist
    along = r * np.cos(delta)
    perp = r * np.abs(np.sin(delta))
    progress = np.clip(along / length, 0.0, 1.0)
    width = np.float32(0.045) * (1.0 - np.float32(0.7) * progress) + np.float32(0.006)  # tapers to the tip
    main = _ridge(perp / width, sharpness) * ((along > 0) & (along < length))

    # Side branches: lines leaving the arm at 60° every `spacing`, longest near the nucleus (a fern).
    spacing = np.float32(0.075)
    base = along - perp / np.float32(np.tan(_SIDE_ANGLE))  # where this point's side branch leaves the arm
    offset = base / spacing
    off_line = np.abs(offset - np.round(offset)) * np.float32(spacing * np.sin(_SIDE_ANGLE))
    run = perp / np.float32(np.sin(_SIDE_ANGLE))  # distance travelled along the side branch
    reach = np.clip((np.float32(0.42) * (length - base) - run) / np.float32(0.06), 0.0, 1.0)
    sides = (
        _ridge(off_line / (np.float32(0.5) * width), sharpness) * reach * ((base > 0.04) & (base < length))
    )

    nucleus = _ridge(r / np.float32(0.09), sharpness)
    vigour = cells.vigour.astype(np.float32).ravel().take(own)
    dendrite: F32 = np.maximum(np.maximum(main, np.float32(0.8) * sides), nucleus) * vigour
    return dendrite


def _ridge(distance: Floats, sharpness: float) -> F32:
    """Ridge profile ``(1 − d)^sharpness`` on ``d ∈ [0, 1]``: the higher the sharpness, the narrower."""
    ridge: F32 = np.power(np.clip(1.0 - distance, 0.0, 1.0), np.float32(sharpness)).astype(np.float32)
    return ridge


def _spline_matrix(n: int, knots: int) -> F32:
    """(n × knots) cubic B-spline weights with knot k at the centre of block k of ``n / knots`` texels.

    Knot indices beyond either end fold back as ``np.pad(mode="symmetric")`` would, the same half-sample
    mirror MirroredRepeatWrapping applies, so the smooth fields have zero slope at the texture border
    and meet their mirror image without a crease.
    """
    c = (np.arange(n, dtype=np.float64) + 0.5) * (knots / n) - 0.5
    base = np.floor(c).astype(np.intp)
    f = c - base
    weights = (
        (1 - f) ** 3 / 6,
        (3 * f**3 - 6 * f**2 + 4) / 6,
        (-3 * f**3 + 3 * f**2 + 3 * f + 1) / 6,
        f**3 / 6,
    )
    matrix = np.zeros((n, knots), dtype=np.float64)
    rows = np.arange(n)
    for k, w in enumerate(weights):
        index = base + (k - 1)
        index = np.where(index < 0, -1 - index, index)
        index = np.where(index >= knots, 2 * knots - 1 - index, index)
        np.add.at(matrix, (rows, np.clip(index, 0, knots - 1)), w)
    return matrix.astype(np.float32)


def _spline(lattice: F32 | F64, n: int) -> F32:
    """Cubic B-spline through a square lattice onto n × n texels (C², so truly smooth): ``W · L · Wᵀ``.

    Separable, so it is two matrix products instead of a per-texel interpolation.
    """
    matrix = _spline_matrix(n, lattice.shape[0])
    return (matrix @ lattice.astype(np.float32) @ matrix.T).astype(np.float32)


def _block_mean(field: F32, size: int) -> F32:
    """Average ``field`` (n × n) down to size × size blocks (size divides n: both are powers of two)."""
    n = field.shape[0]
    f = n // size
    blocks: F32 = field.reshape(size, f, size, f).mean(axis=(1, 3), dtype=np.float64).astype(np.float32)
    return blocks


def _pow2_at_least(value: float) -> int:
    """Smallest power of two ≥ value (block sizes must divide the power-of-two resolution)."""
    return 1 << max(0, int(np.ceil(np.log2(max(value, 1.0)))))


def _blur(field: F32, sigma: float) -> F32:
    """Approximate Gaussian blur of standard deviation ``sigma`` texels: three box passes per axis.

    Box sums are differences of cumulative sums, so the cost does not grow with the radius. The grid is
    extended with ``np.pad(mode="symmetric")``, exactly the texels MirroredRepeatWrapping samples beyond
    the border, so the blur is the one the wrap mode implies. Sums run along contiguous rows (the
    array is transposed for the other axis) in cache-sized strips, several times faster than along columns.
    """
    # Three boxes of odd width w have variance 3·(w² − 1)/12 = σ².
    width = round(float(np.sqrt(4.0 * sigma * sigma + 1.0)))
    width += 1 - width % 2
    if width < 3:
        return field
    half = width // 2
    out = field
    for _ in range(2):  # rows, then (transposed) columns
        rows = np.empty(out.shape, dtype=np.float32)
        step = max(1, _STRIP_TEXELS // out.shape[1])
        for start in range(0, out.shape[0], step):
            strip = out[start : start + step].astype(np.float64)
            for _ in range(3):
                total = np.cumsum(np.pad(strip, ((0, 0), (half + 1, half)), mode="symmetric"), axis=1)
                strip = (total[:, width:] - total[:, :-width]) * (1.0 / width)
            rows[start : start + step] = strip
        out = np.ascontiguousarray(rows.T)
    return out


def _normalise(field: F32) -> F32:
    """Stretch to [0, 1]: the channels are 8-bit, and the full range keeps the most levels."""
    low = float(field.min())
    high = float(field.max())
    if high - low < 1e-12:
        return np.zeros(field.shape, dtype=np.float32)
    return ((field - np.float32(low)) * np.float32(1.0 / (high - low))).astype(np.float32)


def _quantise(unit: F32) -> U8:
    """[0, 1] → uint8, rounding to nearest (0.5 lands on 128, so a flat normal encodes as 128)."""
    levels: U8 = np.rint(np.clip(unit, 0.0, 1.0) * np.float32(255.0)).astype(np.uint8)
    return levels
