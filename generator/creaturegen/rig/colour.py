"""Authored colours are sRGB hex; the field, the GPU and every buffer hold linear values.

Decoding happens here and only here (the seed's failure list names both washed-out and doubly-darkened
creatures), so a slot table never holds sRGB.
"""

from __future__ import annotations

import numpy as np

#: Albedo of a part that declares no colour: a neutral mid grey, so unset parts read as unset.
DEFAULT_COLOR = "#9a9a9a"


def srgb_channel_to_linear(c: float) -> float:
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def hex_to_linear(color: str) -> tuple[float, float, float]:
    """``#rrggbb`` (validated by the spec gate) to linear RGB in [0, 1]."""
    r, g, b = (int(color[i : i + 2], 16) / 255.0 for i in (1, 3, 5))
    return srgb_channel_to_linear(r), srgb_channel_to_linear(g), srgb_channel_to_linear(b)


def linear_to_oklab(rgb: np.ndarray) -> np.ndarray:
    """Linear sRGB (..., 3) to OKLab (..., 3) (Ottosson 2020): the perceptual space of colour gates."""
    lms = rgb @ np.array(
        [
            [0.4122214708, 0.2119034982, 0.0883024619],
            [0.5363325363, 0.6806995451, 0.2817188376],
            [0.0514459929, 0.1073969566, 0.6299787005],
        ]
    )
    lms_ = np.cbrt(lms)
    lab: np.ndarray = lms_ @ np.array(
        [
            [0.2104542553, 1.9779984951, 0.0259040371],
            [0.7936177850, -2.4285922050, 0.7827717662],
            [-0.0040720468, 0.4505937099, -0.8086757660],
        ]
    )
    return lab
