"""The sampling lattice of one body: resolution from a surface-error target, bounds from the slots.

Spacing rule. A marching-cubes surface whose vertices lie on the zero set deviates from it inside a
triangle by at most the chord sagitta ``h²κ/8`` for edge length ``h`` and curvature ``κ``. The sharpest
convex curvature a body of round primitives has is ``1/r_min`` (its thinnest primitive end), so a target
sagitta of ``ε·r_min`` gives ``h = √(8ε)·r_min``. Concave blend fillets are flatter than that (their
radius grows with the blend width k), so the same bound covers them. The grid extent is capped: when the
thinnest part (a horn's or a claw's pointed tip) would need more cells than ``FIRST_CELLS_LIMIT``, the
first lattice has that many along its longest axis and says so (``Grid.limited_by``). The sagitta target
is how the spacing is chosen, not what protects the mesh: the mesh gates (distance to the zero set, normals,
topology, in units of the body size L) judge the result, and a pointed tip a little blunter than its own
radius asks for passes them or fails them by name; refinements follow while they fit the cap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..field.primitives import TAPER_EXACT_THRESHOLD
from ..model import layout as col
from ..model.graph import BlendGraph

#: Surface-error target per tier, as a fraction of the smallest primitive radius (sagitta bound). The
#: lower tiers' are the hero's times 2 and 4, so their lattices are the hero's one and two √2 steps
#: coarser, node for node (``make_grid``): a lower tier refined that far extracts the very mesh the hero
#: does, and no lower tier fails a mesh gate on a lattice the hero passes.
ERROR_TARGET = {"hero": 0.06, "repeated": 0.12, "distant": 0.24}
#: The tier whose lattice the others are steps of.
FINEST_TIER = "hero"
#: Largest lattice extent along any axis; beyond it the target is unreachable at load-time cost.
MAX_CELLS_PER_AXIS = 640
#: Largest first lattice: a body whose sagitta target asks for more starts here, and refinements (each √2
#: finer) go on up to MAX_CELLS_PER_AXIS. Vertices grow with the square of the cell count, so a first try at
#: the limit costs about twice as much as one here; the mesh gates decide whether the coarser one will do.
FIRST_CELLS_LIMIT = 448
#: Fine cells per narrow-band block edge.
BLOCK = 8
#: Upper bound on |∇d| for every primitive form and blend (see ``LIPSCHITZ_BOUND``) with margin.
LIPSCHITZ_MARGIN = 1.01


class GridTooFineError(ValueError):
    """The error target needs a lattice larger than MAX_CELLS_PER_AXIS; names the limiting slot."""


@dataclass(frozen=True)
class Grid:
    """An axis-aligned lattice: node (i, j, k) sits at ``origin + spacing·(i, j, k)``."""

    origin: tuple[float, float, float]
    spacing: float
    shape: tuple[int, int, int]  # nodes per axis, each a multiple of BLOCK plus one
    limited_by: str = ""  # the part whose sagitta target the cell cap did not allow, when one did not fit
    tier: str = FINEST_TIER  # whose mesh gates judge a mesh extracted here (mesh_gates.mesh_limits)

    def points(self, index: npt.NDArray[np.int64] | npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """World positions of integer (or half-integer) lattice coordinates (N, 3)."""
        result: npt.NDArray[np.float64] = np.asarray(self.origin) + self.spacing * index
        return result

    @property
    def blocks(self) -> tuple[int, int, int]:
        n = self.shape
        return ((n[0] - 1) // BLOCK, (n[1] - 1) // BLOCK, (n[2] - 1) // BLOCK)


def smallest_radius(slots: npt.NDArray[np.float64]) -> tuple[float, int]:
    """The thinnest primitive end and its slot index: the curvature bound of the body."""
    radii = np.minimum(slots[:, col.RA], slots[:, col.RB])
    index = int(np.argmin(radii))
    return float(radii[index]), index


def spacing_for(slots: npt.NDArray[np.float64], tier: str) -> float:
    """Lattice spacing meeting the tier's sagitta target relative to the thinnest primitive."""
    r_min, _ = smallest_radius(slots)
    return math.sqrt(8.0 * ERROR_TARGET[tier]) * r_min


def tier_offset(tier: str) -> int:
    """√2 refinements from the tier's first lattice to the hero tier's: h grows with √ε, so a tier whose
    sagitta target is 2ⁿ times the hero's starts n refinements coarser."""
    return max(round(math.log2(ERROR_TARGET[tier] / ERROR_TARGET[FINEST_TIER])), 0)


#: A bound on |∇d| over any body: √(1+s²) for tapered capsules (s ≤ TAPER_EXACT_THRESHOLD), 1 for exact
#: forms. Polynomial smooth-min and log-sum-exp gradients are convex combinations of their children's, and
#: a hard min picks one, so no blend raises it.
LIPSCHITZ_BOUND = LIPSCHITZ_MARGIN * math.sqrt(1.0 + TAPER_EXACT_THRESHOLD**2)


def swell_bound(graph: BlendGraph) -> float:
    """How far the blends can push the zero set beyond the primitives, summed over every op.

    A polynomial smooth-min lies at most k/4 below the min of its children and an n-ary log-sum-exp at
    most k·log N; nesting adds them, so the sum over all ops bounds any chain.
    """
    return sum(op.k / 4.0 if op.kernel == "poly" else op.k * math.log(len(op.children)) for op in graph.ops)


def body_box(
    slots: npt.NDArray[np.float64], graph: BlendGraph
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Rest AABB of every slot's end spheres, widened by the blends' swell bound."""
    a, b = slots[:, col.A], slots[:, col.B]
    r = np.maximum(slots[:, col.RA], slots[:, col.RB])[:, None]
    swell = swell_bound(graph)
    lo = np.minimum(a - r, b - r).min(axis=0) - swell
    hi = np.maximum(a + r, b + r).max(axis=0) + swell
    return lo, hi


def make_grid(
    slots: npt.NDArray[np.float64],
    graph: BlendGraph,
    tier: str,
    slot_names: tuple[str, ...],
    refinement: int = 0,
) -> Grid:
    """The tier's lattice over the body box, padded by two cells and rounded up to whole blocks.

    ``refinement`` n divides the spacing by 2^(n/2): the build retries finer when a topology gate fails
    (a gap between parts narrower than the spacing lets marching cubes bridge it). A lower tier starts
    ``tier_offset`` steps coarser than the hero's first lattice (after its cap, when the thinnest part
    would need more than FIRST_CELLS_LIMIT cells), so its lattices are the hero's, further out.
    """
    box_lo, hi = body_box(slots, graph)
    extent = float((hi - box_lo).max())
    # Every tier's spacing is the hero's first spacing times a power of √2, computed from one exponent so
    # that the repeated tier's refinement n + 1 is the hero's refinement n bit for bit.
    h = spacing_for(slots, FINEST_TIER)
    limited_by = ""
    if extent / h + 4.0 > FIRST_CELLS_LIMIT:
        _, index = smallest_radius(slots)
        limited_by = f"part.{slot_names[index]}"
        h = extent / (FIRST_CELLS_LIMIT - BLOCK)  # room for the two-cell pads, rounded up to a block
    h /= 2.0 ** ((refinement - tier_offset(tier)) / 2.0)
    lo = box_lo - 2.0 * h
    cells = np.ceil((hi + 2.0 * h - lo) / h).astype(np.int64)
    cells = ((cells + BLOCK - 1) // BLOCK) * BLOCK
    if int(cells.max()) > MAX_CELLS_PER_AXIS:
        r_min, index = smallest_radius(slots)
        # The spacing, and with it the cell count, is proportional to the thinnest radius.
        fits = r_min * float(cells.max()) / MAX_CELLS_PER_AXIS
        end = "r" if slots[index, col.RA] <= slots[index, col.RB] else "r2"
        raise GridTooFineError(
            f"part.{slot_names[index]}.{end}: radius {r_min:.4g} m needs {int(cells.max())} lattice cells "
            f"along one axis for the {tier} surface-error target ({ERROR_TARGET[tier]}·r); the limit is "
            f"{MAX_CELLS_PER_AXIS}. Thicken part.{slot_names[index]} to a radius of at least {fits:.3g} m "
            "(r × scale), or choose a coarser tier."
        )
    shape = (int(cells[0]) + 1, int(cells[1]) + 1, int(cells[2]) + 1)
    return Grid((float(lo[0]), float(lo[1]), float(lo[2])), h, shape, limited_by, tier)
