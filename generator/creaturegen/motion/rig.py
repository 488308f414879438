"""Build-time motion data: which slots are legs, ropes and wings, rest frames, and the stated constants.

Everything here is plain numbers derived from the compiled rig and skeleton; ``build_motion``'s record
(motion/data.py) is what the package's core/data.js carries as ``CREATURE.motion`` (its JSON), and the
Python reference reads the same record, so the two cannot drift apart. Quantities that depend on gravity
(swing time, hop air time) are derived at runtime from the injected gravity provider, not here.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Final

from ..model import layout as col
from ..model.record import finite_record
from ..model.skeleton import Skeleton
from ..rig import CompiledRig
from ..spec import CharacterSpec, character
from ..spec.character import LocomotionType
from . import quat as vq
from .data import LegData, MotionConstants, MotionData, MotionGenes, RopeData, SizedFields, Vec3, WingData

#: Walkers, hoppers and swimmers circle at this many body lengths (flyers use their spec radius).
PATH_RADIUS_BODIES: Final = 6.0
#: Share of a leg's room to full extension (reachMax less its rest hip-foot distance) that an upright
#: body on a slope may ask of its downhill legs, so it sits higher than its lowest foot
#: (motion/root.py settle): halfway between its lowest and highest rest foot, where that room allows.
SETTLE_SLACK: Final = 0.25
#: Swing time ``SWING_FROUDE·sqrt(leg/g)`` (dynamic similarity: equal Froude number across leg lengths).
SWING_FROUDE: Final = 1.0
#: A foot lands this fraction of stepLength ahead of its home; it lifts when it lags stepLength behind.
STEP_LEAD: Final = 0.5
#: The lag that triggers a step is capped at this fraction of the shortest leg's horizontal reach at
#: rest hip height, so a stance never asks the IK for more than the leg has (the spec's stepLength is
#: kept and reported beside the cap).
REACH_STEP_FRACTION: Final = 0.6
#: IK reach clamp as a fraction of leg length (a + b): dist ∈ [|a−b| + m(a+b), (a+b)(1−m)].
REACH_MARGIN: Final = 1e-3
#: Hopper: crouch and landing durations (s), squash depth and air stretch (dimensionless).
HOP_CROUCH_S: Final = 0.12
HOP_LAND_S: Final = 0.12
HOP_SQUASH: Final = 0.18
HOP_STRETCH: Final = 0.12
#: A hopper's legs at the apex of a hop: each foot drawn up toward its hip, the hip-foot distance this
#: fraction of the way from the leg's shortest reach (reachMin) to its rest distance, so the knee folds
#: (shipped per leg as the dimensionless ``tuck``, the tucked distance over the rest one).
HOP_TUCK: Final = 0.55
#: A hopper on legs also sinks on them in the crouch and the landing: the root drops by this fraction of
#: the legs' mean rest hip height above their feet, on top of the squash (which shortens the legs with the
#: body and alone bends a knee by a tenth of a degree), so the knees fold as the body lowers. Shipped per
#: leg as ``crouch``; motion/derived.py turns it into the hop's ``dip`` (m).
HOP_CROUCH_DEPTH: Final = 0.15
#: Flap and undulation frequency from a Strouhal number ``f·A/U`` (A = tip excursion).
STROUHAL: Final = 0.3
#: Swimmer: critically damped response at ``SWIM_RESPONSE·√(g/L)`` rad/s.
SWIM_RESPONSE: Final = 1.0
#: Verlet ropes: substeps per tick, relaxation passes per substep, velocity damping per substep.
ROPE_SUBSTEPS: Final = 2
ROPE_PASSES: Final = 4
ROPE_DAMPING: Final = 0.02
#: Largest bend between consecutive rope segments (and between the first segment and its rest direction
#: on the body), degrees: a tail bends, it does not fold back on itself. Enforced in every relaxation pass
#: as a minimum distance 2·segment·cos(limit/2) between a node's neighbours.
ROPE_BEND_LIMIT_DEG: Final = 60.0

#: The walking locomotion types (spec/character.py, where validation reads them too).
WALKERS: Final = character.WALKERS
#: locomotion type -> its gait genes, each the motion-data fields one gene scales together
#: (motion/express.py express_gait): pace scales speed with step or hop length, so timing in ticks holds.
GAIT_GENES: Final[dict[str, tuple[tuple[str, ...], ...]]] = {
    **dict.fromkeys(WALKERS, (("speed", "stepLength"), ("stepHeight",))),
    "hopper": (("speed", "hopLength"), ("hopHeight",)),
    "flyer": (("speed",), ("pathRadius",), ("altitude",)),
    "swimmer": (("speed",), ("undulation",)),
}
#: The motion-data fields that are lengths, which an individual's size s scales (motion/express.py
#: express_size), and those that are speeds, which it scales by √s: Froude similarity (v²/gL held), so with
#: gravity unscaled every time derived from lengths, speeds and gravity (stance, swing, air, hop cycle, flap
#: and undulation periods) scales by √s alike and the gait keeps its proportions. The hopper's stated crouch
#: and landing times (HOP_CROUCH_S, HOP_LAND_S) are seconds and stay. Shipped as ``lengths`` so the JS core
#: scales the very same fields.
#: Directions, angles, cosines, ratios, counts and indices are neither.
SIZED_FIELDS: Final = SizedFields(
    speeds=("speed",),
    top=(
        "bodyScale",
        "groundY",
        "centreY",
        "pathRadius",
        "stepLength",
        "stepLengthSpec",
        "stepLimit",
        "stepHeight",
        "hopLength",
        "hopHeight",
        "altitude",
        "pivot",
    ),
    legs=("hip", "knee", "foot", "a", "b", "reachMin", "reachMax"),
    ropes=("rest", "before", "radius", "segment", "bendMin"),
    wings=("length",),
)
#: The stated constants the motion reads (this module's), shipped with the data.
CONSTANTS: Final = MotionConstants(
    swing_froude=SWING_FROUDE,
    step_lead=STEP_LEAD,
    settle_slack=SETTLE_SLACK,
    hop_crouch_s=HOP_CROUCH_S,
    hop_land_s=HOP_LAND_S,
    hop_squash=HOP_SQUASH,
    hop_stretch=HOP_STRETCH,
    strouhal=STROUHAL,
    swim_response=SWIM_RESPONSE,
    rope_substeps=ROPE_SUBSTEPS,
    rope_passes=ROPE_PASSES,
    rope_damping=ROPE_DAMPING,
    rope_bend_limit_deg=ROPE_BEND_LIMIT_DEG,
)


def _v(x: Iterable[float]) -> Vec3:
    a, b, c = (float(v) for v in x)
    return (a, b, c)


def _locomotion_fields(spec: CharacterSpec) -> dict[str, float]:
    """The spec's locomotion numbers by their JSON names (the type and absent fields left out)."""
    loco = spec.locomotion
    if loco is None:
        return {}
    dumped: dict[str, object] = loco.model_dump(exclude_none=True)
    return {k: v for k, v in dumped.items() if isinstance(v, int | float) and not isinstance(v, bool)}


def build_motion(spec: CharacterSpec, rig: CompiledRig, skeleton: Skeleton) -> MotionData:
    """``CREATURE.motion``: plain JSON numbers, read by the Python reference and the JS core alike. Every
    number is finite and none is -0 (model/record.py finite_record), so a JSON round trip of the data, or
    of an individual's copy (core/genome.js express), is exact."""
    kind: LocomotionType = spec.locomotion.type if spec.locomotion is not None else "none"
    slots = rig.slots
    by_part = _slots_by_part(rig)
    body = float(rig.body_scale)
    phases = sorted({float(p.phase or 0.0) for p in spec.parts if p.shape == "leg"})
    legs = _legs(spec, rig, by_part, phases)
    fields = _locomotion_fields(spec)
    step_spec = float(fields.get("stepLength", 0.0)) * spec.scale
    ground, step_limit = _ground_and_step_limit(legs, rig)
    roots = tuple(s for s in range(rig.slot_count) if skeleton.parent[s] < 0)
    centre_y = sum(0.5 * (float(slots[r, 1]) + float(slots[r, 5])) for r in roots) / len(roots)
    data = MotionData(
        type=kind,
        hz=int(fields.get("tickRate", 60)),
        speed=float(fields.get("speed", 0.0)),
        body_scale=body,
        ground_y=ground,
        centre_y=centre_y,
        path_radius=float(fields["radius"]) * spec.scale if kind == "flyer" else PATH_RADIUS_BODIES * body,
        step_length=min(step_spec, step_limit) if legs else step_spec,
        step_length_spec=step_spec,
        step_limit=step_limit,
        step_height=float(fields.get("stepHeight", 0.0)) * spec.scale,
        hop_length=float(fields.get("hopLength", 0.0)) * spec.scale,
        hop_height=float(fields.get("hopHeight", 0.0)) * spec.scale,
        altitude=float(fields.get("altitude", 0.0)) * spec.scale,
        undulation=float(fields.get("undulation", 0.0)),
        buoyancy=float(fields.get("buoyancy", 1.0)),
        groups=len(phases),
        legs=legs,
        ropes=_ropes(spec, rig, skeleton, by_part),
        wings=_wings(spec, rig, by_part),
        roots=roots,
        parent=tuple(skeleton.parent),
        order=tuple(skeleton.order),
        pivot=tuple(_v(p) for p in skeleton.pivot),
        constants=CONSTANTS,
        # Rope nodes of creatures that stand on the support stay above it by their radius.
        rope_ground=kind in WALKERS or kind == "hopper",
        genes=MotionGenes(
            jitter=spec.genetics.gait, fields=GAIT_GENES.get(kind, ()), size=spec.genetics.size
        ),
        lengths=SIZED_FIELDS,
    )
    return finite_record(data, "motion")


def _slots_by_part(rig: CompiledRig) -> dict[str, list[int]]:
    """Part id -> its slots, in slot order."""
    by_part: dict[str, list[int]] = {}
    for index, owner in enumerate(rig.slot_parts):
        by_part.setdefault(owner, []).append(index)
    return by_part


def _legs(
    spec: CharacterSpec, rig: CompiledRig, by_part: dict[str, list[int]], phases: list[float]
) -> tuple[LegData, ...]:
    """Every leg part's two slots, rest joints, bone lengths, knee hint and hinge, reach and phase group."""
    slots = rig.slots
    legs: list[LegData] = []
    for part in spec.parts:
        if part.shape != "leg":
            continue
        upper, lower = by_part[part.id]
        assert rig.slot_classes[upper] == "leg-upper"
        assert rig.slot_classes[lower] == "leg-lower"
        hip, knee, foot = _v(slots[upper, col.A]), _v(slots[upper, col.B]), _v(slots[lower, col.B])
        mid = [(hip[i] + foot[i]) * 0.5 for i in range(3)]
        hint = [knee[i] - mid[i] for i in range(3)]
        norm = math.sqrt(sum(c * c for c in hint)) or 1.0
        a = math.dist(hip, knee)
        b = math.dist(knee, foot)
        unit_hint = [c / norm for c in hint]
        reach_min = abs(a - b) + REACH_MARGIN * (a + b)
        drop = math.dist(hip, foot)
        reach = vq.normalize([foot[i] - hip[i] for i in range(3)])
        hinge = vq.normalize(vq.cross(reach, vq.gram_schmidt(unit_hint, reach)))
        legs.append(
            LegData(
                part=part.id,
                upper=upper,
                lower=lower,
                hip=hip,
                knee=knee,
                foot=foot,
                a=a,
                b=b,
                hint=_v(unit_hint),
                hinge=_v(hinge),
                group=phases.index(float(part.phase or 0.0)),
                reach_min=reach_min,
                reach_max=(a + b) * (1.0 - REACH_MARGIN),
                tuck=(reach_min + HOP_TUCK * (drop - reach_min)) / drop,
                crouch=HOP_CROUCH_DEPTH,
            )
        )
    return tuple(legs)


def _ropes(
    spec: CharacterSpec, rig: CompiledRig, skeleton: Skeleton, by_part: dict[str, list[int]]
) -> tuple[RopeData, ...]:
    """Every rope part's chain of slots, rest nodes and radii, segment length and bend limit."""
    slots = rig.slots
    ropes = []
    for part in spec.parts:
        if part.shape != "rope":
            continue
        chain = by_part[part.id]
        rest = [_v(slots[s, col.A]) for s in chain] + [_v(slots[chain[-1], col.B])]
        radius = [float(slots[s, col.RA]) for s in chain] + [float(slots[chain[-1], col.RB])]
        segment = math.dist(rest[0], rest[1])
        ropes.append(
            RopeData(
                part=part.id,
                slots=tuple(chain),
                parent=skeleton.parent[chain[0]],
                rest=tuple(rest),
                before=_v(2.0 * rest[0][i] - rest[1][i] for i in range(3)),
                radius=tuple(radius),
                segment=segment,
                bend_min=2.0 * segment * math.cos(math.radians(ROPE_BEND_LIMIT_DEG) / 2.0),
                bend_cos=math.cos(math.radians(ROPE_BEND_LIMIT_DEG)),
                bend_sin=math.sin(math.radians(ROPE_BEND_LIMIT_DEG)),
            )
        )
    return tuple(ropes)


def _wings(spec: CharacterSpec, rig: CompiledRig, by_part: dict[str, list[int]]) -> tuple[WingData, ...]:
    """Every flapping part's slot, flap side and amplitude, and length."""
    slots = rig.slots
    wings = []
    for part in spec.parts:
        if (part.shape != "capsule" and part.shape != "cone") or part.flap is None:
            continue
        (slot,) = by_part[part.id]
        start, end = _v(slots[slot, col.A]), _v(slots[slot, col.B])
        wings.append(
            WingData(
                part=part.id,
                slot=slot,
                sign=1.0 if end[0] >= start[0] else -1.0,
                amplitude=part.flap,
                length=math.dist(start, end),
            )
        )
    return tuple(wings)


def _ground_and_step_limit(legs: tuple[LegData, ...], rig: CompiledRig) -> tuple[float, float]:
    """The rest ground height (the legs' mean rest foot height, else the lowest point of any slot) and the
    cap on a step's lag (REACH_STEP_FRACTION of the shortest leg's horizontal reach at rest hip height, 0
    without legs)."""
    step_limit = 0.0
    if legs:
        ground = sum(leg.foot[1] for leg in legs) / len(legs)
        horizontal = [math.sqrt(max(leg.reach_max**2 - (leg.hip[1] - ground) ** 2, 0.0)) for leg in legs]
        step_limit = REACH_STEP_FRACTION * min(horizontal)
    else:
        ground = float(min(min(s[1] - s[3], s[5] - s[7]) for s in rig.slots.tolist()))
    return ground, step_limit
