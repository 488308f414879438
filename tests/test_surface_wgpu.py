"""The wgpu backend against the numpy float32 reference: parity on every creature, and a planted error.

The points are seeded and aimed at where formulas differ: end caps, the side of every slot at radius
offsets (the axis itself and the exact end points included), the junctions between the children of
every blend op, and the rest AABB padded by 10 %.

Tolerance. Both sides run the same float32 operations in the same order, but a shader compiler may
fuse a multiply and an add into one FMA (WGSL allows it, and lavapipe's LLVM does it in the round
cone's side distance), and ``exp``/``log`` are the adapter's own. Each is a rounding of an
intermediate no larger than the rig, so the gap is a few ulp of ``L = body_scale``; the bound
``1e-5·L + 4 ulp(|d|)`` leaves room for a real GPU's looser ``exp``/``log``/division while staying
orders of magnitude below any formula error (the taper term alone is ~5e-3·L on the beetle).
Rigs without round cones or log-sum-exp ops agree bit for bit on lavapipe; a failure message prints
this run's ``max |Δd| / L``.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest

from conftest import EXAMPLES, missing_setup
from creaturegen.model import layout
from creaturegen.model.graph import BlendGraph, Ref
from creaturegen.rig import CompiledRig, compile_rig
from creaturegen.spec import CharacterSpec, load_spec
from creaturegen.surface.backends import BackendUnavailableError, NumpyBackend, make_backend
from creaturegen.surface.wgpu_field import WgpuBackend, _device

Array = npt.NDArray[Any]

CREATURES = sorted(EXAMPLES.glob("*.json")) + sorted((EXAMPLES / "reference").glob("*.json"))
SEED = 20240611
#: Absolute part of the bound, as a fraction of L.
TOL_L = 1e-5
#: Relative part, in ulp of |d|.
TOL_ULP = 4


@pytest.fixture(scope="module", autouse=True)
def _adapter() -> None:
    try:
        _device()
    except BackendUnavailableError as exc:
        missing_setup(f"no wgpu adapter: {exc}")


@cache
def _rig(path: Path) -> CompiledRig:
    spec = load_spec(path)
    assert isinstance(spec, CharacterSpec)
    return compile_rig(spec)


def _unit(rng: np.random.Generator, n: int) -> Array:
    v = rng.normal(size=(n, 3))
    result: Array = v / np.linalg.norm(v, axis=1, keepdims=True)
    return result


def _perpendicular_unit(rng: np.random.Generator, axis: Array, n: int) -> Array:
    """Random unit vectors perpendicular to ``axis`` (any unit vectors if the axis is zero)."""
    u = _unit(rng, n)
    length = float(np.linalg.norm(axis))
    if length == 0.0:
        return u
    a = axis / length
    v = u - (u @ a)[:, None] * a
    result: Array = v / np.linalg.norm(v, axis=1, keepdims=True)
    return result


def _leaves(graph: BlendGraph, ref: Ref) -> list[int]:
    if ref.kind == "slot":
        return [ref.index]
    return [s for c in graph.ops[ref.index].children for s in _leaves(graph, c)]


def probe_points(rig: CompiledRig, seed: int = SEED) -> npt.NDArray[np.float32]:
    """Seeded points: padded AABB, end caps, slot sides at radius offsets, blend junctions."""
    rng = np.random.default_rng(seed)
    s, body = rig.slots, rig.body_scale
    a, b = s[:, layout.A], s[:, layout.B]
    ra, rb = s[:, layout.RA], s[:, layout.RB]
    lo = np.minimum(a - ra[:, None], b - rb[:, None]).min(axis=0)
    hi = np.maximum(a + ra[:, None], b + rb[:, None]).max(axis=0)
    pad = 0.1 * (hi - lo)
    parts = [rng.uniform(lo - pad, hi + pad, size=(4096, 3))]

    def offsets(n: int) -> Array:
        """Radial offsets: most within ±2 % of L of the surface, a few exactly on it."""
        d = rng.normal(scale=0.02 * body, size=n)
        d[: n // 8] = 0.0
        return d

    for i in range(s.shape[0]):
        axis = b[i] - a[i]
        # End caps: spheres of radius ra / rb around a and b, and the end points themselves.
        parts.append(a[i] + _unit(rng, 64) * (ra[i] + offsets(64))[:, None])
        parts.append(b[i] + _unit(rng, 64) * (rb[i] + offsets(64))[:, None])
        parts.append(np.stack([a[i], b[i]]))
        # The side: along the axis (a little past both ends) at the interpolated radius plus offsets,
        # and on the axis itself.
        t = rng.uniform(-0.1, 1.1, size=96)
        radius = ra[i] + (rb[i] - ra[i]) * np.clip(t, 0.0, 1.0)
        on_axis = a[i] + t[:, None] * axis
        parts.append(on_axis + _perpendicular_unit(rng, axis, 96) * (radius + offsets(96))[:, None])
        parts.append(on_axis[:8])
    # Blend junctions: between a random point of each child's segments, swept across the gap.
    for op in rig.graph.ops:
        groups = [_leaves(rig.graph, c) for c in op.children]
        for left, right in pairwise(groups):
            n = 96
            li, ri = rng.choice(left, size=n), rng.choice(right, size=n)
            ti, tj = rng.uniform(size=(n, 1)), rng.uniform(size=(n, 1))
            pi = a[li] + ti * (b[li] - a[li])
            pj = a[ri] + tj * (b[ri] - a[ri])
            w = rng.uniform(size=(n, 1))
            noise = rng.normal(scale=0.02 * body, size=(n, 3))
            parts.append(pi + w * (pj - pi) + noise)
    return np.concatenate(parts).astype(np.float32)


def parity_gap(
    rig: CompiledRig, points: npt.NDArray[np.float32], backend: WgpuBackend
) -> tuple[float, Array, Array]:
    """(max |Δd| / L, the numpy distances, the excess over the tolerance per point)."""
    ref = NumpyBackend(rig.graph, rig.slots).distance(points)
    got = backend.distance(points)
    assert got.dtype == np.float32
    assert got.shape == ref.shape
    assert np.all(np.isfinite(got))
    gap = np.abs(got.astype(np.float64) - ref.astype(np.float64))
    tol = TOL_L * rig.body_scale + TOL_ULP * np.spacing(np.abs(ref)).astype(np.float64)
    return float(gap.max() / rig.body_scale), ref, gap - tol


@pytest.mark.parametrize("path", CREATURES, ids=lambda p: p.name)
def test_wgpu_matches_numpy_float32_on_every_creature(path: Path) -> None:
    rig = _rig(path)
    points = probe_points(rig)
    assert points.shape[0] >= 4096
    relative, ref, excess = parity_gap(rig, points, WgpuBackend(rig.graph, rig.slots))
    # The set really probes the surface, not just the empty box around it.
    assert np.count_nonzero(np.abs(ref) < 0.01 * rig.body_scale) >= 256
    worst = int(np.argmax(excess))
    assert excess.max() <= 0.0, (
        f"{path.name}: max |Δd|/L = {relative:.3g} exceeds 1e-5·L + 4 ulp at {points[worst].tolist()}"
    )


#: Planted formula errors: (creature, WGSL text to replace, replacement).
MUTATIONS = {
    "taper term dropped": ("beetle.json", "fr.ra + (fr.rb - fr.ra) * t", "fr.ra"),
    "round-cone axial term dropped": ("lizard.json", "sn * (fr.t_raw * fr.len) + c * x", "c * x"),
    "poly correction dropped": ("quadruped.json", " - k * h * one_minus_h", ""),
}


def _mutation(old: str, new: str) -> Callable[[str], str]:
    def hook(source: str) -> str:
        assert source.count(old) == 1, f"the shader no longer contains {old!r} exactly once"
        return source.replace(old, new)

    return hook


@pytest.mark.parametrize("mutation", MUTATIONS, ids=str)
def test_parity_catches_a_planted_formula_error(mutation: str) -> None:
    name, old, new = MUTATIONS[mutation]
    rig = _rig(next(p for p in CREATURES if p.name == name))
    points = probe_points(rig)
    backend = WgpuBackend(rig.graph, rig.slots, _shader_hook=_mutation(old, new))
    assert new in backend.shader_source
    relative, _, excess = parity_gap(rig, points, backend)
    assert excess.max() > 0.0, f"{mutation}: went unnoticed (max |Δd|/L = {relative:.3g})"


def test_chunked_dispatch_and_buffer_reuse_agree_with_one_call(monkeypatch: pytest.MonkeyPatch) -> None:
    """Several chunks (with a ragged last one), then a smaller call reusing the buffers."""
    rig = _rig(EXAMPLES / "beetle.json")
    points = probe_points(rig)[:5000]
    whole = WgpuBackend(rig.graph, rig.slots).distance(points)
    backend = WgpuBackend(rig.graph, rig.slots)
    monkeypatch.setattr(backend, "_chunk", 1024)
    np.testing.assert_array_equal(backend.distance(points), whole)
    buffer = backend._points_buf
    np.testing.assert_array_equal(backend.distance(points[:77]), whole[:77])
    assert backend._points_buf is buffer
    assert backend.distance(points[:0]).shape == (0,)


def test_make_backend_builds_the_wgpu_backend() -> None:
    rig = _rig(EXAMPLES / "reference" / "flyer.json")
    backend = make_backend("wgpu", rig.graph, rig.slots)
    assert backend.name == "wgpu"
    assert isinstance(backend, WgpuBackend)


def test_sphere_nested_cone_and_a_program_without_ops() -> None:
    """The branches the examples barely reach: a sphere, a zero-length slot with unequal radii and a
    slot whose one end sphere holds the other (both the round cone's nested branch), three roots and
    no ops at all (the widths binding is then unused by the shader)."""
    slots = np.zeros((3, layout.WIDTH))
    slots[0, layout.RA] = slots[0, layout.RB] = 0.5
    slots[1, layout.A] = slots[1, layout.B] = [1.0, 0.0, 0.0]
    slots[1, layout.RA], slots[1, layout.RB] = 0.2, 0.4
    slots[2, layout.A], slots[2, layout.B] = [0.0, 1.0, 0.0], [0.0, 1.1, 0.0]
    slots[2, layout.RA], slots[2, layout.RB] = 0.05, 0.3
    graph = BlendGraph((), (Ref("slot", 0), Ref("slot", 1), Ref("slot", 2)))
    rng = np.random.default_rng(SEED)
    points = np.concatenate([rng.normal(size=(4096, 3)), slots[:, layout.A], slots[:, layout.B]])
    points = points.astype(np.float32)
    ref = NumpyBackend(graph, slots).distance(points)
    got = WgpuBackend(graph, slots).distance(points)
    tol = TOL_L * 1.5 + TOL_ULP * np.spacing(np.abs(ref))
    assert np.all(np.abs(got - ref) <= tol), float(np.abs(got - ref).max())
