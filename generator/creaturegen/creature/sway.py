"""The closed-form sway pose: the package's built-in, seekable animation, and its Python reference.

Until locomotion lands (a later issue), every creature idles with a sway: each joint turns about its
rest bend axis by ``θ_j(n) = A·sin(2π·(n + offset)/P + φ_j)`` at integer tick ``n``, composed down the
skeleton. It is a pure function of the tick, so ``seekTick(n)`` and ``stepTicks(n)`` must agree exactly,
and it moves every joint, so skinning and correction are exercised away from the rest pose.

The JS core (templates/creature/core/pose.js) implements these formulas in float64 in the same order;
the GPU receives float32 rows. Composition per slot, parents first (``order``):

    q_s = q_parent ⊗ axisAngle(axis_s, θ_s),
    t_s = R(q_parent)·(pivot_s − R(axisAngle)·pivot_s) + t_parent,

so a posed point is ``x' = R(q_s)·x + t_s`` (deform.Pose), and roots stay at rest (the instance's root
transform carries root motion, applied once on the GPU).

Per-instance offsets come from the seeded LCG (``lcg_next``): integer arithmetic, identical in Python and
JS, so the reference reproduces any spawned instance's pose from its seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from ..field import layout as col
from ..field.primitives import slot_uses_round_cone
from ..motion import quat as vq
from ..rig import CompiledRig
from ..surface.deform import Pose, joint_frame, quaternion_to_matrix
from ..surface.skeleton import Skeleton

F64 = npt.NDArray[np.float64]

#: Sway period in ticks (2 s at 60 Hz) and amplitude (degrees); phase step per joint depth (radians).
PERIOD_TICKS: Final = 120
AMPLITUDE_DEG: Final = 12.0
PHASE_PER_DEPTH: Final = 0.7
#: Rows of four floats per slot in a pose page: (a, ra), (b, rb), (k, rgb), quaternion xyzw, (t, roundCone).
POSE_ROWS: Final = 5
#: Numerical Recipes LCG, modulo 2³².
LCG_A: Final = 1664525
LCG_C: Final = 1013904223


@dataclass(frozen=True)
class Sway:
    """Everything the sway needs, computed once at build time in float64."""

    parent: tuple[int, ...]
    order: tuple[int, ...]  # parents before children
    pivot: F64  # (S, 3)
    axis: F64  # (S, 3) unit bend axis (zero for roots)
    phase: F64  # (S,)
    amplitude: float  # radians
    period: int


def lcg_next(state: int) -> int:
    return (LCG_A * state + LCG_C) % (1 << 32)


def instance_offset(seed: int) -> tuple[int, float]:
    """(tick offset in [0, P), yaw in [0, 2π)) of a spawned instance: two LCG draws from its seed."""
    first = lcg_next(seed % (1 << 32))
    second = lcg_next(first)
    return first % PERIOD_TICKS, second / 4294967296.0 * 2.0 * math.pi


def build_sway(rig: CompiledRig, skeleton: Skeleton) -> Sway:
    depth = skeleton.depth
    axis = np.zeros((rig.slot_count, 3))
    for _, child in skeleton.joints:
        axis[child] = joint_frame(skeleton, rig.slots, child)[1]
    phase = np.array([PHASE_PER_DEPTH * d for d in depth], dtype=np.float64)
    return Sway(
        skeleton.parent,
        skeleton.order,
        skeleton.pivot.copy(),
        axis,
        phase,
        math.radians(AMPLITUDE_DEG),
        PERIOD_TICKS,
    )


def _axis_angle(axis: F64, angle: float) -> F64:
    half = 0.5 * angle
    s = math.sin(half)
    return np.array([axis[0] * s, axis[1] * s, axis[2] * s, math.cos(half)])


def sway_transforms(sway: Sway, tick: int) -> tuple[F64, F64]:
    """Per-slot quaternions (S, 4) xyzw and translations (S, 3) at integer ``tick``."""
    count = len(sway.parent)
    quats = np.zeros((count, 4))
    trans = np.zeros((count, 3))
    phase_of_tick = 2.0 * math.pi * ((tick % sway.period) / sway.period)
    for s in sway.order:
        p = sway.parent[s]
        if p < 0:
            quats[s] = (0.0, 0.0, 0.0, 1.0)
            continue
        angle = sway.amplitude * math.sin(phase_of_tick + float(sway.phase[s]))
        local = _axis_angle(sway.axis[s], angle)
        pivot = sway.pivot[s]
        turned = np.array(vq.rotate(list(local), list(pivot)))
        quats[s] = vq.mul(list(quats[p]), list(local))
        trans[s] = np.array(vq.rotate(list(quats[p]), list(pivot - turned))) + trans[p]
    return quats, trans


def sway_pose(sway: Sway, tick: int) -> Pose:
    """The sway at ``tick`` as a deform.Pose (what the numpy skinning reference consumes)."""
    quats, trans = sway_transforms(sway, tick)
    wxyz = np.concatenate([quats[:, 3:4], quats[:, :3]], axis=1)
    return Pose(quaternion_to_matrix(wxyz), trans)


def pose_rows(rig: CompiledRig, quats: F64, trans: F64) -> npt.NDArray[np.float32]:
    """(S, POSE_ROWS, 4) float32 rows of one instance's pose page entry, as the JS core writes them."""
    slots = rig.slots
    rows = np.zeros((rig.slot_count, POSE_ROWS, 4))
    for s in range(rig.slot_count):
        rows[s, 0, :3] = np.array(vq.rotate(list(quats[s]), list(slots[s, col.A]))) + trans[s]
        rows[s, 1, :3] = np.array(vq.rotate(list(quats[s]), list(slots[s, col.B]))) + trans[s]
    rows[:, 0, 3] = slots[:, col.RA]
    rows[:, 1, 3] = slots[:, col.RB]
    rows[:, 2, 0] = slots[:, col.K]
    rows[:, 2, 1:4] = slots[:, col.RGB]
    rows[:, 3] = quats
    rows[:, 4, :3] = trans
    rows[:, 4, 3] = slot_uses_round_cone(slots)
    return rows.astype(np.float32)
