"""Spec kinds (creature, frost), their pydantic models and the one validation gate."""

from .character import CharacterSpec
from .errors import SpecError, SpecValidationError, format_error
from .frost import FrostEffectSpec
from .gate import KINDS, MAX_SPEC_BYTES, Spec, check, load_spec, parse, read_spec_bytes, validate_bytes
from .types import slugify

__all__ = [
    "KINDS",
    "MAX_SPEC_BYTES",
    "CharacterSpec",
    "FrostEffectSpec",
    "Spec",
    "SpecError",
    "SpecValidationError",
    "check",
    "format_error",
    "load_spec",
    "parse",
    "read_spec_bytes",
    "slugify",
    "validate_bytes",
]
