"""Parallel reproduction: independent work in worker processes.

The report's items share expensive computations through memos (a brute-force curve is
read by three tables and a figure; one identification by a table and a figure). Run
item by item in parallel, they would each redo them, so the work is cut in two kinds of
task for one pool of worker processes:

1. *pieces*: the shared computations of the items to compute (brute-force and
   harmonic-balance curves, identifications, metric grids; each chapter module's
   ``prefetch``);
2. *item tasks*: one item, or a few that share work that is not a piece (a chapter's
   ``task_groups``; all design studies in one), sent with the memo entries they read
   as soon as the pieces they read are done.

Whenever a worker is free it gets the costliest task that is ready (longest first, so
the run does not end waiting on one long task started late). Every piece and item is
computed by the same function with the same arguments as in a serial run, so the
numbers do not change (tests/test_reproduce_parallel.py compares them); only the order
of the work does.
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
    "inerterlab.report.studies": 3.0,
    "inerterlab.report.ch3": 1.0,
    "inerterlab.report.ch4_6": 0.7,
    "inerterlab.report.ch5": 1.5,
    "inerterlab.report.ch7": 0.5,
}
#: items that cost more than their chapter's rate: figures of many panels and long series
#: (the units are those of the pieces' costs: a 200-point brute-force curve is 15)
ITEM_COST_OF = {
    "Fig. 7.2": 6.0,
    "Fig. 7.4": 6.0,
    "Fig. 7.7": 6.5,
    "Fig. 7.9": 4.0,
    "Fig. 7.C": 4.5,
    "Fig. 4.T": 6.0,
    "Fig. 6.T": 6.0,
    "Laws": 4.5,
    "Fig. 3.3/3.8": 1.5,
    "Layouts": 12.0,  # measured 4-6 s, as long as two brute-force curves
}
#: chapters whose items share caches that are not memos: computed in one task
ONE_GROUP = {"inerterlab.report.studies"}
#: chapters whose tasks compile the same numerical code, the model core's integrator
#: (about 100 s of one core on a first run); every other chapter is a family of its own
COMPILE_FAMILY = {
    "inerterlab.report.ch4_6": "core",
    "inerterlab.report.ch5": "core",
    "inerterlab.report.studies": "core",
}
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


def family(module: str) -> str:
    """The compile family of a chapter module (:data:`COMPILE_FAMILY`)."""
    return COMPILE_FAMILY.get(module, module)


def cold_cache() -> bool:
    """True if numba's cache holds no machine code for the model core's integrator for
    this source (the first run after an install or a change of the package): the
    workers would then compile it. False when unsure."""
    try:
        from ..systems import _integrate

        return not _integrate._advance_run._cache._cache_file._load_index()
    except Exception:  # noqa: BLE001 - numba's cache internals: then assume it is warm
        return False


def pick(ready: list, rank, compiling: set):
    """The task to start from ``ready``: the highest ``rank(task)`` (earliest on a tie),
    among those whose compile family (``task[5][1]``'s) is not in ``compiling`` if any
    is: on a cold cache two workers would compile the same code side by side, while one
    of them can compile another chapter's."""
    free = [t for t in ready if family(t[5][1]) not in compiling]
    return max(free or ready, key=lambda t: (rank(t), -t[1]))


def _memos(module) -> dict[str, Memo]:
    return {k: v for k, v in vars(module).items() if isinstance(v, Memo)}


def _piece(module: str, memo_name: str, key: tuple):
    """Worker: one memo entry."""
    return getattr(importlib.import_module(module), memo_name).fn(*key)


def _groups(name: str, module, items: list) -> list[list]:
    """The items of one chapter cut into tasks: all in one where they share caches that
    are not memos, else the chapter's ``task_groups`` (items that share work that is not
    a piece, e.g. a table and its figure), else one task per item (each saved as soon
    as it is done)."""
    if name in ONE_GROUP:
        return [items]
    grouping = getattr(module, "task_groups", None)
    if grouping is None:
        return [[it] for it in items]
    ids = {i: (k, i) for k, i in items}
    return [[ids[i] for i in g] for g in grouping([i for _, i in items])]


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
    timeline: list | None = None,
    tracker=None,
) -> dict[tuple[str, str], dict]:
    """Compute ``items`` (kind, id, function) in ``workers`` processes.

    Returns the records keyed by (kind, id), as :func:`~inerterlab.report.build.
    compute_item` makes them; an item missing from the result (its task failed) is
    left to the caller. ``note`` receives what is running, ``done`` each record as it
    arrives (to save it at once). When ``should_stop`` returns True, no new task starts,
    the running ones finish and are delivered, then ``KeyboardInterrupt`` is raised.
    ``timeline`` (a list) receives one dict per task: its label and the seconds from the
    start of the pool at which it was handed out and at which its result came back.
    ``tracker`` (a :class:`~.timeleft.TimeLeft`) is given the tasks' keys (a piece's
    label; an item task's module and item ids) as they are planned, start and finish.
    """
    import time

    t0 = time.perf_counter()
    by_module: dict[str, list[tuple[str, str]]] = {}
    for kind, ident, fn in items:
        by_module.setdefault(fn.__module__, []).append((kind, ident))
    inner = dataclasses.replace(settings, workers=1)  # no process pools inside workers
    # every task: [cost, order, label, fn, args, meta, deps]; deps are the memo entries
    # (module, memo name, key) it waits for, computed as pieces by other tasks
    tasks: list[list] = []
    seen_pieces: set = set()
    for name, its in by_module.items():
        mod = importlib.import_module(name)
        prefetch = getattr(mod, "prefetch", None)
        names = {id(m): n for n, m in _memos(mod).items()}
        short = name.rsplit(".", 1)[-1]

        def wanted(ids, mod=mod, prefetch=prefetch, names=names):
            out = []
            for memo, key, cost in prefetch(settings, ids) if prefetch else ():
                out.append((names[id(memo)], memo.key(*key), cost, memo))
            return out

        for memo_name, full, cost, memo in wanted([i for _, i in its]):
            if full not in memo.cache and (name, memo_name, full) not in seen_pieces:
                seen_pieces.add((name, memo_name, full))
                tasks.append([cost, len(tasks), f"{short} {memo_name}{full}", _piece,
                              (name, memo_name, full), ("piece", name, memo_name, full),
                              set()])  # fmt: skip
        for group in _groups(name, mod, its):
            entries = wanted([i for _, i in group])
            deps = {(name, n, k) for n, k, _, m in entries if k not in m.cache}
            label = f"{short} {group[0][1]}" if len(group) == 1 else f"{short} {len(group)} items"
            cost = sum(ITEM_COST_OF.get(i, ITEM_COST.get(name, 1.0)) for _, i in group)
            key = f"{short} " + ", ".join(i for _, i in group)
            tasks.append([cost, len(tasks), label, _items, (name, group, inner),
                          ("items", name, [(n, k) for n, k, _, _ in entries], key),
                          deps])  # fmt: skip
    # rank of a task: its cost plus the largest rank of the tasks waiting for it, so a
    # cheap piece that the costliest items wait for goes before costlier loose work
    rank = {id(t): t[0] for t in tasks}
    for t in tasks:
        if t[5][0] == "piece":
            key = t[5][1:]
            after = [u[0] for u in tasks if key in u[6]]
            rank[id(t)] = t[0] + max(after, default=0.0)
    records: dict[tuple[str, str], dict] = {}
    done_pieces: set = set()
    pending: dict = {}

    def key_of(task) -> str:
        return task[5][3] if task[5][0] == "items" else task[2]

    if tracker is not None:
        tracker.plan([key_of(t) for t in tasks], workers)

    # on a cold numba cache, the families whose code a running task compiles: no second
    # task of theirs starts while another is ready (:func:`pick`); a family is compiled
    # (and cached) once one of its tasks has finished
    cold = cold_cache()
    compiled: set = set()

    def compiling() -> set:
        if not cold:
            return set()
        return {family(meta[1]) for _, meta, _ in pending.values()} - compiled

    def next_task():
        """The ready task (all its pieces done) of highest rank: longest first keeps the
        end of the run from waiting on one long task; None if none is ready."""
        ready = [t for t in tasks if t[6] <= done_pieces]
        if not ready:
            return None
        best = pick(ready, lambda t: rank[id(t)], compiling())
        tasks.remove(best)
        return best

    def submit(task) -> None:
        _, _, label, fn, args, meta, _ = task
        if meta[0] == "items":  # the memo entries the items read, from this process
            mod = importlib.import_module(meta[1])
            seeds: dict = {}
            for memo_name, key in meta[2]:
                memo = getattr(mod, memo_name)
                if key in memo.cache:
                    seeds.setdefault(memo_name, {})[key] = memo.cache[key]
            args = (*args, seeds)
        pending[pool.submit(fn, *args)] = (label, meta, time.perf_counter() - t0)
        if tracker is not None:
            tracker.begin(key_of(task))

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
        while tasks or pending:
            if should_stop is not None and should_stop():
                stopping = True
            # keep exactly one task per worker in the pool: a stop then waits only for
            # the running ones, and items join as the pieces they read arrive
            while len(pending) < workers and not stopping:
                task = next_task()
                if task is None:
                    break
                submit(task)
            if not pending:
                break
            if note:
                note(f"{len(pending)} of {len(pending) + len(tasks)} tasks in "
                     f"{workers} processes: " + "; ".join(v[0] for v in pending.values()))  # fmt: skip
            finished, _ = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            for fut in finished:
                label, meta, started = pending.pop(fut)
                compiled.add(family(meta[1]))
                if tracker is not None:
                    tracker.end(meta[3] if meta[0] == "items" else label)
                if timeline is not None:
                    end = time.perf_counter() - t0
                    timeline.append({"task": label, "start_s": started, "end_s": end})
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
                # a failed piece is computed again by the items that read it (and fails
                # there with its reason recorded)
                done_pieces.add((module, memo_name, key))
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
