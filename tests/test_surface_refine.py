"""The refinement budget: small lattices may halve a few more times, large ones stop at two."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from creaturegen.model.skeleton import build_skeleton
from creaturegen.rig import compile_rig
from creaturegen.spec import CharacterSpec, load_spec
from creaturegen.surface import lattice, remedies
from creaturegen.surface.backends import NumpyBackend
from creaturegen.surface.grid import BLOCK, Grid
from creaturegen.surface.lattice import (
    EXTRA_REFINEMENTS,
    MAX_REFINEMENTS,
    SMALL_LATTICE_NODES,
    FixedBackend,
    ValidatedMesh,
    _may_refine,
    validated_mesh,
)
from creaturegen.surface.sampling import _block_nodes

#: Generated seed 4: a handle at its first three distant lattices that no unjoined pair makes certain.
UNTIL_FINE = Path(__file__).parent / "fixtures" / "genus-until-fine-quadruped.json"


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
    from creaturegen.surface.grid import ERROR_TARGET, make_grid, spacing_for, tier_offset

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
            # The same lattice node for node; only whose mesh gates judge it differs.
            assert lower.tier == tier
            assert replace(lower, tier="hero") == hero, (tier, refinement, lower, hero)


def test_a_pointed_tip_starts_at_the_first_lattice_cap_and_refines_up_to_the_limit() -> None:
    """A 1 m body with a 0.5 mm tip asks for far more cells than the cap: the first lattice stops at
    FIRST_CELLS_LIMIT and names the part; refinements follow until MAX_CELLS_PER_AXIS, then stop with a
    message that names the part and the radius that would fit."""
    import numpy as np
    import pytest

    from creaturegen.model import layout as col
    from creaturegen.model.graph import BlendGraph
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


def _validated(path: Path, tier: str, said: list[str]) -> ValidatedMesh:
    spec = load_spec(path)
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    backend = NumpyBackend(rig.graph, rig.slots)
    return validated_mesh(rig, build_skeleton(spec, rig), tier, FixedBackend(backend, "test"), said.append)


def test_a_lattice_refined_for_its_genus_changes_no_result(monkeypatch: pytest.MonkeyPatch) -> None:
    """A lattice whose genus is wrong with no certain handle is refined without its other gates
    (lattice._deferred). The generated quadruped closes a handle at its first three distant lattices: the
    build must end where judging every lattice in full ends, with the same mesh and gate values."""
    said: list[str] = []
    quick = _validated(UNTIL_FINE, "distant", said)
    waited = [line for line in said if "the other gates wait" in line]
    assert len(waited) == 3, said
    monkeypatch.setattr(lattice, "_deferred", lambda *args: None)
    full: list[str] = []
    eager = _validated(UNTIL_FINE, "distant", full)
    assert not any("the other gates wait" in line for line in full)
    assert sum("mesh gates: " in line for line in full) == 4, full
    assert quick.refinement == eager.refinement == 3
    assert np.array_equal(quick.extraction.mesh.faces, eager.extraction.mesh.faces)
    assert [(g.name, g.value, g.passed) for g in quick.gates] == [
        (g.name, g.value, g.passed) for g in eager.gates
    ]


def test_when_every_lattice_has_the_wrong_genus_the_finest_is_reported(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With the budget cut to one refinement the quadruped's two lattices both close the handle: the
    report is the finer one, judged in full, and the coarser (deferred) one is never judged."""
    monkeypatch.setattr(lattice, "_may_refine", lambda refinement, grid, tier="hero": refinement < 1)
    said: list[str] = []
    result = _validated(UNTIL_FINE, "distant", said)
    assert result.refinement == 1
    failed = [g.name for g in result.gates if not g.passed]
    assert "euler" in failed
    assert len(result.gates) > 1
    assert not any("judging refinement 0 in full" in line for line in said), said


@pytest.mark.parametrize(
    ("failed", "some", "expected"),
    [
        (["vertexNormalAngleMax"], ["faceNormalAngleMax"], False),  # as many, another gate
        (["vertexNormalAngleMax"], ["vertexNormalAngleMax", "faceNormalAngleMax"], False),
        (["vertexNormalAngleMax"], ["vertexNormalAngleMax"], True),
        (["vertexNormalAngleMax", "faceNormalAngleMax"], ["faceNormalAngleP99"], True),  # fewer so far
        ([], ["faceNormalAngleMax"], False),
        ([], [], True),
    ],
)
def test_a_remedy_is_turned_down_early_only_when_no_full_pass_could_keep_it(
    failed: list[str], some: list[str], expected: bool
) -> None:
    """The other gates can only add failures: whenever ``_may_be_no_worse`` says no, every superset of
    ``some`` (what a full pass could find) fails ``_no_worse`` too, and when it says yes, ``some`` itself
    (a full pass that adds nothing) is kept."""
    assert remedies._may_be_no_worse(failed, some) == expected
    others = ["euler", "selfIntersections", "surfaceToZeroSet"]
    supersets = [some + others[:n] for n in range(len(others) + 1)]
    if not expected:
        assert not any(remedies._no_worse(failed, full) for full in supersets)
    else:
        assert remedies._no_worse(failed, some)


def test_each_tier_judges_its_mesh_at_its_own_limits() -> None:
    """Distances follow the sagitta targets, the p99 normal angles the tiers' skin tolerances, and each
    lower tier accepts whatever a higher one does (so no lower tier refuses a lattice the hero passes)."""
    from creaturegen.candidates import TIERS
    from creaturegen.surface.grid import ERROR_TARGET
    from creaturegen.surface.mesh_gates import NORMAL_LIMITS, mesh_limits
    from creaturegen.surface.remedies import split_marks
    from creaturegen.surface.subdivide import MARK_FACE_DEG, MARK_VERTEX_DEG, TAIL_MARKS

    hero = mesh_limits("hero")
    assert hero.distance == 0.005
    assert hero.normals == NORMAL_LIMITS
    assert split_marks("hero") == ((MARK_VERTEX_DEG, MARK_FACE_DEG), TAIL_MARKS)
    previous = hero
    for tier in ("repeated", "distant"):
        limits, skin = mesh_limits(tier), TIERS[tier].skin
        assert skin is not None
        assert limits.distance == pytest.approx(0.005 * ERROR_TARGET[tier] / ERROR_TARGET["hero"])
        assert limits.normals[1] == skin.normal_deg
        assert limits.normals[3] == 2.0 * skin.normal_deg
        assert (limits.normals[0], limits.normals[2]) == (NORMAL_LIMITS[0], NORMAL_LIMITS[2])
        assert limits.distance > previous.distance
        assert all(a >= b for a, b in zip(limits.normals, previous.normals, strict=True))
        previous = limits


def test_the_distant_first_lattice_passes_distant_gates_and_fails_the_heros() -> None:
    """The hopper's first distant lattice (1,658 vertices): its distances pass the distant tier's 0.02 L
    and fail the hero's 0.005 L, judged by the same function on the same mesh."""
    from conftest import EXAMPLES, rest_surface
    from creaturegen.surface.mesh_gates import surface_mesh_gates

    s = rest_surface(EXAMPLES / "reference" / "hopper.json", "distant")
    skeleton = build_skeleton(s.spec, s.rig)
    assert s.grid.tier == "distant"
    as_distant, _ = surface_mesh_gates(s.rig, s.extraction, s.field, skeleton, s.grid)
    as_hero, _ = surface_mesh_gates(s.rig, s.extraction, s.field, skeleton, replace(s.grid, tier="hero"))
    distances = ("surfaceToZeroSet", "zeroSetToMesh")
    assert all(g.passed for g in as_distant if g.name in distances)
    assert not any(g.passed for g in as_hero if g.name in distances)
