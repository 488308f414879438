"""Which sampling backend samples each lattice: the one asked for, or the faster measured on this machine.

numpy is always there; wgpu (Mesa lavapipe or a real GPU) is faster per point on big lattices but pays a
start-up of seconds, so "auto" does not start wgpu while numpy would finish the lattice first, and times
both on the same points once it has.
"""

from __future__ import annotations

import numpy as np

from ..model import layout as col
from ..rig import CompiledRig
from .backends import (
    BACKENDS,
    BackendChoiceError,
    BackendUnavailableError,
    FieldBackend,
    NumpyBackend,
    Points,
    make_backend,
    time_backend,
)
from .progress import Progress

#: Calibration points for picking the faster sampling backend.
CALIBRATION_POINTS = 32768
#: wgpu's start-up before its first sample (adapter, device, wgpu-native's cffi type parsing, the first
#: pipeline): 3.1 s to 4.2 s measured in a cProfile'd build on the 2-core machine under load (stop 28),
#: 6.4 s (4.6 s of it the device) on a 2-core Xeon (stop 45). Against numpy's ~0.8 µs per point that is
#: millions of samples.
WGPU_STARTUP_S = 4.0
#: The share of a lattice the narrow band samples at most: 15-35 % of a dense pass (the sampling report's
#: "% of a dense pass"; the beetle's first lattice 17.7 %).
BAND_SHARE = 0.35


class SamplingBackends:
    """The backend each lattice of one build samples with: the one asked for, or for "auto" the faster for
    that lattice with wgpu's start-up counted until it has been paid.

    A build samples its first lattice and, only when a mesh gate fails, √2-finer ones (2.8 and 8 times
    the nodes). Deciding once for every lattice the build might sample started wgpu for bodies that never
    refine: the beetle's hero build then paid 6.4 s of start-up to save 0.2 s of sampling (measured, stop
    45: 31.6 s with wgpu against 27.7 s with numpy, the same .glb). Each lattice now predicts numpy's time
    for its own band; wgpu starts when that exceeds the start-up, and once started it samples every later
    lattice it is faster on. The backends agree to the byte (tests/test_surface_build.py), so the choice
    moves only time."""

    def __init__(self, rig: CompiledRig, requested: str, progress: Progress) -> None:
        if requested != "auto" and requested not in BACKENDS:
            raise BackendChoiceError(f"--backend: unknown {requested!r}; choose auto, {', '.join(BACKENDS)}")
        self._rig = rig
        self._requested = requested
        self._progress = progress
        self._numpy = NumpyBackend(rig.graph, rig.slots)
        self._requested_backend: FieldBackend | None = None
        self._points: Points | None = None
        self._t_numpy: float | None = None
        self._gpu: FieldBackend | None = None
        self._t_gpu: float | None = None
        self._gpu_refused: str | None = None

    def for_lattice(self, nodes: int) -> tuple[FieldBackend, str]:
        """The backend for a lattice of ``nodes`` nodes, and why."""
        if self._requested != "auto":
            if self._requested_backend is None:
                self._requested_backend = make_backend(self._requested, self._rig.graph, self._rig.slots)
            return self._requested_backend, "requested"
        points = self._calibration_points()
        if self._t_numpy is None:
            self._t_numpy = time_backend(self._numpy, points, repeats=2)
        t_numpy = self._t_numpy
        calibration = f"{CALIBRATION_POINTS}-point calibration: numpy {t_numpy * 1e3:.1f} ms"
        if self._gpu_refused is not None:
            return self._chosen(self._numpy, f"wgpu unavailable: {self._gpu_refused}")
        if self._gpu is None:
            predicted = t_numpy / CALIBRATION_POINTS * nodes * BAND_SHARE
            if predicted < WGPU_STARTUP_S:
                why = (
                    f"numpy predicted {predicted:.2f} s for this lattice's band ({nodes:,} nodes), under "
                    f"wgpu's {WGPU_STARTUP_S:g} s start-up ({calibration})"
                )
                return self._chosen(self._numpy, why)
            try:
                self._gpu = make_backend("wgpu", self._rig.graph, self._rig.slots)
                self._t_gpu = time_backend(self._gpu, points, repeats=2)
            except BackendUnavailableError as exc:
                self._gpu_refused = str(exc)
                return self._chosen(self._numpy, f"wgpu unavailable: {exc}")
        assert self._t_gpu is not None
        why = f"{calibration}, wgpu {self._t_gpu * 1e3:.1f} ms"
        return self._chosen(self._gpu if self._t_gpu < t_numpy else self._numpy, why)

    def _calibration_points(self) -> Points:
        if self._points is None:
            slots = self._rig.slots
            lo = np.min(np.minimum(slots[:, col.A], slots[:, col.B]), axis=0)
            hi = np.max(np.maximum(slots[:, col.A], slots[:, col.B]), axis=0)
            rng = np.random.default_rng(0)
            self._points = rng.uniform(lo, hi, (CALIBRATION_POINTS, 3)).astype(np.float32)
        return self._points

    def _chosen(self, backend: FieldBackend, why: str) -> tuple[FieldBackend, str]:
        self._progress(f"sampling backend {backend.name} ({why})")
        return backend, why
