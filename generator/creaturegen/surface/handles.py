"""Which contacts close the mesh's handles, so a failed euler gate names the parts to move.

A creature's skeleton is a tree, so each body component should be a sphere: a handle means two parts
touch somewhere other than the joint that connects them, closing a loop through the skeleton (two legs
on one side whose knees overlap, an antenna resting on the shell far from the head). The mesh is right
to show it, because the field has it, but a skinned mesh would then stretch a web between parts that
move apart, so the build refuses it and says where.

Each vertex is labelled with the part of its nearest slot. The faces where two labels meet are that pair's
contact.
Cutting a contact out of the surface lowers the genus exactly when it runs around a handle; among the
pairs whose cut lowers it, those that are not skeleton neighbours are the culprits (a joint on the loop
lowers the genus too when cut, but it is where the part is meant to attach). A culprit is *certain* when
the field is negative all along the segment joining the two parts' nearest primitives (checked at
samples, with the Lipschitz bound covering the gaps between them): the body then holds a path from one
part to the other at every lattice spacing, and refining the lattice cannot remove the handle.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..model import layout as col
from ..model.skeleton import Skeleton
from .grid import LIPSCHITZ_BOUND
from .mesh import Mesh
from .topology import EdgeTable, components, corner_fans, edge_table

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
DistanceFn = Callable[[F64], F64]

#: Samples along the segment between two parts' nearest primitives when testing the bridge.
BRIDGE_SAMPLES = 65


@dataclass(frozen=True)
class Contact:
    """Two parts whose contact runs around a handle."""

    a: str
    b: str
    genus_drop: float  # how much cutting this contact out lowers the surface's genus
    joined: bool  # skeleton neighbours: the contact is their joint
    gap: float  # primitive-to-primitive distance at rest, m (negative: they overlap by that much)
    bridge: float  # bound on the field's largest value along the segment between the primitives, m
    places: int = 1  # separate pieces of their contact strip (two for a leg touching its body again)

    @property
    def culprit(self) -> bool:
        """A contact to move: between parts the skeleton does not join, or a joined pair that touches
        again away from its joint (a thigh folded against the belly)."""
        return not self.joined or self.places > 1

    @property
    def certain(self) -> bool:
        """The body holds a path between the two parts at any lattice spacing."""
        return not self.joined and self.bridge < 0.0

    def describe(self) -> str:
        how = (
            f"their primitives overlap by {-self.gap:.3g} m"
            if self.gap < 0
            else f"the blend bridges the {self.gap:.3g} m between their primitives"
        )
        joint = "their joint" if self.joined else "not joined in the skeleton"
        if self.joined and self.places > 1:
            joint = f"at their joint and in {self.places - 1} more place{'s' if self.places > 2 else ''}"
            return (
                f"{self.a} touches {self.b} ({joint}): turn or move the child part so it meets its parent "
                "only at the joint"
            )
        change = (
            ""
            if self.joined
            else (
                f": move them apart (hip, pose or size) by over {-self.gap:.3g} m plus their blend width k"
                if self.gap < 0
                else f": move them further apart, or give one a k (or kCap) below {self.gap:.3g} m"
            )
        )
        return f"{self.a} touches {self.b} ({joint}; {how} at rest){change}"


def surface_genus(mesh: Mesh) -> float:
    """Total genus of a triangle set that may have boundaries and pinch vertices.

    Every vertex counts once per fan, as if split (a cut strip often leaves a pinch), and the boundary
    count is the cycle rank of the boundary edges over those split vertices, so g = Σ (2c − χ − b)/2
    holds for the cut surfaces measured here.
    """
    if mesh.faces.shape[0] == 0:
        return 0.0
    table = edge_table(mesh.faces)
    found = components(mesh, table)
    fan = corner_fans(mesh, table)
    fans = np.unique(fan).size
    chi = fans - int(table.valence.size) + int(mesh.faces.shape[0])
    loops = _boundary_loops(np.flatnonzero(table.valence[table.edge_of_half] == 1), fan)
    return (2 * found.count - chi - loops) / 2.0


def _boundary_loops(half: I64, fan: I64) -> int:
    """Cycle rank of the boundary half-edges ``half`` over their ends' fans (``fan``: each corner's fan
    label; half-edge 3f+i runs from corner 3f+i to the next corner of face f)."""
    if half.size == 0:
        return 0
    nxt = 3 * (half // 3) + (half % 3 + 1) % 3
    used, local = np.unique(np.concatenate([fan[half], fan[nxt]]), return_inverse=True)
    graph = coo_matrix(
        (np.ones(half.size), (local[: half.size], local[half.size :])), shape=(used.size, used.size)
    )
    parts, _ = connected_components(graph, directed=False)
    return int(half.size - used.size + parts)


@dataclass(frozen=True)
class Uncut:
    """The whole mesh's tables that every cut reuses (``cut_genus``)."""

    mesh: Mesh
    table: EdgeTable
    fan: I64  # (3F,) fan label of every corner
    fan_vertex: I64  # (fans,) the vertex of each fan label


def uncut(mesh: Mesh) -> Uncut:
    table = edge_table(mesh.faces)
    fan = corner_fans(mesh, table)
    fan_vertex = np.zeros(int(fan.max()) + 1 if fan.size else 0, dtype=np.int64)
    fan_vertex[fan] = np.asarray(mesh.faces, dtype=np.int64).reshape(-1)
    return Uncut(mesh, table, fan, fan_vertex)


def cut_genus(base: Uncut, strip: npt.NDArray[np.bool_]) -> float:
    """``surface_genus`` of the mesh without the faces marked in ``strip``, from the whole mesh's tables.

    Only the vertices of cut faces can change their fans, so their fans are recomputed on the kept faces
    around them and every other vertex keeps its own; edges, components and boundary loops are counted
    over the kept faces with the whole mesh's edge ids. The terms are those of ``surface_genus``, so the
    value is the same (tests/test_surface_handles.py checks it on cuts of every kind), at a fraction of
    the cost on a large mesh, where a failed euler gate cuts once per pair of parts in contact."""
    faces = np.asarray(base.mesh.faces, dtype=np.int64)
    keep = ~strip
    kept_faces = int(np.count_nonzero(keep))
    if kept_faces == 0:
        return 0.0
    kept_half = np.repeat(keep, 3)
    valence = np.bincount(base.table.edge_of_half[kept_half], minlength=base.table.valence.size)
    edges = int(np.count_nonzero(valence))
    touched = np.zeros(base.mesh.vertex_count, dtype=bool)
    touched[faces[strip].reshape(-1)] = True
    ring = keep & touched[faces].any(axis=1)
    ring_fan = corner_fans(Mesh(base.mesh.vertices, base.mesh.faces[ring]))
    at_touched = touched[faces[ring].reshape(-1)]
    fan = base.fan.copy()
    ring_corners = (3 * np.flatnonzero(ring)[:, None] + np.arange(3)).reshape(-1)
    fan[ring_corners[at_touched]] = base.fan_vertex.size + ring_fan[at_touched]
    fans = int(np.count_nonzero(~touched[base.fan_vertex])) + np.unique(ring_fan[at_touched]).size
    chi = fans - edges + kept_faces
    # Components: faces joined through the edges they use (an edge is a node, so an edge of any valence
    # joins all its kept faces); cut faces and edges left without faces are isolated nodes, not counted.
    n, e = faces.shape[0], base.table.valence.size
    halves = np.flatnonzero(kept_half)
    graph = coo_matrix(
        (np.ones(halves.size, dtype=np.int8), (halves // 3, n + base.table.edge_of_half[halves])),
        shape=(n + e, n + e),
    )
    count = int(connected_components(graph.tocsr(), directed=False)[0]) - (n - kept_faces) - (e - edges)
    loops = _boundary_loops(np.flatnonzero(kept_half & (valence[base.table.edge_of_half] == 1)), fan)
    return float(2 * count - chi - loops) / 2.0


def _pieces(faces: npt.NDArray[np.integer]) -> int:
    """Connected pieces of a set of faces (joined through shared vertices)."""
    if faces.shape[0] == 0:
        return 0
    used, local = np.unique(faces, return_inverse=True)
    local = local.reshape(faces.shape)
    rows = np.concatenate([local[:, 0], local[:, 1]])
    cols = np.concatenate([local[:, 1], local[:, 2]])
    graph = coo_matrix((np.ones(rows.size), (rows, cols)), shape=(used.size, used.size))
    count, _ = connected_components(graph, directed=False)
    return int(count)


def primitive_gap(slots: F64, i: int, j: int) -> float:
    """Distance between two rest primitives, each taken at its smaller end radius (inside the round
    cone, so a negative value is a certain overlap)."""
    p, q = _closest_points(slots[i, col.A], slots[i, col.B], slots[j, col.A], slots[j, col.B])
    ri = min(float(slots[i, col.RA]), float(slots[i, col.RB]))
    rj = min(float(slots[j, col.RA]), float(slots[j, col.RB]))
    return float(np.linalg.norm(p - q)) - ri - rj


def _closest_points(p1: F64, q1: F64, p2: F64, q2: F64) -> tuple[F64, F64]:
    """Closest points of two segments (Ericson, Real-Time Collision Detection 5.1.9)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e, f = float(d1 @ d1), float(d2 @ d2), float(d2 @ r)
    if a <= 1e-30 and e <= 1e-30:
        return p1, p2
    if a <= 1e-30:
        return p1, p2 + np.clip(f / e, 0.0, 1.0) * d2
    c = float(d1 @ r)
    if e <= 1e-30:
        return p1 + np.clip(-c / a, 0.0, 1.0) * d1, p2
    b = float(d1 @ d2)
    denom = a * e - b * b
    s = float(np.clip((b * f - c * e) / denom, 0.0, 1.0)) if denom > 1e-30 else 0.0
    t = (b * s + f) / e
    if t < 0.0:
        t, s = 0.0, float(np.clip(-c / a, 0.0, 1.0))
    elif t > 1.0:
        t, s = 1.0, float(np.clip((b - c) / a, 0.0, 1.0))
    return p1 + s * d1, p2 + t * d2


def bridge_bound(distance: DistanceFn, p: F64, q: F64) -> float:
    """An upper bound on the field along segment pq: the largest sample plus the Lipschitz bound times
    half the sample spacing."""
    t = np.linspace(0.0, 1.0, BRIDGE_SAMPLES)[:, None]
    step = float(np.linalg.norm(q - p)) / (BRIDGE_SAMPLES - 1)
    return float(np.max(distance(p + t * (q - p)))) + LIPSCHITZ_BOUND * 0.5 * step


def handle_contacts(
    mesh: Mesh,
    slot_distances: F64,
    distance: DistanceFn,
    skeleton: Skeleton,
    slots: F64,
    slot_parts: tuple[str, ...],
) -> tuple[Contact, ...]:
    """Every pair of parts whose contact runs around a handle, culprits (non-neighbours) first.

    ``slot_distances`` is (S, V): each slot's own distance at each vertex (BodyField.slot_distances).
    Labels are parts, not slots: a part's own segments meet at knees that carry no handle, and a contact that
    spans two segments of a leg must be cut whole to open the loop it closes.
    """
    genus = surface_genus(mesh)
    if genus <= 0.0:
        return ()
    parts, part_of, parent = _part_tree(skeleton, slot_parts)
    face_labels, pairs = _contact_pairs(mesh, slot_distances, part_of)
    base = uncut(mesh)
    found = []
    for i, j in pairs:
        strip = np.any(face_labels == i, axis=1) & np.any(face_labels == j, axis=1)
        drop = genus - cut_genus(base, strip)
        if drop < 1.0:
            continue
        joined = parent.get(int(i)) == j or parent.get(int(j)) == i
        gap, bridge = _pair_bridge(slots, part_of, int(i), int(j), distance)
        places = _pieces(mesh.faces[strip])
        found.append(Contact(f"part.{parts[i]}", f"part.{parts[j]}", drop, bool(joined), gap, bridge, places))
    return tuple(sorted(found, key=lambda c: (c.joined, c.gap, c.a, c.b)))


def _contact_pairs(mesh: Mesh, slot_distances: F64, part_of: I64) -> tuple[I64, I64]:
    """Each face's corner labels (the part of each corner's nearest slot) and the label pairs (i < j) that
    meet along an edge, sorted."""
    label = part_of[np.argmin(slot_distances, axis=0)]
    edges = np.sort(label[mesh.edges()], axis=1)
    pairs: I64 = np.unique(edges[edges[:, 0] != edges[:, 1]], axis=0)
    return label[mesh.faces], pairs


def _part_tree(
    skeleton: Skeleton, slot_parts: tuple[str, ...]
) -> tuple[tuple[str, ...], I64, dict[int, int]]:
    """Parts in slot order, each slot's part index, and each part's parent part (the skeleton's joints
    between slots of different parts)."""
    parts = tuple(dict.fromkeys(slot_parts))
    part_of = np.array([parts.index(p) for p in slot_parts], dtype=np.int64)
    parent = {int(part_of[c]): int(part_of[p]) for p, c in skeleton.joints if part_of[p] != part_of[c]}
    return parts, part_of, parent


def _pair_bridge(slots: F64, part_of: I64, i: int, j: int, distance: DistanceFn) -> tuple[float, float]:
    """(gap, bridge) of parts i and j: the smallest primitive gap between their slots, and the bound on the
    field along the segment joining those two primitives' closest points."""
    gap, a, b = min(
        (primitive_gap(slots, int(a), int(b)), int(a), int(b))
        for a in np.flatnonzero(part_of == i)
        for b in np.flatnonzero(part_of == j)
    )
    p, q = _closest_points(slots[a, col.A], slots[a, col.B], slots[b, col.A], slots[b, col.B])
    return gap, bridge_bound(distance, p, q)


def certain_handle_possible(
    mesh: Mesh,
    slot_distances: F64,
    distance: DistanceFn,
    skeleton: Skeleton,
    slots: F64,
    slot_parts: tuple[str, ...],
) -> bool:
    """Whether ``handle_contacts`` would find a *certain* contact (``Contact.certain``), computing the
    genus only for the pairs that could be one: parts that meet on the mesh, are not joined, and have a
    negative bridge. Each cut's genus costs ~0.1 s on a 160k-vertex mesh and the other pairs are most of them,
    so a lattice that fails euler without a certain handle is refined at once, its contacts looked for
    only if it is reported. Same pairs, bridges and genus drops as ``handle_contacts``, so the answer is
    exactly ``any(c.certain for c in handle_contacts(...))``."""
    _, part_of, parent = _part_tree(skeleton, slot_parts)
    face_labels, pairs = _contact_pairs(mesh, slot_distances, part_of)
    base: Uncut | None = None
    genus = 0.0
    for i, j in pairs:
        if parent.get(int(i)) == j or parent.get(int(j)) == i:
            continue
        if _pair_bridge(slots, part_of, int(i), int(j), distance)[1] >= 0.0:
            continue
        if base is None:
            base, genus = uncut(mesh), surface_genus(mesh)
        if genus <= 0.0:
            return False
        strip = np.any(face_labels == i, axis=1) & np.any(face_labels == j, axis=1)
        if genus - cut_genus(base, strip) >= 1.0:
            return True
    return False
