"""The blend graph as an evaluation program: slots are leaves, ops are smooth-min nodes in post-order.

Canonical order is the point of this module. Slots are numbered in leaf-visit order and ops in
post-order of a traversal whose choices come from the declared structure (left before right, roots as
declared) or, where the spec leaves a choice open (n-ary members, the default graph), from geometry
keys. Part ids and the parts array order never decide anything, so renaming or permuting parts gives
the same program and bit-identical evaluation.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Literal

Kernel = Literal["poly", "lse"]


@dataclass(frozen=True)
class Ref:
    """An op's operand: a slot (leaf primitive) or an earlier op."""

    kind: Literal["slot", "op"]
    index: int


@dataclass(frozen=True)
class BlendOp:
    """One smooth-min. ``poly`` has two children (left, right); ``lse`` has two or more."""

    kernel: Kernel
    children: tuple[Ref, ...]
    k: float
    place: str  # where the op came from, for errors: blend.nodes.<id>, blend.groups.<id>, part.<id>


@dataclass(frozen=True)
class BlendGraph:
    ops: tuple[BlendOp, ...]  # children always precede parents
    roots: tuple[Ref, ...]  # combined by hard min

    def structure(self) -> object:
        """Id-free nested description of the program (kernels and arity), for the topologySignature."""

        def describe(ref: Ref) -> object:
            if ref.kind == "slot":
                return ref.index
            op = self.ops[ref.index]
            return [op.kernel, [describe(c) for c in op.children]]

        return [describe(r) for r in self.roots]


# --- part-level expressions, before multi-slot parts are expanded -------------------------------


@dataclass(frozen=True)
class PartLeaf:
    part: str


@dataclass(frozen=True)
class Combine:
    kernel: Kernel
    children: tuple[Expr, ...]
    k: float
    place: str


Expr = PartLeaf | Combine
Key = tuple[float, ...]


def leaves(expr: Expr) -> list[str]:
    if isinstance(expr, PartLeaf):
        return [expr.part]
    return [p for c in expr.children for p in leaves(c)]


def subtree_key(expr: Expr, part_key: dict[str, Key]) -> Key:
    """A geometry-only sort key for a subtree: its parts' keys, sorted and concatenated."""
    return tuple(itertools.chain.from_iterable(sorted(part_key[p] for p in leaves(expr))))


@dataclass
class _Flattener:
    """Walks part-level expressions in canonical order and emits slots and ops."""

    part_slots: dict[str, list[int]]  # part -> indices into the caller's unordered slot list
    part_k: dict[str, float]
    slot_order: list[int]
    ops: list[BlendOp]

    def emit(self, expr: Expr) -> Ref:
        if isinstance(expr, PartLeaf):
            return self._part(expr.part)
        children = tuple(self.emit(c) for c in expr.children)
        self.ops.append(BlendOp(expr.kernel, children, expr.k, expr.place))
        return Ref("op", len(self.ops) - 1)

    def _part(self, part: str) -> Ref:
        """A one-slot part is a leaf; ropes and legs fold their slots in chain order (a per-part subtree)."""
        refs = []
        for raw in self.part_slots[part]:
            self.slot_order.append(raw)
            refs.append(Ref("slot", len(self.slot_order) - 1))
        acc = refs[0]
        for ref in refs[1:]:
            self.ops.append(BlendOp("poly", (acc, ref), self.part_k[part], f"part.{part}"))
            acc = Ref("op", len(self.ops) - 1)
        return acc


def flatten(
    roots: list[Expr], part_slots: dict[str, list[int]], part_k: dict[str, float]
) -> tuple[BlendGraph, list[int]]:
    """The evaluation program and the canonical slot order (as indices into the unordered slot list)."""
    walker = _Flattener(part_slots, part_k, [], [])
    root_refs = tuple(walker.emit(r) for r in roots)
    return BlendGraph(tuple(walker.ops), root_refs), walker.slot_order
