"""``creaturegen build``: validate a spec and build its package, a frost effect or a creature (with
``--population N``, N geometry identities), printing each step and exiting with the code of the first
failure (cli_errors.py); nothing is written when a spec is invalid (2) or a build gate refuses it (3).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path

from .cli_errors import EXIT_GATE_FAILED, EXIT_INVALID, EXIT_OK, EXIT_REFUSED, print_errors
from .cli_report import print_gates, print_surface_summary, report_creature_package, report_frost_build
from .creature.assets import PICTURE_PATH
from .creature.build import build_creature
from .creature.morphology import identity_genes, variant_bytes
from .emit import PackageWriteError
from .frost.build import build_frost
from .frost.formats import FormatRefusedError
from .lab.picture import picture_unavailable, render_picture
from .motion.compiled import CompiledCreature, compile_creature
from .rig import RigCompileError
from .spec import CharacterSpec, SpecError, SpecValidationError, slugify, validate_bytes
from .spec.summary import summarize
from .surface.backends import BackendChoiceError
from .surface.build import SurfaceBuild, build_surface
from .surface.cache import SurfaceCache
from .surface.deform import DeformationError
from .surface.grid import GridTooFineError
from .surface.refusal import SurfaceRejectedError, refuse_posed


def build_command(args: argparse.Namespace) -> int:
    source = Path(args.spec)
    try:
        data = source.read_bytes()
    except OSError as exc:
        print_errors(args.spec, [SpecError("spec", f"cannot be read: {exc.strerror}")])
        return EXIT_INVALID
    try:
        spec = validate_bytes(data, args.spec)
    except SpecValidationError as exc:
        print_errors(args.spec, exc.errors)
        return EXIT_INVALID
    print(f"{args.spec}: ok")
    print("\n".join(summarize(spec)))
    if isinstance(spec, CharacterSpec):
        return _build_creature(args, spec, data)
    if args.population != 1:
        print_errors(args.spec, [SpecError("--population", "applies to creature specs only")])
        return EXIT_INVALID
    print(
        "==> frost: quantisation gate (30/60/120 FPS replays per storage format), structure maps", flush=True
    )
    try:
        folder = build_frost(spec, data, Path(args.out))
    except FormatRefusedError as exc:
        print_errors(args.spec, [SpecError("tier.historyFormat", str(exc))])
        return EXIT_REFUSED
    except PackageWriteError as exc:
        print(f"{args.spec}: cannot write the package: {exc}", file=sys.stderr)
        return EXIT_INVALID
    report_frost_build(folder)
    return EXIT_OK


def surface_or_exit(name: str, creature: CompiledCreature, tier: str, backend: str) -> SurfaceBuild | int:
    """The surface at ``tier``, or the exit code of its failure, printed naming the gate, part or option:
    EXIT_REFUSED when a gate refuses the geometry, EXIT_INVALID when ``--backend`` cannot be used."""
    try:
        return build_surface(creature, tier=tier, backend=backend, cache=SurfaceCache())
    except (SurfaceRejectedError, GridTooFineError, DeformationError) as exc:
        print_errors(name, [SpecError(f"surface.{tier}", str(exc))])
        return EXIT_REFUSED
    except BackendChoiceError as exc:
        print_errors(name, [SpecError("--backend", str(exc))])
        return EXIT_INVALID


@dataclass(frozen=True)
class _Identity:
    """One geometry identity ready to write: the compiled creature (and the spec's JSON bytes it ships) and
    its surface."""

    name: str
    creature: CompiledCreature
    data: bytes
    build: SurfaceBuild
    more: tuple[SurfaceBuild, ...] = ()  # the coarser tiers' surfaces shipped beside it (--tier hero,distant)


def _identity(args: argparse.Namespace, name: str, spec: CharacterSpec, data: bytes) -> _Identity | int:
    """Compile, extract and gate one identity; on failure the exit code (errors printed, naming the gate or
    part): EXIT_INVALID for a rig the spec cannot compile to, EXIT_REFUSED for a surface gate."""
    try:
        creature = compile_creature(spec)
    except RigCompileError as exc:
        print_errors(name, exc.errors)
        return EXIT_INVALID
    steps = "narrow-band sampling, extraction, gates, skin weights, deformation sweeps"
    builds: list[SurfaceBuild] = []
    for tier in args.tier:
        print(f"==> surface {tier}: {steps}")
        build = surface_or_exit(name, creature, tier, args.backend)
        if isinstance(build, int):
            return build
        print_gates(build)
        if args.posed_gates == "refuse":
            try:
                refuse_posed(build.sidecar, tier)
            except SurfaceRejectedError as exc:
                print_errors(name, [SpecError(f"surface.{tier}", str(exc))])
                return EXIT_REFUSED
        print_surface_summary(build)
        builds.append(build)
    return _Identity(name, creature, data, builds[0], tuple(builds[1:]))


#: Morphology variants drawn per identity asked for before --population gives up.
DRAWS_PER_IDENTITY = 4


def _identities(args: argparse.Namespace, spec: CharacterSpec, data: bytes) -> list[_Identity] | int:
    """The authored identity and, with ``--population N``, N - 1 morphology variants (creature/morphology.py).
    A variant that fails validation or a surface gate is rejected (the reason printed) and the next index is
    drawn, so identity names follow draw indices. On failure the exit code: the authored identity's own
    (EXIT_INVALID or EXIT_REFUSED), EXIT_INVALID when the name leaves no room for identity suffixes, and
    EXIT_REFUSED when N identities do not pass within DRAWS_PER_IDENTITY·N draws (the authored spec is
    valid and built; its variants are what the gates refused)."""
    authored = _identity(args, args.spec, spec, data)
    if isinstance(authored, int):
        return authored
    out = [authored]
    document = json.loads(data)
    bound = spec.genetics.morphology
    index = 0
    while len(out) < args.population and index < DRAWS_PER_IDENTITY * args.population:
        index += 1
        name = f"{args.spec} (identity m{index})"
        genes = identity_genes(spec.seed, index)
        scaled = ", ".join(f"{g} x{1.0 + bound * v:.3f}" for g, v in genes.items())
        print(f"==> identity m{index} ({len(out) + 1} of {args.population}): {scaled}")
        variant_data = variant_bytes(document, index, bound)
        try:
            variant = validate_bytes(variant_data, name)
        except SpecValidationError as exc:
            print_errors(name, exc.errors)
            variant = None
        if isinstance(variant, CharacterSpec) and slugify(variant.name) in {
            slugify(o.creature.spec.name) for o in out
        }:
            print_errors(
                name,
                [SpecError("name", "too long for an identity suffix: the slugs of the identities collide")],
            )
            return EXIT_INVALID
        one = _identity(args, name, variant, variant_data) if isinstance(variant, CharacterSpec) else None
        if not isinstance(one, _Identity):
            print(f"  identity m{index} rejected (above); drawing the next")
            continue
        out.append(one)
    if len(out) < args.population:
        print(
            f"{args.spec}: only {len(out)} of {args.population} identities passed every gate "
            f"in {index} draws; nothing was written (lower genetics.morphology or --population)",
            file=sys.stderr,
        )
        return EXIT_REFUSED
    return out


def _build_creature(args: argparse.Namespace, spec: CharacterSpec, data: bytes) -> int:
    identities = _identities(args, spec, data)
    if isinstance(identities, int):
        return identities
    print("==> package: candidate program tapes, locomotion data, templates")
    picture = args.picture == "on"
    if args.picture == "auto":
        reason = picture_unavailable()
        picture = reason is None
        if reason is not None:
            print(f"  no README picture: the lab cannot run here ({reason}); --picture off to silence this")
    if picture:
        print(f"==> picture: {PICTURE_PATH} rendered by the lab (headless Chromium, WebGPU on SwiftShader)")
    for one in identities:
        try:
            render = render_picture if picture else None
            folder = build_creature(one.creature, one.data, one.build, Path(args.out), render, one.more)
        except PackageWriteError as exc:
            print(f"{one.name}: cannot write the package: {exc}", file=sys.stderr)
            return EXIT_INVALID
        except RuntimeError as exc:
            if not picture:
                raise
            print(
                f"{one.name}: cannot render the README picture ({exc}); it was not written.", file=sys.stderr
            )
            print("  build without it: --picture off", file=sys.stderr)
            return EXIT_GATE_FAILED
        report_creature_package(folder, one.build)
    return EXIT_OK
