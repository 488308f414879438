"""The pose/morphology envelope: how far each slot may move from its rest position.

Until locomotion lands, the envelope is the rest pose widened by each part's declared excursion,
inherited by its children (a child moves with its parent):
- leg: its whole reach, upper + lower (the foot can be anywhere the leg reaches);
- rope: its rest length (a tail can swing anywhere within it);
- flap: a wing rotating by ±flap about ``a`` moves its far end by 2·|b − a|·sin(flap/2);
- hopper: squash s ∈ [SQUASH_MIN, 1/SQUASH_MIN] scales positions by up to |1/√s − 1| about the origin;
- swimmer: undulation θ rotates the body about the origin, moving a point by 2·|p|·sin(θ/2).
Whole-body rigid motion (root translation, flight bank) does not move slots relative to each other.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from ..field import layout as col
from ..rig import CompiledRig
from ..spec import CharacterSpec
from ..spec.character import Part

SQUASH_MIN = 0.7


def _own_excursion(part: Part, scale: float) -> float:
    if part.shape == "leg":
        return (float(part.upper or 0.0) + float(part.lower or 0.0)) * scale
    if part.shape == "rope":
        return float(part.length or 0.0) * scale
    if part.flap and part.a is not None and part.b is not None:
        length = math.dist(part.a, part.b) * scale
        return 2.0 * length * math.sin(part.flap / 2.0)
    return 0.0


def part_excursions(spec: CharacterSpec) -> dict[str, float]:
    """Excursion of each part: its own plus its ancestors' (children ride on their parents)."""
    by_id = {p.id: p for p in spec.parts}
    done: dict[str, float] = {}

    def total(pid: str) -> float:
        if pid not in done:
            part = by_id[pid]
            inherited = total(part.parent) if part.parent is not None else 0.0
            done[pid] = inherited + _own_excursion(part, spec.scale)
        return done[pid]

    return {p.id: total(p.id) for p in spec.parts}


def slot_excursions(spec: CharacterSpec, rig: CompiledRig) -> npt.NDArray[np.float64]:
    """Per-slot excursion radius (S,), metres."""
    by_part = part_excursions(spec)
    e = np.array([by_part[p] for p in rig.slot_parts], dtype=np.float64)
    reach = np.maximum(
        np.linalg.norm(rig.slots[:, col.A], axis=1), np.linalg.norm(rig.slots[:, col.B], axis=1)
    )
    locomotion = spec.locomotion.type if spec.locomotion else "none"
    if locomotion == "hopper":
        e += reach * (1.0 / math.sqrt(SQUASH_MIN) - 1.0)
    elif locomotion == "swimmer" and spec.locomotion is not None:
        e += 2.0 * reach * math.sin(float(spec.locomotion.undulation or 0.0) / 2.0)
    return e
