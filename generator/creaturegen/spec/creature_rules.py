"""Cross-field rules of a creature spec, checked on the raw JSON document.

They run on the raw document rather than on a validated model so that a bad radius in one part does not
hide a parent cycle in another: the gate reports every problem in one pass. Each rule tolerates malformed
items (wrong types are the field validator's job) and only judges what it can read.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from .character import (
    COMMON_PART_FIELDS,
    HOPPER_LEG_COUNTS,
    LEG_COUNTS,
    LOCOMOTION_FIELDS,
    SHAPE_FIELDS,
    WALKER_LEG_COUNTS,
    slots_of,
)
from .errors import SpecError, shown
from .messages import did_you_mean, number
from .places import item_place, usable_ids

DEFAULT_MAX_PARTS = 64


def _dicts(items: object) -> Iterator[tuple[int, dict[str, Any]]]:
    if isinstance(items, list):
        for i, item in enumerate(items):
            if isinstance(item, dict):
                yield i, item


def _is_number(value: object) -> bool:
    """A JSON number that is a finite float (an integer literal past float range is not one)."""
    if not isinstance(value, int | float) or isinstance(value, bool):
        return False
    try:
        return math.isfinite(float(value))
    except OverflowError:
        return False


def _vec3(value: object) -> tuple[float, ...] | None:
    if isinstance(value, list) and len(value) == 3 and all(_is_number(v) for v in value):
        return tuple(float(v) for v in value)
    return None


def duplicate_ids(raw: dict[str, Any], list_keys: tuple[str, ...]) -> list[SpecError]:
    """A repeated id is reported at each repeat, pointing at the first holder."""
    items: Any = raw
    for key in list_keys:
        items = items.get(key) if isinstance(items, dict) else None
    first: dict[str, int] = {}
    errors = []
    prefix = ".".join(list_keys)
    for i, item in _dicts(items):
        ident = item.get("id")
        if not isinstance(ident, str):
            continue
        if ident in first:
            errors.append(
                SpecError(
                    f"{prefix}[{i}].id",
                    f"duplicate id {shown(ident)} (first used by {prefix}[{first[ident]}])",
                )
            )
        else:
            first[ident] = i
    return errors


def part_fields(raw: dict[str, Any]) -> list[SpecError]:
    """Fields each shape needs and accepts, zero-length segments, and k against kCap."""
    errors = []
    for i, part in _dicts(raw.get("parts")):
        at = item_place(raw, ("parts",), i)
        shape = part.get("shape")
        if isinstance(shape, str) and shape in SHAPE_FIELDS:
            required, optional = SHAPE_FIELDS[shape]
            allowed = {*COMMON_PART_FIELDS, *required, *optional}
            errors += [
                SpecError(f"{at}.{f}", f"required for shape {shape}") for f in required if f not in part
            ]
            known = {f for fields in SHAPE_FIELDS.values() for f in (*fields[0], *fields[1])}
            errors += [
                SpecError(f"{at}.{f}", f"not used by shape {shape}")
                for f in part
                if f in known and f not in allowed
            ]
        a, b = _vec3(part.get("a")), _vec3(part.get("b"))
        if shape in ("capsule", "cone") and a is not None and a == b:
            errors.append(SpecError(f"{at}.b", "must differ from a (a zero-length segment is a sphere)"))
        k, k_cap = part.get("k"), part.get("kCap")
        if isinstance(k, int | float) and isinstance(k_cap, int | float) and k > k_cap:
            errors.append(SpecError(f"{at}.k", f"must be <= kCap ({number(k_cap)}) (got {number(k)})"))
    return errors


def parents(raw: dict[str, Any]) -> list[SpecError]:
    """Parents must exist, and the parent chain must end: a cycle has no anchor to accumulate from."""
    ids = usable_ids(raw.get("parts"))
    unique = set(ids.values())
    every_id = {p.get("id") for _, p in _dicts(raw.get("parts")) if isinstance(p.get("id"), str)}
    parent_of: dict[str, str] = {}
    errors = []
    for i, part in _dicts(raw.get("parts")):
        parent = part.get("parent")
        if not isinstance(parent, str):
            continue
        at = item_place(raw, ("parts",), i)
        if parent not in every_id:
            known = {i for i in every_id if isinstance(i, str)}
            errors.append(
                SpecError(f"{at}.parent", f"unknown part {shown(parent)}" + did_you_mean(parent, known))
            )
        elif i in ids and parent in unique:
            parent_of[ids[i]] = parent
    for cycle in _cycles({part: [parent] for part, parent in parent_of.items()}):
        loop = _rotated_loop(cycle)
        errors.append(SpecError(f"part.{loop[0]}.parent", "parent cycle " + _loop_text(loop)))
    return errors


def locomotion(raw: dict[str, Any]) -> list[SpecError]:
    """Fields each locomotion type needs and accepts, and the leg count it drives."""
    loco = raw.get("locomotion")
    if not isinstance(loco, dict) or not isinstance(loco.get("type"), str):
        return []
    if loco["type"] not in LOCOMOTION_FIELDS:
        return []
    kind = str(loco["type"])
    needed = LOCOMOTION_FIELDS[kind]
    every = {f for fields in LOCOMOTION_FIELDS.values() for f in fields}
    errors = [SpecError(f"locomotion.{f}", f"required for type {kind}") for f in needed if f not in loco]
    errors += [
        SpecError(f"locomotion.{f}", f"not used by type {kind}")
        for f in loco
        if f in every and f not in needed
    ]
    legs = sum(1 for _, p in _dicts(raw.get("parts")) if p.get("shape") == "leg")
    if kind in LEG_COUNTS and legs != LEG_COUNTS[kind]:
        errors.append(
            SpecError("locomotion.type", f"{kind} needs {LEG_COUNTS[kind]} leg parts, the spec has {legs}")
        )
    if kind == "hopper" and legs not in HOPPER_LEG_COUNTS:
        errors.append(
            SpecError(
                "locomotion.type",
                f"hopper needs {' or '.join(map(str, HOPPER_LEG_COUNTS))} leg parts (2: the two hind legs "
                f"it hops on, as a kangaroo's or a frog's), the spec has {legs}",
            )
        )
    if kind == "walker" and legs not in WALKER_LEG_COUNTS:
        low, high = WALKER_LEG_COUNTS[0], WALKER_LEG_COUNTS[-1]
        errors.append(
            SpecError(
                "locomotion.type",
                f"walker needs an even number of leg parts from {low} to {high}, the spec has {legs}",
            )
        )
    return errors


def slot_budget(raw: dict[str, Any]) -> list[SpecError]:
    """Compiled slots must fit the per-creature capacity of a pose page."""
    total = 0
    for _, part in _dicts(raw.get("parts")):
        segments = part.get("segments")
        total += slots_of(str(part.get("shape")), segments if isinstance(segments, int) else None)
    cap = raw.get("maxParts", DEFAULT_MAX_PARTS)
    if isinstance(cap, int) and not isinstance(cap, bool) and total > cap:
        return [SpecError("maxParts", f"the parts compile to {total} slots, more than maxParts {cap}")]
    return []


@dataclass
class _BlendGraph:
    """The declared blend graph as read from the raw document."""

    node_place: dict[str, str] = field(default_factory=dict)
    children: dict[str, list[tuple[str, str]]] = field(default_factory=dict)
    roots: list[tuple[str, tuple[str, str]]] = field(default_factory=list)
    uses: dict[tuple[str, str], list[str]] = field(default_factory=lambda: defaultdict(list))


def _read_ref(
    ref: object, at: str, parts: set[str], nodes: set[str], errors: list[SpecError]
) -> tuple[str, str] | None:
    """Resolve one ``{part}``/``{node}`` ref, recording why it does not resolve."""
    if not isinstance(ref, dict):
        return None
    named = [k for k in ("part", "node") if k in ref]
    if len(named) != 1:
        errors.append(SpecError(at, "must name exactly one of part or node"))
        return None
    kind = named[0]
    target = ref[kind]
    if not isinstance(target, str):
        return None
    known = parts if kind == "part" else nodes
    if target not in known:
        errors.append(
            SpecError(f"{at}.{kind}", f"unknown {kind} {shown(target)}" + did_you_mean(target, known))
        )
        return None
    return kind, target


def blend_graph(raw: dict[str, Any]) -> list[SpecError]:
    """Refs resolve, the graph is a tree per root, every part reaches exactly one root, no cycles."""
    blend = raw.get("blend")
    if not isinstance(blend, dict) or blend.get("mode") not in ("tree", "symmetric-nary"):
        return []
    list_key, child_keys = (
        ("nodes", ("left", "right")) if blend["mode"] == "tree" else ("groups", ("members",))
    )
    errors = duplicate_ids(raw, ("blend", list_key))
    parts = set(usable_ids(raw.get("parts")).values())
    node_ids = usable_ids(blend.get(list_key))
    graph = _BlendGraph()
    nodes = set(node_ids.values())
    for i, ident in node_ids.items():
        graph.node_place[ident] = item_place(raw, ("blend", list_key), i)
    for i, node in _dicts(blend.get(list_key)):
        at = item_place(raw, ("blend", list_key), i)
        refs: list[tuple[str, object]] = []
        for key in child_keys:
            value = node.get(key)
            if isinstance(value, list):
                refs += [(f"{at}.{key}[{j}]", r) for j, r in enumerate(value)]
            else:
                refs.append((f"{at}.{key}", value))
        resolved = []
        for ref_at, ref in refs:
            target = _read_ref(ref, ref_at, parts, nodes, errors)
            if target is not None:
                graph.uses[target].append(ref_at)
                resolved.append(target)
        if i in node_ids:
            graph.children[node_ids[i]] = resolved
    roots = blend.get("roots")
    for j, ref in enumerate(roots if isinstance(roots, list) else []):
        target = _read_ref(ref, f"blend.roots[{j}]", parts, nodes, errors)
        if target is not None:
            graph.uses[target].append(f"blend.roots[{j}]")
            graph.roots.append((f"blend.roots[{j}]", target))
    cycle_errors, cyclic = _blend_cycles(graph)
    return errors + cycle_errors + _blend_reach(graph, parts, cyclic)


def _cycles(successors: dict[str, list[str]]) -> list[list[str]]:
    """The cycles met by one iterative depth-first search over every node (sorted starts), each node entered
    once: linear in the graph (a 4,000-part parent chain took minutes with list membership inside a nested
    walk), and no recursion limit for thousands of blend nodes. Parents and blend nodes both use it."""
    done: set[str] = set()
    cycles: list[list[str]] = []
    for start in sorted(successors):
        if start in done:
            continue
        path: list[str] = [start]
        position = {start: 0}
        pending = [iter(successors.get(start, []))]
        while pending:
            child = next(pending[-1], None)
            if child is None:
                finished = path.pop()
                del position[finished]
                done.add(finished)
                pending.pop()
                continue
            if child in done:
                continue
            if child in position:
                cycles.append(path[position[child] :])
                continue
            position[child] = len(path)
            path.append(child)
            pending.append(iter(successors.get(child, [])))
    return cycles


def _rotated_loop(cycle: list[str]) -> list[str]:
    """A cycle written from its smallest member, so the message does not depend on where the search began."""
    first = cycle.index(min(cycle))
    return cycle[first:] + cycle[:first] + [cycle[first]]


#: Members a cycle message lists before it elides the middle (a message stays one readable line).
LOOP_SHOWN = 12


def _loop_text(loop: list[str]) -> str:
    """``a -> b -> a``; a long loop keeps its ends and says how many members it has."""
    if len(loop) <= LOOP_SHOWN:
        return " -> ".join(loop)
    head, tail = loop[: LOOP_SHOWN - 3], loop[-2:]
    return f"{' -> '.join(head)} -> … ({len(loop) - 1} members) -> {' -> '.join(tail)}"


def _blend_cycles(graph: _BlendGraph) -> tuple[list[SpecError], set[str]]:
    errors = []
    cyclic: set[str] = set()
    nodes = {n: [c for kind, c in children if kind == "node"] for n, children in graph.children.items()}
    for cycle in _cycles(nodes):
        if cyclic.isdisjoint(cycle):
            cyclic.update(cycle)
            loop = _rotated_loop(cycle)
            errors.append(SpecError(graph.node_place[loop[0]], "blend cycle " + _loop_text(loop)))
    return errors, cyclic


def _blend_reach(graph: _BlendGraph, parts: set[str], cyclic: set[str]) -> list[SpecError]:
    reached_by: dict[tuple[str, str], list[str]] = defaultdict(list)
    for root_at, root in graph.roots:
        seen: set[tuple[str, str]] = set()
        stack = [root]
        while stack:
            item = stack.pop()
            if item in seen:
                continue
            seen.add(item)
            reached_by[item].append(root_at)
            if item[0] == "node":
                stack += graph.children.get(item[1], [])
    errors = []
    acyclic = sorted(set(graph.node_place) - cyclic)
    targets = [("part", p) for p in sorted(parts)] + [("node", n) for n in acyclic]
    for kind, ident in targets:
        at = f"part.{ident}" if kind == "part" else graph.node_place[ident]
        roots = reached_by.get((kind, ident), [])
        uses = graph.uses.get((kind, ident), [])
        if len(roots) > 1:
            listed = ", ".join(roots)
            errors.append(
                SpecError(at, f"reached from {len(roots)} blend roots ({listed}); it must reach exactly one")
            )
        elif not roots:
            errors.append(SpecError(at, "not reached from any blend root"))
        elif len(uses) > 1:
            listed = ", ".join(uses)
            errors.append(
                SpecError(
                    at,
                    f"used {len(uses)} times ({listed}); each part and node appears once in the blend graph",
                )
            )
    return errors


def check_creature(raw: dict[str, Any]) -> list[SpecError]:
    """Every cross-field rule of a creature spec, in a fixed order."""
    return (
        duplicate_ids(raw, ("parts",))
        + part_fields(raw)
        + parents(raw)
        + locomotion(raw)
        + slot_budget(raw)
        + blend_graph(raw)
    )
