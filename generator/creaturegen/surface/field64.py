"""float64 body distance and analytic gradient at points: the reference every surface stage measures with.

Thin wrappers over field/sampler.py so surface code never forms colours it does not need, and chunked so
a 10⁵-vertex mesh does not allocate (slots × points × 3) temporaries at once.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..field.primitives import primitive_distance, primitive_field
from ..field.sampler import evaluate_distance, evaluate_graph, evaluate_op_distances
from ..model.graph import BlendGraph

F64 = npt.NDArray[np.float64]
#: Points per evaluation pass: the (slots × points) temporaries of a pass stay cache-sized (results are
#: per point, so the chunk changes no value; 4096 measured fastest on a 26-slot body).
CHUNK = 4096


@dataclass(frozen=True)
class BodyField:
    """The rest (or any posed) slot table with its program: callable distance and gradient."""

    graph: BlendGraph
    slots: F64

    def distance(self, points: npt.ArrayLike) -> F64:
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        out = np.empty(p.shape[0])
        for s in range(0, p.shape[0], CHUNK):
            out[s : s + CHUNK] = evaluate_distance(
                self.graph, primitive_distance(self.slots, p[s : s + CHUNK])
            )
        return out

    def field(self, points: npt.ArrayLike) -> tuple[F64, F64]:
        """Distance (P,) and unnormalised analytic gradient (P, 3)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        d = np.empty(p.shape[0])
        g = np.empty((p.shape[0], 3))
        for s in range(0, p.shape[0], CHUNK):
            ds, gs = primitive_field(self.slots, p[s : s + CHUNK])
            d[s : s + CHUNK], g[s : s + CHUNK] = evaluate_graph(self.graph, ds, gs)
        return d, g

    def root_distances(self, points: npt.ArrayLike) -> F64:
        """(R, P) each blend root's distance: the body is their hard min, creased where two tie."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        out = np.empty((len(self.graph.roots), p.shape[0]))
        for s in range(0, p.shape[0], CHUNK):
            d_slots = primitive_distance(self.slots, p[s : s + CHUNK])
            values = evaluate_op_distances(self.graph, d_slots)
            for n, r in enumerate(self.graph.roots):
                out[n, s : s + CHUNK] = d_slots[r.index] if r.kind == "slot" else values[r.index]
        return out

    def smooth(self, band: float) -> Callable[[F64], npt.NDArray[np.bool_]]:
        """A mask function: True where no two roots come within ``band`` of each other (off the crease)."""

        def mask(points: F64) -> npt.NDArray[np.bool_]:
            if len(self.graph.roots) < 2:
                return np.ones(np.asarray(points).reshape(-1, 3).shape[0], dtype=bool)
            two = np.sort(self.root_distances(points), axis=0)[:2]
            result: npt.NDArray[np.bool_] = (two[1] - two[0]) > band
            return result

        return mask

    def gradient(self, points: npt.ArrayLike) -> F64:
        return self.field(points)[1]

    def slot_distances(self, points: npt.ArrayLike) -> F64:
        """(S, P) every slot's own distance: who dominates where (weights, ownership)."""
        result: F64 = primitive_distance(
            self.slots, np.asarray(points, dtype=np.float64).reshape(-1, 3)
        ).astype(np.float64, copy=False)
        return result


#: Squared gradient below which a point has no Newton direction and is left where it is.
NEWTON_FLOOR = 1e-20
FieldFn = Callable[[F64], tuple[F64, F64]]


def newton_project(
    fn: FieldFn,
    points: F64,
    steps: int,
    initial: tuple[F64, F64] | None = None,
    settled: float = 0.0,
) -> tuple[F64, F64, F64]:
    """Newton steps ``p ← p − d∇d/|∇d|²`` onto the zero set of ``fn`` (points → (d, ∇d)); returns the
    points with their final d and ∇d. Points with a vanishing gradient (a medial axis, a crease) stay put;
    callers gate on |d|. ``initial``: ``fn(points)`` when the caller already has it.

    Only points that can still move are evaluated again: a point whose gradient vanished would be stepped
    by nothing, and one with |d| ≤ ``settled`` is already where the caller's tolerance needs it (Newton
    converges quadratically, so most of a mesh's centroids settle in two or three of the steps asked for;
    re-evaluating them was most of the gates' time on a large mesh)."""
    p = np.array(points, dtype=np.float64, copy=True)
    d, g = fn(p) if initial is None else initial
    d, g = np.array(d, dtype=np.float64, copy=True), np.array(g, dtype=np.float64, copy=True)
    live = np.flatnonzero(np.abs(d) > settled)
    for _ in range(steps):
        gg = np.einsum("ij,ij->i", g[live], g[live])
        ok = gg > NEWTON_FLOOR
        live = live[ok]
        if live.size == 0:
            break
        p[live] -= (d[live] / gg[ok])[:, None] * g[live]
        d[live], g[live] = fn(p[live])
        live = live[np.abs(d[live]) > settled]
    return p, d, g


def project(field: BodyField, points: F64, steps: int = 3) -> tuple[F64, F64, F64]:
    """``newton_project`` on the body field, distance and gradient fused in one pass per step."""
    return newton_project(field.field, points, steps)
