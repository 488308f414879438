"""The tier rule (creature/lod.py): its properties in Python, and the package's core/lod.js against it in
Node, frame for frame over random size sequences and random cameras."""

from __future__ import annotations

import itertools
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from conftest import build_example, run_node_tests
from creaturegen.creature.lod import HYSTERESIS, TIER_ORDER, choose_tier, projected_size_px

CEILINGS = {"distant": 40.0, "repeated": 120.0, "hero": 190.0}


def test_a_body_takes_the_coarsest_tier_that_covers_it() -> None:
    assert choose_tier(10.0, None, CEILINGS) == "distant"
    assert choose_tier(80.0, None, CEILINGS) == "repeated"
    assert choose_tier(500.0, None, CEILINGS) == "hero"  # the finest built tier takes any size
    assert choose_tier(80.0, None, {"hero": 190.0, "distant": 40.0}) == "hero"
    assert choose_tier(80.0, None, {"repeated": 120.0, "distant": 40.0}) == "repeated"
    assert choose_tier(500.0, None, {"repeated": 120.0, "distant": 40.0}) == "repeated"


def test_hysteresis_holds_a_tier_at_its_boundary() -> None:
    """Growing past a ceiling switches at once (the subpixel contract); shrinking back switches only
    HYSTERESIS inside the coarser tier's ceiling."""
    assert choose_tier(40.1, "distant", CEILINGS) == "repeated"
    assert choose_tier(39.0, "repeated", CEILINGS) == "repeated"
    assert choose_tier(40.0 * (1.0 - HYSTERESIS) - 1e-9, "repeated", CEILINGS) == "distant"
    sizes = 40.0 + 2.0 * np.sin(np.linspace(0.0, 20.0, 200))  # a body wobbling across the boundary
    tier: str | None = None
    chosen = []
    for size in sizes:
        tier = choose_tier(float(size), tier, CEILINGS)
        chosen.append(tier)
    assert sum(a != b for a, b in itertools.pairwise(chosen)) == 1, "one switch, then held"


def test_projected_size_follows_the_camera() -> None:
    near = projected_size_px(1.0, 2.0, 720.0, fov_deg=50.0)
    assert projected_size_px(1.0, 4.0, 720.0, fov_deg=50.0) == pytest.approx(near / 2.0)
    assert projected_size_px(1.0, 2.0, 720.0, fov_deg=50.0, zoom=2.0) == pytest.approx(2.0 * near)
    assert near == pytest.approx(720.0 / (2.0 * 2.0 * math.tan(math.radians(25.0))))
    assert projected_size_px(1.0, 99.0, 600.0, ortho_height=6.0) == pytest.approx(100.0)


def _reference(seed: int = 5) -> dict[str, object]:
    rng = np.random.default_rng(seed)
    sequences = []
    switches = 0
    subsets = [("hero",), ("distant", "hero"), ("repeated", "hero"), ("distant", "repeated", "hero")]
    for i in range(120):
        built = subsets[i % len(subsets)]
        distant = float(rng.uniform(20.0, 80.0))
        base = {"distant": distant, "repeated": distant * float(rng.uniform(1.5, 3.0)), "hero": 200.0}
        ceilings = {t: base[t] for t in built}
        sizes = np.exp(np.cumsum(rng.normal(0.0, 0.12, 60)) + math.log(float(rng.uniform(10.0, 300.0))))
        tier: str | None = None
        tiers = []
        for size in sizes.tolist():
            tier = choose_tier(size, tier, ceilings)
            tiers.append(tier)
        switches += sum(a != b for a, b in itertools.pairwise(tiers))
        sequences.append({"ceilings": ceilings, "sizes": sizes.tolist(), "tiers": tiers})
    projections = []
    for i in range(200):
        ortho = float(rng.uniform(1.0, 20.0)) if i % 3 == 0 else None
        case = {
            "length": float(rng.uniform(0.05, 5.0)),
            "depth": float(rng.uniform(0.1, 500.0)),
            "viewport": float(rng.integers(64, 2160)),
            "fov": float(rng.uniform(10.0, 100.0)),
            "zoom": float(rng.uniform(0.5, 3.0)),
            "orthoHeight": ortho,
        }
        fov = None if ortho is not None else case["fov"]
        size = projected_size_px(
            case["length"],
            case["depth"],
            case["viewport"],
            fov_deg=fov,
            ortho_height=ortho,
            zoom=case["zoom"],
        )
        projections.append({**case, "size": size})
    return {
        "order": list(TIER_ORDER),
        "hysteresis": HYSTERESIS,
        "sequences": sequences,
        "switches": switches,
        "projections": projections,
    }


def test_the_package_rule_is_the_reference(creature_out: Path, tmp_path: Path) -> None:
    package = build_example("reference/hopper.json", creature_out)
    reference = _reference()
    assert reference["switches"], "the random sizes never cross a ceiling"
    path = tmp_path / "lod-reference.json"
    path.write_text(json.dumps(reference))
    env = {"LOD_CORE": str(package / "core" / "index.js"), "LOD_REFERENCE": str(path)}
    done = run_node_tests("lod.test.mjs", env)
    assert re.search(r"\bpass 3\b", done.stdout), done.stdout
