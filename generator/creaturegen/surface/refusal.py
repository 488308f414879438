"""Refusing a surface: the first failed gate, its value and threshold, the part, and what the user can change.

Every stage of the surface build calls ``fail_on`` with its gates and, where one exists, the remedy to
suggest; the message is the one line the CLI prints with exit 3.
"""

from __future__ import annotations

from .gates import SurfaceGate
from .sidecar import gate_from_row, posed_gate_rows

#: What a refusal of the posed skin (surface/posed.py) tells the user: the motion carries a limb's skin
#: into a fold or through another sheet where the body has none.
POSED_REMEDY = (
    "; the motion presses this skin into itself at that pose: a smaller turn there (a shorter step or hop, "
    "a gentler slope run), a thinner limb at its joint, or more room between the limb and the part it "
    "swings against keeps the skin clear"
)


class SurfaceRejectedError(Exception):
    """A gate failed; the message names the gate, its value, its threshold and the part."""


def fail_on(gates: list[SurfaceGate], where: str, remedy: str = "") -> None:
    failed = [g for g in gates if not g.passed]
    if failed:
        g = failed[0]
        more = f" (also failed: {', '.join(f.name for f in failed[1:])})" if len(failed) > 1 else ""
        detail = f": {g.detail}" if g.detail else ""
        raise SurfaceRejectedError(
            f"{where}: gate {g.name} = {g.value:.4g} {g.unit}, "
            f"threshold {g.threshold:.4g} ({g.direction}){detail}{more}{remedy}"
        )


def mesh_remedy(gates: list[SurfaceGate], certain: bool, refinement: int, spacing: float) -> str:
    """What the build tried for a failed mesh gate, and what the user can change (the gate names the
    place). A wrong genus gets no flips or splits (they cannot change it), and its detail already names
    the contacts to move, so widening a blend would be the wrong advice there."""
    where = f"refinement {refinement} at h = {spacing:.3g} m"
    if any(g.name == "euler" and not g.passed for g in gates):
        if certain:
            return (
                f" (at {where}; the field closes these handles at any lattice): move or shrink the parts "
                "named so they meet only at their joints"
            )
        return (
            f"; refining the lattice did not open the handles (the finest lattice tried, {where}, is "
            "reported): move or shrink the parts named so they meet only at their joints"
        )
    return (
        f"; flipping edges, splitting triangles toward the field and refining the lattice did not help "
        f"(the best lattice tried, {where}, is reported): a feature there is thinner or tighter than the "
        "lattice resolves; thicken the part named, or widen the blend k (or the gap) where it meets its "
        "neighbour"
    )


def refuse_posed(sidecar: dict[str, object], tier: str) -> None:
    """Raise SurfaceRejectedError when a posed-skin gate failed. The gates are recorded, not enforced by
    the build: the caller asks for this (``creaturegen build --posed-gates refuse``)."""
    fail_on([gate_from_row(r) for r in posed_gate_rows(sidecar)], f"surface {tier} posed skin", POSED_REMEDY)
