"""Plain-data account of a compiled rig for ``creaturegen inspect --json`` and build reports."""

from __future__ import annotations

from dataclasses import asdict
from typing import Any

from ..field.floors import floors_for
from ..field.primitives import slot_uses_round_cone
from ..model import layout as col
from .compile import CompiledRig
from .signatures import compiler_description, signatures


def describe_rig(rig: CompiledRig) -> dict[str, Any]:
    exact = slot_uses_round_cone(rig.slots)
    slots = [
        {
            "index": i,
            "part": rig.slot_parts[i],
            "class": rig.slot_classes[i],
            "kernel": "round-cone" if exact[i] else "tapered-capsule",
            "a": row[col.A].tolist(),
            "ra": float(row[col.RA]),
            "b": row[col.B].tolist(),
            "rb": float(row[col.RB]),
            "k": float(row[col.K]),
            "rgbLinear": row[col.RGB].tolist(),
        }
        for i, row in enumerate(rig.slots)
    ]
    ops = [
        {
            "index": i,
            "kernel": op.kernel,
            "k": op.k,
            "from": op.place,
            "children": [{"kind": c.kind, "index": c.index} for c in op.children],
        }
        for i, op in enumerate(rig.graph.ops)
    ]
    return {
        "slotCount": rig.slot_count,
        "bodyScale": rig.body_scale,
        "floors": asdict(floors_for(rig.body_scale)),
        "slots": slots,
        "blend": {"ops": ops, "roots": [{"kind": r.kind, "index": r.index} for r in rig.graph.roots]},
        "compiler": compiler_description(rig),
        "signatures": asdict(signatures(rig)),
    }
