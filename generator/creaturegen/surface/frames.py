"""Radial frames of the slots: chosen once at rest, transported along the skeleton, never re-picked.

A vertex's radial coordinates (θ around, t along its dominant slot) drive anything that must stay
attached to the skin as it moves: texture-space effects, twist distribution, the ``_RADIAL`` asset
channel. θ needs a normal to measure from. Picking that normal from a helper axis of the *current*
direction ("world up unless the limb is nearly vertical, then X") has a branch, and when a posed limb
swings through the branch the normal jumps and every θ on the limb rotates discontinuously (the
seed's failure condition). So the normal is chosen by a fixed rule exactly once, at the skeleton root
at rest, and everything else inherits it:

- Rest: frames are transported from parent to child by the rotation-minimising double reflection of
  Wang et al. (2008). A slot is straight, so its rotation-minimising frame is constant along it and
  only turns at a joint; the double reflection across a joint uses the chord of a fillet at the
  pivot (points equidistant before and after it, chord ∥ t₀ + t₁), which makes it exactly the minimal
  rotation about t₀ × t₁ and independent of where on the parent the child attaches. Chains (legs,
  rope tails) therefore get frames with no twist beyond what their bends force, and θ is continuous
  from one segment into the next.
- Posed: a slot's frame is its rest frame rotated by the minimal rotation taking the rest tangent to
  the posed tangent (plus an explicit twist when the pose carries one), never a frame re-derived from
  the posed direction. The minimal rotation is continuous in the posed direction everywhere except
  at the exact reversal of the rest tangent, where any rule is ambiguous; there it rotates by π about
  the rest normal, a frame-fixed axis, not a world helper. Close to that reversal θ stays continuous
  but turns fast (in the test's sweep: 0.19° per 0.5° of swing at 150° from rest, 1.7° at 170°), so a motion
  that swings a limb that far should carry the previous posed frame instead of the rest frame
  (``posed_frame(previous, a, b)``: the same rule applied step by step, no singularity).
- Spheres have no axis. A sphere takes its parent's tangent (a root sphere +Z), so at rest it inherits
  the parent's frame, and when posed it turns with its parent.

Matrix convention: ``frame[:3, :3]`` has columns (t, n, b) with b = t × n (det +1), and
``frame[:3, 3]`` is the origin (the slot's ``a`` end), so ``frame @ [x_t, x_n, x_b, 1]`` maps local to
world. The asset stores matrices column-major like glTF: pass ``frames.transpose(0, 2, 1)`` there.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..model import layout as col
from ..model.skeleton import Skeleton
from ..rig import CompiledRig
from .mesh import unit_rows

F64 = npt.NDArray[np.float64]

#: Below this length, as a fraction of max(radius, 1 mm), a slot counts as a sphere.
DEGENERATE = 1e-9
#: Reflection chords shorter than this (squared, unit tangents) are skipped.
CHORD_EPS = 1e-24
#: The rest tangent of a root sphere.
ROOT_SPHERE_TANGENT = np.array([0.0, 0.0, 1.0])


def root_normal(t: F64) -> F64:
    """The one fixed rule, applied once per root at rest: the world axis least aligned with ``t``
    (the first on ties), Gram-Schmidt against ``t``."""
    axis = np.zeros(3)
    axis[int(np.argmin(np.abs(t)))] = 1.0
    return unit_rows(axis - (axis @ t) * t)


def double_reflection(t0: F64, r0: F64, t1: F64, chord: F64) -> F64:
    """Wang et al.'s rotation-minimising step: the normal at the next sample, given the tangent and
    normal here, the next tangent, and the chord between the samples. Reflect across the plane normal
    to the chord, then across the plane normal to ``t1 − t_L``; a degenerate reflection is skipped (so
    a reversal ``t1 = −t0`` with a zero chord turns by π about ``r0``)."""
    c1 = float(chord @ chord)
    r_l, t_l = r0, t0
    if c1 > CHORD_EPS:
        r_l = r0 - (2.0 / c1) * float(chord @ r0) * chord
        t_l = t0 - (2.0 / c1) * float(chord @ t0) * chord
    v2 = t1 - t_l
    c2 = float(v2 @ v2)
    r1 = r_l - (2.0 / c2) * float(v2 @ r_l) * v2 if c2 > CHORD_EPS else r_l
    return unit_rows(r1 - (r1 @ t1) * t1)


def _matrix(t: F64, n: F64, origin: F64) -> F64:
    frame = np.eye(4)
    frame[:3, 0], frame[:3, 1], frame[:3, 2], frame[:3, 3] = t, n, np.cross(t, n), origin
    return frame


def _topological(parent: tuple[int, ...] | list[int]) -> list[int]:
    """Slots with every parent before its children (slot order need not be)."""
    children: dict[int, list[int]] = {}
    for child, p in enumerate(parent):
        children.setdefault(p, []).append(child)
    order: list[int] = []
    stack = list(reversed(children.get(-1, [])))
    while stack:
        s = stack.pop()
        order.append(s)
        stack.extend(reversed(children.get(s, [])))
    if len(order) != len(parent):
        raise ValueError("skeleton parents contain a cycle")
    return order


def slot_tangents(slots: F64, parent: tuple[int, ...] | list[int]) -> tuple[F64, npt.NDArray[np.bool_]]:
    """Unit tangent per slot and which slots are spheres (zero length): those take their parent's
    tangent, a root sphere ``ROOT_SPHERE_TANGENT``."""
    axis = slots[:, col.B] - slots[:, col.A]
    length = np.linalg.norm(axis, axis=1)
    scale = np.maximum(np.maximum(slots[:, col.RA], slots[:, col.RB]), 1e-3)
    sphere = length <= DEGENERATE * scale
    tangent = np.zeros_like(axis)
    tangent[~sphere] = axis[~sphere] / length[~sphere, None]
    for s in _topological(parent):
        if sphere[s]:
            tangent[s] = tangent[parent[s]] if parent[s] >= 0 else ROOT_SPHERE_TANGENT
    return tangent, sphere


def rest_frames_from(slots: F64, parent: tuple[int, ...] | list[int]) -> F64:
    """(S, 4, 4) rest frames of a slot table with its skeleton parents; see the module docstring."""
    tangent, _ = slot_tangents(slots, parent)
    frames = np.zeros((slots.shape[0], 4, 4))
    for s in _topological(parent):
        p = parent[s]
        t = tangent[s]
        if p < 0:
            n = root_normal(t)
        else:
            t0, n0 = frames[p, :3, 0], frames[p, :3, 1]
            n = double_reflection(t0, n0, t, chord=t0 + t)
        frames[s] = _matrix(t, n, slots[s, col.A])
    return frames


def rest_frames(rig: CompiledRig, skeleton: Skeleton) -> F64:
    """(S, 4, 4) rest frames of the compiled rig, transported along its skeleton."""
    return rest_frames_from(rig.slots, skeleton.parent)


def minimal_rotation(u: F64, v: F64, reverse_axis: F64) -> F64:
    """(..., 3, 3) the rotation by the smallest angle taking unit ``u`` to unit ``v`` (about u × v).

    At an exact reversal (u = −v) the axis is undetermined; ``reverse_axis`` (a unit vector ⊥ u,
    taken from the frame being rotated) is used, so the result never consults a world axis.
    """
    u, v = np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)
    k = np.cross(u, v)
    c = np.einsum("...i,...i->...", u, v)
    kx = np.zeros((*k.shape[:-1], 3, 3))
    kx[..., 0, 1], kx[..., 0, 2], kx[..., 1, 2] = -k[..., 2], k[..., 1], -k[..., 0]
    kx[..., 1, 0], kx[..., 2, 0], kx[..., 2, 1] = k[..., 2], -k[..., 1], k[..., 0]
    reversed_ = c <= -1.0 + 1e-12
    denom = np.where(reversed_, 1.0, 1.0 + c)
    rotation: F64 = np.eye(3) + kx + (kx @ kx) / denom[..., None, None]
    if np.any(reversed_):
        w = np.broadcast_to(reverse_axis, u.shape)
        flip = 2.0 * np.einsum("...i,...j->...ij", w, w) - np.eye(3)
        rotation = np.where(reversed_[..., None, None], flip, rotation)
    return rotation


def twist_rotation(tangent: F64, angle: float | F64) -> F64:
    """(..., 3, 3) rotation by ``angle`` (radians, right-handed) about the unit ``tangent``."""
    t = np.asarray(tangent, dtype=np.float64)
    a = np.asarray(angle, dtype=np.float64)[..., None, None]
    tx = np.zeros((*t.shape[:-1], 3, 3))
    tx[..., 0, 1], tx[..., 0, 2], tx[..., 1, 2] = -t[..., 2], t[..., 1], -t[..., 0]
    tx[..., 1, 0], tx[..., 2, 0], tx[..., 2, 1] = t[..., 2], -t[..., 1], t[..., 0]
    result: F64 = np.eye(3) + np.sin(a) * tx + (1.0 - np.cos(a)) * (tx @ tx)
    return result


def twisted(frame: F64, angle: float) -> F64:
    """The frame turned by ``angle`` about its own tangent: θ of a point fixed in space drops by it."""
    out = np.array(frame, dtype=np.float64, copy=True)
    out[:3, :3] = twist_rotation(frame[:3, 0], angle) @ frame[:3, :3]
    return out


def posed_frame(rest_frame: F64, a_posed: npt.ArrayLike, b_posed: npt.ArrayLike, twist: float = 0.0) -> F64:
    """The rest frame carried onto a posed segment: minimal rotation of the rest tangent onto
    ``unit(b − a)``, then ``twist`` about it, origin at ``a``. A zero-length posed segment keeps the
    rest orientation. Passing the previous posed frame instead of the rest frame transports
    incrementally along a motion (the same rule, applied step by step)."""
    a, b = np.asarray(a_posed, dtype=np.float64), np.asarray(b_posed, dtype=np.float64)
    rest = rest_frame[:3, :3]
    axis = b - a
    length = float(np.linalg.norm(axis))
    rotation = np.eye(3)
    if length > 0.0:
        rotation = minimal_rotation(rest[:, 0], axis / length, rest[:, 1])
    out = np.eye(4)
    out[:3, :3] = rotation @ rest
    out[:3, 3] = a
    return twisted(out, twist) if twist else out


def posed_frames(
    rest: F64,
    posed_slots: F64,
    parent: tuple[int, ...] | list[int],
    twist: F64 | None = None,
) -> F64:
    """(S, 4, 4) every slot's posed frame from a posed slot table (same layout as the rig's).

    Segments rotate by their own minimal rotation (then ``twist[s]`` about the posed tangent, when
    given); spheres turn with their parent's posed rotation, because a sphere's own pose carries no
    orientation.
    """
    s_count = rest.shape[0]
    axis = posed_slots[:, col.B] - posed_slots[:, col.A]
    length = np.linalg.norm(axis, axis=1)
    _, sphere = slot_tangents(posed_slots, parent)  # a sphere stays a sphere when posed
    moving = ~sphere & (length > 0.0)
    delta = np.tile(np.eye(3), (s_count, 1, 1))
    if moving.any():
        delta[moving] = minimal_rotation(
            rest[moving, :3, 0], axis[moving] / length[moving, None], rest[moving, :3, 1]
        )
    if twist is not None:
        delta = twist_rotation(np.einsum("sij,sj->si", delta, rest[:, :3, 0]), twist) @ delta
    for s in _topological(parent):
        if sphere[s] and parent[s] >= 0:
            delta[s] = delta[parent[s]]
    out = np.zeros_like(rest)
    out[:, :3, :3] = delta @ rest[:, :3, :3]
    out[:, :3, 3] = posed_slots[:, col.A]
    out[:, 3, 3] = 1.0
    return out


def radial_coordinates(points: npt.ArrayLike, frame: F64, length: float | F64) -> tuple[F64, F64]:
    """(θ, t) of points in a slot frame: θ = atan2(q·b, q·n) ∈ (−π, π], t = (q·t) / length, with
    q = p − origin. ``frame`` may be one (4, 4) or one per point (P, 4, 4); ``length`` likewise.
    A non-positive length (a sphere) gives t = 0 rather than a division by zero; ``slot_radial``
    measures spheres in radii instead."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    f = np.asarray(frame, dtype=np.float64)
    q = p - f[..., :3, 3]
    along = np.einsum("...i,...i->...", q, f[..., :3, 0])
    x = np.einsum("...i,...i->...", q, f[..., :3, 1])
    y = np.einsum("...i,...i->...", q, f[..., :3, 2])
    theta: F64 = np.arctan2(y, x)
    scale = np.broadcast_to(np.asarray(length, dtype=np.float64), along.shape)
    t: F64 = np.divide(along, scale, out=np.zeros_like(along), where=scale > 0.0)
    return theta, t


def slot_radial(points: npt.ArrayLike, frames: F64, slots: F64, dominant: npt.ArrayLike) -> F64:
    """(P, 2) (θ, t) of each point in its dominant slot's frame: t is the fraction along a segment
    (0 at ``a``, 1 at ``b``) and, for a sphere, the offset along its inherited tangent in radii."""
    d = np.asarray(dominant, dtype=np.int64)
    length = np.linalg.norm(slots[:, col.B] - slots[:, col.A], axis=1)
    radius = np.maximum(slots[:, col.RA], slots[:, col.RB])
    scale = np.where(length > DEGENERATE * np.maximum(radius, 1e-3), length, radius)
    theta, t = radial_coordinates(points, frames[d], scale[d])
    result: F64 = np.stack([theta, t], axis=1)
    return result
