"""Cache identities of a compiled creature: compilerSignature, topologySignature, geometryDigest.

Each is the sha256 hex of a canonical JSON (sorted keys, no whitespace) or of float64 little-endian
bytes; never a 32-bit hash. What goes into each:
- compilerSignature: versions, kernels, numeric mode, thresholds and floors: how the numbers are made.
- topologySignature: the blend program's shape (kernels, arity, nesting) and the slot classes: what the
  generated evaluation code looks like. Ids, names and colours stay out.
- geometryDigest: the rest geometry values only (a, ra, b, rb, k per slot, in canonical order).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass

import numpy as np

from .. import __version__
from ..field.floors import floors_for
from ..field.primitives import TAPER_EXACT_THRESHOLD
from ..model import layout as col
from .compile import DEFAULT_K_FACTOR, CompiledRig
from .layout import LEG_DROP_MAX, LEG_DROP_MIN

#: Bumped when the meaning of a spec field changes.
SCHEMA_VERSION = 1
#: Bumped when the rest layout, the blend program or the field formulas change.
COMPILER_VERSION = 1

KERNELS = {
    "tree": "quilez-polynomial-smin",
    "nary": "stabilised-log-sum-exp",
    "roots": "hard-min",
    "primitive": "tapered-capsule/exact-round-cone",
    "gradient": "analytic",
    "colour": "proximity-exp",
}


@dataclass(frozen=True)
class Signatures:
    compilerSignature: str  # noqa: N815 - the name used across Python, JS and reports
    topologySignature: str  # noqa: N815
    geometryDigest: str  # noqa: N815


def _sha(text: str | bytes) -> str:
    return hashlib.sha256(text.encode() if isinstance(text, str) else text).hexdigest()


def _canonical(data: object) -> str:
    return json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False)


def compiler_description(rig: CompiledRig) -> dict[str, object]:
    return {
        "schemaVersion": SCHEMA_VERSION,
        "compilerVersion": COMPILER_VERSION,
        "creaturegen": __version__,
        "kernels": KERNELS,
        "numericMode": "float64",
        "taperExactThreshold": TAPER_EXACT_THRESHOLD,
        "defaultKFactor": DEFAULT_K_FACTOR,
        "legDrop": [LEG_DROP_MIN, LEG_DROP_MAX],
        "floors": asdict(floors_for(rig.body_scale)),
    }


def topology_description(rig: CompiledRig) -> dict[str, object]:
    return {"program": rig.graph.structure(), "slotClasses": list(rig.slot_classes)}


def signatures(rig: CompiledRig) -> Signatures:
    geometry = np.ascontiguousarray(rig.slots[:, : col.K + 1], dtype="<f8")
    return Signatures(
        compilerSignature=_sha(_canonical(compiler_description(rig))),
        topologySignature=_sha(_canonical(topology_description(rig))),
        geometryDigest=_sha(geometry.shape[0].to_bytes(4, "little") + geometry.tobytes()),
    )
