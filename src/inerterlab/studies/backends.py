"""Execution backends for sweeps: serial, local processes and Dask distributed.

Every backend meets one contract: :meth:`Backend.run` takes a picklable module-level
function and an iterable of picklable tasks and yields ``(task, result)`` pairs as the
tasks finish, in any order. A backend never evaluates a task twice and never drops one;
if a task raises, the exception propagates out of :meth:`run` (point-level failures are
caught inside the task, so this only happens for infrastructure errors). The number of
tasks in flight is bounded so memory stays flat and an interrupt loses little work.
Backends are context managers; leaving the ``with`` block releases workers.
"""

from __future__ import annotations

import abc
import functools
import multiprocessing
import os
import time
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from typing import Any

from ..errors import InerterlabError, ParameterError

__all__ = ["Backend", "SerialBackend", "ProcessBackend", "DaskBackend", "make_backend", "BACKENDS"]

BACKENDS = ("serial", "processes", "dask")


def _noop() -> None:
    return None


class Backend(abc.ABC):
    """Base class: runs tasks and yields ``(task, result)`` as they complete."""

    name = "base"
    workers = 1

    def __enter__(self) -> Backend:
        self.start()
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close(cancel=exc[0] is not None)

    def start(self) -> None:
        """Acquire workers (called by ``__enter__``); nothing to do by default."""
        return None

    def close(self, cancel: bool = False) -> None:
        """Release workers; ``cancel`` drops queued tasks (after an interrupt)."""
        return None

    @abc.abstractmethod
    def run(self, fn: Callable[[Any], Any], tasks: Iterable[Any]) -> Iterator[tuple[Any, Any]]:
        """Evaluate ``fn(task)`` for every task; yield ``(task, result)`` as each finishes."""

    def describe(self) -> str:
        return f"{self.name} ({self.workers} worker{'s' if self.workers != 1 else ''})"


class SerialBackend(Backend):
    """Runs every task in this process, in order. The reference for the others."""

    name = "serial"

    def run(self, fn, tasks):
        for task in tasks:
            yield task, fn(task)


def _windowed(submit, tasks: Iterable[Any], window: int, wait_any):
    """Keep at most ``window`` futures in flight; yield (task, future) as they finish."""
    it = iter(tasks)
    pending: dict[Any, Any] = {}
    for task in it:
        pending[submit(task)] = task
        if len(pending) >= window:
            break
    while pending:
        for fut in wait_any(list(pending)):
            task = pending.pop(fut)
            nxt = next(it, None)
            if nxt is not None:
                pending[submit(nxt)] = nxt
            yield task, fut


def max_workers() -> int:
    """Most local workers a run may start: 8 per CPU, at least 32."""
    return max(32, 8 * (os.cpu_count() or 1))


def check_workers(name: str, workers) -> int:
    """``workers`` as an int in [1, :func:`max_workers`] or a ParameterError naming ``name``.

    Every local worker is a process started at once; an absurd count would exhaust the
    machine's process table before anything else could refuse it.
    """
    cap = max_workers()
    valid = f"an integer in [1, {cap}] (8 per CPU of this machine, at least 32)"
    if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= cap:
        raise ParameterError(name, workers, valid)
    return workers


def _die_with_parent(parent: int) -> None:
    """Make this worker end when the process that started it ends (even by SIGKILL).

    On Linux the kernel sends SIGKILL when the parent dies (``PR_SET_PDEATHSIG``);
    elsewhere a daemon thread notices that the parent is gone and exits.
    """
    import signal
    import threading

    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        pr_set_pdeathsig = 1
        ok = libc.prctl(pr_set_pdeathsig, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):
        ok = False
    if os.getppid() != parent:  # the parent died before the request took effect
        os._exit(1)
    if ok:
        return

    def watch() -> None:  # pragma: no cover - systems without prctl
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, daemon=True, name="inerterlab-parent-watch").start()


def _worker_start(parent: int, initializer: Callable | None) -> None:
    _die_with_parent(parent)
    if initializer is not None:
        initializer()


class ProcessBackend(Backend):
    """Local worker processes (``concurrent.futures.ProcessPoolExecutor``).

    Workers are started once and reused for every task; on Linux they are forked from
    the calling process, so compiled kernels and imported modules are inherited.

    Parameters
    ----------
    workers : int, optional
        Number of processes (default: the number of CPUs).
    initializer : callable, optional
        Module-level function run once in each worker (e.g. to compile kernels).
    """

    name = "processes"

    def __init__(self, workers: int | None = None, *, initializer: Callable | None = None):
        n = (os.cpu_count() or 1) if workers is None else workers
        self.workers = check_workers("workers", n)
        self.initializer = initializer
        self._pool: ProcessPoolExecutor | None = None

    def start(self) -> None:
        methods = multiprocessing.get_all_start_methods()
        ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
        self._pool = ProcessPoolExecutor(
            max_workers=self.workers,
            mp_context=ctx,
            initializer=functools.partial(_worker_start, os.getpid(), self.initializer),
        )
        # start every worker now (before any progress-bar thread exists in this process)
        for f in [self._pool.submit(_noop) for _ in range(self.workers)]:
            f.result()

    def close(self, cancel: bool = False) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=not cancel, cancel_futures=True)
            self._pool = None

    def run(self, fn, tasks):
        if self._pool is None:
            self.start()
        pool = self._pool

        def wait_any(futs):
            done, _ = wait(futs, return_when=FIRST_COMPLETED)
            return done

        for task, fut in _windowed(lambda t: pool.submit(fn, t), tasks, 3 * self.workers, wait_any):
            yield task, fut.result()


class WorkersLost(InerterlabError):
    """A distributed run lost all its workers and cannot go on."""


class DaskBackend(Backend):
    """Dask distributed: an existing cluster (``scheduler``) or a local one (``workers``).

    Parameters
    ----------
    scheduler : str, optional
        Address of a running scheduler, e.g. ``tcp://10.0.0.5:8786``.
    workers : int, optional
        Start a ``LocalCluster`` on 127.0.0.1 with this many single-threaded workers.
    processes : bool
        Local cluster with worker processes (True) or threads in this process (False).
    """

    name = "dask"
    #: seconds without any worker after which a run stops with a message
    no_worker_timeout = 60.0

    def __init__(
        self, scheduler: str | None = None, workers: int | None = None, *, processes: bool = True
    ):
        if scheduler is not None and workers is not None:
            raise ParameterError(
                "workers", workers, "no value when --scheduler is given (the cluster has its own)"
            )
        if workers is not None:
            check_workers("workers", workers)
        self.scheduler = scheduler
        self.workers = workers or 0
        self.processes = processes
        self._client = None
        self._cluster = None

    def start(self) -> None:
        from distributed import Client, LocalCluster

        if self.scheduler is not None:
            try:
                self._client = Client(self.scheduler, timeout="10s")
            except (OSError, TimeoutError, ValueError, TypeError) as exc:
                raise ParameterError(
                    "scheduler", self.scheduler, f"the address of a running Dask scheduler ({exc})"
                ) from None
            self.workers = max(1, len(self._client.scheduler_info().get("workers", {})))
        else:
            self.workers = self.workers or min(os.cpu_count() or 1, max_workers())
            self._cluster = LocalCluster(
                n_workers=self.workers,
                threads_per_worker=1,
                processes=self.processes,
                host="127.0.0.1",
                protocol="tcp",  # loopback TCP also for threads (inproc rejects a host)
                dashboard_address=":0",
                silence_logs=40,
            )
            self._client = Client(self._cluster)

    def close(self, cancel: bool = False) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None
        if self._cluster is not None:
            self._cluster.close()
            self._cluster = None

    def run(self, fn, tasks):
        from distributed import wait as dwait

        if self._client is None:
            self.start()
        client = self._client

        def wait_any(futs):
            # wait in short slices; if the cluster has had no worker for a while, the
            # futures would wait forever: stop with a message instead (finished points
            # are already in the store)
            gone_since = None
            while True:
                try:
                    return dwait(futs, timeout=2.0, return_when="FIRST_COMPLETED").done
                except TimeoutError:
                    pass
                try:
                    alive = len(client.scheduler_info().get("workers", {}))
                except Exception:  # noqa: BLE001 - the scheduler itself is gone
                    alive = 0
                if alive:
                    gone_since = None
                    continue
                gone_since = gone_since or time.monotonic()
                if time.monotonic() - gone_since > self.no_worker_timeout:
                    raise WorkersLost(
                        f"every Dask worker has been gone for {self.no_worker_timeout:g} s; "
                        "the sweep stopped (finished points are kept in the store: rerun to "
                        "resume once workers are back)"
                    )

        def submit(task):
            return client.submit(fn, task, pure=False)

        for task, fut in _windowed(submit, tasks, 3 * max(1, self.workers), wait_any):
            yield task, fut.result()
            fut.release()

    def describe(self) -> str:
        where = self.scheduler or "local cluster on 127.0.0.1"
        return f"dask ({where}, {self.workers} workers)"


def make_backend(
    backend: str | Backend | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    initializer: Callable | None = None,
) -> Backend:
    """A backend from a name: ``serial``, ``processes`` (default) or ``dask``.

    ``scheduler`` implies ``dask``. ``workers`` is the number of local workers.
    """
    if isinstance(backend, Backend):
        return backend
    if backend is None:
        backend = "dask" if scheduler is not None else "processes"
    if backend not in BACKENDS:
        raise ParameterError("backend", backend, "one of " + ", ".join(map(repr, BACKENDS)))
    if scheduler is not None and backend != "dask":
        raise ParameterError("backend", backend, "'dask' when a scheduler address is given")
    if backend == "serial":
        return SerialBackend()
    if backend == "processes":
        return ProcessBackend(workers, initializer=initializer)
    return DaskBackend(scheduler, workers)
