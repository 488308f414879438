"""Candidate programs: per-region bounded evaluation of the body field, with certificates and a sweep."""

from __future__ import annotations

from dataclasses import dataclass, field

from ..field.floors import floors_for
from ..motion.compiled import CompiledCreature
from ..motion.envelope import PoseEnvelope, pose_envelope
from ..rig import CompiledRig
from .program import CandidateProgram, Certificate
from .regions import DEFAULT_TIER, TIERS, Tier, TierRejectedError, Tolerances, search
from .sweep import SweepResult, run_sweep

#: Band τ around the surface that programs must reproduce, as a fraction of the body size L.
BAND_FACTOR = 0.02
#: Accepted n-ary tail bound and sweep surface error, as a fraction of L.
TAIL_FACTOR = 1e-5
#: Accepted normal angle and OKLab colour distance between a program and the full graph.
MAX_NORMAL_ANGLE_DEG = 0.05
MAX_DELTA_E_OKLAB = 0.002

__all__ = [
    "DEFAULT_TIER",
    "TIERS",
    "CandidateProgram",
    "CandidateSet",
    "Certificate",
    "TierRejectedError",
    "build_candidates",
    "describe_candidates",
    "skin_note",
]


@dataclass(frozen=True)
class Gate:
    name: str
    value: float
    unit: str
    threshold: float

    @property
    def passed(self) -> bool:
        return self.value <= self.threshold


@dataclass(frozen=True)
class CandidateSet:
    tier: Tier
    k_used: int  # most leaves any region keeps: the bound of the runtime's dynamic loop
    programs: tuple[CandidateProgram, ...]
    skipped_outside: int
    skipped_inside: int
    sweep: SweepResult
    gates: tuple[Gate, ...] = field(default=())

    @property
    def certificate_count(self) -> int:
        return sum(len(p.certificates) for p in self.programs)


def tolerances(rig: CompiledRig) -> Tolerances:
    floors = floors_for(rig.body_scale)
    return Tolerances(
        band=BAND_FACTOR * rig.body_scale,
        tail=TAIL_FACTOR * rig.body_scale,
        weight_floor=floors.weight_floor,
        k_floor=floors.k_floor,
    )


def skin_note(tier: str) -> str:
    """Why a skin-represented tier has no candidate programs (the package's candidateNote)."""
    return (
        f"tier {tier}: skin representation, the full graph only where the skin departs (surface/skin_tier.py)"
    )


def build_candidates(
    creature: CompiledCreature, tier: str, envelope: PoseEnvelope | None = None
) -> CandidateSet:
    """Programs for every region, certified and swept; TierRejectedError names what could not be bounded.
    ``envelope`` is the motion envelope when the caller has it (the surface build does), else it is
    measured or read from its disk cache."""
    chosen = TIERS[tier]
    if chosen.skin is not None:
        raise TierRejectedError(skin_note(tier))
    rig = creature.rig
    tol = tolerances(rig)
    if envelope is None:
        envelope = pose_envelope(creature)
    found = search(rig, envelope.slot_excursion, chosen, tol)
    programs = found.programs
    result = run_sweep(rig, programs, envelope.slot_excursion, envelope.poses, tol.band, tol.k_floor)
    gates = (
        Gate("surfaceError", result.surface_error, "m", tol.tail),
        Gate("normalAngle", result.normal_angle_deg, "deg", MAX_NORMAL_ANGLE_DEG),
        Gate("omittedColourError", result.omitted_colour_error, "linear RGB", tol.weight_floor),
        Gate("deltaEOklab", result.delta_e_oklab, "1", MAX_DELTA_E_OKLAB),
    )
    failed = [g for g in gates if not g.passed]
    if failed:
        g = failed[0]
        raise TierRejectedError(
            f"tier {tier}: sweep gate {g.name} = {g.value:.4g} {g.unit} exceeds {g.threshold:.4g}"
        )
    k_used = max((len(p.leaves) for p in programs), default=0)
    return CandidateSet(
        chosen, k_used, tuple(programs), found.skipped_outside, found.skipped_inside, result, gates
    )


def describe_candidates(creature: CompiledCreature, tiers: tuple[str, ...]) -> dict[str, object]:
    """Per tier: accepted with its K, regions, certificates and sweep gates, or rejected with the reason."""
    out: dict[str, object] = {}
    for name in tiers:
        if TIERS[name].skin is not None:
            out[name] = {"status": "skin", "reason": skin_note(name)}
            continue
        try:
            found = build_candidates(creature, name)
        except TierRejectedError as exc:
            out[name] = {"status": "rejected", "reason": str(exc)}
            continue
        kinds: dict[str, int] = {}
        for program in found.programs:
            for cert in program.certificates:
                kinds[cert.kind] = kinds.get(cert.kind, 0) + 1
        out[name] = {
            "status": "accepted",
            "kAuthored": found.tier.k,
            "kUsed": found.k_used,
            "regions": len(found.programs),
            "distinctPrograms": len({(p.leaves, p.graph) for p in found.programs}),
            "skippedOutside": found.skipped_outside,
            "skippedInside": found.skipped_inside,
            "certificates": kinds,
            "sweep": {
                "poses": found.sweep.poses,
                "motionPoses": found.sweep.motion_poses,
                "points": found.sweep.points,
            },
            "gates": [
                {
                    "name": g.name,
                    "value": g.value,
                    "unit": g.unit,
                    "threshold": g.threshold,
                    "passed": g.passed,
                }
                for g in found.gates
            ],
        }
    return out
