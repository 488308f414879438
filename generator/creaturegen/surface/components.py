"""The component policy: every extracted component owns slots, and no blend root splits apart.

A creature is one body per blend root, joined by hard min where roots touch, so the mesh may have fewer
components than roots but never a component that owns no slot (a stray island: a pinched-off tip, a
bubble): those are rejected. A root whose slots land in two components is *declared*, not rejected: the
field itself can leave a part detached (a rope anchored beyond its parent's surface has positive
distance all the way between them), and the mesh must show the field, so the build reports each
detached part by name instead of bridging it.

Ownership is geometric, not by nearest vertex: a slot's axis midpoint lies inside its own primitive
and so inside the body, and the component whose generalised winding number there is ≥ ½ encloses it.
The expected component count is therefore derived, not authored: the number of components that own a
slot, which the policy requires to be every component.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..model import layout as col
from ..model.graph import BlendGraph, Ref
from .handles import Contact
from .mesh import Mesh
from .topology import components

F64 = npt.NDArray[np.float64]


@dataclass(frozen=True)
class ComponentPolicy:
    count: int  # extracted components
    owners: tuple[int, ...]  # owning component per slot (−1: enclosed by none)
    strays: tuple[int, ...]  # components that own no slot
    split_roots: tuple[str, ...]  # "part.<id>" of roots whose slots lie in more than one component
    detached: tuple[str, ...]  # "part.<id>" of the first slot of every component but a root's first
    unowned_slots: tuple[str, ...]  # slots no component encloses
    handles: tuple[Contact, ...] = ()  # contacts closing a handle (looked for only when euler fails)

    @property
    def handles_certain(self) -> bool:
        """Some part pair closes a handle that any lattice would show (surface/handles.py), so the euler
        gate fails at every refinement."""
        return any(c.certain for c in self.handles)

    @property
    def expected(self) -> int:
        return len({o for o in self.owners if o >= 0})

    @property
    def passed(self) -> bool:
        return not (self.strays or self.unowned_slots)


def winding_numbers(corners: F64, points: F64) -> F64:
    """Generalised winding number of a closed triangle set at points (Van Oosterom and Strackee)."""
    out = np.empty(points.shape[0])
    for i, p in enumerate(points):
        a, b, c = corners[:, 0] - p, corners[:, 1] - p, corners[:, 2] - p
        la, lb, lc = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1), np.linalg.norm(c, axis=1)
        det = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = (
            la * lb * lc
            + np.einsum("ij,ij->i", a, b) * lc
            + np.einsum("ij,ij->i", b, c) * la
            + np.einsum("ij,ij->i", c, a) * lb
        )
        out[i] = np.arctan2(det, den).sum() / (2.0 * np.pi)
    return out


def root_slots(graph: BlendGraph) -> list[list[int]]:
    """The slot leaves under each root of the program."""

    def leaves(ref: Ref) -> list[int]:
        if ref.kind == "slot":
            return [ref.index]
        return [s for child in graph.ops[ref.index].children for s in leaves(child)]

    return [leaves(r) for r in graph.roots]


def component_policy(mesh: Mesh, slots: F64, graph: BlendGraph, names: tuple[str, ...]) -> ComponentPolicy:
    found = components(mesh)
    midpoints = 0.5 * (slots[:, col.A] + slots[:, col.B])
    owners = np.full(slots.shape[0], -1)
    corners = mesh.corners()
    for label in range(found.count):
        w = winding_numbers(corners[found.face_labels == label], midpoints)
        owners[(w >= 0.5) & (owners < 0)] = label
    owned = {int(o) for o in owners if o >= 0}
    strays = tuple(label for label in range(found.count) if label not in owned)
    split = []
    detached = []
    for leaves in root_slots(graph):
        homes = {int(owners[s]) for s in leaves if owners[s] >= 0}
        if len(homes) > 1:
            split.append(names[leaves[0]])
            first_home = int(owners[leaves[0]])
            for home in sorted(homes - {first_home}):
                detached.append(names[next(s for s in leaves if owners[s] == home)])
    unowned = tuple(names[s] for s in range(slots.shape[0]) if owners[s] < 0)
    return ComponentPolicy(
        found.count, tuple(int(o) for o in owners), strays, tuple(split), tuple(detached), unowned
    )
