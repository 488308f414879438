"""Plausible random creatures: the project's own corpus, so the compiler is tuned against creatures nobody
here wrote rather than against a handful of examples.

A spec is drawn from one seed by a body plan per locomotion type (a walker's torso on legs, an upright
biped with arms, a hopper's round body, a flyer's wings, a swimmer's fins and tail, a still creature), then
features a designer reaches for: heads on necks, eyes, ears and horns on heads (small parts on big ones),
snouts, rope tails, tapered and thick limbs, 8-legged walkers; the default blend graph, an explicit binary
tree or n-ary groups; sizes from 0.1 to 5 (the spec's ``scale``). Everything is placed in creature space
first and written relative to the parent's anchor, the way the spec's rest layout reads it
(rig/layout.py), so the numbers look like hand-written ones. Pure: the same seed gives the same JSON.

This module draws the locomotion type, palette, scale, gait and blend style and assembles the spec; the
body plans are in corpus/plans/ (one module per locomotion type), the features in corpus/features.py, the
blend graphs in corpus/blends.py and the creature under construction in corpus/creature.py.
"""

from __future__ import annotations

import math
import random
from typing import Any

from .blends import nary_blend, tree_blend
from .creature import Creature
from .plans.biped import biped
from .plans.flyer import flyer
from .plans.hopper import hopper
from .plans.still import still
from .plans.swimmer import swimmer
from .plans.walker import walker

#: Locomotion types the generator draws from (``random --locomotion``), with their share of a corpus.
LOCOMOTION_WEIGHTS: dict[str, float] = {
    "biped": 0.15,
    "quadruped": 0.2,
    "hexapod": 0.1,
    "octopod": 0.08,
    "hopper": 0.12,
    "flyer": 0.12,
    "swimmer": 0.13,
    "none": 0.1,
}
#: The spec's ``scale`` is drawn log-uniformly in this range (metres per authored unit).
SCALE_RANGE = (0.1, 5.0)
#: Part counts the generator aims for (features are added until the count is in range).
PART_RANGE = (4, 24)
PALETTES = (
    ("#6f9a54", "#8dbb6a", "#556f3f", "#d9c27a"),
    ("#7f8fba", "#ddad77", "#5a6485", "#f0e6d0"),
    ("#b5653a", "#e0b06e", "#7b4a2c", "#2b2b2b"),
    ("#5db4d1", "#d8b58c", "#2f6f8a", "#f5f5f5"),
    ("#8a8a8a", "#c0c0c0", "#4d4d4d", "#e8d44d"),
    ("#a05fa8", "#e5a1c9", "#5e2f66", "#fff3a0"),
    ("#3b5f8f", "#2c3e55", "#d9d2c0", "#c04040"),
    ("gray", "#ddd", "DarkSlateGray", "gold"),
    ("sienna", "wheat", "saddlebrown", "black"),
    ("seagreen", "palegreen", "darkolivegreen", "#fff"),
)


def _locomotion(kind: str, c: Creature, rng: random.Random) -> dict[str, Any] | None:
    size = max(
        abs(v)
        for p in c.parts.values()
        for key in ("a", "b", "offset", "hip")
        for v in (p.data.get(key) or [0.0])
    )
    if kind in ("biped", "quadruped", "hexapod", "octopod"):
        legs = [p.data for p in c.parts.values() if p.data["shape"] == "leg"]
        reach = min(leg["upper"] + leg["lower"] for leg in legs)
        return {
            "type": kind,
            "speed": round(rng.uniform(0.3, 1.4), 3),
            "stepLength": round(reach * rng.uniform(0.35, 0.7), 3),
            "stepHeight": round(reach * rng.uniform(0.1, 0.25), 3),
        }
    if kind == "hopper":
        return {
            "type": "hopper",
            "speed": round(rng.uniform(0.4, 1.2), 3),
            "hopLength": round(rng.uniform(0.4, 1.4), 3),
            "hopHeight": round(rng.uniform(0.3, 1.0), 3),
        }
    if kind == "flyer":
        return {
            "type": "flyer",
            "speed": round(rng.uniform(0.5, 1.5), 3),
            "altitude": round(rng.uniform(1.0, 3.0), 3),
            "radius": round(rng.uniform(1.0, 3.0) + size, 3),
        }
    if kind == "swimmer":
        return {
            "type": "swimmer",
            "speed": round(rng.uniform(0.3, 1.0), 3),
            "undulation": round(rng.uniform(0.1, 0.4), 3),
            "buoyancy": round(rng.uniform(0.85, 1.1), 3),
        }
    return None


def random_creature(seed: int, locomotion: str | None = None) -> dict[str, Any]:
    """One plausible creature spec (a JSON-ready dict) drawn from ``seed``; ``locomotion`` pins its type."""
    rng = random.Random(seed)
    kinds = list(LOCOMOTION_WEIGHTS)
    kind = locomotion or rng.choices(kinds, weights=[LOCOMOTION_WEIGHTS[k] for k in kinds])[0]
    if kind not in LOCOMOTION_WEIGHTS:
        raise ValueError(f"unknown locomotion {kind!r} (known: {', '.join(kinds)})")
    c = Creature(rng, rng.choice(PALETTES))
    if kind in ("quadruped", "hexapod", "octopod"):
        legs = {"quadruped": 4, "hexapod": 6, "octopod": 8}[kind]
        walker(c, legs, insect=legs >= 6 or rng.random() < 0.15)
    elif kind == "biped":
        biped(c)
    elif kind == "hopper":
        hopper(c)
    elif kind == "flyer":
        flyer(c)
    elif kind == "swimmer":
        swimmer(c)
    else:
        still(c)
    spec: dict[str, Any] = {
        "name": f"Random {kind.capitalize()} {seed}",
        "seed": seed % (2**32),
        "scale": round(math.exp(rng.uniform(math.log(SCALE_RANGE[0]), math.log(SCALE_RANGE[1]))), 3),
    }
    loco = _locomotion(kind, c, rng)
    if loco is not None:
        spec["locomotion"] = loco
    spec["parts"] = [p.data for p in c.parts.values()]
    style = rng.random()
    if style < 0.2:
        spec["blend"] = tree_blend(c)
    elif style < 0.35:
        spec["blend"] = nary_blend(c)
    return spec
