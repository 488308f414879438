"""Proximity colour: every leaf tints the surface by how close it is to being the nearest one.

w_i = exp(−max(d_i − d_min, 0) / max(k_i, kFloor)), colour = Σ w_i c_i / Σ w_i, with k_i the leaf's
effective blend width. The nearest leaf has w = 1, so Σw ≥ 1 and the division is always safe. Geometric
saturation does not bound these weights (a leaf omitted from the distance can still tint), which is why
candidate programs carry a separate colour-weight bound.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.floating]


def proximity_weights(d_slots: Array, k_slots: Array, k_floor: float) -> Array:
    """Unnormalised weights, shape (S, P)."""
    d_min = d_slots.min(axis=0)
    width = np.maximum(k_slots, k_floor).astype(d_slots.dtype)[:, None]
    weights: Array = np.exp(-np.maximum(d_slots - d_min, 0) / width)
    return weights


def proximity_colour(d_slots: Array, k_slots: Array, rgb_slots: Array, k_floor: float) -> Array:
    """Linear RGB per point, shape (P, 3)."""
    w = proximity_weights(d_slots, k_slots, k_floor)
    rgb = rgb_slots.astype(d_slots.dtype)
    colour: Array = (w.T @ rgb) / w.sum(axis=0)[:, None]
    return colour
