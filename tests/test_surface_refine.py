"""The refinement budget: small lattices may halve a few more times, large ones stop at two."""

from __future__ import annotations

import numpy as np

from creaturegen.surface.build import EXTRA_REFINEMENTS, MAX_REFINEMENTS, SMALL_LATTICE_NODES, _may_refine
from creaturegen.surface.grid import BLOCK, Grid
from creaturegen.surface.sampling import _block_nodes


def _grid(n: int) -> Grid:
    return Grid((0.0, 0.0, 0.0), 0.01, (n, n, n))


def test_every_lattice_gets_the_first_refinements() -> None:
    assert all(_may_refine(r, _grid(600)) for r in range(MAX_REFINEMENTS))


def test_extra_refinements_only_while_the_lattice_is_small() -> None:
    small = _grid(49)  # 49³ = 117,649 nodes
    assert _may_refine(MAX_REFINEMENTS, small)
    assert not _may_refine(MAX_REFINEMENTS + EXTRA_REFINEMENTS, small)
    big = _grid(150)  # 3.4 M nodes, 9.5 M after a √2 refinement
    assert SMALL_LATTICE_NODES < 2.0**1.5 * 150**3
    assert not _may_refine(MAX_REFINEMENTS, big)


def test_a_lower_tier_may_refine_as_far_as_the_hero_would() -> None:
    """The distant lattice starts two √2 refinements coarser than the hero's (sagitta target 0.24 vs 0.06),
    the repeated one one: their budgets count from the hero's first lattice, and their lattices are the
    hero's node for node, so a refinement the hero passes the lower tiers reach and pass too."""
    from conftest import EXAMPLES
    from creaturegen.rig import compile_rig
    from creaturegen.spec import CharacterSpec, load_spec
    from creaturegen.surface.build import tier_offset
    from creaturegen.surface.grid import ERROR_TARGET, make_grid, spacing_for

    spec = load_spec(EXAMPLES / "reference" / "hopper.json")
    assert isinstance(spec, CharacterSpec)
    slots = compile_rig(spec).slots

    big = _grid(150)
    assert [tier_offset(t) for t in ("hero", "repeated", "distant")] == [0, 1, 2]
    assert not _may_refine(MAX_REFINEMENTS, big, "hero")
    assert _may_refine(MAX_REFINEMENTS, big, "repeated")
    assert not _may_refine(MAX_REFINEMENTS + 1, big, "repeated")
    assert _may_refine(MAX_REFINEMENTS + 1, big, "distant")
    assert not _may_refine(MAX_REFINEMENTS + 2, big, "distant")
    small = _grid(49)
    assert _may_refine(MAX_REFINEMENTS + 2 + EXTRA_REFINEMENTS - 1, small, "distant")
    # The offset is the spacing ratio in √2 steps, to the nearest step.
    for tier in ("repeated", "distant"):
        steps = 2.0 * np.log2(spacing_for(slots, tier) / spacing_for(slots, "hero"))
        assert abs(steps - tier_offset(tier)) < 1e-9
        assert ERROR_TARGET[tier] > ERROR_TARGET["hero"]
    rig = compile_rig(spec)
    for refinement in range(3):
        hero = make_grid(rig.slots, rig.graph, "hero", rig.slot_parts, refinement)
        for tier in ("repeated", "distant"):
            lower = make_grid(rig.slots, rig.graph, tier, rig.slot_parts, refinement + tier_offset(tier))
            assert lower == hero, (tier, refinement, lower, hero)


def test_a_pointed_tip_starts_at_the_first_lattice_cap_and_refines_up_to_the_limit() -> None:
    """A 1 m body with a 0.5 mm tip asks for far more cells than the cap: the first lattice stops at
    FIRST_CELLS_LIMIT and names the part; refinements follow until MAX_CELLS_PER_AXIS, then stop with a
    message that names the part and the radius that would fit."""
    import numpy as np
    import pytest

    from creaturegen.field import layout as col
    from creaturegen.rig.graph import BlendGraph
    from creaturegen.surface.grid import (
        BLOCK,
        FIRST_CELLS_LIMIT,
        MAX_CELLS_PER_AXIS,
        GridTooFineError,
        make_grid,
    )

    slots = np.zeros((2, col.WIDTH))
    slots[0, col.A], slots[0, col.B], slots[0, col.RA], slots[0, col.RB] = (0, 0, 0), (0, 0, 1), 0.2, 0.2
    slots[1, col.A], slots[1, col.B], slots[1, col.RA], slots[1, col.RB] = (
        (0, 0, 1),
        (0, 0.3, 1.2),
        0.02,
        5e-4,
    )
    graph = BlendGraph((), ())
    first = make_grid(slots, graph, "hero", ("body", "horn"))
    assert first.limited_by == "part.horn"
    assert max(first.shape) - 1 <= FIRST_CELLS_LIMIT + BLOCK
    finer = make_grid(slots, graph, "hero", ("body", "horn"), refinement=1)
    assert max(finer.shape) - 1 <= MAX_CELLS_PER_AXIS
    assert finer.spacing == pytest.approx(first.spacing / 2**0.5)
    with pytest.raises(
        GridTooFineError, match=r"part\.horn\.r2: .*Thicken part\.horn to a radius of at least"
    ):
        make_grid(slots, graph, "hero", ("body", "horn"), refinement=2)
    # A body whose target fits is not limited.
    slots[1, col.RB] = 0.02
    assert make_grid(slots, graph, "hero", ("body", "horn")).limited_by == ""


def test_block_nodes_are_the_sorted_unique_nodes_of_the_blocks() -> None:
    """sampling._block_nodes marks nodes instead of sorting them; shared block faces still count once and
    the order is np.unique's (the sampled values are scattered back by these ids)."""
    grid = Grid((0.0, 0.0, 0.0), 0.1, (3 * BLOCK + 1, 2 * BLOCK + 1, 4 * BLOCK + 1))
    blocks = np.array([0, 1, 5, 6, 7, 23], dtype=np.int64)
    offsets = np.stack(np.meshgrid(*([np.arange(BLOCK + 1)] * 3), indexing="ij"), axis=-1).reshape(-1, 3)
    corner = np.stack(np.unravel_index(blocks, grid.blocks), axis=1) * BLOCK
    nodes = (corner[:, None, :] + offsets[None, :, :]).reshape(-1, 3)
    expected = np.unique(np.ravel_multi_index((nodes[:, 0], nodes[:, 1], nodes[:, 2]), grid.shape))
    np.testing.assert_array_equal(_block_nodes(grid, blocks), expected)
