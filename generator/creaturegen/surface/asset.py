"""The reference-surface asset: a hand-written glTF 2.0 binary (.glb), its JSON sidecar and a disk cache.

Why by hand: the asset is a cache artefact and a build output, so its bytes must be a pure function of
its arrays (byte-identical rewrites, diffable builds). A writer of ~200 lines with struct and numpy
gives that without a dependency whose output may shift between versions; the reader is only meant for
files this writer made (the cache and the tests), not for arbitrary glTF.

Layout of one file: one scene, one node, one mesh, one triangle primitive. Attributes POSITION (with
the min/max the spec requires) and NORMAL, plus application-specific ones (glTF wants a leading
underscore; three.js's GLTFLoader lower-cases unknown names, so ``_SLOTS`` arrives as ``_slots``):

- ``_SLOTS`` FLOAT VEC4: the slot index of each of the four influences (whole numbers, exact in
  float32 below 2²⁴);
- ``_WEIGHTS`` FLOAT VEC4: their weights (non-negative, sum 1);
- ``_CANDIDATE`` FLOAT SCALAR: the candidate program index (a whole number);
- ``_RADIAL`` FLOAT VEC2: (θ around, t along) the dominant slot's axis;
- ``_SKIN`` FLOAT VEC2: the vertex's skinning method (0 LBS, 1 DQ, 2 CoR: its joint's choice) and its
  correction trust radius in metres, 0 outside the correction region (the region policy, baked);
- ``_COR`` FLOAT VEC3: the vertex's centre of rotation (used only where the method is CoR, else 0);
- ``_COLOUR_SLOTS`` and ``_COLOUR_WEIGHTS`` FLOAT VEC4, only in a skin-represented tier (distant): the
  four leaves of largest rest proximity-colour weight and those weights renormalised to sum 1, which
  colour the vertices that evaluate no field (``_CANDIDATE`` = SKIN_PROGRAM, surface/build.py).

Indices are UNSIGNED_SHORT when every index fits below 65535 (the value glTF reserves for primitive
restart), UNSIGNED_INT otherwise. Per-slot rest frames are one more accessor (FLOAT MAT4, count S)
that no primitive uses; the node's ``extras.restFramesAccessor`` names it. The caller's ``extras``
(signatures and such) go to both ``asset.extras`` and the node's ``extras``: three.js exposes the
first as ``gltf.asset.extras`` and the second as the mesh's ``userData``.

Why the indices are FLOAT: three.js r185's WebGPU backend widens non-normalised UNSIGNED_SHORT vertex
data to uint32 with a fixed 4-byte stride (WebGPUAttributeUtils, "patch for UINT16"), which fits
neither a VEC4 nor a 2-byte scalar padded to glTF's 4-byte element alignment. Float attributes load
and draw as they are; the shader rounds them to integers.

Determinism: arrays are written little-endian in a fixed order, every buffer view starts on a 4-byte
boundary, the JSON has sorted keys, no whitespace and no NaN, the JSON chunk is padded with spaces and
the BIN chunk with zeros.

The cache: a surface is identified by (compilerSignature, topologySignature, geometryDigest, tier);
the topologySignature is only known once the surface is built (it includes the deformation methods
chosen), so a lookup goes through an index file keyed by (compilerSignature, geometryDigest, tier,
settingsDigest). Folder names use 16-hex-digit prefixes for readable paths, but every full signature
is stored in the JSON and compared on read: a prefix collision is a miss, never a wrong hit. Every
file is written atomically (temporary file in the same folder, then ``os.replace``), entries are
written before the index that points at them, and anything unreadable, inconsistent or corrupt (the
sidecar records the .glb's SHA-256) reads as a miss, which the next ``store`` overwrites.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import struct
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final, cast

import numpy as np
import numpy.typing as npt

from .. import __version__
from ..cachedir import default_cache_root

GLB_MAGIC: Final = 0x46546C67  # "glTF"
GLB_VERSION: Final = 2
CHUNK_JSON: Final = 0x4E4F534A  # "JSON"
CHUNK_BIN: Final = 0x004E4942  # "BIN\0"

ARRAY_BUFFER: Final = 34962
ELEMENT_ARRAY_BUFFER: Final = 34963
TRIANGLES: Final = 4

UNSIGNED_SHORT: Final = 5123
UNSIGNED_INT: Final = 5125
FLOAT: Final = 5126

#: Node-extras key naming the rest-frame accessor; reserved, so not allowed in ``SurfaceAsset.extras``.
REST_FRAMES_KEY: Final = "restFramesAccessor"

#: Largest vertex count whose indices fit UNSIGNED_SHORT (65535 is the primitive-restart value).
MAX_UINT16_VERTICES: Final = 65535

_COMPONENT_DTYPES: Final[dict[int, str]] = {UNSIGNED_SHORT: "<u2", UNSIGNED_INT: "<u4", FLOAT: "<f4"}
_TYPE_SIZES: Final[dict[str, int]] = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}

#: Tolerances of the invariants checked on construction (float32 data built in float64).
UNIT_TOLERANCE: Final = 1e-3
WEIGHT_SUM_TOLERANCE: Final = 1e-3

F32 = npt.NDArray[np.float32]
U16 = npt.NDArray[np.uint16]
U32 = npt.NDArray[np.uint32]


class GlbFormatError(ValueError):
    """A .glb that this module did not write, or that is damaged."""


def _frozen(array: npt.ArrayLike, dtype: str, shape: tuple[int | None, ...], name: str) -> Any:
    """A read-only, C-contiguous copy of ``array`` in ``dtype``; ``None`` in ``shape`` is any length."""
    source = np.asarray(array)
    if source.ndim != len(shape) or any(
        want is not None and have != want for have, want in zip(source.shape, shape, strict=True)
    ):
        raise ValueError(f"{name}: shape {source.shape}, expected {shape}")
    target = np.dtype(dtype)
    if target.kind in "ui":
        if source.size and source.dtype.kind not in "ui":
            raise ValueError(f"{name}: integer data expected, got {source.dtype}")
        info = np.iinfo(target)
        if source.size and (int(source.min()) < info.min or int(source.max()) > info.max):
            raise ValueError(f"{name}: values outside {target}")
    with np.errstate(over="ignore", invalid="ignore"):  # overflow to inf is reported just below
        result = np.array(source, dtype=target, order="C", copy=True)
    if target.kind == "f" and not np.all(np.isfinite(result)):
        raise ValueError(f"{name}: non-finite values (in {target})")
    result.flags.writeable = False
    return result


def _json_clean(value: object, what: str) -> dict[str, object]:
    """``value`` after a strict JSON round trip (tuples become lists, keys must be strings)."""
    if not isinstance(value, dict):
        raise TypeError(f"{what} must be a dict")
    try:
        text = json.dumps(value, allow_nan=False, sort_keys=True)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{what} is not strict JSON: {error}") from error
    return cast(dict[str, object], json.loads(text))


@dataclass(frozen=True, eq=False)
class SurfaceAsset:
    """One reference surface: V vertices, F triangles, S slots. Arrays are copied and made read-only.

    ``rest_frames[s]`` is stored column-major like glTF and three.js ``Matrix4.elements``:
    ``rest_frames[s].reshape(16)`` is the element list, ``rest_frames[s].T`` the matrix in row-column
    notation, ``rest_frames[s, 3, :3]`` the translation.
    """

    positions: F32  # (V, 3)
    normals: F32  # (V, 3), unit length
    indices: U32  # (3F,), counter-clockwise seen from outside
    slots: U16  # (V, 4), slot index of each influence, < S
    weights: F32  # (V, 4), non-negative, rows sum to 1
    candidate: U16  # (V,), candidate program index
    radial: F32  # (V, 2), (θ around, t along) the dominant slot's axis
    rest_frames: F32  # (S, 4, 4), column-major
    extras: dict[str, object] = field(default_factory=dict)
    skin: F32 | None = None  # (V, 2): method code (0 lbs, 1 dq, 2 cor), trust radius (0: no correction)
    cor_centers: F32 | None = None  # (V, 3): CoR centre where the method is CoR, else 0
    colour_slots: U16 | None = None  # (V, 4): baked colour leaves (skin-represented tiers only)
    colour_weights: F32 | None = None  # (V, 4): their weights, rows sum to 1

    def __post_init__(self) -> None:
        positions = _frozen(self.positions, "<f4", (None, 3), "positions")
        v = int(positions.shape[0])
        if v == 0:
            raise ValueError("positions: at least one vertex required")
        normals = _frozen(self.normals, "<f4", (v, 3), "normals")
        indices = _frozen(self.indices, "<u4", (None,), "indices")
        slots = _frozen(self.slots, "<u2", (v, 4), "slots")
        weights = _frozen(self.weights, "<f4", (v, 4), "weights")
        candidate = _frozen(self.candidate, "<u2", (v,), "candidate")
        radial = _frozen(self.radial, "<f4", (v, 2), "radial")
        rest_frames = _frozen(self.rest_frames, "<f4", (None, 4, 4), "rest_frames")
        extras = _json_clean(self.extras, "extras")
        skin = _frozen(np.zeros((v, 2)) if self.skin is None else self.skin, "<f4", (v, 2), "skin")
        cor = np.zeros((v, 3)) if self.cor_centers is None else self.cor_centers
        cor_centers = _frozen(cor, "<f4", (v, 3), "cor_centers")
        if (self.colour_slots is None) != (self.colour_weights is None):
            raise ValueError("colour_slots and colour_weights: both or neither")
        colour_slots = (
            None if self.colour_slots is None else _frozen(self.colour_slots, "<u2", (v, 4), "colour_slots")
        )
        colour_weights = (
            None
            if self.colour_weights is None
            else _frozen(self.colour_weights, "<f4", (v, 4), "colour_weights")
        )
        if colour_weights is not None and colour_slots is not None:
            if np.any(colour_weights < 0) or np.any(
                np.abs(colour_weights.astype(np.float64).sum(axis=1) - 1.0) > WEIGHT_SUM_TOLERANCE
            ):
                raise ValueError("colour_weights: must be non-negative and sum to 1")
            if int(colour_slots.max()) >= rest_frames.shape[0]:
                raise ValueError("colour_slots: slot index out of range of rest_frames")

        if indices.size == 0 or indices.size % 3:
            raise ValueError(f"indices: {indices.size} is not a positive multiple of 3")
        if int(indices.max()) >= v:
            raise ValueError("indices: index out of range")
        lengths = np.linalg.norm(normals.astype(np.float64), axis=1)
        if np.any(np.abs(lengths - 1.0) > UNIT_TOLERANCE):
            raise ValueError("normals: not unit length")
        if np.any(weights < 0) or np.any(
            np.abs(weights.astype(np.float64).sum(axis=1) - 1.0) > WEIGHT_SUM_TOLERANCE
        ):
            raise ValueError("weights: must be non-negative and sum to 1")
        if rest_frames.shape[0] == 0:
            raise ValueError("rest_frames: at least one slot required")
        if int(slots.max()) >= rest_frames.shape[0]:
            raise ValueError("slots: slot index out of range of rest_frames")
        if REST_FRAMES_KEY in extras:
            raise ValueError(f"extras: {REST_FRAMES_KEY!r} is reserved")
        if not np.all(np.isin(skin[:, 0], (0.0, 1.0, 2.0))) or np.any(skin[:, 1] < 0):
            raise ValueError("skin: method codes must be 0, 1 or 2 and trust radii non-negative")

        for name, value in (
            ("positions", positions),
            ("normals", normals),
            ("indices", indices),
            ("slots", slots),
            ("weights", weights),
            ("candidate", candidate),
            ("radial", radial),
            ("rest_frames", rest_frames),
            ("extras", extras),
            ("skin", skin),
            ("cor_centers", cor_centers),
            ("colour_slots", colour_slots),
            ("colour_weights", colour_weights),
        ):
            object.__setattr__(self, name, value)

    @property
    def vertex_count(self) -> int:
        return int(self.positions.shape[0])

    @property
    def slot_count(self) -> int:
        return int(self.rest_frames.shape[0])

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, SurfaceAsset):
            return NotImplemented
        arrays = (
            "positions",
            "normals",
            "indices",
            "slots",
            "weights",
            "candidate",
            "radial",
            "rest_frames",
            "skin",
            "cor_centers",
            "colour_slots",
            "colour_weights",
        )
        return self.extras == other.extras and all(_same(getattr(self, a), getattr(other, a)) for a in arrays)

    __hash__ = None  # type: ignore[assignment]


def _same(a: npt.NDArray[Any] | None, b: npt.NDArray[Any] | None) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return a.dtype == b.dtype and np.array_equal(a, b)


# --- writing -----------------------------------------------------------------------------------------


def _pad4(n: int) -> int:
    return (n + 3) & ~3


def _dumps(value: object) -> bytes:
    return json.dumps(
        value, sort_keys=True, separators=(",", ":"), allow_nan=False, ensure_ascii=False
    ).encode("utf-8")


class _BinBuilder:
    """Collects buffer views (each starting 4-byte aligned) and their accessors."""

    def __init__(self) -> None:
        self.chunks: list[bytes] = []
        self.length = 0
        self.views: list[dict[str, object]] = []
        self.accessors: list[dict[str, object]] = []

    def add(
        self,
        data: npt.NDArray[Any],
        component: int,
        kind: str,
        *,
        target: int | None,
        minmax: bool = False,
    ) -> int:
        count = int(data.shape[0])
        little = np.ascontiguousarray(data, dtype=_COMPONENT_DTYPES[component])
        raw = little.tobytes()
        view: dict[str, object] = {"buffer": 0, "byteOffset": self.length, "byteLength": len(raw)}
        if target is not None:
            view["target"] = target
        self.views.append(view)
        self.chunks.append(raw + b"\0" * (_pad4(len(raw)) - len(raw)))
        self.length += _pad4(len(raw))
        accessor: dict[str, object] = {
            "bufferView": len(self.views) - 1,
            "componentType": component,
            "count": count,
            "type": kind,
        }
        if minmax:
            flat = little.reshape(count, -1)
            accessor["min"] = [float(x) for x in flat.min(axis=0)]
            accessor["max"] = [float(x) for x in flat.max(axis=0)]
        self.accessors.append(accessor)
        return len(self.accessors) - 1


def glb_bytes(asset: SurfaceAsset, *, name: str) -> bytes:
    """The .glb file of ``asset`` as bytes (a pure function of its arguments)."""
    b = _BinBuilder()
    attributes = {
        "POSITION": b.add(asset.positions, FLOAT, "VEC3", target=ARRAY_BUFFER, minmax=True),
        "NORMAL": b.add(asset.normals, FLOAT, "VEC3", target=ARRAY_BUFFER),
        "_SLOTS": b.add(asset.slots.astype(np.float32), FLOAT, "VEC4", target=ARRAY_BUFFER),
        "_WEIGHTS": b.add(asset.weights, FLOAT, "VEC4", target=ARRAY_BUFFER),
        "_CANDIDATE": b.add(asset.candidate.astype(np.float32), FLOAT, "SCALAR", target=ARRAY_BUFFER),
        "_RADIAL": b.add(asset.radial, FLOAT, "VEC2", target=ARRAY_BUFFER),
        "_SKIN": b.add(np.asarray(asset.skin), FLOAT, "VEC2", target=ARRAY_BUFFER),
        "_COR": b.add(np.asarray(asset.cor_centers), FLOAT, "VEC3", target=ARRAY_BUFFER),
    }
    if asset.colour_slots is not None and asset.colour_weights is not None:
        attributes["_COLOUR_SLOTS"] = b.add(
            asset.colour_slots.astype(np.float32), FLOAT, "VEC4", target=ARRAY_BUFFER
        )
        attributes["_COLOUR_WEIGHTS"] = b.add(asset.colour_weights, FLOAT, "VEC4", target=ARRAY_BUFFER)
    index_type = UNSIGNED_SHORT if asset.vertex_count <= MAX_UINT16_VERTICES else UNSIGNED_INT
    indices = b.add(asset.indices, index_type, "SCALAR", target=ELEMENT_ARRAY_BUFFER)
    rest_frames = b.add(asset.rest_frames.reshape(-1, 16), FLOAT, "MAT4", target=None)

    document: dict[str, object] = {
        "asset": {"version": "2.0", "generator": f"creaturegen {__version__}", "extras": asset.extras},
        "scene": 0,
        # The scene stays unnamed: three.js reserves names scene-first, so a named scene would turn
        # the mesh object's name into `<name>_1`.
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": name, "mesh": 0, "extras": {**asset.extras, REST_FRAMES_KEY: rest_frames}}],
        "meshes": [
            {
                "name": name,
                "primitives": [{"attributes": attributes, "indices": indices, "mode": TRIANGLES}],
            }
        ],
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": b.length}],
    }
    json_chunk = _dumps(document)
    json_chunk += b" " * (_pad4(len(json_chunk)) - len(json_chunk))
    bin_chunk = b"".join(b.chunks)
    total = 12 + 8 + len(json_chunk) + 8 + len(bin_chunk)
    return b"".join(
        (
            struct.pack("<III", GLB_MAGIC, GLB_VERSION, total),
            struct.pack("<II", len(json_chunk), CHUNK_JSON),
            json_chunk,
            struct.pack("<II", len(bin_chunk), CHUNK_BIN),
            bin_chunk,
        )
    )


def _write_atomic(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and ``os.replace``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def write_glb(path: Path, asset: SurfaceAsset, *, name: str) -> bytes:
    """Write ``asset`` to ``path`` as a .glb (atomically) and return the bytes written."""
    data = glb_bytes(asset, name=name)
    _write_atomic(Path(path), data)
    return data


def sidecar_bytes(data: dict[str, object]) -> bytes:
    """Deterministic JSON: sorted keys, indent 2, no NaN, trailing newline."""
    text = json.dumps(data, sort_keys=True, indent=2, allow_nan=False, ensure_ascii=False)
    return (text + "\n").encode("utf-8")


def write_sidecar(path: Path, data: dict[str, object]) -> None:
    """Write the JSON sidecar of a surface (atomically)."""
    _write_atomic(Path(path), sidecar_bytes(data))


# --- reading -----------------------------------------------------------------------------------------


def _parse_chunks(data: bytes) -> tuple[dict[str, Any], bytes]:
    if len(data) < 20:
        raise GlbFormatError("too short for a GLB header")
    magic, version, total = struct.unpack_from("<III", data, 0)
    if magic != GLB_MAGIC or version != GLB_VERSION:
        raise GlbFormatError("not a glTF 2.0 binary")
    if total != len(data):
        raise GlbFormatError(f"header length {total} != file length {len(data)}")
    json_length, json_type = struct.unpack_from("<II", data, 12)
    if json_type != CHUNK_JSON or 20 + json_length > total:
        raise GlbFormatError("first chunk is not a complete JSON chunk")
    try:
        document = json.loads(data[20 : 20 + json_length].decode("utf-8"))
    except ValueError as error:
        raise GlbFormatError(f"JSON chunk: {error}") from error
    if not isinstance(document, dict):
        raise GlbFormatError("JSON chunk is not an object")
    offset = 20 + json_length
    if offset + 8 > total:
        raise GlbFormatError("BIN chunk missing")
    bin_length, bin_type = struct.unpack_from("<II", data, offset)
    if bin_type != CHUNK_BIN or offset + 8 + bin_length > total:
        raise GlbFormatError("second chunk is not a complete BIN chunk")
    return document, data[offset + 8 : offset + 8 + bin_length]


def _read_accessor(document: dict[str, Any], binary: bytes, index: int, kind: str) -> npt.NDArray[Any]:
    accessor = document["accessors"][index]
    if accessor["type"] != kind:
        raise GlbFormatError(f"accessor {index}: type {accessor['type']}, expected {kind}")
    dtype = np.dtype(_COMPONENT_DTYPES[accessor["componentType"]])
    view = document["bufferViews"][accessor["bufferView"]]
    count, width = int(accessor["count"]), _TYPE_SIZES[kind]
    element = dtype.itemsize * width
    stride = int(view.get("byteStride", element))
    start = int(view.get("byteOffset", 0)) + int(accessor.get("byteOffset", 0))
    end = start + stride * (count - 1) + element
    if count < 1 or stride < element or end > int(view.get("byteOffset", 0)) + int(view["byteLength"]):
        raise GlbFormatError(f"accessor {index}: does not fit its buffer view")
    if end > len(binary):
        raise GlbFormatError(f"accessor {index}: does not fit the BIN chunk")
    raw = np.frombuffer(binary, dtype=np.uint8, count=end - start, offset=start)
    rows = np.lib.stride_tricks.as_strided(raw, shape=(count, element), strides=(stride, 1))
    values: npt.NDArray[Any] = np.ascontiguousarray(rows).view(dtype).reshape(count, width)
    return values[:, 0] if width == 1 else values


def parse_glb(data: bytes) -> SurfaceAsset:
    """The asset in ``data``, the bytes of a .glb written by ``write_glb``."""
    try:
        document, binary = _parse_chunks(data)
        node = document["nodes"][document["scenes"][document.get("scene", 0)]["nodes"][0]]
        primitive = document["meshes"][node["mesh"]]["primitives"][0]
        attributes = primitive["attributes"]
        node_extras = dict(node.get("extras", {}))
        rest_index = node_extras.pop(REST_FRAMES_KEY)
        indices = _read_accessor(document, binary, primitive["indices"], "SCALAR")
        return SurfaceAsset(
            positions=_read_accessor(document, binary, attributes["POSITION"], "VEC3"),
            normals=_read_accessor(document, binary, attributes["NORMAL"], "VEC3"),
            indices=indices.astype(np.uint32),
            slots=_read_accessor(document, binary, attributes["_SLOTS"], "VEC4").astype(np.uint16),
            weights=_read_accessor(document, binary, attributes["_WEIGHTS"], "VEC4"),
            candidate=_read_accessor(document, binary, attributes["_CANDIDATE"], "SCALAR").astype(np.uint16),
            radial=_read_accessor(document, binary, attributes["_RADIAL"], "VEC2"),
            rest_frames=_read_accessor(document, binary, rest_index, "MAT4").reshape(-1, 4, 4),
            extras=document["asset"].get("extras", node_extras),
            skin=_read_accessor(document, binary, attributes["_SKIN"], "VEC2"),
            cor_centers=_read_accessor(document, binary, attributes["_COR"], "VEC3"),
            colour_slots=(
                _read_accessor(document, binary, attributes["_COLOUR_SLOTS"], "VEC4").astype(np.uint16)
                if "_COLOUR_SLOTS" in attributes
                else None
            ),
            colour_weights=(
                _read_accessor(document, binary, attributes["_COLOUR_WEIGHTS"], "VEC4")
                if "_COLOUR_WEIGHTS" in attributes
                else None
            ),
        )
    except GlbFormatError:
        raise
    except (KeyError, IndexError, TypeError, ValueError, AttributeError, struct.error) as error:
        raise GlbFormatError(f"not a creaturegen surface: {type(error).__name__}: {error}") from error


def read_glb(path: Path) -> SurfaceAsset:
    """Read a .glb written by ``write_glb``; raises ``GlbFormatError`` on anything else."""
    return parse_glb(Path(path).read_bytes())


# --- cache -------------------------------------------------------------------------------------------

_HEX = re.compile(r"[0-9a-f]{16,}")
_TIER = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}")
CACHE_KEY: Final = "cacheKey"
PREFIX: Final = 16


def _check_hex(value: str, what: str) -> str:
    if not isinstance(value, str) or not _HEX.fullmatch(value):
        raise ValueError(f"{what}: lowercase hex of at least {PREFIX} digits expected, got {value!r}")
    return value


def _check_tier(tier: str) -> str:
    if not isinstance(tier, str) or not _TIER.fullmatch(tier):
        raise ValueError(f"tier: {tier!r} is not a safe folder-name fragment")
    return tier


def _read_json(path: Path) -> dict[str, Any] | None:
    try:
        value = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return value if isinstance(value, dict) else None


@contextlib.contextmanager
def exclusive(lock: Path) -> Iterator[None]:
    """An exclusive advisory lock on the file ``lock`` (created if missing): one process at a time past
    this point. Without ``fcntl`` (not POSIX) it lets everyone through."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover (not POSIX)
        yield
        return
    with lock.open("a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


@dataclass(frozen=True)
class CachedSurface:
    asset: SurfaceAsset
    sidecar: dict[str, object]
    folder: Path


class SurfaceCache:
    """Surfaces on disk under ``root``; see the module docstring for the layout and its guarantees.

    ``<root>/<compiler[:16]>/<geometry[:16]>/<topology[:16]>-<tier>/surface.glb`` and ``surface.json``;
    ``<root>/<compiler[:16]>/<geometry[:16]>/index-<tier>-<settings[:16]>.json`` maps a lookup key to
    the full topologySignature.
    """

    GLB = "surface.glb"
    SIDECAR = "surface.json"

    def __init__(self, root: Path | None = None) -> None:
        self.root = Path(root) if root is not None else default_cache_root()

    def geometry_folder(self, compiler: str, geometry: str) -> Path:
        c = _check_hex(compiler, "compilerSignature")
        g = _check_hex(geometry, "geometryDigest")
        return self.root / c[:PREFIX] / g[:PREFIX]

    def entry_folder(self, compiler: str, topology: str, geometry: str, tier: str) -> Path:
        t = _check_hex(topology, "topologySignature")
        return self.geometry_folder(compiler, geometry) / f"{t[:PREFIX]}-{_check_tier(tier)}"

    def index_path(self, compiler: str, geometry: str, tier: str, settings_digest: str) -> Path:
        s = _check_hex(settings_digest, "settingsDigest")
        return self.geometry_folder(compiler, geometry) / f"index-{_check_tier(tier)}-{s[:PREFIX]}.json"

    @contextlib.contextmanager
    def building(self, compiler: str, geometry: str, tier: str, settings_digest: str) -> Iterator[None]:
        """Hold the build of one lookup key: a second build of the same surface sharing this cache (another
        process: a parallel build, a test worker) waits here, then finds the entry instead of extracting
        it again. An advisory lock file beside the index; where the platform has no ``fcntl`` the builds
        simply both run (entries are written atomically, so the result is the same)."""
        path = self.index_path(compiler, geometry, tier, settings_digest).with_suffix(".lock")
        path.parent.mkdir(parents=True, exist_ok=True)
        with exclusive(path):
            yield

    def lookup(self, compiler: str, geometry: str, tier: str, settings_digest: str) -> CachedSurface | None:
        """The stored surface for this key, or ``None`` (missing, mismatched or corrupt: all misses)."""
        index = _read_json(self.index_path(compiler, geometry, tier, settings_digest))
        wanted = {
            "compilerSignature": compiler,
            "geometryDigest": geometry,
            "tier": tier,
            "settingsDigest": settings_digest,
        }
        if index is None or any(index.get(k) != v for k, v in wanted.items()):
            return None
        topology = index.get("topologySignature")
        if not isinstance(topology, str) or not _HEX.fullmatch(topology):
            return None
        return self.read_entry(compiler, topology, geometry, tier)

    def read_entry(self, compiler: str, topology: str, geometry: str, tier: str) -> CachedSurface | None:
        """The entry stored under the full key, verified against its sidecar, or ``None``."""
        folder = self.entry_folder(compiler, topology, geometry, tier)
        sidecar = _read_json(folder / self.SIDECAR)
        if sidecar is None:
            return None
        key = sidecar.pop(CACHE_KEY, None)
        wanted = {"compilerSignature": compiler, "topologySignature": topology, "geometryDigest": geometry}
        if not isinstance(key, dict) or key.get("tier") != tier:
            return None
        if any(key.get(k) != v for k, v in wanted.items()):
            return None
        try:
            data = (folder / self.GLB).read_bytes()
            if hashlib.sha256(data).hexdigest() != key.get("glbSha256"):
                return None
            asset = parse_glb(data)
        except (OSError, GlbFormatError):
            return None
        return CachedSurface(asset=asset, sidecar=sidecar, folder=folder)

    def store(
        self,
        compiler: str,
        topology: str,
        geometry: str,
        tier: str,
        settings_digest: str,
        asset: SurfaceAsset,
        sidecar: dict[str, object],
    ) -> Path:
        """Write the entry (surface.glb, then surface.json), then the index; returns the entry folder."""
        if CACHE_KEY in sidecar:
            raise ValueError(f"sidecar: {CACHE_KEY!r} is reserved for the cache")
        folder = self.entry_folder(compiler, topology, geometry, tier)
        index = self.index_path(compiler, geometry, tier, settings_digest)
        data = write_glb(folder / self.GLB, asset, name=f"surface-{tier}")
        key = {
            "compilerSignature": compiler,
            "topologySignature": topology,
            "geometryDigest": geometry,
            "tier": tier,
            "glbSha256": hashlib.sha256(data).hexdigest(),
        }
        write_sidecar(folder / self.SIDECAR, {**sidecar, CACHE_KEY: key})
        write_sidecar(
            index,
            {
                "compilerSignature": compiler,
                "geometryDigest": geometry,
                "tier": tier,
                "settingsDigest": settings_digest,
                "topologySignature": topology,
            },
        )
        return folder
