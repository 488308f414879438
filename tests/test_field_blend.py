"""Blend operators: bounds, saturation, exact gradients, multiplicity bias and the LSE tail bound."""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
import pytest

from conftest import EXAMPLES
from creaturegen.field.blend import hard_min, lse_smin, lse_tail_bound, poly_smin
from creaturegen.field.primitives import primitive_distance, primitive_field
from creaturegen.field.sampler import sample, sample_distance
from creaturegen.rig import compile_rig
from creaturegen.spec import CharacterSpec, load_spec
from test_field_primitives import EPSILON_DECADES, central_difference_sweep, make_slots

Array = npt.NDArray[Any]


def random_pair(n: int = 5000, spread: float = 1.0, seed: int = 11) -> tuple[Array, Array, Array, Array]:
    """Two children's (distance, gradient) at n points; distances scaled by ``spread``."""
    rng = np.random.default_rng(seed)
    return (
        rng.normal(size=n) * spread,
        rng.normal(size=(n, 3)),
        rng.normal(size=n) * spread,
        rng.normal(size=(n, 3)),
    )


# --- polynomial smooth-min -------------------------------------------------------------------------


@pytest.mark.parametrize("k", [1e-3, 0.1, 0.6, 5.0])
def test_poly_smin_lies_between_min_minus_quarter_k_and_min(k: float) -> None:
    dl, gl, dr, gr = random_pair(spread=k)  # most pairs inside the blend band
    d, _, h = poly_smin(dl, gl, dr, gr, k)
    low = np.minimum(dl, dr)
    tol = 4 * np.finfo(float).eps * (np.abs(low) + k)
    assert np.all(d <= low + tol)
    assert np.all(d >= low - k / 4 - tol)
    assert np.any((h > 0) & (h < 1))
    # The bound k/4 is reached when the children agree.
    d_eq, _, _ = poly_smin(dl, gl, dl, gr, k)
    np.testing.assert_allclose(d_eq, dl - k / 4, rtol=0, atol=1e-14 * (1 + k))


def test_poly_smin_saturation_returns_the_exact_min_and_its_gradient() -> None:
    k = 0.3
    dl, gl, dr, gr = random_pair(spread=2.0)
    far = np.abs(dl - dr) >= k
    d, g, h = poly_smin(dl[far], gl[far], dr[far], gr[far], k)
    assert set(np.unique(h)) == {0.0, 1.0}
    left = dl[far] < dr[far]
    np.testing.assert_array_equal(d, np.where(left, dl[far], dr[far]))
    np.testing.assert_array_equal(g, np.where(left[:, None], gl[far], gr[far]))


def test_poly_smin_gradient_is_the_mix_of_child_gradients() -> None:
    k = 0.5
    dl, gl, dr, gr = random_pair(spread=0.2)
    _, g, h = poly_smin(dl, gl, dr, gr, k)
    np.testing.assert_allclose(g, (1 - h)[:, None] * gl + h[:, None] * gr, rtol=0, atol=1e-15)


def capsule_pair() -> Array:
    """Two crossing tapered capsules whose joint is a wide blend region."""
    return make_slots(
        ([-0.6, 0.0, 0.0], 0.30, [0.6, 0.05, 0.0], 0.28),
        ([0.05, -0.5, 0.1], 0.20, [0.1, 0.6, -0.15], 0.22),
    )


def test_blended_capsule_gradient_matches_central_differences() -> None:
    slots, k = capsule_pair(), 0.25

    def blended(p: Array) -> tuple[Array, Array, Array]:
        d, g = primitive_field(slots, p)
        return poly_smin(d[0], g[0], d[1], g[1], k)

    pts = np.random.default_rng(12).uniform(-0.7, 0.7, size=(4000, 3))
    _, _, h = blended(pts)
    pts = pts[(h > 0.05) & (h < 0.95)][:40]  # inside the blend band, clear of its saturation seams
    assert len(pts) == 40
    _, g, _ = blended(pts)
    errors = central_difference_sweep(lambda p: blended(p)[0], pts, g, EPSILON_DECADES)
    assert errors.min(axis=0).max() <= 1e-7


def test_poly_smin_rejects_a_non_positive_width() -> None:
    dl, gl, dr, gr = random_pair(3)
    with pytest.raises(ValueError, match="k"):
        poly_smin(dl, gl, dr, gr, 0.0)


# --- log-sum-exp ------------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1, 2, 5, 40])
def test_lse_smin_lies_between_min_minus_k_log_n_and_min(n: int) -> None:
    k, rng = 0.2, np.random.default_rng(13)
    ds = rng.normal(size=(n, 3000)) * 0.3
    gs = rng.normal(size=(n, 3000, 3))
    d, g, w = lse_smin(ds, gs, k)
    low = ds.min(axis=0)
    assert np.all(d <= low + 1e-15)
    assert np.all(d >= low - k * np.log(n) - 1e-15)
    # A sum of n rounded weights is within n·eps of 1 (its rounding bound); the summation order numpy
    # takes depends on the CPU's SIMD width (40 weights summed to 1 + 5 ulp on an AMD EPYC).
    np.testing.assert_allclose(w.sum(axis=0), 1.0, rtol=0, atol=max(n, 1) * np.finfo(float).eps)
    np.testing.assert_allclose(g, np.einsum("np,npc->pc", w, gs), rtol=0, atol=1e-14)


@pytest.mark.parametrize("n", [2, 3, 7, 64])
def test_lse_smin_of_equal_members_is_min_minus_k_log_n(n: int) -> None:
    k, rng = 0.15, np.random.default_rng(14)
    ds = np.tile(rng.normal(size=200), (n, 1))
    d, _, w = lse_smin(ds, rng.normal(size=(n, 200, 3)), k)
    np.testing.assert_allclose(d, ds[0] - k * np.log(n), rtol=0, atol=1e-14)
    np.testing.assert_allclose(w, 1.0 / n, rtol=0, atol=1e-15)


def test_lse_smin_does_not_overflow_far_from_the_surface() -> None:
    ds = np.array([[1e4, 2e4], [1e4 + 1.0, -3e4]])
    d, g, _ = lse_smin(ds, np.ones((2, 2, 3)), 1e-3)
    assert np.all(np.isfinite(d))
    assert np.all(np.isfinite(g))
    np.testing.assert_allclose(d, [1e4, -3e4])


def test_lse_tail_bound_covers_dropped_members() -> None:
    k, n, rng = 0.1, 12, np.random.default_rng(15)
    ds = np.sort(rng.uniform(0.0, 1.0, size=(n, 500)), axis=0)
    gs = rng.normal(size=(n, 500, 3))
    d_full, _, _ = lse_smin(ds, gs, k)
    checked = 0
    for kept in range(1, n):
        d_kept, _, _ = lse_smin(ds[:kept], gs[:kept], k)
        change = d_kept - d_full
        # Sums against the reference r = 0; the kept sum is exp(−d_kept/k) by definition.
        a = np.exp(-d_kept / k)
        b_exact = np.exp(-ds[kept:] / k).sum(axis=0)
        b_loose = (n - kept) * np.exp(-ds[kept] / k)  # from the nearest omitted member alone
        assert np.all(change >= 0)
        assert np.all(change <= lse_tail_bound(a, b_exact, k) + 1e-14)
        assert np.all(change <= lse_tail_bound(a, b_loose, k) + 1e-14)
        # With the exact omitted sum the bound is the change itself, so it is tight.
        np.testing.assert_allclose(change, lse_tail_bound(a, b_exact, k), rtol=1e-9, atol=1e-14)
        checked += 1
    assert checked == n - 1


def test_lse_tail_bound_rejects_an_empty_kept_sum() -> None:
    with pytest.raises(ValueError, match="kept_sum"):
        lse_tail_bound(0.0, 1.0, 0.1)


# --- hard min ---------------------------------------------------------------------------------------


def test_hard_min_picks_the_winner_and_breaks_ties_to_the_lowest_index() -> None:
    ds = np.array([[0.5, 0.2, 0.1, 0.3], [0.4, 0.2, 0.1, 0.3], [0.6, 0.1, 0.1, 0.3]])
    gs = np.arange(3 * 4 * 3, dtype=float).reshape(3, 4, 3)
    d, g, index = hard_min(ds, gs)
    assert index.tolist() == [1, 2, 0, 0]
    np.testing.assert_array_equal(d, [0.4, 0.1, 0.1, 0.3])
    np.testing.assert_array_equal(g, gs[index, np.arange(4)])


# --- dtype ------------------------------------------------------------------------------------------


def test_float32_blends_stay_float32_even_with_a_float64_width() -> None:
    dl, gl, dr, gr = (x.astype(np.float32) for x in random_pair(100, 0.1))
    outs = poly_smin(dl, gl, dr, gr, np.float64(0.3))
    assert all(x.dtype == np.float32 for x in outs)
    ds, gs = np.stack([dl, dr]), np.stack([gl, gr])
    outs = lse_smin(ds, gs, np.float64(0.3))
    assert all(x.dtype == np.float32 for x in outs)
    d, g, _ = hard_min(ds, gs)
    assert d.dtype == g.dtype == np.float32


def test_distance_only_path_is_bit_identical_to_the_sampler() -> None:
    """The central-difference taps and the benchmark use the distance-only path; it must be the same
    arithmetic as the sampler's distance, on both primitive forms, both blend kernels and several roots."""
    rng = np.random.default_rng(11)
    for name in ("beetle.json", "moth.json", "reference/hexapod.json"):
        spec = load_spec(EXAMPLES / name)
        assert isinstance(spec, CharacterSpec)
        rig = compile_rig(spec)
        points = rng.uniform(-1.0, 1.5, size=(2000, 3))
        for dtype in (np.float64, np.float32):
            d_field, _ = primitive_field(rig.slots, points, dtype=dtype)
            assert np.array_equal(primitive_distance(rig.slots, points, dtype=dtype), d_field)
            full = sample(rig, points, dtype=dtype)
            assert np.array_equal(sample_distance(rig.graph, rig.slots, points, dtype=dtype), full.distance)
