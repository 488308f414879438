"""Self-intersection of a triangle mesh, decided exactly, plus the BVH the distance gates reuse.

Why this shape:
- Broad phase: a median-split BVH over triangle AABBs, built level by level so that every leaf sits at
  the same depth. That makes the tree an implicit heap (node j at depth d covers sorted primitives
  [j·n >> d, (j+1)·n >> d)) and lets a self-overlap traversal advance *all* node pairs one level per
  numpy step, instead of chasing pointers in Python.
- Narrow phase: two non-coplanar triangles meet iff some edge of one, not lying in the other's plane,
  meets the other triangle; coplanar ones meet iff an edge pair crosses or a vertex lies inside the
  other. Both reduce to signs of orient3d / orient2d, so the verdict is exact when the signs are.
- Filtered exact predicates: each determinant is evaluated in float64 with Shewchuk's a-priori forward
  error bound; only determinants whose magnitude is within the bound (or whose inputs risk underflow)
  are recomputed exactly from the float64 inputs, which are dyadic rationals. The exact stage scales
  them to Python integers over one common power of two (the same numbers fractions.Fraction would hold,
  without a gcd per operation) in numpy object arrays: marching cubes on grid-aligned patches makes
  thousands of exactly coplanar quads whose determinants are exactly 0 yet within the bound, and at
  ~1 ms per Fraction determinant that would dominate the whole gate.
- Triangles sharing a vertex index always touch, so only pairs sharing no vertex are tested; faces whose
  corners are exactly collinear have no plane and are skipped (the degenerate gate reports them).
Exactness assumes coordinates below ~1e100 in magnitude (no overflow in the products).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .mesh import Mesh

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
I8 = npt.NDArray[np.int8]
Bools = npt.NDArray[np.bool_]

_EPS = 2.0**-53
#: Shewchuk's first-stage relative error bounds (Robust Adaptive Floating-Point Geometric Predicates).
O3D_BOUND = (7.0 + 56.0 * _EPS) * _EPS
O2D_BOUND = (3.0 + 16.0 * _EPS) * _EPS
#: Below this a non-zero coordinate difference could let a product underflow, voiding the bound.
_TINY = 1e-100
#: Triangle pairs tested per vectorised batch; bounds the narrow phase's temporaries (~1 GB at most).
PAIR_CHUNK = 1 << 20
#: Leaf pairs expanded per batch in the broad phase.
LEAF_PAIR_CHUNK = 1 << 17


# ----------------------------------------------------------------------------------------------- BVH


@dataclass(frozen=True)
class BVH:
    """Implicit-heap BVH: node (d, j) is flat index 2**d − 1 + j, children 2k+1 and 2k+2."""

    depth: int  # leaves are at this depth
    lo: F64  # (2**(depth+1) − 1, 3) node boxes
    hi: F64
    leaves: I64  # (2**depth, m) primitive ids of each leaf, −1 padded
    prim_lo: F64  # (n, 3) the primitive boxes the tree was built on
    prim_hi: F64

    def level(self, d: int) -> slice:
        return slice((1 << d) - 1, (1 << (d + 1)) - 1)


def _depth_for(n: int, leaf_size: int) -> int:
    depth = 0
    while (n + (1 << depth) - 1) >> depth > leaf_size and (2 << depth) <= n:
        depth += 1
    return depth


def build_bvh(lo: F64, hi: F64, leaf_size: int = 4) -> BVH:
    """Median split on the longest centroid extent, every node of a level split by one argsort."""
    n = int(lo.shape[0])
    if n == 0:
        empty = np.zeros((0, 3))
        return BVH(
            0, np.full((1, 3), np.inf), np.full((1, 3), -np.inf), np.full((1, 0), -1, np.int64), empty, empty
        )
    depth = _depth_for(n, leaf_size)
    order = np.arange(n, dtype=np.int64)
    c = 0.5 * (lo + hi)  # centroids, kept in the current order
    positions = np.arange(n, dtype=np.int64)
    for d in range(depth):
        starts = (np.arange((1 << d) + 1, dtype=np.int64) * n) >> d
        node = np.repeat(np.arange(1 << d, dtype=np.int64), np.diff(starts))
        low = np.minimum.reduceat(c, starts[:-1], axis=0)
        extent = np.maximum.reduceat(c, starts[:-1], axis=0) - low
        axis = np.argmax(extent, axis=1)
        pick = np.arange(1 << d) * 3 + axis
        low_axis = low.reshape(-1)[pick]
        scale = 0.5 / np.maximum(extent.reshape(-1)[pick], 1e-300)
        # Node id plus the position along its axis scaled into [0, 0.5]: one float argsort sorts every
        # node at once and never mixes nodes. Ties or rounding only move the split off the exact median.
        key = node + (c.reshape(-1)[positions * 3 + axis[node]] - low_axis[node]) * scale[node]
        perm = np.argsort(key)
        order = order[perm]
        c = c[perm]
    starts = (np.arange((1 << depth) + 1, dtype=np.int64) * n) >> depth
    sizes = np.diff(starts)
    width = int(sizes.max())
    slot = np.arange(width, dtype=np.int64)
    index = starts[:-1, None] + slot[None, :]
    leaves = np.where(slot[None, :] < sizes[:, None], order[np.minimum(index, n - 1)], -1)

    total = (1 << (depth + 1)) - 1
    node_lo = np.empty((total, 3))
    node_hi = np.empty((total, 3))
    first = (1 << depth) - 1
    node_lo[first:] = np.minimum.reduceat(lo[order], starts[:-1], axis=0)
    node_hi[first:] = np.maximum.reduceat(hi[order], starts[:-1], axis=0)
    for d in range(depth - 1, -1, -1):
        parents = np.arange((1 << d) - 1, (1 << (d + 1)) - 1)
        node_lo[parents] = np.minimum(node_lo[2 * parents + 1], node_lo[2 * parents + 2])
        node_hi[parents] = np.maximum(node_hi[2 * parents + 1], node_hi[2 * parents + 2])
    return BVH(depth, node_lo, node_hi, leaves.astype(np.int64), lo, hi)


def refit(bvh: BVH, lo: F64, hi: F64) -> BVH:
    """The same tree over moved primitives (new boxes ``lo``/``hi``, same ids): each node's box
    recomputed bottom-up. A deformation that keeps neighbours together (a skinned pose) keeps the tree
    tight, at the cost of a few reductions instead of a rebuild's argsort per level."""
    valid = bvh.leaves >= 0
    safe = np.where(valid, bvh.leaves, 0)
    node_lo = np.empty_like(bvh.lo)
    node_hi = np.empty_like(bvh.hi)
    first = (1 << bvh.depth) - 1
    node_lo[first:] = np.where(valid[:, :, None], lo[safe], np.inf).min(axis=1)
    node_hi[first:] = np.where(valid[:, :, None], hi[safe], -np.inf).max(axis=1)
    for d in range(bvh.depth - 1, -1, -1):
        parents = np.arange((1 << d) - 1, (1 << (d + 1)) - 1)
        node_lo[parents] = np.minimum(node_lo[2 * parents + 1], node_lo[2 * parents + 2])
        node_hi[parents] = np.maximum(node_hi[2 * parents + 1], node_hi[2 * parents + 2])
    return BVH(bvh.depth, node_lo, node_hi, bvh.leaves, lo, hi)


def triangle_boxes(corners: F64) -> tuple[F64, F64]:
    """(F, 3) lower and upper corners of each triangle's box."""
    return corners.min(axis=1), corners.max(axis=1)


def triangle_bvh(mesh: Mesh, leaf_size: int = 4) -> BVH:
    c = mesh.corners()
    lo = np.minimum(np.minimum(c[:, 0], c[:, 1]), c[:, 2])
    hi = np.maximum(np.maximum(c[:, 0], c[:, 1]), c[:, 2])
    return build_bvh(lo, hi, leaf_size)


def _overlapping(lo: F64, hi: F64, a: I64, b: I64) -> tuple[I64, I64]:
    """The pairs whose closed boxes overlap (touching counts: touching triangles intersect), filtered
    one axis at a time on contiguous columns so most pairs are dropped after one cheap gather."""
    for k in range(3):
        lo_k, hi_k = lo[:, k], hi[:, k]
        keep = (lo_k[a] <= hi_k[b]) & (lo_k[b] <= hi_k[a])
        a, b = a[keep], b[keep]
    return a, b


def node_groups(bvh: BVH, groups: I64) -> I64:
    """(nodes,) the group every primitive under a node shares (≥ 0), or −1 where they differ or one of
    them has none: a node whose primitives all moved together."""
    valid = bvh.leaves >= 0
    leaf = np.where(valid, groups[np.maximum(bvh.leaves, 0)], -2)
    first = leaf[:, 0]
    uniform = np.all((leaf == first[:, None]) | ~valid, axis=1) & (first >= 0)
    out = np.full(bvh.lo.shape[0], -1, dtype=np.int64)
    top = (1 << bvh.depth) - 1
    out[top:] = np.where(uniform, first, -1)
    for d in range(bvh.depth - 1, -1, -1):
        parents = np.arange((1 << d) - 1, (1 << (d + 1)) - 1)
        left, right = out[2 * parents + 1], out[2 * parents + 2]
        out[parents] = np.where(left == right, left, -1)
    return out


def overlapping_leaf_pairs(bvh: BVH, groups: I64 | None = None) -> tuple[I64, I64]:
    """Leaf pairs (a ≤ b, within-level ids) whose boxes overlap, by a breadth-first dual traversal.

    A pair (a, a) expands to its three child pairs (l,l), (l,r), (r,r); a pair a < b to all four, which
    keeps every unordered pair exactly once. With ``groups`` (per node, :func:`node_groups`), a pair of
    nodes whose primitives all share one group is not expanded: no pair under it is wanted.
    """
    a = np.zeros(1, dtype=np.int64)
    b = np.zeros(1, dtype=np.int64)
    lo, hi = np.ascontiguousarray(bvh.lo.T).T, np.ascontiguousarray(bvh.hi.T).T
    for d in range(bvh.depth + 1):
        if groups is not None:
            here = (1 << d) - 1
            ga, gb = groups[a + here], groups[b + here]
            wanted = (ga < 0) | (ga != gb)
            a, b = a[wanted], b[wanted]
        if d == bvh.depth:
            break
        same = a == b
        sa, da, db = a[same], a[~same], b[~same]
        na = np.concatenate([2 * sa, 2 * sa, 2 * sa + 1, 2 * da, 2 * da, 2 * da + 1, 2 * da + 1])
        nb = np.concatenate([2 * sa, 2 * sa + 1, 2 * sa + 1, 2 * db, 2 * db + 1, 2 * db, 2 * db + 1])
        offset = (1 << (d + 1)) - 1
        na, nb = _overlapping(lo, hi, na + offset, nb + offset)
        a, b = na - offset, nb - offset
    return a, b


def candidate_pairs(
    bvh: BVH, faces: npt.NDArray[np.integer], groups: I64 | None = None
) -> Iterator[tuple[I64, I64]]:
    """Batches of face pairs (i, j), each unordered pair once, whose AABBs overlap and that share no
    vertex index. With ``groups`` (F,), pairs of faces in one group ≥ 0 are left out, whole leaf pairs
    first: faces a pose moved together (surface/posed.py)."""
    la, lb = overlapping_leaf_pairs(bvh, None if groups is None else node_groups(bvh, groups))
    m = bvh.leaves.shape[1]
    f = np.asarray(faces, dtype=np.int64)
    lo, hi = np.ascontiguousarray(bvh.prim_lo.T).T, np.ascontiguousarray(bvh.prim_hi.T).T
    upper_i, upper_j = np.triu_indices(m, k=1)
    same = la == lb
    batches = (
        (la[same], lb[same], upper_i, upper_j),
        (la[~same], lb[~same], np.repeat(np.arange(m), m), np.tile(np.arange(m), m)),
    )
    for leaf_a, leaf_b, si, sj in batches:
        for s in range(0, leaf_a.size, LEAF_PAIR_CHUNK):
            i = bvh.leaves[leaf_a[s : s + LEAF_PAIR_CHUNK]][:, si].reshape(-1)
            j = bvh.leaves[leaf_b[s : s + LEAF_PAIR_CHUNK]][:, sj].reshape(-1)
            ok = (i >= 0) & (j >= 0)
            i, j = i[ok], j[ok]
            if groups is not None:
                apart = (groups[i] < 0) | (groups[i] != groups[j])
                i, j = i[apart], j[apart]
            i, j = _overlapping(lo, hi, i, j)
            fi, fj = f[i], f[j]
            shared = np.zeros(i.size, dtype=bool)
            for u in range(3):
                for v in range(3):
                    shared |= fi[:, u] == fj[:, v]
            yield i[~shared], j[~shared]


# ----------------------------------------------------------------------------------------- predicates


def _exact_integers(*arrays: F64) -> list[npt.NDArray[np.object_]]:
    """The float64 inputs as Python integers over one common power-of-two denominator: exact.

    Every float64 is m·2**(e−53) with an integer |m| < 2**53 (np.frexp), so scaling by 2**shift with
    shift = 53 − min e makes each an exact integer. Object arrays of Python ints then evaluate a
    determinant exactly at C-loop speed, which is what keeps the exact fallback affordable when a mesh
    has thousands of exactly coplanar quads (marching cubes on grid-aligned patches makes them).
    """
    parts = [np.frexp(x) for x in arrays]
    shift = 53 - min(int(e.min()) for _, e in parts)
    out = []
    for m, e in parts:
        mant = (m * 2.0**53).astype(np.int64).astype(object)
        out.append(np.left_shift(mant, (e.astype(np.int64) - 53 + shift).astype(object)))
    return out


def _sign_of(det: npt.NDArray[np.object_]) -> I8:
    result: I8 = (det > 0).astype(np.int8) - (det < 0).astype(np.int8)
    return result


def _exact_orient3d(a: F64, b: F64, c: F64, d: F64) -> I8:
    ai, bi, ci, di = _exact_integers(a, b, c, d)
    ad, bd, cd = ai - di, bi - di, ci - di
    det = (
        ad[:, 2] * (bd[:, 0] * cd[:, 1] - bd[:, 1] * cd[:, 0])
        + bd[:, 2] * (cd[:, 0] * ad[:, 1] - cd[:, 1] * ad[:, 0])
        + cd[:, 2] * (ad[:, 0] * bd[:, 1] - ad[:, 1] * bd[:, 0])
    )
    return _sign_of(det)


def _exact_orient2d(a: F64, b: F64, c: F64) -> I8:
    ai, bi, ci = _exact_integers(a, b, c)
    ac, bc = ai - ci, bi - ci
    return _sign_of(ac[:, 0] * bc[:, 1] - ac[:, 1] * bc[:, 0])


def _underflow_risk(*diffs: F64) -> Bools:
    risk = np.zeros(diffs[0].shape[0], dtype=bool)
    for x in diffs:
        ax = np.abs(x)
        risk |= np.any((ax > 0) & (ax < _TINY), axis=1)
    return risk


def orient3d_filtered(a: F64, b: F64, c: F64, d: F64) -> tuple[I8, int]:
    """Sign of det[a−d; b−d; c−d] for (N, 3) rows (positive when d lies below the plane of a, b, c
    seen counter-clockwise), and how many rows needed exact arithmetic."""
    ad, bd, cd = a - d, b - d, c - d
    adx, ady, adz = ad[:, 0], ad[:, 1], ad[:, 2]
    bdx, bdy, bdz = bd[:, 0], bd[:, 1], bd[:, 2]
    cdx, cdy, cdz = cd[:, 0], cd[:, 1], cd[:, 2]
    bc0, bc1 = bdx * cdy, bdy * cdx
    ca0, ca1 = cdx * ady, cdy * adx
    ab0, ab1 = adx * bdy, ady * bdx
    det = adz * (bc0 - bc1) + bdz * (ca0 - ca1) + cdz * (ab0 - ab1)
    perm = (np.abs(bc0) + np.abs(bc1)) * np.abs(adz)
    perm += (np.abs(ca0) + np.abs(ca1)) * np.abs(bdz)
    perm += (np.abs(ab0) + np.abs(ab1)) * np.abs(cdz)
    sign = np.sign(det).astype(np.int8)
    unsure = ((np.abs(det) <= O3D_BOUND * perm) & (perm > 0)) | _underflow_risk(ad, bd, cd)
    idx = np.flatnonzero(unsure)
    if idx.size:
        sign[idx] = _exact_orient3d(a[idx], b[idx], c[idx], d[idx])
    return sign, int(idx.size)


def orient2d_filtered(a: F64, b: F64, c: F64) -> tuple[I8, int]:
    """Sign of (a−c)×(b−c) for (N, 2) rows (positive when a, b, c turn counter-clockwise)."""
    ac, bc = a - c, b - c
    left = ac[:, 0] * bc[:, 1]
    right = ac[:, 1] * bc[:, 0]
    det = left - right
    total = np.abs(left) + np.abs(right)
    sign = np.sign(det).astype(np.int8)
    unsure = ((np.abs(det) <= O2D_BOUND * total) & (total > 0)) | _underflow_risk(ac, bc)
    idx = np.flatnonzero(unsure)
    if idx.size:
        sign[idx] = _exact_orient2d(a[idx], b[idx], c[idx])
    return sign, int(idx.size)


def orient3d(a: F64, b: F64, c: F64, d: F64) -> I8:
    """Exact sign of det[a−d; b−d; c−d], row-wise."""
    return orient3d_filtered(a, b, c, d)[0]


def orient2d(a: F64, b: F64, c: F64) -> I8:
    """Exact sign of (a−c)×(b−c), row-wise."""
    return orient2d_filtered(a, b, c)[0]


def normal_signs(corners: F64) -> tuple[I8, int]:
    """(F, 3) exact signs of the three components of (q−p)×(r−p): all zero iff the corners are collinear.

    Component k is the orient2d of the corners projected onto the two other axes, so it comes from the
    same filtered predicate.
    """
    out = np.empty((corners.shape[0], 3), dtype=np.int8)
    exact = 0
    for k in range(3):
        axes = [(k + 1) % 3, (k + 2) % 3]
        p, q, r = (corners[:, i][:, axes] for i in range(3))
        out[:, k], n = orient2d_filtered(q, r, p)
        exact += n
    return out, exact


# --------------------------------------------------------------------------------------- narrow phase


def _opposite(signs: I8, axis: int) -> Bools:
    """Whether the signs along an axis include both a strictly positive and a strictly negative one."""
    result: Bools = np.any(signs > 0, axis=axis) & np.any(signs < 0, axis=axis)
    return result


def _straddles(sa: I8, sb: I8) -> Bools:
    """The segment between two points with these plane signs meets the plane in exactly one point."""
    result: Bools = (sa.astype(np.int16) * sb <= 0) & ~((sa == 0) & (sb == 0))
    return result


def _coplanar_overlap(t1: F64, t2: F64, axis: npt.NDArray[np.intp]) -> tuple[Bools, int]:
    """Closed 2-D overlap of coplanar triangles projected along `axis` (a normal component exactly ≠ 0,
    so the projection is a bijection of their plane and keeps every orientation up to one sign)."""
    n = t1.shape[0]
    keep = np.stack([(axis + 1) % 3, (axis + 2) % 3], axis=1)
    rows = np.arange(n)[:, None]
    p1 = np.stack([t1[:, i][rows, keep] for i in range(3)], axis=1)  # (n, 3, 2)
    p2 = np.stack([t2[:, i][rows, keep] for i in range(3)], axis=1)
    q1 = np.empty((n, 3, 3), dtype=np.int8)  # orient(T1 edge i, T2 vertex j)
    q2 = np.empty((n, 3, 3), dtype=np.int8)  # orient(T2 edge j, T1 vertex i)
    exact = 0
    for i in range(3):
        for j in range(3):
            q1[:, i, j], e1 = orient2d_filtered(p1[:, i], p1[:, (i + 1) % 3], p2[:, j])
            q2[:, j, i], e2 = orient2d_filtered(p2[:, j], p2[:, (j + 1) % 3], p1[:, i])
            exact += e1 + e2
    hit = np.zeros(n, dtype=bool)
    for i in range(3):
        a, b = p1[:, i], p1[:, (i + 1) % 3]
        for j in range(3):
            c, d = p2[:, j], p2[:, (j + 1) % 3]
            o1, o2 = q1[:, i, j], q1[:, i, (j + 1) % 3]
            o3, o4 = q2[:, j, i], q2[:, j, (i + 1) % 3]
            collinear = (o1 == 0) & (o2 == 0)
            crossing = (o1.astype(np.int16) * o2 <= 0) & (o3.astype(np.int16) * o4 <= 0) & ~collinear
            boxes = np.all(
                (np.minimum(a, b) <= np.maximum(c, d)) & (np.minimum(c, d) <= np.maximum(a, b)), axis=1
            )
            hit |= crossing | (collinear & boxes)
    # A vertex inside the other triangle (no edge crossing: one contains the other).
    hit |= np.any(~_opposite(q2, axis=1), axis=1)
    hit |= np.any(~_opposite(q1, axis=1), axis=1)
    return hit, exact


@dataclass(frozen=True)
class PairVerdict:
    hit: Bools  # the closed triangles share at least one point
    coplanar: Bools  # they lie in one plane (with hit: coincident coverage)
    exact_evaluations: int


def triangle_pairs(t1: F64, t2: F64, n1: I8 | None = None) -> PairVerdict:
    """Exact closed intersection of (N, 3, 3) triangle pairs; both triangles must be non-collinear.

    n1 are T1's exact normal signs (normal_signs), used to pick a projection axis for coplanar pairs;
    computed here when not given.
    """
    n = t1.shape[0]
    hit = np.zeros(n, dtype=bool)
    coplanar = np.zeros(n, dtype=bool)
    exact = 0
    s1 = np.empty((n, 3), dtype=np.int8)  # T1 vertices against T2's plane
    s2 = np.empty((n, 3), dtype=np.int8)
    for i in range(3):
        s1[:, i], e1 = orient3d_filtered(t2[:, 0], t2[:, 1], t2[:, 2], t1[:, i])
        s2[:, i], e2 = orient3d_filtered(t1[:, 0], t1[:, 1], t1[:, 2], t2[:, i])
        exact += e1 + e2
    one_side = (np.all(s1 > 0, axis=1) | np.all(s1 < 0, axis=1)) | (
        np.all(s2 > 0, axis=1) | np.all(s2 < 0, axis=1)
    )
    flat = np.all(s2 == 0, axis=1)
    coplanar[:] = flat

    live = np.flatnonzero(~one_side & ~flat)
    if live.size:
        a1, a2, r1, r2 = t1[live], t2[live], s1[live], s2[live]
        plucker = np.empty((live.size, 3, 3), dtype=np.int8)  # orient3d(T1 edge i, T2 edge j)
        for i in range(3):
            for j in range(3):
                plucker[:, i, j], e = orient3d_filtered(
                    a1[:, i], a1[:, (i + 1) % 3], a2[:, j], a2[:, (j + 1) % 3]
                )
                exact += e
        met = np.zeros(live.size, dtype=bool)
        for i in range(3):
            met |= _straddles(r1[:, i], r1[:, (i + 1) % 3]) & ~_opposite(plucker[:, i, :], axis=1)
            met |= _straddles(r2[:, i], r2[:, (i + 1) % 3]) & ~_opposite(plucker[:, :, i], axis=1)
        hit[live] = met

    flat_idx = np.flatnonzero(flat)
    if flat_idx.size:
        a1 = t1[flat_idx]
        signs = n1[flat_idx] if n1 is not None else normal_signs(a1)[0]
        normal = np.cross(a1[:, 1] - a1[:, 0], a1[:, 2] - a1[:, 0])
        axis = np.argmax(np.where(signs != 0, np.abs(normal) + 1e-300, -1.0), axis=1)
        met, e = _coplanar_overlap(a1, t2[flat_idx], axis)
        hit[flat_idx] = met
        exact += e
    return PairVerdict(hit, coplanar, exact)


# -------------------------------------------------------------------------------------------- report


@dataclass(frozen=True)
class IntersectionReport:
    candidate_pairs: int  # non-adjacent face pairs whose boxes overlap
    intersecting: int  # of those, pairs whose closed triangles share a point (coincident included)
    coincident: int  # of the intersecting, coplanar pairs: two sheets covering the same area
    pairs: I64  # (≤ max_pairs, 2) some intersecting pairs, sorted (face ids, smaller first)
    coincident_pairs: I64  # (≤ max_pairs, 2)
    skipped_degenerate: int  # faces with exactly collinear corners, left out of the test
    exact_evaluations: int  # predicate evaluations settled with exact arithmetic

    @property
    def crossing(self) -> int:
        return self.intersecting - self.coincident


def self_intersections(mesh: Mesh, *, bvh: BVH | None = None, max_pairs: int = 10) -> IntersectionReport:
    """Every pair of faces sharing no vertex index whose closed triangles meet, decided exactly."""
    corners = mesh.corners()
    tree = bvh if bvh is not None else triangle_bvh(mesh)
    signs, exact = normal_signs(corners)
    degenerate = np.all(signs == 0, axis=1)
    candidates = 0
    found: list[I64] = []
    flat: list[I64] = []
    n_hit = n_flat = 0
    for i, j in candidate_pairs(tree, mesh.faces):
        ok = ~(degenerate[i] | degenerate[j])
        i, j = i[ok], j[ok]
        candidates += int(i.size)
        for s in range(0, i.size, PAIR_CHUNK):
            bi, bj = i[s : s + PAIR_CHUNK], j[s : s + PAIR_CHUNK]
            verdict = triangle_pairs(corners[bi], corners[bj], signs[bi])
            exact += verdict.exact_evaluations
            both = np.sort(np.stack([bi, bj], axis=1), axis=1)
            hits = both[verdict.hit]
            coinc = both[verdict.hit & verdict.coplanar]
            n_hit += hits.shape[0]
            n_flat += coinc.shape[0]
            found.append(hits[:max_pairs])
            flat.append(coinc[:max_pairs])

    def first(chunks: list[I64]) -> I64:
        if not chunks:
            return np.zeros((0, 2), dtype=np.int64)
        all_pairs = np.concatenate(chunks)
        ordered: I64 = all_pairs[np.lexsort((all_pairs[:, 1], all_pairs[:, 0]))][:max_pairs]
        return ordered

    return IntersectionReport(
        candidate_pairs=candidates,
        intersecting=n_hit,
        coincident=n_flat,
        pairs=first(found),
        coincident_pairs=first(flat),
        skipped_degenerate=int(np.count_nonzero(degenerate)),
        exact_evaluations=exact,
    )


# ----------------------------------------------------------------------------------- point distances


def point_triangle_distance(points: F64, tri: F64) -> F64:
    """Euclidean distance from (N, 3) points to (N, 3, 3) closed triangles, row-wise.

    Inside the prism over the triangle it is the plane distance; outside, the nearest of the three edge
    segments. That split stays well defined for slivers and zero-area faces, where barycentric closed
    forms divide by ~0.
    """
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    normal = np.cross(b - a, c - a)
    inside = np.ones(points.shape[0], dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(v - u, points - u), normal) >= 0
    nn = np.einsum("ij,ij->i", normal, normal)
    inside &= nn > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        plane = np.abs(np.einsum("ij,ij->i", points - a, normal)) / np.sqrt(nn)
    best = np.full(points.shape[0], np.inf)
    for u, v in ((a, b), (b, c), (c, a)):
        e = v - u
        ee = np.einsum("ij,ij->i", e, e)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.where(ee > 0, np.einsum("ij,ij->i", points - u, e) / ee, 0.0)
        t = np.clip(t, 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(points - (u + t[:, None] * e), axis=1))
    result: F64 = np.where(inside, plane, best)
    return result


def _box_distance_sq(points: F64, lo: F64, hi: F64) -> F64:
    gap = np.maximum(np.maximum(lo - points, points - hi), 0.0)
    result: F64 = np.einsum("ij,ij->i", gap, gap)
    return result


def distances_to_mesh(bvh: BVH, corners: F64, points: F64, upper: F64, chunk: int = 8192) -> F64:
    """Exact (float64) distance from each point to the nearest triangle, pruning BVH nodes farther
    than a known upper bound per point (e.g. the distance to the triangle with the nearest centroid).

    The bound is what makes this fast: with an infinite bound every leaf is visited."""
    out = np.array(upper, dtype=np.float64, copy=True)
    for s in range(0, points.shape[0], chunk):
        p = points[s : s + chunk]
        ub2 = out[s : s + chunk] ** 2
        who = np.arange(p.shape[0], dtype=np.int64)
        node = np.zeros(p.shape[0], dtype=np.int64)
        for _ in range(bvh.depth):
            who = np.concatenate([who, who])
            node = np.concatenate([2 * node + 1, 2 * node + 2])
            keep = _box_distance_sq(p[who], bvh.lo[node], bvh.hi[node]) <= ub2[who]
            who, node = who[keep], node[keep]
        members = bvh.leaves[node - ((1 << bvh.depth) - 1)]
        who = np.repeat(who, members.shape[1])
        tri = members.reshape(-1)
        ok = tri >= 0
        who, tri = who[ok], tri[ok]
        d = point_triangle_distance(p[who], corners[tri])
        best = np.sqrt(ub2)
        np.minimum.at(best, who, d)
        out[s : s + chunk] = best
    return out
