"""Acceptance sweep: candidate programs against the full graph over the motion's poses and the envelope.

Certificates prove what they can; the sweep measures what a user would see. The poses are the rest pose,
the representative poses of the creature's measured motion (motion/envelope.py: real ticks of real gait,
hop, flap and swim cycles, modulo rigid body motion), and random poses that translate every slot by a
random vector inside its excursion ball (the envelope the certificates assume).
Sample points start uniform in each region and take two Newton steps toward the full field's zero set;
points that leave their region or the band τ are dropped. Measured per point: |Δd|, the angle between
the normals, the largest linear-channel colour error, and the OKLab distance of the colours.
All regions are sampled together and each distinct program is evaluated once over all its regions.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from ..field.sampler import sample_graph
from ..model import layout as col
from ..model.graph import BlendGraph
from ..model.rotations import Pose, posed_slots
from ..rig import CompiledRig
from ..rig.colour import linear_to_oklab
from .program import CandidateProgram


@dataclass(frozen=True)
class SweepResult:
    poses: int  # random envelope poses
    motion_poses: int  # poses of the measured motion
    points: int  # in-band samples evaluated, all poses together
    surface_error: float  # max |d_program − d_full|, m
    normal_angle_deg: float
    omitted_colour_error: float  # max linear-channel colour error of the programs (omitted leaves' effect)
    delta_e_oklab: float


def _pose(rig: CompiledRig, excursion: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Every slot translated by its own random vector, uniform in its excursion ball."""
    slots = rig.slots.copy()
    direction = rng.normal(size=(rig.slot_count, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    shift = direction * (excursion * rng.uniform(size=rig.slot_count) ** (1 / 3))[:, None]
    slots[:, col.A] += shift
    slots[:, col.B] += shift
    return slots


def _groups(programs: list[CandidateProgram]) -> dict[tuple[tuple[int, ...], BlendGraph], list[int]]:
    """Regions sharing one program (same leaves, same pruned graph)."""
    groups: dict[tuple[tuple[int, ...], BlendGraph], list[int]] = defaultdict(list)
    for i, program in enumerate(programs):
        groups[(program.leaves, program.graph)].append(i)
    return groups


def run_sweep(
    rig: CompiledRig,
    programs: list[CandidateProgram],
    excursion: np.ndarray,
    motion_poses: tuple[Pose, ...],
    band: float,
    k_floor: float,
    poses: int = 6,
    points_per_region: int = 32,
    seed: int = 20261121,
) -> SweepResult:
    rng = np.random.default_rng(seed)
    lo = np.array([p.lo for p in programs]).reshape(-1, 3)
    hi = np.array([p.hi for p in programs]).reshape(-1, 3)
    region = np.repeat(np.arange(len(programs)), points_per_region)
    groups = _groups(programs)
    worst = np.zeros(4)
    total = 0
    tables = [rig.slots, *(posed_slots(rig.slots, pose) for pose in motion_poses)]
    tables += [_pose(rig, excursion, rng) for _ in range(poses)]
    for slots in tables:
        p = rng.uniform(lo[region], hi[region])
        for _ in range(2):
            f = sample_graph(rig.graph, slots, p, k_floor)
            g2 = np.maximum((f.gradient**2).sum(axis=1), 1e-30)
            p = p - (f.distance / g2)[:, None] * f.gradient
        full = sample_graph(rig.graph, slots, p, k_floor)
        inside = (p >= lo[region]).all(axis=1) & (p <= hi[region]).all(axis=1)
        keep = inside & (np.abs(full.distance) <= band)
        for (leaves, graph), members in groups.items():
            idx = np.flatnonzero(keep & np.isin(region, members))
            if len(idx) == 0:
                continue
            total += len(idx)
            mine = sample_graph(graph, slots[list(leaves)], p[idx], k_floor)
            n_full = full.gradient[idx] / np.linalg.norm(full.gradient[idx], axis=1, keepdims=True)
            n_mine = mine.gradient / np.linalg.norm(mine.gradient, axis=1, keepdims=True)
            angle = np.degrees(np.arccos(np.clip((n_full * n_mine).sum(axis=1), -1.0, 1.0)))
            share = np.abs(full.color[idx] - mine.color).max(axis=1)
            delta_e = np.linalg.norm(linear_to_oklab(full.color[idx]) - linear_to_oklab(mine.color), axis=1)
            error = np.abs(mine.distance - full.distance[idx])
            worst = np.maximum(worst, [error.max(), angle.max(), share.max(), delta_e.max()])
    return SweepResult(poses, len(motion_poses), total, *(float(x) for x in worst))
