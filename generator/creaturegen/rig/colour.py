"""Authored colours are sRGB hex; the field, the GPU and every buffer hold linear values.

Decoding happens here and only here (the seed's failure list names both washed-out and doubly-darkened
creatures), so a slot table never holds sRGB.
"""

from __future__ import annotations

#: Albedo of a part that declares no colour: a neutral mid grey, so unset parts read as unset.
DEFAULT_COLOR = "#9a9a9a"


def srgb_channel_to_linear(c: float) -> float:
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def hex_to_linear(color: str) -> tuple[float, float, float]:
    """``#rrggbb`` (validated by the spec gate) to linear RGB in [0, 1]."""
    r, g, b = (int(color[i : i + 2], 16) / 255.0 for i in (1, 3, 5))
    return srgb_channel_to_linear(r), srgb_channel_to_linear(g), srgb_channel_to_linear(b)
