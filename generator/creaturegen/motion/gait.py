"""The legged gait of a walker: feet planted in the support frame, lifted by phase group.

Stage 3 of a tick (simulate.py): the gait plants feet in the support frame → world target → inverse root
transform → body-frame IK → creature-local leg slots. A planted foot stays where it landed in the support
frame; it lifts when it lags stepLength behind its home (the rest foot under the root) and its group's lift
window is open, and lands stepLead·stepLength ahead of where its home will be when the swing ends. One
phase group swings at a time, so the other groups' feet stay down. The leg placement (IK and the leg gates)
is shared with the hopper's legs (hop.py).
"""

from __future__ import annotations

import math

from ..model.trig import pcos, psin
from . import quat as vq
from .data import LegData
from .ik import solve_leg
from .providers import Frame, to_local, to_world
from .quat import Vec
from .root import path, to_local_root, to_world_root
from .state import Foot, MotionState


def home(leg: LegData, frame: Frame, root: list[float]) -> Vec:
    """Support-local home of a foot: the rest foot under ``root``, on the support ``frame``."""
    local = to_local(frame, to_world_root(root, leg.foot))
    return [local[0], 0.0, local[2]]


def initial_plant(m: MotionState, leg: LegData, frame: Frame) -> Vec:
    """Where a steady gait would have this foot at tick 0: group g last landed (cycle − swing − g·W)
    ticks of travel ago at stepLead·s ahead of its home, so every group lifts as its window opens."""
    data, d = m.data, m.d
    at_home = home(leg, frame, m.root)
    if data.speed <= 0.0:
        return at_home
    lead = data.constants.step_lead * data.step_length
    back = data.speed * d.dt * (d.cycle - d.swing - leg.group * d.window)
    psi = path(m, 0.0)[2]
    offset = lead - back
    return [at_home[0] + psin(psi) * offset, 0.0, at_home[2] + pcos(psi) * offset]


def walk(m: MotionState, n: int, frame: Frame, integrate: bool) -> None:
    """Tick ``n`` of a walker's legs: plant, lift or swing each foot, then place its leg."""
    data, d, gates = m.data, m.d, m.gates
    step_length = data.step_length
    lead = data.constants.step_lead * step_length
    phase = n % d.cycle
    swinging = 0
    for leg, foot in zip(data.legs, m.feet, strict=True):
        if not integrate:
            foot.planted, foot.p = True, initial_plant(m, leg, frame)
        elif not foot.planted and n - foot.n0 >= d.swing:
            foot.planted, foot.p = True, list(foot.t)
        if foot.planted and integrate:
            at_home = home(leg, frame, m.root)
            du, dw = at_home[0] - foot.p[0], at_home[2] - foot.p[2]
            lag = math.sqrt(du * du + dw * dw)
            k = phase - leg.group * d.window
            if lag > step_length and 0 <= k <= d.window - d.swing:
                ahead = home(leg, *m.root_at(n + d.swing))
                du, dw = ahead[0] - foot.p[0], ahead[2] - foot.p[2]
                dl = math.sqrt(du * du + dw * dw)
                foot.planted, foot.n0, foot.s = False, n, list(foot.p)
                foot.t = [ahead[0], 0.0, ahead[2]]
                if dl > 0.0:
                    foot.t = [ahead[0] + du / dl * lead, 0.0, ahead[2] + dw / dl * lead]
                gates.steps += 1
        if foot.planted:
            local = foot.p
        else:
            swinging += 1
            tau = (n - foot.n0) / d.swing
            sigma = tau * tau * (3.0 - 2.0 * tau)
            lift = data.step_height * (4.0 * tau * (1.0 - tau))
            local = [
                foot.s[0] + (foot.t[0] - foot.s[0]) * sigma,
                lift,
                foot.s[2] + (foot.t[2] - foot.s[2]) * sigma,
            ]
        place_leg(m, leg, foot, to_local_root(m.root, to_world(frame, local)), frame)
    count_planted(m, swinging)


def place_leg(m: MotionState, leg: LegData, foot: Foot, target: Vec, frame: Frame) -> None:
    """Two-bone IK toward ``target`` (creature frame) into the leg's slots, and the leg gates."""
    gates = m.gates
    ik = solve_leg(leg, target)
    m.quats[leg.upper], m.trans[leg.upper] = ik.q_upper, ik.t_upper
    m.quats[leg.lower], m.trans[leg.lower] = ik.q_lower, ik.t_lower
    span = leg.a + leg.b
    gates.ik_residual = max(gates.ik_residual, ik.residual)
    drawn = vq.rotate(ik.q_lower, leg.foot)
    drawn = [drawn[0] + ik.t_lower[0], drawn[1] + ik.t_lower[1], drawn[2] + ik.t_lower[2]]
    gates.drawn_foot = max(gates.drawn_foot, vq.distance(drawn, ik.foot) / span)
    if ik.clamped:
        gates.clamped_ticks += 1
    elif foot.planted:
        back = to_local(frame, to_world_root(m.root, drawn))
        gates.plant_drift = max(gates.plant_drift, vq.distance(back, foot.p) / span)
        gates.planted_samples += 1


def count_planted(m: MotionState, swinging: int) -> None:
    """The stance gates of one tick, ``swinging`` feet in the air."""
    gates = m.gates
    if len(m.feet) == 2 and swinging == 2:
        gates.both_swing_ticks += 1
    gates.fewest_planted = min(gates.fewest_planted, len(m.feet) - swinging)
