"""Blend operators on (distance, gradient) pairs: polynomial smooth-min, log-sum-exp, hard min.

Each operator carries the gradient through with its distance, so the body's ``∇d`` is exact without
finite differences. Values keep the dtype they arrive in (a float ``k`` does not promote float32), so
the float32 path mimics the GPU end to end.
"""

from __future__ import annotations

from typing import Any, TypeAlias

import numpy as np
import numpy.typing as npt

FloatArray: TypeAlias = npt.NDArray[np.floating[Any]]
IndexArray: TypeAlias = npt.NDArray[np.intp]
#: A blend width: a Python float or a NumPy scalar of any float dtype (it is converted, never promoting).
Width: TypeAlias = float | np.floating[Any]


def poly_smin(
    dl: FloatArray, gl: FloatArray, dr: FloatArray, gr: FloatArray, k: Width
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Quilez polynomial smooth-min of two children; returns ``(d, g, h)``.

    ``h = clamp(0.5 + 0.5(dL−dR)/k, 0, 1)``, ``d = mix(dL, dR, h) − k·h(1−h)``, ``g = mix(gL, gR, h)``.

    The mixed gradient is the *exact* gradient of ``d``, not an approximation: differentiating,
    ``∂d/∂dL = (1−h) + ((dR−dL)/(2k) − (1−2h)/2)`` and the bracket vanishes because
    ``h − 1/2 = (dL−dR)/(2k)``; likewise ``∂d/∂dR = h``. ``min − k/4 ≤ d ≤ min`` (the correction
    ``k·h(1−h)`` peaks at ``k/4`` when ``h = 1/2``). ``mix`` is written ``x(1−h) + y·h`` so that a
    saturated ``h`` of exactly 0 or 1 returns the child's distance and gradient bit for bit.
    ``k`` must be positive; a zero width is a hard min and belongs to ``hard_min``.
    """
    d, h = poly_smin_distance(dl, dr, k)
    one_minus_h = 1.0 - h
    g = gl * one_minus_h[..., None] + gr * h[..., None]
    return d, g, h


def poly_smin_distance(dl: FloatArray, dr: FloatArray, k: Width) -> tuple[FloatArray, FloatArray]:
    """``poly_smin``'s distance and ``h`` alone (bit-identical to it), for distance-only evaluation."""
    width = _positive_width(k)
    h = np.clip(0.5 + 0.5 * (dl - dr) / width, 0.0, 1.0)
    one_minus_h = 1.0 - h
    d: FloatArray = dl * one_minus_h + dr * h - width * h * one_minus_h
    return d, h


def lse_smin(ds: FloatArray, gs: FloatArray, k: Width) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Order-independent n-ary smooth-min by log-sum-exp; returns ``(d, g, w)``.

    ``d = −k·log Σ exp(−d_i/k)``, evaluated shifted by ``m = min d_i`` so the largest term is exactly 1
    and nothing overflows: ``d = m − k·log Σ exp(−(d_i − m)/k)``. ``w`` are the softmax weights
    ``exp(−(d_i−m)/k) / Σ``, and ``g = Σ w_i g_i`` is the exact gradient (``∂d/∂d_i = w_i``).
    ``ds`` has shape (N, P), ``gs`` (N, P, 3).

    Multiplicity bias: unlike the pairwise polynomial, the kernel does not return the minimum when the
    members agree. Each term is at most 1 and at least one equals 1, so ``1 ≤ Σ ≤ N`` and
    ``min − k·log N ≤ d ≤ min``, with the lower bound reached exactly when all N distances are equal.
    A group of many overlapping members therefore swells by up to ``k·log N``; choose ``k`` for the
    group size, not per pair.

    Tail: the sum is monotone in its members, so dropping members whose terms sum to at most ``B`` from
    a kept sum ``A`` raises ``d`` by at most ``k·log(1 + B/A)``; see ``lse_tail_bound``.
    """
    if ds.ndim != 2 or gs.shape != (*ds.shape, 3):
        raise ValueError(f"lse_smin: expected ds (N, P) and gs (N, P, 3) (got {ds.shape}, {gs.shape})")
    d, w = lse_smin_distance(ds, k)
    g = (w[..., None] * gs).sum(axis=0)
    return d, g, w


def lse_smin_distance(ds: FloatArray, k: Width) -> tuple[FloatArray, FloatArray]:
    """``lse_smin``'s distance and weights alone (bit-identical to it), for distance-only evaluation."""
    width = _positive_width(k)
    m = ds.min(axis=0)
    terms = np.exp(-(ds - m) / width)
    total = terms.sum(axis=0)
    d: FloatArray = m - width * np.log(total)
    w: FloatArray = terms / total
    return d, w


def lse_tail_bound(
    kept_sum: npt.ArrayLike, omitted_bound: npt.ArrayLike, k: Width
) -> npt.NDArray[np.float64]:
    """Largest rise of ``lse_smin``'s distance when members summing to at most ``omitted_bound`` are dropped.

    ``d_kept − d_full = k·log((A + B')/A) ≤ k·log(1 + B/A)`` for omitted terms ``B' ≤ B``. Both sums
    must be expressed against the same reference ``r`` (terms ``exp(−(d_i − r)/k)``); the ratio does
    not depend on which. Conveniently the kept sum is ``A = exp(−(d_kept − r)/k)`` by definition, and
    ``n`` omitted members known to lie at distance ≥ ``d_lo`` give ``B = n·exp(−(d_lo − r)/k)``.
    Computed in float64: this is a certificate, not a field value.
    """
    width = _positive_width(k)
    a = np.asarray(kept_sum, dtype=np.float64)
    b = np.asarray(omitted_bound, dtype=np.float64)
    if np.any(a <= 0.0) or np.any(b < 0.0):
        raise ValueError("lse_tail_bound: kept_sum must be > 0 and omitted_bound >= 0")
    result: npt.NDArray[np.float64] = width * np.log1p(b / a)
    return result


def hard_min(ds: FloatArray, gs: FloatArray) -> tuple[FloatArray, FloatArray, IndexArray]:
    """Minimum over several roots with the winner's gradient; returns ``(d, g, index)``.

    Ties resolve to the lowest index (``argmin``'s first occurrence), so the gradient and any
    per-root attribute chosen through ``index`` are deterministic on the seams between roots.
    """
    if ds.ndim != 2 or gs.shape != (*ds.shape, 3):
        raise ValueError(f"hard_min: expected ds (N, P) and gs (N, P, 3) (got {ds.shape}, {gs.shape})")
    index = np.argmin(ds, axis=0)
    columns = np.arange(ds.shape[1])
    return ds[index, columns], gs[index, columns], index


def _positive_width(k: Width) -> float:
    """``k`` as a Python float, which NumPy treats as weakly typed: it never promotes float32 operands."""
    width = float(k)
    if not width > 0.0:
        raise ValueError(f"k: blend width must be > 0 (got {width})")
    return width
