"""Ropes (tails, tentacles): fixed-step verlet in world space, the anchor following the posed body.

Stage 4 of a tick (simulate.py), written last: each substep moves the nodes by their velocity and gravity,
then relaxation passes restore the segment lengths, hold the bend limit (a node's neighbours at least
bendMin apart) and, for creatures standing on the support, keep the nodes above it by their radius; a
follow-the-leader pass from the anchor then sets every segment to its rest length inside the bend limit's
cone. The rope's slots are posed by parallel transport down the chain.
"""

from __future__ import annotations

import math

from . import quat as vq
from .data import RopeData
from .providers import Frame, to_local, to_world
from .quat import Point, Vec
from .root import to_local_root, to_world_root
from .state import MotionState


def body_point(quats: list[list[float]], trans: list[Vec], slot: int, x: Point) -> Vec:
    """Rest point ``x`` moved rigidly with ``slot`` (creature-local)."""
    q, t = quats[slot], trans[slot]
    r = vq.rotate(q, x)
    return [r[0] + t[0], r[1] + t[1], r[2] + t[2]]


def anchor_point(quats: list[list[float]], trans: list[Vec], rope: RopeData, j: int) -> Vec:
    """Rest point ``j`` of the rope moved rigidly with its parent slot (creature-local)."""
    return body_point(quats, trans, rope.parent, rope.rest[j])


def bend(cur: list[Vec], before: Vec, bend_min: float) -> None:
    """The bend limit: node j's neighbours at least ``bend_min`` apart (the anchor and the point before
    it on the body are fixed, so the first two constraints move only the far node)."""
    for j in range(len(cur) - 1):
        a = before if j == 0 else cur[j - 1]
        b = cur[j + 1]
        dx, dy, dz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        dist = math.sqrt(dx * dx + dy * dy + dz * dz)
        if dist >= bend_min or dist == 0.0:
            continue
        f = (dist - bend_min) / dist
        if j <= 1:
            cur[j + 1] = [b[0] - dx * f, b[1] - dy * f, b[2] - dz * f]
        else:
            hf = 0.5 * f
            cur[j - 1] = [a[0] + dx * hf, a[1] + dy * hf, a[2] + dz * hf]
            cur[j + 1] = [b[0] - dx * hf, b[1] - dy * hf, b[2] - dz * hf]


def follow(cur: list[Vec], before: Vec, rope: RopeData, frame: Frame, ground: bool) -> None:
    """Follow the leader from the anchor: each segment its rest length and within the bend limit of the
    one before (the first of the body's direction into the anchor), and above the support where
    ``ground``. Relaxation passes alone leave a whipped tail stretched and bent past its limit; the skin
    is certified for the poses this bounds (motion/envelope.py)."""
    seg, c_max, s_max, radius = rope.segment, rope.bend_cos, rope.bend_sin, rope.radius
    a = cur[0]
    px, py, pz = a[0] - before[0], a[1] - before[1], a[2] - before[2]
    n = math.sqrt(px * px + py * py + pz * pz)
    px, py, pz = px / n, py / n, pz / n
    for j in range(1, len(cur)):
        a, b = cur[j - 1], cur[j]
        ux, uy, uz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        dist = math.sqrt(ux * ux + uy * uy + uz * uz)
        if dist == 0.0:
            ux, uy, uz = px, py, pz
        else:
            ux, uy, uz = ux / dist, uy / dist, uz / dist
        c = ux * px + uy * py + uz * pz
        if c < c_max:
            wx, wy, wz = ux - c * px, uy - c * py, uz - c * pz
            wn = math.sqrt(wx * wx + wy * wy + wz * wz)
            if wn == 0.0:
                ux, uy, uz = px, py, pz
            else:
                ux = c_max * px + s_max * (wx / wn)
                uy = c_max * py + s_max * (wy / wn)
                uz = c_max * pz + s_max * (wz / wn)
        cur[j] = [a[0] + seg * ux, a[1] + seg * uy, a[2] + seg * uz]
        if ground and height(frame, cur[j]) < radius[j]:
            # Lift the node onto the support at radius height, swinging the segment about its
            # first node so its length holds (the bend may open past the limit there).
            x = to_local(frame, cur[j])
            o = to_local(frame, a)
            dy = min(seg, max(-seg, radius[j] - o[1]))
            dx, dz = x[0] - o[0], x[2] - o[2]
            flat = math.sqrt(dx * dx + dz * dz)
            wide = math.sqrt(max(seg * seg - dy * dy, 0.0))
            if flat == 0.0:
                dx, dz = wide, 0.0
            else:
                dx, dz = dx * (wide / flat), dz * (wide / flat)
            cur[j] = to_world(frame, [o[0] + dx, o[1] + dy, o[2] + dz])
            b = cur[j]
            ux, uy, uz = (b[0] - a[0]) / seg, (b[1] - a[1]) / seg, (b[2] - a[2]) / seg
        px, py, pz = ux, uy, uz


def height(f: Frame, p: Vec) -> float:
    """``to_local(f, p)[1]`` alone (the same products and sums): the height above the support, which the
    rope's ground test reads for every node, the tangential coordinates only where a node is lifted."""
    return (p[0] - f[0]) * f[6] + (p[1] - f[1]) * f[7] + (p[2] - f[2]) * f[8]


def rest_nodes(m: MotionState) -> None:
    """Every rope's nodes where its rest pose puts them on the posed body, not moving (the previous
    nodes the same): the ropes at reset."""
    m.nodes, m.prev_nodes = [], []
    for rope in m.data.ropes:
        world = [
            to_world_root(m.root, anchor_point(m.quats, m.trans, rope, j)) for j in range(len(rope.rest))
        ]
        m.nodes.append(world)
        m.prev_nodes.append([list(x) for x in world])


def step_ropes(m: MotionState, frame: Frame, integrate: bool) -> None:
    """The ropes' stage of one tick: integrate (unless at reset, where they start at rest), then pose the
    rope slots from the nodes."""
    d, c = m.d, m.data.constants
    if not integrate:
        rest_nodes(m)
    g = m.gravity0 if getattr(m.gravity, "constant", False) else m.gravity.at(m.tick * d.dt)
    substeps, passes, keep = c.rope_substeps, c.rope_passes, 1.0 - c.rope_damping
    h = d.dt / substeps
    gx, gy, gz = g[0] * h * h, g[1] * h * h, g[2] * h * h
    ground = m.data.rope_ground
    f0, f1, f2, n0, n1, n2 = frame[0], frame[1], frame[2], frame[6], frame[7], frame[8]
    for index, rope in enumerate(m.data.ropes):
        cur, prev = m.nodes[index], m.prev_nodes[index]
        anchor_local = anchor_point(m.quats, m.trans, rope, 0)
        anchor = to_world_root(m.root, anchor_local)
        seg, bend_min, radius = rope.segment, rope.bend_min, rope.radius
        before = to_world_root(m.root, body_point(m.quats, m.trans, rope.parent, rope.before))
        if integrate:
            for _ in range(substeps):
                cur[0], prev[0] = list(anchor), list(anchor)
                for j in range(1, len(cur)):
                    x, o = cur[j], prev[j]
                    vx, vy, vz = (x[0] - o[0]) * keep, (x[1] - o[1]) * keep, (x[2] - o[2]) * keep
                    prev[j] = list(x)
                    cur[j] = [x[0] + vx + gx, x[1] + vy + gy, x[2] + vz + gz]
                for _ in range(passes):
                    for j in range(len(cur) - 1):
                        a, b = cur[j], cur[j + 1]
                        dx, dy, dz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
                        dist = math.sqrt(dx * dx + dy * dy + dz * dz)
                        if dist == 0.0:
                            continue
                        f = (dist - seg) / dist
                        if j == 0:
                            cur[1] = [b[0] - dx * f, b[1] - dy * f, b[2] - dz * f]
                        else:
                            hf = 0.5 * f
                            cur[j] = [a[0] + dx * hf, a[1] + dy * hf, a[2] + dz * hf]
                            cur[j + 1] = [b[0] - dx * hf, b[1] - dy * hf, b[2] - dz * hf]
                    bend(cur, before, bend_min)
                    if ground:
                        for j in range(1, len(cur)):
                            x = cur[j]  # its height above the support is to_local(frame, x)[1]:
                            if (x[0] - f0) * n0 + (x[1] - f1) * n1 + (x[2] - f2) * n2 < radius[j]:
                                u, _, w = to_local(frame, x)
                                cur[j] = to_world(frame, [u, radius[j], w])
                follow(cur, before, rope, frame, ground)
        pose_rope(m, rope, cur, anchor_local)


def pose_rope(m: MotionState, rope: RopeData, cur: list[Vec], anchor_local: Vec) -> None:
    """The rope's slots from its world nodes ``cur``, and the anchor gate (the posed anchor of segment 0
    against ``anchor_local``, the body's)."""
    local = [to_local_root(m.root, x) for x in cur]
    rest = rope.rest
    # Segment frames by parallel transport down the chain (each turns by the bend from the one
    # before; the first from the parent's), so the twist is continuous and the shortest-arc turn
    # stays far from its ill-conditioned half-turn even when the tail whips past its rest direction.
    prev_q = m.quats[rope.parent]
    prev_dir = vq.rotate(prev_q, vq.normalize([rest[1][k] - rest[0][k] for k in range(3)]))
    for j, slot in enumerate(rope.slots):
        e1 = vq.normalize([local[j + 1][k] - local[j][k] for k in range(3)])
        q = vq.mul(vq.from_to(prev_dir, e1), prev_q)
        prev_q, prev_dir = q, e1
        r = vq.rotate(q, rest[j])
        m.quats[slot] = q
        m.trans[slot] = [local[j][0] - r[0], local[j][1] - r[1], local[j][2] - r[2]]
    r0 = vq.rotate(m.quats[rope.slots[0]], rest[0])
    t0 = m.trans[rope.slots[0]]
    posed = [r0[0] + t0[0], r0[1] + t0[1], r0[2] + t0[2]]
    body = m.data.body_scale
    m.gates.rope_anchor = max(m.gates.rope_anchor, vq.distance(posed, anchor_local) / body)
