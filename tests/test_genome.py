"""Genetics: genomes drawn from spawn seeds (colour genes in OKLab, gait genes), and the build-time
morphology identities of `creaturegen build --population N`.

JS parity of the genome (bit for bit) is in test_creature_package.py (the JS core's pose rows, colour rows
included, against pose_rows with genome_colours) and test_motion.py (the JS core's individuals); the GPU
rows of 64 individuals against Python are a parity gate (test_creature_parity.py, the `grid` group).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from conftest import EXAMPLES, run_cli
from creaturegen.creature.morphology import identity_genes, variant_document
from creaturegen.model import layout as col
from creaturegen.model.genome import (
    Genome,
    draw_genome,
    genetics_data,
    genome_colours,
    linear_from_oklab,
    slot_lab,
)
from creaturegen.model.skeleton import build_skeleton
from creaturegen.motion.data import MotionData
from creaturegen.motion.express import express_gait
from creaturegen.motion.rig import build_motion
from creaturegen.rig import compile_rig
from creaturegen.rig.colour import hex_to_linear
from creaturegen.spec import CharacterSpec, SpecValidationError, load_spec, slugify, validate_bytes
from creaturegen.spec.character import Genetics

SEEDS = range(256)
#: Mid-gamut colours (no channel clips under the default bounds), so the OKLab bounds hold exactly.
MID = ["#7f8fba", "#6f9a54", "#9a7a60", "#8a8a8a"]


def _lab(colours: list[list[float]]) -> np.ndarray:
    return np.asarray(slot_lab(np.asarray(colours)))


def test_genes_are_signed_unit_draws_and_differ_between_seeds() -> None:
    genomes = [draw_genome(seed) for seed in SEEDS]
    genes = np.array([[g.hue, g.chroma, g.lightness, *g.gait] for g in genomes])
    assert genes.min() >= -1.0
    assert genes.max() < 1.0
    assert len({tuple(row) for row in genes.tolist()}) == len(genomes)
    # Each gene spans its range both ways over 256 consecutive seeds. Without mix_seed the k-th draws of
    # consecutive seeds form an arithmetic progression (an LCG is affine): a regular lattice, not variety.
    assert (genes.min(axis=0) < -0.9).all()
    assert (genes.max(axis=0) > 0.9).all()
    steps = np.mod(np.diff(genes[:8], axis=0), 2.0)
    assert not np.allclose(steps, steps[0], atol=1e-6), "consecutive seeds draw a lattice"
    assert draw_genome(7) == draw_genome(7) == draw_genome(7 + (1 << 32))


def test_a_zero_genome_keeps_the_authored_colours() -> None:
    rgb = np.array([hex_to_linear(c) for c in [*MID, "#000000", "#ffffff", "#ff0000"]])
    back = np.array([linear_from_oklab(tuple(lab)) for lab in slot_lab(rgb)])  # type: ignore[arg-type]
    # Ottosson's published matrices are inverse to about 3e-7.
    assert np.abs(back - rgb).max() < 5e-7


def test_colour_genes_stay_within_their_oklab_bounds() -> None:
    """Hue rotation, chroma scale and lightness shift measured back in OKLab, for 256 individuals."""
    bounds = {"hue": 20.0, "chroma": 0.2, "lightness": 0.06}
    genetics = genetics_data(Genetics(**bounds))
    authored = np.array([hex_to_linear(c) for c in MID])
    lab = slot_lab(authored)
    base = np.asarray(lab)
    worst = {"hue": 0.0, "chroma": 0.0, "lightness": 0.0}
    for seed in SEEDS:
        mutated = _lab(genome_colours(genetics, lab, draw_genome(seed)))
        d_l = np.abs(mutated[:, 0] - base[:, 0])
        chroma = np.hypot(mutated[:, 1], mutated[:, 2]) / np.hypot(base[:, 1], base[:, 2])
        turn = np.degrees(
            np.abs(
                np.angle(
                    np.exp(
                        1j * (np.arctan2(mutated[:, 2], mutated[:, 1]) - np.arctan2(base[:, 2], base[:, 1]))
                    )
                )
            )
        )
        colourful = np.hypot(base[:, 1], base[:, 2]) > 0.02  # the grey's hue is not defined
        worst["lightness"] = max(worst["lightness"], float(d_l.max()))
        worst["chroma"] = max(worst["chroma"], float(np.abs(chroma[colourful] - 1.0).max()))
        worst["hue"] = max(worst["hue"], float(turn[colourful].max()))
    print(f"worst over {len(SEEDS)} individuals: {worst}")
    for name, bound in bounds.items():
        assert worst[name] <= bound * (1 + 1e-4) + 1e-6, f"{name}: {worst[name]} > {bound}"
        assert worst[name] >= 0.9 * bound, f"{name}: {worst[name]} never approaches its bound {bound}"


def test_colour_mutation_clips_into_gamut() -> None:
    genetics = genetics_data(Genetics(hue=180.0, chroma=0.5, lightness=0.25))
    lab = slot_lab(np.array([hex_to_linear(c) for c in ["#ff0000", "#00ff00", "#0000ff", "#ffffff"]]))
    for seed in SEEDS:
        rgb = np.asarray(genome_colours(genetics, lab, draw_genome(seed)))
        assert rgb.min() >= 0.0
        assert rgb.max() <= 1.0


def _motion(name: str) -> MotionData:
    spec = load_spec(EXAMPLES / name)
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    return build_motion(spec, rig, build_skeleton(spec, rig))


def test_gait_genes_scale_pace_together_and_respect_the_reach_limit() -> None:
    data = _motion("reference/quadruped.json")
    frozen = json.dumps(data.to_json(), sort_keys=True)
    jitter = data.genes.jitter
    slow = express_gait(data, Genome(0.0, 0.0, 0.0, (-1.0, 0.5, 0.0)))
    assert json.dumps(data.to_json(), sort_keys=True) == frozen, "express_gait modified the authored data"
    assert slow.speed / data.speed == pytest.approx(1.0 - jitter)
    assert slow.step_length / data.step_length == pytest.approx(1.0 - jitter)
    assert slow.step_height / data.step_height == pytest.approx(1.0 + 0.5 * jitter)
    # The quadruped's step length sits at its reach limit: a faster pace is capped there, speed with it.
    fast = express_gait(data, Genome(0.0, 0.0, 0.0, (1.0, 0.0, 0.0)))
    assert data.step_length == data.step_limit
    assert fast.step_length == data.step_limit
    assert fast.speed == data.speed


def test_a_zero_gait_bound_keeps_every_individual_on_the_authored_gait() -> None:
    document = json.loads((EXAMPLES / "reference" / "hopper.json").read_text())
    document["genetics"] = {"gait": 0.0}
    spec = validate_bytes(json.dumps(document).encode(), "hopper")
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    data = build_motion(spec, rig, build_skeleton(spec, rig))
    for seed in range(8):
        assert express_gait(data, draw_genome(seed)) == data


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [("hue", 200.0, "genetics.hue"), ("gait", -0.1, "genetics.gait"), ("chroma", "x", "genetics.chroma")],
)
def test_genetics_bounds_are_validated_naming_the_field(field: str, value: object, message: str) -> None:
    document = json.loads((EXAMPLES / "reference" / "hopper.json").read_text())
    document["genetics"] = {field: value}
    with pytest.raises(SpecValidationError) as caught:
        validate_bytes(json.dumps(document).encode(), "hopper")
    assert any(e.path == message for e in caught.value.errors), [str(e) for e in caught.value.errors]


def test_morphology_variants_scale_girth_limbs_and_tails() -> None:
    document = json.loads((EXAMPLES / "lizard.json").read_text())
    frozen = json.dumps(document)
    variant = variant_document(document, 2, 0.1)
    assert json.dumps(document) == frozen, "variant_document modified the authored document"
    genes = identity_genes(int(document.get("seed", 0)), 2)
    girth, limbs, tails = (1.0 + 0.1 * genes[g] for g in ("girth", "limbs", "tails"))
    assert variant["name"] == f"{document['name']} m2"
    for old, new in zip(document["parts"], variant["parts"], strict=True):
        assert new["r"] == pytest.approx(old["r"] * girth)
        if old["shape"] == "leg":
            assert new["upper"] == pytest.approx(old["upper"] * limbs)
        if old["shape"] == "rope":
            assert new["length"] == pytest.approx(old["length"] * tails)
    for old, new in zip(document["blend"]["nodes"], variant["blend"]["nodes"], strict=True):
        assert new["k"] == pytest.approx(old["k"] * girth)
    # One LCG stream: consecutive identities are not an arithmetic progression of one another.
    girths = [identity_genes(0, i)["girth"] for i in range(1, 5)]
    steps = np.diff(girths)
    assert not np.allclose(steps, steps[0], atol=1e-3), girths
    assert all(-1.0 <= g < 1.0 for i in range(1, 32) for g in identity_genes(4801, i).values())


def test_build_population_writes_one_package_per_identity(tmp_path: Path) -> None:
    spec = EXAMPLES / "reference" / "hopper.json"
    out = tmp_path / "out"
    done = run_cli("build", str(spec), "-o", str(out), "--population", "2")
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    slug = slugify(json.loads(spec.read_text())["name"])
    assert sorted(p.name for p in out.iterdir()) == [slug, f"{slug}-m1"]
    digests = set()
    for folder in out.iterdir():
        sidecar = json.loads((folder / "assets" / "surface.json").read_text())
        digests.add(sidecar["signatures"]["geometryDigest"])
        shipped = validate_bytes((folder / "assets" / "spec.json").read_bytes(), str(folder))
        assert isinstance(shipped, CharacterSpec)
    assert len(digests) == 2, "the identities share a geometry"
    assert "==> identity m1 (2 of 2): girth x" in done.stdout
    variant = load_spec(out / f"{slug}-m1" / "assets" / "spec.json")
    authored = load_spec(spec)
    assert isinstance(variant, CharacterSpec)
    assert isinstance(authored, CharacterSpec)
    ratio = compile_rig(variant).slots[0, col.RA] / compile_rig(authored).slots[0, col.RA]
    assert math.isfinite(ratio)
    assert ratio != 1.0
    assert abs(ratio - 1.0) <= authored.genetics.morphology + 1e-12


@pytest.mark.parametrize("value", ["0", "65", "two"])
def test_build_population_refuses_a_bad_count(value: str, tmp_path: Path) -> None:
    done = run_cli(
        "build", str(EXAMPLES / "reference" / "hopper.json"), "-o", str(tmp_path), "--population", value
    )
    assert done.returncode == 2
    assert "--population" in done.stderr
    assert not any(tmp_path.iterdir())


def test_build_population_is_for_creatures_only(tmp_path: Path) -> None:
    done = run_cli(
        "build", str(EXAMPLES / "frost" / "frost-full.json"), "-o", str(tmp_path), "--population", "2"
    )
    assert done.returncode == 2
    assert "--population: applies to creature specs only" in done.stderr
    assert not any(tmp_path.iterdir())


def test_morphology_leaves_explicit_nulls_alone() -> None:
    document = json.loads((EXAMPLES / "lizard.json").read_text())
    document["parts"][0]["k"] = None
    variant = variant_document(document, 1, 0.1)
    assert variant["parts"][0]["k"] is None


def _numbers(value: object) -> list[float]:
    if isinstance(value, dict):
        return [x for v in value.values() for x in _numbers(v)]
    if isinstance(value, list):
        return [x for v in value for x in _numbers(v)]
    return [value] if isinstance(value, float) else []


@pytest.mark.parametrize("name", ["reference/quadruped.json", "reference/flyer.json", "lizard.json"])
def test_motion_data_survives_a_json_round_trip_exactly(name: str) -> None:
    """core/genome.js express copies an individual's motion data through JSON (V8's fast layouts, so the
    step allocates nothing): exact only if no number is -0 or non-finite, which build_motion ensures."""
    data = _motion(name).to_json()
    numbers = _numbers(data)
    assert numbers
    assert all(math.isfinite(x) for x in numbers), f"{name}: a non-finite number in the motion data"
    assert not any(x == 0.0 and math.copysign(1.0, x) < 0 for x in numbers), f"{name}: -0 in the motion data"
    assert json.loads(json.dumps(data)) == data
