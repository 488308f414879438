"""The body distance as a WGSL compute kernel on wgpu-py, for narrow-band grid sampling on any adapter.

Narrow-band sampling asks for the body distance at millions of grid points, the one place where the
numpy reference (field/sampler.py) is slow. Any WebGPU adapter will do, a CPU one such as Mesa's
lavapipe included, so the kernel is plain WGSL with no optional features.

The kernel computes the *same formulas* as the numpy float32 path, operation for operation, so the two
agree to a few float32 ulp and the mesh does not depend on the backend (surface/backends.py):

* each slot is the tapered capsule or the exact round cone, the form chosen on the CPU in float64 by
  ``slot_uses_round_cone`` and passed to the kernel as a per-slot flag (field/primitives.py: the same
  frame, degenerate-sphere rule, nested-sphere branch and left-to-right three-term dot products);
* blend ops run in program order, children before parents: the polynomial smooth-min and the
  stabilised log-sum-exp exactly as field/blend.py writes them (same operand order, terms summed left
  to right as numpy's axis-0 reduction does); the roots are combined by a hard min.

Only integers (slot and op indices, arities) enter the shader text, which is unrolled in program order;
every number (slot table, blend widths, the gradient floor) travels in buffers as float32, rounded
exactly as numpy rounds it.

Bit-identity is not promised: WGSL lets the compiler fuse a multiply and an add (lavapipe's LLVM does
so in the round cone's side distance) and ``exp``/``log`` are the adapter's own. Each such difference
rounds one intermediate no larger than the rig, so the gap stays at a few ulp of the body scale
(tests/test_surface_wgpu.py measures it per example).
"""

from __future__ import annotations

import contextlib
import importlib
import os
import sys
import tempfile
from collections.abc import Callable, Iterator
from functools import cache
from typing import Any

import numpy as np
import numpy.typing as npt

from ..field.primitives import GRADIENT_FLOOR, slot_uses_round_cone
from ..model import layout
from ..model.graph import BlendGraph, Ref
from .backends import BackendUnavailableError, Distances, Points

#: Invocations per workgroup; the dispatch covers ``ceil(n / 64)`` workgroups and the kernel guards
#: the extent.
WORKGROUP_SIZE = 64
#: Points per dispatch at most (12 MiB of input); the device limits may lower it (see ``_chunk_size``).
MAX_CHUNK = 1 << 20

#: A hook that rewrites the generated WGSL before it is compiled (tests use it to plant formula errors).
ShaderHook = Callable[[str], str]

# The per-slot formulas and the blend kernels; ``main`` is appended by ``build_shader``.
_PRELUDE = """
struct Params {
    count: u32,
    gradient_floor: f32,
    tiny: f32,
    _pad: u32,
}

// Three vec4 rows per slot: (a.xyz, ra), (b.xyz, rb), (k, round-cone flag, 0, 0).
@group(0) @binding(0) var<storage, read> slots: array<vec4<f32>>;
// One blend width per op, in program order.
@group(0) @binding(1) var<storage, read> widths: array<f32>;
// Points as packed x, y, z triples.
@group(0) @binding(2) var<storage, read> points: array<f32>;
@group(0) @binding(3) var<storage, read_write> distances: array<f32>;
@group(0) @binding(4) var<uniform> params: Params;

// Three explicit products summed left to right, as primitives._dot writes them.
fn dot3(u: vec3<f32>, v: vec3<f32>) -> f32 {
    return u.x * v.x + u.y * v.y + u.z * v.z;
}

struct Frame {
    pa: vec3<f32>,
    ba: vec3<f32>,
    ra: f32,
    rb: f32,
    len: f32,
    degenerate: bool,
    t_raw: f32,
}

// primitives._Frame: a segment no longer than the floor is a sphere with t = 0.
fn frame(p: vec3<f32>, i: u32) -> Frame {
    let row_a = slots[3u * i];
    let row_b = slots[3u * i + 1u];
    let a = row_a.xyz;
    var fr: Frame;
    fr.ba = row_b.xyz - a;
    fr.ra = row_a.w;
    fr.rb = row_b.w;
    fr.len = sqrt(dot3(fr.ba, fr.ba));
    let scale = fr.len + max(fr.ra, fr.rb);
    let floor_len = max(params.gradient_floor * scale, params.tiny);
    fr.degenerate = fr.len <= floor_len;
    fr.pa = p - a;
    let len_sq = select(dot3(fr.ba, fr.ba), 1.0, fr.degenerate);
    fr.t_raw = select(dot3(fr.pa, fr.ba) / len_sq, 0.0, fr.degenerate);
    return fr;
}

// primitives._tapered_distance.
fn tapered(fr: Frame) -> f32 {
    let t = clamp(fr.t_raw, 0.0, 1.0);
    let q = fr.pa - fr.ba * t;
    let x = sqrt(dot3(q, q));
    return x - (fr.ra + (fr.rb - fr.ra) * t);
}

// primitives._round_cone_distance.
fn round_cone(fr: Frame) -> f32 {
    let dr = fr.ra - fr.rb;
    let nested = abs(dr) >= fr.len || fr.degenerate;
    var sn = 0.0;
    var c = 1.0;
    if (!nested) {
        sn = dr / fr.len;
        c = sqrt(max((fr.len - dr) * (fr.len + dr), 0.0)) / fr.len;
    }
    let q = fr.pa - fr.ba * fr.t_raw;
    let x = sqrt(dot3(q, q));
    let cl = c * fr.len;
    // Nested: the larger end sphere, taking a on a tie of radii.
    let cap_a = (!nested && (cl * fr.t_raw < sn * x)) || (nested && fr.ra >= fr.rb);
    let cap_b = (!nested && (cl * (fr.t_raw - 1.0) > sn * x)) || (nested && fr.ra < fr.rb);
    let pb = fr.pa - fr.ba;
    let pa_len = sqrt(dot3(fr.pa, fr.pa));
    let pb_len = sqrt(dot3(pb, pb));
    let side_d = sn * (fr.t_raw * fr.len) + c * x - fr.ra;
    return select(select(side_d, pb_len - fr.rb, cap_b), pa_len - fr.ra, cap_a);
}

fn slot_distance(p: vec3<f32>, i: u32) -> f32 {
    let fr = frame(p, i);
    if (slots[3u * i + 2u].y > 0.5) {
        return round_cone(fr);
    }
    return tapered(fr);
}

// blend.poly_smin_distance.
fn poly(dl: f32, dr: f32, k: f32) -> f32 {
    let h = clamp(0.5 + 0.5 * (dl - dr) / k, 0.0, 1.0);
    let one_minus_h = 1.0 - h;
    return dl * one_minus_h + dr * h - k * h * one_minus_h;
}
"""


def _ref(ref: Ref) -> str:
    return f"s{ref.index}" if ref.kind == "slot" else f"o{ref.index}"


def _fold_min(names: list[str]) -> str:
    expr = names[0]
    for name in names[1:]:
        expr = f"min({expr}, {name})"
    return expr


def build_shader(graph: BlendGraph, slot_count: int) -> str:
    """The WGSL module for one program: the prelude, then ``main`` unrolled in program order.

    Only indices enter the text: slot ``i`` is ``s<i>``, op ``j`` is ``o<j>`` with width ``widths[j]``.
    """
    body = [f"    let s{i} = slot_distance(p, {i}u);" for i in range(slot_count)]
    for j, op in enumerate(graph.ops):
        kids = [_ref(c) for c in op.children]
        if op.kernel == "poly":
            if len(kids) != 2:
                raise ValueError(f"{op.place}: a poly op takes two children (got {len(kids)})")
            body.append(f"    let o{j} = poly({kids[0]}, {kids[1]}, widths[{j}]);")
        else:
            # blend.lse_smin_distance: shift by the minimum, terms summed left to right.
            body.append(f"    let m{j} = {_fold_min(kids)};")
            terms = " + ".join(f"exp(-({kid} - m{j}) / widths[{j}])" for kid in kids)
            body.append(f"    let o{j} = m{j} - widths[{j}] * log({terms});")
    if not graph.roots:
        raise ValueError("the blend graph has no roots")
    body.append(f"    distances[i] = {_fold_min([_ref(r) for r in graph.roots])};")
    main = "\n".join(
        [
            f"@compute @workgroup_size({WORKGROUP_SIZE})",
            "fn main(@builtin(global_invocation_id) gid: vec3<u32>) {",
            "    let i = gid.x;",
            "    if (i >= params.count) {",
            "        return;",
            "    }",
            "    let p = vec3<f32>(points[3u * i], points[3u * i + 1u], points[3u * i + 2u]);",
            *body,
            "}",
        ]
    )
    return _PRELUDE + "\n" + main + "\n"


def slot_rows(slots: npt.NDArray[np.float64]) -> npt.NDArray[np.float32]:
    """The slot table as three float32 vec4 rows per slot, with the round-cone flag decided in float64."""
    table = np.asarray(slots, dtype=np.float64)
    if table.ndim != 2 or table.shape[1] != layout.WIDTH:
        raise ValueError(f"slots: expected shape (S, {layout.WIDTH}) (got {table.shape})")
    rows = np.zeros((table.shape[0], 3, 4), dtype=np.float32)
    rows[:, 0, 0:3] = table[:, layout.A]
    rows[:, 0, 3] = table[:, layout.RA]
    rows[:, 1, 0:3] = table[:, layout.B]
    rows[:, 1, 3] = table[:, layout.RB]
    rows[:, 2, 0] = table[:, layout.K]
    rows[:, 2, 1] = slot_uses_round_cone(table)
    return rows.reshape(-1, 4)


#: What Vulkan drivers print on a headless machine while enumerating adapters: noise to a user.
_DRIVER_NOISE = ("XDG_RUNTIME_DIR is invalid or not set",)


@contextlib.contextmanager
def _quiet_driver() -> Iterator[None]:
    """Hold back what native driver code writes to fd 2 during adapter discovery, passing on every line
    but the known headless-machine noise (Python's own stderr is flushed first so nothing reorders)."""
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as held:
        os.dup2(held.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            held.seek(0)
            lines = held.read().decode("utf-8", "replace").splitlines()
            for line in lines:
                if not any(n in line for n in _DRIVER_NOISE):
                    print(line, file=sys.stderr)


@cache
def _device() -> Any:
    """One wgpu device per process (adapter discovery is slow and the device is stateless here)."""
    try:
        wgpu = importlib.import_module("wgpu")
    except ImportError as exc:
        raise BackendUnavailableError(f"the wgpu backend needs wgpu-py (pip install wgpu): {exc}") from exc
    try:
        with _quiet_driver():
            adapter = wgpu.gpu.request_adapter_sync(power_preference="high-performance")
    except Exception as exc:  # wgpu-native reports a missing adapter in several ways
        raise BackendUnavailableError(f"the wgpu backend found no WebGPU adapter: {exc}") from exc
    if adapter is None:
        raise BackendUnavailableError("the wgpu backend found no WebGPU adapter")
    try:
        return adapter.request_device_sync(label="creaturegen field")
    except Exception as exc:
        raise BackendUnavailableError(
            f"the wgpu backend could not open a device on {adapter.info}: {exc}"
        ) from exc


def _chunk_size(limits: Any) -> int:
    """Points per dispatch: bounded by the storage binding and buffer sizes (12 bytes of input per
    point) and by 65535 workgroups of 64 in one dimension."""
    by_binding = int(limits["max-storage-buffer-binding-size"]) // 12
    by_buffer = int(limits["max-buffer-size"]) // 12
    by_dispatch = int(limits["max-compute-workgroups-per-dimension"]) * WORKGROUP_SIZE
    chunk = min(MAX_CHUNK, by_binding, by_buffer, by_dispatch)
    return chunk - chunk % WORKGROUP_SIZE


class WgpuBackend:
    """The body distance of one rig, evaluated by a WGSL kernel; the pipeline is built once."""

    name = "wgpu"

    def __init__(
        self,
        graph: BlendGraph,
        slots: npt.NDArray[np.float64],
        *,
        _shader_hook: ShaderHook | None = None,
    ) -> None:
        self.graph = graph
        self.slots = slots
        self._device = _device()
        self._wgpu: Any = importlib.import_module("wgpu")
        rows = slot_rows(slots)
        source = build_shader(graph, rows.shape[0] // 3)
        if _shader_hook is not None:
            source = _shader_hook(source)
        self.shader_source = source
        dev = self._device
        usage = self._wgpu.BufferUsage
        module = dev.create_shader_module(label="creaturegen distance", code=source)
        # An explicit layout: "auto" would drop ``widths`` from a program without ops.
        kinds = ("read-only-storage",) * 3 + ("storage", "uniform")
        self._layout = dev.create_bind_group_layout(
            entries=[
                {"binding": i, "visibility": self._wgpu.ShaderStage.COMPUTE, "buffer": {"type": kind}}
                for i, kind in enumerate(kinds)
            ]
        )
        self._pipeline = dev.create_compute_pipeline(
            label="creaturegen distance",
            layout=dev.create_pipeline_layout(bind_group_layouts=[self._layout]),
            compute={"module": module, "entry_point": "main"},
        )
        self._slots_buf = dev.create_buffer_with_data(data=rows.tobytes(), usage=usage.STORAGE)
        # A program with no ops still needs a non-empty binding.
        widths = np.array([op.k for op in graph.ops] or [1.0], dtype=np.float32)
        self._widths_buf = dev.create_buffer_with_data(data=widths.tobytes(), usage=usage.STORAGE)
        self._params_buf = dev.create_buffer(size=16, usage=usage.UNIFORM | usage.COPY_DST)
        self._chunk = _chunk_size(dev.limits)
        self._capacity = 0
        self._points_buf: Any = None
        self._out_buf: Any = None
        self._staging_buf: Any = None
        self._bind_group: Any = None

    def _reserve(self, n: int) -> None:
        """Buffers for ``n`` points per dispatch, kept and reused while they are large enough."""
        if n <= self._capacity:
            return
        dev, usage = self._device, self._wgpu.BufferUsage
        capacity = min(self._chunk, max(n, WORKGROUP_SIZE))
        self._points_buf = dev.create_buffer(size=12 * capacity, usage=usage.STORAGE | usage.COPY_DST)
        self._out_buf = dev.create_buffer(size=4 * capacity, usage=usage.STORAGE | usage.COPY_SRC)
        self._staging_buf = dev.create_buffer(size=4 * capacity, usage=usage.MAP_READ | usage.COPY_DST)
        self._bind_group = dev.create_bind_group(
            layout=self._layout,
            entries=[
                {"binding": 0, "resource": {"buffer": self._slots_buf}},
                {"binding": 1, "resource": {"buffer": self._widths_buf}},
                {"binding": 2, "resource": {"buffer": self._points_buf}},
                {"binding": 3, "resource": {"buffer": self._out_buf}},
                {"binding": 4, "resource": {"buffer": self._params_buf}},
            ],
        )
        self._capacity = capacity

    def distance(self, points: Points) -> Distances:
        p = np.ascontiguousarray(np.asarray(points, dtype=np.float32).reshape(-1, 3))
        n = p.shape[0]
        out = np.empty(n, dtype=np.float32)
        if n == 0:
            return out
        self._reserve(min(n, self._chunk))
        params = np.zeros(4, dtype=np.uint32)
        # The floor and tiny as numpy's float32 path rounds them (primitives._Frame).
        params[1:3] = np.array([GRADIENT_FLOOR, np.finfo(np.float32).tiny], dtype=np.float32).view(np.uint32)
        dev, queue = self._device, self._device.queue
        for start in range(0, n, self._chunk):
            chunk = p[start : start + self._chunk]
            m = chunk.shape[0]
            params[0] = m
            queue.write_buffer(self._params_buf, 0, params.tobytes())
            queue.write_buffer(self._points_buf, 0, chunk.tobytes())
            encoder = dev.create_command_encoder()
            compute = encoder.begin_compute_pass()
            compute.set_pipeline(self._pipeline)
            compute.set_bind_group(0, self._bind_group)
            compute.dispatch_workgroups(-(-m // WORKGROUP_SIZE), 1, 1)
            compute.end()
            encoder.copy_buffer_to_buffer(self._out_buf, 0, self._staging_buf, 0, 4 * m)
            queue.submit([encoder.finish()])
            self._staging_buf.map_sync(self._wgpu.MapMode.READ, 0, 4 * m)
            try:
                out[start : start + m] = np.frombuffer(self._staging_buf.read_mapped(0, 4 * m), np.float32)
            finally:
                self._staging_buf.unmap()
        return out
