"""An individual's motion data: the authored record with its size and gait genes expressed (core/genome.js
express, the same scalar arithmetic in the same order).

Which fields a gene scales is data, shipped with the record (``genes.fields``, ``lengths``) so the JS core
scales the very same ones; the fields are named there by their JSON keys, read and replaced here by
key (model/record.py). The authored record is frozen, so an individual never alters it.
"""

from __future__ import annotations

import math

from ..model.genome import Genome
from ..model.record import JsonRecord, field_value, replace_by_key
from .data import MotionData


def express_gait(motion: MotionData, genome: Genome) -> MotionData:
    """The motion data of an individual: gait gene ``i`` scales every field of ``genes.fields[i]`` by
    ``1 + jitter·gene``.

    A walker's pace gene scales speed and stepLength together, so its stance lasts the same number of ticks
    and its phase windows open as authored; the factor is capped where stepLength would pass the reach
    limit (``stepLimit``). Scaling speed alone, or step length alone, lets a foot lag past its reach
    before its window opens (tests/test_motion.py checks every corner of the gene box).
    """
    genes = motion.genes
    changes: dict[str, object] = {}
    for i, group in enumerate(genes.fields):
        factor = 1.0 + genes.jitter * genome.gait[i]
        if "stepLength" in group and motion.step_length > 0.0:
            factor = min(factor, motion.step_limit / motion.step_length)
        for name in group:
            changes[name] = _scaled(field_value(motion, name), factor)
    return replace_by_key(motion, changes)


def individual_size(motion: MotionData, genome: Genome) -> float:
    """The size factor of an individual: ``1 + genes.size·gene`` (1 when the spec's bound is 0)."""
    return 1.0 + float(motion.genes.size) * genome.size


def _scaled(value: object, factor: float) -> object:
    """A number, or a tuple of them (nested element by element), times ``factor``."""
    if isinstance(value, tuple):
        return tuple(_scaled(v, factor) for v in value)
    if isinstance(value, int | float) and not isinstance(value, bool):
        return value * factor
    raise TypeError(f"a gene scales numbers, not {type(value).__name__}")


def _sized(item: JsonRecord, names: tuple[str, ...], size: float) -> dict[str, object]:
    return {name: _scaled(field_value(item, name), size) for name in names}


def express_size(motion: MotionData, size: float) -> MotionData:
    """The motion data of an individual of ``size``: every length ``motion.lengths`` names (top-level, and
    per leg, rope and wing) times ``size``, nested tuples element by element, and every speed times
    √size (Froude similarity, motion/rig.py SIZED_FIELDS)."""
    names = motion.lengths
    changes: dict[str, object] = {}
    for name in names.speeds:
        changes[name] = _scaled(field_value(motion, name), math.sqrt(size))
    changes.update(_sized(motion, names.top, size))
    changes["legs"] = tuple(replace_by_key(leg, _sized(leg, names.legs, size)) for leg in motion.legs)
    changes["ropes"] = tuple(replace_by_key(rope, _sized(rope, names.ropes, size)) for rope in motion.ropes)
    changes["wings"] = tuple(replace_by_key(wing, _sized(wing, names.wings, size)) for wing in motion.wings)
    return replace_by_key(motion, changes)


def express(motion: MotionData, genome: Genome) -> MotionData:
    """The motion data of an individual: its size first, then its gait genes (core/genome.js express)."""
    return express_gait(express_size(motion, individual_size(motion, genome)), genome)
