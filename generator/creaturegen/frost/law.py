"""The history update law: decay and saturating deposit integrated together, in closed form.

For channel state x under brush coverage b held constant for dt seconds:
a = λ + r·b, xEq = r·b/a, x' = xEq + (x − xEq)·e^(−a·dt). Because the solution of a linear ODE with
constant input composes exactly (two steps of dt/2 equal one step of dt), the same pointer path gives the
same history at any frame rate; a per-frame decay constant would not. a = 0 (no decay, no deposit) is the
identity, handled explicitly rather than through 0/0.

A segment that arrives after the render instant ``previous`` that its span [t0, t1] overlaps (a pointer
sample is known only when the next one arrives) was integrated as pure decay over [t0, min(t1, previous)].
Decay is invertible, so the missed deposit is applied exactly later by :func:`catch_up`: with τ the missed
span and s = previous − min(t1, previous) the decay that followed it, the deposited state is
y' = e^(−r·b·τ)·y + e^(−λ·s)·xEq·(1 − e^(−a·τ)), where y is the decay-only state at ``previous``.
Exact for the law (diffusion, when enabled, is split per frame and does not commute with it).
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


def catch_up(x: Array, coverage: Array | float, tau: float, age: float, decay: float, fill: float) -> Array:
    """Turn a state that only decayed over a missed span τ (then ``age`` more seconds) into the state that
    deposited under ``coverage`` over τ and then decayed for ``age``: exact, since decay is invertible."""
    b = np.broadcast_to(np.asarray(coverage, dtype=np.float64), x.shape)
    rb = fill * b
    a = decay + rb
    safe_a = np.where(a > 0.0, a, 1.0)
    gained = np.where(a > 0.0, rb / safe_a * (1.0 - np.exp(-safe_a * tau)), 0.0)
    return np.asarray(np.exp(-rb * tau) * x + np.exp(-decay * age) * gained)


#: Thaw level at which a texel counts as frosted over again (5 % of full thaw left).
REGROWTH_LEVEL = 0.05


def regrowth_seconds(decay: float) -> float:
    """The declared regrowth time: seconds for a fully thawed texel (x = 1) to fall to REGROWTH_LEVEL
    without input, ln(1/level)/λ, from the spec's survivalPerSecond (λ = −ln survival)."""
    return float(np.log(1.0 / REGROWTH_LEVEL) / decay) if decay > 0.0 else float("inf")
