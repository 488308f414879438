"""Bounded local field correction of skinned vertices: Newton toward the posed field, never unbounded.

One step is ``Δp = −(d − iso)·∇d/|∇d|²``. It is trusted only inside a radius taken from the mesh around the
vertex (a fraction of its shortest incident edge, of the radius of the slot it is bound to, and of its
curvature radius estimated from the rest normals), because a Newton step that leaves that ball can
jump to another sheet of the field or fold the triangle fan. A step that does not reduce |d − iso| is
halved (backtracking). Every field evaluation after the initial query is a *trial* and spends from one
budget shared by steps and backtracks (the seed's S, so the GPU's cost is exactly (S + 1)·K).

A vertex keeps its skinned position (the correction is rejected) when:
- the gradient is degenerate (|∇d|² below a floor): no usable direction;
- descent fails: the budget runs out without reducing |d − iso|;
- a corrected incident triangle inverts against the posed field normal (checked on the CPU over the
  whole fan; the GPU checks the per-vertex proxy: the field normal at the corrected point must agree with
  the skinned normal within ``NORMAL_AGREEMENT``).
Only vertices the region policy marks (the skin alone fails its error gate there) are corrected.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .field64 import BodyField
from .mesh import Mesh

F64 = npt.NDArray[np.float64]
B = npt.NDArray[np.bool_]

#: Trust radius: the smallest of these fractions of the shortest incident edge, the bound slot's
#: radius and the local curvature radius.
TRUST_EDGE = 0.5
TRUST_RADIUS = 0.25
TRUST_CURVATURE = 0.5
#: Squared-gradient floor below which a vertex has no usable Newton direction.
GRADIENT_FLOOR = 1e-8
#: Per-vertex proxy for inversion on the GPU: cos of the largest accepted normal turn.
NORMAL_AGREEMENT = 0.0
#: Default shared trial budget S per vertex (the repeated tier's 2 of the seed's table).
DEFAULT_BUDGET = 2
#: Residual early-out: a vertex within this fraction of its trust radius of the iso level stops
#: spending trials (the seed's "residual early-out").
EARLY_OUT = 1e-7


@dataclass(frozen=True)
class CorrectionReport:
    corrected: int  # vertices whose position changed
    considered: int  # vertices the region policy selected
    residual_before: float  # max |d − iso| over considered vertices, m
    residual_after: float  # max |d − iso| over considered vertices after correction, m
    residual_corrected: float  # max |d − iso| over the vertices that kept their correction, m
    clamped: int  # steps shortened to the trust radius
    backtracks: int  # trials that were halved
    rejected_gradient: int
    rejected_descent: int
    rejected_inversion: int
    trials: int  # field evaluations after the initial query, all vertices

    def as_dict(self) -> dict[str, float | int]:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def vertex_edge_floor(mesh: Mesh) -> F64:
    """Shortest incident edge length per vertex."""
    e = mesh.edges()
    length = np.linalg.norm(mesh.vertices[e[:, 0]] - mesh.vertices[e[:, 1]], axis=1)
    floor = np.full(mesh.vertex_count, np.inf)
    np.minimum.at(floor, e[:, 0], length)
    np.minimum.at(floor, e[:, 1], length)
    return floor


def vertex_curvature(mesh: Mesh, normals: F64) -> F64:
    """Largest normal turn per unit length over incident edges: a curvature bound per vertex."""
    e = mesh.edges()
    length = np.linalg.norm(mesh.vertices[e[:, 0]] - mesh.vertices[e[:, 1]], axis=1)
    turn = np.linalg.norm(normals[e[:, 0]] - normals[e[:, 1]], axis=1) / np.maximum(length, 1e-300)
    kappa = np.zeros(mesh.vertex_count)
    np.maximum.at(kappa, e[:, 0], turn)
    np.maximum.at(kappa, e[:, 1], turn)
    return kappa


def trust_radius(rest: Mesh, rest_normals: F64, bound_radius: F64) -> F64:
    """Per-vertex trust radius from the rest mesh (edge, slot radius, curvature), fixed at build time."""
    kappa = vertex_curvature(rest, rest_normals)
    curvature_radius = np.where(kappa > 0, 1.0 / np.maximum(kappa, 1e-300), np.inf)
    result: F64 = np.minimum.reduce(
        [
            TRUST_EDGE * vertex_edge_floor(rest),
            TRUST_RADIUS * bound_radius,
            TRUST_CURVATURE * curvature_radius,
        ]
    )
    return result


def _inverted_vertices(faces: npt.NDArray[np.int32], positions: F64, moved: B, field: BodyField) -> B:
    """Vertices of triangles that touch a moved vertex and face against the field normal. Only those
    fans can have changed, so only they pay a field evaluation (the rest are the skin's own triangles)."""
    faces = faces[np.any(moved[faces], axis=1)]
    c = positions[faces]
    n = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    g = field.gradient(c.mean(axis=1))
    bad = np.einsum("ij,ij->i", n, g) <= 0
    flags = np.zeros(positions.shape[0], dtype=bool)
    flags[faces[bad].reshape(-1)] = True
    return flags


def correct(
    field: BodyField,
    rest: Mesh,
    skinned: F64,
    skinned_normals: F64,
    region: B,
    trust: F64,
    *,
    budget: int = DEFAULT_BUDGET,
    iso: float = 0.0,
) -> tuple[F64, CorrectionReport]:
    """Corrected positions for the vertices in ``region``; everything else keeps its skinned position."""
    idx = np.flatnonzero(region)
    p = skinned[idx].copy()
    d, g = field.field(p)
    residual_before = float(np.max(np.abs(d - iso))) if idx.size else 0.0
    remaining = np.full(idx.size, budget)
    active = np.ones(idx.size, dtype=bool)
    gg = np.einsum("ij,ij->i", g, g)
    reject_gradient = gg < GRADIENT_FLOOR
    active &= ~reject_gradient
    start_err = np.abs(d - iso)
    clamped = backtracks = trials = 0
    scale = np.ones(idx.size)
    step = np.zeros_like(p)
    while True:
        done = np.abs(d - iso) <= EARLY_OUT * trust[idx]
        live = np.flatnonzero(active & (remaining > 0) & ~done)
        if live.size == 0:
            break
        # A fresh Newton step where the last trial succeeded; the halved one where it was rejected.
        fresh = live[scale[live] == 1.0]
        if fresh.size:
            s = -((d[fresh] - iso) / gg[fresh])[:, None] * g[fresh]
            length = np.linalg.norm(s, axis=1)
            over = length > trust[idx[fresh]]
            clamped += int(np.count_nonzero(over))
            s[over] *= (trust[idx[fresh]][over] / length[over])[:, None]
            step[fresh] = s
        trial = p[live] + scale[live][:, None] * step[live]
        dt, gt = field.field(trial)
        trials += live.size
        remaining[live] -= 1
        better = np.abs(dt - iso) < np.abs(d[live] - iso)
        ok, bad = live[better], live[~better]
        p[ok], d[ok], g[ok] = trial[better], dt[better], gt[better]
        gg[ok] = np.einsum("ij,ij->i", g[ok], g[ok])
        scale[ok] = 1.0
        scale[bad] *= 0.5
        backtracks += bad.size
        degenerate = ok[gg[ok] < GRADIENT_FLOOR]
        active[degenerate] = False
    improved = (np.abs(d - iso) < start_err) | (np.abs(d - iso) <= EARLY_OUT * trust[idx])
    reject_descent = ~improved & ~reject_gradient
    # The GPU's per-vertex inversion proxy: the corrected point's field normal must face the skinned one.
    turn = np.einsum("ij,ij->i", g, skinned_normals[idx]) <= NORMAL_AGREEMENT * np.sqrt(gg)
    accept = improved & ~reject_gradient & ~turn
    out = skinned.copy()
    out[idx[accept]] = p[accept]
    # The full check over each fan: any vertex of an inverted triangle falls back to its skinned place.
    moved = np.any(out != skinned, axis=1)
    inverted = _inverted_vertices(rest.faces, out, moved, field) & region & moved
    out[inverted] = skinned[inverted]
    final = np.abs(field.distance(out[idx]) - iso) if idx.size else np.zeros(0)
    kept = np.any(out[idx] != skinned[idx], axis=1)
    report = CorrectionReport(
        corrected=int(np.count_nonzero(np.any(out != skinned, axis=1))),
        considered=int(idx.size),
        residual_before=residual_before,
        residual_after=float(final.max()) if final.size else 0.0,
        residual_corrected=float(final[kept].max()) if kept.any() else 0.0,
        clamped=clamped,
        backtracks=int(backtracks),
        rejected_gradient=int(np.count_nonzero(reject_gradient)),
        rejected_descent=int(np.count_nonzero(reject_descent)),
        rejected_inversion=int(np.count_nonzero(turn & improved)) + int(np.count_nonzero(inverted)),
        trials=int(trials),
    )
    return out, report
