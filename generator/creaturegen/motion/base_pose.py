"""The base pose: per-slot local rotations composed down the skeleton.

Stage 2 of a tick (simulate.py): the flyer's bank and flap (flight.py) and the swimmer's undulation
(swim.py), identity otherwise, composed from the roots down about each slot's pivot. The legs and ropes
stages then overwrite their own slots (the last stage touching a slot wins).
"""

from __future__ import annotations

from . import quat as vq
from .data import MotionData
from .flight import wing_locals
from .quat import Vec
from .state import MotionState
from .swim import undulation_locals


def base_pose(m: MotionState, time: float) -> None:
    """Every slot's base pose at ``time`` into the state's quaternions and translations."""
    data, d = m.data, m.d
    if m.kind != "flyer" and not (m.kind == "swimmer" and d.undulation_hz > 0.0):
        # No local rotation at any time: the same pose every tick, composed once (then copied).
        if m.rest_pose is None:
            compose_base(data, {}, m.quats, m.trans)
            m.rest_pose = ([list(q) for q in m.quats], [list(t) for t in m.trans])
        quats, trans = m.rest_pose
        for s in data.order:
            m.quats[s], m.trans[s] = list(quats[s]), list(trans[s])
        return
    locals_ = wing_locals(data, d, time) if m.kind == "flyer" else undulation_locals(data, d, time)
    compose_base(data, locals_, m.quats, m.trans)


def compose_base(
    data: MotionData, locals_: dict[int, list[float]], quats: list[list[float]], trans: list[Vec]
) -> None:
    """Per-slot local rotations (identity where absent) composed down the skeleton about the pivots, into
    ``quats`` and ``trans``."""
    parent, pivot = data.parent, data.pivot
    for s in data.order:
        local = locals_.get(s, list(vq.IDENTITY))
        pv = pivot[s]
        turned = vq.rotate(local, pv)
        arm = [pv[0] - turned[0], pv[1] - turned[1], pv[2] - turned[2]]
        p = parent[s]
        if p < 0:
            quats[s] = local
            trans[s] = arm
        else:
            quats[s] = vq.mul(quats[p], local)
            moved = vq.rotate(quats[p], arm)
            tp = trans[p]
            trans[s] = [moved[0] + tp[0], moved[1] + tp[1], moved[2] + tp[2]]
