"""The frost build plan: every number the package needs, computed here once, as plain JSON data.

Templates print this plan and nothing else; the JS runtime reads it from core/plan.js. The numpy reference
is driven by the same FrostParams, which is what makes the GPU-vs-numpy parity test meaningful.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import __version__
from ..rig.colour import hex_to_linear
from ..spec.frost import TIER_MAX_HISTORY_SCALE, FrostEffectSpec
from ..spec.types import slugify
from .brush import NOISE_SALT, pcg_hash
from .formats import FormatGate, choose_format
from .params import FrostParams, frost_params, scaled_size
from .structure import StructureMaps, generate_structure
from .structure_file import StructureFile, encode_structure

#: Debug views of the seed, in the order of the composite's view uniform.
DEBUG_VIEWS = (
    "final",
    "scene",
    "blurVertical",
    "blurHorizontal",
    "structure",
    "structureHeight",
    "mainNormal",
    "detailNormal",
    "historyPrevR",
    "historyPrevA",
    "depositR",
    "depositA",
    "historyNextR",
    "historyNextA",
    "maskBefore",
    "maskAfter",
    "sharpBlurMix",
    "refractMain",
    "refractDetail",
    "finalNoRefraction",
)

#: Tier defaults when a package switches away from its authored tier (setTier); the authored tier uses
#: the spec's own scales. Refraction per the seed: full two-scale + Fresnel, balanced two-scale,
#: budgeted single offset.
TIER_DEFAULTS: dict[str, dict[str, Any]] = {
    "full": {"historyScale": 1.0, "blurScale": 0.5, "detail": True, "fresnel": True},
    "balanced": {"historyScale": 0.5, "blurScale": 0.25, "detail": True, "fresnel": False},
    "budgeted": {"historyScale": 0.25, "blurScale": 0.125, "detail": False, "fresnel": False},
}

#: Gaussian sigma in blur-target texels and the alpha guard of the blur's normalisation.
BLUR_SIGMA = 3.0
BLUR_EPSILON = 1e-4

#: Frost coverage between crystals: a haze floor so the pane never shows clear gaps inside frost.
HAZE = 0.6

#: The history memory the README quotes is for this drawing buffer (the seed's reference size).
REFERENCE_DRAWING_BUFFER = (1920, 1080)

BYTES_PER_TEXEL = {"rgba16float": 8, "rgba32float": 16}

#: The three.js release the runtime is written for: the peer dependency range and the REVISION it checks.
THREE_REVISION = "185"
THREE_RANGE = ">=0.185.0 <0.186.0"

#: Hex digits of the content digest in asset file names: enough that two packages' files never share a name.
ASSET_DIGEST_CHARS = 12


@dataclass(frozen=True)
class FrostBuild:
    """The plan plus the binary assets it names."""

    plan: dict[str, Any]
    structure: StructureMaps
    structure_file: StructureFile
    params: FrostParams
    gates: list[FormatGate]


def noise_salts(seed: int) -> list[int]:
    with np.errstate(over="ignore"):
        return [int(pcg_hash(np.array([seed ^ salt], dtype=np.uint32))[0]) for salt in NOISE_SALT]


def asset_file_name(slug: str, role: str, data: bytes, extension: str) -> str:
    """``<slug>-<role>-<digest>.<ext>``: unique per package and per content, so bundlers that copy the
    assets of several packages into one folder never overwrite one with another, and caches never serve
    a stale file under a new build."""
    digest = hashlib.sha256(data).hexdigest()[:ASSET_DIGEST_CHARS]
    return f"{slug}-{role}-{digest}.{extension}"


def build_plan(spec: FrostEffectSpec, spec_sha256: str) -> FrostBuild:
    params = frost_params(spec)
    history_format, gates = choose_format(params, spec.tier.historyFormat)
    structure = generate_structure(spec.structure)
    structure_file = encode_structure(structure)
    slug = slugify(spec.name)
    structure_name = asset_file_name(slug, "structure", structure_file.data, "bin")
    tiers = {name: dict(values) for name, values in TIER_DEFAULTS.items()}
    tiers[spec.tier.name].update(historyScale=params.history_scale, blurScale=spec.tier.blurScale)
    width, height = REFERENCE_DRAWING_BUFFER
    history_width, history_height = scaled_size(width, height, params.history_scale)
    texels = history_width * history_height
    plan: dict[str, Any] = {
        "name": spec.name,
        "slug": slug,
        "version": __version__,
        "specSha256": spec_sha256,
        "params": params.as_plan(),
        "tier": {
            "name": spec.tier.name,
            "historyFormat": history_format,
            "historyFormatRequested": spec.tier.historyFormat,
            "maxHistoryScale": TIER_MAX_HISTORY_SCALE[spec.tier.name],
        },
        "tiers": tiers,
        "refraction": spec.refraction.model_dump(),
        "composite": {
            **spec.composite.model_dump(exclude={"tint"}),
            "tint": spec.composite.tint,
            "tintLinear": list(hex_to_linear(spec.composite.tint)),
            "haze": HAZE,
        },
        "fades": spec.fades.model_dump(),
        "blur": {"sigma": BLUR_SIGMA, "epsilon": BLUR_EPSILON},
        "structure": {**spec.structure.model_dump(), "sha256": structure.sha256},
        "assets": {"structure": structure_file.layout(structure_name)},
        "three": {"revision": THREE_REVISION, "range": THREE_RANGE},
        "noiseSalts": noise_salts(spec.seed),
        "debugViews": list(DEBUG_VIEWS),
        "memory": {
            "referenceDrawingBuffer": [width, height],
            "historyBytes": 2 * texels * BYTES_PER_TEXEL[history_format],
            "structureBytes": int(structure.structure.nbytes + structure.normals.nbytes),
            "structureFileBytes": len(structure_file.data),
        },
        "gates": [gate.as_dict() for gate in gates],
    }
    return FrostBuild(
        plan=plan, structure=structure, structure_file=structure_file, params=params, gates=gates
    )
