"""The generated corpus: plausible random specs, the corpus runner, and a fixed subset that cannot regress.

``make corpus`` builds 200 generated specs at every tier (hours on two cores); ``make test`` builds a fixed
subset (the first SUBSET_SEEDS seeds, not chosen by outcome) at hero and distant and holds it to the
recorded outcomes in tests/corpus-baseline.json: a spec that built there must still build, and every
refusal must name a part. A spec that now builds where it was refused is an improvement: the test says so
and the baseline should be updated (by hand, after looking at why).
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections import Counter
from pathlib import Path

import pytest

from conftest import gallery_shows_every_card
from creaturegen.batch.task import parse_refusal
from creaturegen.corpus.random import LOCOMOTION_WEIGHTS, PART_RANGE, SCALE_RANGE, random_creature
from creaturegen.corpus.run import run_corpus
from creaturegen.spec import CharacterSpec, validate_bytes

BASELINE = Path(__file__).parent / "corpus-baseline.json"
SUBSET_SEEDS = range(0, 3)
SUBSET_TIERS = ("hero", "distant")


def test_random_specs_validate_and_cover_what_people_write() -> None:
    kinds: Counter[str] = Counter()
    blends: Counter[str] = Counter()
    features: Counter[str] = Counter()
    parts = []
    for seed in range(300):
        raw = random_creature(seed)
        spec = validate_bytes(json.dumps(raw).encode(), f"seed {seed}")
        assert isinstance(spec, CharacterSpec)
        kinds[spec.locomotion.type if spec.locomotion else "none"] += 1
        blends[spec.blend.mode if spec.blend else "default"] += 1
        parts.append(len(spec.parts))
        assert SCALE_RANGE[0] <= spec.scale <= SCALE_RANGE[1]
        for part in spec.parts:
            features[part.id.split("-")[0]] += 1
            if part.shape == "rope":
                features["rope"] += 1
        features["named colour"] += any(not str(p["color"]).startswith("#") for p in raw["parts"])
        legs = sum(p.shape == "leg" for p in spec.parts)
        hopper = spec.locomotion is not None and spec.locomotion.type == "hopper"
        features["hopper with legs"] += hopper and legs == 2
        features["8 legs"] += legs == 8
    assert set(kinds) == set(LOCOMOTION_WEIGHTS)
    assert set(blends) == {"default", "tree", "symmetric-nary"}
    assert PART_RANGE[0] <= min(parts)
    assert max(parts) <= PART_RANGE[1]
    assert max(parts) >= 20
    for feature in (
        "eye",
        "ear",
        "horn",
        "neck",
        "antenna",
        "snout",
        "spike",
        "claw",
        "rope",
        "named colour",
    ):
        assert features[feature] > 0, feature


def test_the_same_seed_gives_the_same_spec() -> None:
    assert random_creature(7) == random_creature(7)
    assert random_creature(7) != random_creature(8)
    pinned = random_creature(7, "octopod")
    assert pinned["locomotion"]["type"] == "octopod"
    assert sum(p["shape"] == "leg" for p in pinned["parts"]) == 8


def test_random_command_writes_valid_specs(tmp_path: Path) -> None:
    run = [sys.executable, "-m", "creaturegen.cli"]
    done = subprocess.run(
        [*run, "random", "--seed", "40", "--count", "3", "--locomotion", "flyer", "-o", str(tmp_path)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    files = sorted(tmp_path.glob("*.json"))
    assert [f.name for f in files] == ["seed-00040.json", "seed-00041.json", "seed-00042.json"]
    check = subprocess.run([*run, "validate", *map(str, files)], capture_output=True, text=True, check=False)
    assert check.returncode == 0, check.stderr
    bad = subprocess.run(
        [*run, "random", "--locomotion", "bird", "-o", str(tmp_path / "x")],
        capture_output=True,
        text=True,
        check=False,
    )
    assert bad.returncode == 2
    assert "--locomotion" in bad.stderr
    assert not (tmp_path / "x").exists()


def test_refusal_messages_are_parsed_into_gate_value_and_parts() -> None:
    stderr = (
        "  surface: lattice ...\nerror: XDG_RUNTIME_DIR is invalid\n"
        "x.json: surface.hero: surface hero skin weights: gate weights.continuity = 0.4191 max |Δw| per "
        "edge, threshold 0.4 (max): worst edge between part.eye-left and part.head\n"
    )
    parsed = parse_refusal(stderr)
    assert parsed["gate"] == "weights.continuity"
    assert parsed["value"] == pytest.approx(0.4191)
    assert parsed["threshold"] == pytest.approx(0.4)
    assert parsed["parts"] == ["eye-left", "head"]


@pytest.mark.browser
def test_the_corpus_subset_holds_its_recorded_outcomes(tmp_path: Path) -> None:
    """Hero and distant builds of the first seeds, each in its own process with a cold cache, through
    build-many; its gallery opened in Chromium shows every card."""
    report = run_corpus(tmp_path, SUBSET_SEEDS, SUBSET_TIERS, jobs=1)
    baseline = json.loads(BASELINE.read_text())
    outcome = {(r["spec"], r["tier"]): r for r in report["results"]}
    regressed, improved = [], []
    for (spec, tier), record in outcome.items():
        expected = baseline[spec][tier]
        if record["status"] != "built":
            assert record["status"] == "refused", record
            assert record["exitCode"] == 3
            assert record["parts"], f"{spec} {tier}: the refusal names no part: {record['message']}"
            if expected == "built":
                regressed.append(f"{spec} {tier}: {record['message']}")
        elif expected != "built":
            improved.append(f"{spec} {tier}")
    assert not regressed, regressed
    if improved:
        print(f"now built (update {BASELINE.name}): {improved}")
    # The report and the gallery say the same.
    assert (tmp_path / "index.html").read_text().count('class="card"') == len(SUBSET_SEEDS)
    for tier in SUBSET_TIERS:
        summary = report["summary"][tier]
        built = sum(1 for r in report["results"] if r["tier"] == tier and r["status"] == "built")
        assert summary["built"] == built
        assert summary["specs"] == len(SUBSET_SEEDS)
    gallery_shows_every_card(tmp_path / "index.html", len(SUBSET_SEEDS))
    pictures = list((tmp_path / "pictures").glob("*.png"))
    assert len(pictures) == sum(
        any(outcome[(f"seed-{s:05d}.json", t)]["status"] == "built" for t in SUBSET_TIERS)
        for s in SUBSET_SEEDS
    )
