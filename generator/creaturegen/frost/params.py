"""FrostParams: the numbers every frost implementation reads (numpy reference, JS core, TSL kernels).

The spec speaks in user units (survival per second, deposit per second, radii as fractions of the history
height); the laws need rates. Converting once here, and shipping exactly these numbers to the package as
JSON, is what lets the reference and the GPU agree: neither side re-derives a constant on its own.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, Literal

from ..spec.frost import FrostEffectSpec, HistoryChannel

#: Sub-steps (piecewise-constant input intervals) one update dispatch applies; more are chunked into
#: several dispatches. The reference chunks identically because every dispatch ends in a storage write.
MAX_STEPS_PER_DISPATCH = 16
#: (step, segment) pairs one update dispatch holds (several strokes at once put several segments in a
#: step); a chunk ends before it would hold more. Both sides chunk by this rule.
MAX_PAIRS_PER_DISPATCH = 256
#: Pointer streams that may deposit at once (pointer() refuses a segment that would make more overlap).
MAX_STREAMS = 64
#: Bin entries one dispatch holds: a chunk whose binned entries would exceed it is dispatched as one bin
#: (every texel loops over every pair, the unbinned cost), never truncated.
BIN_CAPACITY = 1 << 20

#: Explicit 5-point diffusion is stable for D·dt/dx² ≤ 1/4 in 2-D; larger frames take more substeps.
DIFFUSION_STABILITY = 0.25

#: Workgroup of the full-field 2-D dispatch and the linear tile dispatch.
WORKGROUP_2D = (8, 8)
WORKGROUP_LINEAR = 64


@dataclass(frozen=True)
class ChannelRates:
    """λ = −ln(survival per second) and r = −ln(1 − deposit per second) of one history channel."""

    decay: float
    fill: float
    radius: float
    noise: float


def channel_rates(channel: HistoryChannel, radius: float) -> ChannelRates:
    return ChannelRates(
        decay=-math.log(channel.survivalPerSecond),
        fill=-math.log1p(-channel.depositPerSecond),
        radius=radius,
        noise=channel.noise,
    )


@dataclass(frozen=True)
class FrostParams:
    """Everything the history update needs; serialised verbatim into the package's plan."""

    visible: ChannelRates
    tilt: ChannelRates
    softness: float
    seed: int
    diffusivity: float
    history_scale: float
    policy: Literal["full-field", "dirty-tiles"]
    tile_size: int
    idle_when_converged: bool
    tolerance: float
    max_interval: float
    catch_up: (
        float  # longest interval caught up in advances of at most max_interval (timeline.advance_instants)
    )
    discontinuity: Literal["reset", "freeze"]
    resize_policy: Literal["clear", "preserve-remap"]
    max_steps: int = MAX_STEPS_PER_DISPATCH
    max_pairs: int = MAX_PAIRS_PER_DISPATCH
    max_streams: int = MAX_STREAMS
    bin_capacity: int = BIN_CAPACITY

    @property
    def channels(self) -> tuple[ChannelRates, ChannelRates]:
        """History channel order: R (visible thaw) first, A (tilt response) second."""
        return (self.visible, self.tilt)

    @property
    def brush_reach(self) -> float:
        """Largest radius any brush deposits at, in history-height units (both channels)."""
        return max(self.visible.radius, self.tilt.radius)

    def as_plan(self) -> dict[str, Any]:
        """JSON-ready dict with camelCase keys, the form the generated JS reads."""
        raw = asdict(self)
        return {
            "visible": raw["visible"],
            "tilt": raw["tilt"],
            "softness": self.softness,
            "seed": self.seed,
            "diffusivity": self.diffusivity,
            "historyScale": self.history_scale,
            "policy": self.policy,
            "tileSize": self.tile_size,
            "idleWhenConverged": self.idle_when_converged,
            "tolerance": self.tolerance,
            "maxInterval": self.max_interval,
            "catchUp": self.catch_up,
            "discontinuity": self.discontinuity,
            "resizePolicy": self.resize_policy,
            "maxSteps": self.max_steps,
            "maxPairs": self.max_pairs,
            "maxStreams": self.max_streams,
            "binCapacity": self.bin_capacity,
            "diffusionStability": DIFFUSION_STABILITY,
            "workgroup2d": list(WORKGROUP_2D),
            "workgroupLinear": WORKGROUP_LINEAR,
        }


def params_from_plan(plan: dict[str, Any]) -> FrostParams:
    """Inverse of :meth:`FrostParams.as_plan`: what the parity job reads back from build-report.json."""
    return FrostParams(
        visible=ChannelRates(**plan["visible"]),
        tilt=ChannelRates(**plan["tilt"]),
        softness=plan["softness"],
        seed=plan["seed"],
        diffusivity=plan["diffusivity"],
        history_scale=plan["historyScale"],
        policy=plan["policy"],
        tile_size=plan["tileSize"],
        idle_when_converged=plan["idleWhenConverged"],
        tolerance=plan["tolerance"],
        max_interval=plan["maxInterval"],
        catch_up=plan["catchUp"],
        discontinuity=plan["discontinuity"],
        resize_policy=plan["resizePolicy"],
        max_steps=plan["maxSteps"],
        max_pairs=plan["maxPairs"],
        max_streams=plan["maxStreams"],
        bin_capacity=plan["binCapacity"],
    )


def frost_params(spec: FrostEffectSpec) -> FrostParams:
    return FrostParams(
        visible=channel_rates(spec.history.visible, spec.brush.radius),
        tilt=channel_rates(spec.history.tilt, spec.brush.tiltRadius),
        softness=spec.brush.softness,
        seed=spec.seed,
        diffusivity=spec.diffusion.diffusivity if spec.diffusion.enabled else 0.0,
        history_scale=spec.tier.resolved_history_scale,
        policy=spec.update.policy,
        tile_size=spec.update.tileSize,
        idle_when_converged=spec.update.idleWhenConverged,
        tolerance=spec.update.convergenceTolerance,
        max_interval=spec.time.maxIntervalSeconds,
        catch_up=spec.time.catchUpSeconds,
        discontinuity=spec.time.discontinuity,
        resize_policy=spec.resizePolicy,
    )


def scaled_size(width: int, height: int, scale: float) -> tuple[int, int]:
    """Reduced-resolution size, rounded by floor(x + 0.5): round() rounds halves to even, JS does not."""
    return max(1, math.floor(width * scale + 0.5)), max(1, math.floor(height * scale + 0.5))
