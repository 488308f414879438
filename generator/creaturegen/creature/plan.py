"""The creature build plan: every number the package's runtime needs, computed once, as plain JSON data.

Templates print this plan (its JSON) and nothing else. ``plan.runtime`` (the typed CreatureData record,
creature/runtime.py) becomes core/data.js; the Python reference (motion/simulate.py, creature/pose.py,
creature/reference.py) reads the same rig, skeleton, motion record and tapes, which is what makes the
lab-vs-numpy parity job meaningful.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import get_args

import numpy as np

from .. import __version__
from ..candidates import TIERS, CandidateSet, TierRejectedError, build_candidates
from ..field.floors import floors_for
from ..field.primitives import GRADIENT_FLOOR, slot_uses_round_cone
from ..model import layout as col
from ..model.genome import genetics_data, slot_lab
from ..model.skeleton import Skeleton
from ..motion.compiled import CompiledCreature
from ..motion.data import MotionData
from ..rig import CompiledRig
from ..spec import CharacterSpec, slugify
from ..spec.character import LocomotionType
from ..surface import correct as correction
from ..surface.build import SurfaceBuild
from ..surface.correction_region import NO_PROGRAM, SKIN_PROGRAM
from ..surface.glb import program_digest
from ..surface.skinning import METHODS
from .assets import AssetNames, asset_plan
from .package_plan import PackagePlan, ThreeRelease, TierAssets, TypeUnions, Usage, Workload
from .pose import POSE_ROWS
from .runtime import CorrectionData, CreatureData, LookData, MeshCounts, TierData, data_declarations
from .tape import Tape, compile_tape

#: The runtime's debug views (lab `setDebugMode`; tsl/material.js DEBUG_MODES); "shell" is the diagnostic
#: capsule shell.
DEBUG_MODES = ("off", "skin-only", "distance", "weights", "normals", "candidates", "shell")
#: vec4 per vertex in a page's deform storage (templates/creature/tsl/deform.js DEFORM_STRIDE, the same
#: number: tests/test_runtime_constants.py).
DEFORM_STRIDE = 3
#: The three.js release the templates are written against: TSL names and node semantics move between
#: releases, so the package pins its peer to it and refuses another REVISION at run time.
THREE_RELEASE = ThreeRelease(revision="185", peer=">=0.185.0 <0.186.0", pin="0.185", types="0.185")


@dataclass(frozen=True)
class TierBuild:
    """One shipped tier: its surface, its runtime record, its tapes and their flat data, its asset names."""

    surface: SurfaceBuild
    data: TierData
    tapes: tuple[Tape, ...]  # candidate programs in asset order, then the full graph
    program: tuple[float, ...]  # the tapes flat, as the .glb carries them (program_data)
    assets: AssetNames


@dataclass(frozen=True)
class CreaturePlan:
    plan: PackagePlan  # what the templates print (as its JSON; its runtime is ``runtime``)
    runtime: CreatureData
    tapes: tuple[Tape, ...]  # candidate programs in asset order, then the full graph
    skeleton: Skeleton
    program: tuple[float, ...]  # the tapes flat, as the .glb carries them (program_data)
    tiers: tuple[TierBuild, ...]  # every shipped tier, finest first (tiers[0] is the one above)


def program_tapes(
    creature: CompiledCreature, tier: str, found: CandidateSet | str | None = None
) -> tuple[list[Tape], str]:
    """Tapes of the tier's candidate programs (the asset's ``_CANDIDATE`` indexes them) + the full graph.
    ``found`` is the surface build's own result when it computed one (the same call on the same rig)."""
    if found is None:
        try:
            found = build_candidates(creature, tier)
        except TierRejectedError as exc:
            found = str(exc)
    if isinstance(found, str):
        tapes, note = [], found
    else:
        tapes, note = [compile_tape(p.graph, p.leaves) for p in found.programs], ""
    tapes.append(compile_tape(creature.rig.graph))
    return tapes, note


def _representation(field_vertices: int, vertices: int) -> str:
    """The README's sentence on how the body is shaded (surface/skin_tier.py for the skin representation)."""
    corrected = (
        "locally corrected toward the smooth-min field where the build proved the skin alone misses it, and "
    )
    if field_vertices == vertices:
        return corrected + "shaded with normals from the field's analytic gradient."
    return (
        corrected
        + f"shaded with the field's analytic normals and colour at the {field_vertices} vertices where "
        "the skin alone departs from the field past this tier's tolerance; the other "
        f"{vertices - field_vertices} vertices evaluate no field (skinned normal, colour baked from the "
        "field's colour weights at rest)."
    )


def program_data(tapes: list[Tape]) -> list[float]:
    """Headers (offset, count, leaves, 0) per program, then every instruction (op, a, b, k), flat."""
    headers: list[float] = []
    body: list[float] = []
    offset = len(tapes)
    for tape in tapes:
        headers += [float(offset), float(len(tape)), float(tape.leaf_count), 0.0]
        for op, a, b, k in tape.instructions:
            body += [float(op), float(a), float(b), float(k)]
        offset += len(tape)
    return headers + body


def tier_build(creature: CompiledCreature, surface: SurfaceBuild) -> TierBuild:
    """One tier's share of the package: its tapes, asset names and runtime record."""
    tapes, note = program_tapes(creature, surface.tier, surface.candidates)
    program = program_data(tapes)
    assets = asset_plan(
        slugify(creature.spec.name), surface.signatures["geometryDigest"], program_digest(program)
    )
    asset = surface.asset
    data = TierData(
        tier=surface.tier,
        # The runtime names its .glb in errors and resolves it against `assetBase`.
        surface_file=assets.surface_file,
        signatures=dict(surface.signatures),
        # The tapes themselves ride in the .glb (surface/glb.py): a GPU buffer, not data to read.
        program_digest=program_digest(program),
        program_rows=len(program) // 4,
        program_count=len(tapes),
        full_program=len(tapes) - 1,
        registers=max(len(t) for t in tapes),
        candidate_note=note,
        mesh=MeshCounts(asset.vertex_count, int(asset.indices.size // 3)),
        projected_size_max_px=_projected_size_max_px(surface.sidecar),
    )
    return TierBuild(surface, data, tuple(tapes), tuple(program), assets)


def build_plan(
    creature: CompiledCreature,
    surface: SurfaceBuild,
    spec_sha256: str,
    more: Sequence[SurfaceBuild] = (),
) -> CreaturePlan:
    """What the templates print for ``creature`` built with ``surface`` (and the coarser tiers ``more``,
    shipped beside it): its skeleton and motion data as the pipeline compiled them (motion/compiled.py),
    never rebuilt here."""
    spec, rig, skeleton, motion = creature.spec, creature.rig, creature.skeleton, creature.motion
    tiers = tuple(tier_build(creature, s) for s in (surface, *more))
    first = tiers[0]
    tapes, assets = list(first.tapes), first.assets
    runtime = _runtime(spec, rig, spec_sha256, skeleton, motion, tuple(t.data for t in tiers))
    workload = _workload(rig, surface, runtime, tapes)
    plan = PackagePlan(
        name=spec.name,
        slug=runtime.slug,
        version=__version__,
        spec_sha256=spec_sha256,
        runtime=runtime,
        assets=assets,
        three=THREE_RELEASE,
        usage=_usage(motion),
        genes="; ".join(" with ".join(g) for g in motion.genes.fields) or "nothing (no locomotion)",
        size_range=f"{1.0 - spec.genetics.size:g} to {1.0 + spec.genetics.size:g}",
        signatures=dict(surface.signatures),
        tier=surface.tier,
        subpixel=_subpixel_sentence(runtime.projected_size_max_px, surface.tier, len(tiers) > 1),
        tier_assets=tuple(
            TierAssets(t.data.tier, t.assets.surface_file, t.assets.surface_path, t.assets.surface_url)
            for t in tiers
        ),
        gates=tuple(g.as_dict() for g in surface.gates),
        representation=_representation(workload.field_vertices, surface.asset.vertex_count),
        workload=workload,
        methods=workload.skinning_methods,
        types=TypeUnions(DEBUG_MODES, tuple(TIERS), get_args(LocomotionType), data_declarations()),
    )
    return CreaturePlan(plan, runtime, first.tapes, skeleton, first.program, tiers)


def _look(spec: CharacterSpec) -> LookData:
    look = spec.look
    return LookData(look.roughness, look.metalness, look.distanceRange, look.aoTaps, look.aoRadius)


def _runtime(
    spec: CharacterSpec,
    rig: CompiledRig,
    spec_sha256: str,
    skeleton: Skeleton,
    motion: MotionData,
    tiers: tuple[TierData, ...],
) -> CreatureData:
    """``plan.runtime``: the data core/data.js holds; its tier fields are the finest shipped tier's."""
    floors = floors_for(rig.body_scale)
    first = tiers[0]
    return CreatureData(
        name=spec.name,
        slug=slugify(spec.name),
        version=__version__,
        spec_sha256=spec_sha256,
        signatures=first.signatures,
        tier=first.tier,
        surface_file=first.surface_file,
        three_revision=THREE_RELEASE.revision,
        body_scale=rig.body_scale,
        slot_count=rig.slot_count,
        # One extra "part" per instance: the root rows (position + alive, yaw cos/sin + squash + size).
        max_parts=rig.slot_count + 1,
        slots=tuple(tuple(row) for row in rig.slots.tolist()),
        slot_names=tuple(skeleton.names),
        round_cone=tuple(int(x) for x in slot_uses_round_cone(rig.slots)),
        # Colour genes mutate these OKLab coordinates of the authored colours (model/genome.py).
        genetics=genetics_data(spec.genetics),
        slot_lab=tuple((big_l, a, b) for big_l, a, b in slot_lab(rig.slots[:, col.RGB])),
        motion=motion,
        tick_rate=motion.hz,
        program_digest=first.program_digest,
        program_rows=first.program_rows,
        program_count=first.program_count,
        full_program=first.full_program,
        registers=first.registers,
        candidate_note=first.candidate_note,
        gradient_floor=GRADIENT_FLOOR,
        tiny=float(np.finfo(np.float32).tiny),
        k_floor=floors.k_floor,
        correction=CorrectionData(correction.DEFAULT_BUDGET, correction.EARLY_OUT, correction.GRADIENT_FLOOR),
        look=_look(spec),
        mesh=first.mesh,
        projected_size_max_px=first.projected_size_max_px,
        tiers=tiers,
    )


def _subpixel_sentence(size: float, tier: str, switches: bool = False) -> str:
    """The README's end of the sentence on the tier's subpixel size (``CREATURE.projectedSizeMaxPx``)."""
    finer = list(TIERS)[: list(TIERS).index(tier)]
    then = f"draw larger bodies with the {finer[-1]} tier's package" if finer else "the finest tier there is"
    if switches:
        then += "; the coarser tiers this package ships take over below their own sizes (`CREATURE.tiers`)"
    return f"{size:.0f} px across on screen (`CREATURE.projectedSizeMaxPx`); {then}."


def _projected_size_max_px(sidecar: dict[str, object]) -> float:
    """The smaller of the sidecar's two subpixel sizes: the mesh's, and the skin representation's."""
    sizes = []
    for key in ("surfaceError", "skinRepresentation"):
        part = sidecar.get(key)
        if isinstance(part, dict) and isinstance(part.get("projectedSizeMaxPx"), int | float):
            sizes.append(float(part["projectedSizeMaxPx"]))
    assert sizes, "the surface sidecar reports no surfaceError"
    return min(sizes)


def _usage(motion: MotionData) -> Usage:
    """The README's minimal page (examples/minimal.js): a swimmer needs a water provider (the template
    only prints these)."""
    swims = motion.type == "swimmer"
    water = ["createAnalyticWater"] if swims else []
    return Usage(
        imports=", ".join(["CREATURE", *water, "createCreaturePopulation"]),
        options="{ capacity: 64, water: createAnalyticWater() }" if swims else "{ capacity: 64 }",
        water=" and `water` (required: this creature swims)" if swims else "",
    )


def _workload(rig: CompiledRig, surface: SurfaceBuild, runtime: CreatureData, tapes: list[Tape]) -> Workload:
    """``plan.workload``: what one body costs per frame at this tier (the README's workload table)."""
    asset = surface.asset
    skin = np.asarray(asset.skin)  # (V, 2): method code, trust radius
    corrected = int(np.count_nonzero(skin[:, 1] > 0))
    # Leaf evaluations per body and frame: each field vertex runs its own program once at its final
    # position (E_snap adds the correction trials of corrected vertices); a skin vertex runs none.
    program = np.asarray(asset.candidate).astype(np.int64)
    in_field = program != SKIN_PROGRAM
    per_program = np.array([len(t.leaves) for t in tapes])
    leaf_evaluations = int(
        per_program[np.where(program[in_field] == NO_PROGRAM, len(tapes) - 1, program[in_field])].sum()
    )
    return Workload(
        tier=surface.tier,
        slots=rig.slot_count,
        K=runtime.registers,
        programs=len(tapes),
        vertices=asset.vertex_count,
        triangles=runtime.mesh.triangles,
        corrected_vertices=corrected,
        field_vertices=int(in_field.sum()),
        leaf_evaluations_per_body=leaf_evaluations,
        pose_bytes_per_body=runtime.max_parts * POSE_ROWS * 16,
        # The deform pre-pass storage (tsl/deform.js DEFORM_STRIDE vec4 per vertex).
        deform_bytes_per_body=asset.vertex_count * DEFORM_STRIDE * 16,
        S=runtime.correction.budget,
        influences=int(np.count_nonzero(np.asarray(asset.weights) > 0, axis=1).max()),
        skinning_methods={m: int(np.count_nonzero(skin[:, 0] == i)) for i, m in enumerate(METHODS)},
        outline_mode="none",
    )
