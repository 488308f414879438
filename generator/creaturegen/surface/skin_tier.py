"""The skin representation of the lower tiers: the field only where the skin alone departs from it.

The seed's rule for bodies that cover few pixels is to change representation before shaving constants:
where the skinned reference mesh alone stays within the tier's error, the live field correction, its
candidate program and the per-vertex field evaluation go. A skin vertex is drawn at its skinned position
with its skinned rest normal (surface/skinning.py; for LBS the formulas of a three.js SkinnedMesh) and a
colour baked from the field's proximity-colour kernel at rest: the BAKED_LEAVES leaves of largest weight,
renormalised. The colours stay per individual (genetic colour variation reads the pose rows); only the
weights are baked.

Where the skin departs (measured over the motion envelope's poses, motion/envelope.py: the poses the
creature's own gait, hop, flap or swim reaches, modulo rigid motion) by more than the tier's position,
normal or colour tolerance, the vertex is a field vertex: corrected where the position fails, and shaded
with the field's normal and colour, all through the full graph, so no certificate can refuse it. That is
mostly the blend fillets of moving joints (a tail's root, a hip), a few per cent to a third of the mesh.

What the skin vertices still give up is measured and reported as the tier's contract: the largest body,
in pixels across its length L, for which their worst position departure stays under SUBPIXEL_PX, and
their normal and colour departures.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..candidates.regions import SkinTolerance
from ..field.colour import proximity_weights
from ..field.primitives import primitive_field
from ..field.sampler import sample_graph
from ..model import layout as col
from ..model.rotations import Pose, posed_slots
from ..model.skeleton import Skeleton
from ..rig import CompiledRig
from ..rig.colour import linear_to_oklab
from . import deform, skinning
from .mesh import Mesh

F64 = npt.NDArray[np.float64]

#: Leaves whose rest colour weights are baked per vertex (one vec4 of slots, one of weights).
BAKED_LEAVES = 4
#: The skin's departure from the posed field, in pixels, that the contract allows at the largest size.
SUBPIXEL_PX = 0.5
#: Reported size of a contract with no departure at all (a body without joints).
MAX_REPORTED_PX = 1e6


@dataclass(frozen=True)
class BakedColour:
    slots: npt.NDArray[np.uint16]  # (V, 4)
    weights: npt.NDArray[np.float32]  # (V, 4), rows sum to 1
    truncation: float  # max linear-channel difference from the full kernel at rest


def baked_colour(rig: CompiledRig, rest: F64, k_floor: float) -> BakedColour:
    """The top BAKED_LEAVES proximity-colour weights of each rest vertex, renormalised (field/colour.py)."""
    d, _ = primitive_field(rig.slots, rest)
    weights = proximity_weights(d, rig.slots[:, col.K], k_floor).T  # (V, S)
    count = min(BAKED_LEAVES, rig.slot_count)
    order = np.argsort(-weights, axis=1, kind="stable")[:, :count]
    kept = np.take_along_axis(weights, order, axis=1)
    kept /= kept.sum(axis=1, keepdims=True)
    pad = BAKED_LEAVES - count
    slots = np.pad(order, ((0, 0), (0, pad)), constant_values=0).astype(np.uint16)
    w32 = np.pad(kept, ((0, 0), (0, pad))).astype(np.float32)
    w32 /= w32.sum(axis=1, keepdims=True, dtype=np.float32)
    rgb = rig.slots[:, col.RGB]
    full = (weights @ rgb) / weights.sum(axis=1, keepdims=True)
    truncation = float(np.abs(baked_rgb(slots, w32, rgb) - full).max()) if len(rest) else 0.0
    return BakedColour(slots, w32, truncation)


def baked_rgb(slots: npt.ArrayLike, weights: npt.ArrayLike, rgb: F64) -> F64:
    """Σ w_i rgb(slot_i) / Σ w_i: a skin-represented vertex's colour (the runtime's formula)."""
    s = np.asarray(slots, dtype=np.int64)
    w = np.asarray(weights, dtype=np.float64)
    out: F64 = (w[:, :, None] * rgb[s]).sum(axis=1) / w.sum(axis=1, keepdims=True)
    return out


@dataclass(frozen=True)
class Departures:
    """Per vertex, the worst over the poses: |distance| (m), normal angle (deg), colour distance (OKLab)."""

    poses: int
    error: F64
    angle: F64
    delta_e: F64


def skin_departures(
    rig: CompiledRig,
    mesh: Mesh,
    normals: F64,
    weights: tuple[npt.NDArray[np.int32], F64],
    skeleton: Skeleton,
    choice: deform.DeformationChoice,
    colour: BakedColour,
    poses: tuple[Pose, ...],
    k_floor: float,
    on_seam: npt.NDArray[np.bool_],
) -> Departures:
    """The skin against the posed field over ``poses`` and the rest pose: position, normal and colour.

    A vertex inside a part that does not skin it (a limb swinging through the body, a rope tip through a
    shell) is hidden by that part and measured by none of the three. Elsewhere the position error is
    |distance| on a joint's seam (a dent or a bulge of the skin shows in the silhouette) and the distance
    outside the field off the seams: a vertex that moves rigidly with its part can only end up outside
    the posed field where a blend fillet moved away, which is seen, while inside it is covered."""
    error = np.zeros(mesh.vertex_count)
    angle = np.zeros(mesh.vertex_count)
    delta_e = np.zeros(mesh.vertex_count)
    baked = baked_rgb(colour.slots, colour.weights, rig.slots[:, col.RGB])
    own = np.zeros((mesh.vertex_count, rig.slot_count), dtype=bool)
    np.put_along_axis(own, weights[0].astype(np.int64), weights[1] > 0.0, axis=1)
    for pose in (Pose.identity(rig.slot_count), *poses):
        skinned = skinning.skin(
            mesh.vertices, normals, weights[0], weights[1], pose, choice.methods, skeleton, choice.centers
        )
        table = posed_slots(rig.slots, pose)
        field = sample_graph(rig.graph, table, skinned.positions, k_floor)
        leaves, _ = primitive_field(table, skinned.positions)
        seen = ~((leaves.T < 0.0) & ~own).any(axis=1)
        unit = field.gradient / np.maximum(np.linalg.norm(field.gradient, axis=1, keepdims=True), 1e-30)
        cos = np.clip((unit * skinned.normals).sum(axis=1), -1.0, 1.0)
        miss = np.where(on_seam, np.abs(field.distance), np.maximum(field.distance, 0.0))
        error = np.maximum(error, np.where(seen, miss, 0.0))
        angle = np.maximum(angle, np.where(seen, np.degrees(np.arccos(cos)), 0.0))
        lab = np.linalg.norm(linear_to_oklab(baked) - linear_to_oklab(field.color), axis=1)
        delta_e = np.maximum(delta_e, np.where(seen, lab, 0.0))
    return Departures(len(poses) + 1, error, angle, delta_e)


def field_vertices(departures: Departures, position_tol: float, tol: SkinTolerance) -> npt.NDArray[np.bool_]:
    """The vertices the skin alone does not carry within the tier's tolerances."""
    mask: npt.NDArray[np.bool_] = (
        (departures.error > position_tol)
        | (departures.angle > tol.normal_deg)
        | (departures.delta_e > tol.delta_e)
    )
    return mask


@dataclass(frozen=True)
class SkinContract:
    poses: int
    vertices: int  # all of the mesh
    field_vertices: int  # those that evaluate the full graph
    error: float  # worst position departure of a skin vertex, m
    worst_part: str  # part.<id> of the dominant slot of that vertex
    normal_deg: tuple[float, float, float]  # p50, p99, max over skin vertices
    delta_e: tuple[float, float, float]  # p50, p99, max over skin vertices (OKLab)
    projected_px: float  # largest size of L on screen, px, where error stays under SUBPIXEL_PX
    truncation: float  # baked colour vs the full kernel at rest, max linear channel

    def describe(self) -> dict[str, object]:
        return {
            "poses": self.poses,
            "vertices": self.vertices,
            "fieldVertices": self.field_vertices,
            "skinErrorMax": self.error,
            "worstPart": self.worst_part,
            "normalAngleDeg": dict(zip(("p50", "p99", "max"), self.normal_deg, strict=True)),
            "deltaEOklab": dict(zip(("p50", "p99", "max"), self.delta_e, strict=True)),
            "subpixelPx": SUBPIXEL_PX,
            "projectedSizeMaxPx": self.projected_px,
            "bakedColourTruncation": self.truncation,
        }


def skin_contract(
    departures: Departures,
    field: npt.NDArray[np.bool_],
    owner: npt.NDArray[np.int32],
    rig: CompiledRig,
    colour: BakedColour,
) -> SkinContract:
    """What the skin vertices (not ``field``) give up, summarised."""
    skin = ~field

    def spread(x: F64) -> tuple[float, float, float]:
        if not x.size:
            return 0.0, 0.0, 0.0
        return float(np.percentile(x, 50)), float(np.percentile(x, 99)), float(x.max())

    error = np.where(skin, departures.error, 0.0)
    worst = int(np.argmax(error)) if error.size else 0
    worst_error = float(error.max()) if error.size else 0.0
    part = f"part.{rig.slot_parts[int(owner[worst])]}" if error.size and worst_error > 0.0 else ""
    px = SUBPIXEL_PX * rig.body_scale / worst_error if worst_error > 0.0 else MAX_REPORTED_PX
    return SkinContract(
        departures.poses,
        int(field.size),
        int(field.sum()),
        worst_error,
        part,
        spread(departures.angle[skin]),
        spread(departures.delta_e[skin]),
        min(px, MAX_REPORTED_PX),
        colour.truncation,
    )
