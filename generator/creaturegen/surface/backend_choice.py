"""Which sampling backend samples the lattice: the one asked for, or the faster measured on this machine.

numpy is always there; wgpu (Mesa lavapipe or a real GPU) is faster per point on big lattices but pays a
start-up of seconds, so "auto" times both on the same points, or does not start wgpu at all when numpy
would finish first.
"""

from __future__ import annotations

import math

import numpy as np

from ..candidates import DEFAULT_TIER
from ..model import layout as col
from ..rig import CompiledRig
from .backends import (
    BACKENDS,
    BackendChoiceError,
    BackendUnavailableError,
    FieldBackend,
    NumpyBackend,
    make_backend,
    time_backend,
)
from .grid import GridTooFineError, make_grid
from .progress import Progress

#: Calibration points for picking the faster sampling backend.
CALIBRATION_POINTS = 32768
#: wgpu's start-up before its first sample (adapter, device, wgpu-native's cffi type parsing, the first
#: pipeline): 3.1 s to 4.2 s measured in a cProfile'd build on the 2-core machine under load, so 2 s is
#: a floor. Against numpy's 0.3 µs per point that is several million samples.
WGPU_STARTUP_S = 2.0
#: Nodes a build may sample per node of its first lattice: the narrow band holds 15-35 % of a dense
#: lattice (the sampling report's "% of a dense pass"), and the refinement budget allows two √2 finer
#: lattices (2^1.5 and 2^3 times the nodes): 0.35 · (1 + 2.83 + 8) ≈ 4.1.
SAMPLED_NODES_PER_FIRST_NODE = 4.1


def choose_backend(
    rig: CompiledRig, requested: str, progress: Progress, tier: str = DEFAULT_TIER
) -> tuple[FieldBackend, str]:
    """The requested backend, or for "auto" the faster of numpy and wgpu measured on this machine.

    Faster for the whole build, start-up included: wgpu pays WGPU_STARTUP_S before its first sample, so
    when numpy is predicted to finish every lattice the build may sample in less than that, wgpu is not
    started at all. Otherwise both are timed on the same points and the faster per point is chosen."""
    if requested != "auto":
        if requested not in BACKENDS:
            raise BackendChoiceError(f"--backend: unknown {requested!r}; choose auto, {', '.join(BACKENDS)}")
        return make_backend(requested, rig.graph, rig.slots), "requested"
    numpy_backend = NumpyBackend(rig.graph, rig.slots)
    rng = np.random.default_rng(0)
    lo = np.min(np.minimum(rig.slots[:, col.A], rig.slots[:, col.B]), axis=0)
    hi = np.max(np.maximum(rig.slots[:, col.A], rig.slots[:, col.B]), axis=0)
    points = rng.uniform(lo, hi, (CALIBRATION_POINTS, 3)).astype(np.float32)
    t_numpy = time_backend(numpy_backend, points, repeats=2)
    try:
        nodes = float(np.prod(make_grid(rig.slots, rig.graph, tier, rig.slot_parts, 0).shape))
    except GridTooFineError:
        nodes = math.inf
    predicted = t_numpy / CALIBRATION_POINTS * nodes * SAMPLED_NODES_PER_FIRST_NODE
    if predicted < WGPU_STARTUP_S:
        why = (
            f"numpy predicted {predicted:.2f} s for every lattice the build may sample, under wgpu's "
            f"{WGPU_STARTUP_S:g} s start-up ({CALIBRATION_POINTS}-point calibration: numpy "
            f"{t_numpy * 1e3:.1f} ms)"
        )
        progress(f"sampling backend numpy ({why})")
        return numpy_backend, why
    try:
        gpu = make_backend("wgpu", rig.graph, rig.slots)
        t_gpu = time_backend(gpu, points, repeats=2)
    except BackendUnavailableError as exc:
        progress(f"sampling backend numpy (wgpu unavailable: {exc})")
        return numpy_backend, f"wgpu unavailable: {exc}"
    chosen: FieldBackend = gpu if t_gpu < t_numpy else numpy_backend
    why = f"{CALIBRATION_POINTS}-point calibration: numpy {t_numpy * 1e3:.1f} ms, wgpu {t_gpu * 1e3:.1f} ms"
    progress(f"sampling backend {chosen.name} ({why})")
    return chosen, why
