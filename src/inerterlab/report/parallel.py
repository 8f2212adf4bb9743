"""Parallel reproduction: independent work in worker processes.

The report's items share expensive computations through memos (a brute-force curve is
read by three tables and a figure; one identification by a table and a figure). Run
item by item in parallel, they would each redo them, so the work is cut in two kinds of
task for one pool of worker processes:

1. *pieces*: the shared computations of the items to compute (brute-force and
   harmonic-balance curves, identifications, metric grids; each chapter module's
   ``prefetch``), longest first;
2. *item groups*: a chapter's items, split into one group per worker, sent once every
   piece of that chapter is done, together with the chapter's memo entries. Chapters
   without pieces (design studies, chapter 3) are sent at once.

Every piece and item is computed by the same function with the same arguments as in a
serial run, so the numbers do not change (tests/test_reproduce_parallel.py compares
them); only the order of the work does.
"""

from __future__ import annotations

import dataclasses
import importlib
import multiprocessing
import os
import signal
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

from ._memo import Memo
from .registry import ReproduceSettings

#: rough cost of one item of a chapter (after its pieces), for ordering the work
ITEM_COST = {
    "inerterlab.report.studies": 4.0,
    "inerterlab.report.ch3": 1.0,
    "inerterlab.report.ch4_6": 0.5,
    "inerterlab.report.ch5": 0.5,
    "inerterlab.report.ch7": 0.5,
}
#: chapters whose items share caches that are not memos: computed in one task
ONE_GROUP = {"inerterlab.report.studies"}
#: chapters whose memo entries are large: one task per worker, not per item
CHUNKED = {"inerterlab.report.ch7"}
#: environment of the workers: one thread each, the processes are the parallelism
_THREAD_ENV = {
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "NUMBA_NUM_THREADS": "1",
}


def default_workers() -> int:
    """Processes for a parallel reproduction: the CPUs this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def _memos(module) -> dict[str, Memo]:
    return {k: v for k, v in vars(module).items() if isinstance(v, Memo)}


def _piece(module: str, memo_name: str, key: tuple):
    """Worker: one memo entry."""
    return getattr(importlib.import_module(module), memo_name).fn(*key)


def _items(module: str, items: list, settings: ReproduceSettings, seeds: dict) -> list[dict]:
    """Worker: whole items, with the chapter's memo entries put in first."""
    from .build import _load_chapters, compute_item

    mod = importlib.import_module(module)
    for name, entries in seeds.items():
        memo = getattr(mod, name)
        for key, value in entries.items():
            memo.put(key, value)
    tables, figures = _load_chapters()
    out = []
    for kind, ident in items:
        fn = (tables if kind == "table" else figures)[ident]
        out.append(compute_item(kind, ident, fn, settings))
    return out


def _worker_init(parent: int) -> None:
    """Workers leave Ctrl-C to the parent, which lets the running tasks finish, and end
    with the parent even when it is killed (SIGKILL leaves no chance to shut the pool)."""
    from ..studies.backends import _die_with_parent

    _die_with_parent(parent)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def run_parallel(
    settings: ReproduceSettings,
    items: list[tuple[str, str, Callable]],
    workers: int,
    *,
    note: Callable[[str], None] | None = None,
    done: Callable[[dict], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> dict[tuple[str, str], dict]:
    """Compute ``items`` (kind, id, function) in ``workers`` processes.

    Returns the records keyed by (kind, id), as :func:`~inerterlab.report.build.
    compute_item` makes them; an item missing from the result (its task failed) is
    left to the caller. ``note`` receives what is running, ``done`` each record as it
    arrives (to save it at once). When ``should_stop`` returns True, no new task starts,
    the running ones finish and are delivered, then ``KeyboardInterrupt`` is raised.
    """
    by_module: dict[str, list[tuple[str, str]]] = {}
    for kind, ident, fn in items:
        by_module.setdefault(fn.__module__, []).append((kind, ident))
    inner = dataclasses.replace(settings, workers=1)  # no process pools inside workers
    pieces = []  # (cost, module, memo name, key)
    waiting: dict[str, int] = {}  # module -> pieces still to come
    for name, its in by_module.items():
        mod = importlib.import_module(name)
        prefetch = getattr(mod, "prefetch", None)
        names = {id(m): n for n, m in _memos(mod).items()}
        for memo, key, cost in prefetch(settings, [i for _, i in its]) if prefetch else ():
            full = memo.key(*key)
            if full not in memo.cache:
                pieces.append((cost, name, names[id(memo)], full))
        waiting[name] = sum(1 for p in pieces if p[1] == name)
    records: dict[tuple[str, str], dict] = {}
    queue: list = []  # tasks not yet handed to the pool: (label, fn, args, meta)
    pending: dict = {}

    def add_items(module: str) -> None:
        its = by_module[module]
        mod = importlib.import_module(module)
        seeds = {n: dict(m.cache) for n, m in _memos(mod).items() if m.cache}
        # one task per item (each saved as soon as it is done), except where the items
        # share caches that are not memos, or the memo entries are large (ch. 7 curves)
        n = 1 if module in ONE_GROUP else min(workers, len(its)) if module in CHUNKED else len(its)
        for i in range(n):
            chunk = its[i::n]
            short = module.rsplit(".", 1)[-1]
            label = f"{short} {chunk[0][1]}" if len(chunk) == 1 else f"{short} {len(chunk)} items"
            queue.append((label, _items, (module, chunk, inner, seeds), ("items", module)))

    # chapters without pieces first (they take long), then the pieces, longest first
    for name in sorted(by_module, key=lambda m: -ITEM_COST.get(m, 1.0) * len(by_module[m])):
        if waiting[name] == 0:
            add_items(name)
    for _cost, name, memo_name, key in sorted(pieces, key=lambda p: -p[0]):
        label = f"{name.rsplit('.', 1)[-1]} {memo_name}{key}"
        queue.append((label, _piece, (name, memo_name, key), ("piece", name, memo_name, key)))

    # the workers start on demand and read these when they start; the parent has loaded
    # its libraries already, so it keeps its own settings
    saved = {k: os.environ.get(k) for k in _THREAD_ENV}
    os.environ.update(_THREAD_ENV)
    ctx = multiprocessing.get_context("spawn")
    pool = ProcessPoolExecutor(
        max_workers=workers, mp_context=ctx, initializer=_worker_init, initargs=(os.getpid(),)
    )
    stopping = False
    try:
        while queue or pending:
            if should_stop is not None and should_stop():
                stopping = True
            # keep exactly one task per worker in the pool: a stop then waits only for
            # the running ones, and items of a chapter join the queue as it unblocks
            while queue and len(pending) < workers and not stopping:
                label, fn, args, meta = queue.pop(0)
                pending[pool.submit(fn, *args)] = (label, meta)
            if not pending:
                break
            if note:
                note(f"{len(pending)} of {len(pending) + len(queue)} tasks in "
                     f"{workers} processes: " + "; ".join(v[0] for v in pending.values()))  # fmt: skip
            finished, _ = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            for fut in finished:
                label, meta = pending.pop(fut)
                try:
                    result = fut.result()
                except Exception:  # noqa: BLE001 - the caller recomputes and records it
                    result = None
                if meta[0] == "items":
                    for rec in result or ():
                        records[(rec["kind"], rec["id"])] = rec
                        if done:
                            done(rec)
                    continue
                _, module, memo_name, key = meta
                if result is not None:
                    getattr(importlib.import_module(module), memo_name).put(key, result)
                waiting[module] -= 1
                if waiting[module] == 0:
                    add_items(module)
        if stopping:
            raise KeyboardInterrupt
    except BaseException:
        for proc in list(getattr(pool, "_processes", {}).values()):
            proc.terminate()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    finally:
        _restore(saved)
    pool.shutdown(wait=True)
    return records


def _restore(saved: dict) -> None:
    for k, v in saved.items():
        if v is None:
            os.environ.pop(k, None)
        else:
            os.environ[k] = v
