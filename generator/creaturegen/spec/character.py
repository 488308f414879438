"""CharacterSpec: the creature kind of spec (``"kind": "creature"``, the default).

Coordinates are Y up, +Z forward, metres. A child part's coordinates are relative to its parent's origin
plus the parent's anchor (its ``a``, else ``offset``, else ``hip``), accumulated along the parent chain.
One model per JSON object; which fields a shape or locomotion type needs lives in the tables below, so
the gate, the JSON Schema and the docs read the same source.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import ConfigDict, Field, StrictInt

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

#: Fields every part may carry, whatever its shape.
COMMON_PART_FIELDS = ("id", "shape", "parent", "color", "k", "kCap")

#: shape -> (required fields, optional fields) beyond COMMON_PART_FIELDS.
SHAPE_FIELDS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "capsule": (("a", "b", "r"), ("r2", "flap")),
    "cone": (("a", "b", "r", "r2"), ("flap",)),
    "sphere": (("r",), ("offset",)),
    "rope": (("segments", "length", "r"), ("offset", "taper")),
    "leg": (("hip", "upper", "lower", "r"), ("phase",)),
}

#: Compiled primitive slots per part: one for round primitives, one per rope segment, two per leg.
FIXED_SLOTS: dict[str, int] = {"capsule": 1, "cone": 1, "sphere": 1, "leg": 2}

#: locomotion type -> fields it requires (no others are accepted besides ``type``).
LOCOMOTION_FIELDS: dict[str, tuple[str, ...]] = {
    "none": (),
    "biped": ("speed", "stepLength", "stepHeight"),
    "quadruped": ("speed", "stepLength", "stepHeight"),
    "hexapod": ("speed", "stepLength", "stepHeight"),
    "octopod": ("speed", "stepLength", "stepHeight"),
    "walker": ("speed", "stepLength", "stepHeight"),
    "hopper": ("speed", "hopLength", "hopHeight"),
    "flyer": ("speed", "altitude", "radius"),
    "swimmer": ("speed", "undulation", "buoyancy"),
}

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
WALKERS: tuple[str, ...] = ("biped", "quadruped", "hexapod", "octopod", "walker")

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


def _part_schema_conditionals(schema: dict[str, Any]) -> None:
    """Per-shape required and allowed fields in the JSON Schema, generated from SHAPE_FIELDS."""
    rules = []
    for shape, (required, optional) in SHAPE_FIELDS.items():
        allowed = sorted({*COMMON_PART_FIELDS, *required, *optional})
        rules.append(
            {
                "if": {"properties": {"shape": {"const": shape}}, "required": ["shape"]},
                "then": {"required": list(required), "propertyNames": {"enum": allowed}},
            }
        )
    schema["allOf"] = rules


def _locomotion_schema_conditionals(schema: dict[str, Any]) -> None:
    """Per-type required and allowed fields in the JSON Schema, generated from LOCOMOTION_FIELDS."""
    schema["allOf"] = [
        {
            "if": {"properties": {"type": {"const": kind}}, "required": ["type"]},
            "then": {"required": list(fields), "propertyNames": {"enum": ["type", "tickRate", *fields]}},
        }
        for kind, fields in LOCOMOTION_FIELDS.items()
    ]


class Locomotion(StrictModel):
    """How the creature moves; which fields apply depends on ``type`` (see LOCOMOTION_FIELDS)."""

    model_config = ConfigDict(json_schema_extra=_locomotion_schema_conditionals)

    type: LocomotionType = Field(description="Locomotion driver.")
    tickRate: Literal[60, 120] | None = Field(
        default=None, description="Fixed steps per second of the locomotion driver; default 60."
    )
    speed: NonNegative | None = Field(default=None, description="Ground or air speed, m/s.")
    stepLength: Positive | None = Field(default=None, description="Foot lag that triggers a step, m.")
    stepHeight: Positive | None = Field(default=None, description="Swing arc apex above support, m.")
    hopLength: Positive | None = Field(default=None, description="Horizontal distance per hop, m.")
    hopHeight: Positive | None = Field(default=None, description="Hop apex height, m.")
    altitude: NonNegative | None = Field(default=None, description="Flight altitude above ground, m.")
    radius: Positive | None = Field(default=None, description="Flight circle radius, m.")
    buoyancy: Positive | None = Field(default=None, description="Rest depth response ratio; 1 is neutral.")
    undulation: NonNegative | None = Field(default=None, description="Body undulation amplitude, rad.")


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


class Part(StrictModel):
    """One body part. Which fields apply depends on ``shape`` (see SHAPE_FIELDS)."""

    model_config = ConfigDict(json_schema_extra=_part_schema_conditionals)

    id: Ident = Field(description="Unique part id; blend refs and parents name parts by it.")
    shape: Shape
    parent: Ident | None = Field(default=None, description="Id of the parent part.")
    a: Vec3 | None = Field(default=None, description="Segment start, relative to the parent anchor, m.")
    b: Vec3 | None = Field(default=None, description="Segment end, relative to the parent anchor, m.")
    offset: Vec3 | None = Field(default=None, description="Centre (sphere) or anchor (rope), m.")
    r: Positive | None = Field(default=None, description="Radius at a (or the sphere radius), m.")
    r2: Positive | None = Field(default=None, description="Radius at b (tapered capsule, cone), m.")
    k: Positive | None = Field(default=None, description="Blend width of this leaf; default 0.6·r.")
    kCap: Positive | None = Field(default=None, description="Upper bound on the effective blend width.")
    color: Color | None = Field(
        default=None, description="sRGB albedo: #rrggbb, #rgb or a CSS colour name (normalised to #rrggbb)."
    )
    segments: Annotated[StrictInt, Field(ge=1, le=64)] | None = Field(default=None, description="Rope slots.")
    length: Positive | None = Field(default=None, description="Rope rest length, m.")
    taper: Annotated[Number, Field(gt=0, le=1)] | None = Field(
        default=None, description="Rope tip radius as a fraction of r."
    )
    hip: Vec3 | None = Field(default=None, description="Leg hip joint, relative to the parent anchor, m.")
    upper: Positive | None = Field(default=None, description="Thigh length, m.")
    lower: Positive | None = Field(default=None, description="Shin length, m.")
    phase: Annotated[Number, Field(ge=0, lt=1)] | None = Field(
        default=None, description="Gait phase, cycles."
    )
    flap: Annotated[Number, Field(ge=0, le=math.pi / 2)] | None = Field(
        default=None, description="Wing flap amplitude, rad."
    )


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
    maxParts: Annotated[StrictInt, Field(ge=1, le=256)] = Field(
        default=64, description="Slot capacity per creature in the pose pages."
    )

    @property
    def slot_count(self) -> int:
        return sum(slots_of(p.shape, p.segments) for p in self.parts)
