"""The pose envelope: the poses the locomotion reference reaches, measured for the sweeps that certify a body.

The candidate sweep and the skinning sweeps used to assume poses (random translations inside a ball
per part, ±60° bends and ±45° twists at every joint). Here the poses come from the creature's own
motion: the Python reference (motion/simulate.py, bit for bit what the package's core runs) is stepped
over whole cycles for the authored individual and every corner of the gene box that moves slots (each
gait gene and the size gene at −1 and +1, the bounds every spawned genome lies within), on every built-in
support a walker or hopper can be given, at four headings where the support is not the same in every
direction (the swimmer on the analytic water a population uses by default).

An individual of size s is a similarity of the certified body: its slot transforms carry ``s·x`` to
``R·s·x + t``, which is the unit body's ``R·x + t/s`` scaled by s. So each sample is recorded as the unit
body's pose (translations divided by the individual's size): what the unit body must carry so that every
size in the box is certified by the same sweeps. Size still changes the poses themselves, because gravity
is not scaled (swing and air times, rope sag and the flyer's bank differ).

Poses are taken modulo the body's rigid motion, in the frame of the first skeleton root: one rigid
transform of every slot changes no distance, normal or weight (the flyer's bank and the swimmer's yaw
wave turn the whole body). What remains is what skinning and candidate programs must carry: per joint,
the child's rotation relative to its parent, split into swing (bend of the child's rest tangent) and
twist (about it); per slot, how far its ends move from rest.

The candidate certificates assume each slot moves at most its widened displacement (``slot_excursion``).
This replaced a model assumed before locomotion existed (a leg's whole reach, a rope's length, a flap's
chord, a squash ratio, inherited down the parts), which the measured motion broke: a rope tail swings its
tip up to twice its length from rest. The hopper's squash is the root transform's, applied after the
field, skin and correction, so it moves no slot.

Sampled corners are not a proof: an individual between them, or at another heading, can go a little
further (ropes are chaotic). The consumers widen what was measured by stated margins, and
tests/test_motion_envelope.py checks randomly spawned individuals on every support against the widened
envelope.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import multiprocessing
import os
from dataclasses import dataclass
from functools import cache
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from ..cachedir import default_cache_root
from ..codedigest import stage_digest
from ..model import layout as col
from ..model.genome import MAX_GAIT_GENES, Genome
from ..model.lcg import instance_yaw
from ..model.rotations import CONJUGATE, Pose, quaternion_multiply, quaternion_to_matrix
from ..model.skeleton import Skeleton, joint_frame
from .compiled import CompiledCreature
from .data import MotionData
from .derived import MotionRangeError, derive
from .express import express
from .providers import AnalyticWater, FlatGround, Gravity, Support, builtin_supports
from .rig import WALKERS
from .simulate import Motion

F64 = npt.NDArray[np.float64]

#: Whole cycles stepped per run (walkers: gait cycles; hopper: hops; flyer: flaps; swimmer: undulation
#: periods), and the least time a run covers: ropes settle from rest and first steps start from the
#: initial plant, and both are poses a spawned instance shows.
CYCLES: Final = 2
MIN_SECONDS: Final = 4.0
#: The most ticks the envelope steps over all its runs: a creature whose slow cycle would need more is
#: refused by name instead of stepping for many minutes (a hopper at scale 1000 hops for half a minute).
#: It is the budget a cap of 20 s per cycle gave a walker's 117 runs (117 × CYCLES × 20 s × 60 Hz), so a
#: swimmer or a flyer, with 9 or 17 runs, may have a slower cycle than a walker (a 32 s undulation).
MAX_ENVELOPE_TICKS: Final = 280_800
#: Poses of the envelope handed to the whole-body sweeps (candidate programs, skin correction), chosen
#: by farthest-point selection over all sampled ticks, starting from the pose that moves slots most.
SWEEP_POSES: Final = 8
#: What the consumers add to the measured envelope: a slot's excursion ball is SLOT_MARGIN times its
#: largest measured displacement; a joint that turns at all (more than STILL_DEG, float noise) is swept
#: JOINT_SLACK_DEG past its measured bend and twist. Individuals between the sampled corners, other
#: headings and rope chaos go a little past the corners (tests/test_motion_envelope.py measures random
#: spawns against the widened envelope on every support); the render pose interpolates between ticks.
SLOT_MARGIN: Final = 1.25
JOINT_SLACK_DEG: Final = 10.0
STILL_DEG: Final = 1e-3
#: A still joint's pivot stays this close to its rest place relative to the parent, × L (float noise).
STILL_DRIFT: Final = 1e-9
#: Headings a run starts at on a support that is not the same in every direction.
HEADINGS: Final = 4
#: Environment variable: how many processes step the envelope's runs (see envelope_workers).
WORKERS_ENV: Final = "CREATUREGEN_WORKERS"


@dataclass(frozen=True)
class JointEnvelope:
    """Worst rotation of one joint's child relative to its parent over every run."""

    child: int
    bend_deg: float  # swing of the child's rest tangent
    twist_deg: float  # about the child's rest tangent
    pivot_drift: float  # |relative transform moves the pivot|, m: a joint turns about its pivot
    worst_run: str = ""  # the run whose turn is largest (bend or twist), named in a refusal


@dataclass(frozen=True)
class PoseEnvelope:
    runs: tuple[str, ...]  # "support genome" labels of the runs stepped
    ticks: int  # ticks per run
    samples: int  # poses measured, all runs together
    joints: tuple[JointEnvelope, ...]  # in skeleton.joints order
    slot_displacement: F64  # (S,) max |posed end − rest end|, m, in the root frame
    poses: tuple[Pose, ...]  # SWEEP_POSES representative poses, root frame
    pose_labels: tuple[str, ...]

    def joint(self, child: int) -> JointEnvelope | None:
        return next((j for j in self.joints if j.child == child), None)

    def still_joints(self, length_scale: float) -> frozenset[int]:
        """Child slots of the joints the motion never turns: no bend or twist past STILL_DEG and a pivot
        that stays within STILL_DRIFT·L of its parent, so child and parent share one transform."""
        return frozenset(
            j.child
            for j in self.joints
            if j.bend_deg <= STILL_DEG
            and j.twist_deg <= STILL_DEG
            and j.pivot_drift <= STILL_DRIFT * length_scale
        )

    def sweep_limits(self, child: int) -> tuple[float, float]:
        """(bend, twist) in degrees the skinning sweep of the joint above ``child`` must reach."""
        j = self.joint(child)
        if j is None:
            return 0.0, 0.0
        widen = [a + JOINT_SLACK_DEG if a > STILL_DEG else 0.0 for a in (j.bend_deg, j.twist_deg)]
        return widen[0], widen[1]

    @property
    def slot_excursion(self) -> F64:
        """(S,) the radius, m, each slot's ends may move from rest: the widened measured displacement."""
        result: F64 = SLOT_MARGIN * self.slot_displacement
        return result

    def describe(self) -> dict[str, object]:
        return {
            "runs": list(self.runs),
            "ticksPerRun": self.ticks,
            "samples": self.samples,
            "sweepPoses": list(self.pose_labels),
            "margins": {"slot": SLOT_MARGIN, "jointSlackDeg": JOINT_SLACK_DEG, "stillDeg": STILL_DEG},
            "slotDisplacement": self.slot_displacement.tolist(),
            "joints": [
                {
                    "child": j.child,
                    "bendDeg": j.bend_deg,
                    "twistDeg": j.twist_deg,
                    "pivotDrift": j.pivot_drift,
                    "worstRun": j.worst_run,
                }
                for j in self.joints
            ],
        }


def _period(data: MotionData) -> int:
    """Ticks of one cycle of an individual's motion (0 where it has none)."""
    d = derive(data, Gravity().at(0.0))
    kind = data.type
    if kind in WALKERS:
        return d.cycle
    if kind == "hopper":
        return d.hop_cycle
    if kind == "flyer" and d.flap_hz > 0.0:
        return math.ceil(d.hz / d.flap_hz)
    if kind == "swimmer" and d.undulation_hz > 0.0:
        return math.ceil(d.hz / d.undulation_hz)
    return 0


def run_ticks(data: MotionData, runs: int = 1) -> int:
    """Ticks per run: CYCLES of the slowest corner individual's period (gait and size genes stretch it),
    and at least MIN_SECONDS; refused when ``runs`` such runs exceed MAX_ENVELOPE_TICKS."""
    period = max(_period(express(data, genome)) for _, genome in corner_genomes(data))
    hz = int(data.hz)
    ticks = max(CYCLES * period, math.ceil(MIN_SECONDS * hz))
    if runs * ticks > MAX_ENVELOPE_TICKS:
        raise MotionRangeError(
            f"locomotion: one {data.type} cycle lasts {period / hz:.1f} s (at the slowest gene corner): "
            f"{runs} runs of {ticks:,} ticks, over the {MAX_ENVELOPE_TICKS:,} the motion envelope steps; "
            "lower the locomotion lengths and heights (or the scale), or raise locomotion.speed"
        )
    return ticks


def corner_genomes(data: MotionData) -> list[tuple[str, Genome]]:
    """The authored genome and every corner of the box of gait genes and size (colour genes move no
    slot); a gene whose bound is 0 stays at 0."""
    genes = data.genes
    count = len(genes.fields) if genes.jitter > 0.0 else 0
    axes = [(-1.0, 1.0)] * count + [(-1.0, 1.0) if genes.size > 0.0 else (0.0,)]
    out = [("authored", Genome(0.0, 0.0, 0.0, (0.0,) * MAX_GAIT_GENES))]
    if count or genes.size > 0.0:
        for *signs, size in itertools.product(*axes):
            words = ["genes " + "".join("+" if s > 0 else "-" for s in signs)] if signs else []
            words += [{1.0: "size +", -1.0: "size -"}[size]] if size else []
            label = " ".join(words)
            gait = (*signs, *[0.0] * (MAX_GAIT_GENES - len(signs)))
            out.append((label, Genome(0.0, 0.0, 0.0, gait, size)))
    return out


@cache
def heading_seeds() -> tuple[int, ...]:
    """Spawn seeds whose heading is nearest 0°, 90°, 180° and 270° (a seed fixes the heading): on a slope
    or a moving platform the legs work differently uphill, downhill and across."""
    seeds = []
    for k in range(HEADINGS):
        target = 2.0 * math.pi * k / HEADINGS
        seeds.append(
            min(
                range(4096),
                key=lambda s: abs((instance_yaw(s) - target + math.pi) % (2.0 * math.pi) - math.pi),
            )
        )
    return tuple(seeds)


def envelope_runs(data: MotionData) -> list[tuple[str, Motion]]:
    """Every genome corner on every support the creature can be given, at every heading where the
    support is not the same in all directions."""
    runs = []
    for (support_name, support), (genome_name, genome) in itertools.product(
        envelope_supports(data).items(), corner_genomes(data)
    ):
        seeds = heading_seeds()[:1] if support_name == "flat" else heading_seeds()
        for seed in seeds:
            motion = individual(data, support, seed, genome)
            heading = round(math.degrees(instance_yaw(seed)))
            runs.append((f"{support_name} {genome_name} heading {heading}°", motion))
    return runs


def envelope_supports(data: MotionData) -> dict[str, Support]:
    """The built-in supports for a creature that stands on one, else flat ground (never consulted)."""
    kind = data.type
    return builtin_supports() if kind in WALKERS or kind == "hopper" else {"flat": FlatGround()}


def individual(data: MotionData, support: Support, seed: int, genome: Genome | None = None) -> Motion:
    """The individual spawned from ``seed`` (its genome unless one is given) on ``support``; a swimmer
    on the analytic water."""
    water = AnalyticWater() if data.type == "swimmer" else None
    return Motion(data, support=support, water=water, genome=genome, seed=seed)


def _step_run(motion: Motion, ticks: int) -> tuple[F64, F64]:
    """One run's samples: quaternions (ticks + 1, S, 4) and translations (ticks + 1, S, 3) of the
    unit body (the individual's divided by its size), tick 0 first."""
    quats: list[float] = []
    trans: list[float] = []
    for tick in range(ticks + 1):
        if tick:
            motion.step()
        quats.extend(itertools.chain.from_iterable(motion.quats))
        trans.extend(itertools.chain.from_iterable(motion.trans))
    slots = len(motion.quats)
    q: F64 = np.asarray(quats, dtype=np.float64).reshape(ticks + 1, slots, 4)
    unit: F64 = np.asarray(trans, dtype=np.float64).reshape(ticks + 1, slots, 3) / motion.size
    return q, unit


#: In a forked worker: the runs it may step and the ticks per run (its copy of the parent's).
_FORKED: tuple[list[Motion], int] | None = None


def _adopt(motions: list[Motion], ticks: int) -> None:
    global _FORKED
    _FORKED = (motions, ticks)


def _step_forked(index: int) -> tuple[F64, F64]:
    assert _FORKED is not None
    motions, ticks = _FORKED
    return _step_run(motions[index], ticks)


def usable_cpus() -> int:
    """The CPUs this process may run on."""
    affinity = getattr(os, "sched_getaffinity", None)
    return len(affinity(0)) if affinity is not None else os.cpu_count() or 1


def envelope_workers(runs: int) -> int:
    """Processes that step the runs: ``$CREATUREGEN_WORKERS`` when it is a positive integer, else the
    usable CPUs, at most one per run. Each run is independent and stepped by the same code, so the
    samples do not depend on how many there are (the corpus runner sets its builds' share of the CPUs)."""
    wanted = os.environ.get(WORKERS_ENV, "").strip()
    count = int(wanted) if wanted.isdigit() and int(wanted) > 0 else usable_cpus()
    return max(1, min(count, runs))


def _step_runs(motions: list[Motion], ticks: int, workers: int) -> list[tuple[F64, F64]]:
    """Every run's samples in run order, stepped here or, with ``workers`` > 1 where fork is available,
    by forked worker processes (each steps its own copy of the runs; these are left unstepped)."""
    if workers <= 1 or "fork" not in multiprocessing.get_all_start_methods():
        return [_step_run(motion, ticks) for motion in motions]
    # A forked child inherits the runs as they are (nothing is pickled on the way in); the samples come
    # back pickled, bit for bit, and map keeps the run order.
    context = multiprocessing.get_context("fork")
    with context.Pool(workers, initializer=_adopt, initargs=(motions, ticks)) as pool:
        return pool.map(_step_forked, range(len(motions)), chunksize=1)


def _record(
    data: MotionData, runs: list[tuple[str, Motion]], workers: int = 1
) -> tuple[list[str], int, F64, F64, list[str]]:
    """(run labels, ticks per run, quaternions (N, S, 4), translations (N, S, 3) of the unit body,
    sample labels)."""
    ticks = run_ticks(data, len(runs))
    return _recorded(runs, ticks, _step_runs([motion for _, motion in runs], ticks, workers))


def _recorded(
    runs: list[tuple[str, Motion]], ticks: int, stepped: list[tuple[F64, F64]]
) -> tuple[list[str], int, F64, F64, list[str]]:
    """``_record``'s result from the stepped runs."""
    labels = [label for label, _ in runs]
    sample_labels = [f"{label} tick {tick}" for label in labels for tick in range(ticks + 1)]
    quats = np.concatenate([q for q, _ in stepped]) if stepped else np.zeros((0, 0, 4))
    trans = np.concatenate([t for _, t in stepped]) if stepped else np.zeros((0, 0, 3))
    return labels, ticks, quats, trans, sample_labels


def _root_frame(quats: F64, trans: F64, root: int) -> tuple[F64, F64]:
    """Every slot's transform composed with the inverse of ``root``'s: the pose modulo rigid motion."""
    inverse = quats[:, root : root + 1] * CONJUGATE
    q = quaternion_multiply(np.broadcast_to(inverse, quats.shape), quats)
    r_inv = quaternion_to_matrix(inverse)
    t = np.einsum(
        "nsij,nsj->nsi", np.broadcast_to(r_inv, (*quats.shape[:2], 3, 3)), trans - trans[:, root : root + 1]
    )
    return q, t


def _joint(
    skeleton: Skeleton, rest: F64, q: F64, t: F64, parent: int, child: int, runs: list[str]
) -> JointEnvelope:
    """Swing and twist of the child relative to its parent at every sample; the worst of each, and the
    run (``runs``: each sample's) where the larger of the two peaks."""
    rel = quaternion_multiply(q[:, parent] * CONJUGATE, q[:, child])
    rel = np.where(rel[:, 3:] < 0.0, -rel, rel)
    tangent, _, _ = joint_frame(skeleton, rest, child)
    along = rel[:, :3] @ tangent
    twist = 2.0 * np.arctan2(np.abs(along), rel[:, 3])
    turned = np.einsum("nij,j->ni", quaternion_to_matrix(rel), tangent)
    bend = np.arccos(np.clip(turned @ tangent, -1.0, 1.0))
    # The pivot carried by the child's transform and by the parent's must coincide.
    pivot = skeleton.pivot[child]
    by_child = np.einsum("nij,j->ni", quaternion_to_matrix(q[:, child]), pivot) + t[:, child]
    by_parent = np.einsum("nij,j->ni", quaternion_to_matrix(q[:, parent]), pivot) + t[:, parent]
    drift = np.linalg.norm(by_child - by_parent, axis=1)
    worst = int(np.argmax(np.maximum(bend, twist))) if bend.size else -1
    return JointEnvelope(
        child,
        float(np.degrees(bend.max())),
        float(np.degrees(twist.max())),
        float(drift.max()),
        runs[worst] if worst >= 0 else "",
    )


def _farthest(points: F64, count: int, first: int) -> list[int]:
    chosen = [first]
    gap = np.linalg.norm(points - points[first], axis=1)
    while len(chosen) < min(count, len(points)):
        nxt = int(np.argmax(gap))
        if gap[nxt] <= 0.0:
            break
        chosen.append(nxt)
        gap = np.minimum(gap, np.linalg.norm(points - points[nxt], axis=1))
    return chosen


def measure_envelope(
    data: MotionData, rest: F64, skeleton: Skeleton, runs: list[tuple[str, Motion]] | None = None
) -> PoseEnvelope:
    """Step every run (by default :func:`envelope_runs`, stepped by :func:`envelope_workers` processes),
    measure every joint and slot, and pick the whole-body sweep poses. Runs passed in are stepped here."""
    if runs is None:
        runs = envelope_runs(data)
        workers = envelope_workers(len(runs))
    else:
        workers = 1
    return _summarise(data, rest, skeleton, *_record(data, runs, workers))


def _summarise(
    data: MotionData,
    rest: F64,
    skeleton: Skeleton,
    labels: list[str],
    ticks: int,
    quats: F64,
    trans: F64,
    sample_labels: list[str],
) -> PoseEnvelope:
    """The envelope of the recorded runs: every joint and slot measured, the sweep poses picked."""
    root = int(data.roots[0])
    q, t = _root_frame(quats, trans, root)
    runs = [label.rsplit(" tick ", 1)[0] for label in sample_labels]
    joints = tuple(_joint(skeleton, rest, q, t, p, c, runs) for p, c in skeleton.joints)
    rot = quaternion_to_matrix(q)
    ends = []
    for end in (col.A, col.B):
        posed = np.einsum("nsij,sj->nsi", rot, rest[:, end]) + t
        ends.append(posed - rest[:, end])
    moved = np.concatenate(ends, axis=2)  # (N, S, 6)
    displacement = np.maximum(np.linalg.norm(ends[0], axis=2), np.linalg.norm(ends[1], axis=2)).max(axis=0)
    flat = moved.reshape(len(moved), -1)
    picked = _farthest(flat, SWEEP_POSES, int(np.argmax(np.linalg.norm(flat, axis=1))))
    poses = tuple(Pose(rot[n], t[n]) for n in picked)
    return PoseEnvelope(
        tuple(labels),
        ticks,
        len(q),
        joints,
        displacement,
        poses,
        tuple(sample_labels[n] for n in picked),
    )


def _to_json(env: PoseEnvelope) -> str:
    return json.dumps(
        {
            "runs": env.runs,
            "ticks": env.ticks,
            "samples": env.samples,
            "joints": [[j.child, j.bend_deg, j.twist_deg, j.pivot_drift, j.worst_run] for j in env.joints],
            "slotDisplacement": env.slot_displacement.tolist(),
            "poses": [[p.rotations.tolist(), p.translations.tolist()] for p in env.poses],
            "labels": env.pose_labels,
        }
    )


def _from_json(text: str) -> PoseEnvelope:
    raw = json.loads(text)
    return PoseEnvelope(
        tuple(raw["runs"]),
        int(raw["ticks"]),
        int(raw["samples"]),
        tuple(JointEnvelope(int(c), b, t, d, w) for c, b, t, d, w in raw["joints"]),
        np.asarray(raw["slotDisplacement"], dtype=np.float64),
        tuple(
            Pose(np.asarray(r, dtype=np.float64), np.asarray(t, dtype=np.float64)) for r, t in raw["poses"]
        ),
        tuple(raw["labels"]),
    )


def pose_envelope(creature: CompiledCreature) -> PoseEnvelope:
    """The envelope of the creature's motion. Stepping every run takes seconds, so it is kept on disk beside
    the surface cache, keyed by the motion data, the rest slots and the code of this stage (floats
    round-trip exactly). The surface build hands the envelope it measured to the candidate stage; no
    module keeps one in memory."""
    with start_pose_envelope(creature) as pending:
        return pending.result()


class PendingEnvelope:
    """An envelope being measured by forked workers while the caller does other work (the surface stage
    samples and extracts the mesh meanwhile: on two cores its single-threaded numpy leaves one idle).
    ``result()`` waits for it; leaving the ``with`` block without asking stops the workers."""

    def __init__(
        self,
        key: str,
        ready: PoseEnvelope | None,
        measure: tuple[MotionData, F64, Skeleton] | None = None,
    ) -> None:
        self._key, self._ready, self._measure = key, ready, measure
        self._pool: Any = None
        self._stepping: Any = None
        self._runs: list[tuple[str, Motion]] = []
        self._ticks = 0
        if ready is None and measure is not None:
            data = measure[0]
            runs = envelope_runs(data)
            workers = envelope_workers(len(runs))
            self._ticks = run_ticks(data, len(runs))
            self._runs = runs
            if workers > 1 and "fork" in multiprocessing.get_all_start_methods():
                motions = [motion for _, motion in runs]
                context = multiprocessing.get_context("fork")
                self._pool = context.Pool(workers, initializer=_adopt, initargs=(motions, self._ticks))
                self._stepping = self._pool.map_async(_step_forked, range(len(runs)), chunksize=1)
                self._pool.close()

    def __enter__(self) -> PendingEnvelope:
        return self

    def __exit__(self, *_: object) -> None:
        if self._pool is not None:
            self._pool.terminate()
            self._pool.join()
            self._pool = None

    def result(self) -> PoseEnvelope:
        """The envelope (waiting for the workers, or stepping here when none were started)."""
        if self._ready is None:
            assert self._measure is not None
            data, rest, skeleton = self._measure
            if self._stepping is not None:
                stepped = self._stepping.get()
                self._pool.join()
                self._pool = None
            else:
                stepped = [_step_run(motion, self._ticks) for _, motion in self._runs]
            envelope = _summarise(data, rest, skeleton, *_recorded(self._runs, self._ticks, stepped))
            path = default_cache_root() / "envelope" / f"{self._key}.json"
            path.parent.mkdir(parents=True, exist_ok=True)
            staging = path.with_suffix(f".{os.getpid()}.tmp")
            staging.write_text(_to_json(envelope))
            staging.replace(path)
            self._ready = envelope
        return self._ready


def start_pose_envelope(creature: CompiledCreature) -> PendingEnvelope:
    """``pose_envelope`` started: from memory or disk when there, else its runs stepping in forked workers
    (where fork and more than one CPU are available) until ``result()`` is asked. It must be started
    before anything starts a GPU device's threads (forking after that is unsafe)."""
    rig, skeleton, data = creature.rig, creature.skeleton, creature.motion
    key = hashlib.sha256(
        json.dumps(data.to_json(), sort_keys=True).encode()
        + rig.slots.tobytes()
        + stage_digest("creaturegen.motion.envelope").encode()
    ).hexdigest()
    path = default_cache_root() / "envelope" / f"{key}.json"
    if path.is_file():
        return PendingEnvelope(key, _from_json(path.read_text()))
    return PendingEnvelope(key, None, (data, rig.slots, skeleton))
