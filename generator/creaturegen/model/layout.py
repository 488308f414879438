"""Column layout of the compiled slot table.

One row per primitive slot, float64, shape ``(S, WIDTH)``: ``a.xyz | ra | b.xyz | rb | k | rgb``. The
order mirrors the runtime pose buffer of the seed (``a.xyz|ra, b.xyz|rb, k|rgb``) so the table can be
uploaded as-is; every reader indexes through these names rather than through literals, so a layout
change is one edit here.
"""

from __future__ import annotations

from typing import Final

#: First end point of the segment (the centre of a sphere).
A: Final = slice(0, 3)
#: Radius at ``a``.
RA: Final = 3
#: Second end point; equal to ``a`` for a sphere.
B: Final = slice(4, 7)
#: Radius at ``b``; equal to ``ra`` for a sphere.
RB: Final = 7
#: The leaf's effective blend width.
K: Final = 8
#: Linear (already sRGB-decoded) colour.
RGB: Final = slice(9, 12)
#: Number of columns.
WIDTH: Final = 12
