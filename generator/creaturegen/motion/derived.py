"""Numbers derived at spawn time from the motion data and the injected gravity: swing and hop durations
quantised to whole ticks, flap and undulation frequencies, the swimmer's response rate.

Rounding rule (stated once, used everywhere seconds become ticks): ``ticks(s) = floor(s·hz + 0.5)``,
round half up, identical in Python and JS (Python's ``round`` is half-even, so it is not used).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .data import MotionData

#: The longest interval a locomotion parameter may ask for (an hour): past it, or infinite, the tick
#: counts stop being numbers a build can step (a valid ``hopHeight: 1e308`` overflowed here).
MAX_INTERVAL_S = 3600.0


class MotionRangeError(ValueError):
    """A valid spec whose locomotion timing is beyond what can be stepped; the message names the fields."""


def ticks_from_seconds(seconds: float, hz: int) -> int:
    if not math.isfinite(seconds) or seconds > MAX_INTERVAL_S:
        raise MotionRangeError(
            f"locomotion: one motion interval would last {seconds:.3g} s, more than {MAX_INTERVAL_S:g} s: "
            "lower the locomotion lengths and heights (or the scale), or raise the speed"
        )
    return math.floor(seconds * hz + 0.5)


@dataclass(frozen=True)
class Derived:
    hz: int
    dt: float
    g: float
    swing: int  # swing duration, ticks
    window: int  # lift window per phase group, ticks
    cycle: int  # gait cycle, ticks
    half_air: int
    air: int
    crouch: int
    land: int
    hop_cycle: int
    hop_idle: int
    dip: float  # how far a hopper on legs sinks on them at the bottom of its crouch and landing, m
    v0: float
    apex: float
    flap_hz: float
    bank: float  # reported; the pose uses its half-angle sine and cosine (square roots only)
    bank_half_sin: float
    bank_half_cos: float
    swim_omega: float
    swim_depth: float
    undulation_hz: float

    def as_dict(self) -> dict[str, float]:
        return dict(self.__dict__)


def derive(data: MotionData, gravity: list[float]) -> Derived:
    hz = int(data.hz)
    dt = 1.0 / hz
    g = math.sqrt(gravity[0] * gravity[0] + gravity[1] * gravity[1] + gravity[2] * gravity[2])
    c = data.constants
    speed = data.speed
    body = data.body_scale
    legs = data.legs
    swing = window = cycle = 0
    if legs:
        leg_len = sum(leg.a + leg.b for leg in legs) / len(legs)
        swing = max(2, ticks_from_seconds(c.swing_froude * math.sqrt(leg_len / g), hz))
        groups = data.groups
        # A foot lands stepLead·s ahead of home and lifts once it lags s behind: planted for
        # (1 + stepLead)·s / v seconds. The cycle is that stance plus the swing, a whole number of
        # windows, so a steady gait lifts each group right as its window opens. The stance is rounded
        # up with one whole tick to spare: on the curved path the lag grows along a chord, a little
        # slower than v·t, and a stance that filled its windows exactly missed its lift by a hair and
        # waited a whole cycle, its foot lagging past its reach (the quadruped at the large size corner).
        stance = 0
        if speed > 0.0:
            stance = math.floor((1.0 + c.step_lead) * data.step_length / (speed * dt)) + 2
        window = max(swing + 1, -(-(swing + stance) // groups))
        cycle = groups * window
    half_air = max(1, ticks_from_seconds(math.sqrt(2.0 * data.hop_height / g), hz))
    air = 2 * half_air
    crouch = max(2, ticks_from_seconds(c.hop_crouch_s, hz))
    land = max(2, ticks_from_seconds(c.hop_land_s, hz))
    busy = crouch + air + land
    hop_cycle = busy + 1
    if speed > 0.0 and data.hop_length > 0.0:
        hop_cycle = max(busy + 1, ticks_from_seconds(data.hop_length / speed, hz))
    dip = 0.0
    if data.type == "hopper" and legs:
        # The legs' mean rest hip height above their feet, times each leg's crouch fraction.
        for leg in legs:
            dip = dip + leg.crouch * (leg.hip[1] - leg.foot[1])
        dip = dip / len(legs)
    t_half = half_air * dt
    v0 = g * t_half
    flap_hz = 0.0
    wings = data.wings
    if wings:
        excursion = max(2.0 * w.amplitude * w.length for w in wings)
        flap_hz = c.strouhal * speed / excursion if excursion > 0.0 else 0.0
    radius = data.path_radius
    bank = math.atan2(speed * speed, g * radius) if radius > 0.0 else 0.0
    # Coordinated turn: tan β = v²/(g R); cos β from a square root, then the half angle, so no library
    # trigonometry reaches the pose.
    lift = g * radius
    cos_bank = lift / math.sqrt(speed * speed * (speed * speed) + lift * lift) if radius > 0.0 else 1.0
    undulation = data.undulation
    undulation_hz = c.strouhal * speed / (2.0 * undulation * body) if undulation > 0.0 else 0.0
    return Derived(
        hz=hz,
        dt=dt,
        g=g,
        swing=swing,
        window=window,
        cycle=cycle,
        half_air=half_air,
        air=air,
        crouch=crouch,
        land=land,
        hop_cycle=hop_cycle,
        hop_idle=hop_cycle - busy,
        dip=dip,
        v0=v0,
        apex=0.5 * g * t_half * t_half,
        flap_hz=flap_hz,
        bank=bank,
        bank_half_sin=math.sqrt((1.0 - cos_bank) * 0.5),
        bank_half_cos=math.sqrt((1.0 + cos_bank) * 0.5),
        swim_omega=c.swim_response * math.sqrt(g / body),
        swim_depth=(1.0 - data.buoyancy) * body,
        undulation_hz=undulation_hz,
    )
