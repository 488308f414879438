"""The surface's cache identity: the rig's three signatures, extended by how the surface was made.

- compilerSignature gains the extraction algorithm and every setting that shapes the mesh (error
  target, block size, relaxation, root tolerance) and the skinning, sweep and correction constants, so a
  change to any of them is a different compiler.
- topologySignature gains the tier, the mesh connectivity (digest of the face array) and the chosen
  deformation method per slot: two bodies share generated skinning code only if all of these agree.
- geometryDigest stays the rest geometry.
The cache is looked up before extraction by (compilerSignature, geometryDigest, tier, settingsDigest),
because the topology is only known afterwards.
"""

from __future__ import annotations

import hashlib
import json

import numpy as np
import numpy.typing as npt

from ..codedigest import stage_digest
from ..rig import CompiledRig
from ..rig.signatures import Signatures, compiler_description, signatures, topology_description
from . import correct, extract, grid, sampling

EXTRACTOR = (
    "sign-lattice lewiner marching cubes (scikit-image), float64 Illinois edge roots, tangential relaxation"
)


def _sha(data: object) -> str:
    return hashlib.sha256(json.dumps(data, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def surface_settings(tier: str) -> dict[str, object]:
    """Every constant that shapes the surface of a tier; part of the compilerSignature."""
    return {
        "tier": tier,
        "extractor": EXTRACTOR,
        "errorTarget": grid.ERROR_TARGET[tier],
        "block": grid.BLOCK,
        "maxCellsPerAxis": grid.MAX_CELLS_PER_AXIS,
        "lipschitzMargin": grid.LIPSCHITZ_MARGIN,
        "signSettleFactor": sampling.SIGN_SETTLE_FACTOR,
        "slab": extract.SLAB,
        "relax": {"rounds": extract.RELAX_ROUNDS, "step": extract.RELAX_STEP},
        "rootTolerance": extract.ROOT_TOLERANCE,
        "correction": {
            "trust": [correct.TRUST_EDGE, correct.TRUST_RADIUS, correct.TRUST_CURVATURE],
            "gradientFloor": correct.GRADIENT_FLOOR,
            "normalAgreement": correct.NORMAL_AGREEMENT,
        },
    }


#: The module whose import closure is the surface stage's code (codedigest.py): any edit to a statement
#: it runs is a different compiler, so a stale cache entry is never served while the version number
#: stands still during development; an edit elsewhere, or to prose, keeps the cache.
SURFACE_ENTRY = "creaturegen.surface.build"


def source_digest() -> str:
    """The digest of the surface stage's code (see SURFACE_ENTRY)."""
    return stage_digest(SURFACE_ENTRY)


def settings_digest(tier: str, extra: dict[str, object]) -> str:
    return _sha({"surface": surface_settings(tier), "extra": extra})


def surface_signatures(
    rig: CompiledRig,
    tier: str,
    faces: npt.NDArray[np.int32],
    methods: tuple[str, ...],
    extra: dict[str, object],
) -> Signatures:
    base = signatures(rig)
    compiler = compiler_signature(rig, tier, extra)
    connectivity = hashlib.sha256(np.ascontiguousarray(faces, dtype="<i4").tobytes()).hexdigest()
    topology = _sha(
        {
            "rig": topology_description(rig),
            "tier": tier,
            "faces": connectivity,
            "faceCount": int(faces.shape[0]),
            "deformation": list(methods),
        }
    )
    return Signatures(
        compilerSignature=compiler, topologySignature=topology, geometryDigest=base.geometryDigest
    )


def compiler_signature(rig: CompiledRig, tier: str, extra: dict[str, object]) -> str:
    """The compilerSignature alone, known before extraction (the cache key)."""
    return _sha({"rig": compiler_description(rig), "surface": surface_settings(tier), "extra": extra})
