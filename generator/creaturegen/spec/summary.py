"""A short human-readable account of a validated spec, printed by ``validate -v`` and ``build``."""

from __future__ import annotations

from collections import Counter

from .character import CharacterSpec
from .frost import FrostEffectSpec
from .types import slugify


def summarize(spec: CharacterSpec | FrostEffectSpec) -> list[str]:
    if isinstance(spec, FrostEffectSpec):
        return _frost(spec)
    return _creature(spec)


def _creature(spec: CharacterSpec) -> list[str]:
    shapes = Counter(p.shape for p in spec.parts)
    loco = spec.locomotion.type if spec.locomotion else "none"
    if spec.blend is None:
        blend = "default graph (built by the rig compiler from geometry and structure)"
    elif spec.blend.mode == "tree":
        blend = f"tree, {len(spec.blend.nodes)} nodes, {len(spec.blend.roots)} root(s)"
    else:
        blend = f"symmetric-nary, {len(spec.blend.groups)} groups, {len(spec.blend.roots)} root(s)"
    return [
        f"creature {spec.name!r} -> package {slugify(spec.name)}",
        f"  seed {spec.seed}, scale {spec.scale:g}, locomotion {loco}",
        "  parts "
        + ", ".join(f"{n} {s}" for s, n in sorted(shapes.items()))
        + f" ({len(spec.parts)} in all)",
        f"  slots {spec.slot_count} of maxParts {spec.maxParts}",
        f"  blend {blend}",
    ]


def _frost(spec: FrostEffectSpec) -> list[str]:
    tier = spec.tier
    return [
        f"frost {spec.name!r} -> package {slugify(spec.name)}",
        f"  tier {tier.name}: history x{tier.resolved_history_scale:g} {tier.historyFormat}, "
        f"blur x{tier.blurScale:g}",
        f"  update {spec.update.policy}, diffusion {'on' if spec.diffusion.enabled else 'off'}, "
        f"resize {spec.resizePolicy}, structure {spec.structure.resolution}px seed {spec.structure.seed}",
    ]
