"""The excursion the certificates assume: how far each slot may move from its rest position.

It is the measured pose envelope (motion/envelope.py: the creature's own locomotion stepped over whole
cycles for the corners of its gait-gene box, on every built-in support), widened by its stated margin,
per slot. Whole-body rigid motion (root translation and yaw, the flyer's bank, the swimmer's yaw wave)
is taken out, since it moves no slot relative to another; the hopper's squash is applied by the root
transform after the field, skin and correction, so it moves no slot either.

This replaced a model assumed before locomotion existed (a leg's whole reach, a rope's length, a flap's
chord, a squash ratio, inherited down the parts), which the measured motion broke: rope tails swing their
tips up to twice their length from rest, past the ball the certificates had assumed.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..motion.envelope import pose_envelope
from ..rig import CompiledRig
from ..spec import CharacterSpec


def slot_excursions(spec: CharacterSpec, rig: CompiledRig) -> npt.NDArray[np.float64]:
    """Per-slot excursion radius (S,), metres."""
    return pose_envelope(spec, rig).slot_excursion
