"""Signed distance and analytic gradient of one primitive slot at many points.

Every slot is a segment ``a → b`` with radii ``ra``, ``rb`` (a sphere is the zero-length case). Two
distance forms exist, and the slot's taper slope chooses between them:

* the **tapered capsule** of the seed (step 5): cheap, one clamp and one square root, and the form the
  TSL emitter uses for nearly cylindrical parts;
* the **exact round cone** (Quilez ``sdRoundCone``: the convex hull of the two end spheres), used
  once the taper is steep enough that the tapered form's errors matter.

The gradient is fused into the same pass rather than taken by finite differences (the seed's ~7×
saving) and is returned *unnormalised*: the snap step divides by ``|∇d|²`` and shading normalises
itself, so throwing the norm away here would hide the tapered form's ``√(1+s²)`` from both.

Everything runs in the requested dtype, constants included, so ``float32`` reproduces the rounding of
the GPU path rather than a float64 result cast down at the end.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property
from typing import Any, NamedTuple, TypeAlias

import numpy as np
import numpy.typing as npt

from ..model import layout

FloatArray: TypeAlias = npt.NDArray[np.floating[Any]]
BoolArray: TypeAlias = npt.NDArray[np.bool_]
IndexArray: TypeAlias = npt.NDArray[np.intp]
#: A vector field as three same-shaped arrays, one per coordinate.
Components: TypeAlias = tuple[FloatArray, FloatArray, FloatArray]
#: The fallback directions (N, 3) of the short radial vectors at (slot rows, points) ``at``.
Fallback: TypeAlias = Callable[[tuple[IndexArray, IndexArray]], FloatArray]

#: Taper slope ``|s| = |rb − ra| / |b − a|`` above which a slot uses the exact round cone.
#:
#: The tapered capsule measures distance perpendicular to the axis and subtracts a linearly varying
#: radius. That is not the Euclidean distance to the hull of the end spheres: its zero set lies inside
#: the true round cone by about ``r·s²/2`` (the side line's offset ``r(1/√(1−s²) − 1)``), its sides
#: meet the caps with a crease, and its side gradient has norm ``√(1+s²)`` rather than 1, so it is
#: only a bound-respecting distance after dividing by that norm. At ``s = 0.05`` the zero-set gap is
#: about ``1.25e-3·r`` and the norm excess ``1.25e-3``, below what the surface gates resolve; steeper
#: tapers pay for the exact form.
TAPER_EXACT_THRESHOLD: float = 0.05

#: Default ``gradient_floor``: radial vectors shorter than this times the slot scale
#: (``|b − a| + max(ra, rb)``) have no usable direction and take the fallback rule below.
GRADIENT_FLOOR: float = 1e-12


def slot_uses_round_cone(slots: FloatArray) -> BoolArray:
    """Which slots take the exact round cone: taper slope strictly above ``TAPER_EXACT_THRESHOLD``.

    Decided in float64 from the compiled table whatever dtype the field is later evaluated in, so the
    CPU reference and the GPU path always agree on the form. Written as ``|rb − ra| > T·L`` so that a
    zero-length slot with unequal radii (an infinite slope) goes to the round cone, whose nested-sphere
    branch handles it, while a true sphere (``ra == rb``) stays on the tapered form.
    """
    table = _check_slots(slots).astype(np.float64)
    length = np.linalg.norm(table[:, layout.B] - table[:, layout.A], axis=1)
    taper = np.abs(table[:, layout.RB] - table[:, layout.RA])
    result: BoolArray = taper > TAPER_EXACT_THRESHOLD * length
    return result


def primitive_field(
    slots: FloatArray,
    points: FloatArray,
    dtype: npt.DTypeLike = np.float64,
    gradient_floor: float = GRADIENT_FLOOR,
) -> tuple[FloatArray, FloatArray]:
    """Distance ``d`` of shape (S, P) and unnormalised gradient ``g`` of shape (S, P, 3) (a view of a
    (3, S, P) array: each coordinate is written as one contiguous block).

    Each slot is evaluated in the form ``slot_uses_round_cone`` picks for it; see the module
    docstring for why the gradient keeps its norm.
    """
    table = _check_slots(slots)
    pts = _check_points(points)
    dt = _float_dtype(dtype)
    round_cone = slot_uses_round_cone(table)
    d = np.empty((table.shape[0], pts.shape[0]), dtype=dt)
    g = np.empty((3, table.shape[0], pts.shape[0]), dtype=dt)
    for mask, form in ((~round_cone, _tapered_field), (round_cone, _round_cone_field)):
        if mask.any():
            rows = _rows(mask)
            d[rows], gradient = form(_Frame(table[rows], pts, dt, gradient_floor))
            for k in range(3):
                g[k, rows] = gradient[k]
    return d, g.transpose(1, 2, 0)


def primitive_distance(
    slots: FloatArray, points: FloatArray, dtype: npt.DTypeLike = np.float64
) -> FloatArray:
    """Distance only, shape (S, P): the same forms and arithmetic as ``primitive_field`` (bit-identical
    distances), without the gradient work. Central-difference verification taps and benchmarks use it."""
    table = _check_slots(slots)
    pts = _check_points(points)
    dt = _float_dtype(dtype)
    round_cone = slot_uses_round_cone(table)
    d = np.empty((table.shape[0], pts.shape[0]), dtype=dt)
    for mask, form in ((~round_cone, _tapered_distance), (round_cone, _round_cone_distance)):
        if mask.any():
            rows = _rows(mask)
            d[rows] = form(_Frame(table[rows], pts, dt, GRADIENT_FLOOR)).d
    return d


def _rows(mask: BoolArray) -> slice | IndexArray:
    """The slots ``mask`` selects: every slot as a slice (views and block copies, no gather)."""
    return slice(None) if mask.all() else np.flatnonzero(mask)


def tapered_capsule_field(
    slots: FloatArray,
    points: FloatArray,
    dtype: npt.DTypeLike = np.float64,
    gradient_floor: float = GRADIENT_FLOOR,
) -> tuple[FloatArray, FloatArray]:
    """The seed's tapered capsule for every slot, whatever its slope.

    ``t = clamp(((p−a)·(b−a))/L², 0, 1)``, ``q = p − a − (b−a)t``, ``d = |q| − lerp(ra, rb, t)``. Where
    the clamp is inactive ``t`` moves with ``p`` and ``∇d = q̂ − s·â`` (the radial direction tilted by
    the taper slope ``s = (rb−ra)/L``); on the caps ``t`` is frozen and ``∇d = q̂``, radial from the
    end point. A sphere is the zero-length case: ``t = 0``, radial from ``a``.
    """
    fr = _Frame(_check_slots(slots), _check_points(points), _float_dtype(dtype), gradient_floor)
    d, g = _tapered_field(fr)
    return d, np.stack(g, axis=-1)


def _tapered_field(fr: _Frame) -> tuple[FloatArray, Components]:
    d, q, q_len = _tapered_distance(fr)
    # Strict inequalities: on the seams t is unchanged by the clamp, so the side formula holds there as
    # a one-sided derivative, and an axis point at t = 0 falls back like the round cone's side does.
    below, above = fr.t_raw < 0.0, fr.t_raw > 1.0

    def fallback(at: tuple[IndexArray, IndexArray]) -> FloatArray:
        axis = fr.axis[at[0], 0]
        result: FloatArray = np.where(
            below[at][:, None], -axis, np.where(above[at][:, None], axis, fr.perpendicular[at[0], 0])
        )
        return result

    q_hat = _unit(q, q_len, fr.floor, fallback)
    interior = ~(below | above)
    slope = np.where(interior, fr.slope, 0.0)
    g = tuple(q_hat[k] - slope * fr.axis[..., k] for k in range(3))
    return d, (g[0], g[1], g[2])


def round_cone_field(
    slots: FloatArray,
    points: FloatArray,
    dtype: npt.DTypeLike = np.float64,
    gradient_floor: float = GRADIENT_FLOOR,
) -> tuple[FloatArray, FloatArray]:
    """The exact round cone (convex hull of the two end spheres) for every slot.

    In the plane of the axis, with ``y`` along ``â`` and ``x`` the radial distance, the side line has
    unit outward normal ``(sn, c)``, ``sn = (ra−rb)/L``, ``c = √(L²−(ra−rb)²)/L``, and touches the
    sphere at ``a`` where ``u = c·y − sn·x`` is 0 and the sphere at ``b`` where ``u = c·L``. So
    ``u < 0`` is sphere ``a``, ``u > c·L`` sphere ``b``, and between them ``d = sn·y + c·x − ra`` with
    unit gradient ``c·q̂ + sn·â`` — the same three regions as Quilez's ``sdRoundCone``, exact inside
    and out. When ``|ra−rb| ≥ L`` one sphere contains the other and the hull is the larger sphere.

    Intermediate quantities are those of the tapered form, so with ``ra == rb`` (``sn = 0``, ``c = 1``
    exactly, since ``√(L·L) = L`` in IEEE arithmetic) both return bit-identical results.
    """
    fr = _Frame(_check_slots(slots), _check_points(points), _float_dtype(dtype), gradient_floor)
    d, g = _round_cone_field(fr)
    return d, np.stack(g, axis=-1)


def _round_cone_field(fr: _Frame) -> tuple[FloatArray, Components]:
    d, q, x, sn, c, pb, pa_len, pb_len, cap_a, cap_b = _round_cone_distance(fr)

    def constant(direction: FloatArray) -> Fallback:
        def fallback(at: tuple[IndexArray, IndexArray]) -> FloatArray:
            result: FloatArray = direction[at[0], 0]
            return result

        return fallback

    g_a = _unit(fr.pa, pa_len, fr.floor, constant(-fr.axis))
    g_b = _unit(pb, pb_len, fr.floor, constant(fr.axis))
    u = _unit(q, x, fr.floor, constant(fr.perpendicular))
    g = tuple(
        np.where(cap_a, g_a[k], np.where(cap_b, g_b[k], c * u[k] + sn * fr.axis[..., k])) for k in range(3)
    )
    return d, (g[0], g[1], g[2])


class _TaperedCore(NamedTuple):
    """The tapered form's distance and the radial vector its gradient reuses."""

    d: FloatArray
    q: Components
    x: FloatArray  # |q|


class _ConeCore(NamedTuple):
    """The round cone's distance, its region masks and what its gradient reuses."""

    d: FloatArray
    q: Components
    x: FloatArray
    sn: FloatArray  # side normal's axial part
    c: FloatArray  # side normal's radial part
    pb: Components  # p − b
    pa_len: FloatArray
    pb_len: FloatArray
    cap_a: BoolArray
    cap_b: BoolArray


def _tapered_distance(fr: _Frame) -> _TaperedCore:
    t = np.clip(fr.t_raw, 0.0, 1.0)
    q = _along(fr.pa, fr.ba, t)
    x = _norm_xyz(q)
    return _TaperedCore(x - (fr.ra + (fr.rb - fr.ra) * t), q, x)


def _round_cone_distance(fr: _Frame) -> _ConeCore:
    dr = fr.ra - fr.rb
    nested = (np.abs(dr) >= fr.length) | fr.degenerate
    with np.errstate(divide="ignore", invalid="ignore"):
        sn = np.where(nested, 0.0, dr / fr.length)
        c = np.where(nested, 1.0, np.sqrt(np.maximum((fr.length - dr) * (fr.length + dr), 0.0)) / fr.length)
    q = _along(fr.pa, fr.ba, fr.t_raw)
    x = _norm_xyz(q)
    cl = c * fr.length
    cap_a = ~nested & (cl * fr.t_raw < sn * x)
    cap_b = ~nested & (cl * (fr.t_raw - 1.0) > sn * x)
    # Nested: the larger end sphere, taking a on a tie of radii.
    cap_a = cap_a | (nested & (fr.ra >= fr.rb))
    cap_b = cap_b | (nested & (fr.ra < fr.rb))
    pb = (fr.pa[0] - fr.ba[..., 0], fr.pa[1] - fr.ba[..., 1], fr.pa[2] - fr.ba[..., 2])
    pa_len, pb_len = _norm_xyz(fr.pa), _norm_xyz(pb)
    side_d = sn * (fr.t_raw * fr.length) + c * x - fr.ra
    d = np.where(cap_a, pa_len - fr.ra, np.where(cap_b, pb_len - fr.rb, side_d))
    return _ConeCore(d, q, x, sn, c, pb, pa_len, pb_len, cap_a, cap_b)


class _Frame:
    """Per-slot geometry (shape (S, 1, …)) and per-point projections (shape (S, P), one array per
    coordinate: contiguous rows run several times faster than (S, P, 3) strides), in one dtype.

    Degenerate directions follow one deterministic rule, so the output is finite everywhere and the
    same on every run:

    * a segment no longer than the floor is a sphere: ``t = 0`` and its axis is taken as ``+z``;
    * a radial vector no longer than the floor is replaced on the cap at ``a`` by ``−â`` and on the cap
      at ``b`` by ``+â`` (the limits approached along the axis from outside), and elsewhere by the
      *perpendicular* of the axis: the coordinate vector ``e_i`` with the smallest ``|â_i|`` (lowest
      ``i`` on ties) with its ``â`` component removed, normalised. It depends on the slot only, never
      on the point, and is never short (``|â_i|² ≤ 1/3``). A sphere's centre therefore falls back
      to ``+x``.
    """

    def __init__(self, slots: FloatArray, points: FloatArray, dtype: np.dtype[Any], floor: float) -> None:
        table = slots.astype(dtype)
        pts = points.astype(dtype)
        a = table[:, None, layout.A]
        self.ba = table[:, None, layout.B] - a
        self.ra = table[:, None, layout.RA]
        self.rb = table[:, None, layout.RB]
        self.length = _norm(self.ba)
        scale = self.length + np.maximum(self.ra, self.rb)
        self.floor = np.maximum(floor * scale, np.finfo(dtype).tiny)
        self.degenerate = self.length <= self.floor
        pa = tuple(pts[None, :, k] - a[..., k] for k in range(3))
        self.pa: Components = (pa[0], pa[1], pa[2])
        length_sq = np.where(self.degenerate, 1.0, _dot(self.ba, self.ba))
        self.t_raw = np.where(self.degenerate, 0.0, _dot_xyz(self.pa, self.ba) / length_sq)

    # Only the gradient needs these; the distance-only path never computes them.
    @cached_property
    def _safe_length(self) -> FloatArray:
        result: FloatArray = np.where(self.degenerate, 1.0, self.length)
        return result

    @cached_property
    def axis(self) -> FloatArray:
        z_axis = np.zeros_like(self.ba)
        z_axis[..., 2] = 1.0
        result: FloatArray = np.where(
            self.degenerate[..., None], z_axis, self.ba / self._safe_length[..., None]
        )
        return result

    @cached_property
    def slope(self) -> FloatArray:
        result: FloatArray = np.where(self.degenerate, 0.0, (self.rb - self.ra) / self._safe_length)
        return result

    @cached_property
    def perpendicular(self) -> FloatArray:
        return _perpendicular(self.axis)


def _perpendicular(axis: FloatArray) -> FloatArray:
    """The documented fallback direction perpendicular to each unit axis (see ``_Frame``)."""
    basis = np.eye(3, dtype=axis.dtype)[np.argmin(np.abs(axis), axis=-1)]
    v = basis - _dot(basis, axis)[..., None] * axis
    result: FloatArray = v / _norm(v)[..., None]
    return result


def _unit(v: Components, length: FloatArray, floor: FloatArray, fallback: Fallback) -> Components:
    """``v / length`` per coordinate; where ``length <= floor`` (rare) the fallback direction instead."""
    short = length <= floor
    safe = np.where(short, 1.0, length)
    unit = [v[k] / safe for k in range(3)]
    if short.any():
        rows, points = np.nonzero(short)
        at = (rows, points)
        direction = fallback(at)
        for k in range(3):
            unit[k][at] = direction[:, k]
    return unit[0], unit[1], unit[2]


def _along(pa: Components, ba: FloatArray, t: FloatArray) -> Components:
    """``pa − ba·t`` per coordinate (the radial vector from the axis point at ``t``)."""
    return pa[0] - ba[..., 0] * t, pa[1] - ba[..., 1] * t, pa[2] - ba[..., 2] * t


def _dot_xyz(u: Components, v: FloatArray) -> FloatArray:
    """``_dot`` of per-coordinate arrays with a (…, 3) vector: the same products, summed in the same order."""
    result: FloatArray = u[0] * v[..., 0] + u[1] * v[..., 1] + u[2] * v[..., 2]
    return result


def _norm_xyz(v: Components) -> FloatArray:
    """``_norm`` of per-coordinate arrays."""
    result: FloatArray = np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return result


def _dot(u: FloatArray, v: FloatArray) -> FloatArray:
    """Three explicit products, summed left to right as a shader would, in the operands' dtype."""
    result: FloatArray = u[..., 0] * v[..., 0] + u[..., 1] * v[..., 1] + u[..., 2] * v[..., 2]
    return result


def _norm(v: FloatArray) -> FloatArray:
    result: FloatArray = np.sqrt(_dot(v, v))
    return result


def _float_dtype(dtype: npt.DTypeLike) -> np.dtype[Any]:
    dt = np.dtype(dtype)
    if dt.kind != "f":
        raise ValueError(f"dtype: must be a floating type (got {dt})")
    return dt


def _check_slots(slots: FloatArray) -> FloatArray:
    table = np.asarray(slots)
    if table.ndim != 2 or table.shape[1] != layout.WIDTH:
        raise ValueError(f"slots: expected shape (S, {layout.WIDTH}) (got {table.shape})")
    return table


def _check_points(points: FloatArray) -> FloatArray:
    pts = np.asarray(points)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points: expected shape (P, 3) (got {pts.shape})")
    return pts
