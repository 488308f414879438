"""What a creature package's templates print, as typed records (creature/plan.py builds them).

The templates read the plan's JSON (``PackagePlan.to_json()``, model/record.py: camelCase keys in field
order, nested records as objects), exactly as core/data.js reads CREATURE's; Python reads the records by
attribute, so a misspelt key is a mypy error, not a silently empty line of a README.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..model.record import JsonRecord
from .assets import AssetNames
from .runtime import CreatureData


@dataclass(frozen=True, slots=True)
class TierAssets(JsonRecord):
    """A shipped tier's surface file (tsl/asset.js prints one static URL per file)."""

    tier: str
    surface_file: str
    surface_path: str
    surface_url: str


@dataclass(frozen=True, slots=True)
class ThreeRelease(JsonRecord):
    """The three.js release the templates are written against: TSL names and node semantics move between
    releases, so the package pins its peer to it and refuses another REVISION at run time."""

    revision: str
    peer: str
    pin: str
    types: str


@dataclass(frozen=True, slots=True)
class Usage(JsonRecord):
    """The README's minimal page (examples/minimal.js): a swimmer needs a water provider."""

    imports: str
    options: str
    water: str


@dataclass(frozen=True, slots=True)
class Workload(JsonRecord):
    """What one body costs per frame at this tier (the README's workload table)."""

    tier: str
    slots: int
    K: int
    programs: int
    vertices: int
    triangles: int
    corrected_vertices: int
    field_vertices: int
    leaf_evaluations_per_body: int
    pose_bytes_per_body: int
    deform_bytes_per_body: int
    S: int
    """Correction trials a corrected vertex may spend after its initial query (the shared budget),
    rejected backtracking trials included: its snap evaluates its program at most S + 1 times."""
    influences: int
    """The most skin influences (non-zero weights) any vertex has; at most 4."""
    skinning_methods: dict[str, int]
    """Vertices per skinning method (lbs, dq, cor), as each vertex's joint chose."""
    outline_mode: str
    """The outline the package draws: "none" (no outline pass is built yet)."""


@dataclass(frozen=True, slots=True)
class TypeUnions(JsonRecord):
    """The string unions of core/index.d.ts, from the Python definitions the runtime data comes from, and
    its interfaces of that data (emit/tstypes.py)."""

    debug_mode: tuple[str, ...]
    tier_name: tuple[str, ...]
    locomotion_type: tuple[str, ...]
    declarations: str


@dataclass(frozen=True, slots=True)
class PackagePlan(JsonRecord):
    """Everything the creature templates print."""

    name: str
    slug: str
    version: str
    spec_sha256: str
    runtime: CreatureData
    """core/data.js's CREATURE."""
    assets: AssetNames
    """The finest shipped tier's surface (the package's own)."""
    three: ThreeRelease
    usage: Usage
    genes: str
    """The README's gait-gene line (each gene scales its fields together)."""
    size_range: str
    signatures: dict[str, str]
    tier: str
    subpixel: str
    tier_assets: tuple[TierAssets, ...]
    gates: tuple[dict[str, object], ...]  # SurfaceGate.as_dict()
    representation: str
    workload: Workload
    methods: dict[str, int]
    types: TypeUnions
    picture: str | None = None
    """The README picture's path, when the build rendered one."""
    files: tuple[str, ...] = ()
    """package.json ``files``."""
