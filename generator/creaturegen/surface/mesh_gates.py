"""The rest mesh's gates for the surface build: every gate of surface/gates.py at the limits a build uses.

The limits live here because they are a build's choices (a fillet narrower than a few lattice cells, the
crease band between blend roots), while surface/gates.py measures; a failed gate is named after the part
nearest its worst place so the refusal says where.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from ..candidates import TIERS
from ..model.skeleton import Skeleton
from ..rig import CompiledRig
from .components import ComponentPolicy, component_policy
from .extract import Extraction
from .field64 import BodyField
from .gates import (
    DISTANCE_TOL,
    FACE_NORMAL_P99_DEG,
    VERTEX_NORMAL_P99_DEG,
    SurfaceGate,
    mesh_gates,
)
from .grid import ERROR_TARGET, FINEST_TIER, Grid
from .handles import handle_contacts
from .mesh import Mesh
from .skin_tier import SUBPIXEL_PX
from .topology import components

F64 = npt.NDArray[np.float64]

#: Our extracted and relaxed meshes keep their 1st-percentile minimum angle above this (degrees); raw
#: marching cubes would sit near 1.5°, which is why the relaxation exists.
MIN_ANGLE_P1_DEG = 15.0
#: Mesh-normal maxima (degrees): a blend fillet narrower than a few lattice cells turns the true normal
#: faster than a triangle can follow, so the worst vertex sits well above the bulk (the p99 gates of
#: surface/gates.py stay at 5° and 10°). Shading uses the analytic normals stored per vertex, not these.
VERTEX_NORMAL_MAX_DEG = 45.0
FACE_NORMAL_MAX_DEG = 60.0


#: Vertices within this many lattice cells of a hard-min crease between two blend roots are left out of
#: the normal gates: the analytic normal itself jumps there, so no mesh normal can agree with it.
CREASE_BAND_CELLS = 2.0
#: The mesh gates an edge flip (surface/flips.py) and a local subdivision (surface/subdivide.py) can mend,
#: tried in that order before a finer lattice.
#: (vertex max, vertex p99, face max, face p99) normal angles, degrees: every mesh gate pass uses these.
NORMAL_LIMITS = (VERTEX_NORMAL_MAX_DEG, VERTEX_NORMAL_P99_DEG, FACE_NORMAL_MAX_DEG, FACE_NORMAL_P99_DEG)
NORMAL_GATES = frozenset(
    {"vertexNormalAngleMax", "vertexNormalAngleP99", "faceNormalAngleMax", "faceNormalAngleP99", "inverted"}
)


#: The area-weighted tails among them: a second, finer split pass answers these (subdivide.TAIL_MARKS).
P99_GATES = frozenset({"vertexNormalAngleP99", "faceNormalAngleP99"})


@dataclass(frozen=True)
class MeshLimits:
    """The thresholds of the geometric mesh gates at one tier; topology, components, angles and
    intersections are every tier's alike."""

    distance: float  # surfaceToZeroSet and zeroSetToMesh, fraction of L
    normals: tuple[float, float, float, float]  # NORMAL_LIMITS' order, degrees


def mesh_limits(tier: str) -> MeshLimits:
    """A tier's mesh is judged at the fidelity its bodies are drawn at, or a lower tier would refine to
    the hero's mesh and draw as many vertices for a body a few dozen pixels tall (it did: the distant
    hopper drew the hero's 6,458). Distances scale with the tier's sagitta target (ERROR_TARGET: 2 and 4
    times the hero's, 0.01 and 0.02 L), which is what its lattice spacing was chosen for; the p99 normal
    angles are the tier's own skin tolerance (candidates TIERS: 10° at repeated, 20° at distant; the
    angle past which a skin vertex already becomes a field vertex), face p99 twice that as at the hero.
    The worst-vertex maxima stay the hero's: they catch a fold, which no distance makes invisible. What a
    mesh gives up is reported with it (``surface_error``: the largest size on screen at which it stays
    subpixel), so a tier is chosen by projected size, never drawn larger unknowingly."""
    if tier == FINEST_TIER:
        return MeshLimits(DISTANCE_TOL, NORMAL_LIMITS)
    skin = TIERS[tier].skin
    assert skin is not None, f"tier {tier} has no skin tolerance"
    ratio = ERROR_TARGET[tier] / ERROR_TARGET[FINEST_TIER]
    normals = (VERTEX_NORMAL_MAX_DEG, skin.normal_deg, FACE_NORMAL_MAX_DEG, 2.0 * skin.normal_deg)
    return MeshLimits(DISTANCE_TOL * ratio, normals)


def surface_error(gates: list[SurfaceGate]) -> dict[str, float]:
    """What the rest mesh gives up against the zero set, for choosing a tier by projected size: the worse
    of its two distance gates (fraction of L) and the largest size of L on screen, in pixels, at which
    that stays under SUBPIXEL_PX (the skin representation's ``projectedSizeMaxPx`` says the same of the
    skin's departure over the motion)."""
    worst = max(g.value for g in gates if g.name in ("surfaceToZeroSet", "zeroSetToMesh"))
    return {
        "distanceMax": worst,
        "subpixelPx": SUBPIXEL_PX,
        "projectedSizeMaxPx": SUBPIXEL_PX / max(worst, 1e-12),
    }


def surface_mesh_gates(
    rig: CompiledRig, ex: Extraction, rest_field: BodyField, skeleton: Skeleton, grid: Grid
) -> tuple[list[SurfaceGate], ComponentPolicy]:
    """Every mesh gate at the thresholds of the lattice's tier (``mesh_limits``), plus the component
    policy's (one list for the build and bench/surface, so both judge a mesh the same way). When the
    euler gate fails, the policy carries the contacts that close the handles and the gate's detail names
    them."""
    names = skeleton.names
    limits = mesh_limits(grid.tier)
    policy = component_policy(ex.mesh, rig.slots, rig.graph, names)
    gates = mesh_gates(
        ex.mesh,
        length_scale=rig.body_scale,
        distance=rest_field.distance,
        gradient=rest_field.gradient,
        field=rest_field.field,
        expected_components=policy.expected,
        min_angle_bound_deg=MIN_ANGLE_P1_DEG,
        surface_tol=limits.distance,
        coverage_tol=limits.distance,
        vertex_normal_max_deg=limits.normals[0],
        vertex_normal_p99_deg=limits.normals[1],
        face_normal_max_deg=limits.normals[2],
        face_normal_p99_deg=limits.normals[3],
        smooth=rest_field.smooth(CREASE_BAND_CELLS * grid.spacing),
    )
    strays = f"components {list(policy.strays)} own no slot" if policy.strays else ""
    euler = next(g for g in gates if g.name == "euler")
    if not euler.passed:
        distances = rest_field.slot_distances(ex.mesh.vertices)
        found = handle_contacts(ex.mesh, distances, rest_field.distance, skeleton, rig.slots, rig.slot_parts)
        policy = replace(policy, handles=found)
        gates = [_name_parts(g, ex.mesh, policy, names) if g is euler else g for g in gates]
    gates = [g if g.passed or g.where is None else _name_part_at(g, rest_field, names) for g in gates]
    gates += [
        SurfaceGate("strayComponents", float(len(policy.strays)), 0.0, "components", "max", strays),
        SurfaceGate(
            "unownedSlots",
            float(len(policy.unowned_slots)),
            0.0,
            "slots",
            "max",
            ", ".join(policy.unowned_slots),
        ),
        SurfaceGate("unbracketedEdges", float(ex.unresolved_edges), 0.0, "vertices", "max"),
    ]
    return gates, policy


def _name_parts(
    gate: SurfaceGate, mesh: Mesh, policy: ComponentPolicy, names: tuple[str, ...]
) -> SurfaceGate:
    """The euler gate's detail rewritten to name the contacts that close the handles (the parts to move)
    and, failing that, the parts of every component that is not a sphere."""
    found = components(mesh)
    bad = [c for c in range(found.count) if int(found.euler[c]) != 2]
    culprits = [c for c in policy.handles if c.culprit]
    if culprits:
        genus = sum(float(found.genus[c]) for c in bad)
        detail = f"genus {genus:g}, expected 0 (the skeleton is a tree): " + "; ".join(
            c.describe() for c in culprits
        )
        return SurfaceGate(gate.name, gate.value, gate.threshold, gate.unit, gate.direction, detail)
    parts = []
    for c in bad:
        owned = ", ".join(n for n, o in zip(names, policy.owners, strict=True) if o == c)
        parts.append(f"genus {float(found.genus[c]):g} in the component of {owned}")
    return SurfaceGate(gate.name, gate.value, gate.threshold, gate.unit, gate.direction, "; ".join(parts))


def _name_part_at(gate: SurfaceGate, rest_field: BodyField, names: tuple[str, ...]) -> SurfaceGate:
    """A failed gate's detail with the part whose primitive is nearest the gate's worst point."""
    assert gate.where is not None
    slot = int(np.argmin(rest_field.slot_distances(np.asarray([gate.where]))[:, 0]))
    at = ", ".join(f"{v:.4g}" for v in gate.where)
    detail = "; ".join(x for x in (gate.detail, f"near {names[slot]} at ({at}) m") if x)
    return replace(gate, detail=detail)
