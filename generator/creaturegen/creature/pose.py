"""Pose pages and the seeded LCG: how one instance's pose reaches the GPU, and where its variation comes from.

The pose of an instance is whatever the locomotion core (motion/simulate.py, core/motion/motion.js) left in
its per-slot quaternions and translations, ``x' = R(q_s)·x + t_s`` in creature-local space, plus the root
(position, heading cos/sin, squash) that the material applies once. The JS core writes them as float32
rows (core/pose.js writePoseRows, the same arithmetic in the same order as ``pose_rows``):

- per slot, POSE_ROWS vec4: (a, ra), (b, rb), (k, rgb), quaternion xyzw, (t, roundCone), where rgb is
  the individual's colour (model/genome.py genome_colours);
- after the slots, two root rows: (x, y, z, alive), (cos yaw, sin yaw, squash, size).

An individual's size s (model/genome.py) scales its rest geometry before the slot transforms: the rows
hold ``R(q_s)·(s·a) + t_s``, ``s·r`` and ``s·k``; the GPU scales every blend op's k (tsl/field.js) and each
rest vertex, centre of rotation and trust radius (tsl/body.js) by the root row's size, so the drawn body
is the certified one scaled by s.

The LCG is integer arithmetic, identical in Python and JS, so the reference reproduces any spawned
instance from its seed.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Final

import numpy as np
import numpy.typing as npt

from ..field.primitives import slot_uses_round_cone
from ..model import layout as col
from ..model.graph import BlendGraph
from ..model.rotations import Pose, quaternion_to_matrix
from ..motion import quat as vq
from ..rig import CompiledRig

F64 = npt.NDArray[np.float64]

#: Rows of four floats per slot in a pose page: (a, ra), (b, rb), (k, rgb), quaternion xyzw, (t, roundCone);
#: the shipped core/pose.js exports the same POSE_ROWS.
POSE_ROWS: Final = 5


def as_pose(quats: Sequence[Sequence[float]], trans: Sequence[Sequence[float]]) -> Pose:
    """Per-slot quaternions (xyzw) and translations as a rotations.Pose (what the numpy skinning consumes)."""
    q = np.asarray(quats, dtype=np.float64)
    return Pose(quaternion_to_matrix(q), np.asarray(trans, dtype=np.float64))


def sized_graph(graph: BlendGraph, size: float) -> BlendGraph:
    """The blend graph of an individual of ``size``: every op's blend width times ``size`` (the GPU scales
    each instruction's k by the root row's size, tsl/field.js)."""
    return dataclasses.replace(graph, ops=tuple(dataclasses.replace(op, k=op.k * size) for op in graph.ops))


def sized_slots(slots: F64, size: float) -> F64:
    """The slot table of an individual of ``size``: ends, radii and blend widths times ``size`` (the
    colours are the genome's business, see genome_colours)."""
    out = np.array(slots, dtype=np.float64, copy=True)
    for columns in (col.A, col.RA, col.B, col.RB, col.K):
        out[:, columns] = out[:, columns] * size
    return out


def pose_rows(
    rig: CompiledRig,
    quats: Sequence[Sequence[float]],
    trans: Sequence[Sequence[float]],
    colours: Sequence[Sequence[float]] | None = None,
    size: float = 1.0,
) -> npt.NDArray[np.float32]:
    """(S, POSE_ROWS, 4) float32 rows of one instance's pose page entry, as the JS core writes them;
    ``colours`` is the individual's per-slot linear rgb (model/genome.py), else the authored one;
    ``size`` its size factor (Motion.size)."""
    slots = sized_slots(rig.slots, size)
    t = np.asarray(trans, dtype=np.float64)
    rows = np.zeros((rig.slot_count, POSE_ROWS, 4))
    for s in range(rig.slot_count):
        rows[s, 0, :3] = np.array(vq.rotate(list(quats[s]), list(slots[s, col.A]))) + t[s]
        rows[s, 1, :3] = np.array(vq.rotate(list(quats[s]), list(slots[s, col.B]))) + t[s]
    rows[:, 0, 3] = slots[:, col.RA]
    rows[:, 1, 3] = slots[:, col.RB]
    rows[:, 2, 0] = slots[:, col.K]
    rows[:, 2, 1:4] = slots[:, col.RGB] if colours is None else np.asarray(colours, dtype=np.float64)
    rows[:, 3] = np.asarray(quats, dtype=np.float64)
    rows[:, 4, :3] = t
    rows[:, 4, 3] = slot_uses_round_cone(rig.slots)  # the certified body's choice, as CREATURE.roundCone
    return rows.astype(np.float32)


def root_rows(root: Sequence[float], alive: bool = True, size: float = 1.0) -> npt.NDArray[np.float32]:
    """(2, 4) float32 root rows: (x, y, z, alive), (cos yaw, sin yaw, squash, size)."""
    return np.array(
        [[root[0], root[1], root[2], float(alive)], [root[3], root[4], root[5], size]], dtype=np.float32
    )
