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

import numpy as np
import numpy.typing as npt

from ..field import layout as col
from ..rig import CompiledRig
from ..spec import CharacterSpec

F64 = npt.NDArray[np.float64]


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


def build_skeleton(spec: CharacterSpec, rig: CompiledRig) -> Skeleton:
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
