"""The compiled creature: a spec with what every later stage reads of it, built once per build.

The rig (slots and blend graph), the skeleton and the motion data are pure functions of the spec. The
motion envelope, the candidate programs, the surface and the plan all read them, so the pipeline builds
them here, once, and hands the bundle down the stages (rig → skeleton → motion data → envelope →
candidates → surface → plan) instead of each stage rebuilding what it needs. The lab's reference
(creature/reference.py) rebuilds them from the package's shipped spec on purpose: it checks a package
independently of the build that made it.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..model.skeleton import Skeleton, build_skeleton
from ..rig import CompiledRig, compile_rig
from ..spec import CharacterSpec
from .data import MotionData
from .rig import build_motion


@dataclass(frozen=True)
class CompiledCreature:
    spec: CharacterSpec
    rig: CompiledRig
    skeleton: Skeleton
    motion: MotionData


def compile_creature(spec: CharacterSpec) -> CompiledCreature:
    """Rig, skeleton and motion data of ``spec``. Raises RigCompileError for a spec the rig compiler
    refuses and MotionRangeError for a motion that cannot be stepped, both naming the place."""
    rig = compile_rig(spec)
    skeleton = build_skeleton(spec, rig)
    return CompiledCreature(spec, rig, skeleton, build_motion(spec, rig, skeleton))
