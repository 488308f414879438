"""The motion data as typed records: what motion/rig.py ``build_motion`` derives from the rig and skeleton,
what the Python reference (motion/simulate.py and its stages) reads, and what core/data.js ships as
``CREATURE.motion``.

The records are frozen (an individual's copy, motion/express.py, replaces fields and never aliases the
authored data) and their JSON (model/record.py ``to_json``) is the shipped object, key for key. The
package's TypeScript interfaces of the same shapes are rendered from these classes (emit/tstypes.py), so
a field added here is declared there too; the attribute docstrings below become the interfaces' comments.
Lengths are creature-local metres, angles radians unless named otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated

from ..model.record import JsonRecord, TsName
from ..spec.character import LocomotionType

#: A point or direction in creature-local space (the package's ``Vec3``).
Vec3 = Annotated[tuple[float, float, float], TsName("Vec3")]


@dataclass(frozen=True, slots=True)
class LegData(JsonRecord):
    """One leg of a walker or hopper (two slots: upper and lower), rest geometry in creature-local metres."""

    part: str
    upper: int
    """Slot of the thigh (hip to knee)."""
    lower: int
    """Slot of the shin (knee to foot)."""
    hip: Vec3
    knee: Vec3
    foot: Vec3
    a: float
    """Thigh length."""
    b: float
    """Shin length."""
    hint: Vec3
    """Unit direction from the hip-foot midpoint to the rest knee: the side the knee bends to."""
    hinge: Vec3
    """The knee's rest hinge axis (normal of the hip-knee-foot plane): the slot frames' second axis, so the
    bones never twist as the leg swings (motion/ik.py)."""
    group: int
    """Phase group: one group swings at a time."""
    reach_min: float
    """Shortest hip-foot distance the IK allows."""
    reach_max: float
    """Longest hip-foot distance the IK allows (just short of full extension)."""
    tuck: float
    """A hopper's foot at the apex: hip + (foot − hip)·tuck (a ratio, so an individual's size scales it
    with hip and foot)."""
    crouch: float
    """Share of the legs' rest hip height a hopper on legs sinks by in its crouch and landing."""


@dataclass(frozen=True, slots=True)
class RopeData(JsonRecord):
    """A rope part (tail, tentacle): a chain of slots simulated follow-the-leader."""

    part: str
    slots: tuple[int, ...]
    """The chain's slots, anchor first."""
    parent: int
    """The slot the anchor rides on."""
    rest: tuple[Vec3, ...]
    """Rest nodes: every slot's start, then the last slot's end."""
    before: Vec3
    """The rest point one segment before the anchor, on the body: the bend limit's first reference."""
    radius: tuple[float, ...]
    """Radius at every node (creatures on a support keep their nodes this far above it)."""
    segment: float
    """Rest length of every segment."""
    bend_min: float
    """Least distance between a node's neighbours: the bend limit as a relaxation constraint."""
    bend_cos: float
    """Cosine of the bend limit: the follow-the-leader pass's cone (motion/ropes.py follow)."""
    bend_sin: float
    """Sine of the bend limit."""


@dataclass(frozen=True, slots=True)
class WingData(JsonRecord):
    """A flapping part: one slot turned about Z at the flap frequency."""

    part: str
    slot: int
    sign: float
    """+1 for a wing reaching toward +x, −1 toward −x, so the wings of both sides flap as mirror images."""
    amplitude: float
    """Flap amplitude, radians."""
    length: float


@dataclass(frozen=True, slots=True)
class MotionConstants(JsonRecord):
    """The stated constants the motion reads (motion/rig.py, where each is explained), shipped with the data
    so the JS core never restates them."""

    swing_froude: float
    step_lead: float
    settle_slack: float
    hop_crouch_s: float
    hop_land_s: float
    hop_squash: float
    hop_stretch: float
    strouhal: float
    swim_response: float
    rope_substeps: int
    rope_passes: int
    rope_damping: float
    rope_bend_limit_deg: float


@dataclass(frozen=True, slots=True)
class MotionGenes(JsonRecord):
    """Gait genes: ``fields[i]`` lists the motion fields gene i scales by 1 + jitter·gene; ``size`` bounds
    the size gene."""

    jitter: float
    fields: tuple[tuple[str, ...], ...]
    size: float


@dataclass(frozen=True, slots=True)
class SizedFields(JsonRecord):
    """Motion fields scaled with an individual's size, by group: lengths by the size, speeds by its square
    root (motion/rig.py SIZED_FIELDS), so the JS core scales the very same fields."""

    speeds: tuple[str, ...]
    top: tuple[str, ...]
    legs: tuple[str, ...]
    ropes: tuple[str, ...]
    wings: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class MotionData(JsonRecord):
    """CREATURE.motion: what createMotion runs (creaturegen's motion/rig.py build_motion, as JSON)."""

    type: Annotated[LocomotionType, TsName("LocomotionType")]
    hz: int
    """Fixed steps per second."""
    speed: float
    """Along the path, m/s."""
    body_scale: float
    ground_y: float
    """Rest height of the ground: the legs' mean rest foot height, else the body's lowest point."""
    centre_y: float
    path_radius: float
    """Radius of the circle the creature travels."""
    step_length: float
    """The lag that lifts a foot: the spec's step length, capped by the legs' reach (stepLimit)."""
    step_length_spec: float
    step_limit: float
    step_height: float
    hop_length: float
    hop_height: float
    altitude: float
    undulation: float
    buoyancy: float
    groups: int
    """Phase groups of the legs."""
    legs: tuple[LegData, ...]
    ropes: tuple[RopeData, ...]
    wings: tuple[WingData, ...]
    roots: tuple[int, ...]
    """Slots without a parent."""
    parent: tuple[int, ...]
    """Every slot's parent slot (−1 at a root)."""
    order: tuple[int, ...]
    """Slots, parents before children."""
    pivot: tuple[Vec3, ...]
    """Every slot's pivot: where it turns about its parent."""
    constants: MotionConstants
    rope_ground: bool
    """Rope nodes stay above the support by their radius (creatures that stand on one)."""
    genes: MotionGenes
    lengths: SizedFields
