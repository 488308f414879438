"""One creature's locomotion, tick by tick: the Python reference of core/motion/motion.js.

Order of writes per tick (the seed's rule; the last stage touching a slot wins):
1. root: position, yaw and squash (closed form for walkers, hoppers and flyers; the swimmer's vertical
   response is integrated);
2. base pose: per-slot local rotations composed down the skeleton (flyer bank and flap, swimmer
   undulation; identity otherwise);
3. legs: gait plants feet in the support frame → world target → inverse root transform → body-frame IK
   → creature-local leg slots (a hopper's two legs plant together on the ground and tuck in the air);
4. ropes: fixed-step verlet in world space, anchor following the posed body, written last.

Integer ticks are authoritative: state at tick n is reached only by stepping from tick 0, so
``seek_tick(n)`` (reset, then n steps) and n calls of ``step()`` give the same state, bit for bit.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from typing import Any

from ..model.genome import Genome, draw_genome, express, individual_size
from ..model.lcg import instance_yaw
from ..model.trig import pcos, psin
from . import quat as vq
from .derived import Derived, derive
from .ik import solve_leg
from .providers import (
    SWIMMER_CHANNELS,
    AnalyticWater,
    FlatGround,
    Frame,
    Gravity,
    Support,
    to_local,
    to_world,
)
from .quat import Vec
from .rig import WALKERS

Z_AXIS = [0.0, 0.0, 1.0]
Y_AXIS = [0.0, 1.0, 0.0]


class TierRefusedError(ValueError):
    """The injected providers do not represent what this locomotion needs (absent, never invented)."""


@dataclass
class Foot:
    planted: bool = True
    p: Vec = field(default_factory=lambda: [0.0, 0.0, 0.0])  # support-local plant
    s: Vec = field(default_factory=lambda: [0.0, 0.0, 0.0])  # swing start
    t: Vec = field(default_factory=lambda: [0.0, 0.0, 0.0])  # swing target
    n0: int = 0


@dataclass
class Gates:
    """Worst values seen since reset (measured every tick)."""

    plant_drift: float = 0.0  # |support-local drawn foot − plant| / leg length, planted and unclamped
    ik_residual: float = 0.0
    drawn_foot: float = 0.0  # |drawn foot (slot transform) − IK foot| / leg length
    clamped_ticks: int = 0
    planted_samples: int = 0
    both_swing_ticks: int = 0
    # Fewest feet planted on any tick (the number of legs until a foot lifts): one phase group swings at a
    # time, so a walker keeps at least its other groups' feet down (4 of 8 for alternating tetrapods).
    fewest_planted: int = 0
    steps: int = 0
    rope_anchor: float = 0.0  # |posed anchor of segment 0 − body anchor| / L
    swim_tracking: float = 0.0  # max |y − target| after 2 s, metres
    apex_error: float = 0.0  # |y at the apex tick − closed-form apex|, metres
    apex_squash: float = 1.0
    squash_det: float = 0.0  # max |sx·sy·sz − 1|

    def as_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


class Motion:
    """State and fixed step of one creature (stateful by nature: feet, ropes and the swimmer integrate)."""

    def __init__(
        self,
        data: dict[str, Any],
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
        self.kind = str(data["type"])
        self.support: Support = support or FlatGround()
        self.gravity = gravity or Gravity()
        self.water = water
        if self.kind == "swimmer":
            if water is None:
                raise TierRefusedError("swimmer: no WaterSurfaceProvider was injected")
            missing = [c for c in SWIMMER_CHANNELS if c not in water.channels]
            if missing:
                raise TierRefusedError(f"swimmer: the water provider does not represent {', '.join(missing)}")
        self.gravity0 = self.gravity.at(0.0)
        self.d: Derived = derive(self.data, self.gravity0)
        yaw = instance_yaw(seed)
        self.theta0 = -yaw
        self.position = [float(c) for c in position]
        self.slot_count = len(data["parent"])
        # The base pose of a body without local rotations (see _base_pose), composed on first use.
        self._rest_pose: tuple[list[list[float]], list[Vec]] | None = None
        self.reset()

    # --- state -----------------------------------------------------------------------------------

    def reset(self) -> None:
        radius = self.data["pathRadius"]
        self.centre = [
            self.position[0] - radius * pcos(self.theta0),
            self.position[1],
            self.position[2] - radius * psin(self.theta0),
        ]
        self.tick = 0
        self.feet = [Foot() for _ in self.data["legs"]]
        self.nodes: list[list[Vec]] = []
        self.prev_nodes: list[list[Vec]] = []
        self.swim_y = 0.0
        self.swim_vy = 0.0
        self.gates = Gates(fewest_planted=len(self.data["legs"]))
        self.quats: list[list[float]] = [list(vq.IDENTITY) for _ in range(self.slot_count)]
        self.trans: list[Vec] = [[0.0, 0.0, 0.0] for _ in range(self.slot_count)]
        self.root: list[float] = [0.0, 0.0, 0.0, 1.0, 0.0, 1.0]  # position, cos yaw, sin yaw, squash
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

    # --- root ------------------------------------------------------------------------------------

    def _path(self, dist: float) -> tuple[float, float, float]:
        """Support-local (u, w) and heading ψ on the circle after ``dist`` metres."""
        radius = self.data["pathRadius"]
        theta = self.theta0 + dist / radius
        return self.centre[0] + radius * pcos(theta), self.centre[2] + radius * psin(theta), -theta

    def _grounded(
        self, frame: Frame, u: float, w: float, psi: float, lift: float, squash: float
    ) -> list[float]:
        """Root (x, y, z, cos yaw, sin yaw, squash) on the support at (u, w), heading ψ in its plane."""
        ground = to_world(frame, [u, 0.0, w])
        sp, cp = psin(psi), pcos(psi)
        fx = sp * frame[3] + cp * frame[9]
        fz = sp * frame[5] + cp * frame[11]
        norm = math.sqrt(fx * fx + fz * fz)
        c, s = fz / norm, fx / norm
        if self.data["legs"]:
            lift = lift + self._settle(frame, c, s)
        y = ground[1] + lift - self.data["groundY"] * squash
        return [ground[0], y, ground[2], c, s, squash]

    def _settle(self, frame: Frame, c: float, s: float) -> float:
        """How far an upright body sinks on a tilted support: halfway between its lowest and highest rest
        foot's support height (relative to under the root), but never so far that a downhill leg must
        reach past ``settleSlack`` of the room its rest pose leaves to full extension. Sinking to the lowest
        foot, as it did, folded the uphill legs of a long body to a twentieth of their reach and turned
        their hips over (generated seed 189 on the 10° slope)."""
        ny = frame[7]
        lowest = highest = 0.0
        room = math.inf
        for leg in self.data["legs"]:
            r = vq.yaw_rotate(c, s, leg["foot"])
            dy = -(frame[6] * r[0] + frame[8] * r[2]) / ny
            lowest, highest = min(lowest, dy), max(highest, dy)
            room = min(room, leg["reachMax"] - vq.distance(leg["hip"], leg["foot"]))
        slack = float(self.data["constants"]["settleSlack"])
        return lowest + min(0.5 * (highest - lowest), slack * max(room, 0.0))

    def _hop(self, n: int) -> tuple[float, float, float]:
        """(distance along the path, height above the support, squash) of the hopper at tick ``n``. In the
        crouch and the landing a hopper on legs also sinks on them (``dip``, 0 without legs)."""
        d, c = self.d, self.data["constants"]
        hop_length = self.data["hopLength"] if self.data["speed"] > 0.0 else 0.0
        k, m = divmod(n, d.hop_cycle)
        if m < d.hop_idle:
            return k * hop_length, 0.0, 1.0
        m -= d.hop_idle
        if m < d.crouch:
            sink = psin(math.pi * (m / d.crouch))
            return k * hop_length, 0.0 - d.dip * sink, 1.0 - c["hopSquash"] * sink
        m -= d.crouch
        if m < d.air:
            ts = m * d.dt
            tau = m / d.air
            e = 2.0 * tau - 1.0
            y = d.v0 * ts - 0.5 * d.g * ts * ts
            return k * hop_length + hop_length * tau, y, 1.0 + c["hopStretch"] * (e * e)
        m -= d.air
        sink = psin(math.pi * (m / d.land))
        return (k + 1) * hop_length, 0.0 - d.dip * sink, 1.0 - c["hopSquash"] * sink

    def root_at(self, n: int) -> tuple[Frame, list[float]]:
        """Support frame and root (x, y, z, cos yaw, sin yaw, squash) at tick ``n``."""
        time = n * self.d.dt
        frame = self.support.frame(time)
        data = self.data
        if self.kind in WALKERS:
            u, w, psi = self._path(data["speed"] * time)
            return frame, self._grounded(frame, u, w, psi, 0.0, 1.0)
        if self.kind == "hopper":
            dist, lift, squash = self._hop(n)
            u, w, psi = self._path(dist)
            return frame, self._grounded(frame, u, w, psi, lift, squash)
        if self.kind == "flyer":
            u, w, psi = self._path(data["speed"] * time)
            return frame, [u, data["altitude"] - data["groundY"], w, pcos(psi), psin(psi), 1.0]
        if self.kind == "swimmer":
            u, w, psi = self._path(data["speed"] * time)
            return frame, [u, self.swim_y, w, pcos(psi), psin(psi), 1.0]
        return frame, self._grounded(frame, self.position[0], self.position[2], -self.theta0, 0.0, 1.0)

    @staticmethod
    def to_world_root(root: list[float], x: Vec) -> Vec:
        """Creature-local → world: p + R_yaw(S·x), S = diag(1/√s, s, 1/√s) (determinant 1); the root is
        (x, y, z, cos yaw, sin yaw, squash)."""
        c, s, squash = root[3], root[4], root[5]
        k = 1.0 / math.sqrt(squash)
        r = vq.yaw_rotate(c, s, [x[0] * k, x[1] * squash, x[2] * k])
        return [root[0] + r[0], root[1] + r[1], root[2] + r[2]]

    @staticmethod
    def to_local_root(root: list[float], x: Vec) -> Vec:
        c, s, squash = root[3], root[4], root[5]
        r = vq.yaw_unrotate(c, s, [x[0] - root[0], x[1] - root[1], x[2] - root[2]])
        sq = math.sqrt(squash)
        return [r[0] * sq, r[1] / squash, r[2] * sq]

    # --- one tick --------------------------------------------------------------------------------

    def _update(self, n: int, *, integrate: bool) -> None:
        time = n * self.d.dt
        if self.kind == "swimmer":
            self._swim(n, integrate)
        frame, root = self.root_at(n)
        self.root = root
        if self.kind == "hopper":
            self._hop_gates(n, root)
        self._base_pose(time)
        if self.data["legs"]:
            self._gait(n, frame, integrate)
        if self.data["ropes"]:
            self._ropes(frame, integrate)

    def _swim(self, n: int, integrate: bool) -> None:
        d, data = self.d, self.data
        time = n * d.dt
        u, w, _ = self._path(data["speed"] * time)
        assert self.water is not None
        sample = self.water.sample(u, w, time)
        eta = sample["freeSurfacePoint"][1]
        target = eta - d.swim_depth - data["centreY"]
        target_v = sample["geometricNormalVelocityMps"][0] / sample["freeSurfaceNormal"][1]
        if not integrate:
            self.swim_y, self.swim_vy = target, target_v
        else:
            om = d.swim_omega
            acc = om * om * (target - self.swim_y) + 2.0 * om * (target_v - self.swim_vy)
            self.swim_vy = self.swim_vy + acc * d.dt
            self.swim_y = self.swim_y + self.swim_vy * d.dt
        current = sample.get("materialCurrentVelocityMps")
        if current is not None:
            self.centre[0] = self.centre[0] + current[0] * d.dt
            self.centre[2] = self.centre[2] + current[2] * d.dt
        if time >= 2.0:
            self.gates.swim_tracking = max(self.gates.swim_tracking, abs(self.swim_y - target))

    def _hop_gates(self, n: int, root: list[float]) -> None:
        squash = root[5]
        k = 1.0 / math.sqrt(squash)
        self.gates.squash_det = max(self.gates.squash_det, abs(k * squash * k - 1.0))
        d = self.d
        if n % d.hop_cycle == d.hop_idle + d.crouch + d.half_air:
            _, lift, _ = self._hop(n)
            self.gates.apex_error = max(self.gates.apex_error, abs(lift - d.apex))
            self.gates.apex_squash = squash

    def _base_pose(self, time: float) -> None:
        data, d = self.data, self.d
        if self.kind != "flyer" and not (self.kind == "swimmer" and d.undulation_hz > 0.0):
            # No local rotation at any time: the same pose every tick, composed once (then copied).
            if self._rest_pose is None:
                self._compose_base({})
                self._rest_pose = ([list(q) for q in self.quats], [list(t) for t in self.trans])
            quats, trans = self._rest_pose
            for s in data["order"]:
                self.quats[s], self.trans[s] = list(quats[s]), list(trans[s])
            return
        locals_: dict[int, list[float]] = {}
        if self.kind == "flyer":
            for r in data["roots"]:
                locals_[r] = [0.0, 0.0, d.bank_half_sin, d.bank_half_cos]
            flap = psin(2.0 * math.pi * d.flap_hz * time)
            for wing in data["wings"]:
                locals_[wing["slot"]] = vq.axis_angle(Z_AXIS, wing["sign"] * wing["amplitude"] * flap)
        elif self.kind == "swimmer" and d.undulation_hz > 0.0:
            angle = data["undulation"] * psin(2.0 * math.pi * d.undulation_hz * time)
            for r in data["roots"]:
                locals_[r] = vq.axis_angle(Y_AXIS, angle)
        self._compose_base(locals_)

    def _compose_base(self, locals_: dict[int, list[float]]) -> None:
        """Per-slot local rotations (identity where absent) composed down the skeleton about the pivots."""
        data = self.data
        parent, pivot = data["parent"], data["pivot"]
        for s in data["order"]:
            local = locals_.get(s, list(vq.IDENTITY))
            pv = pivot[s]
            turned = vq.rotate(local, pv)
            arm = [pv[0] - turned[0], pv[1] - turned[1], pv[2] - turned[2]]
            p = parent[s]
            if p < 0:
                self.quats[s] = local
                self.trans[s] = arm
            else:
                self.quats[s] = vq.mul(self.quats[p], local)
                moved = vq.rotate(self.quats[p], arm)
                tp = self.trans[p]
                self.trans[s] = [moved[0] + tp[0], moved[1] + tp[1], moved[2] + tp[2]]

    # --- legs ------------------------------------------------------------------------------------

    def _home(self, leg: dict[str, Any], frame: Frame, root: list[float]) -> Vec:
        """Support-local home of a foot: the rest foot under ``root``, on the support ``frame``."""
        local = to_local(frame, self.to_world_root(root, leg["foot"]))
        return [local[0], 0.0, local[2]]

    def _initial_plant(self, leg: dict[str, Any], frame: Frame) -> Vec:
        """Where a steady gait would have this foot at tick 0: group g last landed (cycle − swing − g·W)
        ticks of travel ago at stepLead·s ahead of its home, so every group lifts as its window opens."""
        data, d = self.data, self.d
        home = self._home(leg, frame, self.root)
        if data["speed"] <= 0.0:
            return home
        lead = data["constants"]["stepLead"] * data["stepLength"]
        back = data["speed"] * d.dt * (d.cycle - d.swing - leg["group"] * d.window)
        psi = self._path(0.0)[2]
        offset = lead - back
        return [home[0] + psin(psi) * offset, 0.0, home[2] + pcos(psi) * offset]

    def _gait(self, n: int, frame: Frame, integrate: bool) -> None:
        if self.kind == "hopper":
            self._hop_legs(n, frame, integrate)
            return
        data, d, gates = self.data, self.d, self.gates
        step_length = data["stepLength"]
        lead = data["constants"]["stepLead"] * step_length
        m = n % d.cycle
        swinging = 0
        for leg, foot in zip(data["legs"], self.feet, strict=True):
            if not integrate:
                foot.planted, foot.p = True, self._initial_plant(leg, frame)
            elif not foot.planted and n - foot.n0 >= d.swing:
                foot.planted, foot.p = True, list(foot.t)
            if foot.planted and integrate:
                home = self._home(leg, frame, self.root)
                du, dw = home[0] - foot.p[0], home[2] - foot.p[2]
                lag = math.sqrt(du * du + dw * dw)
                k = m - leg["group"] * d.window
                if lag > step_length and 0 <= k <= d.window - d.swing:
                    ahead = self._home(leg, *self.root_at(n + d.swing))
                    du, dw = ahead[0] - foot.p[0], ahead[2] - foot.p[2]
                    dl = math.sqrt(du * du + dw * dw)
                    foot.planted, foot.n0, foot.s = False, n, list(foot.p)
                    foot.t = [ahead[0], 0.0, ahead[2]]
                    if dl > 0.0:
                        foot.t = [ahead[0] + du / dl * lead, 0.0, ahead[2] + dw / dl * lead]
                    gates.steps += 1
            if foot.planted:
                local = foot.p
            else:
                swinging += 1
                tau = (n - foot.n0) / d.swing
                sigma = tau * tau * (3.0 - 2.0 * tau)
                lift = data["stepHeight"] * (4.0 * tau * (1.0 - tau))
                local = [
                    foot.s[0] + (foot.t[0] - foot.s[0]) * sigma,
                    lift,
                    foot.s[2] + (foot.t[2] - foot.s[2]) * sigma,
                ]
            self._place_leg(leg, foot, self.to_local_root(self.root, to_world(frame, local)), frame)
        self._count_planted(swinging)

    def _hop_legs(self, n: int, frame: Frame, integrate: bool) -> None:
        """A hopper's two hind legs, together: planted on the support while the body is on it (idle, crouch,
        landing), their plants fixed in the support frame while the IK bends them under the sinking, squashed
        body; airborne from the first air tick, when each foot leaves its take-off plant (s), is drawn up
        toward its hip (``tuck`` of the rest hip-foot distance) at the apex and reaches for its landing plant
        (t): the rest foot under the root at the landing tick, known in closed form when it takes off. The
        target blends s and t (smoothstep σ(τ)) in the creature frame, pulled toward the tuck by
        (4τ(1 − τ))², so a leg first stretches toward the ground it left (the push-off), then folds, then
        stretches toward the ground ahead."""
        d = self.d
        m = n % d.hop_cycle
        airborne = d.hop_idle + d.crouch <= m < d.hop_idle + d.crouch + d.air
        swinging = 0
        for leg, foot in zip(self.data["legs"], self.feet, strict=True):
            if not integrate:
                foot.planted, foot.p = True, self._home(leg, frame, self.root)
            elif foot.planted and airborne:
                foot.planted, foot.n0, foot.s = False, n, list(foot.p)
                foot.t = self._home(leg, *self.root_at(n + d.air))
                self.gates.steps += 1
            elif not foot.planted and not airborne:
                foot.planted, foot.p = True, list(foot.t)
            if foot.planted:
                target = self.to_local_root(self.root, to_world(frame, foot.p))
            else:
                swinging += 1
                tau = (n - foot.n0) / d.air
                sigma = tau * tau * (3.0 - 2.0 * tau)
                arc = 4.0 * tau * (1.0 - tau)
                pull = arc * arc
                a = self.to_local_root(self.root, to_world(frame, foot.s))
                b = self.to_local_root(self.root, to_world(frame, foot.t))
                hip, rest, tuck = leg["hip"], leg["foot"], leg["tuck"]
                target = [0.0, 0.0, 0.0]
                for k in range(3):
                    base = a[k] + (b[k] - a[k]) * sigma
                    tucked = hip[k] + (rest[k] - hip[k]) * tuck
                    target[k] = base + (tucked - base) * pull
            self._place_leg(leg, foot, target, frame)
        self._count_planted(swinging)

    def _place_leg(self, leg: dict[str, Any], foot: Foot, target: Vec, frame: Frame) -> None:
        """Two-bone IK toward ``target`` (creature frame) into the leg's slots, and the leg gates."""
        gates = self.gates
        ik = solve_leg(leg, target)
        self.quats[leg["upper"]], self.trans[leg["upper"]] = ik.q_upper, ik.t_upper
        self.quats[leg["lower"]], self.trans[leg["lower"]] = ik.q_lower, ik.t_lower
        span = leg["a"] + leg["b"]
        gates.ik_residual = max(gates.ik_residual, ik.residual)
        drawn = vq.rotate(ik.q_lower, leg["foot"])
        drawn = [drawn[0] + ik.t_lower[0], drawn[1] + ik.t_lower[1], drawn[2] + ik.t_lower[2]]
        gates.drawn_foot = max(gates.drawn_foot, vq.distance(drawn, ik.foot) / span)
        if ik.clamped:
            gates.clamped_ticks += 1
        elif foot.planted:
            back = to_local(frame, self.to_world_root(self.root, drawn))
            gates.plant_drift = max(gates.plant_drift, vq.distance(back, foot.p) / span)
            gates.planted_samples += 1

    def _count_planted(self, swinging: int) -> None:
        gates = self.gates
        if len(self.feet) == 2 and swinging == 2:
            gates.both_swing_ticks += 1
        gates.fewest_planted = min(gates.fewest_planted, len(self.feet) - swinging)

    # --- ropes -----------------------------------------------------------------------------------

    def _body_point(self, slot: int, x: Vec) -> Vec:
        """Rest point ``x`` moved rigidly with ``slot`` (creature-local)."""
        q, t = self.quats[slot], self.trans[slot]
        r = vq.rotate(q, x)
        return [r[0] + t[0], r[1] + t[1], r[2] + t[2]]

    def _anchor_point(self, rope: dict[str, Any], j: int) -> Vec:
        """Rest point ``j`` of the rope moved rigidly with its parent slot (creature-local)."""
        return self._body_point(rope["parent"], rope["rest"][j])

    @staticmethod
    def _bend(cur: list[Vec], before: Vec, bend_min: float) -> None:
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

    def _follow(self, cur: list[Vec], before: Vec, rope: dict[str, Any], frame: Frame) -> None:
        """Follow the leader from the anchor: each segment its rest length and within the bend limit of the
        one before (the first of the body's direction into the anchor), and above the support. Relaxation
        passes alone leave a whipped tail stretched and bent past its limit; the skin is certified for the
        poses this bounds (motion/envelope.py)."""
        seg, c_max, s_max, radius = rope["segment"], rope["bendCos"], rope["bendSin"], rope["radius"]
        ground = self.data["ropeGround"]
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
            if ground and _height(frame, cur[j]) < radius[j]:
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

    def _ropes(self, frame: Frame, integrate: bool) -> None:
        d, c = self.d, self.data["constants"]
        if not integrate:
            self.nodes, self.prev_nodes = [], []
            for rope in self.data["ropes"]:
                world = [
                    self.to_world_root(self.root, self._anchor_point(rope, j))
                    for j in range(len(rope["rest"]))
                ]
                self.nodes.append(world)
                self.prev_nodes.append([list(x) for x in world])
        g = self.gravity0 if getattr(self.gravity, "constant", False) else self.gravity.at(self.tick * d.dt)
        substeps, passes, keep = c["ropeSubsteps"], c["ropePasses"], 1.0 - c["ropeDamping"]
        h = d.dt / substeps
        gx, gy, gz = g[0] * h * h, g[1] * h * h, g[2] * h * h
        ground = self.data["ropeGround"]
        f0, f1, f2, n0, n1, n2 = frame[0], frame[1], frame[2], frame[6], frame[7], frame[8]
        for index, rope in enumerate(self.data["ropes"]):
            cur, prev = self.nodes[index], self.prev_nodes[index]
            anchor_local = self._anchor_point(rope, 0)
            anchor = self.to_world_root(self.root, anchor_local)
            seg, bend_min, radius = rope["segment"], rope["bendMin"], rope["radius"]
            before = self.to_world_root(self.root, self._body_point(rope["parent"], rope["before"]))
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
                        self._bend(cur, before, bend_min)
                        if ground:
                            for j in range(1, len(cur)):
                                x = cur[j]  # its height above the support is to_local(frame, x)[1]:
                                if (x[0] - f0) * n0 + (x[1] - f1) * n1 + (x[2] - f2) * n2 < radius[j]:
                                    u, _, w = to_local(frame, x)
                                    cur[j] = to_world(frame, [u, radius[j], w])
                    self._follow(cur, before, rope, frame)
            local = [self.to_local_root(self.root, x) for x in cur]
            rest = rope["rest"]
            # Segment frames by parallel transport down the chain (each turns by the bend from the one
            # before; the first from the parent's), so the twist is continuous and the shortest-arc turn
            # stays far from its ill-conditioned half-turn even when the tail whips past its rest direction.
            prev_q = self.quats[rope["parent"]]
            prev_dir = vq.rotate(prev_q, vq.normalize([rest[1][k] - rest[0][k] for k in range(3)]))
            for j, slot in enumerate(rope["slots"]):
                e1 = vq.normalize([local[j + 1][k] - local[j][k] for k in range(3)])
                q = vq.mul(vq.from_to(prev_dir, e1), prev_q)
                prev_q, prev_dir = q, e1
                r = vq.rotate(q, rest[j])
                self.quats[slot] = q
                self.trans[slot] = [local[j][0] - r[0], local[j][1] - r[1], local[j][2] - r[2]]
            r0 = vq.rotate(self.quats[rope["slots"][0]], rest[0])
            t0 = self.trans[rope["slots"][0]]
            posed = [r0[0] + t0[0], r0[1] + t0[1], r0[2] + t0[2]]
            body = self.data["bodyScale"]
            self.gates.rope_anchor = max(self.gates.rope_anchor, vq.distance(posed, anchor_local) / body)

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


def _height(f: Frame, p: Vec) -> float:
    """``to_local(f, p)[1]`` alone (the same products and sums): the height above the support, which the
    rope's ground test reads for every node, the tangential coordinates only where a node is lifted."""
    return (p[0] - f[0]) * f[6] + (p[1] - f[1]) * f[7] + (p[2] - f[2]) * f[8]


def hash_bytes(data: bytes, tick: int) -> str:
    h1, h2 = 0x811C9DC5, 0x050C5D1F
    prefix = bytes((tick >> (8 * k)) & 255 for k in range(4))
    for b in prefix + data:
        h1 = ((h1 ^ b) * 0x01000193) & 0xFFFFFFFF
        h2 = ((h2 ^ b) * 0x01000193) & 0xFFFFFFFF
        h2 = ((h2 << 13) | (h2 >> 19)) & 0xFFFFFFFF
    return f"{h1:08x}{h2:08x}"
