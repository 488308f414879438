"""The numpy reference simulation of the frost history: same grid, same law, same brush, same diffusion.

It mirrors the GPU pipeline dispatch for dispatch (retire clears, then update chunks of at most
``max_steps`` input intervals, then diffusion substeps), so that with ``storage="float16"`` it also rounds
where the GPU writes its RGBA16F textures. With ``storage="float64"`` nothing is rounded: that is the form
in which 30, 60 and 120 FPS replays of one pointer path must agree to 1e-12, since the closed-form law
composes exactly for piecewise-constant input.

State layout (H, W, 4), like the textures: R visible thaw, G visible deposit of the last frame (debug),
B tilt deposit of the last frame (debug), A tilt response.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .brush import Segment, coverage, texel_noise
from .law import Array, advance, catch_up
from .params import FrostParams
from .schedule import BoolGrid, TilePlan, TileScheduler, bin_steps, diffusion_substeps
from .timeline import (
    Decision,
    Step,
    advance_instants,
    chunk_steps,
    classify_interval,
    late_steps,
    split_interval,
    too_many_streams,
    validate_segment,
)

Storage = Literal["float16", "float32", "float64"]

#: numpy dtype that rounds like each history texture format when the GPU stores a texel.
STORAGE_OF_FORMAT: dict[str, Storage] = {"rgba16float": "float16", "rgba32float": "float32"}
STATE_CHANNELS = (0, 3)  # R, A hold state; G, B are the last frame's deposits.
DEPOSIT_CHANNELS = (1, 2)


@dataclass
class FrameReport:
    """What one update did: the same counters the lab publishes per frame."""

    decision: Decision
    steps: int = 0
    dispatches: int = 0
    texels: int = 0
    update_tiles: int = 0
    retired_tiles: int = 0
    substeps: int = 0
    late_steps: int = 0
    advances: int = 0  # 1 for an ordinary frame, ceil(dt / maxInterval) for a caught-up stall
    pointer_seconds: float = 0.0
    bin_entries: int = 0  # (step, segment) entries over the chunks' bins (schedule.bin_steps)
    texel_steps: int = 0  # law evaluations: Σ over updated texels of their bin's entries
    unbinned_texel_steps: int = 0  # what every updated texel looping over every pair would evaluate


@dataclass
class Counters:
    frames: int = 0
    discontinuities: int = 0
    catch_ups: int = 0
    dispatches: int = 0
    texels: int = 0
    pointer_seconds: float = 0.0
    history: list[FrameReport] = field(default_factory=list)


class FrostReference:
    """A stateful history on the CPU; feed it the lab's segments and instants, read ``state``."""

    def __init__(self, params: FrostParams, width: int, height: int, storage: Storage = "float64") -> None:
        self.params = params
        self.storage = storage
        self.counters = Counters()
        self.pending: list[Segment] = []
        self.fresh_from = 0  # pending[fresh_from:] were queued since the last update
        self.origin: float | None = None  # where the history's timeline starts (see late_steps)
        self._last_end: dict[int, float] = {}  # per stream
        self._allocate(width, height)

    def _allocate(self, width: int, height: int) -> None:
        self.width, self.height = width, height
        self.state = np.zeros((height, width, 4))
        self.scheduler = TileScheduler(self.params, width, height)
        self.thinning = [
            channel.noise * texel_noise(width, height, self.params.seed, index)
            for index, channel in enumerate(self.params.channels)
        ]

    def _store(self, values: Array) -> Array:
        if self.storage == "float64":
            return values
        return np.asarray(values.astype(self.storage).astype(np.float64))

    def queue(self, segment: Segment) -> None:
        problem = validate_segment(segment, self._last_end.get(segment.stream))
        if problem is None:
            problem = too_many_streams(segment, self.pending, self.params.max_streams)
        if problem is not None:
            raise ValueError(problem)
        self.pending.append(segment)
        self._last_end[segment.stream] = segment.t1

    def update(self, previous: float, current: float) -> FrameReport:
        decision = classify_interval(previous, current, self.params.max_interval, self.params.catch_up)
        report = FrameReport(decision=decision)
        if decision == "none":
            return report
        self.counters.frames += 1
        if decision == "discontinuity":
            self.counters.discontinuities += 1
            self.pending = []
            self.fresh_from = 0
            self.origin = current
            self._last_end = {}
            if self.params.discontinuity == "reset":
                self._allocate(self.width, self.height)
            self.counters.history.append(report)
            return report
        origin = self.origin = previous if self.origin is None else self.origin
        ends = [current]
        if decision == "catch-up":
            self.counters.catch_ups += 1
            ends = advance_instants(previous, current, self.params.max_interval)
        start, fresh = previous, True
        for end in ends:
            fresh = not self._advance(start, end, origin, report, fresh) and fresh
            start = end
        self.counters.pointer_seconds += report.pointer_seconds
        self.counters.dispatches += report.dispatches
        self.counters.texels += report.texels
        self.counters.history.append(report)
        return report

    def _advance(
        self, previous: float, current: float, origin: float, report: FrameReport, fresh: bool
    ) -> bool:
        """One advance over [previous, current): a frame's whole interval, or one piece of a catch-up (the
        segments queued during a stall are fresh for the first piece only). ``fresh``: no advance of this
        frame has updated tiles yet. Returns whether this one did."""
        late = late_steps(previous, self.pending[self.fresh_from :], origin)
        steps = late + split_interval(previous, current, self.pending)
        report.late_steps += len(late)
        report.pointer_seconds += sum(s.pointer_seconds for s in steps)
        substeps = diffusion_substeps(self.params.diffusivity, current - previous, self.height)
        plan = self.scheduler.plan(steps, current - previous, substeps)
        self._apply(plan, steps, substeps, report, current - previous, first=fresh)
        report.advances += 1
        self.pending = [g for g in self.pending if g.t1 > current]
        self.fresh_from = len(self.pending)
        return bool(plan.update)

    def _apply(
        self,
        plan: TilePlan,
        steps: list[Step],
        substeps: int,
        report: FrameReport,
        frame_dt: float,
        first: bool,
    ) -> None:
        """Retire, update and diffuse over one advance; the report sums over a frame's advances. ``first``:
        no earlier advance of the frame updated tiles: this one's first chunk restarts the last-frame deposit
        channels."""
        w, h = self.width, self.height
        report.steps += len(steps)
        report.update_tiles += len(plan.update)
        report.retired_tiles += len(plan.retire)
        if plan.retire:
            self.state[plan.mask(plan.retire, w, h)] = 0.0
            report.dispatches += 1
            report.texels += plan.texels(plan.retire)
        if not plan.update:
            return
        mask = plan.mask(plan.update, w, h)
        texels = plan.texels(plan.update)
        for chunk_index, chunk in enumerate(chunk_steps(steps, self.params.max_steps, self.params.max_pairs)):
            self._law(chunk, mask, first=first and chunk_index == 0)
            bins = bin_steps(chunk, self.params, w, h)
            report.bin_entries += bins.total
            report.texel_steps += bins.texel_steps(mask)
            report.unbinned_texel_steps += int(np.count_nonzero(mask)) * sum(len(s.segments) for s in chunk)
            report.dispatches += 1
            report.texels += texels
        report.substeps += substeps
        if substeps:
            rate = self.params.diffusivity * (frame_dt / substeps) * h * h
            for _ in range(substeps):
                self._diffuse(rate, mask)
                report.dispatches += 1
                report.texels += texels

    def _law(self, steps: list[Step], mask: BoolGrid, first: bool) -> None:
        x = [self.state[..., c].copy() for c in STATE_CHANNELS]
        deposit = [np.zeros_like(x[0]) if first else self.state[..., c].copy() for c in DEPOSIT_CHANNELS]
        for step in steps:
            for index, channel in enumerate(self.params.channels):
                b: Array | float = 0.0
                for segment in step.segments:
                    b = np.maximum(
                        b,
                        coverage(
                            segment,
                            self.width,
                            self.height,
                            channel.radius,
                            self.params.softness,
                            self.thinning[index],
                        ),
                    )
                if step.segments:
                    deposit[index] = np.maximum(deposit[index], b)
                if step.age is None:
                    x[index] = advance(x[index], b, step.dt, channel.decay, channel.fill)
                else:
                    x[index] = catch_up(x[index], b, step.dt, step.age, channel.decay, channel.fill)
        for c, value in zip((*STATE_CHANNELS, *DEPOSIT_CHANNELS), (*x, *deposit), strict=True):
            self.state[..., c] = np.where(mask, self._store(value), self.state[..., c])

    def _diffuse(self, rate: float, mask: BoolGrid) -> None:
        for c in STATE_CHANNELS:
            x = self.state[..., c]
            padded = np.pad(x, 1, mode="edge")
            laplacian = padded[:-2, 1:-1] + padded[2:, 1:-1] + padded[1:-1, :-2] + padded[1:-1, 2:] - 4.0 * x
            self.state[..., c] = np.where(mask, self._store(x + rate * laplacian), x)

    def resize(self, width: int, height: int) -> None:
        """Apply the declared resize policy: clear, or remap the old history bilinearly by UV."""
        if self.params.resize_policy == "clear" or self.counters.frames == 0:
            self._allocate(width, height)
            return
        old, bounds = self.state, self.scheduler.bounds.max(axis=(1, 2))
        self._allocate(width, height)
        self.state = self._store(remap_bilinear(old, width, height))
        self.scheduler.mark_all((float(bounds[0]), float(bounds[1])))


def remap_bilinear(state: Array, width: int, height: int) -> Array:
    """Resample (H, W, C) at the new texel centres by UV; clamp-to-edge, like the GPU kernel's loads."""
    old_h, old_w = state.shape[:2]
    x = np.clip((np.arange(width) + 0.5) / width * old_w - 0.5, 0.0, old_w - 1.0)
    y = np.clip((np.arange(height) + 0.5) / height * old_h - 0.5, 0.0, old_h - 1.0)
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    x1, y1 = np.minimum(x0 + 1, old_w - 1), np.minimum(y0 + 1, old_h - 1)
    fx, fy = (x - x0)[None, :, None], (y - y0)[:, None, None]
    top = state[y0][:, x0] * (1 - fx) + state[y0][:, x1] * fx
    bottom = state[y1][:, x0] * (1 - fx) + state[y1][:, x1] * fx
    return np.asarray(top * (1 - fy) + bottom * fy)
