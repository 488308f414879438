"""Mesh-validity gates: does an extracted closed mesh faithfully and cleanly represent the field's zero set?

Why these gates: a mesh can be combinatorially perfect and still be the wrong surface (displaced, missing
a lobe, normals fighting the field), or sit on the right surface and still break a renderer or a
physics step (holes, pinches, flipped or duplicated sheets, self-crossings, slivers). Each gate measures
one of those failure modes with a number and a threshold, so a report says how far off a mesh is, not
only that it is.

Every threshold is a parameter. Defaults:
- counts (boundary/non-manifold edges, non-manifold vertices, winding, χ ≠ 2, degenerate, inverted,
  intersecting and coincident pairs) must be 0; components must equal ``expected_components`` (1);
- degenerate area below ``AREA_EPS_FACTOR``·L² (1e-12·L²);
- 1st-percentile minimum triangle angle at least ``MIN_ANGLE_P1_DEG`` (1°: raw marching cubes on a
  smooth surface sits near 1.5°, so this catches a sliver tail, not marching cubes itself);
- surface→zero-set and zero-set→mesh distances at most ``DISTANCE_TOL``·L (0.005·L) each;
- normal angles against ∇d: vertex normals ``VERTEX_NORMAL_MAX_DEG``/``VERTEX_NORMAL_P99_DEG`` (15°/5°),
  face normals ``FACE_NORMAL_MAX_DEG``/``FACE_NORMAL_P99_DEG`` (30°/10°). Face maxima are looser because
  a sliver's normal follows its chord, not the surface. Area weighting biases vertex normals on the
  irregular fans marching cubes makes (a 5-cells-per-radius torus reaches p99 ≈ 5°, max ≈ 5.5°, while
  its face normals stay under 4°), hence the 5° p99. The p99s are over surface area, not element count
  (``_angle_gates``), so a mesh refined locally is judged by the same surface fraction.

The zero-set→mesh gate only sees the zero set that Newton reaches from its seeds: within
``SEED_OFFSET_FACTOR``·L of the mesh, or inside the mesh's box padded by ``BOX_PADDING_FACTOR``·L. A
lobe the mesh lacks entirely and that lies outside that box goes unseen.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from . import topology
from .field64 import newton_project
from .intersect import BVH, distances_to_mesh, point_triangle_distance, self_intersections, triangle_bvh
from .mesh import Mesh, angles_deg

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
DistanceFn = Callable[[F64], F64]
#: True where the field's gradient is continuous (off a hard-min crease), so a normal comparison means
#: something; the normal gates skip the other points and say how many.
SmoothFn = Callable[[F64], npt.NDArray[np.bool_]]
GradientFn = Callable[[F64], F64]
#: Distance and gradient in one pass (points → (d, ∇d)); the values ``DistanceFn`` and ``GradientFn`` give.
FieldFn = Callable[[F64], tuple[F64, F64]]
Direction = Literal["max", "min"]

AREA_EPS_FACTOR = 1e-12
MIN_ANGLE_P1_DEG = 1.0
DISTANCE_TOL = 0.005
VERTEX_NORMAL_MAX_DEG = 15.0
VERTEX_NORMAL_P99_DEG = 5.0
FACE_NORMAL_MAX_DEG = 30.0
FACE_NORMAL_P99_DEG = 10.0
#: A Newton-projected seed counts as on the zero set below this |d|, as a fraction of L.
CONVERGED_FACTOR = 1e-10
#: Seeds for the zero-set→mesh gate: vertex seeds (subsampled past this), random box seeds, offset ±.
VERTEX_SEEDS = 20000
BOX_SEEDS = 2048
SEED_OFFSET_FACTOR = 0.02
BOX_PADDING_FACTOR = 0.1
NEWTON_STEPS = 8
#: A projected point within this fraction of the convergence tolerance takes no further Newton step: it can
#: move the point by no more than a thousandth of what the gates could see.
SETTLED_FRACTION = 1e-3
#: Interior barycentric sample points per face besides the centroid (the three (2/3, 1/6, 1/6) points).
_INTERIOR = np.array([[4.0, 1.0, 1.0], [1.0, 4.0, 1.0], [1.0, 1.0, 4.0], [2.0, 2.0, 2.0]]) / 6.0


@dataclass(frozen=True)
class SurfaceGate:
    """One measured property: passes when value ≤ threshold ('max') or value ≥ threshold ('min')."""

    name: str
    value: float
    threshold: float
    unit: str
    direction: Direction = "max"
    detail: str = ""
    #: A point where the gate is worst (or first fails), so the build can name the part there; not
    #: stored in the sidecar, which records what was measured, not where to look.
    where: tuple[float, float, float] | None = field(default=None, compare=False)

    @property
    def passed(self) -> bool:
        if math.isnan(self.value):
            return False
        return self.value <= self.threshold if self.direction == "max" else self.value >= self.threshold

    def as_dict(self) -> dict[str, object]:
        return {
            "name": self.name,
            "value": self.value,
            "threshold": self.threshold,
            "unit": self.unit,
            "direction": self.direction,
            "passed": self.passed,
            "detail": self.detail,
        }


def _count_gate(name: str, count: int, unit: str, detail: str, where: F64 | None = None) -> SurfaceGate:
    return SurfaceGate(
        name, float(count), 0.0, unit, "max", detail if count else "", _point(where) if count else None
    )


def _point(p: F64 | None) -> tuple[float, float, float] | None:
    """A gate's location as plain floats (None when there is nothing to point at)."""
    if p is None or np.size(p) == 0:
        return None
    x, y, z = (float(v) for v in np.asarray(p, dtype=np.float64).reshape(-1, 3)[0])
    return (x, y, z)


def _at(mesh: Mesh, ids: npt.ArrayLike) -> F64 | None:
    """Mean position of the vertices of the first row of ``ids`` (a vertex, an edge or a face)."""
    rows = np.asarray(ids, dtype=np.int64)
    if rows.size == 0:
        return None
    first = rows.reshape(rows.shape[0], -1)[0]
    result: F64 = mesh.vertices[first].mean(axis=0)
    return result


def _first(ids: npt.ArrayLike, limit: int = 5) -> str:
    flat = np.asarray(ids)[:limit]
    return ", ".join(str(tuple(int(x) for x in row)) if np.ndim(row) else str(int(row)) for row in flat)


def vertex_normals(mesh: Mesh) -> F64:
    """Area-weighted: the unnormalised face normal is twice the area vector, so a plain sum weights it."""
    fn = mesh.face_normals()
    out = np.zeros((mesh.vertex_count, 3))
    for k in range(3):
        np.add.at(out, mesh.faces[:, k], fn)
    return out


def project_to_zero_set(
    points: F64,
    distance: DistanceFn,
    gradient: GradientFn,
    steps: int,
    tol: float,
    *,
    field: FieldFn | None = None,
    initial: tuple[F64, F64] | None = None,
) -> tuple[F64, npt.NDArray[np.bool_], F64]:
    """Newton onto the zero set (field64.newton_project); returns the points, which ended with
    |d| < tol and the gradient there. The gates measure only converged points, so a bad seed cannot
    fake a failure. ``field`` (distance and gradient in one pass) and ``initial`` (its values at
    ``points``, already known) save evaluations and change no value."""
    fused = field if field is not None else _fused(distance, gradient)
    p, d, g = newton_project(fused, points, steps, initial, settled=SETTLED_FRACTION * tol)
    return p, np.abs(d) < tol, g


def _fused(distance: DistanceFn, gradient: GradientFn) -> FieldFn:
    return lambda q: (distance(q), gradient(q))


def surface_samples(mesh: Mesh, table: topology.EdgeTable) -> tuple[F64, I64]:
    """Points on every triangle (vertices, edge midpoints, centroid, interior points) and one face per
    point, for reporting where the worst one lies."""
    v = mesh.vertices
    faces = mesh.faces.astype(np.int64)
    face_of_vertex = np.zeros(mesh.vertex_count, dtype=np.int64)
    face_of_vertex[faces.reshape(-1)] = np.repeat(np.arange(mesh.face_count), 3)
    used = np.zeros(mesh.vertex_count, dtype=bool)
    used[faces.reshape(-1)] = True
    mids = 0.5 * (v[table.edges[:, 0]] + v[table.edges[:, 1]])
    face_of_edge = np.zeros(table.edges.shape[0], dtype=np.int64)
    face_of_edge[table.edge_of_half] = np.repeat(np.arange(mesh.face_count), 3)
    interior = np.einsum("kc,fcd->fkd", _INTERIOR, mesh.corners()).reshape(-1, 3)
    points = np.concatenate([v[used], mids, interior])
    owner = np.concatenate(
        [face_of_vertex[used], face_of_edge, np.repeat(np.arange(mesh.face_count), _INTERIOR.shape[0])]
    )
    return points, owner.astype(np.int64)


def coverage_seeds(mesh: Mesh, normals: F64, length_scale: float, rng: np.random.Generator) -> F64:
    """Vertices pushed ± along their normals plus uniform points in the padded box: seeds that Newton
    carries onto the zero set both near the mesh and (from the box) near parts the mesh may have missed."""
    if mesh.vertex_count == 0:
        return np.zeros((0, 3))
    used = np.unique(mesh.faces.reshape(-1))
    if used.size > VERTEX_SEEDS:
        used = rng.choice(used, VERTEX_SEEDS, replace=False)
    n = normals[used]
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.where(norm > 0, n / np.where(norm > 0, norm, 1.0), 0.0)
    offset = rng.uniform(-1.0, 1.0, size=(used.size, 1)) * SEED_OFFSET_FACTOR * length_scale
    near = mesh.vertices[used] + offset * n
    lo = mesh.vertices.min(axis=0) - BOX_PADDING_FACTOR * length_scale
    hi = mesh.vertices.max(axis=0) + BOX_PADDING_FACTOR * length_scale
    box = rng.uniform(lo, hi, size=(BOX_SEEDS, 3))
    result: F64 = np.concatenate([near, box])
    return result


def zero_set_to_mesh(mesh: Mesh, bvh: BVH, points: F64) -> F64:
    """Exact distance from each point to the mesh: the triangle with the nearest centroid gives an upper
    bound, the BVH then visits only boxes within it."""
    corners = mesh.corners()
    centroids = corners.mean(axis=1)
    _, nearest = cKDTree(centroids).query(points, k=1)
    upper = point_triangle_distance(points, corners[np.asarray(nearest, dtype=np.int64)])
    return distances_to_mesh(bvh, corners, points, upper)


def mesh_gates(
    mesh: Mesh,
    *,
    length_scale: float,
    distance: DistanceFn,
    gradient: GradientFn,
    expected_components: int = 1,
    min_angle_bound_deg: float = MIN_ANGLE_P1_DEG,
    area_eps_factor: float = AREA_EPS_FACTOR,
    surface_tol: float = DISTANCE_TOL,
    coverage_tol: float = DISTANCE_TOL,
    vertex_normal_max_deg: float = VERTEX_NORMAL_MAX_DEG,
    vertex_normal_p99_deg: float = VERTEX_NORMAL_P99_DEG,
    face_normal_max_deg: float = FACE_NORMAL_MAX_DEG,
    face_normal_p99_deg: float = FACE_NORMAL_P99_DEG,
    seed: int = 0,
    smooth: SmoothFn | None = None,
    field: FieldFn | None = None,
) -> list[SurfaceGate]:
    """All gates, in a fixed order; distances are reported as fractions of ``length_scale`` (L).

    ``distance(points (N,3)) -> (N,)`` and ``gradient(points) -> (N,3)`` are the analytic field in float64
    (the gradient need not be unit length); ``field(points) -> (d, g)``, when given, must return exactly
    those two in one pass (BodyField.field), which the Newton projections use. Every gate is always
    evaluated, so one report lists every failure at once.
    """
    table = topology.edge_table(mesh.faces)
    bvh = triangle_bvh(mesh)
    gates = topology_gates(
        mesh, table, expected_components, area_eps_factor * length_scale**2, min_angle_bound_deg
    )
    gates += intersection_gates(mesh, bvh)
    gates += field_gates(
        mesh,
        table,
        bvh,
        length_scale=length_scale,
        distance=distance,
        gradient=gradient,
        surface_tol=surface_tol,
        coverage_tol=coverage_tol,
        normal_limits=(
            vertex_normal_max_deg,
            vertex_normal_p99_deg,
            face_normal_max_deg,
            face_normal_p99_deg,
        ),
        seed=seed,
        smooth=smooth,
        field=field,
    )
    return gates


def topology_gates(
    mesh: Mesh,
    table: topology.EdgeTable,
    expected_components: int,
    area_eps: float,
    min_angle_bound_deg: float,
) -> list[SurfaceGate]:
    """The combinatorial gates plus the per-triangle shape gates (degenerate, min angle)."""
    edges = topology.edge_report(mesh, table)
    valence = table.valence
    bad_vertices = topology.nonmanifold_vertices(mesh, table)
    comps = topology.components(mesh, table)
    chi = comps.euler
    off_chi = np.flatnonzero(chi != 2)
    degenerate = np.flatnonzero(topology.degenerate_faces(mesh, area_eps))
    angles = topology.min_angles_deg(mesh)
    p1 = topology.min_angle_percentile_deg(angles, 1.0)
    components_off = abs(comps.count - expected_components)
    return [
        _count_gate(
            "watertight",
            edges.boundary_edges,
            "edges",
            f"{edges.boundary_edges} boundary edges, first {_first(table.edges[valence == 1])}",
            _at(mesh, table.edges[valence == 1]),
        ),
        _count_gate(
            "edgeManifold",
            edges.nonmanifold_edges,
            "edges",
            f"{edges.nonmanifold_edges} edges with >2 faces, first {_first(table.edges[valence > 2])}",
            _at(mesh, table.edges[valence > 2]),
        ),
        _count_gate(
            "vertexManifold",
            int(bad_vertices.size),
            "vertices",
            f"first {_first(bad_vertices)}",
            _at(mesh, bad_vertices),
        ),
        _count_gate("winding", edges.winding_violations, "edges", "half-edges not paired head to tail"),
        _count_gate(
            "euler",
            int(off_chi.size),
            "components",
            f"χ per component {chi[:8].tolist()}; "
            f"genus {comps.genus[off_chi][:5].tolist()} at components {off_chi[:5].tolist()}",
        ),
        SurfaceGate(
            "components",
            float(components_off),
            0.0,
            "components",
            "max",
            f"found {comps.count}, expected {expected_components}; "
            f"faces per component {comps.faces[:8].tolist()}"
            if components_off
            else "",
        ),
        _count_gate(
            "degenerate",
            int(degenerate.size),
            "faces",
            f"area < {area_eps:.3g} or repeated index; first faces {_first(degenerate)}",
            _at(mesh, mesh.faces[degenerate]),
        ),
        SurfaceGate(
            "minAngleP1",
            p1,
            min_angle_bound_deg,
            "deg",
            "min",
            f"1st-percentile smallest triangle angle {p1:.3g}° below {min_angle_bound_deg:.3g}°"
            if p1 < min_angle_bound_deg
            else "",
            _point(_at(mesh, mesh.faces[[int(np.argmin(angles))]])) if p1 < min_angle_bound_deg else None,
        ),
    ]


def intersection_gates(mesh: Mesh, bvh: BVH) -> list[SurfaceGate]:
    """Self-intersections (any contact between faces sharing no vertex) and doubled coverage (coplanar
    contact, or two faces over the same vertex set)."""
    report = self_intersections(mesh, bvh=bvh)
    dups = topology.duplicate_faces(mesh)
    coverage = report.coincident + int(dups.shape[0])
    return [
        _count_gate(
            "selfIntersections",
            report.intersecting,
            "pairs",
            f"{report.intersecting} face pairs touch or cross ({report.coincident} coplanar), "
            f"first {_first(report.pairs)}",
            _at(mesh, mesh.faces[np.asarray(report.pairs, dtype=np.int64).reshape(-1)[:1]]),
        ),
        _count_gate(
            "coincidentCoverage",
            coverage,
            "pairs",
            f"{report.coincident} coplanar overlapping pairs (first {_first(report.coincident_pairs)}), "
            f"{dups.shape[0]} duplicate faces (first {_first(dups)})",
            _at(
                mesh,
                mesh.faces[np.r_[np.ravel(report.coincident_pairs), np.ravel(dups)][:1].astype(np.int64)],
            ),
        ),
    ]


def weighted_percentile(values: F64, weights: F64, percent: float) -> float:
    """The smallest value below which ``percent`` % of the total weight lies (inverted CDF)."""
    if values.size == 0:
        return 0.0
    order = np.argsort(values, kind="stable")
    cumulative = np.cumsum(weights[order])
    at = int(np.searchsorted(cumulative, percent / 100.0 * cumulative[-1], side="left"))
    return float(values[order][min(at, values.size - 1)])


def vertex_areas(mesh: Mesh) -> F64:
    """A third of the area of every face around each vertex (the vertex's share of the surface)."""
    third = np.linalg.norm(mesh.face_normals(), axis=1) / 6.0
    out = np.zeros(mesh.vertex_count)
    for k in range(3):
        np.add.at(out, mesh.faces[:, k], third)
    return out


def _angle_gates(
    prefix: str, angles: F64, ids: I64, points: F64, areas: F64, max_deg: float, p99_deg: float
) -> list[SurfaceGate]:
    """Max and p99 of the normal angles; both point at the worst one (where the tail is heaviest).

    The p99 is over surface area (each vertex weighted by its share of the area, each face by its own),
    not over element count: it bounds the fraction of the surface whose shading normal departs, which is
    what a viewer sees, and it does not depend on where the mesh is dense. On a lattice's mesh the two
    agree (marching cubes spreads vertices evenly); after local subdivision (surface/subdivide.py) a count
    would rise with every vertex added where the surface bends, although every angle there fell."""
    worst = float(np.max(angles)) if angles.size else 0.0
    p99 = weighted_percentile(angles, areas, 99.0)
    at = int(ids[np.argmax(angles)]) if angles.size else -1
    where = _point(points[np.argmax(angles)]) if angles.size else None
    return [
        SurfaceGate(
            f"{prefix}NormalAngleMax", worst, max_deg, "deg", "max", f"worst at {prefix} {at}", where
        ),
        SurfaceGate(f"{prefix}NormalAngleP99", p99, p99_deg, "deg", "max", "", where),
    ]


def field_gates(
    mesh: Mesh,
    table: topology.EdgeTable,
    bvh: BVH,
    *,
    length_scale: float,
    distance: DistanceFn,
    gradient: GradientFn,
    surface_tol: float,
    coverage_tol: float,
    normal_limits: Sequence[float],
    seed: int,
    smooth: SmoothFn | None = None,
    field: FieldFn | None = None,
) -> list[SurfaceGate]:
    """Gates against the analytic field: orientation, two-sided distance, normal agreement."""
    length = float(length_scale)
    tol = CONVERGED_FACTOR * length
    corners = mesh.corners()
    centroids = corners.mean(axis=1)
    fn = mesh.face_normals()
    fused = field if field is not None else _fused(distance, gradient)

    # The field at the centroids serves the orientation gate and starts their projection below.
    at_centroids = fused(centroids)
    inverted = np.flatnonzero(np.einsum("ij,ij->i", fn, at_centroids[1]) <= 0)

    samples, owner = surface_samples(mesh, table)
    residual = np.abs(distance(samples)) if samples.size else np.zeros(0)
    far = int(np.argmax(residual)) if residual.size else -1
    surface_err = float(residual[far]) / length if residual.size else math.nan

    normals = vertex_normals(mesh)
    seeds = coverage_seeds(mesh, normals, length, np.random.default_rng(seed))
    on_set, converged, _ = project_to_zero_set(seeds, distance, gradient, NEWTON_STEPS, tol, field=fused)
    on_set = on_set[converged]
    if on_set.shape[0] and mesh.face_count:
        gap = zero_set_to_mesh(mesh, bvh, on_set)
        worst = int(np.argmax(gap))
        coverage = float(gap[worst]) / length
        coverage_detail = (
            f"{on_set.shape[0]}/{seeds.shape[0]} seeds converged; farthest at {on_set[worst].tolist()}"
        )
        coverage_at = _point(on_set[worst])
    else:
        coverage_at = None
        coverage = math.inf
        coverage_detail = f"no seed of {seeds.shape[0]} converged onto the zero set"

    return [
        _count_gate(
            "inverted",
            int(inverted.size),
            "faces",
            f"normal · ∇d ≤ 0 at centroid; first {_first(inverted)}",
            centroids[inverted[:1]],
        ),
        SurfaceGate(
            "surfaceToZeroSet",
            surface_err,
            surface_tol,
            "L",
            "max",
            f"max |d| on {samples.shape[0]} samples at face {int(owner[far]) if far >= 0 else -1}",
            _point(samples[far]) if far >= 0 else None,
        ),
        SurfaceGate("zeroSetToMesh", coverage, coverage_tol, "L", "max", coverage_detail, coverage_at),
        *_normal_gates(mesh, normals, (centroids, at_centroids), gradient, fused, tol, normal_limits, smooth),
    ]


def normal_gates(
    mesh: Mesh,
    *,
    length_scale: float,
    field: FieldFn,
    normal_limits: Sequence[float],
    smooth: SmoothFn | None = None,
) -> list[SurfaceGate]:
    """The four normal-angle gates alone, exactly as ``field_gates`` computes them: what a local remedy
    for them must pass first, at a fraction of a full gate pass (no surface samples, coverage seeds,
    topology or intersections)."""
    centroids = mesh.corners().mean(axis=1)
    tol = CONVERGED_FACTOR * float(length_scale)
    return _normal_gates(
        mesh,
        vertex_normals(mesh),
        (centroids, field(centroids)),
        lambda q: field(q)[1],
        field,
        tol,
        normal_limits,
        smooth,
    )


def _normal_gates(
    mesh: Mesh,
    normals: F64,
    at_centroids: tuple[F64, tuple[F64, F64]],
    gradient: GradientFn,
    fused: FieldFn,
    tol: float,
    normal_limits: Sequence[float],
    smooth: SmoothFn | None,
) -> list[SurfaceGate]:
    """Vertex normals against ∇d at the vertices, face normals against ∇d at their centroids' feet on the
    zero set (``at_centroids``: the centroids and the field there); off the crease band when ``smooth``."""
    centroids, start = at_centroids
    fn = mesh.face_normals()
    used = np.unique(mesh.faces.reshape(-1)).astype(np.int64)
    feet, _, at_feet = project_to_zero_set(
        centroids, lambda q: fused(q)[0], gradient, NEWTON_STEPS, tol, field=fused, initial=start
    )
    face_ids = np.arange(mesh.face_count, dtype=np.int64)
    if smooth is not None:
        used = used[smooth(mesh.vertices[used])]
        keep = smooth(feet)
        face_ids, feet, fn, at_feet = face_ids[keep], feet[keep], fn[keep], at_feet[keep]
    vertex_angles = angles_deg(normals[used], gradient(mesh.vertices[used]))
    face_angles = angles_deg(fn, at_feet)
    v_areas = vertex_areas(mesh)[used]
    f_areas = np.linalg.norm(fn, axis=1)
    vmax, vp99, fmax, fp99 = normal_limits
    return [
        *_angle_gates("vertex", vertex_angles, used, mesh.vertices[used], v_areas, vmax, vp99),
        *_angle_gates("face", face_angles, face_ids, feet, f_areas, fmax, fp99),
    ]
