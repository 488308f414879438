"""The surface stage end to end on every conformance creature: sampling, extraction, every gate, skin
weights, the deformation choice, the bounded correction, the asset, the cache and the CLI. A body whose
parts close a loop is refused by name in tests/test_surface_handles.py.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from conftest import CREATURE_EXAMPLES, EXAMPLES, REPO, rest_surface, run_cli
from creaturegen.creature.assets import surface_path
from creaturegen.model.skeleton import build_skeleton
from creaturegen.motion.compiled import compile_creature
from creaturegen.spec import CharacterSpec, load_spec
from creaturegen.surface import lattice, mesh_gates
from creaturegen.surface.build import SurfaceBuild, build_surface
from creaturegen.surface.cache import SurfaceCache
from creaturegen.surface.glb import parse_glb
from creaturegen.surface.refusal import SurfaceRejectedError

#: Parts the field itself leaves detached (rope or antenna anchored beyond the parent's surface).
DETACHED = {
    "reference/quadruped.json": ("part.tail[0]",),
    "reference/swimmer.json": ("part.tail[0]",),
    "reference/hexapod.json": ("part.antenna-right", "part.antenna-left"),
}


def _spec(name: str) -> CharacterSpec:
    spec = load_spec(EXAMPLES / name)
    assert isinstance(spec, CharacterSpec)
    return spec


@cache
def _built(name: str, cache_root: str) -> SurfaceBuild:
    spec = _spec(name)
    return build_surface(
        compile_creature(spec), backend="wgpu", cache=SurfaceCache(Path(cache_root)), progress=lambda _: None
    )


@pytest.fixture(scope="module")
def cache_root(surface_cache_root: str) -> str:
    return surface_cache_root


@pytest.mark.parametrize("name", CREATURE_EXAMPLES)
def test_every_gate_passes_and_the_asset_is_consistent(name: str, cache_root: str) -> None:
    built = _built(name, cache_root)
    failed = [g.name for g in built.gates if not g.passed]
    assert failed == []
    names = {g.name for g in built.gates}
    for required in (
        "watertight",
        "euler",
        "selfIntersections",
        "inverted",
        "surfaceToZeroSet",
        "zeroSetToMesh",
        "minAngleP1",
        "weights.partition",
        "weights.barrier_leakage",
        "correctionNeverWorse",
    ):
        assert required in names
    assert any(n.startswith("deform.") for n in names)
    asset = built.asset
    assert asset.positions.shape[0] == built.sidecar["counts"]["vertices"]  # type: ignore[index]
    assert np.allclose(asset.weights.sum(axis=1), 1.0, atol=1e-6)
    assert np.allclose(np.linalg.norm(asset.normals, axis=1), 1.0, atol=1e-5)
    assert int(asset.slots.max()) < asset.rest_frames.shape[0]
    components = built.sidecar["components"]
    assert isinstance(components, dict)
    assert tuple(components["detached"]) == DETACHED.get(name, ())
    sampling = built.sidecar["sampling"]
    assert isinstance(sampling, dict)
    assert sampling["fine"] < sampling["dense"]


def test_a_cache_hit_skips_extraction(cache_root: str) -> None:
    name = "reference/hopper.json"
    first = _built(name, cache_root)
    messages: list[str] = []
    spec = _spec(name)
    again = build_surface(
        compile_creature(spec), cache=SurfaceCache(Path(cache_root)), progress=messages.append
    )
    assert again.cached
    assert not any("extracted" in m for m in messages)
    assert again.asset == first.asset
    assert again.signatures == first.signatures


def test_a_failed_gate_stops_the_build_and_names_it(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(mesh_gates, "MIN_ANGLE_P1_DEG", 89.0)
    monkeypatch.setattr(lattice, "MAX_REFINEMENTS", 0)
    spec = _spec("reference/hopper.json")
    with pytest.raises(SurfaceRejectedError, match=r"gate minAngleP1 = .* threshold 89"):
        build_surface(compile_creature(spec), backend="numpy", cache=None, progress=lambda _: None)


def test_every_failed_mesh_gate_names_the_part_nearby() -> None:
    """The pincer's first lattice fails the distance and normal gates at the crease where its claws meet
    the body; each failed gate's detail names the part whose primitive is nearest its worst point."""
    s = rest_surface(REPO / "tests" / "fixtures" / "pincer.json", "hero")
    skeleton = build_skeleton(s.spec, s.rig)
    gates, _ = mesh_gates.surface_mesh_gates(s.rig, s.extraction, s.field, skeleton, s.grid)
    failed = {g.name: g.detail for g in gates if not g.passed}
    assert {"surfaceToZeroSet", "zeroSetToMesh", "vertexNormalAngleP99"} <= set(failed), failed
    parts = ("part.body", "part.claw-left", "part.claw-right")
    for name, detail in failed.items():
        if name != "euler":
            assert any(f"near {p} at (" in detail for p in parts), (name, detail)
    assert "part.claw-right touches part.claw-left" in failed["euler"]


def _package_digest(folder: Path) -> str:
    h = hashlib.sha256()
    for path in sorted(folder.rglob("*")):
        if path.is_file():
            h.update(path.relative_to(folder).as_posix().encode())
            h.update(path.read_bytes())
    return h.hexdigest()


def test_cli_build_is_byte_identical_across_backends_and_caches(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    spec = str(EXAMPLES / "reference" / "hopper.json")
    digests = []
    for n, backend in enumerate(("numpy", "wgpu", "wgpu")):
        env_cache = tmp_path / f"cache-{min(n, 1)}"  # the third run reuses the second's cache: a hit
        # monkeypatch restores the run's own cache afterwards (deleting it sent later tests on this
        # worker into the user's real cache)
        monkeypatch.setenv("CREATUREGEN_CACHE", str(env_cache))
        result = run_cli("build", spec, "-o", str(tmp_path / f"out-{n}"), "--backend", backend)
        assert result.returncode == 0, result.stderr
        if n == 2:
            assert "cache hit" in result.stdout + result.stderr
        digests.append(_package_digest(tmp_path / f"out-{n}" / "hopper-squash-core"))
    assert digests[0] == digests[1] == digests[2]
    glb = surface_path(tmp_path / "out-0" / "hopper-squash-core").read_bytes()
    assert parse_glb(glb).positions.shape[1] == 3


def test_two_builds_sharing_a_cache_extract_once(tmp_path: Path) -> None:
    """Two `creaturegen build` processes started together on one spec and one cold cache: one extracts,
    the other waits on SurfaceCache.building and takes the entry (what lets the test workers share a
    cache), and both write the same package."""
    env = {**os.environ, "CREATUREGEN_CACHE": str(tmp_path / "cache")}
    spec = str(EXAMPLES / "reference" / "hopper.json")
    runs = [
        subprocess.Popen(
            [sys.executable, "-m", "creaturegen.cli", "build", spec, "-o", str(tmp_path / f"out-{n}")],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        for n in range(2)
    ]
    outputs = [run.communicate(timeout=600) for run in runs]
    assert [run.returncode for run in runs] == [0, 0], outputs
    logs = [out + err for out, err in outputs]
    assert sorted("cache hit" in log for log in logs) == [False, True], "expected one extraction, one hit"
    digests = {_package_digest(tmp_path / f"out-{n}" / "hopper-squash-core") for n in range(2)}
    assert len(digests) == 1


def test_cli_inspect_prints_the_surface_gates() -> None:
    """Through the run's surface cache: a cold build says which sampling backend it chose, a hit says
    where the entry is, and both print every gate."""
    result = run_cli(
        "inspect", str(EXAMPLES / "reference" / "hopper.json"), "--surface", "hero", "--tiers", "hero"
    )
    assert result.returncode == 0, result.stderr
    assert "gate watertight: 0 edges (<= 0) pass" in result.stdout
    assert "gate selfIntersections" in result.stdout
    assert "sampling backend" in result.stderr or "cache hit" in result.stderr


def test_cli_bad_backend_is_exit_2_and_writes_nothing(tmp_path: Path) -> None:
    result = run_cli(
        "build", str(EXAMPLES / "reference" / "hopper.json"), "-o", str(tmp_path), "--backend", "cuda"
    )
    assert result.returncode == 2
    assert "--backend" in result.stderr + result.stdout
    assert not any(tmp_path.iterdir())
    assert REPO.exists()
