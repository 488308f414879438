"""Which history tiles a frame dispatches: full-field, dirty tiles, and idle, from analytic bounds.

No readback decides anything: each tile carries an upper bound on each channel, known on the CPU from the
law itself. A frame sets the bound of every tile a brush capsule reaches to 1 (coverage and equilibrium are
at most 1), lets diffusion spread bounds into neighbouring tiles (the maximum principle: a diffused value
never exceeds its neighbourhood's maximum), and decays the rest by e^(−λ·dt). A tile whose bounds fall to
the tolerance is retired: both ping-pong textures are cleared to 0 there (the equilibrium without input),
after which the law leaves it exactly invariant and no dispatch touches it again until a brush does.

The full-field policy is one tile covering the whole history; with ``idleWhenConverged`` it retires like any
tile, otherwise it is dispatched every frame. The JS core implements this same scheduler line for line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .brush import Segment
from .params import DIFFUSION_STABILITY, FrostParams
from .timeline import Step

BoolGrid = npt.NDArray[np.bool_]


def diffusion_substeps(diffusivity: float, dt: float, height: int) -> int:
    """Substeps that keep D·(dt/n)/dx² ≤ 1/4 with dx = 1/H (history-height units); 0 without diffusion."""
    number = diffusivity * dt * height * height
    return math.ceil(number / DIFFUSION_STABILITY) if number > 0.0 else 0


@dataclass(frozen=True)
class TilePlan:
    """Row-major tile indices to update and to retire (clear) this frame, and the tile geometry."""

    update: tuple[int, ...]
    retire: tuple[int, ...]
    tile_width: int
    tile_height: int
    tiles_x: int
    tiles_y: int

    def mask(self, tiles: tuple[int, ...], width: int, height: int) -> BoolGrid:
        """Texel mask (H, W) of the given tiles, clipped to the history extent."""
        mask = np.zeros((height, width), dtype=bool)
        for tile in tiles:
            tx, ty = tile % self.tiles_x, tile // self.tiles_x
            x0, y0 = tx * self.tile_width, ty * self.tile_height
            mask[y0 : y0 + self.tile_height, x0 : x0 + self.tile_width] = True
        return mask

    def texels(self, tiles: tuple[int, ...]) -> int:
        """Texels a dispatch over these tiles covers, extent guards included (what the GPU is asked for)."""
        return len(tiles) * self.tile_width * self.tile_height


def texel_box(
    segment: Segment, dt: float, reach: float, width: int, height: int
) -> tuple[int, int, int, int] | None:
    """Inclusive texel box (x0, y0, x1, y1) a segment's capsule can reach over dt, or None when it deposits
    nothing (no pressure, no time) or lies off the history."""
    if segment.pressure <= 0.0 or dt <= 0.0:
        return None
    us, vs = (segment.start[0], segment.end[0]), (segment.start[1], segment.end[1])
    rx = reach * height / width
    x0 = max(math.floor((min(us) - rx) * width), 0)
    x1 = min(math.floor((max(us) + rx) * width), width - 1)
    y0 = max(math.floor((min(vs) - reach) * height), 0)
    y1 = min(math.floor((max(vs) + reach) * height), height - 1)
    return None if x0 > x1 or y0 > y1 else (x0, y0, x1, y1)


@dataclass(frozen=True)
class Bins:
    """The segments of a chunk of steps binned into square screen tiles of ``size`` texels: the GPU loops
    each texel over its bin's (step, segment) entries only, so overlapping strokes cost Σ_t P_t·E_t (texels
    of tile t times entries in it) rather than every texel times every pair. A chunk whose entries would
    overflow the bin capacity is one bin holding every pair (``single``): the unbinned cost, never a loss."""

    size: int
    bins_x: int
    entries: npt.NDArray[np.int64]  # (bins,) entries per bin
    single: bool

    @property
    def total(self) -> int:
        return int(self.entries.sum())

    def texel_steps(self, update: BoolGrid) -> int:
        """Σ over the bins of ``update`` (a texel mask) of texels × entries: the law's evaluations."""
        if self.single:
            return int(np.count_nonzero(update)) * self.total
        count = 0
        for b in np.flatnonzero(self.entries):
            by, bx = divmod(int(b), self.bins_x)
            block = update[by * self.size : (by + 1) * self.size, bx * self.size : (bx + 1) * self.size]
            count += int(np.count_nonzero(block)) * int(self.entries[b])
        return count


def bin_steps(steps: list[Step], params: FrostParams, width: int, height: int) -> Bins:
    """Entries per bin of one chunk (the JS core's StepBins, line for line): tiles of the scheduler's
    tile size, whatever the policy; a pair lands in every bin its capsule's texel box reaches."""
    size = params.tile_size
    bins_x, bins_y = math.ceil(width / size), math.ceil(height / size)
    grid = np.zeros((bins_y, bins_x), dtype=np.int64)
    pairs = 0
    for step in steps:
        for segment in step.segments:
            pairs += 1
            box = texel_box(segment, step.dt, params.brush_reach, width, height)
            if box is None:
                continue
            x0, y0, x1, y1 = box
            grid[y0 // size : y1 // size + 1, x0 // size : x1 // size + 1] += 1
    if int(grid.sum()) > params.bin_capacity:
        return Bins(max(width, height), 1, np.array([pairs], dtype=np.int64), True)
    return Bins(size, bins_x, grid.reshape(-1), False)


class TileScheduler:
    """Per-tile channel bounds for one history size; reset by a resize or a discontinuity."""

    def __init__(self, params: FrostParams, width: int, height: int) -> None:
        self.params = params
        full = params.policy == "full-field"
        self.tile_width = width if full else params.tile_size
        self.tile_height = height if full else params.tile_size
        self.tiles_x = math.ceil(width / self.tile_width)
        self.tiles_y = math.ceil(height / self.tile_height)
        self.width, self.height = width, height
        self.bounds = np.zeros((2, self.tiles_y, self.tiles_x))
        self.live = np.zeros((self.tiles_y, self.tiles_x), dtype=bool)

    def touched(self, steps: list[Step]) -> BoolGrid:
        """Tiles any capsule of this frame can reach (brush AABB in texels, both channels' radii)."""
        touched = np.zeros_like(self.live)
        for step in steps:
            for segment in step.segments:
                box = texel_box(segment, step.dt, self.params.brush_reach, self.width, self.height)
                if box is None:
                    continue
                x0, y0, x1, y1 = box
                touched[
                    y0 // self.tile_height : y1 // self.tile_height + 1,
                    x0 // self.tile_width : x1 // self.tile_width + 1,
                ] = True
        return touched

    def plan(self, steps: list[Step], frame_dt: float, substeps: int) -> TilePlan:
        if substeps > 0:
            halo = math.ceil(substeps / min(self.tile_width, self.tile_height))
            self.bounds = _dilate(self.bounds, halo)
        decays = np.array([c.decay for c in self.params.channels])[:, None, None]
        self.bounds = self.bounds * np.exp(-decays * frame_dt)
        touched = self.touched(steps)
        self.bounds[:, touched] = 1.0
        live = np.any(self.bounds > self.params.tolerance, axis=0)
        if self.params.policy == "full-field" and not self.params.idle_when_converged:
            live = np.ones_like(live)
        retire = self.live & ~live
        self.bounds[:, ~live] = 0.0
        self.live = live
        return TilePlan(
            update=tuple(int(i) for i in np.flatnonzero(live)),
            retire=tuple(int(i) for i in np.flatnonzero(retire)),
            tile_width=self.tile_width,
            tile_height=self.tile_height,
            tiles_x=self.tiles_x,
            tiles_y=self.tiles_y,
        )

    def mark_all(self, bound: tuple[float, float]) -> None:
        """After a remapping resize: every tile may hold content up to the old bounds."""
        self.bounds[0], self.bounds[1] = bound
        self.live = np.any(self.bounds > self.params.tolerance, axis=0)


def _dilate(bounds: npt.NDArray[np.float64], halo: int) -> npt.NDArray[np.float64]:
    """Maximum over a (2·halo+1)² tile neighbourhood, per channel (edges replicate)."""
    padded = np.pad(bounds, ((0, 0), (halo, halo), (halo, halo)), mode="edge")
    out = bounds.copy()
    ny, nx = bounds.shape[1:]
    for dy in range(2 * halo + 1):
        for dx in range(2 * halo + 1):
            out = np.maximum(out, padded[:, dy : dy + ny, dx : dx + nx])
    return out
