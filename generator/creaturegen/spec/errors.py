"""Spec errors: one record per problem, each naming its place in the spec.

Specs are often written by an AI from a prompt, so an error must say *where* (``part.<id>.<field>``) and
*what* in one line that a model or a person can act on without reading the schema.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass

#: Place used for problems with the document as a whole (size, top-level type).
WHOLE_SPEC = "spec"


@dataclass(frozen=True, order=True)
class SpecError:
    """One validation problem. ``path`` is a place such as ``part.body.r`` or, for JSON syntax, ``3:14``."""

    path: str
    message: str

    def __str__(self) -> str:
        return f"{self.path}: {self.message}"

    def as_dict(self) -> dict[str, str]:
        return {"path": self.path, "message": self.message}


_LINE_COLUMN = re.compile(r"^\d+:\d+$")


def format_error(source: str, error: SpecError) -> str:
    """``file: part.body.r: message``, or compiler style ``file:3:14: message`` for JSON syntax."""
    if _LINE_COLUMN.match(error.path):
        return f"{source}:{error.path}: {error.message}"
    return f"{source}: {error.path}: {error.message}"


class SpecValidationError(Exception):
    """Raised by the gate with every error it found, never just the first."""

    def __init__(self, errors: list[SpecError], source: str = "<spec>") -> None:
        self.errors = errors
        self.source = source
        super().__init__(f"{source}: {len(errors)} error(s)\n" + "\n".join(f"  {e}" for e in errors))


def shown(value: object, limit: int = 48) -> str:
    """Quote user input for a message through JSON, so quotes, backslashes and markup stay inert."""
    text = json.dumps(value, ensure_ascii=True, allow_nan=True)
    return text if len(text) <= limit else text[: limit - 3] + "..."
