"""Skin weights of the reference mesh over slots: harmonic weights with handles and contact barriers.

Why not proximity weights. A weight that falls off with distance to a slot (``1/d``, a softmax of
``−d``) is never exactly 0 or 1, so every slot drags every vertex a little, and where two limbs touch at
rest a vertex of one limb is as close to the other limb as to its own: proximity glues them, and
posing pulls skin off one limb onto the other. Harmonic weights avoid both. Vertices a slot clearly
owns are pinned (Dirichlet handles, weight 1 on that slot); the free vertices between them take the
weights of least Dirichlet energy, so a transition is as smooth as the band between handles allows and
its width follows the joint's geometry rather than a kernel constant.

Handles. A vertex is a handle of its owner ``s`` (the slot with the smallest own signed distance) when
- it lies on that slot's own surface, ``d_s ≤ SURFACE_MARGIN · r_s``: the smooth-min only moves the
  surface outward of a slot where another slot is within the blend width, so this rejects vertices on
  a blend fillet; and
- every other slot is farther by a gap, ``d_s' − d_s ≥ max(HANDLE_GAP · min(r_s, r_s'), EDGE_GAP · h)``
  (``h`` the local edge length). The gap scales with the *thinner* slot of the pair because a joint
  region is limb-sized (a shell-sized gap would merge the free bands of neighbouring hips into one
  sheet), and never drops below a few edges, so no transition is squeezed into one edge ring of a
  coarse mesh.
A slot that owns vertices but has none passing both tests (a short rope segment whose joint bands
overlap, a part that only surfaces inside a blend) takes its owned vertices with the largest relative
gap (within ``FALLBACK_FRACTION`` of its best) as handles, so every slot with surface presence is
pinned; a slot that owns no vertex (buried) gets no handle and weight 0 everywhere, and the coverage
gate names it.

Contact barriers. Limbs touching at rest are joined by mesh edges; diffusion would carry one limb's
weight across the contact into the other. Two measures, both needed:
- every edge whose endpoints are owned by slots that are not skeleton neighbours
  (``Skeleton.neighbours``: the slot, its parent, its children) gets weight 0. This makes the contact
  a free (Neumann) boundary for both sides, so a limb's contact face keeps that limb's weight instead
  of being dragged toward the other limb's zero. Cutting can strand free vertices from every handle
  (an island of one slot's ownership in another's territory); such a component has no boundary data,
  so the cut edges around it are restored (repeatedly), and a component that still reaches no handle
  is pinned to its vertices' owners;
- slot ``s`` may be non-zero only on vertices owned by its skeleton neighbours. Cutting alone is not
  enough: at a three-way junction (a knee buried in the body, so the lower leg touches the body beside
  the upper leg) the body's weight flows around the cut through the upper leg's free band into the
  lower leg (measured: 0.7 on the quadruped). The allowed set is further limited to vertices where
  ``s`` is within ``REACH`` gaps of the nearest slot, which only drops unknowns whose value is ~0 and
  keeps the system small.

Solve. Per-slot harmonic solves with these per-slot supports would no longer sum to 1 (their zero
boundaries differ), and dividing by the sum blows up exactly at junctions where the common neighbour's
own weight is small (sums down to 0.14 measured). So the weights minimise the summed Dirichlet energy
``Σ_s w_sᵀ L w_s`` subject to the handles, the supports and ``Σ_s w_s = 1`` at every free vertex: one
sparse saddle-point (KKT) system, one LU (``splu``), all slots at once. ``L`` uses cotangent weights
(the Laplace-Beltrami discretisation, so the result follows the surface rather than how marching cubes
triangulated it) clamped to ``[COT_FLOOR, COT_CAP]``: a negative weight (obtuse pair) breaks the
maximum principle, a zero one can disconnect the graph, an unbounded one (a sliver) only hurts
conditioning. Where a common neighbour exists it takes up the weight the barrier forbids the others,
which is what keeps a junction smooth.

Pruning. The ``max_influences`` largest weights are kept, negatives (round-off) clamp to 0 and each row
is renormalised, so the partition of unity holds after pruning; unused influence slots repeat the
dominant slot with weight 0.

Gates (each measured against a stated threshold):
- ``weights.partition``: max |Σw − 1| after pruning, ≤ ``PARTITION_MAX`` (1e-6);
- ``weights.nonnegative``: min w ≥ 0;
- ``weights.influences``: most non-zero influences on a vertex ≤ ``max_influences``;
- ``weights.barrier_leakage``: max weight a slot holds on a vertex owned by a slot that is not its
  skeleton neighbour, ≤ ``LEAKAGE_MAX`` (0.01);
- ``weights.continuity``: max over mesh edges of max_g |ΔW_g|, ≤ ``CONTINUITY_MAX``, on edges outside
  the contact zones, where W_g sums the weights of the slots of one *motion group*: slots joined by
  joints the creature's motion never turns (an eye on a head, a horn, a fin the gait does not move;
  the build passes them from the measured motion envelope). Every slot of a group gets the same
  transform in every pose, so every skinning method maps a vertex to the same place however its weight
  is split inside the group: a jump there cannot be seen, and a gate on it refused creatures for
  nothing (eyes on heads, measured on the generated corpus). Between groups the gate is unchanged.
  Unitless on purpose: a hard seam (handles of two slots side by side, a cut where none was meant)
  reads ≈ 1 whatever the mesh density, a transition spread over n edge rings ≈ 1/n.
  A contact zone is where two slots that are not skeleton neighbours are both within a handle gap of
  the surface: there the barrier makes weights jump by design (the contact is meant to open when the
  limbs move), and a junction squeezed between them may be one or two edges wide. The detail reports
  the maximum over all kept (uncut) edges too;
- ``weights.handle_coverage``: slots that own surface vertices but have no handle, = 0 (buried slots
  are listed in the detail, not counted).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import splu

from ..model import layout as col
from ..model.skeleton import Skeleton
from .field64 import BodyField
from .gates import SurfaceGate
from .mesh import Mesh

F64 = npt.NDArray[np.float64]
I32 = npt.NDArray[np.int32]
I64 = npt.NDArray[np.int64]
Bool = npt.NDArray[np.bool_]

#: A handle lies on its slot's own surface: ``d_s ≤ SURFACE_MARGIN · r_s``.
SURFACE_MARGIN = 0.05
#: A handle is farther from every other slot by ``HANDLE_GAP · min(r_s, r_s')`` ...
HANDLE_GAP = 0.5
#: ... and by at least ``EDGE_GAP`` local edge lengths.
EDGE_GAP = 3.0
#: Fallback handles of a slot with none: owned vertices within this fraction of its best relative gap.
FALLBACK_FRACTION = 0.5
#: A slot's weight is an unknown only where it is within this many handle gaps of the nearest slot.
REACH = 4.0
#: Clamp of the cotangent edge weights (dimensionless).
COT_FLOOR = 1e-4
COT_CAP = 1e3
#: Rounds of restoring cut edges around components that lost every handle.
RESTORE_ROUNDS = 8
#: Gate thresholds.
PARTITION_MAX = 1e-6
LEAKAGE_MAX = 0.01
CONTINUITY_MAX = 0.4


@dataclass(frozen=True)
class SkinWeights:
    indices: I32  # (V, max_influences) slot per influence, largest weight first; pad = dominant slot
    weights: F64  # (V, max_influences) non-negative, rows sum to 1; pad = 0
    owner: I32  # (V,) nearest slot by the slot's own distance
    handle: I32  # (V,) slot a vertex is pinned to, −1 for free vertices
    contact: npt.NDArray[np.bool_]  # (V,) in a contact zone of two non-neighbour slots
    barrier_edges: int  # undirected mesh edges cut by the contact barrier
    gates: tuple[SurfaceGate, ...]

    @property
    def dominant(self) -> I32:
        result: I32 = self.indices[:, 0]
        return result

    @property
    def passed(self) -> bool:
        return all(g.passed for g in self.gates)

    def gate(self, name: str) -> SurfaceGate:
        return next(g for g in self.gates if g.name == name)

    def dense(self, slot_count: int) -> F64:
        """(V, S) weights, zero where a slot is not among a vertex's influences."""
        out = np.zeros((self.indices.shape[0], slot_count))
        np.add.at(out, (np.arange(self.indices.shape[0])[:, None], self.indices), self.weights)
        return out


def slot_radius(slots: F64) -> F64:
    """Largest radius of each slot: the size its joint band scales with."""
    result: F64 = np.maximum(slots[:, col.RA], slots[:, col.RB])
    return result


def neighbour_matrix(skeleton: Skeleton) -> Bool:
    """(S, S) True where two slots are skeleton neighbours (or the same slot)."""
    near = np.eye(len(skeleton.parent), dtype=bool)
    for parent, child in skeleton.joints:
        near[parent, child] = near[child, parent] = True
    return near


def undirected_edges(mesh: Mesh) -> I64:
    """(E, 2) unique undirected edges, smaller index first."""
    e = np.sort(mesh.edges().astype(np.int64), axis=1)
    key = np.unique(e[:, 0] * mesh.vertex_count + e[:, 1])  # 1-D unique: far faster than axis=0
    result: I64 = np.stack([key // mesh.vertex_count, key % mesh.vertex_count], axis=1)
    return result


def edge_scale(mesh: Mesh, edges: I64) -> F64:
    """Mean incident edge length per vertex: the local mesh spacing a transition must span."""
    length = np.linalg.norm(mesh.vertices[edges[:, 0]] - mesh.vertices[edges[:, 1]], axis=1)
    total = np.bincount(edges.ravel(), np.repeat(length, 2), minlength=mesh.vertex_count)
    count = np.bincount(edges.ravel(), minlength=mesh.vertex_count)
    result: F64 = np.divide(total, count, out=np.zeros_like(total), where=count > 0)
    return result


def cotangent_weights(mesh: Mesh) -> sp.csr_matrix:
    """Symmetric (V, V) edge weights: half the summed cotangents of the two opposite angles, clamped
    to ``[COT_FLOOR, COT_CAP]``."""
    v = mesh.vertices
    f = mesh.faces.astype(np.int64)
    rows, cols, vals = [], [], []
    for k in range(3):
        o, i, j = f[:, k], f[:, (k + 1) % 3], f[:, (k + 2) % 3]
        u, w = v[i] - v[o], v[j] - v[o]
        cross = np.linalg.norm(np.cross(u, w), axis=1)
        dot = np.einsum("ij,ij->i", u, w)
        half_cot = 0.5 * np.divide(dot, cross, out=np.zeros_like(dot), where=cross > 0.0)
        rows += [i, j]
        cols += [j, i]
        vals += [half_cot, half_cot]
    n = mesh.vertex_count
    csr = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    csr.sum_duplicates()
    csr.data = np.clip(csr.data, COT_FLOOR, COT_CAP)
    return csr


def _relative_gap(distances: F64, owner: I32, radius: F64, spacing: F64) -> F64:
    """(S, V): how far each slot is behind the owner, in units of the pair's required handle gap."""
    cols = np.arange(distances.shape[1])
    pair = HANDLE_GAP * np.minimum(radius[:, None], radius[owner][None, :])
    gap = np.maximum(pair, EDGE_GAP * spacing[None, :])
    result: F64 = (distances - distances[owner, cols][None, :]) / gap
    return result


def _handles(distances: F64, owner: I32, radius: F64, relative: F64) -> tuple[I32, list[int]]:
    """Handle slot per vertex (−1 free) and the slots that needed the fallback rule."""
    s_count, v_count = distances.shape
    cols = np.arange(v_count)
    others = relative.copy()
    others[owner, cols] = np.inf
    margin = others.min(axis=0) if s_count > 1 else np.full(v_count, np.inf)
    on_surface = distances[owner, cols] <= SURFACE_MARGIN * radius[owner]
    handle = np.where(on_surface & (margin >= 1.0), owner, -1).astype(np.int32)
    relaxed: list[int] = []
    present = np.bincount(owner, minlength=s_count) > 0
    pinned = np.bincount(handle[handle >= 0], minlength=s_count) > 0
    for s in np.flatnonzero(present & ~pinned):
        mine = owner == s
        best = float(margin[mine].max())
        if best > 0.0:
            handle[mine & (margin >= FALLBACK_FRACTION * best)] = s
            relaxed.append(int(s))
    return handle, relaxed


def _cut(weights: sp.csr_matrix, owner: I32, near: Bool, handle: I32) -> tuple[sp.csr_matrix, int]:
    """Zero the edges between non-neighbour owners, except around components left without a handle."""
    coo = weights.tocoo()
    r, c = coo.row.astype(np.int64), coo.col.astype(np.int64)
    cut = ~near[owner[r], owner[c]]
    n = weights.shape[0]
    kept = weights
    for _ in range(RESTORE_ROUNDS):
        kept = sp.csr_matrix((coo.data[~cut], (r[~cut], c[~cut])), shape=(n, n))
        stranded = _stranded(kept, handle)
        restore = cut & (stranded[r] | stranded[c])
        if not restore.any():
            break
        cut &= ~restore
    else:
        kept = sp.csr_matrix((coo.data[~cut], (r[~cut], c[~cut])), shape=(n, n))
    return kept, int(cut.sum()) // 2


def _stranded(weights: sp.csr_matrix, handle: I32) -> Bool:
    """Vertices whose connected component (under non-zero edge weights) holds no handle."""
    count, label = connected_components(weights, directed=False)
    reached = np.zeros(count, dtype=bool)
    reached[label[handle >= 0]] = True
    result: Bool = ~reached[label]
    return result


def _solve(weights: sp.csr_matrix, handle: I32, allowed: Bool) -> F64:
    """(V, S) weights minimising ``Σ_s w_sᵀ L w_s`` subject to the handles and ``Σ_s w_s = 1``.

    Unknowns are ``w_s(v)`` for free ``v`` where ``allowed[s, v]``; every other ``w_s(v)`` is fixed
    (1 on the handles of ``s``, else 0). The Lagrange conditions ``L_s w_s + λ = b_s``, ``Σ_s w_s = 1``
    form one sparse saddle-point system, factorised once. The degree keeps every edge, so an edge
    leaving a slot's allowed region acts as zero Dirichlet data rather than as a missing edge.
    """
    n = weights.shape[0]
    out = np.zeros((n, allowed.shape[0]))
    pinned = handle >= 0
    out[np.flatnonzero(pinned), handle[pinned]] = 1.0
    free = np.flatnonzero(~pinned)
    if free.size == 0:
        return out
    position = np.full(n, -1, dtype=np.int64)
    position[free] = np.arange(free.size)
    laplacian = (sp.diags(np.asarray(weights.sum(axis=1)).ravel()) - weights).tocsr()
    blocks, rhs, unknowns = [], [], []
    for s in range(allowed.shape[0]):
        rows = np.flatnonzero(~pinned & allowed[s])
        if rows.size:
            blocks.append(laplacian[rows][:, rows])
            rhs.append(np.asarray(weights[rows][:, np.flatnonzero(handle == s)].sum(axis=1)).ravel())
            unknowns.append((s, rows))
    count = sum(rows.size for _, rows in unknowns)
    where = np.concatenate([position[rows] for _, rows in unknowns])
    constraint = sp.csr_matrix((np.ones(count), (where, np.arange(count))), shape=(free.size, count))
    kkt = sp.bmat([[sp.block_diag(blocks), constraint.T], [constraint, None]], format="csc")
    x = splu(kkt).solve(np.concatenate([*rhs, np.ones(free.size)]))
    start = 0
    for s, rows in unknowns:
        out[rows, s] = x[start : start + rows.size]
        start += rows.size
    return out


def _prune(dense: F64, max_influences: int) -> tuple[I32, F64]:
    """Largest ``max_influences`` weights per row, clamped at 0 and renormalised; pad = dominant slot."""
    k = min(max_influences, dense.shape[1])
    order = np.argsort(-dense, axis=1, kind="stable")[:, :k]
    top = np.clip(np.take_along_axis(dense, order, axis=1), 0.0, None)
    total = top.sum(axis=1, keepdims=True)
    top = np.divide(top, total, out=np.zeros_like(top), where=total > 0.0)
    top[total[:, 0] <= 0.0, 0] = 1.0
    indices = np.repeat(order[:, :1], max_influences, axis=1).astype(np.int32)
    weights = np.zeros((dense.shape[0], max_influences))
    used = top > 0.0
    indices[:, :k] = np.where(used, order, order[:, :1])
    weights[:, :k] = top
    return indices, weights


def motion_groups(skeleton: Skeleton, still: frozenset[int]) -> I32:
    """(S,) group per slot: slots joined through joints whose child is in ``still`` (joints the motion
    never turns) share a group, so they share one transform in every pose."""
    group = np.arange(len(skeleton.parent), dtype=np.int32)
    for slot in skeleton.order:  # parents first: a still child takes its parent's final group
        parent = skeleton.parent[slot]
        if parent >= 0 and slot in still:
            group[slot] = group[parent]
    return group


def skin_weights(
    mesh: Mesh,
    field: BodyField,
    skeleton: Skeleton,
    *,
    max_influences: int = 4,
    barrier: bool = True,
    still: frozenset[int] = frozenset(),
) -> SkinWeights:
    """Harmonic skin weights with contact barriers and gates; the module docstring says why.

    ``barrier=False`` drops both barrier measures (edge cut and neighbour supports), which is only
    useful to show that the leakage gate catches what the barrier prevents. ``still`` holds the child
    slots of joints the motion never turns (the continuity gate reads their groups' summed weights).
    """
    if max_influences < 1:
        raise ValueError("max_influences must be at least 1")
    s_count = field.slots.shape[0]
    radius = slot_radius(field.slots)
    distances = field.slot_distances(mesh.vertices)  # (S, V)
    owner = np.argmin(distances, axis=0).astype(np.int32)
    edges = undirected_edges(mesh)
    relative = _relative_gap(distances, owner, radius, edge_scale(mesh, edges))
    handle, relaxed = _handles(distances, owner, radius, relative)
    near = neighbour_matrix(skeleton)
    cot = cotangent_weights(mesh)
    barrier_edges = 0
    if barrier:
        cot, barrier_edges = _cut(cot, owner, near, handle)
    stranded = _stranded(cot, handle)
    handle[stranded] = owner[stranded]
    pinned = np.bincount(handle[handle >= 0], minlength=s_count) > 0
    allowed = (relative <= REACH) & pinned[:, None]
    if barrier:
        allowed &= near[:, owner]
    # A free vertex needs one unknown; its owner qualifies unless the owner has no handle at all.
    lonely = ~allowed.any(axis=0) & (handle < 0)
    handle[lonely] = owner[lonely]
    indices, weights = _prune(_solve(cot, handle, allowed), max_influences)
    close = relative <= 1.0
    closeness = close.astype(np.float64)
    contact = np.einsum("sv,st,tv->v", closeness, (~near).astype(np.float64), closeness) > 0.0
    kept = np.asarray(cot[edges[:, 0], edges[:, 1]]).ravel() > 0.0
    gates = _gates(
        edges[kept],
        contact,
        indices,
        weights,
        owner,
        handle,
        near,
        skeleton,
        relaxed,
        int(stranded.sum()),
        motion_groups(skeleton, still),
    )
    return SkinWeights(indices, weights, owner, handle, contact, barrier_edges, gates)


def _gates(
    edges: I64,
    contact: Bool,
    indices: I32,
    weights: F64,
    owner: I32,
    handle: I32,
    near: Bool,
    skeleton: Skeleton,
    relaxed: list[int],
    stranded: int,
    groups: I32,
) -> tuple[SurfaceGate, ...]:
    s_count = near.shape[0]
    v_count = indices.shape[0]
    partition = float(np.abs(weights.sum(axis=1) - 1.0).max(initial=0.0))
    influences = int((weights > 0.0).sum(axis=1).max(initial=0))
    leak = np.where(~near[owner[:, None], indices], weights, 0.0).max(axis=1, initial=0.0)
    worst = int(np.argmax(leak)) if v_count else 0
    dense = np.zeros((v_count, s_count))
    np.add.at(dense, (np.arange(v_count)[:, None], indices), weights)
    jump = group_jumps(dense, groups, edges)
    slot_jump = np.abs(dense[edges[:, 0]] - dense[edges[:, 1]]).max(axis=1, initial=0.0)
    outside = ~contact[edges[:, 0]] & ~contact[edges[:, 1]]
    smooth = jump[outside] if outside.any() else np.zeros(1)
    worst_edge = int(np.flatnonzero(outside)[np.argmax(smooth)]) if outside.any() else 0
    merged = len(groups) - len(np.unique(groups))
    present = np.bincount(owner, minlength=s_count) > 0
    pinned = np.bincount(handle[handle >= 0], minlength=s_count) > 0
    missing = [skeleton.names[s] for s in np.flatnonzero(present & ~pinned)]
    buried = [skeleton.names[s] for s in np.flatnonzero(~present)]
    coverage = [
        f"no handle: {', '.join(missing)}" if missing else "",
        f"buried (no surface, weight 0): {', '.join(buried)}" if buried else "",
        f"fallback handles: {', '.join(skeleton.names[s] for s in relaxed)}" if relaxed else "",
        f"{stranded} vertices pinned to their owner (no handle reachable)" if stranded else "",
    ]
    leak_detail = (
        f"vertex {worst} owned by {skeleton.names[owner[worst]]}" if leak.size and leak[worst] > 0 else ""
    )
    return (
        SurfaceGate("weights.partition", partition, PARTITION_MAX, "|Σw−1|"),
        SurfaceGate("weights.nonnegative", float(weights.min(initial=0.0)), 0.0, "w", "min"),
        SurfaceGate("weights.influences", float(influences), float(indices.shape[1]), "influences"),
        SurfaceGate(
            "weights.barrier_leakage", float(leak.max(initial=0.0)), LEAKAGE_MAX, "w", detail=leak_detail
        ),
        SurfaceGate(
            "weights.continuity",
            float(smooth.max()),
            CONTINUITY_MAX,
            "max |Δw| per edge",
            detail=(
                f"outside contact zones: p99 {float(np.quantile(smooth, 0.99)):.3g} "
                f"over {int(outside.sum())} edges; "
                f"all kept edges {float(jump.max(initial=0.0)):.3g}; "
                f"{int(contact.sum())} contact-zone vertices; "
                f"per slot {float(slot_jump[outside].max(initial=0.0)):.3g} ({merged} slots share a "
                f"motion group with their parent); worst edge between "
                f"{_edge_slots(edges[worst_edge], dense, skeleton)}"
            ),
        ),
        SurfaceGate(
            "weights.handle_coverage",
            float(len(missing)),
            0.0,
            "slots",
            detail="; ".join(x for x in coverage if x),
        ),
    )


def group_jumps(dense: F64, groups: I32, edges: I64) -> F64:
    """Per edge, the largest change of one motion group's summed weight along it (what the continuity
    gate reads)."""
    membership = np.zeros((dense.shape[1], int(groups.max(initial=0)) + 1))
    membership[np.arange(dense.shape[1]), groups] = 1.0
    grouped = dense @ membership
    result: F64 = np.abs(grouped[edges[:, 0]] - grouped[edges[:, 1]]).max(axis=1, initial=0.0)
    return result


def steep_faces(mesh: Mesh, weights: SkinWeights, groups: I32, mark: float) -> I64:
    """Faces with an edge outside the contact zones along which a motion group's weight changes by more
    than ``mark``: where splitting the mesh spreads a steep transition over more edges."""
    edges = mesh.edges().astype(np.int64)
    jump = group_jumps(weights.dense(len(groups)), groups, edges)
    outside = ~weights.contact[edges[:, 0]] & ~weights.contact[edges[:, 1]]
    steep = (jump > mark) & outside
    result: I64 = np.unique(np.flatnonzero(steep) // 3)
    return result


def _edge_slots(edge: I64, dense: F64, skeleton: Skeleton) -> str:
    """The two slots whose weights change most along ``edge``, by name (the parts a seam lies between)."""
    change = dense[edge[0]] - dense[edge[1]]
    gain, loss = int(np.argmax(change)), int(np.argmin(change))
    return f"{skeleton.names[gain]} and {skeleton.names[loss]}"
