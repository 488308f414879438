"""Primitive distances and their fused analytic gradients (field step 5 of the seed).

The gradient checks sweep the central-difference step over eight decades instead of trusting one
step: truncation error shrinks with the step and rounding error grows as it shrinks, so a correct
analytic gradient shows a V whose floor sits near machine precision, and a wrong one shows a floor at
the size of the mistake. ``central_difference_sweep`` is the reusable instrument.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest

from creaturegen.field.primitives import (
    TAPER_EXACT_THRESHOLD,
    primitive_field,
    round_cone_field,
    slot_uses_round_cone,
    tapered_capsule_field,
)
from creaturegen.model import layout

Array = npt.NDArray[Any]

#: Steps of the sweep, as fractions of the slot length scale.
EPSILON_DECADES = 10.0 ** -np.arange(1, 10)


def central_difference_sweep(
    field: Callable[[Array], Array],
    points: Array,
    gradient: Array,
    epsilons: Array,
    dtype: npt.DTypeLike = np.float64,
) -> Array:
    """Worst-component error |central difference − analytic| per step and point, shape (E, P).

    ``field`` maps points (P, 3) of ``dtype`` to distances (P,) of ``dtype``. The offsets, the
    differences and the division all happen in ``dtype``, and the divisor is the step the perturbed
    coordinates actually represent (``(p+e) − (p−e)`` in ``dtype``), so a float32 sweep measures the
    float32 field rather than the rounding of the step. A step lost entirely to rounding counts as an
    infinite error. Errors are returned in float64.
    """
    dt = np.dtype(dtype)
    pts = np.asarray(points, dtype=dt)
    analytic = np.asarray(gradient, dtype=np.float64)
    errors = np.empty((len(epsilons), pts.shape[0]))
    for row, eps in enumerate(epsilons):
        worst = np.zeros(pts.shape[0])
        for axis in range(3):
            offset = np.zeros(3, dtype=dt)
            offset[axis] = dt.type(eps)
            plus, minus = pts + offset, pts - offset
            step = plus[:, axis] - minus[:, axis]
            rise = field(plus) - field(minus)
            assert rise.dtype == dt
            with np.errstate(divide="ignore", invalid="ignore"):
                fd = np.where(step > 0, rise / np.where(step > 0, step, 1), np.inf)
            err = np.abs(fd.astype(np.float64) - analytic[:, axis])
            worst = np.maximum(worst, np.where(np.isfinite(err), err, np.inf))
        errors[row] = worst
    return errors


def make_slots(*rows: tuple[Array | list[float], float, Array | list[float], float]) -> Array:
    """A slot table from ``(a, ra, b, rb)`` rows; k and colour do not enter the distance."""
    table = np.zeros((len(rows), layout.WIDTH))
    for i, (a, ra, b, rb) in enumerate(rows):
        table[i, layout.A], table[i, layout.RA] = a, ra
        table[i, layout.B], table[i, layout.RB] = b, rb
        table[i, layout.K] = 0.1
    return table


def slot_frame(a: Array, b: Array) -> tuple[Array, Array, Array]:
    """Unit axis and two unit perpendiculars of a segment, for placing points in its own coordinates."""
    axis = (b - a) / np.linalg.norm(b - a)
    e1 = np.cross(axis, [0.3, 0.5, 0.8])
    e1 /= np.linalg.norm(e1)
    return axis, e1, np.cross(axis, e1)


def points_in_frame(a: Array, b: Array, y: Array, rho: Array, phi: Array) -> Array:
    """Points at axial coordinate ``y`` (from ``a``), radial distance ``rho`` and azimuth ``phi``."""
    axis, e1, e2 = slot_frame(a, b)
    radial = np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2
    out: Array = a + y[:, None] * axis + rho[:, None] * radial
    return out


A0 = np.array([0.1, -0.2, 0.3])
B0 = A0 + np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])  # unit length
TAPERED = make_slots((A0, 0.40, B0, 0.37))  # s = −0.03: tapered form
CONE = make_slots((A0, 0.45, B0, 0.15))  # s = −0.30: exact round cone
CONE_SN, CONE_C = 0.30, np.sqrt(1.0 - 0.30**2)


def sample_class(name: str, n: int = 24) -> tuple[Array, Array]:
    """(slots, points) for one sample class, kept 0.2·L from t-clamp seams, region seams and the axis."""
    rng = np.random.default_rng(sum(map(ord, name)))
    phi = rng.uniform(0.0, 2 * np.pi, n)
    rho = rng.uniform(0.25, 0.9, n)
    if name == "interior":
        return TAPERED, points_in_frame(A0, B0, rng.uniform(0.2, 0.8, n), rho, phi)
    if name == "cap":
        y = np.where(rng.random(n) < 0.5, rng.uniform(-0.7, -0.2, n), rng.uniform(1.2, 1.7, n))
        return TAPERED, points_in_frame(A0, B0, y, rho, phi)
    # Round cone: draw many and keep those whose region coordinate u = c·y − sn·x is clear of 0 and c·L.
    y, rho = rng.uniform(-0.8, 1.8, 40 * n), rng.uniform(0.25, 0.9, 40 * n)
    u = CONE_C * y - CONE_SN * rho
    keep = (u > 0.2) & (u < CONE_C - 0.2) if name == "round_cone_side" else (u < -0.2) | (u > CONE_C + 0.2)
    y, rho = y[keep][:n], rho[keep][:n]
    assert y.size == n
    return CONE, points_in_frame(A0, B0, y, rho, rng.uniform(0.0, 2 * np.pi, n))


SAMPLE_CLASSES = ("interior", "cap", "round_cone_side", "round_cone_cap")


def sweep(name: str, dtype: npt.DTypeLike) -> Array:
    slots, pts = sample_class(name)
    pts = pts.astype(dtype)
    _, g = primitive_field(slots, pts, dtype)
    return central_difference_sweep(
        lambda p: primitive_field(slots, p, dtype)[0][0], pts, g[0], EPSILON_DECADES, dtype
    )


# --- form selection ---------------------------------------------------------------------------------


def test_threshold_selects_the_form_by_taper_slope() -> None:
    slots = make_slots(
        ([0, 0, 0], 0.0, [1, 0, 0], TAPER_EXACT_THRESHOLD),  # exactly at the threshold: tapered
        ([0, 0, 0], 0.3, [2, 0, 0], 0.3 + 2 * 0.049),
        ([0, 0, 0], 0.3, [2, 0, 0], 0.3 + 2 * 0.051),
        ([0, 0, 0], 0.3, [0, 0, 1], 0.3 - 0.051),
        ([1, 1, 1], 0.2, [1, 1, 1], 0.2),  # sphere
        ([1, 1, 1], 0.2, [1, 1, 1], 0.3),  # zero length, unequal radii: infinite slope
    )
    assert slot_uses_round_cone(slots).tolist() == [False, False, True, True, False, True]


def test_primitive_field_dispatches_each_slot_to_its_form() -> None:
    slots = np.vstack([TAPERED, CONE])
    pts = np.random.default_rng(1).normal(size=(50, 3))
    d, g = primitive_field(slots, pts)
    d_tap, g_tap = tapered_capsule_field(TAPERED, pts)
    d_cone, g_cone = round_cone_field(CONE, pts)
    np.testing.assert_array_equal(d, np.vstack([d_tap, d_cone]))
    np.testing.assert_array_equal(g, np.concatenate([g_tap, g_cone]))


# --- gradient norms ---------------------------------------------------------------------------------


@pytest.mark.parametrize("slope", [0.0, 0.02, -0.02, 0.0499, -0.0499])
def test_tapered_interior_gradient_norm_is_sqrt_one_plus_s2(slope: float) -> None:
    length = 1.7
    slots = make_slots((A0, 0.4, A0 + length * (B0 - A0), 0.4 + slope * length))
    assert not slot_uses_round_cone(slots)[0]
    rng = np.random.default_rng(2)
    n = 200
    pts = points_in_frame(
        A0, B0, rng.uniform(0.05, 0.95, n) * length, rng.uniform(0.01, 2.0, n), rng.uniform(0, 7, n)
    )
    _, g = primitive_field(slots, pts)
    real_slope = (slots[0, layout.RB] - slots[0, layout.RA]) / length
    np.testing.assert_allclose(np.linalg.norm(g[0], axis=1), np.sqrt(1 + real_slope**2), rtol=0, atol=1e-12)


def test_cap_and_round_cone_gradient_norms_are_one() -> None:
    for name in SAMPLE_CLASSES[1:]:
        slots, pts = sample_class(name, 200)
        _, g = primitive_field(slots, pts)
        np.testing.assert_allclose(np.linalg.norm(g[0], axis=1), 1.0, rtol=0, atol=1e-12, err_msg=name)
    # Every point of several round cones, including the nested one and reversed tapers.
    cones = make_slots(
        ([0, 0, 0], 0.5, [1, 0.2, 0], 0.1),
        ([0, 0, 0], 0.1, [0, 1, 1], 0.6),
        ([0, 0, 0], 0.8, [0.3, 0, 0], 0.2),  # nested: the larger sphere
    )
    pts = np.random.default_rng(3).normal(size=(500, 3))
    _, g = primitive_field(cones, pts)
    np.testing.assert_allclose(np.linalg.norm(g, axis=2), 1.0, rtol=0, atol=1e-12)


# --- gradient against central differences ----------------------------------------------------------


@pytest.mark.parametrize("name", SAMPLE_CLASSES)
def test_gradient_sweep_f64_has_a_floor_at_machine_precision(name: str) -> None:
    errors = sweep(name, np.float64)
    floor = errors.min(axis=0)
    assert floor.max() <= 1e-8
    # A V, not a monotone curve: both ends of the sweep sit well above the floor, so the floor is the
    # plateau between truncation (large steps) and rounding (small steps), not an artefact of either.
    assert np.all(errors[0] > 100 * floor)
    assert np.all(errors[-1] > 100 * floor)


@pytest.mark.parametrize("name", SAMPLE_CLASSES)
def test_gradient_sweep_f32_floor_is_higher_and_at_larger_steps(name: str) -> None:
    err32, err64 = sweep(name, np.float32), sweep(name, np.float64)
    assert err32.min(axis=0).max() <= 1e-3
    # Rounding grows 2^29 times faster in float32, so its best step is larger than float64's.
    assert np.all(np.argmin(err32, axis=0) < np.argmin(err64, axis=0))


def test_sweep_detects_a_wrong_gradient() -> None:
    """The instrument can fail: a gradient off by 1e-5 shows a floor at 1e-5, not at 1e-10."""
    slots, pts = sample_class("interior")
    _, g = primitive_field(slots, pts)
    errors = central_difference_sweep(
        lambda p: primitive_field(slots, p)[0][0], pts, g[0] * (1 + 1e-5), EPSILON_DECADES
    )
    assert errors.min(axis=0).min() > 1e-6


# --- exact cases ------------------------------------------------------------------------------------


def test_sphere_is_a_zero_length_capsule() -> None:
    centre, r = np.array([0.3, -1.2, 2.0]), 0.7
    slots = make_slots((centre, r, centre, r))
    pts = np.random.default_rng(4).normal(size=(300, 3)) * 2 + centre
    d, g = primitive_field(slots, pts)
    offset = pts - centre
    dist = np.linalg.norm(offset, axis=1)
    np.testing.assert_allclose(d[0], dist - r, rtol=0, atol=1e-15)
    np.testing.assert_allclose(g[0], offset / dist[:, None], rtol=0, atol=1e-15)


def test_forms_are_bit_identical_when_radii_are_equal() -> None:
    rng = np.random.default_rng(5)
    a = rng.normal(size=(6, 3))
    b = a + rng.normal(size=(6, 3))
    r = rng.uniform(0.1, 0.6, 6)
    slots = make_slots(*((a[i], r[i], b[i], r[i]) for i in range(6)))
    pts = rng.normal(size=(400, 3)) * 1.5
    pts[:6] = a  # exactly on the end points and the axis, where the fallbacks act
    pts[6:12] = 0.5 * (a + b)
    for dtype in (np.float64, np.float32):
        d_tap, g_tap = tapered_capsule_field(slots, pts, dtype)
        d_cone, g_cone = round_cone_field(slots, pts, dtype)
        np.testing.assert_array_equal(d_tap, d_cone)
        np.testing.assert_array_equal(g_tap, g_cone)


def test_nested_round_cone_is_the_larger_sphere() -> None:
    slots = make_slots(([0, 0, 0], 0.3, [0.1, 0.2, 0], 0.9))
    pts = np.random.default_rng(6).normal(size=(100, 3))
    d, _ = primitive_field(slots, pts)
    np.testing.assert_allclose(d[0], np.linalg.norm(pts - [0.1, 0.2, 0], axis=1) - 0.9, atol=1e-15)


def round_cone_surface(a: Array, ra: float, b: Array, rb: float, spacing: float) -> Array:
    """Dense points on the boundary of the convex hull of two spheres, built without the SDF.

    Caps through the support map (boundary point of outward normal n is the centre + r·n of whichever
    sphere has the larger support a·n + r), sides as the straight segments between the two tangent
    circles, which the support map cannot reach (every side point of one azimuth shares a normal).
    """
    length = float(np.linalg.norm(b - a))
    sn = (ra - rb) / length
    axis, e1, e2 = slot_frame(a, b)
    n_dir = int(4 * np.pi * max(ra, rb) ** 2 / spacing**2) * 2
    i = np.arange(n_dir) + 0.5
    z = 1 - 2 * i / n_dir
    theta = np.pi * (1 + 5**0.5) * i
    normals = np.stack([np.sqrt(1 - z**2) * np.cos(theta), np.sqrt(1 - z**2) * np.sin(theta), z], axis=1)
    on_a = normals @ a + ra >= normals @ b + rb
    caps = np.where(on_a[:, None], a + ra * normals, b + rb * normals)
    n_phi = int(2 * np.pi * max(ra, rb) / spacing) + 1
    n_lam = int(length / spacing) + 1
    phi, lam = np.meshgrid(np.linspace(0, 2 * np.pi, n_phi), np.linspace(0, 1, n_lam))
    side_normal = sn * axis + np.sqrt(1 - sn**2) * (
        np.cos(phi.ravel())[:, None] * e1 + np.sin(phi.ravel())[:, None] * e2
    )
    lam = lam.ravel()[:, None]
    sides = (1 - lam) * (a + ra * side_normal) + lam * (b + rb * side_normal)
    return np.vstack([caps, sides])


def brute_distance(points: Array, surface: Array) -> Array:
    """Distance from each point to the nearest surface sample (never less than the true distance)."""
    squared = (points**2).sum(axis=1)[:, None] - 2 * points @ surface.T + (surface**2).sum(axis=1)[None]
    out: Array = np.sqrt(np.maximum(squared.min(axis=1), 0.0))
    return out


def test_round_cone_is_a_true_sdf() -> None:
    ra, rb = 0.45, 0.15
    surface = round_cone_surface(A0, ra, B0, rb, spacing=0.006)
    rng = np.random.default_rng(7)
    n = 600
    pts = points_in_frame(A0, B0, rng.uniform(-0.7, 1.4, n), rng.uniform(0, 0.9, n), rng.uniform(0, 7, n))
    d, _ = primitive_field(CONE, pts)
    keep = np.abs(d[0]) > 0.03  # sampling error of the surface is ~spacing²/(2|d|) away from it
    pts, d = pts[keep][:150], d[0][keep][:150]
    assert (d < 0).sum() >= 30  # both sides are checked
    excess = brute_distance(pts, surface) - np.abs(d)
    assert excess.min() >= -1e-9  # |d| is never more than the distance to an actual surface point
    assert excess.max() <= 1e-3
    # The tapered form fails the same check on this steep cone (s = 0.3): the test can fail.
    d_tap = tapered_capsule_field(CONE, pts)[0][0]
    assert np.abs(brute_distance(pts, surface) - np.abs(d_tap)).max() > 1e-2
    # Sign from the hull itself: outside iff some direction separates the point from both spheres.
    normals = rng.normal(size=(20000, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    support = np.maximum(normals @ A0 + ra, normals @ B0 + rb)
    outside = ((pts @ normals.T) - support > 0).any(axis=1)
    np.testing.assert_array_equal(outside, d > 0)


def tapered_zero_set_gap(ra: float, rb: float, n: int = 4000) -> float:
    """Largest exact round-cone distance of points on the tapered form's zero set (same slot)."""
    slots = make_slots((A0, ra, B0, rb))
    rng = np.random.default_rng(8)
    y = rng.uniform(-ra, 1 + rb, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    lo, hi = np.zeros(n), np.full(n, 2.0)  # bisection on the radial distance
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        inside = tapered_capsule_field(slots, points_in_frame(A0, B0, y, mid, phi))[0][0] < 0
        lo, hi = np.where(inside, mid, lo), np.where(inside, hi, mid)
    on_zero_set = points_in_frame(A0, B0, y, 0.5 * (lo + hi), phi)
    d_cone = round_cone_field(slots, on_zero_set)[0][0]
    return float(np.abs(d_cone).max())


def test_tapered_zero_set_departs_from_round_cone_by_r_s_squared() -> None:
    ra, s = 0.4, TAPER_EXACT_THRESHOLD
    gap = tapered_zero_set_gap(ra, ra - s)
    bound = ra * (1 - np.sqrt(1 - s**2))  # ≈ r·s²/2, the side-line offset at the wide end
    assert 0.9 * bound <= gap <= bound * (1 + 1e-9)


# --- degenerate directions and dtype ----------------------------------------------------------------


def test_degenerate_directions_follow_the_documented_rule() -> None:
    slots = make_slots(
        ([0, 0, 0], 0.3, [2, 0, 0], 0.3),  # axis +x: perpendicular is +y
        ([0, 0, 0], 0.3, [0, 0, 2], 0.25),  # axis +z, s = −0.025: perpendicular is +x
        ([0, 0, 0], 0.5, [0, 0, 2], 0.1),  # round cone along +z
        ([1, 1, 1], 0.3, [1, 1, 1], 0.3),  # sphere: its centre falls back to +x
    )
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 1], [1, 1, 1]], dtype=float)
    for dtype in (np.float64, np.float32):
        d, g = primitive_field(slots, pts, dtype)
        assert np.all(np.isfinite(d))
        assert np.all(np.isfinite(g))
        np.testing.assert_array_equal(g[0, 0], [0, 1, 0])
        np.testing.assert_array_equal(g[0, 1], [0, 1, 0])
        np.testing.assert_allclose(g[1, 2], [1, 0, 0.025], atol=1e-7)
        np.testing.assert_array_equal(g[3, 3], [1, 0, 0])
        np.testing.assert_allclose(np.linalg.norm(g[2, 2]), 1.0, atol=1e-6)
    # Within the floor of an end point but on its cap side: the outward axis direction.
    behind_a, beyond_b = [[-1e-14, 0, 0], [2 + 1e-14, 0, 0]], [[0, 0, -1e-14], [0, 0, 2 + 1e-14]]
    _, g = primitive_field(slots, np.array(behind_a + beyond_b))
    np.testing.assert_array_equal(g[0, :2], [[-1, 0, 0], [1, 0, 0]])
    np.testing.assert_array_equal(g[2, 2:], [[0, 0, -1], [0, 0, 1]])


def test_float32_path_computes_in_float32() -> None:
    slots = np.vstack([TAPERED, CONE, make_slots(([0, 0, 0], 0.2, [0, 0, 0], 0.2))])
    pts = np.random.default_rng(9).normal(size=(2000, 3))
    d32, g32 = primitive_field(slots, pts, np.float32)
    d64, g64 = primitive_field(slots, pts, np.float64)
    for form in (tapered_capsule_field, round_cone_field):
        assert all(out.dtype == np.float32 for out in form(slots, pts, np.float32))
    assert d32.dtype == g32.dtype == np.float32
    # Close to the reference, but not the reference rounded once at the end: float32 arithmetic
    # rounds at every step, so many values differ from the cast-down float64 result.
    np.testing.assert_allclose(d32, d64, atol=2e-6)
    assert (d32 != d64.astype(np.float32)).mean() > 0.1
    assert (g32 != g64.astype(np.float32)).mean() > 0.1


def test_bad_inputs_are_rejected() -> None:
    with pytest.raises(ValueError, match="slots"):
        primitive_field(np.zeros((2, 8)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="points"):
        primitive_field(TAPERED, np.zeros((3,)))
    with pytest.raises(ValueError, match="dtype"):
        primitive_field(TAPERED, np.zeros((1, 3)), np.int32)
