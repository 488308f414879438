"""Parity gates on skinning: GPU-skinned vertex positions vs numpy LBS/DQ/CoR on the same pose; every
vertex the GPU corrected no farther from the numpy posed field than its skinned position (the corrected
residual reported); the drawn vertices (the page's deform storage) vs the GPU body path; where the tier is
skin-represented (vertices with program SKIN_PROGRAM evaluate no field), the drawn normal of those
vertices vs numpy's skinned normal and their drawn colour vs the baked colour of the individual, and the
field gates over the other vertices only; and the display path (the shipped material's positionNode,
rendered) vs numpy's root transform of the drawn vertices.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt
from playwright.sync_api import Page

from ..creature import reference as cref
from ..creature.pose import as_pose
from ..motion.root import to_world_root
from ..motion.simulate import Motion
from ..surface.correction_region import SKIN_PROGRAM
from .creature_lab import LAB_SEED, b64_floats
from .creature_pose import ANGLE_TOL_DEG, DISTANCE_TOL
from .report import ParityReport

#: float32 tolerance relative to L: skinned position.
POSITION_TOL = 1e-5
#: Corrected vertices may not end farther from the field than their skinned place (float32 slack × L).
NEVER_WORSE_SLACK = 1e-6
#: A skin-program vertex's baked colour (four float32 slot colours blended in float32) vs numpy float64.
SKIN_COLOUR_TOL = 1e-6
#: Median angle between the rendered world normal and numpy's transformed vertex normal of the nearest
#: vertex: interpolation inside a triangle accounts for a few degrees; a wrong transform for more.
DISPLAY_NORMAL_DEG = 3.0

F64 = npt.NDArray[np.float64]


def root_transform(root: list[float], points: F64, normals: F64) -> tuple[F64, F64]:
    """Points through the locomotion reference's own root transform (root.to_world_root: p + R_yaw(S·x),
    S = diag(1/√s, s, 1/√s)); normals by S's inverse transpose and the same yaw, renormalised (the
    reference moves no normals, so this one line of it is written here)."""
    world = np.array([to_world_root(root, p) for p in points.tolist()], dtype=np.float64)
    c, s, squash = root[3], root[4], root[5]
    n = normals * np.array([math.sqrt(squash), 1.0 / squash, math.sqrt(squash)])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    turned = np.stack([c * n[:, 0] + s * n[:, 2], n[:, 1], -s * n[:, 0] + c * n[:, 2]], axis=1)
    return world, turned


def _display_gates(
    page: Page, ref: cref.PackageReference, motion: Motion, local: F64, gradient: F64, report: ParityReport
) -> None:
    """The display path (the shipped material's own positionNode, rendered) against numpy's root transform
    of the drawn vertices: each covered pixel's world position must lie on the transformed mesh (within the
    longest edge around its nearest vertices) and its normal must match the nearest vertex's."""
    from scipy.spatial import cKDTree

    shot = page.evaluate("() => window.__lab.displayPath()")
    w, h = int(shot["width"]), int(shot["height"])
    position = b64_floats(shot["position"]).reshape(h * w, 4).astype(np.float64)
    normal = b64_floats(shot["normal"]).reshape(h * w, 4).astype(np.float64)
    covered = position[:, 3] > 0.5
    position[:, :3] -= float(shot["offset"])
    normal[:, :3] -= float(shot["offset"])
    world, turned = root_transform(
        list(motion.root), local, gradient / np.linalg.norm(gradient, axis=1)[:, None]
    )
    faces = np.asarray(ref.asset.indices).reshape(-1, 3)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    length = np.linalg.norm(world[edges[:, 0]] - world[edges[:, 1]], axis=1)
    reach = np.zeros(world.shape[0])
    np.maximum.at(reach, edges[:, 0], length)
    np.maximum.at(reach, edges[:, 1], length)
    pixels = position[covered, :3]
    report.gate("display path covers body 0", float(covered.sum() == 0), 0, "empty")
    if not covered.any():
        return
    distance, nearest = cKDTree(world).query(pixels, k=8)
    off = float((distance[:, 0] / reach[nearest].max(axis=1)).max())
    report.gate("display path world positions vs numpy's root transform", off, 1.0, "edge lengths")
    n_px = normal[covered, :3] / np.linalg.norm(normal[covered, :3], axis=1, keepdims=True)
    cosine = np.clip((n_px * turned[nearest[:, 0]]).sum(axis=1), -1.0, 1.0)
    angle = np.degrees(np.arccos(cosine))
    report.gate("display path normals vs numpy (median)", float(np.median(angle)), DISPLAY_NORMAL_DEG, "deg")
    report.measurements["displayPath"] = {
        "pixels": int(covered.sum()),
        "positionOffEdgeLengths": off,
        "normalAngleDeg": {"median": float(np.median(angle)), "p95": float(np.percentile(angle, 95))},
    }


def skin_gates(page: Page, ref: cref.PackageReference, motion: Motion, report: ParityReport) -> None:
    scale = ref.rig.body_scale
    pose = as_pose(motion.quats, motion.trans)
    table = cref.posed_table(ref, pose, motion.size)
    got = page.evaluate("() => window.__lab.readSkinned(0)")
    skinned = b64_floats(got["skinned"]).reshape(-1, 3).astype(np.float64)
    corrected = b64_floats(got["corrected"]).reshape(-1, 3).astype(np.float64)
    accepted = b64_floats(got["accepted"]) > 0.5
    expected = cref.skinned_reference(ref, pose, motion.size)
    error = np.linalg.norm(skinned - expected, axis=1) / scale
    report.gate("GPU-skinned vertices vs numpy", float(error.max()), POSITION_TOL, "L")
    field = cref.field_at(ref, table, np.concatenate([skinned, corrected]), motion.size)
    n = skinned.shape[0]
    d_skin, d_corr = np.abs(field.distance[:n]), np.abs(field.distance[n:])
    region = np.asarray(ref.asset.skin)[:, 1] > 0
    worse = (d_corr - d_skin)[accepted] / scale
    report.gate(
        "corrected vertices never farther from the field than skinned",
        float(worse.max()) if worse.size else 0.0,
        NEVER_WORSE_SLACK,
        "L",
    )
    report.gate(
        "corrections outside the region policy", float(np.count_nonzero(accepted & ~region)), 0, "vertices"
    )
    # What the passes draw (the page's deform storage, written by the pre-pass) against the same body path
    # run by the diagnostics kernel: a wrong index, range or stale pose in the pre-pass shows up here.
    drawn = page.evaluate("() => window.__lab.readDeformed(0)")
    drawn_position = b64_floats(drawn["position"]).reshape(-1, 3).astype(np.float64)
    drawn_error = np.linalg.norm(drawn_position - corrected, axis=1) / scale
    report.gate(
        "drawn vertices (deform storage) vs the GPU body path", float(drawn_error.max()), POSITION_TOL, "L"
    )
    drawn_distance = b64_floats(drawn["distance"]).astype(np.float64)
    drawn_gradient = b64_floats(drawn["gradient"]).reshape(-1, 3).astype(np.float64)
    # A skin-represented tier: vertices whose program is SKIN_PROGRAM evaluate no field (distance 0, the
    # skinned rest normal, the baked colour); the field gates read the others only.
    skin_only = cref.skin_program_vertices(ref)
    evaluating = ~skin_only
    at_drawn = cref.field_at(ref, table, drawn_position[evaluating], motion.size)
    report.gate(
        "drawn field distance vs numpy at the drawn vertices",
        float(np.abs(drawn_distance[evaluating] - at_drawn.distance).max() / scale)
        if evaluating.any()
        else 0.0,
        DISTANCE_TOL,
        "L",
    )
    if skin_only.any():
        _skin_program_gates(ref, motion, drawn, drawn_gradient, drawn_distance, skin_only, report)
    _display_gates(page, ref, motion, drawn_position, drawn_gradient, report)
    report.measurements["correction"] = {
        "region": int(region.sum()),
        "accepted": int(accepted.sum()),
        "residualSkinnedMaxL": float(d_skin[region].max() / scale) if region.any() else 0.0,
        "residualCorrectedMaxL": float(d_corr[region].max() / scale) if region.any() else 0.0,
        "residualSkinnedP99L": float(np.percentile(d_skin[region], 99) / scale) if region.any() else 0.0,
        "residualCorrectedP99L": float(np.percentile(d_corr[region], 99) / scale) if region.any() else 0.0,
        "wholeMeshMaxL": float(d_corr.max() / scale),
    }


def _skin_program_gates(
    ref: cref.PackageReference,
    motion: Motion,
    drawn: dict[str, Any],
    drawn_gradient: F64,
    drawn_distance: F64,
    skin_only: npt.NDArray[np.bool_],
    report: ParityReport,
) -> None:
    """The vertices that evaluate no field, as the passes draw them: the skinned rest normal (numpy's
    skin_lbs/skin_dq/skin_cor normal by the vertex's method) and the baked colour of the individual
    (Σ cwᵢ·rgb(csᵢ) over the asset's colour slots), and no field result stored for them."""
    pose = as_pose(motion.quats, motion.trans)
    _, normals = cref.skinned_vertices(ref, pose, motion.size)
    theta = _angle_deg(drawn_gradient[skin_only], normals[skin_only])
    report.gate(
        "drawn normal of skin-program vertices vs numpy skinned normal",
        float(theta.max()),
        ANGLE_TOL_DEG,
        "deg",
    )
    colour = b64_floats(drawn["colour"]).reshape(-1, 3).astype(np.float64)
    baked = cref.baked_colours(ref, LAB_SEED)
    colour_error = np.abs(colour[skin_only] - baked[skin_only]).max()
    report.gate(
        "drawn colour of skin-program vertices vs numpy baked colour",
        float(colour_error),
        SKIN_COLOUR_TOL,
        "linear rgb",
    )
    accepted = b64_floats(drawn["accepted"])
    program = b64_floats(drawn["program"])
    stray = (
        (drawn_distance[skin_only] != 0.0)
        | (accepted[skin_only] != 0.0)
        | (program[skin_only] != SKIN_PROGRAM)
    )
    report.gate(
        "skin-program vertices storing a field result (distance, correction or program)",
        int(np.count_nonzero(stray)),
        0,
        "vertices",
    )
    report.measurements["skinProgram"] = {
        "vertices": int(skin_only.sum()),
        "fieldVertices": int((~skin_only).sum()),
        "normalAngleDeg": {"max": float(theta.max()), "p99": float(np.percentile(theta, 99))},
        "colourMaxAbs": float(colour_error),
    }


def _angle_deg(u: F64, v: F64) -> F64:
    cos = (u * v).sum(1) / np.maximum(np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1), 1e-300)
    result: F64 = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    return result
