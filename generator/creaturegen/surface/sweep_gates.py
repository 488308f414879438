"""Judging one joint's sweep: the gates every method's measurements must pass, and why these bounds.

The sweep (surface/sweep.py) measures; this module turns its numbers into one :class:`MethodSweep`
per method, each gate a :class:`~creaturegen.surface.gates.SurfaceGate` with the pose where it was
worst, so surface/deform.py can keep the first method whose every gate passes and a refusal or a
report can say which bound failed where.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final, Literal

import numpy as np
import numpy.typing as npt

from .gates import SurfaceGate
from .skinning import METHODS, Method
from .sweep import SweepMeasures

F64 = npt.NDArray[np.float64]
Bools = npt.NDArray[np.bool_]


# --------------------------------------------------------------------------------------------- gates
# Two kinds of gate. The error a posed seam shows has two sources: the weights' transition (a vertex
# with 30 % of its weight on the parent lags 30 % of the rotation behind the child, whatever the method)
# and the method's blending. Measured over the examples at the default sweep, the first dominates
# (0.2 to 1.8·r_j near the joint for every method alike), so an absolute bound tight enough to see a
# method's artefact would reject every method. Hence:
# - absolute gates, every method: what any acceptable skin may do (surface_max, surface_p99,
#   joint_collapse). When no method meets them the joint is broken and the build fails;
# - relative gates: what a method adds on top of what the weights already cost, against the best of
#   the three at the same pose (surface_excess, every method; bulge_excess, DQ and CoR) or against DQ,
#   which moves every vertex rigidly (volume_loss, LBS). The split follows the seed: LBS is kept where
#   its twist/volume sweep passes, DQ and CoR are gated on their bulge and twist errors.
# Folds (dihedral increase, flipped faces) are measured and reported but not gated: at the default
# sweep every method folds the inner crease of most thin-limb joints (0.5 to 8 % of the seam faces,
# often more for DQ than for LBS), so a gate would reject every method; the correction pass checks
# inversions where they matter.
# Lengths are in units of the joint scale s_j = max(r_j, D): r_j is the child's radius at its pivot end
# and D the distance from the pivot to the nearest seam vertex. D ≈ r_j for a knee; where the pivot is
# buried inside the parent (a hip, a tail fin) the seam turns on a longer lever, every method moves it
# further, and its artefacts grow with D as they grow with r_j elsewhere.
#: Largest side-aware surface error (see :func:`~creaturegen.surface.sweep.measure_sweep`) near the
#: joint, × s_j. A skinned joint off the posed body by more than two of its own radii no longer reads as
#: the same limb, and is far beyond what the bounded correction pass (a fraction of the slot radius per
#: vertex) can pull back.
SURFACE_MAX_FACTOR: Final = 2.0
#: Its 99th percentile, × s_j: the bulk of the joint ring must stay within one and a half radii.
SURFACE_P99_FACTOR: Final = 1.5
#: What a method may add over the best method at the same pose, × s_j, to the worst surface error and
#: to the worst outward error (bulge). A quarter radius is where a thinned or swollen joint starts to
#: read as a different shape next to the alternative.
EXCESS_FACTOR: Final = 0.25
#: Volume a method loses against DQ at the same pose (ΔV_dq − ΔV, whole mesh), × the joint volume
#: 4/3·π·r_j²·s_j (the joint ball, stretched along the lever). DQ moves every seam vertex rigidly, so the
#: weights' lag and any overlap change its volume exactly as they change the others'; what remains is
#: the volume a blend gives up by contracting vertices towards the pivot, LBS's elbow and candy-wrapper
#: loss. Half the joint ball is a limb thinned by a tenth of its radius over three and a half radii,
#: about where the thinning becomes visible. (The posed body's own volume change would be the better
#: reference, but integrating the field per pose costs more than the whole sweep.)
VOLUME_FACTOR: Final = 0.5
#: Smallest ratio posed/rest of a seam vertex's distance to the pivot, over the vertices nearest the
#: pivot. A joint rotation keeps every distance to its pivot (DQ reproduces that exactly); LBS's blend
#: of two rotations shortens it to cos(θ/2) at a 50/50 seam. 0.8 admits LBS up to a relative rotation
#: of ~74° (the default 60° bend: 0.87) and rejects the 90° candy wrapper (cos 45° ≈ 0.71).
COLLAPSE_MIN: Final = 0.8


@dataclass(frozen=True)
class Measurement:
    """A worst value over the sweep that informs but does not decide."""

    name: str
    value: float
    unit: str
    pose: str  # the sweep pose where it was reached

    def as_dict(self) -> dict[str, object]:
        return {"name": self.name, "value": self.value, "unit": self.unit, "pose": self.pose}


@dataclass(frozen=True)
class MethodSweep:
    """One method's worst case over one joint's sweep."""

    method: Method
    gates: tuple[SurfaceGate, ...]
    measurements: tuple[Measurement, ...]
    # Hemisphere flips summed over the sweep's poses (DQ, CoR), counted on the two-influence form: zero
    # unless a sweep angle passes 180°, since the identity and a rotation below 180° share a hemisphere.
    flips: int

    @property
    def passed(self) -> bool:
        return all(g.passed for g in self.gates)

    @property
    def failed(self) -> tuple[SurfaceGate, ...]:
        return tuple(g for g in self.gates if not g.passed)

    def describe(self) -> dict[str, object]:
        return {
            "method": self.method,
            "passed": self.passed,
            "flips": self.flips,
            "gates": [g.as_dict() for g in self.gates],
            "measurements": [m.as_dict() for m in self.measurements],
        }


def _worst(column: F64, labels: Sequence[str], low: bool = False) -> tuple[float, str]:
    """The worst value over the sweep's poses and the pose's label."""
    if column.size == 0:
        return (1.0 if low else 0.0), ""
    p = int(np.argmin(column) if low else np.argmax(column))
    return float(column[p]), labels[p]


def _excess(values: F64, keeps: Bools | None = None) -> F64:
    """(P, 3) per pose, each method's value above the best (smallest) of the methods marked in ``keeps``
    at that pose (the methods that keep the joint over the whole sweep), or of all three where none is."""
    if keeps is None:
        keeps = np.ones(values.shape, dtype=bool)
    usable = np.where(keeps.any(axis=1, keepdims=True), keeps, True)
    best = np.where(usable, values, np.inf).min(axis=1, keepdims=True)
    result: F64 = np.maximum(values - best, 0.0)
    return result


def _gate(
    name: str, worst: tuple[float, str], threshold: float, unit: str, direction: Literal["max", "min"] = "max"
) -> SurfaceGate:
    return SurfaceGate(name, worst[0], threshold, unit, direction, worst[1])


def _keeps(collapse: F64, volume: F64, ball: float) -> Bools:
    """(P, 3) per pose, the methods the relative gates compare with (see :func:`_excess`)."""
    # The relative gates compare a method with the best of the methods that could be chosen instead: those
    # that keep the joint at every pose of the sweep by their own gates (no collapse, and for LBS no more
    # volume lost than VOLUME_FACTOR of the joint ball). A collapsed or deflated joint hugs the posed body
    # from inside (vertices pulled towards the pivot), so measuring DQ's or CoR's surface error and bulge
    # against it charged them for not collapsing, and a method that collapses at some pose is no
    # alternative at any other (thick hips of wolves and elephants, knees on slopes, on the corpus).
    keeps = collapse >= COLLAPSE_MIN
    keeps[:, 0] &= (volume[:, 1] - volume[:, 0]) <= VOLUME_FACTOR * ball
    result: Bools = np.broadcast_to(keeps.all(axis=0), keeps.shape)
    return result


def _method_sweep(
    k: int,
    sweep: SweepMeasures,
    keeps: Bools,
    r_l: float,
    ball: float,
    length_scale: float,
    rest_volume: float,
) -> MethodSweep:
    """Method ``METHODS[k]``'s gates and measurements, each at its worst pose of the sweep; ``r_l`` is the
    joint scale in units of L, ``ball`` the joint volume (see :data:`VOLUME_FACTOR`)."""
    method = METHODS[k]

    def worst(values: F64, low: bool = False) -> tuple[float, str]:
        return _worst(values[:, k], sweep.labels, low)

    common = (
        _gate("surface_max", worst(sweep.surface_max / length_scale), SURFACE_MAX_FACTOR * r_l, "L"),
        _gate("surface_p99", worst(sweep.surface_p99 / length_scale), SURFACE_P99_FACTOR * r_l, "L"),
        _gate(
            "surface_excess",
            worst(_excess(sweep.surface_max, keeps) / length_scale),
            EXCESS_FACTOR * r_l,
            "L",
        ),
        _gate("joint_collapse", worst(sweep.collapse, low=True), COLLAPSE_MIN, "ratio", "min"),
    )
    # The seed's split: LBS stands or falls by its twist (collapse) and volume sweep; DQ and CoR,
    # whose blended rotation keeps a pivot rotation's radii, by their bulge.
    specific = (
        _gate(
            "volume_loss",
            worst((sweep.volume[:, 1:2] - sweep.volume) / rest_volume),
            VOLUME_FACTOR * ball / rest_volume,
            "V_rest",
        )
        if method == "lbs"
        else _gate(
            "bulge_excess", worst(_excess(sweep.bulge, keeps) / length_scale), EXCESS_FACTOR * r_l, "L"
        )
    )
    measurements = tuple(
        Measurement(name, *worst(values), unit)
        for name, values, unit in (
            ("bulge", sweep.bulge / length_scale, "L"),
            ("volume_change", np.abs(sweep.volume) / rest_volume, "V_rest"),
            ("dihedral_increase", sweep.dihedral, "deg"),
            ("flipped_faces", sweep.flipped, "faces"),
        )
    )
    gates = (*common, specific)
    return MethodSweep(method, gates, measurements, int(sweep.flips[k]))


def method_sweeps(sweep: SweepMeasures, length_scale: float, rest_volume: float) -> tuple[MethodSweep, ...]:
    """Every method's verdict over one joint's sweep, in preference order; ``rest_volume`` is the rest
    mesh's, the unit of the volume gates."""
    r_l = sweep.scale / length_scale
    ball = 4.0 / 3.0 * math.pi * sweep.radius**2 * sweep.scale
    keeps = _keeps(sweep.collapse, sweep.volume, ball)
    return tuple(
        _method_sweep(k, sweep, keeps, r_l, ball, length_scale, rest_volume) for k in range(len(METHODS))
    )
