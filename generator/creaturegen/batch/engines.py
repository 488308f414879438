"""Where batch tasks run: a local pool on this machine, or a Dask distributed cluster.

Both take the same task functions (task.py) and give back futures (``result()``, ``add_done_callback``),
so run.py does not know which one it drives. The local pool holds ``jobs`` build slots and
``parity_jobs`` Chromium slots; each task is a process of its own (task.py), so a slot is a thread that
waits on it. On Dask a parity task asks for the worker resource ``chromium`` (start such workers with
``--resources chromium=1``); a build asks for none. A worker that dies mid-task is Dask's to recover: the
scheduler gives its tasks to another worker, up to ``distributed.scheduler.allowed-failures`` times.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any, Protocol, TypeVar

from .task import TaskResult

T = TypeVar("T")

#: The worker resource a parity task needs on a cluster.
CHROMIUM_RESOURCE = "chromium"


class TaskFuture(Protocol):
    def result(self, timeout: float | None = None) -> Any: ...

    def add_done_callback(self, fn: Callable[[Any], object]) -> None: ...


class Engine(Protocol):
    name: str

    def workers(self) -> int: ...

    def submit(
        self, fn: Callable[[T], TaskResult], task: T, *, key: str, chromium: bool = False
    ) -> TaskFuture: ...

    def close(self) -> None: ...


class LocalEngine:
    """``jobs`` builds and ``parity_jobs`` parity jobs at a time on this machine."""

    name = "local"

    def __init__(self, jobs: int, parity_jobs: int = 1) -> None:
        self.jobs = max(1, jobs)
        self._builds = ThreadPoolExecutor(self.jobs, thread_name_prefix="creaturegen-build")
        self._parity = ThreadPoolExecutor(max(1, parity_jobs), thread_name_prefix="creaturegen-parity")

    def workers(self) -> int:
        return self.jobs

    def submit(
        self, fn: Callable[[T], TaskResult], task: T, *, key: str, chromium: bool = False
    ) -> Future[TaskResult]:
        return (self._parity if chromium else self._builds).submit(fn, task)

    def close(self) -> None:
        self._builds.shutdown(wait=False, cancel_futures=True)
        self._parity.shutdown(wait=False, cancel_futures=True)


class DaskEngine:
    """A Dask distributed scheduler at ``address`` (``tcp://HOST:PORT``); its workers must have creaturegen
    installed (the tasks are its functions)."""

    name = "dask"

    def __init__(self, address: str, timeout: float = 30.0) -> None:
        try:
            from distributed import Client
        except ImportError as exc:  # the cluster extra is not installed
            raise RuntimeError(
                "--scheduler needs Dask distributed: pip install 'creaturegen[cluster]'"
            ) from exc
        self.address = address
        self._client = Client(address, timeout=timeout, set_as_default=False)  # type: ignore[no-untyped-call]

    def workers(self) -> int:
        info = self._client.scheduler_info()
        return sum(int(w.get("nthreads", 1)) for w in info.get("workers", {}).values())

    def submit(
        self, fn: Callable[[T], TaskResult], task: T, *, key: str, chromium: bool = False
    ) -> TaskFuture:
        resources = {CHROMIUM_RESOURCE: 1} if chromium else None
        future: TaskFuture = self._client.submit(fn, task, key=key, pure=False, resources=resources)
        return future

    def close(self) -> None:
        self._client.close()  # type: ignore[no-untyped-call]
