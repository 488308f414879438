"""What a batch worker runs: one ``creaturegen build`` or one ``creaturegen parity``, in a process of its
own, exactly as a user runs it (exit code, one-line refusal, nothing written on failure).

A process per task rather than a build inside the worker: a build that crashes, leaks or runs past its time
takes only its own process with it, a worker thread never shares ``sys.stdout`` with another build, and a
killed worker takes its build down too (PR_SET_PDEATHSIG on Linux) instead of leaving an orphan writing
into the output. The cost is the interpreter's start and imports, about 1.8 s a task on this machine
(README, "Batch builds").

Tasks and results are plain picklable data: a Dask worker on another machine receives the spec's bytes,
not a path, and returns the package as bytes (``dest`` None) when it shares no folder with the client.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import io
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tarfile
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: A build or parity job past this is recorded as a timeout (the slowest cold corpus build: about 140 s).
DEFAULT_TIMEOUT_S = 900.0
#: Surface cache choice meaning "a fresh empty cache for this task": every time measured is a cold build.
PRIVATE_CACHE = "private"
#: Environment a worker process may carry for itself that a build child must not inherit (child_env).
WORKER_TUNING = ("MALLOC_TRIM_THRESHOLD_",)
#: A status meaning the task's process died of a signal: its worker was killed, not the spec refused.
LOST = "lost"

_PART = re.compile(r"part\.([A-Za-z][A-Za-z0-9_-]*)")
#: cli_report.py's line for a surface that came from the surface cache.
_CACHE_HIT = re.compile(r"^  mesh \{.*\}; cache hit$", re.MULTILINE)
_GATE = re.compile(
    r"gate (?P<gate>[\w.\-]+) = (?P<value>[-+0-9.eE]+|nan|inf)\s*(?P<unit>[^,]*), threshold "
    r"(?P<threshold>[-+0-9.eE]+)"
)


@dataclass(frozen=True)
class BuildTask:
    """One spec at one tier (``tier`` None: a frost effect, which has no tiers)."""

    key: str
    spec_id: str
    spec_file: str  # the file's name: the build's messages name it as the user named it
    data: bytes
    tier: str | None
    dest: str | None  # where the package lands (shared folder); None: returned as bytes
    work: str | None = None  # staging folder on the destination's file system (an atomic rename)
    cache: str | None = None  # surface cache folder, PRIVATE_CACHE, or None for the worker's own
    envelope_workers: int = 1  # processes the build steps its motion envelope in
    posed_gates: str = "report"
    timeout: float = DEFAULT_TIMEOUT_S


@dataclass(frozen=True)
class ParityTask:
    """The parity job of one built package, on a worker that has Chromium."""

    key: str
    spec_id: str
    tier: str | None
    package: str | None  # the package folder (shared); None: ``payload`` carries it
    payload: bytes | None = None
    timeout: float = DEFAULT_TIMEOUT_S


@dataclass(frozen=True)
class TaskResult:
    record: dict[str, Any]
    payload: bytes | None = None  # the package (build) or its parity/ folder (parity), as a .tar.gz


def worker_name() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"


def _die_with_parent() -> Callable[[], None] | None:
    """A preexec hook that makes the child die when the worker does (Linux), else None."""
    if not sys.platform.startswith("linux"):
        return None
    libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)

    def hook() -> None:
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG

    return hook


def _run(command: list[str], env: dict[str, str], timeout: float) -> tuple[int, str, str, float]:
    """(exit code, stdout, stderr, seconds); a timeout is code None → -1 with a message."""
    start = time.perf_counter()
    try:
        done = subprocess.run(
            command,
            capture_output=True,
            text=True,
            env=env,
            timeout=timeout,
            check=False,
            preexec_fn=_die_with_parent(),
        )
        code, stdout, stderr = done.returncode, done.stdout, done.stderr
    except subprocess.TimeoutExpired as exc:
        code, stdout, stderr = -1000, str(exc.stdout or ""), f"timeout after {timeout:.0f} s"
    return code, stdout, stderr, time.perf_counter() - start


def _status(code: int) -> str:
    if code == -1000:
        return "timeout"
    if code < 0:
        return LOST
    return {0: "built", 2: "invalid", 3: "refused"}.get(code, "error")


def parse_refusal(stderr: str) -> dict[str, Any]:
    """The gate, value, threshold and parts a refusal message names (empty fields when it names none)."""
    lines = [
        line for line in stderr.splitlines() if line and not line.startswith(("  surface:", "error: XDG"))
    ]
    message = lines[-1] if lines else ""
    found = _GATE.search(message)
    result: dict[str, Any] = {"message": message[:2000], "parts": sorted(set(_PART.findall(message)))}
    if "no skinning method passes" in message:
        result["gate"] = "deform.sweep"
    if found:
        result["gate"] = found["gate"]
        result["value"] = float(found["value"])
        result["threshold"] = float(found["threshold"])
        result["unit"] = found["unit"].strip()
    return result


def package_figures(package: Path) -> dict[str, Any]:
    """What the index keeps of a built package's build-report.json: signatures, the workload tuple, the
    gates that failed (a creature's posed-skin gates are recorded, not enforced: surface/posed.py)."""
    report = json.loads((package / "build-report.json").read_text(encoding="utf-8"))
    creature = report.get("kind") == "creature"
    signatures = report.get("signatures") if creature else {"structureSha256": report.get("structureSha256")}
    out: dict[str, Any] = {"specSha256": report.get("specSha256", ""), "signatures": signatures}
    if creature:
        workload = report.get("workload", {})
        out["workload"] = workload
        out["vertices"], out["triangles"] = workload.get("vertices"), workload.get("triangles")
        posed = report.get("surface", {}).get("posedGates", [])
        out["posedFailed"] = [r["name"] for r in posed if not r["passed"]]
        out["posedParts"] = {
            r["name"]: sorted(set(_PART.findall(str(r.get("detail", ""))))) for r in posed if not r["passed"]
        }
    else:
        out["historyFormat"] = report.get("historyFormat", {}).get("historyFormat")
        out["memory"] = report.get("memory", {})
    return out


def pack(folder: Path) -> bytes:
    """``folder`` as a gzip tar (entries relative to it, sorted)."""
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w:gz") as archive:
        for path in sorted(folder.rglob("*")):
            archive.add(path, arcname=str(path.relative_to(folder)), recursive=False)
    return buffer.getvalue()


def unpack(payload: bytes, folder: Path) -> None:
    """A ``pack`` payload into ``folder`` (the data filter refuses links and paths that leave it)."""
    folder.mkdir(parents=True, exist_ok=True)
    with tarfile.open(fileobj=io.BytesIO(payload), mode="r:gz") as archive:
        archive.extractall(folder, filter="data")


def place(source: Path, dest: Path) -> None:
    """Move a finished folder to ``dest``, replacing what is there with two renames (a reader sees the old
    package or the new one, never half of each)."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    old = dest.with_name(f".{dest.name}.old-{os.getpid()}")
    if dest.exists():
        os.replace(dest, old)
    shutil.move(str(source), str(dest))
    shutil.rmtree(old, ignore_errors=True)


def child_env() -> dict[str, str]:
    """This process's environment for a build or parity child, without the worker's malloc tuning: Dask's
    nanny sets MALLOC_TRIM_THRESHOLD_=65536 for its workers (distributed.nanny.pre-spawn-environ), and glibc
    then hands every large numpy temporary back to the kernel; a build that inherits it ran 1.5× slower
    here (README, "Batch builds")."""
    env = {k: v for k, v in os.environ.items() if k not in WORKER_TUNING}
    env["PYTHONUNBUFFERED"] = "1"
    return env


def _build_env(task: BuildTask, work: Path) -> dict[str, str]:
    """The build's environment: the task's surface cache and envelope processes, no README picture (the
    gallery draws its own thumbnails; a Chromium per build would double a batch's time)."""
    env = {**child_env(), "CREATUREGEN_PICTURE": "off"}
    env["CREATUREGEN_WORKERS"] = str(max(1, task.envelope_workers))
    if task.cache == PRIVATE_CACHE:
        env["CREATUREGEN_CACHE"] = str(work / "cache")
    elif task.cache is not None:
        env["CREATUREGEN_CACHE"] = task.cache
    return env


def run_build(task: BuildTask) -> TaskResult:
    """Build one spec at one tier; the record says what happened, the package lands at ``task.dest`` or
    comes back as bytes."""
    if task.work is not None:
        Path(task.work).mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="creaturegen-batch-", dir=task.work) as temp:
        work = Path(temp)
        spec = work / "spec" / task.spec_file
        spec.parent.mkdir()
        spec.write_bytes(task.data)
        staging = work / "out"
        command = [sys.executable, "-m", "creaturegen.cli", "build", str(spec), "--picture", "off"]
        if task.tier is not None:
            command += ["--tier", task.tier, "--posed-gates", task.posed_gates]
        command += ["-o", str(staging)]
        code, stdout, stderr, seconds = _run(command, _build_env(task, work), task.timeout)
        status = _status(code)
        record: dict[str, Any] = {
            "spec": task.spec_file,
            "id": task.spec_id,
            "tier": task.tier or "effect",
            "status": status,
            "exitCode": code,
            "seconds": round(seconds, 3),
            "worker": worker_name(),
        }
        if status != "built":
            record.update(parse_refusal(stderr.replace(str(spec), task.spec_file)))
            if status in ("error", LOST):
                record["stderrTail"] = stderr[-3000:]
            return TaskResult(record)
        built = next(p for p in staging.iterdir() if p.is_dir())
        record.update(package_figures(built))
        record["surfaceCached"] = bool(_CACHE_HIT.search(stdout)) if task.tier is not None else False
        if task.dest is None:
            return TaskResult(record, pack(built))
        place(built, Path(task.dest))
        return TaskResult(record)


def _parity_record(task: ParityTask, package: Path, code: int, stderr: str, seconds: float) -> dict[str, Any]:
    record: dict[str, Any] = {
        "id": task.spec_id,
        "tier": task.tier or "effect",
        "exitCode": code,
        "seconds": round(seconds, 3),
        "worker": worker_name(),
    }
    report = package / "parity" / "report.json"
    if code in (0, 1) and report.is_file():
        gates = json.loads(report.read_text(encoding="utf-8")).get("gates", [])
        record["status"] = "passed" if code == 0 else "failed"
        record["gates"] = len(gates)
        record["failed"] = [g["name"] for g in gates if g.get("status") != "pass"]
    else:
        record["status"] = {-1000: "timeout"}.get(code, LOST if code < 0 else "error")
        record["message"] = (stderr.strip().splitlines() or [""])[-1][:2000]
        record["stderrTail"] = stderr[-3000:]
    return record


def run_parity(task: ParityTask) -> TaskResult:
    """The package's parity job in headless Chromium; the report lands in the package's parity/ folder
    (shared) or comes back as bytes."""
    with tempfile.TemporaryDirectory(prefix="creaturegen-parity-") as temp:
        if task.package is not None:
            package = Path(task.package)
        else:
            assert task.payload is not None, "a parity task carries its package or names it"
            package = Path(temp) / task.spec_id
            unpack(task.payload, package)
        command = [sys.executable, "-m", "creaturegen.cli", "parity", str(package)]
        code, _, stderr, seconds = _run(command, child_env(), task.timeout)
        record = _parity_record(task, package, code, stderr, seconds)
        parity = package / "parity"
        payload = pack(parity) if task.package is None and parity.is_dir() else None
        return TaskResult(record, payload)
