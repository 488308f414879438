"""Field sampling backends: one interface, the numpy reference and a WGSL kernel on wgpu-py.

A backend answers one question, the body distance at many points in float32, because that is all the
narrow-band sampler needs; signs near zero and every vertex position are settled afterwards in float64
numpy (surface/extract.py), so the mesh does not depend on which backend sampled the grid.
"""

from __future__ import annotations

import time
from typing import Protocol

import numpy as np
import numpy.typing as npt

from ..field.sampler import sample_distance
from ..model.graph import BlendGraph

Points = npt.NDArray[np.float32]  # (N, 3)
Distances = npt.NDArray[np.float32]  # (N,)


class FieldBackend(Protocol):
    """Evaluates one rig's rest field; built once per rig so a GPU backend can keep its pipeline."""

    name: str

    def distance(self, points: Points) -> Distances: ...


class NumpyBackend:
    """The CPU reference formulas in float32 (field/sampler.py), chunked to bound memory."""

    name = "numpy"
    #: Points per call: the sampler holds (slots × points × 3) gradients-free temporaries.
    CHUNK = 65536

    def __init__(self, graph: BlendGraph, slots: npt.NDArray[np.float64]) -> None:
        self.graph = graph
        self.slots = slots

    def distance(self, points: Points) -> Distances:
        p = np.asarray(points, dtype=np.float32).reshape(-1, 3)
        out = np.empty(p.shape[0], dtype=np.float32)
        for start in range(0, p.shape[0], self.CHUNK):
            stop = start + self.CHUNK
            out[start:stop] = sample_distance(self.graph, self.slots, p[start:stop], dtype=np.float32)
        return out


BACKENDS = ("numpy", "wgpu")


def make_backend(name: str, graph: BlendGraph, slots: npt.NDArray[np.float64]) -> FieldBackend:
    """A backend by name; "wgpu" raises BackendUnavailableError when no adapter can be had."""
    if name == "numpy":
        return NumpyBackend(graph, slots)
    if name == "wgpu":
        from .wgpu_field import WgpuBackend

        return WgpuBackend(graph, slots)
    raise BackendChoiceError(f"unknown sampling backend {name!r}; choose one of {', '.join(BACKENDS)}")


class BackendChoiceError(ValueError):
    """``--backend`` names no backend: the one error the CLI attributes to that option."""


class BackendUnavailableError(RuntimeError):
    """The backend cannot run on this machine (no adapter, no wgpu-py)."""


def time_backend(backend: FieldBackend, points: Points, repeats: int = 3) -> float:
    """Best-of wall time of one distance call, seconds (first call excluded: it compiles)."""
    backend.distance(points[:64])
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        backend.distance(points)
        best = min(best, time.perf_counter() - t0)
    return best
