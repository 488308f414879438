"""The debug shell ('shell' view, tsl/shell.js) against numpy: its counts, its placement on the pose rows and
its snap onto the union field.

The shell is the seed's preview representation: every slot as a capsule of the tier's preview counts
(V_slot = (2 + 2·capRings)·radial + 2 vertices: hero 98, repeated 62, distant 50), placed on its pose row and
snapped onto the union field by a fixed number of Newton steps p ← p − d·∇d/|∇d|². Here numpy builds the same
unit shell, places it on the posed slot table of the Python locomotion reference and snaps it with the
reference sampler in float64; the page reads the shell back through the package's own shellVertex (the
function the view's positionNode runs).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from playwright.sync_api import Page

from ..creature import reference as cref
from ..creature.pose import as_pose
from ..model import layout as col
from ..motion.simulate import Motion
from ..surface.correct import GRADIENT_FLOOR
from .report import ParityReport

F64 = npt.NDArray[np.float64]

#: tsl/shell.js SHELL_TIERS, SHELL_RADIAL, SHELL_CAP_RINGS, SHELL_SNAP_STEPS (per tier): the seed's preview
#: shell counts (12/10/8 around, 3/2/2 cap rings) and correction trials (2/2/1), pinned by
#: tests/test_runtime_constants.py.
SHELL_TIERS = ("hero", "repeated", "distant")
SHELL_RADIAL = (12, 10, 8)
SHELL_CAP_RINGS = (3, 2, 2)
SHELL_SNAP_STEPS = (2, 2, 1)
#: The runtime's length floor for a slot axis (field.js `tiny`): a shorter segment takes +y.
AXIS_TINY = 1e-12
#: Snapped positions, GPU vs numpy (fraction of L): float32 field steps against float64 ones.
POSITION_TOL = 1e-4
#: A vertex whose numpy snap moves by more than this (fraction of L: a quarter of POSITION_TOL) when its
#: points, or its pose rows and arithmetic too, are rounded to float32 is ill-conditioned: its Newton path
#: crosses a gradient seam (a capsule's cap seam, a hard-min tie), where any float32 evaluation may take the
#: other side. The set is numpy's alone (the GPU cannot widen it); the GPU is compared on the others.
SEAM_SENSITIVITY = 2.5e-5
#: The most of a shell's vertices that may be ill-conditioned: a sanity bound that keeps the comparison
#: about most of the shell (shells start on slot surfaces buried in the body or across blends, whose paths
#: cross seams often; the share is reported as measured).
SEAM_SHARE_MAX = 0.25


def shell_counts(tier: str) -> tuple[int, int, int, int]:
    """(radial, capRings, steps, vertices per slot) of ``tier``, as tsl/shell.js shellCounts."""
    t = SHELL_TIERS.index(tier)
    radial, rings = SHELL_RADIAL[t], SHELL_CAP_RINGS[t]
    return radial, rings, SHELL_SNAP_STEPS[t], (2 + 2 * rings) * radial + 2


def unit_shell(radial: int, cap_rings: int) -> tuple[F64, F64]:
    """Directions (V, 3) from each vertex's end centre in the slot frame (y along a→b) and ends (V,), in
    tsl/shell.js shellGeometry's order: pole at a, a's cap rings to its equator, b's equator to its pole."""
    azimuth = 2.0 * np.pi * np.arange(radial) / radial
    polar = (np.pi / 2.0) * np.arange(1, cap_rings + 2) / (cap_rings + 1)

    def ring(end: int, angle: float) -> F64:
        y = -np.cos(angle) if end == 0 else np.cos(angle)
        return np.stack(
            [np.sin(angle) * np.cos(azimuth), np.full(radial, y), np.sin(angle) * np.sin(azimuth)], axis=1
        )

    rows = [np.array([[0.0, -1.0, 0.0]])]
    rows += [ring(0, a) for a in polar]
    rows += [ring(1, a) for a in polar[::-1]]
    rows.append(np.array([[0.0, 1.0, 0.0]]))
    dirs = np.concatenate(rows)
    ends = np.concatenate([np.zeros(1 + (cap_rings + 1) * radial), np.ones(1 + (cap_rings + 1) * radial)])
    return dirs, ends


def placed_shell(table: F64, dirs: F64, ends: F64) -> F64:
    """(S·V, 3) every slot's unit shell on its row of ``table`` (segment a→b, radii ra→rb), slot by slot."""
    a, b = table[:, col.A], table[:, col.B]
    ra, rb = table[:, col.RA], table[:, col.RB]
    ba = b - a
    length = np.linalg.norm(ba, axis=1, keepdims=True)
    axis = np.where(length > AXIS_TINY, ba / np.maximum(length, AXIS_TINY), np.array([0.0, 1.0, 0.0]))
    helper = np.where(np.abs(axis[:, :1]) < 0.9, np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]))
    u = np.cross(axis, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    w = np.cross(axis, u)
    n = (
        u[:, None, :] * dirs[None, :, 0:1]
        + axis[:, None, :] * dirs[None, :, 1:2]
        + w[:, None, :] * dirs[None, :, 2:3]
    )
    centre = a[:, None, :] + (b - a)[:, None, :] * ends[None, :, None]
    radius = ra[:, None] + (rb - ra)[:, None] * ends[None, :]
    placed: F64 = (centre + n * radius[..., None]).reshape(-1, 3)
    return placed


def snapped_shell(
    ref: cref.PackageReference, table: F64, size: float, tier: str, rounding: str = "none"
) -> tuple[F64, F64, F64]:
    """(placed, snapped, d at the snapped points) for ``tier``'s shell of every slot of ``table``, in float64.
    ``rounding`` perturbs it as the GPU's float32 does: "points" rounds each point to float32 before it is
    evaluated; "all" also rounds the pose rows and evaluates the field in float32."""
    radial, rings, steps, _ = shell_counts(tier)
    dirs, ends = unit_shell(radial, rings)
    if rounding == "all":  # the pose rows as the GPU holds them
        table = table.astype(np.float32).astype(np.float64)
    placed = placed_shell(table, dirs, ends)
    p = placed.copy()
    for _ in range(steps):
        if rounding != "none":
            p = p.astype(np.float32).astype(np.float64)
        sample = cref.field_at(ref, table, p, size, np.float32 if rounding == "all" else np.float64)
        g = np.asarray(sample.gradient, dtype=np.float64)
        d = np.asarray(sample.distance, dtype=np.float64)
        gg = (g * g).sum(axis=1)
        ok = gg >= GRADIENT_FLOOR
        p = np.where(ok[:, None], p - g * (d / np.where(ok, gg, 1.0))[:, None], p)
    final = np.asarray(cref.field_at(ref, table, p, size).distance, dtype=np.float64)
    return placed, p, final


def shell_gates(
    page: Page, ref: cref.PackageReference, motion: Motion, tier: str, report: ParityReport
) -> None:
    """Counts, placement and snap of instance 0's shell: the page's readback (the package's shellVertex)
    against numpy, and the drawn shell mesh's vertex count against the seed's V_slot."""
    scale = ref.rig.body_scale
    got = page.evaluate("() => window.__lab.readShell(0)")
    radial, rings, steps, per_slot = shell_counts(tier)
    slots = ref.rig.slots.shape[0]
    counts = got["counts"]
    off_by = abs(int(counts["vertices"]) - per_slot) + abs(int(got["drawnVertices"]) - per_slot)
    name = f"debug shell vertices per slot vs (2 + 2·{rings})·{radial} + 2 ({tier})"
    report.gate(name, float(off_by), 0.0, "vertices")
    if off_by or len(got["position"]) != 3 * slots * per_slot:
        report.gate("debug shell on the pose rows: GPU vs numpy", float("inf"), 1e-6, "L")
        return
    table = cref.posed_table(ref, as_pose(motion.quats, motion.trans), motion.size)
    placed, snapped, final = snapped_shell(ref, table, motion.size, tier)
    moved = np.zeros(len(snapped))
    for rounding in ("points", "all"):
        perturbed = snapped_shell(ref, table, motion.size, tier, rounding)[1]
        moved = np.maximum(moved, np.abs(perturbed - snapped).max(axis=1) / scale)
    seam = moved > SEAM_SENSITIVITY
    gpu_placed = np.asarray(got["placed"], dtype=np.float64).reshape(-1, 3)
    gpu_snapped = np.asarray(got["position"], dtype=np.float64).reshape(-1, 3)
    report.gate(
        "debug shell on the pose rows: GPU vs numpy",
        float(np.abs(gpu_placed - placed).max()) / scale,
        1e-6,
        "L",
    )
    error = np.abs(gpu_snapped - snapped).max(axis=1) / scale
    report.gate(
        f"debug shell after {steps} snap steps: GPU vs numpy (off seams)",
        float(error[~seam].max()),
        POSITION_TOL,
        "L",
    )
    report.gate("debug shell vertices on seams (share)", float(seam.mean()), SEAM_SHARE_MAX, "")
    on_rows = np.asarray(cref.field_at(ref, table, placed, motion.size).distance, dtype=np.float64)
    report.measurements["shell"] = {
        "tier": tier,
        "slots": slots,
        "verticesPerSlot": per_slot,
        "vertices": slots * per_slot,
        "snapSteps": steps,
        "seamVertices": int(seam.sum()),
        "maxErrorOnSeamsL": float(error[seam].max()) if seam.any() else 0.0,
        "placedResidualP95L": float(np.percentile(np.abs(on_rows), 95)) / scale,
        "snappedResidualP95L": float(np.percentile(np.abs(final), 95)) / scale,
        "snappedResidualMaxL": float(np.abs(final).max()) / scale,
    }
