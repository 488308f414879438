"""The reference-surface asset: .glb writer/reader, sidecar, cache, and three.js's GLTFLoader reading it."""

from __future__ import annotations

import json
import shutil
import struct
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest

from conftest import REPO, missing_setup
from creaturegen import __version__
from creaturegen.cachedir import default_cache_root
from creaturegen.surface.asset import SurfaceAsset
from creaturegen.surface.cache import SurfaceCache
from creaturegen.surface.glb import (
    ARRAY_BUFFER,
    ELEMENT_ARRAY_BUFFER,
    UNSIGNED_INT,
    UNSIGNED_SHORT,
    GlbFormatError,
    glb_bytes,
    parse_glb,
    read_glb,
    write_glb,
    write_sidecar,
)

CHECK_GLB = REPO / "tools" / "check-glb.mjs"
THREE = (
    REPO
    / "generator"
    / "creaturegen"
    / "web_lab"
    / "node_modules"
    / "three"
    / "examples"
    / "jsm"
    / "loaders"
    / "GLTFLoader.js"
)
EXTRAS: dict[str, object] = {"signatures": {"compilerSignature": "ab" * 32}, "tier": "full", "pi": 3.25}


def make_asset(
    vertices: int = 4, slots: int = 3, seed: int = 0, extras: dict[str, object] | None = None
) -> SurfaceAsset:
    """A tetrahedron (plus `vertices - 4` unused loose vertices) with random but valid per-vertex data."""
    rng = np.random.default_rng(seed)
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    if vertices > 4:
        positions = np.vstack([positions, rng.normal(size=(vertices - 4, 3))])
    normals = positions - positions.mean(axis=0)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    weights = rng.random((vertices, 4)) + 0.01
    weights /= weights.sum(axis=1, keepdims=True)
    frames = np.tile(np.eye(4), (slots, 1, 1))
    frames[:, 3, :3] = rng.normal(size=(slots, 3))  # column-major: translation in the last column
    return SurfaceAsset(
        positions=positions.astype(np.float32),
        normals=normals.astype(np.float32),
        indices=np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.uint32).ravel(),
        slots=rng.integers(0, slots, (vertices, 4)).astype(np.uint16),
        weights=weights.astype(np.float32),
        candidate=rng.integers(0, 9, vertices).astype(np.uint16),
        radial=(rng.random((vertices, 2)) * [2 * np.pi, 1.0]).astype(np.float32),
        rest_frames=frames.astype(np.float32),
        extras=EXTRAS if extras is None else extras,
    )


def chunks(data: bytes) -> tuple[dict[str, object], bytes, bytes]:
    """(JSON document, raw JSON chunk, BIN chunk), asserting the GLB framing on the way."""
    magic, version, total = struct.unpack_from("<III", data, 0)
    assert (magic, version, total) == (0x46546C67, 2, len(data))
    json_length, json_type = struct.unpack_from("<II", data, 12)
    assert json_type == 0x4E4F534A
    raw_json = data[20 : 20 + json_length]
    bin_length, bin_type = struct.unpack_from("<II", data, 20 + json_length)
    assert bin_type == 0x004E4942
    binary = data[28 + json_length : 28 + json_length + bin_length]
    assert 28 + json_length + bin_length == total
    return json.loads(raw_json), raw_json, binary


# --- glb -----------------------------------------------------------------------------------------------


def test_round_trip_is_exact(tmp_path: Path) -> None:
    asset = make_asset()
    write_glb(tmp_path / "a.glb", asset, name="surface")
    back = read_glb(tmp_path / "a.glb")
    assert back == asset
    assert back.indices.dtype == np.uint32
    assert back.slots.dtype == np.uint16
    assert back.candidate.dtype == np.uint16
    assert back.rest_frames.shape == (3, 4, 4)
    assert back.extras == EXTRAS
    assert back != make_asset(seed=1)


def test_rewrite_is_byte_identical(tmp_path: Path) -> None:
    first = write_glb(tmp_path / "a.glb", make_asset(), name="surface")
    second = write_glb(tmp_path / "b.glb", make_asset(), name="surface")
    assert first == second == (tmp_path / "a.glb").read_bytes() == (tmp_path / "b.glb").read_bytes()
    again = write_glb(tmp_path / "c.glb", read_glb(tmp_path / "a.glb"), name="surface")
    assert again == first
    assert glb_bytes(make_asset(), name="other") != first
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_glb_framing_alignment_and_json(tmp_path: Path) -> None:
    data = glb_bytes(make_asset(vertices=5), name="surface")
    document, raw_json, binary = chunks(data)
    assert len(data) % 4 == 0
    assert len(raw_json) % 4 == 0
    assert len(binary) % 4 == 0
    assert raw_json == raw_json.rstrip(b" ") + b" " * (len(raw_json) - len(raw_json.rstrip(b" ")))
    # Deterministic JSON: sorted keys, compact separators.
    stripped = raw_json.rstrip(b" ")
    assert (
        stripped == json.dumps(document, sort_keys=True, separators=(",", ":"), ensure_ascii=False).encode()
    )

    asset_info = document["asset"]
    assert isinstance(asset_info, dict)
    assert asset_info["version"] == "2.0"
    assert asset_info["generator"] == f"creaturegen {__version__}"
    assert asset_info["extras"] == EXTRAS

    views = document["bufferViews"]
    accessors = document["accessors"]
    buffers = document["buffers"]
    assert isinstance(views, list)
    assert isinstance(accessors, list)
    assert isinstance(buffers, list)
    assert buffers == [{"byteLength": len(binary)}]
    covered = np.zeros(len(binary), dtype=bool)
    for view in views:
        assert view["byteOffset"] % 4 == 0
        assert view["byteOffset"] + view["byteLength"] <= len(binary)
        covered[view["byteOffset"] : view["byteOffset"] + view["byteLength"]] = True
    # Padding between and after views is zeros.
    assert not np.frombuffer(binary, dtype=np.uint8)[~covered].any()

    meshes = document["meshes"]
    assert isinstance(meshes, list)
    assert len(meshes) == 1
    (primitive,) = meshes[0]["primitives"]
    assert primitive["mode"] == 4
    attributes = primitive["attributes"]
    assert set(attributes) == {
        "POSITION",
        "NORMAL",
        "_SLOTS",
        "_WEIGHTS",
        "_CANDIDATE",
        "_RADIAL",
        "_SKIN",
        "_COR",
    }
    formats = {name: (accessors[i]["componentType"], accessors[i]["type"]) for name, i in attributes.items()}
    assert formats == {
        "POSITION": (5126, "VEC3"),
        "NORMAL": (5126, "VEC3"),
        "_SLOTS": (5126, "VEC4"),
        "_WEIGHTS": (5126, "VEC4"),
        "_CANDIDATE": (5126, "SCALAR"),
        "_RADIAL": (5126, "VEC2"),
        "_SKIN": (5126, "VEC2"),
        "_COR": (5126, "VEC3"),
    }
    for name, i in attributes.items():
        view = views[accessors[i]["bufferView"]]
        assert view["target"] == ARRAY_BUFFER
        # Every vertex element starts on a 4-byte boundary (the 2-byte _CANDIDATE gets byteStride 4).
        assert view.get("byteStride", 4) % 4 == 0, name
        assert accessors[i]["count"] == 5
    assert "byteStride" not in views[accessors[attributes["_CANDIDATE"]]["bufferView"]]
    assert views[accessors[primitive["indices"]]["bufferView"]]["target"] == ELEMENT_ARRAY_BUFFER
    assert "byteStride" not in views[accessors[primitive["indices"]]["bufferView"]]

    position = accessors[attributes["POSITION"]]
    positions = make_asset(vertices=5).positions
    assert position["min"] == positions.min(axis=0).tolist()
    assert position["max"] == positions.max(axis=0).tolist()

    nodes = document["nodes"]
    assert isinstance(nodes, list)
    rest = accessors[nodes[0]["extras"]["restFramesAccessor"]]
    assert (rest["componentType"], rest["type"], rest["count"]) == (5126, "MAT4", 3)
    assert "target" not in views[rest["bufferView"]]
    assert {k: v for k, v in nodes[0]["extras"].items() if k != "restFramesAccessor"} == EXTRAS


@pytest.mark.parametrize(
    ("vertices", "component"), [(4, UNSIGNED_SHORT), (65535, UNSIGNED_SHORT), (65536, UNSIGNED_INT)]
)
def test_index_component_type(tmp_path: Path, vertices: int, component: int) -> None:
    """UNSIGNED_SHORT while every index stays below 65535 (glTF's primitive-restart value)."""
    asset = make_asset(vertices=vertices)
    data = write_glb(tmp_path / "a.glb", asset, name="surface")
    document, _, _ = chunks(data)
    accessors = document["accessors"]
    meshes = document["meshes"]
    assert isinstance(accessors, list)
    assert isinstance(meshes, list)
    index = accessors[meshes[0]["primitives"][0]["indices"]]
    assert index["componentType"] == component
    assert index["count"] == 12
    assert read_glb(tmp_path / "a.glb") == asset


def test_invalid_assets_are_rejected() -> None:
    good = make_asset()
    fields = {name: getattr(good, name) for name in good.__dataclass_fields__}
    bad_cases: list[dict[str, object]] = [
        {"normals": good.normals * 2},
        {"weights": good.weights * 2},
        {"weights": np.where(np.arange(4) == 0, -0.5, 0.5) * np.ones((4, 4))},
        {"slots": np.full((4, 4), 3)},
        {"indices": np.array([0, 1, 4])},
        {"indices": np.array([0, 1])},
        {"positions": np.full((4, 3), np.nan)},
        {"radial": np.full((4, 2), 1e39)},
        {"candidate": np.full(4, 70000)},
        {"candidate": np.full(4, 1.5)},
        {"rest_frames": np.zeros((0, 4, 4))},
        {"extras": {"restFramesAccessor": 1}},
        {"extras": {"x": float("nan")}},
        {"radial": np.zeros((4, 3))},
    ]
    for case in bad_cases:
        with pytest.raises(ValueError):  # noqa: PT011 - each case has its own message
            SurfaceAsset(**{**fields, **case})
    with pytest.raises(TypeError):
        SurfaceAsset(**{**fields, "extras": [1]})


def test_asset_arrays_are_read_only() -> None:
    asset = make_asset()
    with pytest.raises(ValueError, match="read-only"):
        asset.positions[0, 0] = 1.0


def test_garbage_is_a_format_error(tmp_path: Path) -> None:
    data = glb_bytes(make_asset(), name="surface")
    for broken in (
        b"",
        b"gltf" + data[4:],
        data[:8] + b"\0\0\0\0" + data[12:],
        data[:-4],
        data[:12] + b"\0" * (len(data) - 12),
    ):
        with pytest.raises(GlbFormatError):
            parse_glb(broken)
    (tmp_path / "x.glb").write_bytes(b"not a glb at all, just words")
    with pytest.raises(GlbFormatError):
        read_glb(tmp_path / "x.glb")


def test_sidecar_is_deterministic(tmp_path: Path) -> None:
    write_sidecar(tmp_path / "a.json", {"b": 1, "a": {"d": [1, 2], "c": "é"}})
    text = (tmp_path / "a.json").read_text(encoding="utf-8")
    assert text == '{\n  "a": {\n    "c": "é",\n    "d": [\n      1,\n      2\n    ]\n  },\n  "b": 1\n}\n'
    with pytest.raises(ValueError, match="JSON compliant"):
        write_sidecar(tmp_path / "b.json", {"x": float("inf")})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]


# --- three.js ------------------------------------------------------------------------------------------


def run_three(path: Path, *flags: str) -> dict[str, object]:
    node = shutil.which("node")
    if node is None:
        missing_setup("node is not installed")
    if not THREE.exists():
        missing_setup("web_lab/node_modules is missing (npm ci in web_lab)")
    result = subprocess.run(
        [node, str(CHECK_GLB), str(path), *flags], capture_output=True, text=True, check=False, timeout=120
    )
    assert result.returncode == 0, result.stderr
    report: dict[str, object] = json.loads(result.stdout)
    return report


def test_three_gltfloader_reads_the_asset(tmp_path: Path) -> None:
    asset = make_asset(vertices=6)
    write_glb(tmp_path / "a.glb", asset, name="creature-surface")
    report = run_three(tmp_path / "a.glb", "--values")

    assert report["warnings"] == []
    assert report["meshCount"] == 1
    assert report["meshName"] == "creature-surface"
    assert report["generator"] == f"creaturegen {__version__}"
    assert report["vertexCount"] == 6
    # Unknown attribute names are lower-cased by GLTFLoader; POSITION/NORMAL map to three's names.
    attributes = report["attributes"]
    assert isinstance(attributes, dict)
    assert set(attributes) == {
        "position",
        "normal",
        "_slots",
        "_weights",
        "_candidate",
        "_radial",
        "_skin",
        "_cor",
    }

    expected: dict[str, tuple[npt.NDArray[Any], str]] = {
        "position": (asset.positions, "Float32Array"),
        "normal": (asset.normals, "Float32Array"),
        "_slots": (asset.slots, "Float32Array"),
        "_weights": (asset.weights, "Float32Array"),
        "_candidate": (asset.candidate, "Float32Array"),
        "_radial": (asset.radial, "Float32Array"),
        "_skin": (np.asarray(asset.skin), "Float32Array"),
        "_cor": (np.asarray(asset.cor_centers), "Float32Array"),
    }
    for name, (values, array_type) in expected.items():
        seen = attributes[name]
        width = 1 if values.ndim == 1 else values.shape[1]
        assert (seen["itemSize"], seen["count"], seen["arrayType"]) == (width, 6, array_type), name
        assert seen["normalized"] is False
        assert np.array_equal(np.asarray(seen["values"], dtype=values.dtype), values.reshape(-1)), name
        # Every attribute is tightly packed 4-byte data: none is interleaved.
        assert seen["interleaved"] is False, name

    index = report["index"]
    assert isinstance(index, dict)
    assert index["arrayType"] == "Uint16Array"
    assert index["values"] == asset.indices.tolist()

    user_data = report["userData"]
    assert isinstance(user_data, dict)
    assert user_data["restFramesAccessor"] == 9  # after 8 attributes and the indices
    assert {k: user_data[k] for k in EXTRAS} == EXTRAS
    assert report["assetExtras"] == EXTRAS

    frames = report["restFrames"]
    assert isinstance(frames, dict)
    assert (frames["itemSize"], frames["count"]) == (16, 3)
    # Matrix4.fromArray order: the stored (S, 4, 4) array flattened is three's column-major elements.
    assert np.array_equal(np.asarray(frames["values"], dtype=np.float32), asset.rest_frames.reshape(-1))


def test_three_gltfloader_reads_uint32_indices(tmp_path: Path) -> None:
    write_glb(tmp_path / "big.glb", make_asset(vertices=65536), name="big")
    report = run_three(tmp_path / "big.glb")
    index = report["index"]
    assert isinstance(index, dict)
    assert (index["arrayType"], index["count"]) == ("Uint32Array", 12)
    assert report["vertexCount"] == 65536
    assert report["warnings"] == []


# --- cache ---------------------------------------------------------------------------------------------

C = "c0" * 32
T = "70" * 32
G = "9e" * 32
S = "5e" * 32


def same_prefix(signature: str) -> str:
    """Another full signature sharing the 16-digit folder prefix."""
    return signature[:16] + "f" * (len(signature) - 16)


def test_cache_store_then_hit(tmp_path: Path) -> None:
    cache = SurfaceCache(tmp_path)
    assert cache.lookup(C, G, "full", S) is None
    sidecar: dict[str, object] = {"vertexCount": 4, "signatures": {"topologySignature": T}}
    folder = cache.store(C, T, G, "full", S, make_asset(), sidecar)
    assert folder == tmp_path / C[:16] / G[:16] / f"{T[:16]}-full"
    assert sorted(p.name for p in folder.iterdir()) == ["surface.glb", "surface.json"]
    assert (folder.parent / f"index-full-{S[:16]}.json").is_file()

    hit = cache.lookup(C, G, "full", S)
    assert hit is not None
    assert hit.asset == make_asset()
    assert hit.sidecar == sidecar
    assert hit.folder == folder
    stored = json.loads((folder / "surface.json").read_text())
    assert stored["cacheKey"]["compilerSignature"] == C
    assert stored["cacheKey"]["topologySignature"] == T
    assert stored["cacheKey"]["geometryDigest"] == G
    assert not list(tmp_path.rglob("*.tmp"))


def test_cache_misses_on_other_tier_or_settings(tmp_path: Path) -> None:
    cache = SurfaceCache(tmp_path)
    cache.store(C, T, G, "full", S, make_asset(), {})
    assert cache.lookup(C, G, "lite", S) is None
    assert cache.lookup(C, G, "full", "ab" * 32) is None
    assert cache.lookup("ab" * 32, G, "full", S) is None
    assert cache.lookup(C, "ab" * 32, "full", S) is None
    assert cache.lookup(C, G, "full", S) is not None


def test_cache_corrupt_glb_is_a_miss_and_store_repairs_it(tmp_path: Path) -> None:
    cache = SurfaceCache(tmp_path)
    folder = cache.store(C, T, G, "full", S, make_asset(), {"a": 1})
    glb = folder / "surface.glb"
    data = bytearray(glb.read_bytes())
    data[-8] ^= 0xFF  # a flipped bit in the vertex data still parses: the recorded hash catches it
    glb.write_bytes(bytes(data))
    assert cache.lookup(C, G, "full", S) is None
    glb.write_bytes(b"truncated")
    assert cache.lookup(C, G, "full", S) is None
    (folder / "surface.json").write_text("{not json")
    assert cache.lookup(C, G, "full", S) is None
    (folder.parent / f"index-full-{S[:16]}.json").write_text("[]")
    assert cache.lookup(C, G, "full", S) is None

    cache.store(C, T, G, "full", S, make_asset(), {"a": 1})
    hit = cache.lookup(C, G, "full", S)
    assert hit is not None
    assert hit.asset == make_asset()
    assert hit.sidecar == {"a": 1}


def test_cache_full_signature_mismatch_with_same_prefix_is_a_miss(tmp_path: Path) -> None:
    cache = SurfaceCache(tmp_path)
    cache.store(C, T, G, "full", S, make_asset(), {})
    # Same folder and index paths, different full signatures.
    assert cache.index_path(same_prefix(C), same_prefix(G), "full", same_prefix(S)) == cache.index_path(
        C, G, "full", S
    )
    assert cache.lookup(same_prefix(C), G, "full", S) is None
    assert cache.lookup(C, same_prefix(G), "full", S) is None
    assert cache.lookup(C, G, "full", same_prefix(S)) is None
    assert cache.read_entry(C, same_prefix(T), G, "full") is None
    assert cache.read_entry(C, T, G, "full") is not None

    # An index pointing at a topology whose folder holds another full topologySignature.
    index = cache.index_path(C, G, "full", S)
    record = json.loads(index.read_text())
    record["topologySignature"] = same_prefix(T)
    index.write_text(json.dumps(record))
    assert cache.lookup(C, G, "full", S) is None


def test_cache_rejects_unsafe_keys(tmp_path: Path) -> None:
    cache = SurfaceCache(tmp_path)
    with pytest.raises(ValueError, match="tier"):
        cache.lookup(C, G, "../x", S)
    with pytest.raises(ValueError, match="compilerSignature"):
        cache.lookup("short", G, "full", S)
    with pytest.raises(ValueError, match="reserved"):
        cache.store(C, T, G, "full", S, make_asset(), {"cacheKey": 1})


def test_cache_default_root(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("CREATUREGEN_CACHE", str(tmp_path / "c"))
    assert default_cache_root() == tmp_path / "c"
    assert SurfaceCache().root == tmp_path / "c"
    monkeypatch.delenv("CREATUREGEN_CACHE")
    monkeypatch.setenv("HOME", str(tmp_path))
    assert default_cache_root() == tmp_path / ".cache" / "creaturegen" / "surface"
