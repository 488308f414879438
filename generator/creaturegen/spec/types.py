"""Field types shared by both spec kinds.

Numbers are strict (``true`` is not 1, ``"1.5"`` is not a number) and finite, because every number ends up
in a GPU buffer or a closed-form law where NaN would spread silently.
"""

from __future__ import annotations

import re
from typing import Annotated

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, StrictFloat, StrictInt
from pydantic_core import PydanticCustomError

ID_PATTERN = r"^[A-Za-z][A-Za-z0-9_-]{0,63}$"
NAME_MAX_LENGTH = 80

#: What a regex means, for messages; pydantic only knows the pattern.
PATTERN_MEANINGS: dict[str, str] = {
    ID_PATTERN: "an id: a letter, then up to 63 letters, digits, '-' or '_'",
}

Number = StrictFloat
Positive = Annotated[StrictFloat, Field(gt=0)]
NonNegative = Annotated[StrictFloat, Field(ge=0)]
UnitInterval = Annotated[StrictFloat, Field(ge=0, le=1)]
Vec3 = Annotated[list[StrictFloat], Field(min_length=3, max_length=3)]
Ident = Annotated[str, Field(pattern=ID_PATTERN)]
Seed = Annotated[StrictInt, Field(ge=0, le=2**32 - 1)]


def slugify(name: str) -> str:
    """npm-safe package name from a display name: lower-case ASCII letters, digits and single dashes."""
    return re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")[:64].strip("-")


#: Error type of checks written for this project; its message is used as is.
RULE_ERROR = "spec_rule"


def rule_error(message: str) -> PydanticCustomError:
    """A validator failure whose message reaches the user verbatim."""
    return PydanticCustomError(RULE_ERROR, message)


def _check_name(name: str) -> str:
    if any(ord(c) < 32 or ord(c) == 127 for c in name):
        raise rule_error("must not contain control characters")
    if not slugify(name):
        raise rule_error("must contain a letter or digit (the package name is its slug)")
    return name


Name = Annotated[str, Field(min_length=1, max_length=NAME_MAX_LENGTH), AfterValidator(_check_name)]


class StrictModel(BaseModel):
    """Base of every spec model: unknown fields are errors and non-finite numbers are rejected."""

    model_config = ConfigDict(
        extra="forbid",
        allow_inf_nan=False,
        populate_by_name=False,
        frozen=True,
        strict=True,
        validate_default=True,
    )
