"""One creature's locomotion, tick by tick: the Python reference of core/motion/motion.js.

Order of writes per tick (the seed's rule; the last stage touching a slot wins):
1. root: position, yaw and squash (closed form for walkers, hoppers and flyers; the swimmer's vertical
   response is integrated): root.py, hop.py, swim.py;
2. base pose: per-slot local rotations composed down the skeleton (flyer bank and flap, swimmer
   undulation; identity otherwise): base_pose.py, flight.py, swim.py;
3. legs: gait plants feet in the support frame → world target → inverse root transform → body-frame IK
   → creature-local leg slots (a hopper's two legs plant together on the ground and tuck in the air):
   gait.py, hop.py;
4. ropes: fixed-step verlet in world space, anchor following the posed body, written last: ropes.py.

``Motion`` holds the state (state.py) and composes the stages. Integer ticks are authoritative: state at
tick n is reached only by stepping from tick 0, so ``seek_tick(n)`` (reset, then n steps) and n calls of
``step()`` give the same state, bit for bit.
"""

from __future__ import annotations

import struct

from ..model.genome import Genome, draw_genome
from ..model.lcg import instance_yaw
from ..model.trig import pcos, psin
from . import quat as vq
from .base_pose import base_pose
from .data import MotionData
from .derived import derive
from .express import express, individual_size
from .gait import walk
from .hop import hop_at, hop_gates, hop_legs
from .providers import SWIMMER_CHANNELS, AnalyticWater, FlatGround, Frame, Gravity, Support
from .rig import WALKERS
from .root import grounded, path
from .ropes import step_ropes
from .state import Foot, Gates, MotionState
from .swim import follow_surface


class TierRefusedError(ValueError):
    """The injected providers do not represent what this locomotion needs (absent, never invented)."""


class Motion(MotionState):
    """State and fixed step of one creature (stateful by nature: feet, ropes and the swimmer integrate)."""

    def __init__(
        self,
        data: MotionData,
        *,
        support: Support | None = None,
        gravity: Gravity | None = None,
        water: AnalyticWater | None = None,
        seed: int = 0,
        position: tuple[float, float, float] = (0.0, 0.0, 0.0),
        genome: Genome | None = None,
    ) -> None:
        # The individual's motion data: the authored parameters scaled by its size and gait genes (the
        # seed's, unless a genome is given). Its size also scales its rest geometry (creature/pose.py).
        genes = genome if genome is not None else draw_genome(seed)
        self.size = individual_size(data, genes)
        self.data = express(data, genes)
        self.kind = data.type
        self.support = support or FlatGround()
        self.gravity = gravity or Gravity()
        self.water = water
        if self.kind == "swimmer":
            if water is None:
                raise TierRefusedError("swimmer: no WaterSurfaceProvider was injected")
            missing = [c for c in SWIMMER_CHANNELS if c not in water.channels]
            if missing:
                raise TierRefusedError(f"swimmer: the water provider does not represent {', '.join(missing)}")
        self.gravity0 = self.gravity.at(0.0)
        self.d = derive(self.data, self.gravity0)
        yaw = instance_yaw(seed)
        self.theta0 = -yaw
        self.position = [float(c) for c in position]
        self.slot_count = len(data.parent)
        self.rest_pose = None
        self.reset()

    # --- state -----------------------------------------------------------------------------------

    def reset(self) -> None:
        radius = self.data.path_radius
        self.centre = [
            self.position[0] - radius * pcos(self.theta0),
            self.position[1],
            self.position[2] - radius * psin(self.theta0),
        ]
        self.tick = 0
        self.feet = [Foot() for _ in self.data.legs]
        self.nodes = []
        self.prev_nodes = []
        self.swim_y = 0.0
        self.swim_vy = 0.0
        self.gates = Gates(fewest_planted=len(self.data.legs))
        self.quats = [list(vq.IDENTITY) for _ in range(self.slot_count)]
        self.trans = [[0.0, 0.0, 0.0] for _ in range(self.slot_count)]
        self.root = [0.0, 0.0, 0.0, 1.0, 0.0, 1.0]  # position, cos yaw, sin yaw, squash
        self._update(0, integrate=False)

    def step(self) -> None:
        self.tick += 1
        self._update(self.tick, integrate=True)

    def step_ticks(self, n: int) -> None:
        for _ in range(n):
            self.step()

    def seek_tick(self, n: int) -> None:
        self.reset()
        self.step_ticks(n)

    # --- one tick --------------------------------------------------------------------------------

    def root_at(self, n: int) -> tuple[Frame, list[float]]:
        """Support frame and root (x, y, z, cos yaw, sin yaw, squash) at tick ``n``."""
        time = n * self.d.dt
        frame = self.support.frame(time)
        data = self.data
        if self.kind in WALKERS:
            u, w, psi = path(self, data.speed * time)
            return frame, grounded(data, frame, u, w, psi, 0.0, 1.0)
        if self.kind == "hopper":
            dist, lift, squash = hop_at(data, self.d, n)
            u, w, psi = path(self, dist)
            return frame, grounded(data, frame, u, w, psi, lift, squash)
        if self.kind == "flyer":
            u, w, psi = path(self, data.speed * time)
            return frame, [u, data.altitude - data.ground_y, w, pcos(psi), psin(psi), 1.0]
        if self.kind == "swimmer":
            u, w, psi = path(self, data.speed * time)
            return frame, [u, self.swim_y, w, pcos(psi), psin(psi), 1.0]
        return frame, grounded(data, frame, self.position[0], self.position[2], -self.theta0, 0.0, 1.0)

    def _update(self, n: int, *, integrate: bool) -> None:
        time = n * self.d.dt
        if self.kind == "swimmer":
            follow_surface(self, n, integrate)
        frame, root = self.root_at(n)
        self.root = root
        if self.kind == "hopper":
            hop_gates(self, n, root)
        base_pose(self, time)
        if self.data.legs:
            if self.kind == "hopper":
                hop_legs(self, n, frame, integrate)
            else:
                walk(self, n, frame, integrate)
        if self.data.ropes:
            step_ropes(self, frame, integrate)

    # --- output ----------------------------------------------------------------------------------

    def state_vector(self) -> list[float]:
        """Root, then every slot's quaternion and translation, then rope nodes: what parity compares."""
        out = list(self.root)
        for q, t in zip(self.quats, self.trans, strict=True):
            out += q + t
        for nodes in self.nodes:
            for x in nodes:
                out += x
        return out

    def state_hash(self) -> str:
        """FNV-1a lanes (core/hash.js) over the tick and the float64 state, in state_vector order plus
        the integrator state (previous rope nodes, feet, swimmer)."""
        values = self.state_vector()
        for nodes in self.prev_nodes:
            for x in nodes:
                values += x
        for foot in self.feet:
            values += [1.0 if foot.planted else 0.0, *foot.p, *foot.s, *foot.t, float(foot.n0)]
        values += [self.swim_y, self.swim_vy, self.centre[0], self.centre[2]]
        return hash_bytes(struct.pack(f"<{len(values)}d", *values), self.tick)


def hash_bytes(data: bytes, tick: int) -> str:
    h1, h2 = 0x811C9DC5, 0x050C5D1F
    prefix = bytes((tick >> (8 * k)) & 255 for k in range(4))
    for b in prefix + data:
        h1 = ((h1 ^ b) * 0x01000193) & 0xFFFFFFFF
        h2 = ((h2 ^ b) * 0x01000193) & 0xFFFFFFFF
        h2 = ((h2 << 13) | (h2 >> 19)) & 0xFFFFFFFF
    return f"{h1:08x}{h2:08x}"
