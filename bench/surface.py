"""Surface-extraction benchmark: narrow band vs dense N³ sampling, numpy vs wgpu, extraction, validation.

For every creature example (``examples/*.json`` and ``examples/reference/*.json``) at every surface tier
(hero, repeated, distant) it builds the tier's lattice (``surface/grid.py: make_grid``) and measures, in
this run:

* **the lattice**: shape, spacing, nodes of a dense N³ pass, the coarse (block-centre) and fine (surface
  shell) samples of the narrow band and the fraction fine/dense; counts, not times;
* **narrow-band sampling** (``surface/sampling.py: sample_band``, the whole call: block certificates,
  fine nodes, float64 settling of near-zero nodes) with the numpy backend and with the wgpu backend on the
  same grid, best of ``--repeats``; the time spent inside the backend's ``distance`` calls is clocked
  apart (the rest is the sampler's bookkeeping); both sign lattices are compared node for node;
* **the dense N³ baseline**: every lattice node evaluated once, points generated slab by slab in float32
  as the band does, chunks of ``DENSE_CHUNK`` nodes. wgpu always (when it has an adapter); numpy only
  where the lattice has at most ``NUMPY_DENSE_MAX_NODES`` nodes (beyond that it takes too long and is
  recorded as null with the reason), or where numpy sampled the band faster. ``dense_backend`` names the
  backend that was faster at band sampling in this run, the baseline the headline saving uses. Dense
  signs are checked against the band's sign lattice away from zero (``|d| ≥ δ``, the settle band);
* **extraction** (``surface/extract.py: extract`` on the numpy band) and **validation**
  (``surface/mesh_gates.py: surface_mesh_gates``: the build's gates and thresholds and the component policy,
  at the first lattice only: the build's √2 refinement on a failed gate is not benchmarked),
  each timed once: vertex and triangle counts, every gate as measured, the names of failed gates.

Sampling variants run interleaved in rounds whose order rotates, after a 64-point warm-up call per
backend (the wgpu pipeline is built before timing, and its build time is reported apart). Times are the
best of the rounds; ratios (dense/band per backend, numpy/wgpu) divide times of this run. A tier whose
error target needs too fine a lattice (``GridTooFineError``) is recorded with the error message. JSON goes
to ``--out``; progress to stderr; a summary table to stdout.

    python bench/surface.py --out bench/results/surface.json
"""

from __future__ import annotations

import argparse
import fnmatch
import gc
import importlib.metadata
import json
import math
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import numpy.typing as npt

from benchlib import machine
from creaturegen.model.skeleton import Skeleton, build_skeleton
from creaturegen.rig import CompiledRig, compile_rig
from creaturegen.spec import CharacterSpec, load_spec
from creaturegen.surface.backends import BackendUnavailableError, FieldBackend, NumpyBackend, make_backend
from creaturegen.surface.components import ComponentPolicy
from creaturegen.surface.extract import extract
from creaturegen.surface.field64 import BodyField
from creaturegen.surface.gates import SurfaceGate
from creaturegen.surface.grid import ERROR_TARGET, Grid, GridTooFineError, make_grid, smallest_radius
from creaturegen.surface.mesh_gates import surface_mesh_gates
from creaturegen.surface.sampling import SIGN_SETTLE_FACTOR, NarrowBand, sample_band

T = TypeVar("T")

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
TIERS = tuple(ERROR_TARGET)  # hero, repeated, distant
BACKEND_NAMES = ("numpy", "wgpu")

#: numpy dense passes only up to this many lattice nodes (unless numpy was the faster band sampler).
NUMPY_DENSE_MAX_NODES = 2_000_000
#: Nodes per backend call in the dense pass (whole x-planes, at least one).
DENSE_CHUNK = 1 << 20
#: Points of the warm-up call per backend before any timing.
WARMUP_POINTS = 64

NOTES = " ".join(
    [
        "Times are wall-clock on this host. The wgpu backend runs on whatever adapter wgpu-py finds",
        "(see environment.wgpu_adapter): on a CPU adapter such as Mesa's llvmpipe it is compiled SIMD code",
        "on the same cores numpy uses, not a GPU. Narrow-band sampling times include the block",
        "certificates, the fine shell and the float64 re-evaluation of near-zero nodes (always numpy, for",
        "both backends), so its numpy/wgpu ratio need not match that of the dense pass, which is backend",
        "evaluation plus point generation only. Dense passes evaluate float32 distances only and keep",
        "them; the band's saving in samples (fine/dense) bounds its saving in time only loosely, because",
        "the band also pays per-call overhead and the settle pass. Extraction and validation are numpy",
        "float64 and do not depend on the sampling backend (the sign lattices are compared).",
    ]
)


# --- helpers -------------------------------------------------------------------------------------------


def _ratio(num: float | None, den: float | None) -> float | None:
    if num is None or den is None or den <= 0:
        return None
    return num / den


def _timed(fn: Callable[[], T]) -> tuple[float, T]:
    gc.collect()
    start = time.perf_counter()
    result = fn()
    return time.perf_counter() - start, result


def dense_pass(grid: Grid, backend: FieldBackend) -> npt.NDArray[np.float32]:
    """Every lattice node through ``backend``: whole x-planes per call, points built in float64 and cast
    to float32 as ``sample_band`` builds its own; returns the distances in C order of the lattice."""
    nx, ny, nz = grid.shape
    plane = ny * nz
    planes_per_call = max(1, DENSE_CHUNK // plane)
    jk = np.stack(np.meshgrid(np.arange(ny), np.arange(nz), indexing="ij"), axis=-1).reshape(-1, 2)
    out = np.empty(nx * plane, dtype=np.float32)
    for x0 in range(0, nx, planes_per_call):
        x1 = min(nx, x0 + planes_per_call)
        ijk = np.empty(((x1 - x0) * plane, 3), dtype=np.float64)
        ijk[:, 0] = np.repeat(np.arange(x0, x1, dtype=np.float64), plane)
        ijk[:, 1:] = np.tile(jk, (x1 - x0, 1))
        out[x0 * plane : x1 * plane] = backend.distance(grid.points(ijk).astype(np.float32))
    return out


class ClockedBackend:
    """A backend that adds up the wall time spent inside its ``distance`` calls (the rest of a band
    sampling call is the sampler's own bookkeeping: block nodes, float64 settling, the sign lattice)."""

    def __init__(self, inner: FieldBackend) -> None:
        self.inner = inner
        self.name = inner.name
        self.seconds = 0.0

    def distance(self, points: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
        start = time.perf_counter()
        result = self.inner.distance(points)
        self.seconds += time.perf_counter() - start
        return result


def gate_rows(gates: Sequence[SurfaceGate]) -> list[dict[str, object]]:
    return [g.as_dict() for g in gates]


def relative_example(path: Path) -> str:
    return path.relative_to(EXAMPLES).as_posix() if path.is_relative_to(EXAMPLES) else str(path)


# --- one example at one tier --------------------------------------------------------------------------


def measure_tier(
    spec: CharacterSpec,
    rig: CompiledRig,
    skeleton: Skeleton,
    backends: dict[str, FieldBackend],
    tier: str,
    repeats: int,
    log: Callable[[str], None],
) -> dict[str, Any]:
    record: dict[str, Any] = {"tier": tier, "error_target_r_min": ERROR_TARGET[tier]}
    try:
        grid = make_grid(rig.slots, rig.graph, tier, rig.slot_parts)
    except GridTooFineError as exc:
        record["error"] = {"type": "GridTooFineError", "message": str(exc)}
        log(f"    {tier}: GridTooFineError: {exc}")
        return record
    nodes = int(np.prod(grid.shape))
    length = rig.body_scale
    delta = SIGN_SETTLE_FACTOR * length

    # The variants of one round: band sampling per backend, dense passes where they are affordable.
    work: dict[str, Callable[[], object]] = {}

    in_backend: dict[str, list[float]] = {name: [] for name in backends}

    def band_of(name: str, backend: FieldBackend) -> Callable[[], NarrowBand]:
        def run() -> NarrowBand:
            clocked = ClockedBackend(backend)
            result = sample_band(grid, clocked, rig.graph, rig.slots, length)
            in_backend[name].append(clocked.seconds)
            return result

        return run

    for name, backend in backends.items():
        work[f"band_{name}"] = band_of(name, backend)
    if "wgpu" in backends:
        work["dense_wgpu"] = lambda: dense_pass(grid, backends["wgpu"])
    if nodes <= NUMPY_DENSE_MAX_NODES:
        work["dense_numpy"] = lambda: dense_pass(grid, backends["numpy"])

    times: dict[str, list[float]] = {k: [] for k in work}
    results: dict[str, object] = {}
    order = list(work)

    def run_rounds(names_to_run: list[str]) -> None:
        for r in range(repeats):
            shift = r % len(names_to_run)
            for key in names_to_run[shift:] + names_to_run[:shift]:
                seconds, value = _timed(work[key])
                times[key].append(seconds)
                results[key] = value

    run_rounds(order)
    best = {k: min(v) for k, v in times.items()}
    faster = min((k for k in best if k.startswith("band_")), key=lambda k: best[k]).removeprefix("band_")
    numpy_dense_reason = None
    if "dense_numpy" not in work:
        if faster == "numpy":  # the headline baseline must exist: time it even on a big lattice
            work["dense_numpy"] = lambda: dense_pass(grid, backends["numpy"])
            times["dense_numpy"] = []
            run_rounds(["dense_numpy"])
            best["dense_numpy"] = min(times["dense_numpy"])
        else:
            numpy_dense_reason = (
                f"not timed: {nodes:,} nodes > {NUMPY_DENSE_MAX_NODES:,} (numpy dense takes too long; "
                f"{faster} was the faster band sampler)"
            )

    band = results["band_numpy"]
    assert isinstance(band, NarrowBand)
    band_flat = band.inside.reshape(-1)
    sampling: dict[str, Any] = {}
    for name in BACKEND_NAMES:
        if name not in backends:
            sampling[name] = None
            continue
        b = results[f"band_{name}"]
        assert isinstance(b, NarrowBand)
        dense_key = f"dense_{name}"
        dense_s = best.get(dense_key)
        mismatches = None
        if dense_key in results:
            d = results[dense_key]
            assert isinstance(d, np.ndarray)
            mismatches = int(np.count_nonzero(((d < 0) != band_flat) & (np.abs(d) >= delta)))
        band_times = times[f"band_{name}"]
        in_best = in_backend[name][band_times.index(min(band_times))]
        sampling[name] = {
            "band_seconds_best": best[f"band_{name}"],
            "band_seconds_all": band_times,
            "band_seconds_in_backend": in_best,
            "band_fraction_in_backend": in_best / best[f"band_{name}"],
            "band_sign_lattice_equals_numpy": bool(np.array_equal(b.inside, band.inside)),
            "band_settled_samples": b.settled_samples,
            "dense_seconds_best": dense_s,
            "dense_seconds_all": times.get(dense_key),
            "dense_null_reason": numpy_dense_reason if name == "numpy" and dense_s is None else None,
            "dense_nodes_per_second": nodes / dense_s if dense_s else None,
            "dense_sign_mismatches_outside_settle_band": mismatches,
            "dense_over_band": _ratio(dense_s, best[f"band_{name}"]),
        }
    ratios: dict[str, float | None] = {
        "band_numpy_over_wgpu": None,
        "dense_numpy_over_wgpu": None,
        "dense_fastest_over_band_fastest": None,
    }
    if "wgpu" in backends:
        ratios["band_numpy_over_wgpu"] = _ratio(best["band_numpy"], best["band_wgpu"])
        ratios["dense_numpy_over_wgpu"] = _ratio(best.get("dense_numpy"), best.get("dense_wgpu"))
    ratios["dense_fastest_over_band_fastest"] = _ratio(best.get(f"dense_{faster}"), best[f"band_{faster}"])

    # Extraction and validation on the numpy band (the reference; the wgpu lattice is compared above).
    field = BodyField(rig.graph, rig.slots)
    t_extract, ex = _timed(lambda: extract(field, band, length))
    mesh = ex.mesh

    def validate() -> tuple[list[SurfaceGate], ComponentPolicy]:
        return surface_mesh_gates(rig, ex, field, skeleton, grid)

    t_validate, (gates, policy) = _timed(validate)
    failed = [g.name for g in gates if not g.passed]

    record.update(
        {
            "lattice": {
                "shape": list(grid.shape),
                "spacing_m": grid.spacing,
                "spacing_over_L": grid.spacing / length,
                "dense_nodes": nodes,
                "blocks_total": band.total_blocks,
                "blocks_active": band.active_blocks,
                "coarse_samples": band.coarse_samples,
                "fine_samples": band.fine_samples,
                "settled_samples": band.settled_samples,
                "fine_over_dense": band.fine_samples / nodes,
                "coarse_plus_fine_over_dense": (band.coarse_samples + band.fine_samples) / nodes,
            },
            "dense_backend": faster,
            "dense_backend_choice": "the faster narrow-band sampler in this run ("
            + ", ".join(f"{k.removeprefix('band_')} {best[k]:.4g} s" for k in best if k.startswith("band_"))
            + ")",
            "sampling": sampling,
            "measured_ratios": ratios,
            "extraction": {
                "seconds": t_extract,
                "vertices": mesh.vertex_count,
                "triangles": mesh.face_count,
                "residual_over_L": ex.residual / length,
                "unresolved_edges": ex.unresolved_edges,
                "relax_reverted": ex.relax_reverted,
            },
            "validation": {
                "seconds": t_validate,
                "components_found": policy.count,
                "components_expected": policy.expected,
                "gates_total": len(gates),
                "gates_passed": len(gates) - len(failed),
                "all_passed": not failed,
                "failed": failed,
                "gates": gate_rows(gates),
            },
        }
    )
    np_s = sampling["numpy"]
    wg_s = sampling.get("wgpu")
    log(
        f"    {tier}: lattice {'x'.join(map(str, grid.shape))} ({nodes:,} nodes), fine "
        f"{band.fine_samples / nodes:.1%}; band numpy {np_s['band_seconds_best']:.3f} s"
        + (f", wgpu {wg_s['band_seconds_best']:.3f} s" if wg_s else "")
        + f"; dense {faster} {best.get(f'dense_{faster}', math.nan):.3f} s; extract {t_extract:.2f} s, "
        f"validate {t_validate:.2f} s; {mesh.vertex_count:,} v, {mesh.face_count:,} t; gates "
        f"{len(gates) - len(failed)}/{len(gates)}" + (f" (failed {', '.join(failed)})" if failed else "")
    )
    return record


def measure_example(
    path: Path, tiers: Sequence[str], repeats: int, log: Callable[[str], None]
) -> dict[str, Any]:
    spec = load_spec(path)
    assert isinstance(spec, CharacterSpec), f"{path} is not a creature spec"
    rig = compile_rig(spec)
    skeleton = build_skeleton(spec, rig)
    backends: dict[str, FieldBackend] = {"numpy": NumpyBackend(rig.graph, rig.slots)}
    setup: dict[str, Any] = {"numpy": 0.0}
    wgpu_reason = None
    started = time.perf_counter()
    try:
        backends["wgpu"] = make_backend("wgpu", rig.graph, rig.slots)
        setup["wgpu"] = time.perf_counter() - started
    except BackendUnavailableError as exc:
        wgpu_reason = str(exc)
        setup["wgpu"] = None
        log(f"  wgpu unavailable: {exc}")
    warm = np.zeros((WARMUP_POINTS, 3), dtype=np.float32)
    for backend in backends.values():
        backend.distance(warm)
    r_min, _ = smallest_radius(rig.slots)
    return {
        "example": relative_example(path),
        "slots": rig.slot_count,
        "blend_ops": len(rig.graph.ops),
        "body_scale_L_m": rig.body_scale,
        "r_min_m": r_min,
        "backend_setup_seconds": setup,
        "wgpu_unavailable_reason": wgpu_reason,
        "tiers": [measure_tier(spec, rig, skeleton, backends, tier, repeats, log) for tier in tiers],
    }


# --- driver ------------------------------------------------------------------------------------------


def default_examples() -> list[Path]:
    return sorted(EXAMPLES.glob("*.json")) + sorted((EXAMPLES / "reference").glob("*.json"))


def select_examples(patterns: Sequence[str]) -> list[Path]:
    """Examples whose file name or path under examples/ matches any of the globs, in default order."""
    every = default_examples()
    chosen = []
    for path in every:
        rel = relative_example(path)
        if any(fnmatch.fnmatch(path.name, p) or fnmatch.fnmatch(rel, p) for p in patterns):
            chosen.append(path)
    return chosen


def wgpu_adapter() -> dict[str, Any]:
    try:
        from creaturegen.surface.wgpu_field import _device

        adapter = _device().adapter
    except BackendUnavailableError as exc:
        return {"available": False, "reason": str(exc)}
    info = {
        k: (v if isinstance(v, str | int | float | bool) else str(v)) for k, v in dict(adapter.info).items()
    }
    return {"available": True, "summary": str(adapter.summary), "info": info}


def environment() -> dict[str, Any]:
    try:
        wgpu_version: str | None = importlib.metadata.version("wgpu")
    except importlib.metadata.PackageNotFoundError:
        wgpu_version = None
    return {**machine(), "numpy": np.__version__, "wgpu_py": wgpu_version, "wgpu_adapter": wgpu_adapter()}


def _f(value: float | None, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def table(results: list[dict[str, Any]]) -> str:
    head = (
        f"{'example':<26}{'tier':<9}{'lattice':>12}{'nodes':>10}{'fine/N³':>8}{'band np s':>10}"
        f"{'band wg s':>10}{'in wg':>7}{'np/wg':>7}{'dense wg s':>11}{'dense np s':>11}"
        f"{'N³/bd wg':>9}{'N³/bd np':>9}"
        f"{'extr s':>8}{'valid s':>8}{'verts':>8}{'tris':>8}  gates"
    )
    rows = [head]
    for r in results:
        for t in r["tiers"]:
            if "error" in t:
                rows.append(
                    f"{r['example']:<26}{t['tier']:<9}  {t['error']['type']}: {t['error']['message']}"
                )
                continue
            lat, s, m = t["lattice"], t["sampling"], t["measured_ratios"]
            wg = s["wgpu"] or {}
            v = t["validation"]
            gates = f"{v['gates_passed']}/{v['gates_total']}" + (
                f" failed {','.join(v['failed'])}" if v["failed"] else ""
            )
            shape = "x".join(map(str, lat["shape"]))
            rows.append(
                f"{r['example']:<26}{t['tier']:<9}{shape:>12}{lat['dense_nodes']:>10}"
                f"{lat['fine_over_dense']:>8.3f}{s['numpy']['band_seconds_best']:>10.3f}"
                f"{_f(wg.get('band_seconds_best'), '.3f'):>10}"
                f"{_f(wg.get('band_fraction_in_backend'), '.0%'):>7}"
                f"{_f(m['band_numpy_over_wgpu'], '.2f'):>7}"
                f"{_f(wg.get('dense_seconds_best'), '.3f'):>11}"
                f"{_f(s['numpy']['dense_seconds_best'], '.3f'):>11}"
                f"{_f(wg.get('dense_over_band'), '.2f'):>9}{_f(s['numpy']['dense_over_band'], '.2f'):>9}"
                f"{t['extraction']['seconds']:>8.2f}{v['seconds']:>8.2f}"
                f"{t['extraction']['vertices']:>8}{t['extraction']['triangles']:>8}  {gates}"
            )
    return "\n".join(rows)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--out", type=Path, default=REPO / "bench" / "results" / "surface.json")
    parser.add_argument(
        "--examples",
        default="",
        help="comma-separated file names or globs under examples/ (biped.json,reference/h*); default: all",
    )
    parser.add_argument(
        "--tiers", default=",".join(TIERS), help=f"comma-separated subset of {','.join(TIERS)}"
    )
    parser.add_argument(
        "--repeats", type=int, default=1, help="timed rounds of the sampling variants (best of)"
    )
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error("--repeats must be at least 1")
    tiers = [t.strip() for t in args.tiers.split(",") if t.strip()]
    unknown = [t for t in tiers if t not in TIERS]
    if not tiers or unknown:
        parser.error(f"--tiers: unknown {unknown or 'empty'}; choose from {', '.join(TIERS)}")
    patterns = [p.strip() for p in args.examples.split(",") if p.strip()]
    paths = select_examples(patterns) if patterns else default_examples()
    if not paths:
        parser.error(f"--examples {args.examples!r} matches no example under {EXAMPLES}")

    def log(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    started = time.perf_counter()
    results = []
    for i, path in enumerate(paths, 1):
        log(f"[{i}/{len(paths)}] {relative_example(path)}")
        results.append(measure_example(path, tiers, args.repeats, log))
    report = {
        "benchmark": "surface",
        "environment": environment(),
        "parameters": {
            "examples": [relative_example(p) for p in paths],
            "tiers": tiers,
            "error_targets": {t: ERROR_TARGET[t] for t in tiers},
            "repeats": args.repeats,
            "warmup": f"one {WARMUP_POINTS}-point distance call per backend after it is built",
            "sampling_times": "best of the rounds; the variants of a round run in an order that rotates",
            "dense_pass": f"every lattice node once, whole x-planes per call, at most {DENSE_CHUNK} nodes "
            "per call unless one plane is larger; float32 points built as sample_band builds them",
            "numpy_dense_max_nodes": NUMPY_DENSE_MAX_NODES,
            "dense_backend": "per tier, the backend with the faster narrow-band sampling in this run",
            "extraction_and_validation": "timed once each, on the numpy band",
            "validation": "surface/mesh_gates.py surface_mesh_gates: the build's mesh gates and thresholds "
            "and its component policy, on the first lattice (no refinement)",
            "ratios": "dense_over_band: dense pass / band sampling per backend; numpy_over_wgpu: the same "
            "variant on both backends; all from best times of this run",
        },
        "results": results,
        "notes": NOTES,
        "wall_seconds": time.perf_counter() - started,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n")
    print(table(results), flush=True)
    log(f"wrote {args.out} ({report['wall_seconds']:.1f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
