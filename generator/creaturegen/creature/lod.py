"""The projected-size contract a body's tier is chosen by: its length L on screen, in pixels, from the
camera's unjittered projection, against each built tier's subpixel size (``CREATURE.projectedSizeMaxPx``),
with hysteresis so that a body at a boundary does not switch every frame.

The package's twin is core/lod.js (``projectedSizePx``, ``chooseTier``); tests/js/lod.test.mjs holds the two
to the same choices and sizes. Unjittered: the size is computed from the camera's field of view (or
orthographic extent) and zoom, never from a projection matrix a TAA pass has offset by a subpixel jitter.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Final

#: Coarse to fine: a body is drawn by the coarsest built tier whose subpixel size covers it.
TIER_ORDER: Final = ("distant", "repeated", "hero")
#: A body moves to a coarser tier only once its size is this fraction inside that tier's subpixel size;
#: it moves to a finer one as soon as it outgrows its own (the subpixel contract is never broken).
HYSTERESIS: Final = 0.15


def projected_size_px(
    length: float,
    depth: float,
    viewport_height_px: float,
    *,
    fov_deg: float | None = None,
    ortho_height: float | None = None,
    zoom: float = 1.0,
) -> float:
    """L on screen, in pixels, at view depth ``depth`` (> 0, along the camera's axis): a perspective camera
    of vertical field of view ``fov_deg``, or an orthographic one whose visible height is
    ``ortho_height`` (top − bottom). Depth is clamped to a tiny positive value (a body at or behind the eye
    is as large as it gets)."""
    if ortho_height is not None:
        return length * viewport_height_px * zoom / ortho_height
    assert fov_deg is not None, "a perspective camera needs fov_deg"
    half = math.tan(math.radians(fov_deg) / 2.0)
    return length * viewport_height_px * zoom / (2.0 * half * max(depth, 1e-9))


def choose_tier(size_px: float, current: str | None, ceilings: Mapping[str, float]) -> str:
    """The tier for a body of ``size_px`` now drawn by ``current`` (None: not yet drawn), among the built
    tiers ``ceilings`` (tier → its subpixel size). The finest built tier takes any size; a coarser one a
    size up to its ceiling, and a body switches down into it only below (1 − HYSTERESIS) of it."""
    built = [t for t in TIER_ORDER if t in ceilings]
    assert built, "no tier is built"
    finest = built[-1]

    def fits(tier: str, margin: float) -> bool:
        return tier == finest or size_px <= ceilings[tier] * margin

    if current in built and fits(current, 1.0):
        coarser = built[: built.index(current)]
        return next((t for t in coarser if fits(t, 1.0 - HYSTERESIS)), current)
    return next(t for t in built if fits(t, 1.0))
