"""Candidate programs: certified omissions, the envelope sweep, growing K and rejecting tiers."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest

from conftest import EXAMPLES, PARITY_EXAMPLES, TEST_FULL
from creaturegen.candidates import CandidateSet, TierRejectedError, build_candidates, tolerances
from creaturegen.candidates.bounds import leaf_bounds, subtree_info
from creaturegen.candidates.program import build_program
from creaturegen.candidates.regions import RegionSearch, Tier, search
from creaturegen.field.floors import floors_for
from creaturegen.field.sampler import sample_graph
from creaturegen.model.rotations import posed_slots
from creaturegen.motion.compiled import compile_creature
from creaturegen.motion.envelope import pose_envelope
from creaturegen.rig import CompiledRig, compile_rig
from creaturegen.spec import CharacterSpec, load_spec

CREATURES = [p for p in sorted(EXAMPLES.rglob("*.json")) if "frost" not in p.parts]
#: The examples whose hero programs are certified here: every one in ``make test-full``; in ``make test``
#: the ones whose packages the suite builds (a hero build certifies its programs too) and the beetle,
#: whose n-ary tails a test below reads. The others (biped, hexapod, lizard, moth) cost 33 s of envelope
#: sweeps on two cores and are certified by ``make test-full`` and by every build of them.
CERTIFIED = (
    CREATURES
    if TEST_FULL
    else [p for p in CREATURES if p.relative_to(EXAMPLES).as_posix() in {*PARITY_EXAMPLES, "beetle.json"}]
)


@cache
def _compiled(path: Path) -> tuple[CharacterSpec, CompiledRig]:
    spec = load_spec(path)
    assert isinstance(spec, CharacterSpec)
    return spec, compile_rig(spec)


@cache
def _hero(path: Path) -> CandidateSet:
    spec, _rig = _compiled(path)
    return build_candidates(compile_creature(spec), "hero")


@pytest.mark.parametrize("path", CERTIFIED, ids=lambda p: p.name)
def test_hero_programs_are_certified_and_pass_the_sweep(path: Path) -> None:
    _, rig = _compiled(path)
    found = _hero(path)
    assert found.programs, "every body has surface regions"
    assert all(p.certified for p in found.programs)
    assert found.k_used == max(len(p.leaves) for p in found.programs) <= rig.slot_count
    assert found.sweep.points >= 1000
    for gate in found.gates:
        assert gate.passed, gate


def test_an_uncertified_omission_is_flagged_and_really_changes_the_field() -> None:
    """Certificates are not decoration: drop a leaf that touches the region and both the certificate and
    the measured field disagree with the full graph."""
    spec, rig = _compiled(EXAMPLES / "reference" / "biped.json")
    head = rig.slot_parts.index("head")
    centre = rig.slots[head, 0:3]
    lo, hi = centre - 0.1, centre + 0.1
    excursion = pose_envelope(compile_creature(spec)).slot_excursion
    bounds = leaf_bounds(rig.slots, excursion, lo, hi)
    tol = tolerances(rig)
    kept = set(range(rig.slot_count)) - {head}
    program = build_program(
        rig.graph,
        subtree_info(rig.graph),
        bounds,
        rig.slots,
        kept,
        (lo, hi),
        tol.band,
        tol.tail,
        tol.weight_floor,
        tol.k_floor,
    )
    failing = [c for c in program.certificates if not c.holds]
    assert {c.kind for c in failing} >= {"poly-saturation", "colour-weight"}
    points = centre + np.array([[0.0, 0.16, 0.0], [0.16, 0.0, 0.0], [0.0, 0.0, 0.16]])
    full = sample_graph(rig.graph, rig.slots, points, tol.k_floor)
    mine = sample_graph(program.graph, rig.slots[list(program.leaves)], points, tol.k_floor)
    assert np.abs(full.distance - mine.distance).min() > 0.05


def test_certified_programs_are_bit_exact_for_polynomial_trees() -> None:
    """A saturation certificate means h clamps to 0: the program returns the kept child bit for bit."""
    _, rig = _compiled(EXAMPLES / "reference" / "quadruped.json")
    found = _hero(EXAMPLES / "reference" / "quadruped.json")
    rng = np.random.default_rng(5)
    k_floor = floors_for(rig.body_scale).k_floor
    checked = 0
    for program in found.programs:
        p = rng.uniform(program.lo, program.hi, size=(64, 3))
        full = sample_graph(rig.graph, rig.slots, p, k_floor)
        band = np.abs(full.distance) <= tolerances(rig).band
        mine = sample_graph(program.graph, rig.slots[list(program.leaves)], p, k_floor)
        assert np.array_equal(mine.distance[band], full.distance[band])
        checked += int(band.sum())
    assert checked > 100


def test_lse_tail_bounds_cover_the_measured_error() -> None:
    found = _hero(EXAMPLES / "beetle.json")
    tails = [c for p in found.programs for c in p.certificates if c.kind == "lse-tail"]
    assert tails, "the beetle's n-ary groups are pruned somewhere"
    assert found.sweep.surface_error <= max(c.value for c in tails) + 1e-15
    assert found.sweep.surface_error > 0  # the tail is real, not zero


#: A capped tier of K = 4: the shipped lower tiers use the skin representation (surface/skin_tier.py) and
#: no candidate programs, but the capped search is what a field tier with a hard K does.
CAPPED = Tier("capped", 4, 4)


def _capped(path: Path) -> RegionSearch:
    spec, rig = _compiled(path)
    return search(rig, pose_envelope(compile_creature(spec)).slot_excursion, CAPPED, tolerances(rig))


def test_the_lower_tiers_have_no_candidate_programs() -> None:
    spec, _rig = _compiled(EXAMPLES / "reference" / "flyer.json")
    for tier in ("repeated", "distant"):
        with pytest.raises(TierRejectedError, match=rf"^tier {tier}: skin representation"):
            build_candidates(compile_creature(spec), tier)


def test_small_tiers_are_rejected_with_the_region_and_omission_named() -> None:
    with pytest.raises(
        TierRejectedError, match=r"^tier capped: region \[.*\] needs more than K = 4 leaves: "
    ):
        _capped(EXAMPLES / "reference" / "quadruped.json")


def test_a_rigid_creature_fits_a_small_k() -> None:
    found = _capped(EXAMPLES / "reference" / "flyer.json")
    assert max(len(p.leaves) for p in found.programs) <= 4


def test_the_sweep_reads_the_motion_and_the_certificates_contain_it() -> None:
    """The candidate sweep evaluates the programs at the motion's own poses, and every slot of those poses
    lies inside the excursion ball the certificates assumed (tests/test_motion_envelope.py checks
    individuals the envelope never stepped)."""
    spec, rig = _compiled(EXAMPLES / "reference" / "quadruped.json")
    found = _hero(EXAMPLES / "reference" / "quadruped.json")
    env = pose_envelope(compile_creature(spec))
    assert found.sweep.motion_poses == len(env.poses) > 0
    excursion = env.slot_excursion
    for pose in env.poses:
        moved = np.linalg.norm(posed_slots(rig.slots, pose)[:, 0:3] - rig.slots[:, 0:3], axis=1)
        assert np.all(moved <= excursion + 1e-12)
    tail = [s for s, part in enumerate(rig.slot_parts) if part == "tail"]
    assert excursion[tail[-1]] > excursion[tail[0]] > 0.0, "a tail's tip swings furthest"


def _two_leaf_colour(colour_b: tuple[float, float, float], gap: float) -> tuple[float, bool]:
    """The colour certificate of keeping slot 0 and omitting slot 1, whose lower bound lies ``gap`` above
    the kept upper bound (k = 0.1, so the omitted weight is e^(−gap/0.1))."""
    from creaturegen.candidates.bounds import LeafBounds, subtree_info
    from creaturegen.candidates.program import _colour_certificate
    from creaturegen.model import layout as col
    from creaturegen.model.graph import BlendGraph

    slots = np.zeros((2, col.WIDTH))
    slots[:, col.RA] = slots[:, col.RB] = 0.1
    slots[:, col.K] = 0.1
    slots[0, col.RGB] = (0.5, 0.3, 0.2)
    slots[1, col.RGB] = colour_b
    bounds = LeafBounds(lower=np.array([-0.01, gap]), upper=np.array([0.0, 1.0]))
    info = subtree_info(BlendGraph((), ()))
    cert = _colour_certificate(info, bounds, slots, {0}, 0.0, 2.0**-8, 1e-6)
    return cert.value, cert.holds


def test_the_colour_certificate_bounds_the_colour_error_not_the_weight() -> None:
    """An omitted leaf of the kept leaf's colour changes no colour however near it is; one of another
    colour must be far enough that its weight times the colour difference stays under one 8-bit step."""
    weight = float(np.exp(-0.07 / 0.1))  # ≈ 0.5: far above the old weight-only floor of 1/256
    same, holds_same = _two_leaf_colour((0.5, 0.3, 0.2), 0.07)
    assert same == 0.0
    assert holds_same
    other, holds_other = _two_leaf_colour((0.1, 0.3, 0.2), 0.07)
    assert other == pytest.approx(weight * 0.4)
    assert not holds_other
    # Far enough away, the other colour's weight is negligible and the omission holds again.
    far, holds_far = _two_leaf_colour((0.1, 0.3, 0.2), 0.6)
    assert far <= 2.0**-8
    assert holds_far
    # An omitted leaf that might be the nearest one (weight sum ≥ 1) is never omitted.
    _, holds_near = _two_leaf_colour((0.5, 0.3, 0.2), -0.05)
    assert not holds_near


def test_a_capped_tier_refusal_names_the_parts_and_the_remedy() -> None:
    with pytest.raises(TierRejectedError) as caught:
        _capped(EXAMPLES / "reference" / "quadruped.json")
    message = str(caught.value)
    assert "part." in message
    assert "--tier hero" in message
