"""The Python side of the locomotion parity job: reference traces the generated JS core must reproduce.

``motion_reference`` runs the reference on every built-in support surface (and the analytic water for a
swimmer), records the state vector at PARITY_TICKS and the gates, and returns plain JSON that
tests/js/motion_core.test.mjs compares against ``createMotion`` from a built package's core. The tolerance
is relative: ``|js − py| ≤ RELATIVE · max(|py|, L)`` per number, L the body scale.
"""

from __future__ import annotations

from typing import Any, Final

from .data import MotionData
from .driver import Driver, interpolate_root, interpolate_slot
from .providers import AnalyticWater, builtin_supports
from .simulate import Motion

PARITY_TICKS: Final = (0, 1, 2, 3, 10, 59, 60, 100, 250, 500, 999, 1000)
RELATIVE: Final = 1e-12
#: A frame-time sequence with hitches, a pause (0) and a negative value, for the driver trace.
DRIVER_FRAMES: Final = (0.016, 0.017, 0.0, 0.05, 0.016, 0.4, 0.016, -0.01, 0.0333, 1.0, 0.008, 0.008)
SEEDS: Final = (7, 90210)


def run_case(data: MotionData, support: str, seed: int) -> dict[str, Any]:
    motion = Motion(data, support=builtin_supports()[support], water=AnalyticWater(), seed=seed)
    frames = []
    for tick in range(PARITY_TICKS[-1] + 1):
        if tick:
            motion.step()
        if tick in PARITY_TICKS:
            frames.append({"tick": tick, "state": motion.state_vector()})
    prev_root, prev_quats = list(motion.root), [list(q) for q in motion.quats]
    prev_trans = [list(t) for t in motion.trans]
    motion.step()
    alpha = 0.375
    root = interpolate_root(prev_root, motion.root, alpha)
    blended = [
        interpolate_slot(q0, t0, q1, t1, alpha)
        for q0, t0, q1, t1 in zip(prev_quats, prev_trans, motion.quats, motion.trans, strict=True)
    ]
    render = root + [x for q, t in blended for x in q + t]
    return {
        "support": support,
        "seed": seed,
        "frames": frames,
        "render": {"tick": motion.tick, "alpha": alpha, "state": render},
        "gates": motion.gates.as_dict(),
        "derived": motion.d.as_dict(),
    }


def driver_trace(hz: int) -> list[dict[str, float]]:
    driver = Driver(hz)
    out = []
    for dt in DRIVER_FRAMES:
        steps = driver.advance(dt)
        out.append({"dt": dt, "steps": steps, "alpha": driver.alpha, "accumulator": driver.accumulator})
    return out


def motion_reference(data: MotionData) -> dict[str, Any]:
    cases = [run_case(data, support, SEEDS[0]) for support in builtin_supports()]
    cases.append(run_case(data, "flat", SEEDS[1]))
    return {
        "relative": RELATIVE,
        "bodyScale": data.body_scale,
        "ticks": list(PARITY_TICKS),
        "cases": cases,
        "driver": {"hz": data.hz, "frames": driver_trace(int(data.hz))},
    }
