"""The Python side of the creature parity job: what the lab's GPU readbacks are compared against.

Everything here is the float64 reference (field/sampler.py, surface/skinning.py, motion/simulate.py),
rebuilt from the package's own ``assets/spec.json`` and surface .glb (creature/assets.py names it);
nothing is read from the package's JS or computed by the browser.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from ..field.floors import floors_for
from ..field.sampler import FieldSample, sample_graph
from ..model import layout as col
from ..model.genome import draw_genome, genetics_data, genome_colours, slot_lab
from ..model.graph import Ref
from ..model.rotations import Pose, posed_slots
from ..motion.compiled import compile_creature
from ..motion.data import MotionData
from ..motion.providers import AnalyticWater
from ..motion.simulate import Motion
from ..rig import CompiledRig
from ..spec import CharacterSpec, validate_bytes
from ..surface.asset import SurfaceAsset
from ..surface.correction_region import SKIN_PROGRAM
from ..surface.glb import read_glb
from ..surface.skinning import skin_cor, skin_dq, skin_lbs
from .assets import SPEC_PATH, surface_path
from .pose import sized_graph, sized_slots

F64 = npt.NDArray[np.float64]

#: Share of the probe points placed on caps, taper interiors and blends (the rest fill the box).
PROBE_MIX = {"caps": 0.25, "taper": 0.25, "blends": 0.25}


@dataclass(frozen=True)
class PackageReference:
    spec: CharacterSpec
    rig: CompiledRig
    motion: MotionData  # CREATURE.motion, rebuilt from the spec
    asset: SurfaceAsset


def load_reference(package: Path) -> PackageReference:
    spec_path = package / SPEC_PATH
    spec = validate_bytes(spec_path.read_bytes(), str(spec_path))
    if not isinstance(spec, CharacterSpec):
        raise ValueError(f"{package}: {SPEC_PATH} is not a creature spec")
    # Compiled again from the shipped spec, not handed over by the build: the reference checks the
    # package, independently of the build that made it.
    creature = compile_creature(spec)
    return PackageReference(spec, creature.rig, creature.motion, read_glb(surface_path(package)))


def instance_motion(
    ref: PackageReference, seed: int, tick: int, position: tuple[float, float, float]
) -> Motion:
    """An instance spawned from ``seed`` at ``position`` on the built-in flat ground (the analytic water
    for a swimmer: the providers a population uses by default), stepped to its tick ``tick``."""
    motion = Motion(ref.motion, water=AnalyticWater(), seed=seed, position=position)
    motion.step_ticks(tick)
    return motion


def instance_colours(ref: PackageReference, seed: int) -> list[list[float]]:
    """Per-slot linear rgb of the individual spawned from ``seed`` (its colour genes in OKLab)."""
    lab = slot_lab(ref.rig.slots[:, col.RGB])
    return genome_colours(genetics_data(ref.spec.genetics), lab, draw_genome(seed))


def posed_table(ref: PackageReference, pose: Pose, size: float = 1.0) -> F64:
    """The slot table of an individual of ``size`` in ``pose`` (what its pose rows hold, in float64)."""
    return posed_slots(sized_slots(ref.rig.slots, size), pose)


def field_at(
    ref: PackageReference,
    table: F64,
    points: F64,
    size: float = 1.0,
    dtype: type[np.floating] = np.float64,
) -> FieldSample:
    """The field of a posed slot table (of an individual of ``size``: its colour-kernel floor scales too),
    evaluated in ``dtype`` (float32: the GPU's precision, to tell ill-conditioned points)."""
    graph = sized_graph(ref.rig.graph, size)
    return sample_graph(graph, table, points, floors_for(ref.rig.body_scale).k_floor * size, dtype=dtype)


def probe_points(table: F64, graph_pairs: list[tuple[int, int]], count: int, seed: int = 0) -> F64:
    """Seeded points on caps, inside tapers, across blends and over the whole box (count in total)."""
    rng = np.random.default_rng(seed)
    a, b = table[:, col.A], table[:, col.B]
    ra, rb = table[:, col.RA], table[:, col.RB]
    n_slot = table.shape[0]
    parts: list[F64] = []

    def around(centre: F64, radius: F64, spread: float, n: int) -> F64:
        direction = rng.normal(size=(n, 3))
        direction /= np.linalg.norm(direction, axis=1, keepdims=True)
        scale = radius[:, None] * (1.0 + spread * rng.uniform(-1.0, 1.0, (n, 1)))
        result: F64 = centre + direction * scale
        return result

    n_caps = int(count * PROBE_MIX["caps"])
    s = rng.integers(0, n_slot, n_caps)
    end_b = rng.random(n_caps) < 0.5
    parts.append(around(np.where(end_b[:, None], b[s], a[s]), np.where(end_b, rb[s], ra[s]), 0.3, n_caps))
    n_taper = int(count * PROBE_MIX["taper"])
    s = rng.integers(0, n_slot, n_taper)
    t = rng.uniform(0.05, 0.95, (n_taper, 1))
    parts.append(around(a[s] + (b[s] - a[s]) * t, ra[s] + (rb[s] - ra[s]) * t[:, 0], 0.6, n_taper))
    n_blend = int(count * PROBE_MIX["blends"])
    if graph_pairs:
        pick = rng.integers(0, len(graph_pairs), n_blend)
        i = np.array([graph_pairs[k][0] for k in pick])
        j = np.array([graph_pairs[k][1] for k in pick])
        mid_i = 0.5 * (a[i] + b[i])
        mid_j = 0.5 * (a[j] + b[j])
        w = rng.uniform(0.2, 0.8, (n_blend, 1))
        parts.append(around(mid_i * (1 - w) + mid_j * w, 0.5 * (ra[i] + ra[j]), 0.8, n_blend))
    lo = np.minimum(a, b).min(axis=0) - np.maximum(ra, rb).max()
    hi = np.maximum(a, b).max(axis=0) + np.maximum(ra, rb).max()
    rest = count - sum(p.shape[0] for p in parts)
    parts.append(rng.uniform(lo, hi, (rest, 3)))
    result: F64 = np.concatenate(parts)
    return result


def blend_pairs(rig: CompiledRig) -> list[tuple[int, int]]:
    """Slot pairs meeting in a blend op (first leaf of each child), where blend regions lie."""

    def first_leaf(ref: Ref) -> int:
        while ref.kind == "op":
            ref = rig.graph.ops[ref.index].children[0]
        return ref.index

    pairs = []
    for op in rig.graph.ops:
        leaves = [first_leaf(c) for c in op.children]
        pairs += [(leaves[0], other) for other in leaves[1:]]
    return pairs


def skinned_vertices(ref: PackageReference, pose: Pose, size: float = 1.0) -> tuple[F64, F64]:
    """Each vertex skinned in float64 by its baked method (LBS, DQ or CoR), as surface/skinning.py does:
    positions and the skinned rest normals (LBS by the cofactor of the blended matrix, DQ and CoR by the
    blended rotation, unit). An individual of ``size`` skins its rest vertices and centres of rotation
    scaled by it (a similarity: the normals do not change)."""
    asset = ref.asset
    vertices = asset.positions.astype(np.float64) * size
    normals = asset.normals.astype(np.float64)
    indices = asset.slots.astype(np.int64)
    weights = asset.weights.astype(np.float64)
    method = np.asarray(asset.skin)[:, 0].astype(np.int64)
    out = np.empty_like(vertices)
    out_normals = np.empty_like(normals)
    for code in (0, 1, 2):
        rows = np.flatnonzero(method == code)
        if rows.size == 0:
            continue
        v, n, i, w = vertices[rows], normals[rows], indices[rows], weights[rows]
        if code == 0:
            part = skin_lbs(v, n, i, w, pose)
        elif code == 1:
            part = skin_dq(v, n, i, w, pose)
        else:
            centres = np.asarray(asset.cor_centers)[rows].astype(np.float64) * size
            part = skin_cor(v, n, i, w, pose, centres)
        out[rows], out_normals[rows] = part.positions, part.normals
    return out, out_normals


def skinned_reference(ref: PackageReference, pose: Pose, size: float = 1.0) -> F64:
    """Each vertex's skinned position (see :func:`skinned_vertices`)."""
    return skinned_vertices(ref, pose, size)[0]


def skin_program_vertices(ref: PackageReference) -> npt.NDArray[np.bool_]:
    """(V,) the vertices that evaluate no field (candidate code SKIN_PROGRAM: a skin-represented tier)."""
    mask: npt.NDArray[np.bool_] = np.asarray(ref.asset.candidate).astype(np.int64) == SKIN_PROGRAM
    return mask


def baked_colours(ref: PackageReference, seed: int) -> F64:
    """(V, 3) each vertex's baked colour for the individual spawned from ``seed``: Σ cwᵢ·rgb(csᵢ) / Σ cwᵢ
    over the asset's four colour slots and weights, rgb its per-slot colour (:func:`instance_colours`).
    Zeros where the asset has no baked colours (a tier whose vertices all evaluate the field)."""
    asset = ref.asset
    if asset.colour_slots is None or asset.colour_weights is None:
        return np.zeros((asset.vertex_count, 3))
    rgb = np.asarray(instance_colours(ref, seed), dtype=np.float64)
    slots = np.asarray(asset.colour_slots).astype(np.int64)
    weights = np.asarray(asset.colour_weights).astype(np.float64)
    result: F64 = np.einsum("vk,vkc->vc", weights, rgb[slots]) / weights.sum(axis=1, keepdims=True)
    return result


def self_occlusion(
    ref: PackageReference, table: F64, points: F64, gradients: F64, size: float, taps: int, radius: float
) -> F64:
    """(P,) tsl/body.js selfOcclusion in float64: ``taps`` taps of the full field at δᵢ = r·i/taps along
    n̂ = g/|g| (r = radius·L·size, i = 1..taps), each counting max(δᵢ − d, 0)/δᵢ with weight 2⁻ⁱ,
    normalised; 1 − that, clamped to [0, 1]. Ones when ``taps`` is 0."""
    if taps == 0:
        return np.ones(len(points))
    n = gradients / np.maximum(np.linalg.norm(gradients, axis=1, keepdims=True), 1e-300)
    reach = radius * ref.rig.body_scale * size
    occlusion = np.zeros(len(points))
    total = 0.0
    for i in range(1, taps + 1):
        delta = reach * i / taps
        d = np.asarray(field_at(ref, table, points + n * delta, size).distance, dtype=np.float64)
        occlusion += 0.5**i * np.maximum(delta - d, 0.0) / delta
        total += 0.5**i
    result: F64 = np.clip(1.0 - occlusion / total, 0.0, 1.0)
    return result
