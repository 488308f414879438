"""The slot skeleton: which slot hangs from which, and where each joint pivots, in the rest pose.

Skinning binds the reference mesh to slots, so it needs the parent structure the rig compile flattened
away. Rules (part parents come from the spec; slots of one part chain in their canonical order):
- a leg's lower slot hangs from its upper slot at the knee; rope segment j+1 hangs from segment j;
- the first slot of a part hangs from the slot of its parent part nearest to the part's anchor point;
- a parentless part's first slot is a root (parent −1).
The pivot of a joint is where the child attaches: its ``a`` end for segments, and for a sphere the
closest point on the parent's axis to its centre (a sphere has no end to pivot about).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import numpy.typing as npt

from ..spec import CharacterSpec
from . import layout as col
from .rotations import Pose, rotation_matrix

F64 = npt.NDArray[np.float64]


class SlotTable(Protocol):
    """What the skeleton reads of a compiled rig (rig.CompiledRig has it): the rest slot table and, per
    slot, its part and its primitive class."""

    @property
    def slots(self) -> F64: ...
    @property
    def slot_parts(self) -> tuple[str, ...]: ...
    @property
    def slot_classes(self) -> tuple[str, ...]: ...
    @property
    def slot_count(self) -> int: ...


@dataclass(frozen=True)
class Skeleton:
    parent: tuple[int, ...]  # parent slot per slot, −1 for roots
    pivot: F64  # (S, 3) rest joint position of each slot (its a end for roots)
    names: tuple[str, ...]  # "part.<id>" or "part.<id>[j]" per slot, for gate messages

    @property
    def joints(self) -> list[tuple[int, int]]:
        """(parent, child) pairs, in slot order."""
        return [(p, c) for c, p in enumerate(self.parent) if p >= 0]

    @property
    def depth(self) -> list[int]:
        """Joints between each slot and its root (0 for roots)."""
        out = []
        for slot in range(len(self.parent)):
            count, walk = 0, slot
            while self.parent[walk] >= 0:
                walk, count = self.parent[walk], count + 1
            out.append(count)
        return out

    @property
    def order(self) -> tuple[int, ...]:
        """Slots parents first (by depth, then index): the order poses compose down the skeleton."""
        depth = self.depth
        return tuple(sorted(range(len(self.parent)), key=lambda s: (depth[s], s)))

    def neighbours(self, slot: int) -> set[int]:
        """The slot, its parent and its children: the slots a vertex of ``slot`` may blend with."""
        near = {slot}
        if self.parent[slot] >= 0:
            near.add(self.parent[slot])
        near.update(c for c, p in enumerate(self.parent) if p == slot)
        return near


def closest_on_segment(a: F64, b: F64, p: F64) -> F64:
    ab = b - a
    denom = float(ab @ ab)
    t = 0.0 if denom == 0.0 else min(1.0, max(0.0, float((p - a) @ ab) / denom))
    result: F64 = a + t * ab
    return result


def build_skeleton(spec: CharacterSpec, rig: SlotTable) -> Skeleton:
    """Slot parents and pivots from the spec's part parents and the compiled rest slots."""
    slots = rig.slots
    by_part: dict[str, list[int]] = {}
    for index, part in enumerate(rig.slot_parts):
        by_part.setdefault(part, []).append(index)
    parts = {p.id: p for p in spec.parts}
    parent = [-1] * rig.slot_count
    pivot = slots[:, col.A].copy()
    names: list[str] = []
    for pid, indices in by_part.items():
        multi = len(indices) > 1
        names.extend(f"part.{pid}[{j}]" if multi else f"part.{pid}" for j in range(len(indices)))
        for previous, current in itertools.pairwise(indices):
            parent[current] = previous
        first = indices[0]
        owner = parts[pid].parent
        if owner is None:
            continue
        anchor = slots[first, col.A]
        candidates = by_part[owner]
        gaps = [
            np.linalg.norm(closest_on_segment(slots[c, col.A], slots[c, col.B], anchor) - anchor)
            for c in candidates
        ]
        chosen = candidates[int(np.argmin(gaps))]
        parent[first] = chosen
        if rig.slot_classes[first] == "sphere":
            pivot[first] = closest_on_segment(slots[chosen, col.A], slots[chosen, col.B], anchor)
    ordered_names = [""] * rig.slot_count
    cursor = 0
    for indices in by_part.values():
        for index in indices:
            ordered_names[index] = names[cursor]
            cursor += 1
    return Skeleton(tuple(parent), pivot, tuple(ordered_names))


Bools = npt.NDArray[np.bool_]


def subtree(skeleton: Skeleton, slot: int) -> Bools:
    """(S,) the slot and every slot hanging below it: what moves when its joint turns."""
    parent = np.asarray(skeleton.parent)
    inside = np.zeros(parent.size, dtype=bool)
    inside[slot] = True
    while True:
        grown: Bools = inside | ((parent >= 0) & inside[np.maximum(parent, 0)])
        if (grown == inside).all():
            return grown
        inside = grown


def joint_frame(skeleton: Skeleton, rest_slots: F64, child: int) -> tuple[F64, F64, F64]:
    """The child's rest tangent and two bend axes perpendicular to it.

    A sphere child has no axis of its own, so its tangent runs from the pivot to its centre. The first
    bend axis is perpendicular to both the child's and the parent's tangent (the hinge that folds the
    child towards its parent); a straight chain falls back to the world axis least aligned with it, so
    the frame is deterministic.
    """
    a, b = rest_slots[child, col.A], rest_slots[child, col.B]
    scale = max(float(rest_slots[child, col.RA]), 1e-300)
    tangent = b - a
    if np.linalg.norm(tangent) <= 1e-9 * scale:
        tangent = a - skeleton.pivot[child]
    parent = skeleton.parent[child]
    parent_tangent = (
        rest_slots[parent, col.B] - rest_slots[parent, col.A]
        if parent >= 0
        else np.zeros(3, dtype=np.float64)
    )
    if np.linalg.norm(tangent) <= 1e-9 * scale:
        tangent = parent_tangent if np.linalg.norm(parent_tangent) > 0 else np.array([0.0, 1.0, 0.0])
    tangent = tangent / np.linalg.norm(tangent)
    e1 = np.cross(tangent, parent_tangent)
    if np.linalg.norm(e1) <= 1e-6 * max(float(np.linalg.norm(parent_tangent)), 1e-300):
        e1 = np.cross(tangent, np.eye(3)[int(np.argmin(np.abs(tangent)))])
    e1 = e1 / np.linalg.norm(e1)
    e2 = np.cross(tangent, e1)
    return tangent, e1, e2


def pose_joint(
    skeleton: Skeleton,
    rest_slots: F64,
    joint_child: int,
    bend_axis: int | npt.ArrayLike,
    bend_angle: float,
    twist_angle: float,
) -> Pose:
    """Turn ``joint_child`` and everything below it about its pivot; every other slot stays at rest.

    ``bend_axis`` is 0 or 1 (the axes of :func:`joint_frame`) or a vector, projected perpendicular to
    the child's tangent. The twist (about the rest tangent) is applied first, then the bend, so a twist
    spins the limb about its own axis whatever the bend. Angles in radians.
    """
    tangent, e1, e2 = joint_frame(skeleton, rest_slots, joint_child)
    if isinstance(bend_axis, int | np.integer):
        axis = (e1, e2)[int(bend_axis)]
    else:
        axis = np.asarray(bend_axis, dtype=np.float64).reshape(3)
        axis = axis - (axis @ tangent) * tangent
        if np.linalg.norm(axis) <= 1e-12 * max(float(np.linalg.norm(bend_axis)), 1e-300):
            if bend_angle != 0.0:
                raise ValueError("bend_axis is parallel to the child's tangent: that is a twist")
            axis = e1
    q = rotation_matrix(axis, bend_angle) @ rotation_matrix(tangent, twist_angle)
    pivot = skeleton.pivot[joint_child]
    pose = Pose.identity(len(skeleton.parent))
    moved = subtree(skeleton, joint_child)
    pose.rotations[moved] = q
    pose.translations[moved] = pivot - q @ pivot
    return pose
