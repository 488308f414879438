"""The files of a reference-surface asset: a hand-written glTF 2.0 binary (.glb) and its JSON sidecar.

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
  colour the vertices that evaluate no field (``_CANDIDATE`` = SKIN_PROGRAM, surface/correction_region.py).

Indices are UNSIGNED_SHORT when every index fits below 65535 (the value glTF reserves for primitive
restart), UNSIGNED_INT otherwise. Per-slot rest frames are one more accessor (FLOAT MAT4, count S)
that no primitive uses; the node's ``extras.restFramesAccessor`` names it. A package's .glb carries one
more: the candidate program tapes (FLOAT VEC4, surface/glb.py ``PROGRAM_KEY``: headers then instructions,
creature/plan.py ``program_data``), the GPU buffer the runtime's field reads, named by the node's
``extras.programAccessor``; its digest (``programDigest``, the sha256 of its little-endian float32
bytes) joins the signatures in ``asset.extras``. The caller's ``extras``
(signatures and such) go to both ``asset.extras`` and the node's ``extras``: three.js exposes the
first as ``gltf.asset.extras`` and the second as the mesh's ``userData``.

Why the indices are FLOAT: three.js r185's WebGPU backend widens non-normalised UNSIGNED_SHORT vertex
data to uint32 with a fixed 4-byte stride (WebGPUAttributeUtils, "patch for UINT16"), which fits
neither a VEC4 nor a 2-byte scalar padded to glTF's 4-byte element alignment. Float attributes load
and draw as they are; the shader rounds them to integers.

Determinism: arrays are written little-endian in a fixed order, every buffer view starts on a 4-byte
boundary, the JSON has sorted keys, no whitespace and no NaN, the JSON chunk is padded with spaces and
the BIN chunk with zeros.
"""

from __future__ import annotations

import hashlib
import json
import os
import struct
import tempfile
from pathlib import Path
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from .. import __version__
from .asset import REST_FRAMES_KEY, SurfaceAsset

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

#: Largest vertex count whose indices fit UNSIGNED_SHORT (65535 is the primitive-restart value).
MAX_UINT16_VERTICES: Final = 65535

_COMPONENT_DTYPES: Final[dict[int, str]] = {UNSIGNED_SHORT: "<u2", UNSIGNED_INT: "<u4", FLOAT: "<f4"}
_TYPE_SIZES: Final[dict[str, int]] = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


#: The node extra naming the program tapes' accessor, and the asset extra holding their digest.
PROGRAM_KEY: Final = "programAccessor"
PROGRAM_DIGEST_KEY: Final = "programDigest"


def program_bytes(program: npt.ArrayLike) -> bytes:
    """The program tapes as the .glb stores them: float32, little-endian, four numbers per row."""
    values = np.ascontiguousarray(program, dtype="<f4")
    if values.ndim != 1 or values.size == 0 or values.size % 4:
        raise ValueError(f"program tapes: expected a flat, non-empty array of vec4 rows, got {values.shape}")
    return values.tobytes()


def program_digest(program: npt.ArrayLike) -> str:
    """sha256 of :func:`program_bytes`: the signature core/surface.js compares before drawing."""
    return hashlib.sha256(program_bytes(program)).hexdigest()


class GlbFormatError(ValueError):
    """A .glb that this module did not write, or that is damaged."""


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


def glb_bytes(asset: SurfaceAsset, *, name: str, program: npt.ArrayLike | None = None) -> bytes:
    """The .glb file of ``asset`` as bytes (a pure function of its arguments); with ``program`` (a
    package's program tapes, flat) the tapes ride in the same file, so the runtime fetches one asset and
    a copy step cannot pair a mesh with another build's programs."""
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
    extras: dict[str, object] = dict(asset.extras)
    node_extras: dict[str, object] = {**asset.extras, REST_FRAMES_KEY: rest_frames}
    if program is not None:
        rows = np.frombuffer(program_bytes(program), dtype="<f4").reshape(-1, 4)
        extras[PROGRAM_DIGEST_KEY] = program_digest(program)
        node_extras = {**extras, REST_FRAMES_KEY: rest_frames}
        node_extras[PROGRAM_KEY] = b.add(rows, FLOAT, "VEC4", target=None)

    document: dict[str, object] = {
        "asset": {"version": "2.0", "generator": f"creaturegen {__version__}", "extras": extras},
        "scene": 0,
        # The scene stays unnamed: three.js reserves names scene-first, so a named scene would turn
        # the mesh object's name into `<name>_1`.
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": name, "mesh": 0, "extras": node_extras}],
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
        node_extras.pop(PROGRAM_KEY, None)
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


def parse_program(data: bytes) -> npt.NDArray[np.float32] | None:
    """The program tapes a package's .glb carries (flat, as creature/plan.py ``program_data`` wrote
    them), or None for a .glb without them (the surface cache's)."""
    try:
        document, binary = _parse_chunks(data)
        node = document["nodes"][document["scenes"][document.get("scene", 0)]["nodes"][0]]
        index = node.get("extras", {}).get(PROGRAM_KEY)
        if index is None:
            return None
        rows: npt.NDArray[np.float32] = _read_accessor(document, binary, index, "VEC4").reshape(-1)
        return rows
    except GlbFormatError:
        raise
    except (KeyError, IndexError, TypeError, ValueError, AttributeError, struct.error) as error:
        raise GlbFormatError(f"not a creaturegen package surface: {type(error).__name__}: {error}") from error


def read_glb(path: Path) -> SurfaceAsset:
    """Read a .glb written by ``write_glb``; raises ``GlbFormatError`` on anything else."""
    return parse_glb(Path(path).read_bytes())
