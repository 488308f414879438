"""A package that ships several tiers (``creaturegen build --tier hero,distant``): one .glb per tier, the
tiers in CREATURE.tiers, and a population that moves its bodies between them by their size on screen.
The parity job's tier gates (creature_tiers.py) are run on the hopper and shown to fail on a planted
move that leaves the moved body's surface undeformed; the choice gate's comparison is shown to fail on a
planted wrong choice in Python (reference_walk), and tests/test_lod.py holds core/lod.js to
creature/lod.py. Fails (never skips) when the browser or node_modules is missing.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import build_example, run_cli, spec_file
from creaturegen.creature.assets import surface_path
from creaturegen.lab.creature_parity import run_creature_parity
from creaturegen.lab.creature_tiers import reference_walk, shipped_ceilings
from test_creature_parity import TWO_TIER_EXAMPLE, _planted, assert_every_gate

TWO_TIERS = "hero,distant"


@pytest.fixture
def two_tier(creature_out: Path) -> Path:
    return build_example(TWO_TIER_EXAMPLE, creature_out, TWO_TIERS)


def _data(package: Path) -> dict[str, object]:
    text = (package / "core" / "data.js").read_text()
    start = text.index("Object.freeze(") + len("Object.freeze(")
    data: dict[str, object] = json.loads(text[start : text.rindex(");")])
    return data


def test_a_two_tier_package_ships_both_surfaces_finest_first(two_tier: Path) -> None:
    data = _data(two_tier)
    tiers = data["tiers"]
    assert isinstance(tiers, list)
    assert [t["tier"] for t in tiers] == ["hero", "distant"]
    assert data["tier"] == "hero"
    assert data["surfaceFile"] == tiers[0]["surfaceFile"]
    assert tiers[1]["mesh"]["vertices"] < tiers[0]["mesh"]["vertices"]
    assert tiers[1]["projectedSizeMaxPx"] < tiers[0]["projectedSizeMaxPx"]
    files = json.loads((two_tier / "package.json").read_text())["files"]
    for t in tiers:
        assert (two_tier / "assets" / t["surfaceFile"]).is_file()
        assert f"assets/{t['surfaceFile']}" in files
    # Every tier's own static URL, for bundlers.
    asset = (two_tier / "tsl" / "asset.js").read_text()
    for t in tiers:
        assert f'new URL("../assets/{t["surfaceFile"]}", import.meta.url)' in asset
    assert shipped_ceilings(two_tier) == {t["tier"]: t["projectedSizeMaxPx"] for t in tiers}
    # Python tools find the finest tier's surface (the package's own) whether or not the report is there.
    assert surface_path(two_tier).name == tiers[0]["surfaceFile"]


def test_tier_lists_are_checked_on_the_command_line(tmp_path: Path) -> None:
    spec = str(spec_file("reference/hopper.json"))
    for bad, says in (("hero,far", "unknown tier 'far'"), ("hero,hero", "a tier named twice")):
        result = run_cli("build", spec, "-o", str(tmp_path), "--tier", bad)
        assert result.returncode == 2, result.stdout + result.stderr
        assert says in result.stderr
    assert not any(tmp_path.iterdir())


def test_the_reference_walk_finds_a_wrong_choice() -> None:
    """reference_walk replays creature/lod.py over what the page recorded: a frame whose recorded tier
    differs from the rule's, or whose size does, is reported."""
    view = [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, -10.0, 1.0]  # eye at z = 10 looking down -z
    body = {"id": 0, "centre": [0.0, 0.0, 0.0], "size": 1.0}
    ceilings = {"hero": 200.0, "distant": 40.0}
    frames = []
    for size_px, tier in ((100.0, "hero"), (20.0, "distant"), (20.0, "hero")):
        # The height that makes L = 1 at depth 10 with fov 90° measure size_px.
        frames.append(
            {
                "view": view,
                "fov": 90.0,
                "zoom": 1.0,
                "height": size_px * 20.0,
                "bodies": [{**body, "tier": tier, "sizePx": size_px}],
            }
        )
    replay = reference_walk(frames, 1.0, ceilings, "hero")
    assert replay["sizeRelError"] < 1e-12
    assert [m["frame"] for m in replay["mismatches"]] == [2]
    assert replay["moves"] == {"finer": 0, "coarser": 1}
    frames[0]["bodies"][0]["sizePx"] = 101.0
    assert reference_walk(frames, 1.0, ceilings, "hero")["sizeRelError"] > 1e-3


@pytest.mark.browser
def test_a_two_tier_package_passes_every_parity_gate(two_tier: Path) -> None:
    """The whole job, grid included: the tier walk, and every other group on the finest tier, which is the
    hero hopper's body (so `make test` runs the hopper's job here and not on a second, hero-only package)."""
    assert_every_gate(two_tier, TWO_TIER_EXAMPLE)
    written = json.loads((two_tier / "parity" / "report.json").read_text())
    names = {g["name"] for g in written["gates"]}
    assert "pipelines and buffers created by the walk's tier moves (device count)" in names
    assert any(n.startswith("silhouette of the distant tier vs the hero tier") for n in names)
    moves = written["measurements"]["tierWalk"]["moves"]
    print(f"two-tier hopper: walk moves {moves}, {written['measurements']['silhouette.distant']}")
    assert moves["finer"] > 0
    assert moves["coarser"] > 0


@pytest.mark.browser
def test_the_job_catches_a_move_that_does_not_deform_the_moved_body(two_tier: Path, tmp_path: Path) -> None:
    planted = _planted(two_tier, tmp_path, "tiers.js", [("  to.moved[j] = 1;\n", "")])
    report = run_creature_parity(planted, groups=("tiers",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert any(n.startswith("silhouette of the distant tier") for n in failed), report.summary()
    assert any(n.startswith("drawn vertices of") and "moved back to hero" in n for n in failed), (
        report.summary()
    )
