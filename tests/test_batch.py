"""``creaturegen build-many`` (issue 28): a batch on the local pool and on a Dask cluster of two workers,
every spec accounted for when a worker is killed mid-batch, a rerun that skips what is done, and the
gallery in Chromium (the corpus's gallery is opened in test_corpus.py)."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import psutil
import pytest

from conftest import REPO, gallery_shows_every_card
from creaturegen.batch.results import job_key, next_step
from creaturegen.batch.specs import BatchInputError, load_batch, spec_files
from creaturegen.batch.task import pack, unpack

HOPPER = REPO / "examples" / "reference" / "hopper.json"
FROST = REPO / "examples" / "frost" / "frost-budgeted.json"


def _specs(folder: Path) -> Path:
    """hopper.json, a copy of it under another file name (same name inside: its own package), a frost
    effect and an invalid creature."""
    folder.mkdir(parents=True)
    shutil.copy(HOPPER, folder / "hopper.json")
    shutil.copy(HOPPER, folder / "hopper-again.json")
    shutil.copy(FROST, folder / "frost.json")
    (folder / "broken.json").write_text('{"name": "Broken", "parts": [{"id": "body", "shape": "sphere"}]}')
    return folder


def _build_many(*args: str) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-m", "creaturegen.cli", "build-many", *args]
    return subprocess.run(command, capture_output=True, text=True, check=False, timeout=600)


def _index(out: Path) -> dict[str, object]:
    index = json.loads((out / "index.json").read_text())
    assert isinstance(index, dict)
    return index


def test_specs_get_unique_ids_and_folders_are_searched(tmp_path: Path) -> None:
    folder = _specs(tmp_path / "specs")
    (folder / ".hidden").mkdir()
    shutil.copy(HOPPER, folder / ".hidden" / "skipped.json")
    specs = load_batch(spec_files([str(folder), str(folder / "frost.json")]))
    assert [s.id for s in specs] == [
        "broken",
        "frost-pane-budgeted",
        "hopper-squash-core",
        "hopper-squash-core-2",
    ]
    assert [s.kind for s in specs] == ["invalid", "frost", "creature", "creature"]
    assert "part.body" in specs[0].errors[0]
    keys = {job_key(s.id, s.data, "hero", {}) for s in specs}
    assert len(keys) == 4, "two copies of one spec are two jobs (two packages), not one"
    with pytest.raises(BatchInputError, match="no such file"):
        spec_files([str(tmp_path / "missing")])
    (tmp_path / "empty").mkdir()
    with pytest.raises(BatchInputError, match=r"no \.json"):
        spec_files([str(tmp_path / "empty")])


def test_a_path_that_is_not_there_is_one_line_exit_2_and_nothing_written(tmp_path: Path) -> None:
    done = _build_many(str(tmp_path / "missing"), "-o", str(tmp_path / "out"))
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        f"creaturegen build-many: {tmp_path / 'missing'}: no such file or folder"
    ]
    assert not (tmp_path / "out").exists()


def test_packages_travel_as_bytes_and_stay_inside_their_folder(tmp_path: Path) -> None:
    source = tmp_path / "a"
    (source / "core").mkdir(parents=True)
    (source / "core" / "x.js").write_text("export {};\n")
    unpack(pack(source), tmp_path / "b")
    assert (tmp_path / "b" / "core" / "x.js").read_text() == "export {};\n"
    assert pack(source) == pack(source), "the same folder packs to the same bytes"


def test_a_record_stands_only_while_its_package_does(tmp_path: Path) -> None:
    assert next_step(None, tmp_path, False) == "build"
    assert next_step({"status": "refused"}, tmp_path, True) == "done"
    assert next_step({"status": "lost"}, tmp_path, False) == "build"
    assert next_step({"status": "built", "package": "packages/x.hero"}, tmp_path, False) == "build"


@pytest.mark.browser
def test_a_local_batch_records_every_outcome_and_a_rerun_skips_it(tmp_path: Path) -> None:
    specs, out = _specs(tmp_path / "specs"), tmp_path / "out"
    first = _build_many(str(specs), "-o", str(out), "--tiers", "hero", "--jobs", "2")
    assert first.returncode == 0, first.stdout[-3000:] + first.stderr[-3000:]
    index = _index(out)
    outcome = {(r["id"], r["tier"]): r for r in index["results"]}  # type: ignore[attr-defined]
    assert {k: r["status"] for k, r in outcome.items()} == {
        ("broken", "hero"): "invalid",
        ("frost-pane-budgeted", "effect"): "built",
        ("hopper-squash-core", "hero"): "built",
        ("hopper-squash-core-2", "hero"): "built",
    }
    assert "part.body.r" in outcome[("broken", "hero")]["message"]
    assert sorted(p.name for p in (out / "packages").iterdir()) == [
        "frost-pane-budgeted.effect",
        "hopper-squash-core-2.hero",
        "hopper-squash-core.hero",
    ]
    hopper = outcome[("hopper-squash-core", "hero")]
    assert hopper["workload"]["vertices"] > 0
    assert hopper["signatures"]["compilerSignature"]
    assert "invalid" in first.stdout
    assert "wrote" in first.stdout
    # Again: every job is done, nothing runs; then one package is removed and only it is built again.
    again = _build_many(str(specs), "-o", str(out), "--tiers", "hero")
    assert again.returncode == 0, again.stderr[-3000:]
    run = _index(out)["run"]
    assert (run["ran"], run["skipped"]) == (0, 3)  # type: ignore[index]
    shutil.rmtree(out / "packages" / "hopper-squash-core-2.hero")
    third = _build_many(str(specs), "-o", str(out), "--tiers", "hero")
    assert third.returncode == 0, third.stderr[-3000:]
    run = _index(out)["run"]
    assert (run["ran"], run["skipped"], run["surfaceCacheHits"]) == (1, 2, 1)  # type: ignore[index]
    gallery_shows_every_card(out / "index.html", 4, invalid=1)


def _build_children(parent: psutil.Process) -> list[psutil.Process]:
    found = []
    for child in parent.children(recursive=True):
        try:
            if "creaturegen.cli" in child.cmdline() and "build" in child.cmdline():
                found.append(child)
        except psutil.NoSuchProcess:
            continue
    return found


def _kill_first_build(parent: psutil.Process, deadline_s: float = 120.0) -> None:
    """SIGKILL the first build process that ``parent`` starts (a worker dying mid-task)."""
    deadline = time.monotonic() + deadline_s
    while time.monotonic() < deadline:
        children = _build_children(parent)
        if children:
            time.sleep(0.5)  # well inside the build, not at its start
            children[0].send_signal(signal.SIGKILL)
            return
        time.sleep(0.05)
    raise AssertionError("no build process started")


def test_a_worker_killed_mid_batch_is_run_again_and_every_spec_is_accounted_for(tmp_path: Path) -> None:
    specs, out = _specs(tmp_path / "specs"), tmp_path / "out"
    command = [sys.executable, "-m", "creaturegen.cli", "build-many", str(specs), "-o", str(out)]
    command += ["--tiers", "hero", "--jobs", "1", "--no-pictures"]
    batch = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        _kill_first_build(psutil.Process(batch.pid))
        stdout, stderr = batch.communicate(timeout=600)
    finally:
        if batch.poll() is None:
            batch.kill()
    assert batch.returncode == 0, stdout[-3000:] + stderr[-3000:]
    results = _index(out)["results"]
    assert len(results) == 4  # type: ignore[arg-type]
    assert {r["status"] for r in results} == {"built", "invalid"}  # type: ignore[union-attr]
    assert max(r.get("attempts", 1) for r in results) == 2  # type: ignore[union-attr]


@pytest.fixture
def cluster() -> Iterator[tuple[str, dict[str, int]]]:
    """A Dask cluster of two worker processes, one thread each; only worker "chromium" declares the
    resource parity tasks ask for. Yields the scheduler address and {worker name: pid}."""
    from distributed import Client, Nanny, Scheduler, SpecCluster

    workers = {
        "chromium": {"cls": Nanny, "options": {"nthreads": 1, "resources": {"chromium": 1}}},
        "plain": {"cls": Nanny, "options": {"nthreads": 1}},
    }
    spec_cluster = SpecCluster(
        workers=workers, scheduler={"cls": Scheduler, "options": {"dashboard_address": None}}, silence_logs=40
    )
    with spec_cluster, Client(spec_cluster) as client:
        client.wait_for_workers(2)
        pids = client.run(os.getpid)
        names = {w["name"]: address for address, w in client.scheduler_info()["workers"].items()}
        yield spec_cluster.scheduler_address, {name: pids[address] for name, address in names.items()}


@pytest.mark.browser
def test_a_dask_cluster_builds_runs_parity_on_the_chromium_worker_and_survives_a_kill(
    tmp_path: Path, cluster: tuple[str, dict[str, int]]
) -> None:
    address, pids = cluster
    specs = tmp_path / "specs"
    specs.mkdir()
    shutil.copy(HOPPER, specs / "hopper.json")
    shutil.copy(FROST, specs / "frost.json")
    out = tmp_path / "out"
    command = [sys.executable, "-m", "creaturegen.cli", "build-many", str(specs), "-o", str(out)]
    command += ["--tiers", "hero,distant", "--scheduler", address, "--no-pictures"]
    batch = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        # Kill a worker process while it builds: the scheduler gives its task to a worker again.
        deadline = time.monotonic() + 120
        victim = None
        while victim is None and time.monotonic() < deadline:
            for name, pid in pids.items():
                if _build_children(psutil.Process(pid)):
                    victim = name
                    break
            time.sleep(0.05)
        assert victim is not None, "no worker started a build"
        time.sleep(0.5)
        os.kill(pids[victim], signal.SIGKILL)
        killed = pids[victim]
        stdout, stderr = batch.communicate(timeout=600)
    finally:
        if batch.poll() is None:
            batch.kill()
    assert batch.returncode == 0, stdout[-3000:] + stderr[-3000:]
    assert not psutil.pid_exists(killed) or psutil.Process(killed).status() == psutil.STATUS_ZOMBIE
    index = _index(out)
    assert index["run"]["engine"] == "dask"  # type: ignore[index]
    assert index["run"]["transfer"] == "bytes"  # type: ignore[index]
    results = {(r["id"], r["tier"]): r for r in index["results"]}  # type: ignore[attr-defined]
    assert sorted(results) == [
        ("frost-pane-budgeted", "effect"),
        ("hopper-squash-core", "distant"),
        ("hopper-squash-core", "hero"),
    ]
    assert all(r["status"] == "built" for r in results.values()), results
    assert (out / "packages" / "hopper-squash-core.distant" / "build-report.json").is_file()
    # Parity of the frost package on a cluster: it may only run where Chromium is declared.
    parity = _build_many(str(specs / "frost.json"), "-o", str(out), "--parity", "--scheduler", address)
    assert parity.returncode == 0, parity.stdout[-3000:] + parity.stderr[-3000:]
    index = _index(out)
    assert (index["run"]["ran"], index["run"]["skipped"]) == (1, 0)  # type: ignore[index]
    record = index["results"][0]  # type: ignore[index]
    assert record["parity"]["status"] == "passed", record
    assert record["skipped"] is False
    assert (out / record["package"] / "parity" / "report.json").is_file()
    from distributed import Client

    with Client(address) as client:  # the workers now (a killed one was restarted with a new pid)
        now = client.run(os.getpid)
        chromium = [
            a for a, w in client.scheduler_info()["workers"].items() if w["resources"].get("chromium")
        ]
    assert int(record["parity"]["worker"].rsplit(":", 1)[1]) == now[chromium[0]]
