"""Morphology variants: other geometry identities of one spec, drawn at build time (``build --population N``).

A spawn never changes the body's shape: its connectivity, skin weights and candidate programs belong to
the extracted mesh. A different shape is a different spec, compiled, extracted and gated like any other,
with its own geometryDigest. Identity 0 is the authored spec; identity i > 0 scales, by its genes,
- girth: every radius (``r``, ``r2``) and every authored blend width ``k`` / ``kCap`` (so blends keep their
  proportions to the parts they join);
- limbs: every leg's ``upper`` and ``lower``;
- tails: every rope's ``length``;
each by ``1 + morphology·gene``, the genes signed draws in [-1, 1) of one LCG stream from the spec
seed. The variant is written back as spec JSON, so it is validated by the same gate as a hand-written one.
"""

from __future__ import annotations

import copy
import json
from typing import Any, Final

from ..model.lcg import lcg_next

#: Genes of one identity, in draw order.
GENES: Final = ("girth", "limbs", "tails")


def identity_genes(seed: int, index: int) -> dict[str, float]:
    """Signed genes in [-1, 1) of identity ``index`` (> 0): draws 3(index-1)+1 .. 3·index of one LCG stream
    from the spec seed. (Streams seeded at seed + index·stride would be worthless: an LCG is affine, so
    their draws form an arithmetic progression across identities.)"""
    state = seed % (1 << 32)
    for _ in range(len(GENES) * (index - 1)):
        state = lcg_next(state)
    genes = {}
    for name in GENES:
        state = lcg_next(state)
        genes[name] = state / 2147483648.0 - 1.0
    return genes


def variant_document(document: dict[str, Any], index: int, bound: float) -> dict[str, Any]:
    """The spec document of identity ``index``: the authored one scaled by its genes, named "<name> m<i>"."""
    genes = identity_genes(int(document.get("seed", 0)), index)
    scale = {name: 1.0 + bound * gene for name, gene in genes.items()}
    variant = copy.deepcopy(document)
    variant["name"] = f"{document['name']} m{index}"
    for part in variant["parts"]:
        for field in ("r", "r2", "k", "kCap"):
            if part.get(field) is not None:
                part[field] = part[field] * scale["girth"]
        if part.get("shape") == "leg":
            part["upper"] *= scale["limbs"]
            part["lower"] *= scale["limbs"]
        if part.get("shape") == "rope":
            part["length"] *= scale["tails"]
    blend = variant.get("blend") or {}
    for node in [*blend.get("nodes", []), *blend.get("groups", [])]:
        node["k"] = node["k"] * scale["girth"]
    return variant


def variant_bytes(document: dict[str, Any], index: int, bound: float) -> bytes:
    """Spec JSON of identity ``index`` (deterministic: same spec, index and bound give the same bytes)."""
    return (json.dumps(variant_document(document, index, bound), indent=2) + "\n").encode()
