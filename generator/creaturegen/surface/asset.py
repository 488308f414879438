"""The reference-surface asset: one surface's per-vertex data (the ``SurfaceAsset`` model) and the
invariants every copy of it holds, checked on construction.

The model knows nothing of files: surface/glb.py writes it as a hand-written glTF 2.0 binary (.glb) with
a JSON sidecar and reads it back, and surface/cache.py keeps those files on disk by signature. What each
array means on the GPU side (the glTF attribute it becomes) is in surface/glb.py's docstring.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Final, cast

import numpy as np
import numpy.typing as npt

#: Node-extras key naming the rest-frame accessor; reserved, so not allowed in ``SurfaceAsset.extras``.
REST_FRAMES_KEY: Final = "restFramesAccessor"

#: Tolerances of the invariants checked on construction (float32 data built in float64).
UNIT_TOLERANCE: Final = 1e-3
WEIGHT_SUM_TOLERANCE: Final = 1e-3

F32 = npt.NDArray[np.float32]
U16 = npt.NDArray[np.uint16]
U32 = npt.NDArray[np.uint32]


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
