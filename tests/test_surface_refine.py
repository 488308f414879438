"""The refinement budget: small lattices may halve a few more times, large ones stop at two."""

from __future__ import annotations

from creaturegen.surface.build import EXTRA_REFINEMENTS, MAX_REFINEMENTS, SMALL_LATTICE_NODES, _may_refine
from creaturegen.surface.grid import Grid


def _grid(n: int) -> Grid:
    return Grid((0.0, 0.0, 0.0), 0.01, (n, n, n))


def test_every_lattice_gets_the_first_refinements() -> None:
    assert all(_may_refine(r, _grid(600)) for r in range(MAX_REFINEMENTS))


def test_extra_refinements_only_while_the_lattice_is_small() -> None:
    small = _grid(49)  # 117,649 nodes: the eyed hopper of corpus seed 10 at refinement 2
    assert _may_refine(MAX_REFINEMENTS, small)
    assert not _may_refine(MAX_REFINEMENTS + EXTRA_REFINEMENTS, small)
    big = _grid(121)  # 1.77 M nodes, 5.0 M after a √2 refinement
    assert SMALL_LATTICE_NODES < 2.0**1.5 * 121**3
    assert not _may_refine(MAX_REFINEMENTS, big)
