"""Genomes: what makes one spawned individual differ from another, drawn from its seed by the LCG.

A genome is a handful of signed genes in [-1, 1), each the draw at a fixed index of the LCG stream that
starts at ``mix_seed(seed)`` (draw 1 is reserved, draw 2 is the heading, see lcg.instance_yaw):

- draws 3, 4, 5: hue, chroma, lightness, applied in OKLab to every authored colour (one rotation, one
  scale and one shift per individual, so the body's pattern stays coherent). The authored sRGB hex is the
  only input: its OKLab coordinates are computed at build time (``slot_lab``) and shipped; the runtime
  only mutates them and converts back (cubes and 3×3 products, no cube root), so Python and JS agree bit
  for bit.
- draws 6, 7, 8: one gait gene per group of the locomotion type's gene list (the motion data's ``genes``),
  each scaling its parameters by ``1 + jitter·gene`` (motion/express.py); a walker's step length stays
  within its reach limit.
- draw 9: size, ``1 + genes.size·gene``. Size is the one morphology gene a spawn may carry, because it is a
  similarity: the rest geometry (slot ends, radii, blend widths; the mesh's vertices and centres of
  rotation) and every length of the motion data scale together, so the field of an individual of size s is
  ``s·f(x/s)`` and its skinned, corrected mesh is the certified one scaled by s, with the same connectivity,
  the same signed Jacobians (times s³) and the same surface error relative to its own length. Gravity is
  not scaled, so speeds scale by √s (Froude similarity: every time derived from lengths, speeds and gravity
  scales by √s and the gait keeps its proportions up to whole ticks; the hopper's stated crouch and landing
  seconds stay), and the build's pose envelope steps the size corners too. Proportions
  (girth, limbs, tails) change the shape, so they are build-time identities (creature/morphology.py),
  never a spawn.

The JS core (core/genome.js) runs the same scalar arithmetic in the same order.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from ..spec.character import Genetics
from .lcg import lcg_next, mix_seed
from .record import JsonRecord
from .trig import pcos, psin

#: Draw index (1-based) of each gene; the gait genes follow GAIT_DRAW in gene-list order.
HUE_DRAW: Final = 3
CHROMA_DRAW: Final = 4
LIGHTNESS_DRAW: Final = 5
GAIT_DRAW: Final = 6
#: Gait genes a type may carry (the longest gene list).
MAX_GAIT_GENES: Final = 3
SIZE_DRAW: Final = GAIT_DRAW + MAX_GAIT_GENES

# Björn Ottosson's OKLab matrices (linear sRGB -> LMS, LMS' -> Lab, and their inverses).
_M1: Final = (
    (0.4122214708, 0.5363325363, 0.0514459929),
    (0.2119034982, 0.6806995451, 0.1073969566),
    (0.0883024619, 0.2817188376, 0.6299787005),
)
_M2: Final = (
    (0.2104542553, 0.7936177850, -0.0040720468),
    (1.9779984951, -2.4285922050, 0.4505937099),
    (0.0259040371, 0.7827717662, -0.8086757660),
)
_M2_INV: Final = (
    (1.0, 0.3963377774, 0.2158037573),
    (1.0, -0.1055613458, -0.0638541728),
    (1.0, -0.0894841775, -1.2914855480),
)
_M1_INV: Final = (
    (4.0767416621, -3.3077115913, 0.2309699292),
    (-1.2684380046, 2.6097574011, -0.3413193965),
    (-0.0041960863, -0.7034186147, 1.7076147010),
)


@dataclass(frozen=True)
class Genome:
    """Signed genes in [-1, 1) of one individual."""

    hue: float
    chroma: float
    lightness: float
    gait: tuple[float, ...]
    size: float = 0.0


def _signed(draw: int) -> float:
    return draw / 2147483648.0 - 1.0


def draw_genome(seed: int) -> Genome:
    """The genome of the individual spawned from ``seed`` (the same draws as core/genome.js drawGenome)."""
    state = mix_seed(seed)
    draws = []
    for _ in range(SIZE_DRAW):
        state = lcg_next(state)
        draws.append(_signed(state))
    gait_from = GAIT_DRAW - 1
    return Genome(
        hue=draws[HUE_DRAW - 1],
        chroma=draws[CHROMA_DRAW - 1],
        lightness=draws[LIGHTNESS_DRAW - 1],
        gait=tuple(draws[gait_from : gait_from + MAX_GAIT_GENES]),
        size=draws[SIZE_DRAW - 1],
    )


def _row(m: tuple[tuple[float, float, float], ...], i: int, x: float, y: float, z: float) -> float:
    """Row ``i`` of a 3×3 matrix times (x, y, z), summed left to right as the JS core does."""
    return m[i][0] * x + m[i][1] * y + m[i][2] * z


def slot_lab(rgb_linear: npt.NDArray[np.float64]) -> list[list[float]]:
    """OKLab (L, a, b) of each slot's authored colour (the sRGB hex the rig decoded to linear, where OKLab's
    forward transform starts). Build time, shipped as data; scalar arithmetic, so no BLAS reordering makes
    the build's numbers and the parity reference's differ."""
    out = []
    for r, g, b in np.asarray(rgb_linear, dtype=np.float64).tolist():
        lms = [math.cbrt(_row(_M1, i, r, g, b)) for i in range(3)]
        out.append([_row(_M2, i, *lms) for i in range(3)])
    return out


def linear_from_oklab(lab: tuple[float, float, float]) -> tuple[float, float, float]:
    """Linear sRGB of an OKLab colour, each channel clamped to [0, 1] (out-of-gamut mutations clip)."""
    big_l, a, b = lab
    l_ = _row(_M2_INV, 0, big_l, a, b)
    m_ = _row(_M2_INV, 1, big_l, a, b)
    s_ = _row(_M2_INV, 2, big_l, a, b)
    lc, mc, sc = l_ * l_ * l_, m_ * m_ * m_, s_ * s_ * s_
    return (
        min(1.0, max(0.0, _row(_M1_INV, 0, lc, mc, sc))),
        min(1.0, max(0.0, _row(_M1_INV, 1, lc, mc, sc))),
        min(1.0, max(0.0, _row(_M1_INV, 2, lc, mc, sc))),
    )


def genome_colours(genetics: ColourGenetics, lab: list[list[float]], genome: Genome) -> list[list[float]]:
    """Per-slot linear rgb of an individual: hue rotated, chroma scaled and lightness shifted in OKLab."""
    angle = genetics.hue_rad * genome.hue
    cos, sin = pcos(angle), psin(angle)
    scale = 1.0 + genetics.chroma * genome.chroma
    shift = genetics.lightness * genome.lightness
    out = []
    for big_l, a, b in lab:
        lightness = min(1.0, max(0.0, big_l + shift))
        out.append(
            list(linear_from_oklab((lightness, (cos * a - sin * b) * scale, (sin * a + cos * b) * scale)))
        )
    return out


@dataclass(frozen=True, slots=True)
class ColourGenetics(JsonRecord):
    """The bounds of the colour genes, as the runtime reads them (CREATURE.genetics): each gene in [-1, 1)
    times its bound."""

    hue_rad: float
    """Largest hue rotation, radians (the spec states degrees)."""
    chroma: float
    """Largest relative change of chroma."""
    lightness: float
    """Largest shift of OKLab lightness."""


def genetics_data(genetics: Genetics) -> ColourGenetics:
    """The plan's colour genetics (the hue bound in radians, as the runtime reads it)."""
    return ColourGenetics(math.radians(genetics.hue), genetics.chroma, genetics.lightness)
