"""Blend graphs of random creatures: an explicit binary tree or n-ary groups over the parent hierarchy
(a spec without one keeps the default blend graph).
"""

from __future__ import annotations

from typing import Any

from .creature import Creature


def _ref(c: Creature, pid: str, nodes: dict[str, str]) -> dict[str, str]:
    return {"node": nodes[pid]} if pid in nodes else {"part": pid}


def tree_blend(c: Creature) -> dict[str, Any]:
    """A binary tree following the parent hierarchy: each part absorbs its children's subtrees in turn,
    with a width a designer would pick (a fraction of the thinner side's radius)."""
    rng = c.rng
    nodes: list[dict[str, Any]] = []
    subtree: dict[str, str] = {}

    def fold(pid: str) -> float:
        part = c.parts[pid]
        radius = part.radius
        left: dict[str, str] = {"part": pid}
        for child in part.children:
            child_r = fold(child)
            k = max(0.004, rng.uniform(0.3, 0.6) * min(radius, child_r))
            node_id = f"{pid}-{child}"
            nodes.append({"id": node_id, "left": left, "right": _ref(c, child, subtree), "k": round(k, 4)})
            left = {"node": node_id}
        if "node" in left:
            subtree[pid] = left["node"]
        return radius

    roots = c.roots()
    for root in roots:
        fold(root)
    return {"mode": "tree", "roots": [_ref(c, r, subtree) for r in roots], "nodes": nodes}


def nary_blend(c: Creature) -> dict[str, Any]:
    """n-ary groups: a part and its children's subtrees in one order-independent group."""
    rng = c.rng
    groups: list[dict[str, Any]] = []
    subtree: dict[str, str] = {}

    def fold(pid: str) -> float:
        part = c.parts[pid]
        if not part.children:
            return part.radius
        members = [{"part": pid}]
        smallest = part.radius
        for child in part.children:
            smallest = min(smallest, fold(child))
            members.append(_ref(c, child, subtree))
        k = max(0.004, rng.uniform(0.15, 0.35) * smallest)
        subtree[pid] = f"{pid}-group"
        groups.append({"id": subtree[pid], "members": members, "kernel": "log-sum-exp", "k": round(k, 4)})
        return part.radius

    roots = c.roots()
    for root in roots:
        fold(root)
    return {"mode": "symmetric-nary", "roots": [_ref(c, r, subtree) for r in roots], "groups": groups}
