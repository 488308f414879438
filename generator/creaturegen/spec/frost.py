"""FrostEffectSpec: the frost/thaw surface effect (``"kind": "frost"``).

Every tunable of the dynamic-surface seed has a field with a unit and a default, so ``{"kind": "frost",
"name": "Pane"}`` is a complete spec. The defaults are measured, not guessed: with them a one-second wipe at
ordinary speed leaves a trail of median OKLab ΔE ≈ 0.09 in the composite that frosts over again in ≈ 6 s
(the parity job's trail gates; the README's "The frost effect" has the figures). History law (per
channel): λ = −ln(survivalPerSecond), r = −ln(1 − depositPerSecond), a = λ + r·b, xEq = r·b/a,
x' = xEq + (x − xEq)·e^(−a·dt).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, StrictBool, StrictInt, ValidationInfo, field_validator

from .colors import Color
from .messages import number
from .types import Name, NonNegative, Number, Positive, Seed, StrictModel, UnitInterval, rule_error

TierName = Literal["full", "balanced", "budgeted"]

#: Largest history resolution scale each tier admits (full-res, half-res, quarter-res in the seed).
TIER_MAX_HISTORY_SCALE: dict[str, float] = {"full": 1.0, "balanced": 0.5, "budgeted": 0.25}

#: Storage formats proven storage-writable on the target adapters; "auto" lets the quantisation gate choose.
HistoryFormat = Literal["auto", "rgba16float", "rgba32float"]


class HistoryChannel(StrictModel):
    """Decay and saturating deposit of one history channel (R visible thaw, A tilt response)."""

    survivalPerSecond: Annotated[Number, Field(gt=0, le=1)] = Field(
        default=0.75, description="Fraction of thaw left after one second without input; 1 never refreezes."
    )
    depositPerSecond: Annotated[Number, Field(ge=0, lt=1)] = Field(
        default=0.999999,
        description="Fraction of the gap to full thaw filled per second under full coverage.",
    )
    noise: UnitInterval = Field(default=0.35, description="Amplitude of the brush's deposit noise.")


class History(StrictModel):
    visible: HistoryChannel = Field(default_factory=HistoryChannel)
    tilt: HistoryChannel = Field(
        default_factory=lambda: HistoryChannel(survivalPerSecond=0.9, depositPerSecond=0.98, noise=0.1)
    )


class Brush(StrictModel):
    """Swept, aspect-corrected capsule brushes; radii in history UV units (fraction of its height)."""

    radius: Annotated[Number, Field(gt=0, le=0.5)] = Field(default=0.07, description="Visible brush radius.")
    tiltRadius: Annotated[Number, Field(gt=0, le=0.5)] = Field(
        default=0.1, description="Tilt brush radius; at least the visible radius (smoother)."
    )
    softness: Annotated[Number, Field(gt=0, le=1)] = Field(
        default=0.5, description="Fraction of the radius over which coverage falls to zero."
    )

    @field_validator("tiltRadius")
    @classmethod
    def _tilt_is_smoother(cls, value: float, info: ValidationInfo) -> float:
        radius = info.data.get("radius")
        if radius is not None and value < radius:
            raise rule_error(
                f"must be >= brush.radius ({number(radius)}); the tilt brush is the smoother one"
            )
        return value


class Fades(StrictModel):
    side: Annotated[Number, Field(ge=0, le=0.5)] = Field(default=0.04, description="Edge fade width, UV.")
    corner: Annotated[Number, Field(ge=0, le=0.5)] = Field(
        default=0.08, description="Corner fade radius, UV."
    )


class Diffusion(StrictModel):
    """Optional Laplacian smoothing of the history; substeps keep D·dt/dx² ≤ 1/4."""

    enabled: StrictBool = False
    diffusivity: NonNegative = Field(
        default=0.0, description="D in history-UV² per second (UV measured along the history height)."
    )

    @field_validator("diffusivity")
    @classmethod
    def _enabled_needs_rate(cls, value: float, info: ValidationInfo) -> float:
        if info.data.get("enabled") and value <= 0:
            raise rule_error("must be > 0 when diffusion is enabled")
        return value


class Tier(StrictModel):
    name: TierName = "full"
    historyScale: Annotated[Number, Field(gt=0, le=1)] | None = Field(
        default=None,
        description="History resolution / drawing-buffer resolution; default: the tier's largest.",
    )
    historyFormat: HistoryFormat = Field(
        default="auto",
        description="History storage; auto picks the most compact format that passes the quantisation gate.",
    )
    blurScale: Annotated[Number, Field(gt=0, le=1)] = Field(
        default=0.5, description="Blur pass resolution / drawing-buffer resolution."
    )

    @field_validator("historyScale")
    @classmethod
    def _within_tier(cls, value: float | None, info: ValidationInfo) -> float | None:
        tier = info.data.get("name")
        cap = TIER_MAX_HISTORY_SCALE.get(str(tier))
        if value is not None and cap is not None and value > cap:
            raise rule_error(f"tier {tier} allows at most {number(cap)} (got {number(value)})")
        return value

    @property
    def resolved_history_scale(self) -> float:
        return self.historyScale if self.historyScale is not None else TIER_MAX_HISTORY_SCALE[self.name]


class Update(StrictModel):
    policy: Literal["full-field", "dirty-tiles"] = "full-field"
    tileSize: Literal[8, 16, 32, 64] = 16
    idleWhenConverged: StrictBool = Field(
        default=True, description="Dispatch nothing once the history has converged and no input arrives."
    )
    convergenceTolerance: Annotated[Number, Field(gt=0, le=0.01)] = Field(
        default=1e-4, description="Largest |x − xEq| treated as converged."
    )


class Refraction(StrictModel):
    mainScreenPeriod: Positive = Field(default=480.0, description="Main normal period on screen, px.")
    mainStrength: NonNegative = Field(default=0.02, description="Main refraction offset scale, UV.")
    detailScreenPeriod: Positive = Field(default=96.0, description="Detail normal period on screen, px.")
    detailStrength: NonNegative = Field(default=0.006, description="Detail refraction offset scale, UV.")
    ior: Annotated[Number, Field(ge=1, le=3)] = Field(default=1.31, description="Index of refraction of ice.")
    thickness: Positive = Field(default=1.0, description="Relative slab thickness scaling the offset.")
    sourceInset: Annotated[Number, Field(ge=0, le=0.25)] = Field(
        default=0.02, description="UV inset that keeps refracted lookups inside the source."
    )
    fresnelStrength: UnitInterval = 0.5

    @field_validator("detailScreenPeriod")
    @classmethod
    def _detail_is_finer(cls, value: float, info: ValidationInfo) -> float:
        main = info.data.get("mainScreenPeriod")
        if main is not None and value >= main:
            raise rule_error(f"must be < mainScreenPeriod ({number(main)}); detail is the finer scale")
        return value


class Composite(StrictModel):
    tint: Color = Field(default="#dbeaf7", description="sRGB frost tint (decoded once to linear).")
    brightness: Annotated[Number, Field(ge=0, le=4)] = 1.5
    saturation: Annotated[Number, Field(ge=0, le=2)] = 0.5
    blurMix: UnitInterval = Field(default=1.0, description="Weight of the blurred scene under full frost.")
    maskLow: UnitInterval = Field(
        default=0.4,
        description="smoothstep lower edge of the frost mask (of 1 − thaw): thaw ≥ 1 − maskLow is clear.",
    )
    maskHigh: UnitInterval = Field(default=1.0, description="smoothstep upper edge of the frost mask.")
    opacity: UnitInterval = 1.0

    @field_validator("maskHigh")
    @classmethod
    def _edges_ordered(cls, value: float, info: ValidationInfo) -> float:
        low = info.data.get("maskLow")
        if low is not None and value <= low:
            raise rule_error(f"must be > maskLow ({number(low)})")
        return value


class Structure(StrictModel):
    """Static crystalline structure and normal maps, generated once in Python and shipped as data."""

    seed: Seed = 7
    resolution: Literal[64, 128, 256, 512, 1024, 2048] = 256
    # At least one cell: a crystal wider than the texture is no pattern (and its blur overflowed the bake).
    crystalScale: Annotated[Number, Field(ge=1)] = Field(
        default=6.0, description="Crystal cells across the texture (at least 1)."
    )
    branches: Annotated[StrictInt, Field(ge=1, le=16)] = 6
    # Bounded so the baking stays finite (a valid 1e308 overflowed it): sharper than 64 is a hairline,
    # and 32 times the default relief already reads as a flat mirror of spikes.
    ridgeSharpness: Annotated[Number, Field(gt=0, le=64)] = 2.0
    normalStrength: Annotated[Number, Field(ge=0, le=32)] = 1.0

    @field_validator("crystalScale")
    @classmethod
    def _cells_resolvable(cls, value: float, info: ValidationInfo) -> float:
        resolution = info.data.get("resolution")
        if resolution is not None and value > resolution / 4:
            raise rule_error(
                f"must be <= resolution / 4 ({number(resolution / 4)}): a crystal needs at least 4 texels"
            )
        return value


#: Most equal advances one catch-up frame may run: each costs about one ordinary frame's dispatches.
MAX_CATCH_UP_ADVANCES = 16


class TimePolicy(StrictModel):
    """What a negative, NaN or too-long interval does: never a silent clamp.

    A frame the browser stalls for a second or two (a hitch under load) is not a seek: the pointer kept
    moving and its timestamped segments are queued. Up to ``catchUpSeconds`` the interval is caught up as
    equal advances of at most ``maxIntervalSeconds``, so that input deposits in full; past it (a tab in
    the background for minutes, a seek) the declared discontinuity policy runs.
    """

    discontinuity: Literal["reset", "freeze"] = "reset"
    maxIntervalSeconds: Positive = Field(
        default=1.0,
        description="Longest interval one advance integrates; longer ones are caught up or jumps.",
    )
    catchUpSeconds: NonNegative = Field(
        default=4.0,
        description="Longest interval caught up (in advances of at most maxIntervalSeconds) before it is a "
        "discontinuity; at most maxIntervalSeconds turns catch-up off.",
    )

    @field_validator("catchUpSeconds")
    @classmethod
    def _catch_up_bounded(cls, value: float, info: ValidationInfo) -> float:
        longest = info.data.get("maxIntervalSeconds")
        if longest is not None and value > MAX_CATCH_UP_ADVANCES * longest:
            bound = number(MAX_CATCH_UP_ADVANCES * longest)
            raise rule_error(
                f"must be <= {MAX_CATCH_UP_ADVANCES} x maxIntervalSeconds ({bound}):"
                " each advance of a catch-up costs a frame's work; raise maxIntervalSeconds or lower this"
            )
        return value


class FrostEffectSpec(StrictModel):
    """A frozen pane that a pointer thaws and whose frost grows back, seen through refraction and blur."""

    schema_: str | None = Field(default=None, alias="$schema", description="JSON Schema of this file.")
    kind: Literal["frost"]
    name: Name = Field(description="Display name; the npm package name is its slug.")
    seed: Seed = 0
    history: History = Field(default_factory=History)
    brush: Brush = Field(default_factory=Brush)
    fades: Fades = Field(default_factory=Fades)
    diffusion: Diffusion = Field(default_factory=Diffusion)
    tier: Tier = Field(default_factory=Tier)
    update: Update = Field(default_factory=Update)
    refraction: Refraction = Field(default_factory=Refraction)
    composite: Composite = Field(default_factory=Composite)
    resizePolicy: Literal["clear", "preserve-remap"] = "clear"
    structure: Structure = Field(default_factory=Structure)
    time: TimePolicy = Field(default_factory=TimePolicy)
