"""One-line messages for pydantic's error types.

Tests pin messages exactly, and pydantic's own wording changes between minor releases, so every error type
a spec can produce is worded here; an unexpected type falls back to pydantic's text.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable
from typing import Any

from pydantic_core import ErrorDetails

from .errors import shown
from .types import PATTERN_MEANINGS


def number(value: object) -> str:
    """A bound or input as people write it: 0 not 0.0, 1.5707963267948966 as is."""
    if isinstance(value, float) and value.is_integer() and math.isfinite(value):
        return str(int(value))
    return str(value)


def _bound(op: str, ctx: dict[str, Any], key: str, value: object) -> str:
    return f"must be {op} {number(ctx[key])} (got {shown(value)})"


def did_you_mean(name: str, vocabulary: Iterable[str]) -> str:
    """A hint for a misspelt key or id; case is ignored because ``IOR`` for ``ior`` is the usual slip."""
    by_lower = {word.lower(): word for word in sorted(set(vocabulary))}
    close = difflib.get_close_matches(name.lower(), list(by_lower), n=1, cutoff=0.75)
    return f"; did you mean '{by_lower[close[0]]}'?" if close else ""


def plural(count: object, noun: str) -> str:
    return f"{count} {noun}" if count == 1 else f"{count} {noun}s"


def describe(err: ErrorDetails, vocabulary: Iterable[str]) -> str:
    """Message for one pydantic error; ``vocabulary`` holds the known field names for suggestions."""
    kind = err["type"]
    ctx: dict[str, Any] = dict(err.get("ctx") or {})
    value = err.get("input")
    field = err["loc"][-1] if err["loc"] else ""
    simple = {
        "missing": "is required",
        "float_type": f"must be a number (got {shown(value)})",
        "int_type": f"must be an integer (got {shown(value)})",
        "string_type": f"must be a string (got {shown(value)})",
        "bool_type": f"must be true or false (got {shown(value)})",
        "list_type": f"must be an array (got {shown(value)})",
        "model_type": f"must be an object (got {shown(value)})",
        "model_attributes_type": f"must be an object (got {shown(value)})",
        "dict_type": f"must be an object (got {shown(value)})",
        "finite_number": f"must be a finite number (got {shown(value)})",
        "union_tag_not_found": "is required",
    }
    if kind in simple:
        return simple[kind]
    if kind == "extra_forbidden":
        return "unknown field" + did_you_mean(str(field), vocabulary)
    if kind in ("literal_error", "union_tag_invalid"):
        expected = str(ctx.get("expected") or ctx.get("expected_tags", ""))
        options = expected.replace("'", "").replace(" or ", ", ")
        return f"must be one of {options} (got {shown(value if kind == 'literal_error' else ctx.get('tag'))})"
    bounds = {
        "greater_than": (">", "gt"),
        "greater_than_equal": (">=", "ge"),
        "less_than": ("<", "lt"),
        "less_than_equal": ("<=", "le"),
    }
    if kind in bounds:
        op, key = bounds[kind]
        return _bound(op, ctx, key, value)
    if kind == "string_pattern_mismatch":
        meaning = PATTERN_MEANINGS.get(str(ctx.get("pattern")), f"match {ctx.get('pattern')}")
        return f"must be {meaning} (got {shown(value)})"
    if kind == "string_too_short":
        return "must not be empty"
    if kind == "string_too_long":
        return f"must be at most {ctx['max_length']} characters (got {len(str(value))})"
    if kind in ("too_short", "too_long"):
        limit = ctx.get("min_length") if kind == "too_short" else ctx.get("max_length")
        if err["loc"] and err["loc"][-1] in ("a", "b", "offset", "hip"):
            return f"must be an array of 3 numbers (got {ctx.get('actual_length')})"
        word = "at least" if kind == "too_short" else "at most"
        return f"must have {word} {plural(limit, 'item')} (got {ctx.get('actual_length')})"
    return str(err["msg"])
