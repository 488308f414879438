"""CharacterSpec: the creature kind of spec (``"kind": "creature"``, the default).

Coordinates are Y up, +Z forward, metres. A child part's coordinates are relative to its parent's origin
plus the parent's anchor (its ``a``, else ``offset``, else ``hip``), accumulated along the parent chain.
A part is one model per ``shape`` and a locomotion one model per ``type`` (the walkers share one), in
tagged unions: a model lists exactly the fields its shape or type requires and accepts, and the tables
SHAPE_FIELDS and LOCOMOTION_FIELDS that the gate's rules read are derived from the models, so the gate,
the JSON Schema and the docs read the same source.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal, get_args

from pydantic import Field, StrictInt

from .colors import Color
from .types import (
    Ident,
    Name,
    NonNegative,
    Number,
    Positive,
    Seed,
    StrictModel,
    Vec3,
)

Shape = Literal["capsule", "sphere", "cone", "rope", "leg"]
LocomotionType = Literal[
    "none", "biped", "quadruped", "hexapod", "octopod", "walker", "hopper", "flyer", "swimmer"
]
WalkerType = Literal["biped", "quadruped", "hexapod", "octopod", "walker"]

#: Compiled primitive slots per part: one for round primitives, one per rope segment, two per leg.
FIXED_SLOTS: dict[str, int] = {"capsule": 1, "cone": 1, "sphere": 1, "leg": 2}

#: locomotion type -> number of leg parts it drives; types not listed here, in WALKER_LEG_COUNTS nor in
#: HOPPER_LEG_COUNTS accept any count.
LEG_COUNTS: dict[str, int] = {
    "biped": 2,
    "quadruped": 4,
    "hexapod": 6,
    "octopod": 8,
    "swimmer": 0,
}

#: Types whose legs walk: one gait (motion/gait.py) plants and lifts their feet by phase group, so they
#: differ only in the leg count they require. The motion reference, the envelope and the JS core read this
#: tuple (the JS core a copy of it, pinned by the motion parity test).
WALKERS: tuple[str, ...] = get_args(WalkerType)

#: Leg counts of the generic ``walker``: left/right pairs, one to four of them. More legs than eight would
#: outgrow a pose page's slot budget long before the gait cared.
WALKER_LEG_COUNTS: tuple[int, ...] = (2, 4, 6, 8)

#: Leg counts of a ``hopper``: none (the body hops on its own squash) or the two hind legs it hops on, a
#: kangaroo's or a frog's. Both legs plant, push off, tuck and land together (motion/hop.py
#: hop_legs), whatever their ``phase``.
HOPPER_LEG_COUNTS: tuple[int, ...] = (0, 2)

BLEND_KERNELS = ("log-sum-exp",)


def slots_of(shape: str, segments: int | None) -> int:
    """Primitive slots a part compiles to; the rig compiler and the maxParts rule share this count."""
    if shape == "rope":
        return segments or 0
    return FIXED_SLOTS.get(shape, 0)


_TICK_RATE = "Fixed steps per second of the locomotion driver; default 60."
_SPEED = "Ground or air speed, m/s."


class NoLocomotion(StrictModel):
    """A creature that stands still."""

    type: Literal["none"] = Field(description="Locomotion driver.")
    tickRate: Literal[60, 120] | None = Field(default=None, description=_TICK_RATE)


class WalkerLocomotion(StrictModel):
    """Legs that walk by phase group: the leg count is fixed by the type (``walker``: 2, 4, 6 or 8)."""

    type: WalkerType = Field(description="Locomotion driver.")
    tickRate: Literal[60, 120] | None = Field(default=None, description=_TICK_RATE)
    speed: NonNegative = Field(description=_SPEED)
    stepLength: Positive = Field(description="Foot lag that triggers a step, m.")
    stepHeight: Positive = Field(description="Swing arc apex above support, m.")


class HopperLocomotion(StrictModel):
    """A body that hops, on its own squash or on two hind legs."""

    type: Literal["hopper"] = Field(description="Locomotion driver.")
    tickRate: Literal[60, 120] | None = Field(default=None, description=_TICK_RATE)
    speed: NonNegative = Field(description=_SPEED)
    hopLength: Positive = Field(description="Horizontal distance per hop, m.")
    hopHeight: Positive = Field(description="Hop apex height, m.")


class FlyerLocomotion(StrictModel):
    """A flyer circling at an altitude."""

    type: Literal["flyer"] = Field(description="Locomotion driver.")
    tickRate: Literal[60, 120] | None = Field(default=None, description=_TICK_RATE)
    speed: NonNegative = Field(description=_SPEED)
    altitude: NonNegative = Field(description="Flight altitude above ground, m.")
    radius: Positive = Field(description="Flight circle radius, m.")


class SwimmerLocomotion(StrictModel):
    """A legless swimmer that undulates."""

    type: Literal["swimmer"] = Field(description="Locomotion driver.")
    tickRate: Literal[60, 120] | None = Field(default=None, description=_TICK_RATE)
    speed: NonNegative = Field(description=_SPEED)
    undulation: NonNegative = Field(description="Body undulation amplitude, rad.")
    buoyancy: Positive = Field(description="Rest depth response ratio; 1 is neutral.")


#: How the creature moves; which fields apply depends on ``type``.
Locomotion = Annotated[
    NoLocomotion | WalkerLocomotion | HopperLocomotion | FlyerLocomotion | SwimmerLocomotion,
    Field(discriminator="type"),
]
LOCOMOTION_MODELS: tuple[type[StrictModel], ...] = (
    NoLocomotion,
    WalkerLocomotion,
    HopperLocomotion,
    FlyerLocomotion,
    SwimmerLocomotion,
)


class Genetics(StrictModel):
    """How far one spawned individual may differ from the authored creature (each gene is a seeded draw in
    [-1, 1) times its bound). Colours mutate in OKLab on the authored sRGB colours: one hue rotation, chroma
    scale and lightness shift per individual, so the pattern of the body stays coherent. Gait genes scale
    the locomotion parameters of its type (walkers: pace, i.e. speed with stepLength, and stepHeight).
    Size scales a spawned individual as a whole (a similarity: its shape, blend widths and every length of
    its motion, never gravity), which keeps it inside the fixed-connectivity envelope the build certified.
    Morphology (girth, limb and tail proportions) bounds the build-time identities of
    ``build --population N``, never a spawn."""

    hue: Annotated[Number, Field(ge=0, le=180)] = Field(
        default=20.0, description="Largest hue rotation in the OKLab a-b plane, degrees."
    )
    chroma: Annotated[Number, Field(ge=0, le=0.5)] = Field(
        default=0.2, description="Largest relative change of OKLab chroma."
    )
    lightness: Annotated[Number, Field(ge=0, le=0.25)] = Field(
        default=0.06, description="Largest shift of OKLab lightness L (0..1)."
    )
    gait: Annotated[Number, Field(ge=0, le=0.25)] = Field(
        default=0.08,
        description="Largest relative change of each gait gene (a walker's step length stays "
        "within its reach limit).",
    )
    size: Annotated[Number, Field(ge=0, le=0.25)] = Field(
        default=0.08,
        description="Largest relative change of an individual's size at spawn: its whole body and every "
        "length of its motion scale by 1 + size·gene (a similarity of the certified body, so the same mesh; "
        "gravity is not scaled).",
    )
    morphology: Annotated[Number, Field(ge=0, le=0.25)] = Field(
        default=0.1,
        description="Largest relative change of girth, limb and tail length between the geometry "
        "identities of `creaturegen build --population N` (never at spawn: a new shape is a new mesh).",
    )


_ID = "Unique part id; blend refs and parents name parts by it."
_PARENT = "Id of the parent part."
_COLOR = "sRGB albedo: #rrggbb, #rgb or a CSS colour name (normalised to #rrggbb)."
_K = "Blend width of this leaf; default 0.6·r."
_K_CAP = "Upper bound on the effective blend width."
_A = "Segment start, relative to the parent anchor, m."
_B = "Segment end, relative to the parent anchor, m."
_FLAP = "Wing flap amplitude, rad."
Flap = Annotated[Number, Field(ge=0, le=math.pi / 2)]


class CapsulePart(StrictModel):
    """A segment from a to b, radius r at a and r2 (default r) at b."""

    id: Ident = Field(description=_ID)
    shape: Literal["capsule"]
    parent: Ident | None = Field(default=None, description=_PARENT)
    a: Vec3 = Field(description=_A)
    b: Vec3 = Field(description=_B)
    r: Positive = Field(description="Radius at a, m.")
    r2: Positive | None = Field(default=None, description="Radius at b (tapered capsule), m.")
    flap: Flap | None = Field(default=None, description=_FLAP)
    color: Color | None = Field(default=None, description=_COLOR)
    k: Positive | None = Field(default=None, description=_K)
    kCap: Positive | None = Field(default=None, description=_K_CAP)


class ConePart(StrictModel):
    """A segment from a to b, radius r at a and r2 at b."""

    id: Ident = Field(description=_ID)
    shape: Literal["cone"]
    parent: Ident | None = Field(default=None, description=_PARENT)
    a: Vec3 = Field(description=_A)
    b: Vec3 = Field(description=_B)
    r: Positive = Field(description="Radius at a, m.")
    r2: Positive = Field(description="Radius at b, m.")
    flap: Flap | None = Field(default=None, description=_FLAP)
    color: Color | None = Field(default=None, description=_COLOR)
    k: Positive | None = Field(default=None, description=_K)
    kCap: Positive | None = Field(default=None, description=_K_CAP)


class SpherePart(StrictModel):
    """A ball of radius r centred at offset (default the origin)."""

    id: Ident = Field(description=_ID)
    shape: Literal["sphere"]
    parent: Ident | None = Field(default=None, description=_PARENT)
    r: Positive = Field(description="Sphere radius, m.")
    offset: Vec3 | None = Field(default=None, description="Centre, relative to the parent anchor, m.")
    color: Color | None = Field(default=None, description=_COLOR)
    k: Positive | None = Field(default=None, description=_K)
    kCap: Positive | None = Field(default=None, description=_K_CAP)


class RopePart(StrictModel):
    """A chain of equal segments laid along -Z from its anchor, tapering from r to r·taper."""

    id: Ident = Field(description=_ID)
    shape: Literal["rope"]
    parent: Ident | None = Field(default=None, description=_PARENT)
    segments: Annotated[StrictInt, Field(ge=1, le=64)] = Field(description="Rope slots.")
    length: Positive = Field(description="Rope rest length, m.")
    r: Positive = Field(description="Radius at the anchor, m.")
    offset: Vec3 | None = Field(default=None, description="Anchor, relative to the parent anchor, m.")
    taper: Annotated[Number, Field(gt=0, le=1)] | None = Field(
        default=None, description="Rope tip radius as a fraction of r."
    )
    color: Color | None = Field(default=None, description=_COLOR)
    k: Positive | None = Field(default=None, description=_K)
    kCap: Positive | None = Field(default=None, description=_K_CAP)


class LegPart(StrictModel):
    """A two-bone leg hanging from its hip, knee bent toward +Z."""

    id: Ident = Field(description=_ID)
    shape: Literal["leg"]
    parent: Ident | None = Field(default=None, description=_PARENT)
    hip: Vec3 = Field(description="Leg hip joint, relative to the parent anchor, m.")
    upper: Positive = Field(description="Thigh length, m.")
    lower: Positive = Field(description="Shin length, m.")
    r: Positive = Field(description="Leg radius, m.")
    phase: Annotated[Number, Field(ge=0, lt=1)] | None = Field(
        default=None, description="Gait phase, cycles."
    )
    color: Color | None = Field(default=None, description=_COLOR)
    k: Positive | None = Field(default=None, description=_K)
    kCap: Positive | None = Field(default=None, description=_K_CAP)


#: One body part; which fields apply depends on ``shape``.
Part = Annotated[CapsulePart | SpherePart | ConePart | RopePart | LegPart, Field(discriminator="shape")]
PART_MODELS: tuple[type[StrictModel], ...] = (CapsulePart, SpherePart, ConePart, RopePart, LegPart)

#: Fields every part may carry, whatever its shape.
COMMON_PART_FIELDS = ("id", "shape", "parent", "color", "k", "kCap")


def _fields_by_tag(
    models: tuple[type[StrictModel], ...], tag: str, common: tuple[str, ...]
) -> dict[str, tuple[tuple[str, ...], tuple[str, ...]]]:
    """tag value -> (required fields, optional fields) beyond ``common``, read from the models."""
    table: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {}
    for model in models:
        own = {name: info for name, info in model.model_fields.items() if name not in common}
        required = tuple(name for name, info in own.items() if info.is_required())
        optional = tuple(name for name, info in own.items() if not info.is_required())
        for value in get_args(model.model_fields[tag].annotation):
            table[value] = (required, optional)
    return table


#: shape -> (required fields, optional fields) beyond COMMON_PART_FIELDS, read from the part models.
SHAPE_FIELDS = _fields_by_tag(PART_MODELS, "shape", COMMON_PART_FIELDS)

#: locomotion type -> fields it requires (no others are accepted besides ``type`` and ``tickRate``).
LOCOMOTION_FIELDS: dict[str, tuple[str, ...]] = {
    kind: required
    for kind, (required, _) in _fields_by_tag(LOCOMOTION_MODELS, "type", ("type", "tickRate")).items()
}


class Ref(StrictModel):
    """A blend-graph edge: exactly one of ``part`` or ``node`` (a tree node or an n-ary group)."""

    part: Ident | None = None
    node: Ident | None = None


class BlendNode(StrictModel):
    """Polynomial smooth-min of two children with a symmetric width ``k``."""

    id: Ident
    left: Ref
    right: Ref
    k: Positive = Field(description="Smooth-min width, m.")


class BlendGroup(StrictModel):
    """Order-independent n-ary smooth-min over its members."""

    id: Ident
    members: Annotated[list[Ref], Field(min_length=2)]
    kernel: Literal["log-sum-exp"] = "log-sum-exp"
    k: Positive = Field(description="Kernel width, m.")


class TreeBlend(StrictModel):
    """Explicit binary blend tree; several roots combine by hard min."""

    mode: Literal["tree"]
    roots: Annotated[list[Ref], Field(min_length=1)]
    nodes: list[BlendNode] = Field(default_factory=list)


class NaryBlend(StrictModel):
    """Symmetric n-ary groups; several roots combine by hard min."""

    mode: Literal["symmetric-nary"]
    roots: Annotated[list[Ref], Field(min_length=1)]
    groups: list[BlendGroup] = Field(default_factory=list)


Blend = Annotated[TreeBlend | NaryBlend, Field(discriminator="mode")]


class Look(StrictModel):
    """How the body is shaded. Each control is a uniform of the one material every page shares, so changing
    it at run time (``population.setLook``) is a uniform write: no material, pipeline or buffer is made."""

    roughness: Annotated[Number, Field(ge=0, le=1)] = Field(
        default=0.55, description="Surface roughness of the physically based material (0 mirror, 1 matte)."
    )
    metalness: Annotated[Number, Field(ge=0, le=1)] = Field(
        default=0.0, description="Metalness of the physically based material (creatures: 0)."
    )
    distanceRange: Annotated[Number, Field(gt=0, le=0.1)] = Field(
        default=0.005,
        description="The 'distance' debug view's colour range: ±this fraction of the body scale L.",
    )
    aoTaps: Annotated[StrictInt, Field(ge=0, le=8)] = Field(
        default=0,
        description="Field self-occlusion: distance taps along each vertex's normal (0: off). Darkens the "
        "albedo where the body folds onto itself (intra-body only); costs aoTaps field evaluations per "
        "vertex and deform.",
    )
    aoRadius: Annotated[Number, Field(gt=0, le=0.25)] = Field(
        default=0.05, description="How far along the normal the occlusion taps reach, a fraction of L."
    )


class CharacterSpec(StrictModel):
    """A creature: round primitives blended by smooth minimum into one signed distance field."""

    schema_: str | None = Field(default=None, alias="$schema", description="JSON Schema of this file.")
    kind: Literal["creature"] = "creature"
    name: Name = Field(description="Display name; the npm package name is its slug.")
    seed: Seed = Field(default=0, description="Seed of the creature's LCG (variation, noise).")
    scale: Annotated[Number, Field(gt=0, le=1000)] = Field(
        default=1.0, description="Multiplies every length and radius."
    )
    locomotion: Locomotion | None = None
    genetics: Genetics = Field(
        default_factory=Genetics, description="Bounds of per-individual variation drawn by spawn(seed)."
    )
    parts: Annotated[list[Part], Field(min_length=1)]
    blend: Blend | None = Field(default=None, description="Blend graph; omitted means the default graph.")
    look: Look = Field(default_factory=Look, description="Shading controls (uniforms: setLook changes them).")
    maxParts: Annotated[StrictInt, Field(ge=1, le=256)] = Field(
        default=64, description="Slot capacity per creature in the pose pages."
    )

    @property
    def slot_count(self) -> int:
        return sum(slots_of(p.shape, p.segments if isinstance(p, RopePart) else None) for p in self.parts)
