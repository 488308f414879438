"""Rig compile: a validated CharacterSpec becomes a slot table and a blend program.

The slot table is one float64 row per slot, ``a.xyz, ra, b.xyz, rb, k, r, g, b`` (model/layout.py), in
canonical order (model/graph.py). Problems the gate cannot see because they only appear once geometry is
laid out and scaled (nested cone ends, a blend width that overflows or swallows the body) raise
RigCompileError naming the part or node.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model import layout as col
from ..model.graph import BlendGraph, Combine, Expr, Key, PartLeaf, flatten, subtree_key
from ..spec import CharacterSpec, SpecError
from ..spec.character import Part
from .colour import DEFAULT_COLOR, hex_to_linear
from .layout import origins, part_slots

#: Default leaf blend width as a fraction of the part radius (seed: k = 0.6·r, capped by kCap).
DEFAULT_K_FACTOR = 0.6
#: A blend width beyond this multiple of the body size no longer blends parts; it inflates the body.
MAX_K_BODY_FACTOR = 4.0


#: The largest body the compiler accepts, m: every downstream figure (lattice, envelope, JSON) stays finite.
MAX_BODY_M = 1.0e4
#: A step or hop length or height beyond this many body sizes is no gait the envelope can measure (a
#: valid stepHeight of 1e308 divided by zero downstream); a flea's jump is about 100 body lengths.
MAX_STRIDE_BODY_FACTOR = 200.0


#: The thinnest radius and blend width the compiler accepts, as a fraction of the body size: below it the
#: blend arithmetic overflows (a valid r of 1e-300 printed numpy warnings) and no lattice resolves the part.
MIN_BODY_FRACTION = 1.0e-4


def _thin_errors(table: np.ndarray, slot_parts: tuple[str, ...], body: float) -> list[SpecError]:
    """Radii and leaf blend widths of at least MIN_BODY_FRACTION of the body size, once per part."""
    floor = MIN_BODY_FRACTION * body
    errors: list[SpecError] = []
    seen: set[str] = set()
    for row, part in enumerate(slot_parts):
        if part in seen:
            continue
        for field, value in (("r", min(table[row, col.RA], table[row, col.RB])), ("k", table[row, col.K])):
            if value < floor:
                errors.append(
                    SpecError(
                        f"part.{part}.{field}",
                        f"{value:.6g} m is less than {MIN_BODY_FRACTION:g} of the body size ({body:.6g} m)",
                    )
                )
                seen.add(part)
                break
    return errors


def _motion_errors(spec: CharacterSpec, body: float) -> list[SpecError]:
    """Step and hop lengths and heights within MAX_STRIDE_BODY_FACTOR body sizes (after scale)."""
    loco = spec.locomotion
    errors = []
    for name in ("stepLength", "stepHeight", "hopLength", "hopHeight"):
        value = getattr(loco, name, None) if loco is not None else None
        if value is not None and value * spec.scale > MAX_STRIDE_BODY_FACTOR * body:
            errors.append(
                SpecError(
                    f"locomotion.{name}",
                    f"{value * spec.scale:.6g} m is more than {MAX_STRIDE_BODY_FACTOR:g}x the body size "
                    f"({body:.6g} m)",
                )
            )
    return errors


class RigCompileError(Exception):
    """Every compile problem at once, each named like a spec error."""

    def __init__(self, errors: list[SpecError]) -> None:
        self.errors = errors
        super().__init__("\n".join(str(e) for e in errors))


@dataclass(frozen=True)
class CompiledRig:
    """What every later stage consumes: pure data, no spec objects."""

    slots: np.ndarray  # (S, 12) float64, canonical order
    slot_classes: tuple[str, ...]
    slot_parts: tuple[str, ...]  # owning part id per slot (diagnostics and naming only)
    graph: BlendGraph
    body_scale: float  # L: largest extent of the rest AABB, metres

    @property
    def slot_count(self) -> int:
        return int(self.slots.shape[0])


def effective_k(part: Part, scale: float) -> float:
    """The leaf's blend width: its k, else 0.6·r, capped by kCap; scaled like every length."""
    k = part.k if part.k is not None else DEFAULT_K_FACTOR * part.r
    if part.kCap is not None:
        k = min(k, part.kCap)
    return k * scale


def _declared_roots(spec: CharacterSpec, part_key: dict[str, Key]) -> list[Expr]:
    blend = spec.blend
    assert blend is not None
    if blend.mode == "tree":
        nodes = {n.id: n for n in blend.nodes}

        def tree_ref(part: str | None, node: str | None) -> Expr:
            if part is not None:
                return PartLeaf(part)
            n = nodes[str(node)]
            children = (tree_ref(n.left.part, n.left.node), tree_ref(n.right.part, n.right.node))
            return Combine("poly", children, n.k * spec.scale, f"blend.nodes.{n.id}")

        return [tree_ref(r.part, r.node) for r in blend.roots]
    groups = {g.id: g for g in blend.groups}

    def group_ref(part: str | None, node: str | None) -> Expr:
        if part is not None:
            return PartLeaf(part)
        g = groups[str(node)]
        members = [group_ref(m.part, m.node) for m in g.members]
        members.sort(key=lambda e: subtree_key(e, part_key))
        return Combine("lse", tuple(members), g.k * spec.scale, f"blend.groups.{g.id}")

    return [group_ref(r.part, r.node) for r in blend.roots]


def _default_roots(spec: CharacterSpec, part_key: dict[str, Key], part_k: dict[str, float]) -> list[Expr]:
    """The graph a spec without ``blend`` gets: each part absorbs its children's subtrees.

    Children join in the order of their geometry keys with k = min(k of the part, k of the child), so a
    thin, kCap-limited child stays crisp; parentless parts are roots in key order. Only geometry and the
    parent structure decide, never ids or the array order.
    """
    children: dict[str | None, list[str]] = {}
    for part in spec.parts:
        children.setdefault(part.parent, []).append(part.id)

    def subtree(pid: str) -> Expr:
        acc: Expr = PartLeaf(pid)
        kids = sorted((subtree(c) for c in children.get(pid, [])), key=lambda e: subtree_key(e, part_key))
        for kid in kids:
            head = kid.part if isinstance(kid, PartLeaf) else _first_part(kid)
            k = min(part_k[pid], part_k[head])
            acc = Combine("poly", (acc, kid), k, f"part.{head}")
        return acc

    roots = [subtree(pid) for pid in children.get(None, [])]
    return sorted(roots, key=lambda e: subtree_key(e, part_key))


def _first_part(expr: Expr) -> str:
    while isinstance(expr, Combine):
        expr = expr.children[0]
    return expr.part


def _geometry_errors(spec: CharacterSpec, rows: dict[str, np.ndarray]) -> list[SpecError]:
    errors = []
    if not all(np.isfinite(r).all() for r in rows.values()):
        return [SpecError("scale", f"scaled geometry is not finite (scale {spec.scale:g})")]
    for part in spec.parts:
        for a_x, ra, b_x, rb in ((r[0:3], r[3], r[4:7], r[7]) for r in rows[part.id]):
            length = float(np.linalg.norm(b_x - a_x))
            if part.shape != "sphere" and abs(ra - rb) >= length:
                field = "taper" if part.shape == "rope" else "r2"
                errors.append(
                    SpecError(
                        f"part.{part.id}.{field}",
                        f"the end spheres nest (|ra - rb| = {abs(ra - rb):.6g} >= length {length:.6g}); "
                        "use a sphere or a longer segment",
                    )
                )
                break
    return errors


def _k_errors(
    graph: BlendGraph, slot_k: np.ndarray, slot_parts: tuple[str, ...], body: float
) -> list[SpecError]:
    limit = MAX_K_BODY_FACTOR * body
    errors = []
    widths = [(op.place, op.k) for op in graph.ops] + [
        (f"part.{p}", float(k)) for p, k in zip(slot_parts, slot_k, strict=True)
    ]
    seen: set[str] = set()
    for place, k in widths:
        if place in seen:
            continue
        if not math.isfinite(k) or k <= 0:
            errors.append(
                SpecError(f"{place}.k", f"blend width {k:g} is not a positive finite number once scaled")
            )
            seen.add(place)
        elif k > limit:
            errors.append(
                SpecError(
                    f"{place}.k",
                    f"blend width {k:.6g} m exceeds {MAX_K_BODY_FACTOR:g}x the body size ({body:.6g} m)",
                )
            )
            seen.add(place)
    return errors


def compile_rig(spec: CharacterSpec) -> CompiledRig:
    """Lay out, order and check the slots of a validated spec."""
    origin = origins(spec)
    rows: dict[str, np.ndarray] = {}
    classes: dict[str, tuple[str, ...]] = {}
    for part in spec.parts:
        laid = part_slots(part, origin[part.id])
        rows[part.id] = laid.geometry * spec.scale
        classes[part.id] = laid.classes
    errors = _geometry_errors(spec, rows)
    if errors:
        raise RigCompileError(errors)

    part_k = {p.id: effective_k(p, spec.scale) for p in spec.parts}
    colours = {p.id: hex_to_linear(p.color or DEFAULT_COLOR) for p in spec.parts}
    part_key = {p.id: (*rows[p.id].ravel().tolist(), part_k[p.id], *colours[p.id]) for p in spec.parts}
    roots = (
        _declared_roots(spec, part_key) if spec.blend is not None else _default_roots(spec, part_key, part_k)
    )

    unordered: list[tuple[str, int]] = [(p.id, j) for p in spec.parts for j in range(len(rows[p.id]))]
    index_of = {entry: i for i, entry in enumerate(unordered)}
    slots_of_part = {p.id: [index_of[(p.id, j)] for j in range(len(rows[p.id]))] for p in spec.parts}
    graph, order = flatten(roots, slots_of_part, part_k)

    table = np.zeros((len(order), col.WIDTH), dtype=np.float64)
    slot_parts: list[str] = []
    slot_classes: list[str] = []
    for row, raw in enumerate(order):
        pid, j = unordered[raw]
        table[row, 0:8] = rows[pid][j]
        table[row, col.K] = part_k[pid]
        table[row, col.RGB] = colours[pid]
        slot_parts.append(pid)
        slot_classes.append(classes[pid][j])

    body = body_scale(table)
    if not math.isfinite(body) or body > MAX_BODY_M:
        biggest = slot_parts[int(np.argmax(np.maximum(table[:, col.RA], table[:, col.RB])))]
        raise RigCompileError(
            [
                SpecError(
                    f"part.{biggest}",
                    f"the body spans {body:.6g} m, more than {MAX_BODY_M:g} m: a smaller part or scale",
                )
            ]
        )
    errors = _k_errors(graph, table[:, col.K], tuple(slot_parts), body) + _motion_errors(spec, body)
    errors += _thin_errors(table, tuple(slot_parts), body)
    if errors:
        raise RigCompileError(errors)
    return CompiledRig(table, tuple(slot_classes), tuple(slot_parts), graph, body)


def body_scale(slots: np.ndarray) -> float:
    """L, the largest extent of the rest AABB of all slots (their spheres included)."""
    lo = np.minimum(slots[:, col.A] - slots[:, [col.RA]], slots[:, col.B] - slots[:, [col.RB]]).min(axis=0)
    hi = np.maximum(slots[:, col.A] + slots[:, [col.RA]], slots[:, col.B] + slots[:, [col.RB]]).max(axis=0)
    with np.errstate(over="ignore"):  # an infinite span is refused by name in compile_rig
        return float((hi - lo).max())
