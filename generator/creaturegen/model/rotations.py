"""Poses of the slot table: per-slot rigid transforms, the rotations that build them, and quaternions.

A pose carries each slot from rest to its posed place, ``x' = R·x + t``. Quaternions are (x, y, z, w)
everywhere in creaturegen: here, in the motion core (motion/quat.py), in three.js and in the shipped JS
and WGSL. Unit, with w ≥ 0 when converted from a matrix.

Sums over a quaternion's four components (:func:`quaternion_dot`, :func:`quaternion_norm`) add w first,
then x, y, z: the order the surface reference has always summed in, so its skinned positions and the
gate figures recorded from them keep their last bit when the storage order changed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from . import layout as col

F64 = npt.NDArray[np.float64]

#: Multiplying by this conjugates a unit quaternion (its inverse).
CONJUGATE: Final = np.array([-1.0, -1.0, -1.0, 1.0])


@dataclass(frozen=True)
class Pose:
    """Per-slot rigid transforms rest → posed: ``x' = rotations[s] @ x + translations[s]``."""

    rotations: F64  # (S, 3, 3)
    translations: F64  # (S, 3)

    @classmethod
    def identity(cls, slot_count: int) -> Pose:
        return cls(np.tile(np.eye(3), (slot_count, 1, 1)), np.zeros((slot_count, 3)))

    @classmethod
    def rigid(cls, slot_count: int, rotation: npt.ArrayLike, translation: npt.ArrayLike) -> Pose:
        """Every slot under one transform: the whole body moved, which every method must reproduce."""
        r = np.asarray(rotation, dtype=np.float64).reshape(3, 3)
        t = np.asarray(translation, dtype=np.float64).reshape(3)
        return cls(np.tile(r, (slot_count, 1, 1)), np.tile(t, (slot_count, 1)))

    @property
    def slot_count(self) -> int:
        return int(self.rotations.shape[0])


def rotation_matrix(axis: npt.ArrayLike, angle: float) -> F64:
    """Rodrigues; the axis need not be unit."""
    u = np.asarray(axis, dtype=np.float64).reshape(3)
    u = u / np.linalg.norm(u)
    k = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    result: F64 = np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)
    return result


def posed_slots(rest_slots: F64, pose: Pose) -> F64:
    """The slot table with both ends moved by their slot's transform; radii, k and colour stay."""
    out = rest_slots.copy()
    for ends in (col.A, col.B):
        out[:, ends] = np.einsum("sij,sj->si", pose.rotations, rest_slots[:, ends]) + pose.translations
    return out


def matrix_to_quaternion(rotations: F64) -> F64:
    """(..., 3, 3) → (..., 4) unit quaternions with w ≥ 0 (Shepperd: divide by the largest component)."""
    m = np.asarray(rotations, dtype=np.float64).reshape(-1, 3, 3)
    m00, m11, m22 = m[:, 0, 0], m[:, 1, 1], m[:, 2, 2]
    trace = m00 + m11 + m22
    case = np.argmax(np.stack([trace, m00, m11, m22], axis=1), axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        s0 = np.sqrt(np.maximum(1.0 + trace, 0.0)) * 2.0
        s1 = np.sqrt(np.maximum(1.0 + m00 - m11 - m22, 0.0)) * 2.0
        s2 = np.sqrt(np.maximum(1.0 - m00 + m11 - m22, 0.0)) * 2.0
        s3 = np.sqrt(np.maximum(1.0 - m00 - m11 + m22, 0.0)) * 2.0
        candidates = np.stack(
            [
                np.stack(
                    [
                        0.25 * s0,
                        (m[:, 2, 1] - m[:, 1, 2]) / s0,
                        (m[:, 0, 2] - m[:, 2, 0]) / s0,
                        (m[:, 1, 0] - m[:, 0, 1]) / s0,
                    ],
                    axis=1,
                ),
                np.stack(
                    [
                        (m[:, 2, 1] - m[:, 1, 2]) / s1,
                        0.25 * s1,
                        (m[:, 0, 1] + m[:, 1, 0]) / s1,
                        (m[:, 0, 2] + m[:, 2, 0]) / s1,
                    ],
                    axis=1,
                ),
                np.stack(
                    [
                        (m[:, 0, 2] - m[:, 2, 0]) / s2,
                        (m[:, 0, 1] + m[:, 1, 0]) / s2,
                        0.25 * s2,
                        (m[:, 1, 2] + m[:, 2, 1]) / s2,
                    ],
                    axis=1,
                ),
                np.stack(
                    [
                        (m[:, 1, 0] - m[:, 0, 1]) / s3,
                        (m[:, 0, 2] + m[:, 2, 0]) / s3,
                        (m[:, 1, 2] + m[:, 2, 1]) / s3,
                        0.25 * s3,
                    ],
                    axis=1,
                ),
            ],
            axis=1,
        )
    # Shepperd's cases are written w-first (as the literature does); stored x, y, z, w.
    q = candidates[np.arange(m.shape[0]), case][:, [1, 2, 3, 0]]
    q = q / quaternion_norm(q)[:, None]
    q = np.where(q[:, 3:] < 0, -q, q)
    result: F64 = q.reshape(*np.shape(rotations)[:-2], 4)
    return result


def quaternion_to_matrix(q: F64) -> F64:
    """(..., 4) unit quaternions → (..., 3, 3); (0, 0, 0, 1) maps to the identity exactly."""
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    result: F64 = np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )
    return result


def quaternion_multiply(a: F64, b: F64) -> F64:
    """Hamilton product ``a·b`` (apply b, then a)."""
    ax, ay, az, aw = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bx, by, bz, bw = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    result: F64 = np.stack(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ],
        axis=-1,
    )
    return result


def quaternion_dot(a: F64, b: F64) -> F64:
    """Four-component dot product over the last axis, summed w first (see the module docstring)."""
    ww = a[..., 3] * b[..., 3]
    result: F64 = ((ww + a[..., 0] * b[..., 0]) + a[..., 1] * b[..., 1]) + a[..., 2] * b[..., 2]
    return result


def quaternion_norm(q: F64) -> F64:
    """Length over the last axis, summed w first (see the module docstring)."""
    result: F64 = np.sqrt(quaternion_dot(q, q))
    return result
