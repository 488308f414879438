"""Names for places in a spec: ``part.<id>.<field>``, ``blend.nodes.<id>.k``, ``locomotion.speed``.

A list item is named by its id when that id is valid and unique, so a message survives reordering;
otherwise by its index (``parts[3].r``), because a bad or repeated id cannot identify anything.
"""

from __future__ import annotations

import json
import re
from collections import Counter
from collections.abc import Sequence
from typing import Any

from .errors import WHOLE_SPEC
from .types import ID_PATTERN

#: list field (as a path of keys) -> singular prefix used when the item has a usable id.
ID_LISTS: dict[tuple[str, ...], str] = {
    ("parts",): "part",
    ("blend", "nodes"): "blend.nodes",
    ("blend", "groups"): "blend.groups",
}

#: Discriminator tags pydantic inserts into locations of tagged unions; they are not spec keys.
UNION_TAGS = frozenset({"tree", "symmetric-nary"})

_ID_RE = re.compile(ID_PATTERN)
#: Keys shown as ``.key`` in a place; any other key is shown JSON-quoted, ``["a b"]``.
_PLAIN_KEY = re.compile(r"[A-Za-z0-9_$-]{1,64}")


#: usable_ids of the lists seen last, by identity: places of many errors in one list would otherwise
#: recount its ids once per error (quadratic in a 20,000-part spec). The document is never mutated.
_RECENT: dict[int, tuple[list[Any], dict[int, str]]] = {}


def usable_ids(items: object) -> dict[int, str]:
    """Index -> id for list items whose id is well-formed and appears once."""
    if not isinstance(items, list):
        return {}
    hit = _RECENT.get(id(items))
    if hit is not None and hit[0] is items:
        return hit[1]
    if len(_RECENT) > 8:
        _RECENT.clear()
    found = _usable_ids(items)
    _RECENT[id(items)] = (items, found)
    return found


def _usable_ids(items: list[Any]) -> dict[int, str]:
    ids = {i: it.get("id") for i, it in enumerate(items) if isinstance(it, dict)}
    valid = {i: v for i, v in ids.items() if isinstance(v, str) and _ID_RE.match(v)}
    counts = Counter(valid.values())
    return {i: v for i, v in valid.items() if counts[v] == 1}


def item_place(raw: object, list_keys: tuple[str, ...], index: int) -> str:
    """The place of one item of an id-bearing list, e.g. ``part.body`` or ``parts[3]``."""
    items: Any = raw
    for key in list_keys:
        items = items.get(key) if isinstance(items, dict) else None
    ident = usable_ids(items).get(index)
    if ident is not None:
        return f"{ID_LISTS[list_keys]}.{ident}"
    return ".".join(list_keys) + f"[{index}]"


def place(raw: object, loc: Sequence[str | int]) -> str:
    """Render a location (keys and indices from the document root) as a place name."""
    keys = [k for k in loc if not (isinstance(k, str) and k in UNION_TAGS)]
    if not keys:
        return WHOLE_SPEC
    out = ""
    consumed = 0
    for list_keys in ID_LISTS:
        n = len(list_keys)
        index = keys[n] if len(keys) > n else None
        if tuple(keys[:n]) == list_keys and isinstance(index, int):
            out = item_place(raw, list_keys, index)
            consumed = n + 1
            break
    for key in keys[consumed:]:
        if isinstance(key, int):
            out += f"[{key}]"
        elif _PLAIN_KEY.fullmatch(key):
            out += f".{key}" if out else key
        else:
            # A key a person could not type back (empty, spaces, control characters, markup, lone
            # surrogates) is shown as a JSON string, so the place stays one printable ASCII line.
            quoted = f"[{json.dumps(key, ensure_ascii=True)}]"
            out += quoted if out else WHOLE_SPEC + quoted
    return out
