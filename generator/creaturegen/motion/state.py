"""What every stage of one tick reads and writes: the individual's motion data, its root, its posed slots,
its feet and ropes, and the gates measured on them.

simulate.py's ``Motion`` owns this state and composes the stages that write it (root.py, base_pose.py,
gait.py, hop.py, flight.py, swim.py, ropes.py); each stage is a function of the state, so it reads as its
own concept, as the JS core does (core/motion/state.js and one module per stage). The state is stateful
by nature: feet, ropes and the swimmer integrate, so the state at tick n is reached only by stepping from
tick 0.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

from .data import MotionData
from .derived import Derived
from .providers import AnalyticWater, Frame, Gravity, Support
from .quat import Vec


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

    def as_dict(self) -> dict[str, float]:
        return dict(self.__dict__)


class MotionState(ABC):
    """One creature's locomotion state (set by simulate.Motion at spawn and reset)."""

    # The individual: its size factor, its motion data (the authored data expressed by its genes), its
    # locomotion type, the numbers derived from the data and the gravity at spawn.
    size: float
    data: MotionData
    kind: str
    d: Derived
    # The injected providers, and gravity at time 0.
    support: Support
    gravity: Gravity
    water: AnalyticWater | None
    gravity0: Vec
    # Where it spawned: the path's start angle and the spawn position.
    theta0: float
    position: list[float]
    slot_count: int
    # The path's centre (a water current carries it), the tick, and what integrates.
    centre: list[float]
    tick: int
    feet: list[Foot]
    nodes: list[list[Vec]]
    prev_nodes: list[list[Vec]]
    swim_y: float
    swim_vy: float
    gates: Gates
    # The output: per-slot quaternion and translation, the root (position, cos yaw, sin yaw, squash).
    quats: list[list[float]]
    trans: list[Vec]
    root: list[float]
    # The base pose of a body without local rotations (see base_pose.py), composed on first use.
    rest_pose: tuple[list[list[float]], list[Vec]] | None

    @abstractmethod
    def root_at(self, n: int) -> tuple[Frame, list[float]]:
        """Support frame and root (x, y, z, cos yaw, sin yaw, squash) at tick ``n``."""
