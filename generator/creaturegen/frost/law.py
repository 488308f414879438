"""The history update law: decay and saturating deposit integrated together, in closed form.

For channel state x under brush coverage b held constant for dt seconds:
a = λ + r·b, xEq = r·b/a, x' = xEq + (x − xEq)·e^(−a·dt). Because the solution of a linear ODE with
constant input composes exactly (two steps of dt/2 equal one step of dt), the same pointer path gives the
same history at any frame rate; a per-frame decay constant would not. a = 0 (no decay, no deposit) is the
identity, handled explicitly rather than through 0/0.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]


def advance(x: Array, coverage: Array | float, dt: float, decay: float, fill: float) -> Array:
    """State after dt seconds of constant coverage (the zero-rate limit a = 0 keeps x)."""
    b = np.broadcast_to(np.asarray(coverage, dtype=np.float64), x.shape)
    a = decay + fill * b
    moving = a > 0.0
    safe_a = np.where(moving, a, 1.0)
    equilibrium = np.where(moving, fill * b / safe_a, x)
    return np.where(moving, equilibrium + (x - equilibrium) * np.exp(-safe_a * dt), x)
