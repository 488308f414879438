"""The body's analytic gradient against central differences of its distance, on every example creature.

The sampler carries ``∇d`` through every primitive and blend op instead of differencing (sampler.py).
This checks that claim end to end on the compiled rigs, at three classes of points near the surface
(``|d| < BAND·L``):

* **cap**: the gradient is one slot's, and that slot's point lies beyond an end (``t`` clamped on the
  tapered form, a cap region of the round cone; a sphere, the zero-length slot, counts here too);
* **interior**: the gradient is one slot's, and the point projects inside the segment (the tapered
  side ``q̂ − s·â`` or the round cone's side ``c·q̂ + sn·â``);
* **blend**: an op that carries at least ``BLEND_SHARE`` of the gradient is mixing: a poly op with
  ``BLEND_H[0] < h < BLEND_H[1]``, or an lse op with two members above ``BLEND_SHARE`` weight.

"The gradient is one slot's" means no blend activity on the path to it: every op that reaches the
gradient has ``h`` exactly 0 or 1 (poly) or one member above ``LSE_DOMINANT`` (lse). Ops that reach
it with weight 0 are ignored (two legs' op on the far side of the body has ``h = ½`` on the midline
without touching the gradient there).

The field is only piecewise smooth, so every point is kept ``MARGIN·L`` (more than every step of the
plateau) clear of every kink that can reach the gradient there: the ``t``-clamp seams of the tapered
form, the region boundaries of the round cone, the axis (or the end point, on a cap), the ``h``-clamps
of the poly ops, and ties between hard-min roots. The distances are first-order estimates, so a point
is also kept only if its regime (each relevant slot's region, each relevant poly op's clamp state, the
winning root) is the same at ``p ± MARGIN·L`` along every axis.

The step is swept from 1e-1·L to 1e-9·L: truncation error falls with the step and rounding error rises
as it shrinks, so a correct gradient shows a V whose floor is at the dtype's precision, over a plateau
of several steps, and a wrong one shows a floor at the size of the mistake (``test_sweep_detects…``).
The beetle has no cap or interior points at all: its root is an lse group whose members are never far
enough apart for one to carry ``LSE_DOMINANT`` of the weight; ``points_of`` proves that rather than
assuming it, and its blend points are mostly lse-mixing ones (``test_nary_blend_points_mix_an_lse_op``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest

from conftest import EXAMPLES
from creaturegen.field.primitives import GRADIENT_FLOOR, primitive_field, slot_uses_round_cone
from creaturegen.field.sampler import evaluate_ops, sample
from creaturegen.model import layout as col
from creaturegen.model.graph import Ref
from creaturegen.rig import CompiledRig, compile_rig
from creaturegen.spec import CharacterSpec, validate_bytes

Array = npt.NDArray[Any]

CREATURES = [p for p in sorted(EXAMPLES.rglob("*.json")) if "frost" not in p.parts]
CLASSES = ("cap", "interior", "blend")

#: Central-difference steps, as fractions of the body scale L: 1e-1 … 1e-9 in thirds of a decade. Whole
#: decades cannot show a plateau of three steps within 10× of the floor: truncation falls 100× per decade
#: (ε²) and rounding rises 10× (1/ε), so the 10× window around the floor is under two decades wide.
EPSILONS = 10.0 ** -np.linspace(1.0, 9.0, 25)
#: Points are sampled within this fraction of L of the surface.
BAND = 0.05
#: Clearance from every gradient kink, as a fraction of L (above the plateau steps of both dtypes).
MARGIN = 5e-3
#: A slot or op reaching the gradient with less weight than this cannot move it measurably.
RELEVANT = 1e-12
#: An lse op counts as quiet when one member carries more than this weight.
LSE_DOMINANT = 1.0 - 1e-9
#: A poly op is mixing with h strictly inside this range.
BLEND_H = (0.05, 0.95)
#: An lse member is mixing above this weight; a mixing op must carry this share of the gradient.
BLEND_SHARE = 0.05
#: Points tested per class (drawn from all that qualify), and the least a class may have.
PER_CLASS = 40
MIN_PER_CLASS = 20
#: Candidates drawn around each slot before filtering.
CANDIDATES_PER_SLOT = 800

#: Region codes: beyond a (or a sphere), inside the segment, beyond b.
CAP_A, SIDE, CAP_B = 0, 1, 2
#: Clamp states of a poly op (lse ops have none).
H_ZERO, H_MIXED, H_ONE, NO_CLAMP = 0, 1, 2, -1


def _compile(path: Path) -> CompiledRig:
    spec = validate_bytes(path.read_bytes())
    assert isinstance(spec, CharacterSpec)
    return compile_rig(spec)


# --- where the field is smooth, and which formula it uses there -------------------------------------


def _slot_regions(rig: CompiledRig, points: Array) -> tuple[Array, Array]:
    """Region code (S, P) of every slot at every point, and the distance (S, P) to that slot's kinks.

    Kinks of the tapered form: the seams ``t = 0`` and ``t = 1`` and, inside the segment, the axis (on
    a cap, ``q`` is radial from the end point, so only the end point itself). Kinks of the round cone:
    its region boundaries ``u = 0`` and ``u = c·L`` (``|u|`` is the meridian-plane distance to the
    boundary line, a lower bound on the distance to the boundary cone) and the axis or end point. A
    sphere's only kink is its centre. Computed in float64 from the same rules as primitives.py.
    """
    s = rig.slots
    a = s[:, None, col.A]
    ba = s[:, None, col.B] - a
    ra, rb = s[:, col.RA, None], s[:, col.RB, None]
    length = np.linalg.norm(ba, axis=-1)
    degenerate = length <= GRADIENT_FLOOR * (length + np.maximum(ra, rb))
    safe = np.where(degenerate, 1.0, length)
    axis = ba / safe[..., None]
    pa = points[None, :, :] - a
    y = np.einsum("spk,sqk->sp", pa, axis)
    x = np.linalg.norm(pa - y[..., None] * axis, axis=-1)
    pa_len = np.linalg.norm(pa, axis=-1)
    pb_len = np.linalg.norm(pa - ba, axis=-1)

    dr = ra - rb
    assert np.all(degenerate | (np.abs(dr) < length)), "nested round cones are rejected by compile_rig"
    sn = dr / safe
    c = np.sqrt(np.maximum(length**2 - dr**2, 0.0)) / safe
    u = c * y - sn * x
    cone = slot_uses_round_cone(s)[:, None]
    lo = np.where(cone, u, y)
    hi = np.where(cone, u - c * length, y - length)
    region = np.where(lo < 0, CAP_A, np.where(hi > 0, CAP_B, SIDE))
    radial = np.choose(region, [pa_len, x, pb_len])
    kink = np.minimum(np.minimum(np.abs(lo), np.abs(hi)), radial)
    region = np.where(degenerate, CAP_A, region)
    kink = np.where(degenerate, pa_len, kink)
    return region, kink


@dataclass(frozen=True)
class Analysis:
    """How the body's gradient is assembled at each point (P points, S slots, O ops)."""

    distance: Array  # (P,)
    slot_weight: Array  # (S, P): ∂d/∂d_slot, the share of the gradient each slot carries
    op_weight: Array  # (O, P): ∂d/∂d_op
    region: Array  # (S, P): CAP_A | SIDE | CAP_B
    slot_kink: Array  # (S, P): distance to the slot's nearest kink
    clamp: Array  # (O, P): H_ZERO | H_MIXED | H_ONE for poly, NO_CLAMP for lse
    op_kink: Array  # (O, P): distance to the poly op's nearest h-clamp (first order); inf for lse
    quiet: Array  # (O, P): poly h exactly 0 or 1; lse one member above LSE_DOMINANT
    mixing: Array  # (O, P): poly h inside BLEND_H; lse two members above BLEND_SHARE
    winner: Array  # (P,): the root the hard min picks
    root_kink: Array  # (P,): distance to the nearest tie with another root (first order)


def analyse(rig: CompiledRig, points: Array) -> Analysis:
    points = np.asarray(points, dtype=np.float64)
    n_points = points.shape[0]
    d_slots, g_slots = primitive_field(rig.slots, points)
    values = evaluate_ops(rig.graph, d_slots, g_slots)
    ops = rig.graph.ops

    def get(ref: Ref) -> tuple[Array, Array]:
        if ref.kind == "slot":
            return d_slots[ref.index], g_slots[ref.index]
        return values[ref.index].distance, values[ref.index].gradient

    clamp = np.full((len(ops), n_points), NO_CLAMP)
    op_kink = np.full((len(ops), n_points), np.inf)
    quiet = np.zeros((len(ops), n_points), dtype=bool)
    mixing = np.zeros((len(ops), n_points), dtype=bool)
    for j, (op, value) in enumerate(zip(ops, values, strict=True)):
        if op.kernel == "poly":
            (dl, gl), (dr, gr) = (get(c) for c in op.children)
            h_raw = 0.5 + 0.5 * (dl - dr) / op.k
            h_slope = 0.5 * np.linalg.norm(gl - gr, axis=-1) / op.k
            with np.errstate(divide="ignore"):
                op_kink[j] = np.minimum(np.abs(h_raw), np.abs(1.0 - h_raw)) / h_slope
            h = value.blend
            clamp[j] = np.where(h == 0.0, H_ZERO, np.where(h == 1.0, H_ONE, H_MIXED))
            quiet[j] = clamp[j] != H_MIXED
            mixing[j] = (h > BLEND_H[0]) & (h < BLEND_H[1])
        else:
            quiet[j] = value.blend.max(axis=0) > LSE_DOMINANT
            mixing[j] = (value.blend > BLEND_SHARE).sum(axis=0) >= 2

    root_d = np.stack([get(r)[0] for r in rig.graph.roots])
    root_g = np.stack([get(r)[1] for r in rig.graph.roots])
    winner = np.argmin(root_d, axis=0)
    columns = np.arange(n_points)
    gap = root_d - root_d[winner, columns]
    spread = np.linalg.norm(root_g - root_g[winner, columns], axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ties = np.where(np.arange(len(root_d))[:, None] == winner, np.inf, gap / spread)
    root_kink = ties.min(axis=0)

    # Back-propagate ∂d/∂(child) from the roots: the hard min passes 1 to the winner, a poly op passes
    # (1−h, h), an lse op its softmax weights. Parents follow children in program order.
    slot_weight = np.zeros_like(d_slots)
    op_weight = np.zeros((len(ops), n_points))

    def add(ref: Ref, w: Array) -> None:
        (slot_weight if ref.kind == "slot" else op_weight)[ref.index] += w

    for i, root in enumerate(rig.graph.roots):
        add(root, (winner == i).astype(np.float64))
    for j in reversed(range(len(ops))):
        mix = values[j].blend
        shares = (1.0 - mix, mix) if ops[j].kernel == "poly" else tuple(mix)
        for child, share in zip(ops[j].children, shares, strict=True):
            add(child, share * op_weight[j])

    region, slot_kink = _slot_regions(rig, points)
    distance = root_d[winner, columns]
    return Analysis(
        distance, slot_weight, op_weight, region, slot_kink, clamp, op_kink, quiet, mixing, winner, root_kink
    )


def _candidates(rig: CompiledRig, seed: int) -> Array:
    """Points around every slot's surface, within about BAND·L of it; a third on the end spheres.

    Rounded to float32, so the float64 and float32 sweeps difference the very same points.
    """
    rng = np.random.default_rng(seed)
    s = rig.slots
    n = CANDIDATES_PER_SLOT
    slot = np.repeat(np.arange(len(s)), n)
    t = np.where(rng.random(slot.size) < 1 / 3, rng.integers(0, 2, slot.size), rng.random(slot.size))
    centre = s[slot, col.A] + (s[slot, col.B] - s[slot, col.A]) * t[:, None]
    radius = s[slot, col.RA] + (s[slot, col.RB] - s[slot, col.RA]) * t
    direction = rng.normal(size=(slot.size, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    band = BAND * rig.body_scale
    offset = rng.uniform(-np.minimum(band, 0.95 * radius), band)
    points = centre + direction * (radius + offset)[:, None]
    rounded: Array = points.astype(np.float32).astype(np.float64)
    return rounded


def _clear_of_kinks(rig: CompiledRig, at: Analysis) -> Array:
    """Points in the band whose relevant slots, ops and roots are all MARGIN·L from a kink."""
    margin = MARGIN * rig.body_scale
    slots_ok = np.all((at.slot_weight <= RELEVANT) | (at.slot_kink > margin), axis=0)
    ops_ok = np.all((at.op_weight <= RELEVANT) | (at.op_kink > margin), axis=0)
    ok: Array = (np.abs(at.distance) < BAND * rig.body_scale) & slots_ok & ops_ok & (at.root_kink > margin)
    return ok


def _regime_is_stable(rig: CompiledRig, points: Array, at: Analysis) -> Array:
    """The relevant regime is unchanged at p ± MARGIN·L along each axis."""
    margin = MARGIN * rig.body_scale
    relevant_slots, relevant_ops = at.slot_weight > RELEVANT, at.op_weight > RELEVANT
    stable = np.ones(points.shape[0], dtype=bool)
    for axis in range(3):
        for sign in (-1.0, 1.0):
            moved = points.copy()
            moved[:, axis] += sign * margin
            there = analyse(rig, moved)
            stable &= np.all(~relevant_slots | (there.region == at.region), axis=0)
            stable &= np.all(~relevant_ops | (there.clamp == at.clamp), axis=0)
            stable &= there.winner == at.winner
    return stable


def _root_lse_lead(rig: CompiledRig, points: Array) -> Array:
    """How far a root lse op is from quiet at each point: its lead over the runner-up, as a fraction.

    A quiet lse op needs its top member above ``LSE_DOMINANT``, so the runner-up must trail the nearest
    member by at least ``k·ln(LSE_DOMINANT / (1 − LSE_DOMINANT))`` (about 20.7k). Returns the actual
    lead over that need at points whose winning root is an lse op, NaN elsewhere. The lead is a
    difference of two distances, so it moves at most about 2·|Δp|: a sampled maximum well below 1
    cannot hide a quiet point between the samples.
    """
    d_slots, g_slots = primitive_field(rig.slots, points)
    values = evaluate_ops(rig.graph, d_slots, g_slots)
    roots = rig.graph.roots
    root_d = np.stack([d_slots[r.index] if r.kind == "slot" else values[r.index].distance for r in roots])
    winner = np.argmin(root_d, axis=0)
    need = np.log(LSE_DOMINANT / (1.0 - LSE_DOMINANT))
    lead = np.full(points.shape[0], np.nan)
    for i, root in enumerate(roots):
        if root.kind == "op" and rig.graph.ops[root.index].kernel == "lse":
            operands = np.sort(values[root.index].operands, axis=0)
            share = (operands[1] - operands[0]) / (rig.graph.ops[root.index].k * need)
            lead = np.where(winner == i, share, lead)
    return lead


@dataclass(frozen=True)
class Classified:
    rig: CompiledRig
    points: dict[str, Array]  # class -> (n, 3) float64 (float32-representable), at most PER_CLASS
    counts: dict[str, int]  # class -> how many qualified before PER_CLASS were drawn
    band: int  # candidates within BAND·L of the surface
    clear: int  # of those, clear of every kink with a stable regime
    root_lse_lead: Array  # (band,): _root_lse_lead at every band candidate
    lse_mixing: int  # chosen blend points at which an lse op is mixing


@functools.cache
def classified(path: Path) -> Classified:
    rig = _compile(path)
    points = _candidates(rig, seed=sum(map(ord, path.name)))
    at = analyse(rig, points)
    in_band = np.abs(at.distance) < BAND * rig.body_scale
    lead = _root_lse_lead(rig, points[in_band])
    keep = _clear_of_kinks(rig, at)
    points = points[keep]
    at = analyse(rig, points)
    keep = _regime_is_stable(rig, points, at)
    points = points[keep]
    at = analyse(rig, points)

    quiet = np.all((at.op_weight <= RELEVANT) | at.quiet, axis=0)
    active = np.argmax(at.slot_weight, axis=0)
    active_region = at.region[active, np.arange(points.shape[0])]
    masks = {
        "cap": quiet & (active_region != SIDE),
        "interior": quiet & (active_region == SIDE),
        "blend": np.any((at.op_weight > BLEND_SHARE) & at.mixing, axis=0),
    }
    assert not np.any(masks["blend"] & quiet)

    rng = np.random.default_rng(1)
    take = {}
    for name, mask in masks.items():
        index = np.flatnonzero(mask)
        take[name] = np.sort(rng.choice(index, size=min(PER_CLASS, index.size), replace=False))
    chosen = {name: points[index] for name, index in take.items()}
    counts = {name: int(mask.sum()) for name, mask in masks.items()}
    is_lse = np.array([op.kernel == "lse" for op in rig.graph.ops], dtype=bool)[:, None]
    lse_mixing = np.any(is_lse & (at.op_weight > BLEND_SHARE) & at.mixing, axis=0)
    n_lse = int(lse_mixing[take["blend"]].sum())
    return Classified(rig, chosen, counts, int(in_band.sum()), points.shape[0], lead, n_lse)


def points_of(path: Path, name: str) -> Array:
    """The class's points; a class with too few must be impossible for a stated reason, or this fails.

    The one accepted reason: cap and interior points need every op on the gradient's path quiet, and
    where every point's gradient passes through a root lse op that is never near quiet (the beetle's
    ``body`` group: its members are too close together for any one to carry 1 − 1e-9 of the weight
    anywhere in the band), there are none. The blend class must always have points.
    """
    c = classified(path)
    count = c.counts[name]
    if count >= MIN_PER_CLASS:
        return c.points[name]
    assert count == 0, f"{path.name}: only {count} {name} points (need {MIN_PER_CLASS}); sample more"
    assert name != "blend", f"{path.name}: no blend points"
    lead = c.root_lse_lead
    assert lead.size > 0, f"{path.name}: no band points"
    assert np.all(np.isfinite(lead)), (
        f"{path.name}: no {name} points, and not every band point's gradient passes through a root lse op"
    )
    # Quiet needs a lead of 1; the lead moves by at most 2|Δp|/(20.7·k), so a sampled maximum of 0.75
    # leaves any quiet point at least (1 − 0.75)·20.7·k / 2 ≈ 2.6·k from every one of the band samples.
    assert lead.max() < 0.75, (
        f"{path.name}: no {name} points, yet a root lse op comes within {lead.max():.2f} of quiet"
    )
    pytest.skip(
        f"{path.name} has no {name} points: over {lead.size} band points its root lse op's lead is at "
        f"most {lead.max():.2f} of the {np.log(LSE_DOMINANT / (1 - LSE_DOMINANT)):.1f}·k a quiet op needs"
    )


# --- the instrument ----------------------------------------------------------------------------------


@dataclass(frozen=True, repr=False)
class Sweep:
    """Relative error ``|g_fd − g| / |g|`` of 6-tap central differences, per step and point."""

    epsilons: Array  # (E,) absolute steps
    errors: Array  # (E, P)

    @property
    def curve(self) -> Array:
        """Worst point per step."""
        result: Array = self.errors.max(axis=1)
        return result

    @property
    def floor(self) -> float:
        return float(self.curve.min())

    def plateau(self, factor: float = 10.0) -> tuple[int, int]:
        """Index range [first, last] of the consecutive steps around the best within ``factor`` of it."""
        curve = self.curve
        best = int(np.argmin(curve))
        first = last = best
        while first > 0 and curve[first - 1] <= factor * curve[best]:
            first -= 1
        while last < curve.size - 1 and curve[last + 1] <= factor * curve[best]:
            last += 1
        return first, last

    def __repr__(self) -> str:
        return f"Sweep(floor={self.floor:.3g}, plateau={self.plateau()})"

    def describe(self) -> str:
        first, last = self.plateau()
        rows = [
            f"  eps {eps:9.2e}  max rel err {err:9.2e}{'  *' if first <= i <= last else ''}"
            for i, (eps, err) in enumerate(zip(self.epsilons, self.curve, strict=True))
        ]
        return "\n".join(rows)


def gradient_sweep(
    rig: CompiledRig,
    points: Array,
    dtype: type[np.floating[Any]] = np.float64,
    scale_gradient: float = 1.0,
) -> Sweep:
    """Central differences of ``sample(rig, ·, dtype).distance`` against its gradient over EPSILONS·L.

    Offsets, differences and the division happen in ``dtype``, dividing by the step the perturbed
    coordinates actually represent, so a float32 sweep measures the float32 field and not the rounding
    of the step; a step lost entirely to rounding counts as an infinite error. ``scale_gradient``
    multiplies the analytic gradient (to show the instrument can fail).
    """
    dt = np.dtype(dtype)
    pts = np.asarray(points, dtype=dt)
    n = pts.shape[0]
    analytic = sample(rig, pts, dtype=dtype).gradient.astype(np.float64) * scale_gradient
    epsilons = EPSILONS * rig.body_scale
    offsets = np.zeros((epsilons.size, 3, 3), dtype=dt)  # (E, axis, xyz)
    for axis in range(3):
        offsets[:, axis, axis] = epsilons.astype(dt)
    plus = pts[None, None] + offsets[:, :, None, :]  # (E, 3, P, 3)
    minus = pts[None, None] - offsets[:, :, None, :]
    field = sample(rig, np.concatenate([plus.reshape(-1, 3), minus.reshape(-1, 3)]), dtype=dtype).distance
    assert field.dtype == dt
    rise = (field[: plus[..., 0].size] - field[plus[..., 0].size :]).reshape(epsilons.size, 3, n)
    step = np.stack([plus[:, axis, :, axis] - minus[:, axis, :, axis] for axis in range(3)], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        fd = np.where(step > 0, rise / np.where(step > 0, step, 1), np.inf).astype(np.float64)
    fd = np.moveaxis(fd, 1, 2)  # (E, P, 3)
    with np.errstate(invalid="ignore"):
        errors = np.linalg.norm(fd - analytic[None], axis=-1) / np.linalg.norm(analytic, axis=-1)
    return Sweep(epsilons, np.where(np.isfinite(errors), errors, np.inf))


# --- the checks --------------------------------------------------------------------------------------

CASES = [pytest.param(path, name, id=f"{path.stem}-{name}") for path in CREATURES for name in CLASSES]


def _report(path: Path, name: str, sweep: Sweep, dtype: npt.DTypeLike) -> str:
    return f"{path.name} {name} ({np.dtype(dtype).name}, {sweep.errors.shape[1]} points):\n{sweep.describe()}"


@pytest.mark.parametrize(("path", "name"), CASES)
def test_gradient_sweep_f64_reaches_machine_precision_over_a_plateau(path: Path, name: str) -> None:
    rig = classified(path).rig
    sweep = gradient_sweep(rig, points_of(path, name), np.float64)
    message = _report(path, name, sweep, np.float64)
    assert sweep.floor <= 1e-8, message
    # The V's floor spans several steps (truncation falls as ε², rounding rises as 1/ε), so the minimum
    # is the plateau between them and not one lucky step; it is closed on both sides within the sweep.
    first, last = sweep.plateau()
    assert last - first + 1 >= 3, message
    assert first > 0, message
    assert last < sweep.curve.size - 1, message


@pytest.mark.parametrize(("path", "name"), CASES)
def test_gradient_sweep_f32_floor_is_higher_and_at_larger_steps(path: Path, name: str) -> None:
    rig = classified(path).rig
    points = points_of(path, name)
    sweep32, sweep64 = gradient_sweep(rig, points, np.float32), gradient_sweep(rig, points, np.float64)
    message = _report(path, name, sweep32, np.float32) + "\n" + _report(path, name, sweep64, np.float64)
    assert sweep64.floor < sweep32.floor <= 2e-3, message
    # Rounding grows 2^29 times faster in float32, so its whole plateau lies at larger steps.
    assert sweep32.plateau()[1] < sweep64.plateau()[0], message


def test_sweep_detects_a_wrong_gradient() -> None:
    """The instrument can fail: a gradient off by 1e-5 shows a floor near 1e-5, not near 1e-10."""
    path = EXAMPLES / "lizard.json"
    for name in CLASSES:
        sweep = gradient_sweep(classified(path).rig, points_of(path, name), scale_gradient=1 + 1e-5)
        assert sweep.floor > 5e-6, _report(path, name, sweep, np.float64)


@pytest.mark.parametrize("path", CREATURES, ids=lambda p: p.stem)
def test_nary_blend_points_mix_an_lse_op(path: Path) -> None:
    """Where a creature has lse groups, most of its blend points exercise the n-ary kernel itself."""
    c = classified(path)
    if any(op.kernel == "lse" for op in c.rig.graph.ops):
        assert c.lse_mixing >= MIN_PER_CLASS, c.lse_mixing
    else:
        assert c.lse_mixing == 0
