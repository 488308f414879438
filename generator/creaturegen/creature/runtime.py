"""CREATURE as a typed record: every number of this creature and build the package's runtime reads, which
core/data.js ships. Constants of the runtime's own code (the pose and deform layouts, the candidate codes,
the LCG, the debug views) are the JS modules' exported constants instead, pinned to their Python twins by
tests/test_runtime_constants.py.

creature/plan.py builds it; its JSON (model/record.py ``to_json``) is the plan's ``runtime`` and the text of
core/data.js, key for key as the untyped dict it replaced. core/index.d.ts declares its interfaces by
rendering these classes (emit/tstypes.py), the motion data's included (motion/data.py), so the shipped
declarations are the shipped data's, field for field; the attribute docstrings become their comments.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Annotated

from ..emit.tstypes import declarations
from ..model.genome import ColourGenetics
from ..model.record import JsonRecord, TsName
from ..motion.data import MotionData, Vec3


@dataclass(frozen=True, slots=True)
class CorrectionData(JsonRecord):
    """The local correction of the skinned surface toward the field's iso level (surface/correct.py)."""

    budget: int
    """Shared trial budget per vertex."""
    early_out: float
    """A vertex within this fraction of its trust radius of the iso level stops spending trials."""
    gradient_floor: float
    """Squared-gradient floor below which a vertex has no usable Newton direction."""


@dataclass(frozen=True, slots=True)
class LookData(JsonRecord):
    """The shading controls at spawn (the spec's ``look``): tsl/material.js reads them as uniforms."""

    roughness: float
    metalness: float
    distance_range: float
    """The 'distance' debug view's colour range, a fraction of the body scale."""
    ao_taps: int
    """Field self-occlusion taps along each vertex's normal (0: off)."""
    ao_radius: float
    """How far the occlusion taps reach, a fraction of the body scale."""


@dataclass(frozen=True, slots=True)
class MeshCounts(JsonRecord):
    """The reference surface's size."""

    vertices: int
    triangles: int


@dataclass(frozen=True, slots=True)
class TierData(JsonRecord):
    """One tier the package ships: its surface file and the program tapes that file carries. A population
    draws each body with one of them and moves it between them by its size on screen (core/lod.js)."""

    tier: Annotated[str, TsName("TierName")]
    surface_file: str
    """The tier's .glb in assets/ (its name digests geometry and programs, so tiers never collide)."""
    signatures: Annotated[dict[str, str], TsName("CreatureSignatures")]
    program_digest: str
    program_rows: int
    program_count: int
    full_program: int
    registers: int
    candidate_note: str
    mesh: MeshCounts
    projected_size_max_px: float
    """The largest size of L on screen, in pixels, at which this tier stays within half a pixel of the
    field (CreatureData.projectedSizeMaxPx, for this tier)."""


@dataclass(frozen=True, slots=True)
class CreatureData(JsonRecord):
    """CREATURE: the build plan of this creature, as data (core/data.js)."""

    name: str
    slug: str
    """The npm package name."""
    version: str
    """creaturegen version that built the package."""
    spec_sha256: str
    signatures: Annotated[dict[str, str], TsName("CreatureSignatures")]
    tier: Annotated[str, TsName("TierName")]
    surface_file: str
    """The reference surface's file name in assets/ (``new URL(surfaceFile, assetBase)`` when assetBase is
    given)."""
    three_revision: str
    """three.js REVISION the package was built for ('185')."""
    body_scale: float
    slot_count: int
    max_parts: int
    """Pose-texture parts per instance: every slot, and one for the root rows."""
    slots: tuple[tuple[float, ...], ...]
    """Rest slot table, one row of 12 numbers per slot."""
    slot_names: tuple[str, ...]
    round_cone: tuple[int, ...]
    genetics: ColourGenetics
    slot_lab: tuple[Vec3, ...]
    """OKLab coordinates of every slot's authored colour, which the colour genes mutate."""
    motion: MotionData
    tick_rate: int
    program_digest: str
    """sha256 of the program tapes the .glb carries (surface/glb.py ``program_digest``), checked on load."""
    program_rows: int
    """Their length in vec4 rows: a header per program, then every instruction."""
    program_count: int
    full_program: int
    registers: int
    candidate_note: str
    gradient_floor: float
    tiny: float
    k_floor: float
    correction: CorrectionData
    look: LookData
    mesh: MeshCounts
    projected_size_max_px: float
    """The largest size of the body's length L on screen, in pixels, at which this tier's surface stays
    within half a pixel of the field: the rest mesh's distance to the zero set and, at a skin-represented
    tier, the skin's departure over the motion (assets/surface.json ``surfaceError`` and
    ``skinRepresentation``). Draw a body larger than this with a finer tier."""
    tiers: tuple[TierData, ...]
    """Every tier this package ships, finest first; the first is the one the fields above describe
    (``creaturegen build --tier hero,distant`` ships two). A population loads the tiers it is asked for."""


@cache
def data_declarations() -> str:
    """core/index.d.ts's interfaces of CREATURE and every record it holds (the plan's ``types``)."""
    return declarations(CreatureData)
