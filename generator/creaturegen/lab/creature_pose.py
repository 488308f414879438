"""Parity gates on the body at the parity tick: the GPU pose rows (slots and root) after seekTick vs the
Python locomotion reference (motion/simulate.py) in float32; the material's own TSL field program
(probeField) vs numpy float64 at seeded points, |Δd| and the normal angle (points where numpy's own float32
and float64 normals disagree by more than the tolerance sit on a gradient seam and are counted, not gated);
the JS locomotion core in the page vs Python and every planted foot on its plant point; and
stateHash(seekTick(n)) == stateHash(stepTicks(n)).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from playwright.sync_api import Page

from ..creature import reference as cref
from ..creature.pose import as_pose, pose_rows, root_rows
from ..motion.simulate import Motion
from .creature_lab import LAB_SEED, PARITY_TICK
from .report import ParityReport

PROBE_POINTS = 4096
#: float32 tolerances: field distance relative to L; normal angle in degrees (the skin gates use both too).
DISTANCE_TOL = 1e-5
ANGLE_TOL_DEG = 0.05
#: A planted foot drawn from float32 pose rows lies on its float64 plant point to float32 precision
#: (leg lengths); legged bodies must have at least one planted foot at the parity tick.
FOOT_DRIFT_TOL = 1e-5

F64 = npt.NDArray[np.float64]


def hash_gate(page: Page, report: ParityReport) -> None:
    page.evaluate("() => window.__lab.seekTick(0)")
    page.evaluate(f"() => window.__lab.stepTicks({PARITY_TICK})")
    stepped = page.evaluate("() => window.__lab.stateHash()")
    page.evaluate("() => window.__lab.seekTick(5)")
    page.evaluate(f"() => window.__lab.seekTick({PARITY_TICK})")
    seeked = page.evaluate("() => window.__lab.stateHash()")
    report.gate("stateHash(seekTick(n)) != stateHash(stepTicks(n))", float(stepped != seeked), 0, "mismatch")
    report.measurements["stateHash"] = {"tick": PARITY_TICK, "stepped": stepped, "seeked": seeked}


def pose_and_field_gates(
    page: Page, ref: cref.PackageReference, motion: Motion, report: ParityReport
) -> None:
    scale = ref.rig.body_scale
    gpu_rows = np.asarray(page.evaluate("() => window.__lab.readPose(0)"), dtype=np.float32)
    rows = np.concatenate(
        [
            pose_rows(
                ref.rig, motion.quats, motion.trans, cref.instance_colours(ref, LAB_SEED), motion.size
            ).reshape(-1),
            root_rows(motion.root, size=motion.size).reshape(-1),
        ]
    )
    report.gate(
        "pose rows (slots and root): GPU vs the Python locomotion reference",
        float(np.abs(gpu_rows[: rows.size] - rows).max()) / scale,
        1e-6,
        "L",
    )
    report.measurements["motion"] = {
        "tick": PARITY_TICK,
        "root": list(motion.root),
        "size": motion.size,
        "gates": motion.gates.as_dict(),
    }
    table = cref.posed_table(ref, as_pose(motion.quats, motion.trans), motion.size)
    points = cref.probe_points(table, cref.blend_pairs(ref.rig), PROBE_POINTS)
    raw = page.evaluate("(p) => window.__lab.probeField(p)", points.reshape(-1).tolist())
    gpu = np.asarray(raw, dtype=np.float64).reshape(-1, 4)
    exact = cref.field_at(ref, table, points, motion.size)
    f32 = cref.field_at(ref, table, points.astype(np.float32).astype(np.float64), motion.size)
    dd = np.abs(gpu[:, 0] - exact.distance) / scale
    report.gate(f"field |d_gpu - d_numpy| at {len(points)} points", float(dd.max()), DISTANCE_TOL, "L")

    def angle(u: F64, v: F64) -> F64:
        cos = (u * v).sum(1) / np.maximum(np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1), 1e-300)
        result: F64 = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
        return result

    # Points on a gradient seam (a tapered cap seam, a hard-min tie) are ill-conditioned for any float32
    # evaluation: numpy's own float32 path already disagrees with float64 there.
    seam = (
        angle(np.asarray(f32.gradient, dtype=np.float64), np.asarray(exact.gradient, dtype=np.float64))
        > ANGLE_TOL_DEG
    )
    theta = angle(gpu[:, 1:], np.asarray(exact.gradient, dtype=np.float64))[~seam]
    report.gate("field normal angle GPU vs numpy (off seams)", float(theta.max()), ANGLE_TOL_DEG, "deg")
    report.measurements["field"] = {
        "points": len(points),
        "seamPoints": int(seam.sum()),
        "maxAbsDistanceL": float(dd.max()),
        "p99AngleDeg": float(np.percentile(theta, 99)),
    }


def motion_gates(page: Page, ref: cref.PackageReference, motion: Motion, report: ParityReport) -> None:
    """The locomotion core as it runs in the page (V8 in Chromium) against the Python reference, and the
    planted feet as the GPU pose buffer draws them against their plant points (the lab's markers)."""
    scale = ref.rig.body_scale
    got = page.evaluate("() => window.__lab.motionState(0)")
    expected = np.asarray(motion.state_vector())
    state = np.asarray(got["state"], dtype=np.float64)
    relative = float(np.abs(state - expected).max() / max(float(np.abs(expected).max()), scale))
    report.gate(
        f"motion state in the lab vs Python at tick {PARITY_TICK} (relative)",
        relative if got["tick"] == PARITY_TICK and state.shape == expected.shape else 1.0,
        1e-12,
        "rel",
    )
    feet = page.evaluate("() => window.__lab.footDrift(0)")
    planted = [f["drift"] for f in feet if f["planted"]]
    report.gate(
        "planted feet in the GPU pose buffer vs their plant points",
        max(planted, default=0.0),
        FOOT_DRIFT_TOL,
        "leg lengths",
        passed=(bool(planted) or not feet) and max(planted, default=0.0) <= FOOT_DRIFT_TOL,
    )
    report.measurements["feet"] = {"legs": len(feet), "planted": len(planted), "drift": feet}
