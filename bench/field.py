"""Field benchmark: full graph vs candidate programs, analytic gradient vs central differences.

For every creature example (``examples/**/*.json`` except ``examples/frost``) it measures, on one set of
near-surface points, the evaluations per second of distance + gradient + colour for

* ``full``: the whole blend graph over every slot (``sample_graph(rig.graph, rig.slots, ...)``);
* ``candidates``: every point through its region's candidate program, the regions that share one
  program evaluated together (as the acceptance sweep does);
* ``candidates_per_region``: the same, one call per region (shows the per-call overhead);
* ``full_fd``: the full graph with a six-tap central-difference gradient: a distance-only evaluation at
  the point (which also gives the colour) and at six offset points, through the package's
  distance-only path (``primitive_distance`` / ``evaluate_distance``: the sampler's formulas without
  the gradient work);
* ``full_fd_sampler``: the same seven evaluations through ``sample_graph``, its gradient ignored.

All variants run interleaved in rounds whose order rotates; every ratio is the median over rounds of
the ratio measured within a round. Output is JSON; progress and a summary table go to stderr.

    python bench/field.py --out bench/results/field.json
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from collections import defaultdict
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from benchlib import machine
from creaturegen.candidates import build_candidates, tolerances
from creaturegen.field.colour import proximity_colour
from creaturegen.field.floors import floors_for
from creaturegen.field.primitives import primitive_distance
from creaturegen.field.sampler import evaluate_distance, sample_distance, sample_graph
from creaturegen.model import layout as col
from creaturegen.model.graph import BlendGraph
from creaturegen.motion.compiled import compile_creature
from creaturegen.rig import CompiledRig
from creaturegen.spec import CharacterSpec, load_spec

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
F64 = npt.NDArray[np.float64]

#: Padding of the rest AABB the start points are drawn from, as a fraction of the body size L.
PAD_FACTOR = 0.1
NEWTON_STEPS = 2
SNAP_STEPS = (0, 1, 2)
VARIANTS = ("full", "candidates", "candidates_per_region", "full_fd", "full_fd_sampler")

NOTES = " ".join(
    [
        "The cost model counts leaf evaluations per point on a GPU, where one point runs one fused loop.",
        "This is a NumPy CPU reference on float64 arrays, so it need not match.",
        "Every NumPy operation pays a fixed dispatch cost and writes a full temporary array, so time",
        "follows the number of array operations and the memory they touch rather than the arithmetic.",
        "The analytic gradient is not free here: it carries a vector per slot and point beside each",
        "distance and adds the blend and fallback work, while a distance-only evaluation skips all of",
        "it; the model treats the gradient as fused at no extra evaluations.",
        "Candidate programs split the points into one batch per distinct program (or per region), and",
        "small batches are dominated by per-call overhead that does not shrink with K.",
        "The colour pass over the kept leaves, the blend ops and the root minimum are outside the leaf",
        "count. The GPU side (divergence between regions with different K, occupancy, register",
        "pressure) has no counterpart here. Predicted figures are pure arithmetic on P and K; only the",
        "measured figures were timed, in this run.",
    ]
)


# --- the measured work --------------------------------------------------------------------------------

#: The six tap directions of a central difference.
_TAPS = np.concatenate([np.eye(3), -np.eye(3)])


def fd_distance_only(
    graph: BlendGraph, slots: F64, points: F64, h: float, k_floor: float
) -> tuple[F64, F64, F64]:
    """Distance, central-difference gradient and colour: seven distance-only field evaluations."""
    d_slots = primitive_distance(slots, points)
    distance = evaluate_distance(graph, d_slots)
    color = proximity_colour(d_slots, slots[:, col.K], slots[:, col.RGB], k_floor)
    taps = [sample_distance(graph, slots, points + h * e) for e in _TAPS]
    gradient = np.stack([taps[i] - taps[i + 3] for i in range(3)], axis=1) / (2.0 * h)
    return distance, gradient, color


def fd_sampler(graph: BlendGraph, slots: F64, points: F64, h: float, k_floor: float) -> tuple[F64, F64, F64]:
    """The same through ``sample_graph`` seven times, its analytic gradient thrown away."""
    centre = sample_graph(graph, slots, points, k_floor)
    taps = [sample_graph(graph, slots, points + h * e, k_floor).distance for e in _TAPS]
    gradient = np.stack([taps[i] - taps[i + 3] for i in range(3)], axis=1) / (2.0 * h)
    return centre.distance, gradient, centre.color


# --- points and regions ---------------------------------------------------------------------------------


def assign_regions(points: F64, lo: F64, hi: F64) -> npt.NDArray[np.intp]:
    """First region whose closed box holds each point, -1 for none."""
    region = np.full(len(points), -1, dtype=np.intp)
    for start in range(0, len(points), 4096):
        p = points[start : start + 4096]
        inside = ((p[None] >= lo[:, None]) & (p[None] <= hi[:, None])).all(axis=2)
        region[start : start + 4096] = np.where(inside.any(axis=0), inside.argmax(axis=0), -1)
    return region


def near_surface_points(
    rig: CompiledRig, lo: F64, hi: F64, count: int, rng: np.random.Generator
) -> tuple[F64, npt.NDArray[np.intp]]:
    """Uniform in the padded AABB, two Newton steps to the full field's zero set, kept when inside a
    candidate region and within the band τ."""
    k_floor = floors_for(rig.body_scale).k_floor
    band = tolerances(rig).band
    radius = np.maximum(rig.slots[:, col.RA], rig.slots[:, col.RB])[:, None]
    box_lo = np.minimum(rig.slots[:, col.A], rig.slots[:, col.B]) - radius
    box_hi = np.maximum(rig.slots[:, col.A], rig.slots[:, col.B]) + radius
    pad = PAD_FACTOR * rig.body_scale
    start, stop = box_lo.min(axis=0) - pad, box_hi.max(axis=0) + pad
    kept_p: list[F64] = []
    kept_r: list[npt.NDArray[np.intp]] = []
    total = 0
    for _ in range(50):
        p = rng.uniform(start, stop, size=(max(2 * count, 256), 3))
        for _ in range(NEWTON_STEPS):
            f = sample_graph(rig.graph, rig.slots, p, k_floor)
            g2 = np.maximum((f.gradient**2).sum(axis=1), 1e-30)
            p = p - (f.distance / g2)[:, None] * f.gradient
        d = sample_graph(rig.graph, rig.slots, p, k_floor).distance
        region = assign_regions(p, lo, hi)
        keep = (region >= 0) & (np.abs(d) <= band)
        kept_p.append(p[keep])
        kept_r.append(region[keep])
        total += int(keep.sum())
        if total >= count:
            break
    else:
        raise RuntimeError(f"only {total} of {count} near-surface points landed in a region")
    return np.concatenate(kept_p)[:count], np.concatenate(kept_r)[:count]


# --- timing --------------------------------------------------------------------------------------------


def _time(fn: Callable[[], object]) -> float:
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def _median(values: Sequence[float]) -> float:
    return float(statistics.median(values))


def interleaved(work: dict[str, Callable[[], object]], repeats: int) -> dict[str, list[float]]:
    """One warm-up round, then ``repeats`` rounds, each running every variant once in a rotated order."""
    names = list(work)
    for name in names:
        work[name]()
    times: dict[str, list[float]] = {n: [] for n in names}
    for r in range(repeats):
        shift = r % len(names)
        for name in names[shift:] + names[:shift]:
            times[name].append(_time(work[name]))
    return times


def measure_example(
    path: Path, points: int, repeats: int, seed: int, log: Callable[[str], None]
) -> dict[str, Any]:
    spec = load_spec(path)
    assert isinstance(spec, CharacterSpec)
    creature = compile_creature(spec)
    rig = creature.rig
    started = time.perf_counter()
    found = build_candidates(creature, "hero")
    elapsed = time.perf_counter() - started
    log(f"  {len(found.programs)} regions, K_used {found.k_used} (build_candidates {elapsed:.1f} s, untimed)")
    programs = found.programs
    lo = np.array([p.lo for p in programs], dtype=np.float64).reshape(-1, 3)
    hi = np.array([p.hi for p in programs], dtype=np.float64).reshape(-1, 3)
    rng = np.random.default_rng(seed)
    pts, region = near_surface_points(rig, lo, hi, points, rng)
    floors = floors_for(rig.body_scale)
    k_floor, h = floors.k_floor, floors.epsilon_length
    slots, graph = rig.slots, rig.graph

    # Distinct programs and their points; regions with no point are not evaluated.
    groups: dict[tuple[tuple[int, ...], BlendGraph], list[int]] = defaultdict(list)
    for i, program in enumerate(programs):
        groups[(program.leaves, program.graph)].append(i)
    batches = []
    for (leaves, pgraph), members in groups.items():
        idx = np.flatnonzero(np.isin(region, members))
        if len(idx):
            batches.append((pgraph, slots[list(leaves)], pts[idx]))
    per_region = []
    for i in np.unique(region):
        program = programs[i]
        per_region.append((program.graph, slots[list(program.leaves)], pts[region == i]))
    leaves_per_point = np.array([len(programs[i].leaves) for i in region])
    k_mean = float(leaves_per_point.mean())

    # Before timing: the FD gradient against the analytic one (its median relative error is reported)
    # and every point covered once by the candidates.
    reference = sample_graph(graph, slots, pts, k_floor)
    _, fd_gradient, _ = fd_distance_only(graph, slots, pts, h, k_floor)
    fd_error = np.linalg.norm(fd_gradient - reference.gradient, axis=1) / np.linalg.norm(
        reference.gradient, axis=1
    )
    assert sum(len(b[2]) for b in batches) == len(pts) == sum(len(b[2]) for b in per_region)

    work: dict[str, Callable[[], object]] = {
        "full": lambda: sample_graph(graph, slots, pts, k_floor),
        "candidates": lambda: [sample_graph(g, s, p, k_floor) for g, s, p in batches],
        "candidates_per_region": lambda: [sample_graph(g, s, p, k_floor) for g, s, p in per_region],
        "full_fd": lambda: fd_distance_only(graph, slots, pts, h, k_floor),
        "full_fd_sampler": lambda: fd_sampler(graph, slots, pts, h, k_floor),
    }
    log(f"  {len(pts)} points, {len(batches)} distinct programs over {len(per_region)} regions; timing")
    times = interleaved(work, repeats)

    def ratio(num: str, den: str) -> float:
        return _median([a / b for a, b in zip(times[num], times[den], strict=True)])

    n, s_count, k_used = len(pts), rig.slot_count, found.k_used
    variants = {}
    for name, ts in times.items():
        t = _median(ts)
        leaves = {"full": s_count, "full_fd": 7 * s_count, "full_fd_sampler": 7 * s_count}.get(name, k_mean)
        variants[name] = {
            "seconds_median": t,
            "seconds_min": min(ts),
            "seconds_max": max(ts),
            "points_per_second": n / t,
            "leaf_evaluations_per_second": n * leaves / t,
        }
    predicted = {
        f"S{s}": {
            "e_snap_k_used": (s + 1) * k_used,
            "e_snap_k_mean": (s + 1) * k_mean,
            "e_forbidden": (s + 1) * 7 * s_count,
        }
        for s in SNAP_STEPS
    }
    return {
        "example": path.relative_to(EXAMPLES).as_posix() if path.is_relative_to(EXAMPLES) else str(path),
        "slot_count_P": s_count,
        "blend_ops": len(graph.ops),
        "regions": len(programs),
        "regions_with_points": len(per_region),
        "distinct_programs_with_points": len(batches),
        "points": n,
        "k_used": k_used,
        "k_mean_per_point": k_mean,
        "fd_step_m": h,
        "fd_gradient_relative_error_median": float(np.median(fd_error)),
        "variants": variants,
        "measured_ratios": {
            "candidates_speedup_vs_full": ratio("full", "candidates"),
            "candidates_per_region_speedup_vs_full": ratio("full", "candidates_per_region"),
            "fd_over_analytic": ratio("full_fd", "full"),
            "fd_sampler_over_analytic": ratio("full_fd_sampler", "full"),
            "combined_full_fd_over_candidates_analytic": ratio("full_fd", "candidates"),
            "combined_full_fd_sampler_over_candidates_analytic": ratio("full_fd_sampler", "candidates"),
        },
        "cost_model": {
            "predicted_candidates_speedup_P_over_k_mean": s_count / k_mean,
            "predicted_fd_over_analytic": 7,
            "predicted_forbidden_over_snap_7P_over_k_used": 7 * s_count / k_used,
            "predicted_forbidden_over_snap_7P_over_k_mean": 7 * s_count / k_mean,
            "predicted_leaf_evaluations": predicted,
        },
    }


# --- driver ------------------------------------------------------------------------------------------


def default_examples() -> list[Path]:
    return [p for p in sorted(EXAMPLES.rglob("*.json")) if "frost" not in p.relative_to(EXAMPLES).parts]


def environment() -> dict[str, Any]:
    return {**machine(), "python_implementation": platform.python_implementation(), "numpy": np.__version__}


def table(results: list[dict[str, Any]]) -> str:
    head = (
        f"{'example':<26}{'P':>4}{'Kuse':>5}{'Kmean':>7}{'full Mpt/s':>11}{'cand Mpt/s':>11}"
        f"{'cand×':>7}{'P/Km':>6}{'FD/an':>7}{'FD/an sam':>10}{'comb':>7}{'7P/Ku':>7}{'7P/Km':>7}"
    )
    rows = [head]
    for r in results:
        v, m, c = r["variants"], r["measured_ratios"], r["cost_model"]
        rows.append(
            f"{r['example']:<26}{r['slot_count_P']:>4}{r['k_used']:>5}{r['k_mean_per_point']:>7.2f}"
            f"{v['full']['points_per_second'] / 1e6:>11.3f}"
            f"{v['candidates']['points_per_second'] / 1e6:>11.3f}"
            f"{m['candidates_speedup_vs_full']:>7.2f}{c['predicted_candidates_speedup_P_over_k_mean']:>6.2f}"
            f"{m['fd_over_analytic']:>7.2f}{m['fd_sampler_over_analytic']:>10.2f}"
            f"{m['combined_full_fd_over_candidates_analytic']:>7.2f}"
            f"{c['predicted_forbidden_over_snap_7P_over_k_used']:>7.2f}"
            f"{c['predicted_forbidden_over_snap_7P_over_k_mean']:>7.2f}"
        )
    return "\n".join(rows)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--out", type=Path, default=REPO / "bench" / "results" / "field.json")
    parser.add_argument("--points", type=int, default=20_000, help="near-surface points per example")
    parser.add_argument("--repeats", type=int, default=5, help="timed rounds after one warm-up round")
    parser.add_argument("--seed", type=int, default=20260101)
    parser.add_argument("examples", nargs="*", type=Path, help="spec files (default: every creature example)")
    args = parser.parse_args(argv)
    if args.points < 1 or args.repeats < 1:
        parser.error("--points and --repeats must be at least 1")
    paths = [p.resolve() for p in args.examples] or default_examples()

    def log(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    started = time.perf_counter()
    results = []
    for i, path in enumerate(paths, 1):
        log(f"[{i}/{len(paths)}] {path.name}")
        results.append(measure_example(path, args.points, args.repeats, args.seed, log))
    report = {
        "benchmark": "field",
        "environment": environment(),
        "parameters": {
            "points": args.points,
            "repeats": args.repeats,
            "warmup_rounds": 1,
            "seed": args.seed,
            "dtype": "float64",
            "tier": "hero",
            "newton_steps": NEWTON_STEPS,
            "aabb_pad_factor": PAD_FACTOR,
            "point_selection": "uniform in the padded rest AABB, Newton steps on the full field, kept when "
            "inside a candidate region (first matching box) and within the band τ",
            "candidates": "regions sharing a program evaluated in one batch; candidates_per_region: one "
            "call per region",
            "fd_method": "six-tap central differences with step epsilon_length; full_fd: the package's "
            "distance-only path (primitive_distance / evaluate_distance, no gradient computed), colour "
            "from the centre evaluation; full_fd_sampler: sample_graph seven times, gradient ignored",
            "ratios": "median over rounds of the ratio of two variants timed in the same round; the "
            "variant order rotates every round",
        },
        "results": results,
        "notes": NOTES,
        "wall_seconds": time.perf_counter() - started,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n")
    log(table(results))
    log(f"wrote {args.out} ({report['wall_seconds']:.1f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
