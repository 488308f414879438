"""Blend programs as tapes: the instruction list the runtime's field loop interprets.

A candidate program (or the full graph) is a small DAG of smooth-min ops over slot leaves. The GPU runs
it as a straight list of instructions whose register ``i`` is the result of instruction ``i``, so one
dynamic loop bounded by the program's own length evaluates it: no per-graph shader text, no masked
full-budget unroll, and every region's program shares one pipeline. The LEAF instructions lead the
tape, so the runtime runs them in a loop of their own (the header carries their count). Each
instruction is four floats ``(op, a, b, k)`` (small integers are exact in float32):

- ``LEAF``  slot ``a``'s distance and gradient (a global slot index into the pose page);
- ``POLY``  polynomial smooth-min of registers ``a`` (left) and ``b`` (right), width ``k``;
- ``COPY``  register ``a`` again: n-ary members are copied next to each other before an ``LSE``;
- ``LSE``   log-sum-exp over the ``b`` registers starting at ``a``, width ``k``;
- ``MIN``   hard min of registers ``a`` and ``b``, ``b`` winning only when strictly smaller (argmin's
  first occurrence, as ``blend.hard_min`` breaks ties).

The operand orders are exactly those of field/sampler.py, so the interpreter computes the reference's
formulas in the reference's order.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

from ..model.graph import BlendGraph, Ref

LEAF: Final = 0
POLY: Final = 1
COPY: Final = 2
LSE: Final = 3
MIN: Final = 4


@dataclass(frozen=True)
class Tape:
    """One program's instructions, each ``(op, a, b, k)``; the result is the last register."""

    instructions: tuple[tuple[int, int, int, float], ...]
    leaves: tuple[int, ...]  # global slot indices, in LEAF order

    def __len__(self) -> int:
        return len(self.instructions)

    @property
    def leaf_count(self) -> int:
        """The LEAF instructions, which lead the tape (the runtime's header carries the count)."""
        return len(self.leaves)


def compile_tape(graph: BlendGraph, leaves: tuple[int, ...] | None = None) -> Tape:
    """The tape of ``graph``; ``leaves`` maps its slot refs to global slot indices (identity if None)."""
    code: list[tuple[int, int, int, float]] = []
    slot_register: dict[int, int] = {}
    op_register: dict[int, int] = {}
    order = leaves if leaves is not None else tuple(range(_slot_count(graph)))

    def register(ref: Ref) -> int:
        if ref.kind == "slot":
            if ref.index not in slot_register:
                code.append((LEAF, order[ref.index], 0, 0.0))
                slot_register[ref.index] = len(code) - 1
            return slot_register[ref.index]
        if ref.index not in op_register:
            op = graph.ops[ref.index]
            kids = [register(c) for c in op.children]
            if op.kernel == "poly":
                code.append((POLY, kids[0], kids[1], float(op.k)))
            else:
                first = len(code)
                code.extend((COPY, kid, 0, 0.0) for kid in kids)
                code.append((LSE, first, len(kids), float(op.k)))
            op_register[ref.index] = len(code) - 1
        return op_register[ref.index]

    roots = [register(r) for r in graph.roots]
    if not roots:
        raise ValueError("the blend graph has no roots")
    acc = roots[0]
    for root in roots[1:]:
        code.append((MIN, acc, root, 0.0))
        acc = len(code) - 1
    if acc != len(code) - 1:  # a lone root evaluated earlier than the last instruction
        code.append((COPY, acc, 0, 0.0))
    leaf_order = tuple(order[i] for i in sorted(slot_register, key=slot_register.__getitem__))
    return Tape(_leaves_first(code), leaf_order)


def _leaves_first(code: list[tuple[int, int, int, float]]) -> tuple[tuple[int, int, int, float], ...]:
    """``code`` with its LEAF instructions first, each group in its own order, operands renumbered.

    The runtime then fills the leaf registers in one loop that runs only the slot formula and the blends in a
    second that never does: a GPU lane (and SwiftShader's CPU lanes, which run every branch of an ``if`` under
    a mask) otherwise pays for the slot formula at every blend instruction too. Every operand still names an
    earlier register, an ``LSE``'s copies stay contiguous (no leaf sits between them) and the leaves keep
    their order, so each register holds the same value and the colour sums run in the same order.
    """
    leaves = [i for i, ins in enumerate(code) if ins[0] == LEAF]
    blends = [i for i, ins in enumerate(code) if ins[0] != LEAF]
    moved = {old: new for new, old in enumerate(leaves + blends)}
    out = [code[i] for i in leaves]
    for i in blends:
        op, a, b, k = code[i]
        out.append((op, moved[a], b if op in (LSE, COPY) else moved[b], k))
    return tuple(out)


def _slot_count(graph: BlendGraph) -> int:
    seen = [c.index for op in graph.ops for c in op.children if c.kind == "slot"]
    seen += [r.index for r in graph.roots if r.kind == "slot"]
    return max(seen) + 1
