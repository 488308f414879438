"""``build_many``: every spec at every tier asked for, on an engine (engines.py), each outcome recorded.

One failing spec never stops the batch: a refusal or an invalid spec is a record like a package. A task
whose process died of a signal (a killed worker) is run again, up to ``attempts`` times in all, then
recorded as ``lost`` with what it printed. The index (``OUT/index.json``) and the gallery
(``OUT/index.html``) are written at the end from every record, the ones skipped included.
"""

from __future__ import annotations

import json
import queue
import shutil
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import __version__
from ..candidates import TIERS
from ..motion.envelope import usable_cpus
from .engines import DaskEngine, Engine, LocalEngine, TaskFuture
from .gallery import write_gallery
from .pictures import draw_pictures
from .progress import Progress
from .results import compiler_digest, job_key, load_record, next_step, package_folder, save_record, summary
from .specs import BatchSpec, load_batch, spec_files
from .task import (
    DEFAULT_TIMEOUT_S,
    LOST,
    BuildTask,
    ParityTask,
    TaskResult,
    pack,
    place,
    run_build,
    run_parity,
    unpack,
)

#: The tier name of a frost effect's one job (frost effects have no surface tiers).
EFFECT = "effect"


@dataclass(frozen=True)
class BatchOptions:
    tiers: tuple[str, ...] = tuple(TIERS)
    parity: bool = False
    jobs: int = 0  # local build slots; 0: the usable CPUs
    parity_jobs: int = 1
    scheduler: str | None = None  # a Dask scheduler address; None: the local pool
    transfer: str = "auto"  # "shared" (workers write OUT) or "bytes" (packages come back); auto by engine
    cache: str | None = None  # surface cache folder, task.PRIVATE_CACHE (cold builds), None: default
    posed_gates: str = "report"
    timeout: float = DEFAULT_TIMEOUT_S
    attempts: int = 3
    pictures: bool = True
    quiet: bool = False


@dataclass
class _Job:
    spec: BatchSpec
    tier: str
    key: str
    record: dict[str, Any] | None = None
    attempts: int = 0
    skipped: bool = False
    parity_only: bool = False


def _jobs(specs: list[BatchSpec], options: BatchOptions) -> list[_Job]:
    build_options = {"posedGates": options.posed_gates}
    out = []
    for spec in specs:
        for tier in options.tiers if spec.kind != "frost" else (EFFECT,):
            out.append(_Job(spec, tier, job_key(spec.id, spec.data, tier, build_options)))
    return out


def _record(job: _Job, status: str, code: int, message: str) -> dict[str, Any]:
    """A record the client writes itself (no task ran to the end)."""
    return {
        "spec": Path(job.spec.path).name,
        "id": job.spec.id,
        "tier": job.tier,
        "status": status,
        "exitCode": code,
        "seconds": 0.0,
        "message": message,
        "parts": [],
    }


def _invalid(job: _Job) -> dict[str, Any]:
    """The record of a spec the gate refused (on the client: once, not once per worker)."""
    record = _record(job, "invalid", 2, job.spec.errors[0] if job.spec.errors else "")
    record["errors"] = list(job.spec.errors[:20])
    return record


class _Batch:
    """The state of one run: its engine, the jobs, what is in flight (a queue of finished futures)."""

    def __init__(self, out: Path, options: BatchOptions, engine: Engine) -> None:
        self.out, self.options, self.engine = out, options, engine
        auto_bytes = options.transfer == "auto" and options.scheduler is not None
        self.shared = not (options.transfer == "bytes" or auto_bytes)
        self.finished: queue.Queue[tuple[str, _Job, TaskFuture]] = queue.Queue()
        self.in_flight = 0
        jobs = max(1, engine.workers())
        self.envelope_workers = max(1, usable_cpus() // jobs) if engine.name == "local" else 1
        self.progress: Progress | None = None

    def _submit(self, stage: str, job: _Job, task: BuildTask | ParityTask) -> None:
        job.attempts += 1
        key = f"{stage}-{job.key}-{job.attempts}"
        if isinstance(task, BuildTask):
            future = self.engine.submit(run_build, task, key=key)
        else:
            future = self.engine.submit(run_parity, task, key=key, chromium=True)
        self.in_flight += 1
        future.add_done_callback(lambda f: self.finished.put((stage, job, f)))

    def build(self, job: _Job) -> None:
        dest = package_folder(self.out, job.spec.id, job.tier)
        task = BuildTask(
            key=job.key,
            spec_id=job.spec.id,
            spec_file=Path(job.spec.path).name,
            data=job.spec.data,
            tier=None if job.tier == EFFECT else job.tier,
            dest=str(dest.resolve()) if self.shared else None,
            work=str((self.out / ".work").resolve()) if self.shared else None,
            cache=self.options.cache,
            envelope_workers=self.envelope_workers,
            posed_gates=self.options.posed_gates,
            timeout=self.options.timeout,
        )
        self._submit("build", job, task)

    def parity(self, job: _Job) -> None:
        """Runs only for a job whose package landed, in this run or an earlier one (its record says where)."""
        assert job.record is not None
        folder = self.out / job.record["package"]
        task = ParityTask(
            key=job.key,
            spec_id=job.spec.id,
            tier=job.tier,
            package=str(folder.resolve()) if self.shared else None,
            payload=None if self.shared else pack(folder),
            timeout=self.options.timeout,
        )
        self._submit("parity", job, task)

    def _result(self, job: _Job, future: TaskFuture) -> TaskResult | None:
        """The task's result, or None when the engine lost it (a worker died too often)."""
        try:
            result: TaskResult = future.result()
        except Exception as exc:
            print(f"  {job.spec.id} {job.tier}: {type(exc).__name__}: {exc}", file=sys.stderr)
            return None
        return result

    def _land(self, job: _Job, result: TaskResult) -> dict[str, Any]:
        """A build's record, its package in OUT (unpacked when it came back as bytes)."""
        record = dict(result.record)
        if record["status"] == "built":
            folder = package_folder(self.out, job.spec.id, job.tier)
            if result.payload is not None:
                staging = self.out / ".work" / f"{job.key}-unpack"
                shutil.rmtree(staging, ignore_errors=True)
                unpack(result.payload, staging)
                place(staging, folder)
            record["package"] = str(folder.relative_to(self.out))
        return record

    def _retried(self, job: _Job, result: TaskResult | None, again: Callable[[_Job], None]) -> bool:
        """Run a lost task again while it has attempts left (True when it was resubmitted)."""
        lost = result is None or result.record["status"] == LOST
        if lost and job.attempts < self.options.attempts:
            again(job)
            return True
        return False

    def on_build(self, job: _Job, future: TaskFuture) -> bool:
        """True when the job is over (False: it was resubmitted or went on to parity)."""
        result = self._result(job, future)
        if self._retried(job, result, self.build):
            return False
        if result is None:
            job.record = _record(job, LOST, -1, f"the worker was lost {job.attempts} times")
            return True
        job.record = self._land(job, result)
        job.record["attempts"] = job.attempts
        if job.record["status"] == "built" and self.options.parity:
            job.attempts = 0
            self.parity(job)
            return False
        return True

    def on_parity(self, job: _Job, future: TaskFuture) -> bool:
        assert job.record is not None
        result = self._result(job, future)
        if self._retried(job, result, self.parity):
            return False
        if result is None:
            job.record["parity"] = {"status": LOST, "message": f"lost {job.attempts} times"}
            return True
        job.record["parity"] = dict(result.record)
        if result.payload is not None:
            target = self.out / job.record["package"] / "parity"
            shutil.rmtree(target, ignore_errors=True)
            unpack(result.payload, target)
        return True

    def finish(self, job: _Job) -> None:
        assert job.record is not None
        save_record(self.out / "results", job.key, job.record)
        if self.progress is not None:
            record = job.record
            what = record["status"] + (f" ({record['gate']})" if record.get("gate") else "")
            if "parity" in record:
                what += f", parity {record['parity']['status']}"
            self.progress.finished(
                record, f"{job.spec.id} {job.tier}: {what} {record.get('seconds', 0):.1f} s"
            )

    def drain(self) -> None:
        """Wait for every task in flight (and the ones they start) to end."""
        while self.in_flight:
            stage, job, future = self.finished.get()
            self.in_flight -= 1
            over = self.on_build(job, future) if stage == "build" else self.on_parity(job, future)
            if over:
                self.finish(job)


def make_engine(options: BatchOptions) -> Engine:
    if options.scheduler:
        return DaskEngine(options.scheduler)
    return LocalEngine(options.jobs or usable_cpus(), options.parity_jobs)


def _plan(out: Path, jobs: list[_Job], options: BatchOptions) -> list[_Job]:
    """The jobs to run: the others take their records from OUT/results (done) or the client (invalid)."""
    todo = []
    for job in jobs:
        if job.spec.kind == "invalid":
            job.record = _invalid(job)
            continue
        record = load_record(out / "results", job.key)
        step = next_step(record, out, options.parity)
        if step == "done":
            job.record, job.skipped = record, True
        else:
            job.record, job.parity_only = (record, True) if step == "parity" else (None, False)
            todo.append(job)
    return todo


def _run_stats(jobs: list[_Job], batch: _Batch, wall: float) -> dict[str, Any]:
    engine, options = batch.engine, batch.options
    transfer = "shared" if batch.shared else "bytes"
    ran = [j for j in jobs if not j.skipped and j.spec.kind != "invalid"]
    records = [j.record for j in ran if j.record is not None]
    built = [r for r in records if r.get("status") == "built"]
    cached = sum(1 for r in built if r.get("surfaceCached"))
    parity = [r["parity"] for r in records if r.get("parity")]
    return {
        "engine": engine.name,
        "scheduler": options.scheduler,
        "workers": engine.workers(),
        "transfer": transfer,
        "jobs": len(jobs),
        "skipped": sum(1 for j in jobs if j.skipped),
        "ran": len(ran),
        "retried": sum(1 for r in records if r.get("attempts", 1) > 1),
        "wallSeconds": round(wall, 3),
        "buildSeconds": round(sum(r.get("seconds", 0.0) for r in records), 3),
        "paritySeconds": round(sum(p.get("seconds", 0.0) for p in parity), 3),
        "jobsPerMinute": round(60.0 * len(ran) / wall, 3) if wall > 0 and ran else 0.0,
        "surfaceCacheHits": cached,
        "surfaceCacheHitRate": round(cached / len(built), 4) if built else 0.0,
    }


def build_many(paths: Sequence[str], out: Path, options: BatchOptions) -> dict[str, Any]:
    """Build every spec under ``paths`` into ``out`` and write ``out/index.json`` and ``out/index.html``."""
    specs = load_batch(spec_files(paths, exclude=out))
    jobs = _jobs(specs, options)
    todo = _plan(out, jobs, options)
    engine = make_engine(options)  # before anything is written: a bad path or scheduler writes nothing
    out.mkdir(parents=True, exist_ok=True)
    batch = _Batch(out, options, engine)

    def say(text: str) -> None:
        if not options.quiet:
            print(text, flush=True)

    invalid = [s for s in specs if s.kind == "invalid"]
    say(
        f"==> build-many: {len(specs)} specs ({len(invalid)} invalid), {len(jobs)} jobs "
        f"({sum(j.skipped for j in jobs)} done before), {engine.workers()} {engine.name} workers"
    )
    for spec in invalid:
        say(f"  invalid: {spec.errors[0] if spec.errors else spec.path}")
    batch.progress = None if options.quiet else Progress(len(jobs), len(jobs) - len(todo))
    started = time.perf_counter()
    try:
        for job in todo:
            if job.parity_only:
                batch.parity(job)
            else:
                batch.build(job)
        batch.drain()
    finally:
        if batch.progress is not None:
            batch.progress.close()
        stats = _run_stats(jobs, batch, time.perf_counter() - started)
        engine.close()
        shutil.rmtree(out / ".work", ignore_errors=True)
    return write_index(out, specs, jobs, options, stats)


def write_index(
    out: Path, specs: list[BatchSpec], jobs: list[_Job], options: BatchOptions, stats: dict[str, Any]
) -> dict[str, Any]:
    records = []
    for job in jobs:
        if job.record is not None:
            job.record["skipped"] = job.skipped
            records.append(job.record)
    pictures = draw_pictures(out, specs, records) if options.pictures else {}
    tiers = [*options.tiers, EFFECT] if any(s.kind == "frost" for s in specs) else list(options.tiers)
    index = {
        "creaturegen": __version__,
        "compilerDigest": compiler_digest(),
        "tiers": tiers,
        "parity": options.parity,
        "run": stats,
        "summary": summary(records, tiers),
        "specs": {
            s.id: {"name": s.name, "file": s.path, "kind": s.kind, "picture": pictures.get(s.id), **s.info}
            for s in specs
        },
        "results": records,
    }
    (out / "index.json").write_text(json.dumps(index, indent=1, sort_keys=True), encoding="utf-8")
    write_gallery(out, index)
    return index
