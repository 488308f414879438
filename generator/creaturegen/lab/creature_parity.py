"""The creature parity job: run a built package in the lab (headless Chromium, WebGPU on SwiftShader)
and diff what the GPU computed, read back from the device, against the numpy reference.

Gates, all measured in the run (thresholds are relative to the body scale L where they are lengths):
- pose pages: the GPU pose rows (slots and root) after seekTick vs the Python locomotion reference
  (motion/simulate.py) in float32;
- field: GPU probeField (a compute kernel running the material's own TSL field program) vs numpy float64
  at ≥ 4096 seeded points on caps, inside tapers, across blends and over the box: |Δd| and the normal
  angle (points where numpy's own float32 and float64 normals disagree by more than the tolerance sit on a
  gradient seam and are counted, not gated);
- skinning: GPU-skinned vertex positions vs numpy LBS/DQ/CoR on the same pose; where the tier is
  skin-represented (vertices with program SKIN_PROGRAM evaluate no field), the drawn normal of those
  vertices vs numpy's skinned normal and their drawn colour vs the baked colour of the individual, and the
  field gates over the other vertices only;
- correction: every vertex the GPU corrected is no farther from the numpy posed field than its skinned
  position, and the corrected residual is reported;
- shadows: the silhouette seen from the sun vs the shadow footprint on the ground (the depth pass uses the
  same position function), max distance of a disagreeing texel to the other mask's edge;
- no GPU validation errors; no pipelines and no buffers created by a burst of spawns that fills the lab's
  first pose page and opens its second, and one tick and frame of them all after reveal;
- stateHash(seekTick(n)) == stateHash(stepTicks(n));
- motion: the JS locomotion core in the page vs Python (relative 1e-12), and every planted foot as the GPU
  pose buffer draws it (rows read back, root squash/yaw/position applied) on its plant point;
- genetics grid: 64 individuals (seeds 0..63) spawned in an 8×8 grid and stepped: every one's GPU pose
  rows (its OKLab-mutated colours and the pose its size and gait genes give) vs its Python reference, no two
  individuals alike; parity/grid.png shows them.
"""

from __future__ import annotations

import base64
import contextlib
import json
import math
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from playwright.sync_api import Page
from scipy import ndimage

from ..creature import reference as cref
from ..creature.pose import POSE_ROWS, as_pose, pose_rows, root_rows
from ..model import layout as col
from ..model.genome import slot_lab
from ..motion.simulate import Motion
from ..surface.build import SKIN_PROGRAM
from .browser import LabPage, launch_lab_page
from .png import write_png
from .report import ParityReport, adapter_gate, console_problems
from .server import WEB_LAB, serve

DEFAULT_CANVAS = (192, 144)
#: The pose tick the GPU gates run at (away from rest: feet in swing, the hopper in the air), and the seed
#: and spawn position of instance 0 (the lab's defaults).
PARITY_TICK = 37
LAB_SEED = 1
LAB_POSITION = (0.0, 0.0, 0.0)
PROBE_POINTS = 4096
#: float32 tolerances relative to L: field distance, skinned position; normal angle in degrees.
DISTANCE_TOL = 1e-5
POSITION_TOL = 1e-5
ANGLE_TOL_DEG = 0.05
#: Corrected vertices may not end farther from the field than their skinned place (float32 slack × L).
NEVER_WORSE_SLACK = 1e-6
#: Silhouette vs shadow footprint: a disagreeing texel may lie at most this far from the other's edge.
SHADOW_TEXELS = 2.0
#: A planted foot drawn from float32 pose rows lies on its float64 plant point to float32 precision
#: (leg lengths); legged bodies must have at least one planted foot at the parity tick.
FOOT_DRIFT_TOL = 1e-5
#: Bodies per pose page in the parity lab, and the spawn burst after reveal: instance 0 plus PAGE_SIZE
#: spawns fill page 0 and put one body on page 1, so the burst crosses a page boundary and the frame draws
#: two pages. Small on purpose: the one frame deforms every spawned body in software (SwiftShader took
#: 65 s for 51 beetles of 65,410 vertices), and a bigger page adds nothing the gates could see.
PAGE_SIZE = 8
SPAWNS = PAGE_SIZE
#: Pages the burst's bodies occupy. The lab holds one page more unless the genetics grid runs (its GRID_SIDE²
#: bodies need more): with exactly two pages the pages-in-use gate could not fail, since nine bodies need
#: both; a third page lets a spawn that spreads bodies over pages show (the preload warms every page, one
#: body each, so capacity costs time).
PAGES_IN_BURST = 2
SPARE_PAGES = 1
#: The genetics grid: side, first seed, spacing (body lengths) and the tick it is compared at.
GRID_SIDE = 8
GRID_SEED = 0
GRID_SPACING = 2.0
GRID_TICK = 24
#: Genome colours in the GPU rows vs Python: both round the same float64 value to float32, so exactly 0.
COLOUR_TOL = 0.0
#: A skin-program vertex's baked colour (four float32 slot colours blended in float32) vs numpy float64.
SKIN_COLOUR_TOL = 1e-6

F64 = npt.NDArray[np.float64]


def _b64_floats(text: str) -> npt.NDArray[np.float32]:
    return np.frombuffer(base64.b64decode(text), dtype=np.float32)


def _rgba(shot: dict[str, Any]) -> npt.NDArray[np.uint8]:
    raw = np.frombuffer(base64.b64decode(shot["rgba"]), dtype=np.uint8)
    return raw.reshape(int(shot["height"]), int(shot["width"]), 4)


@contextlib.contextmanager
def open_creature_lab(
    package: Path, canvas: tuple[int, int] = DEFAULT_CANVAS, **query: int
) -> Iterator[Page]:
    """The creature lab page on ``package`` (any folder: its parent is served as /out/); ``query`` adds
    page parameters (capacity, pageSize, seed)."""
    with open_creature_lab_page(package, canvas, **query) as lab_page:
        yield lab_page.page


@contextlib.contextmanager
def open_creature_lab_page(
    package: Path, canvas: tuple[int, int] = DEFAULT_CANVAS, **query: int
) -> Iterator[LabPage]:
    """open_creature_lab with the page's console transcript since launch (the parity gates read it)."""
    params = {"pkg": package.name, "w": canvas[0], "h": canvas[1], "seed": LAB_SEED, **query}
    url_path = "creature.html?" + "&".join(f"{k}={v}" for k, v in params.items())
    with (
        serve(WEB_LAB, mounts={"out": package.parent}) as base,
        launch_lab_page(base + url_path, timeout_s=300) as lab_page,
    ):
        error = lab_page.lab.get("error")
        if error:
            raise RuntimeError(f"{package.name}: the lab failed to load the package: {error}")
        yield lab_page


#: Median angle between the rendered world normal and numpy's transformed vertex normal of the nearest
#: vertex: interpolation inside a triangle accounts for a few degrees; a wrong transform for more.
DISPLAY_NORMAL_DEG = 3.0


def _counter_gates(page: Page, report: ParityReport) -> None:
    page.evaluate("() => window.__lab.resetCounters()")
    # Spawn without drawing, then one tick and one frame of all of them: a pipeline built at draw time
    # would show up here too.
    page.evaluate(f"() => window.__lab.spawn(1000, {SPAWNS}, 1.5, false)")
    page.evaluate("() => window.__lab.stepTicks(1)")
    page.evaluate("() => window.__lab.finish()")
    after = page.evaluate("() => window.__lab.counters()")["sinceReveal"]
    pipelines = after["createRenderPipeline"] + after["createRenderPipelineAsync"]
    pipelines += after["createComputePipeline"] + after["createComputePipelineAsync"]
    report.gate(f"pipelines created by {SPAWNS} spawns after reveal", pipelines, 0, "pipelines")
    report.gate(f"buffers created by {SPAWNS} spawns after reveal", after["createBuffer"], 0, "buffers")
    telemetry = page.evaluate("() => window.__lab.telemetry()")
    drawn = page.evaluate("() => window.__lab.draws()")
    body_passes = [n for n in drawn["perPass"] if n > 0]
    pages = telemetry["pagesInUse"]
    report.gate(
        f"pose pages in use after {SPAWNS} spawns of pageSize {PAGE_SIZE}",
        pages,
        PAGES_IN_BURST,
        "pages",
        passed=pages == PAGES_IN_BURST,
    )
    # One instanced draw per page and pass, never one per body. A pass may draw fewer: it culls a page
    # whose bodies lie outside its frustum (the shadow camera covers body 0 only, and the burst's body on
    # page 1 stands 1.5 L away).
    report.gate(
        "body draw calls in a render pass beyond pages in use (encoder count)",
        float(max((n - pages for n in body_passes), default=pages)),
        0,
        "draws",
    )
    report.gate(
        "render passes drawing the bodies (display + shadow)",
        len(body_passes),
        2,
        "passes",
        passed=len(body_passes) >= 2,
    )
    report.measurements["population"] = {
        "count": telemetry["count"],
        "pagesInUse": pages,
        "pages": telemetry["pages"],
        "drawsPerPass": drawn["perPass"],
        "lastFrameBytes": telemetry["stats"]["lastFrameBytes"],
        "spawnCost": page.evaluate("() => window.__lab.spawnCost()"),
        "sinceReveal": after,
    }
    page.evaluate("() => window.__lab.despawnAll([0])")


def _hash_gate(page: Page, report: ParityReport) -> None:
    page.evaluate("() => window.__lab.seekTick(0)")
    page.evaluate(f"() => window.__lab.stepTicks({PARITY_TICK})")
    stepped = page.evaluate("() => window.__lab.stateHash()")
    page.evaluate("() => window.__lab.seekTick(5)")
    page.evaluate(f"() => window.__lab.seekTick({PARITY_TICK})")
    seeked = page.evaluate("() => window.__lab.stateHash()")
    report.gate("stateHash(seekTick(n)) != stateHash(stepTicks(n))", float(stepped != seeked), 0, "mismatch")
    report.measurements["stateHash"] = {"tick": PARITY_TICK, "stepped": stepped, "seeked": seeked}


def _pose_and_field_gates(
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


def _motion_gates(page: Page, ref: cref.PackageReference, motion: Motion, report: ParityReport) -> None:
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


def root_transform(root: list[float], points: F64, normals: F64) -> tuple[F64, F64]:
    """Points through the locomotion reference's own root transform (Motion.to_world_root: p + R_yaw(S·x),
    S = diag(1/√s, s, 1/√s)); normals by S's inverse transpose and the same yaw, renormalised (the
    reference moves no normals, so this one line of it is written here)."""
    world = np.array([Motion.to_world_root(root, p) for p in points.tolist()], dtype=np.float64)
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
    position = _b64_floats(shot["position"]).reshape(h * w, 4).astype(np.float64)
    normal = _b64_floats(shot["normal"]).reshape(h * w, 4).astype(np.float64)
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


def _skin_gates(page: Page, ref: cref.PackageReference, motion: Motion, report: ParityReport) -> None:
    scale = ref.rig.body_scale
    pose = as_pose(motion.quats, motion.trans)
    table = cref.posed_table(ref, pose, motion.size)
    got = page.evaluate("() => window.__lab.readSkinned(0)")
    skinned = _b64_floats(got["skinned"]).reshape(-1, 3).astype(np.float64)
    corrected = _b64_floats(got["corrected"]).reshape(-1, 3).astype(np.float64)
    accepted = _b64_floats(got["accepted"]) > 0.5
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
    drawn_position = _b64_floats(drawn["position"]).reshape(-1, 3).astype(np.float64)
    drawn_error = np.linalg.norm(drawn_position - corrected, axis=1) / scale
    report.gate(
        "drawn vertices (deform storage) vs the GPU body path", float(drawn_error.max()), POSITION_TOL, "L"
    )
    drawn_distance = _b64_floats(drawn["distance"]).astype(np.float64)
    drawn_gradient = _b64_floats(drawn["gradient"]).reshape(-1, 3).astype(np.float64)
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
    colour = _b64_floats(drawn["colour"]).reshape(-1, 3).astype(np.float64)
    baked = cref.baked_colours(ref, LAB_SEED)
    colour_error = np.abs(colour[skin_only] - baked[skin_only]).max()
    report.gate(
        "drawn colour of skin-program vertices vs numpy baked colour",
        float(colour_error),
        SKIN_COLOUR_TOL,
        "linear rgb",
    )
    accepted = _b64_floats(drawn["accepted"])
    program = _b64_floats(drawn["program"])
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


def shadow_mismatch(silhouette: npt.NDArray[np.bool_], footprint: npt.NDArray[np.bool_]) -> tuple[float, int]:
    """(largest distance in texels from a disagreeing texel to the other mask, disagreeing texels)."""
    only_sil = silhouette & ~footprint
    only_foot = footprint & ~silhouette
    dist_to_foot = ndimage.distance_transform_edt(~footprint)
    dist_to_sil = ndimage.distance_transform_edt(~silhouette)
    worst = max(
        float(dist_to_foot[only_sil].max()) if only_sil.any() else 0.0,
        float(dist_to_sil[only_foot].max()) if only_foot.any() else 0.0,
    )
    return worst, int(only_sil.sum() + only_foot.sum())


def _shadow_gate(page: Page, package: Path, report: ParityReport) -> None:
    shot = page.evaluate("() => window.__lab.shadowParity(128)")
    size = int(shot["size"])
    sil = np.frombuffer(base64.b64decode(shot["silhouette"]), np.uint8).reshape(size, size, 4)
    foot = np.frombuffer(base64.b64decode(shot["footprint"]), np.uint8).reshape(size, size, 4)
    silhouette = sil[..., :3].max(axis=2) > 127
    lum = foot[..., :3].astype(np.float64).mean(axis=2)
    lit = float(np.median(lum[~silhouette])) if (~silhouette).any() else 255.0
    footprint = lum < 0.5 * lit
    worst, count = shadow_mismatch(silhouette, footprint)
    report.gate("silhouette vs shadow footprint", worst, SHADOW_TEXELS, "texels")
    report.measurements["shadow"] = {
        "size": size,
        "silhouetteTexels": int(silhouette.sum()),
        "footprintTexels": int(footprint.sum()),
        "disagreeingTexels": count,
    }
    write_png(package / "parity" / "silhouette.png", sil)
    write_png(package / "parity" / "footprint.png", foot)


def _pictures(page: Page, package: Path, debug: bool, report: ParityReport) -> None:
    """front.png (the README's picture); with ``debug``, the distance, normals and candidates views too
    (each is a material variant compiled on first use, ~10 s on SwiftShader), each gated to differ from
    the shipped view and to be more than one colour (a mode that never reaches the shader draws the body
    as shipped; a broken one draws nothing)."""
    front = _rgba(page.evaluate("() => window.__lab.capturePixels('front')"))
    write_png(package / "parity" / "front.png", front)
    same: list[str] = []
    blank: list[str] = []
    for mode in ("distance", "normals", "candidates", "shell") if debug else ():
        page.evaluate(f"() => window.__lab.setDebugMode('{mode}')")
        picture = _rgba(page.evaluate("() => window.__lab.capturePixels('front')"))
        write_png(package / "parity" / f"debug-{mode}.png", picture)
        if np.array_equal(picture, front):
            same.append(mode)
        if bool((picture[..., :3] == picture[0, 0, :3]).all()):
            blank.append(mode)
    page.evaluate("() => window.__lab.setDebugMode('off')")
    if debug:
        report.gate(f"debug views identical to the shipped view {same}", len(same), 0, "views")
        report.gate(f"debug views of one colour {blank}", len(blank), 0, "views")


def _grid_gates(page: Page, ref: cref.PackageReference, package: Path, report: ParityReport) -> None:
    """The genetics grid: each individual's GPU pose rows against the Python reference spawned from the same
    seed and position (the colour rows alone at float32 rounding, all rows relative to L), and how far the
    individuals differ: colour (OKLab distance of the mean slot colour to the authored one), speed (pace gene
    and √size together) and size."""
    # Not drawn at spawn: the step's one upload and deform pre-pass draws all 64.
    bodies = page.evaluate(f"() => window.__lab.grid({GRID_SIDE}, {GRID_SEED}, {GRID_SPACING}, false)")
    page.evaluate(f"() => window.__lab.stepTicks({GRID_TICK})")
    scale = ref.rig.body_scale
    slots = ref.rig.slot_count
    worst_rows = worst_colour = 0.0
    colours, speeds, sizes = [], [], []
    for body in bodies:
        gpu = np.asarray(page.evaluate(f"() => window.__lab.readPose({body['id']})"), dtype=np.float32)
        seed = int(body["seed"])
        x, y, z = (float(c) for c in body["position"])
        motion = cref.instance_motion(ref, seed, GRID_TICK, (x, y, z))
        mine = cref.instance_colours(ref, seed)
        rows = np.concatenate(
            [
                pose_rows(ref.rig, motion.quats, motion.trans, mine, motion.size).reshape(-1),
                root_rows(motion.root, size=motion.size).reshape(-1),
            ]
        )
        got = gpu[: rows.size]
        worst_rows = max(worst_rows, float(np.abs(got - rows).max()) / scale)
        colour_rows = got[: slots * POSE_ROWS * 4].reshape(slots, POSE_ROWS, 4)[:, 2, 1:4]
        worst_colour = max(worst_colour, float(np.abs(colour_rows - np.asarray(mine, np.float32)).max()))
        colours.append(colour_rows.astype(np.float64).ravel())
        speeds.append(motion.data["speed"] / ref.motion["speed"] if ref.motion["speed"] > 0 else 1.0)
        sizes.append(motion.size)
    report.gate(
        f"genome colours of {len(bodies)} individuals: GPU pose rows vs Python (OKLab mutation)",
        worst_colour,
        COLOUR_TOL,
        "linear rgb",
    )
    report.gate(
        f"pose rows of {len(bodies)} individuals at tick {GRID_TICK}: GPU vs Python (size and gait genes)",
        worst_rows,
        1e-6,
        "L",
    )
    flat = np.asarray(colours)
    gaps = np.linalg.norm(flat[:, None, :] - flat[None, :, :], axis=2)[np.triu_indices(len(flat), 1)]
    genetics = ref.spec.genetics
    if genetics.hue or genetics.chroma or genetics.lightness:
        identical = int(np.count_nonzero(gaps == 0.0))
        report.gate("individuals with identical colours in the grid", identical, 0, "pairs")
    # How far the individuals stray: OKLab distance of each slot colour from the authored one.
    authored = np.asarray(slot_lab(ref.rig.slots[:, col.RGB]))
    shift = np.linalg.norm(np.asarray([slot_lab(c.reshape(-1, 3)) for c in flat]) - authored, axis=2)
    report.measurements["grid"] = {
        "bodies": len(bodies),
        "tick": GRID_TICK,
        "minColourGapLinear": float(gaps.min()),
        "oklabShift": {"median": float(np.median(shift)), "max": float(shift.max())},
        "speedRatio": [float(min(speeds)), float(max(speeds))],
        "size": [float(min(sizes)), float(max(sizes))],
    }
    shot = page.evaluate("() => window.__lab.capturePixels('grid')")
    write_png(package / "parity" / "grid.png", _rgba(shot))


GATE_GROUPS = ("population", "hash", "field", "motion", "skin", "shadow", "grid")


def run_creature_parity(
    package: Path,
    canvas: tuple[int, int] = DEFAULT_CANVAS,
    groups: tuple[str, ...] = GATE_GROUPS,
    debug_pictures: bool = False,
) -> ParityReport:
    """The creature gates (all groups by default) for one built package; writes parity/report.json and
    PNGs (front.png always, debug views on request) into it. GPU validation errors are always gated."""
    package = package.resolve()
    ref = cref.load_reference(package)
    # Instance 0 as the lab spawns it, at the parity tick: what every pose, field and skin gate compares.
    motion = cref.instance_motion(ref, LAB_SEED, PARITY_TICK, LAB_POSITION)
    report = ParityReport(package=package.name)
    (package / "parity").mkdir(exist_ok=True)
    seconds: dict[str, float] = {}
    start = time.perf_counter()
    capacity = GRID_SIDE * GRID_SIDE if "grid" in groups else (PAGES_IN_BURST + SPARE_PAGES) * PAGE_SIZE
    with open_creature_lab_page(package, canvas, capacity=capacity, pageSize=PAGE_SIZE) as lab_page:
        page = lab_page.page
        seconds["load"] = time.perf_counter() - start
        report.measurements["adapter"] = page.evaluate("() => window.__lab.info()")["adapter"]
        adapter_gate(report, report.measurements["adapter"])
        report.measurements["bootMs"] = page.evaluate("() => window.__lab.bootMs")

        def phase(name: str, run: Callable[[], object]) -> None:
            if name in groups:
                t = time.perf_counter()
                run()
                seconds[name] = time.perf_counter() - t

        phase("population", lambda: _counter_gates(page, report))
        phase("hash", lambda: _hash_gate(page, report))
        page.evaluate(f"() => window.__lab.seekTick({PARITY_TICK})")
        phase("field", lambda: _pose_and_field_gates(page, ref, motion, report))
        phase("motion", lambda: _motion_gates(page, ref, motion, report))
        phase("skin", lambda: _skin_gates(page, ref, motion, report))
        phase("shadow", lambda: _shadow_gate(page, package, report))
        t = time.perf_counter()
        _pictures(page, package, debug_pictures, report)
        seconds["pictures"] = time.perf_counter() - t
        # Last: the grid replaces every body (instance 0 included) of the lab.
        phase("grid", lambda: _grid_gates(page, ref, package, report))
        page.evaluate("() => window.__lab.finish()")
        errors: list[str] = page.evaluate("() => window.__lab.errors")
        report.gate("GPU validation errors", len(errors), 0, "errors")
        report.measurements["gpuErrors"] = errors[:20]
        console = console_problems(lab_page.console) + list(lab_page.page_errors)
        report.gate("console errors and warnings (pipeline compiles included)", len(console), 0, "lines")
        report.measurements["consoleProblems"] = console[:20]
        report.measurements["slots"] = ref.rig.slot_count
        report.measurements["bodyScale"] = ref.rig.body_scale
        report.measurements["seconds"] = seconds
    (package / "parity" / "report.json").write_text(
        json.dumps(report.as_dict(), indent=2, sort_keys=True) + "\n"
    )
    return report
