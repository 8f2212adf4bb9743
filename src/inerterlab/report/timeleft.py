"""Time left of a reproduction, from the measured cost of each task and the speed
observed so far.

A run is a set of tasks (the items of a serial run; the pieces and item groups of a
parallel one, :mod:`.parallel`), each with a cost measured on an earlier run: the
previous report at the same ``--out`` (its manifest keeps ``task_seconds``), else the
table shipped in ``data/reproduce_costs.json`` (measured once; its provenance is in
the file). The speed of this run is the measured time of the finished tasks over their
expected cost; the time left is the expected cost of what is left, scaled by that
speed and shared among the workers, and never less than the longest running task's
own rest. Before any task has finished the estimate is at the reference speed (or
slower, if a running task has already overrun its cost) and says so; with no cost known for the tasks it says it cannot estimate.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from importlib import resources
from pathlib import Path


class TimeLeft:
    """Estimator of the time left; call :meth:`plan`, then :meth:`begin` and
    :meth:`end` with each task's key as it starts and finishes.

    Parameters
    ----------
    costs : dict
        Expected seconds per task key (from an earlier run); tasks not in it get the
        median of the known costs.
    source : str
        Where ``costs`` came from, for the message.
    clock : callable
        Seconds (monotonic); a fake one in tests.
    """

    def __init__(self, costs: dict | None = None, *, source: str = "",
                 clock: Callable[[], float] = time.perf_counter):  # fmt: skip
        self.costs = {str(k): float(v) for k, v in (costs or {}).items() if float(v) >= 0}
        self.source = source
        self.clock = clock
        self.workers = 1
        self.tasks: list[str] | None = None  # None: not planned yet
        self.running: dict[str, float] = {}
        self.finished: dict[str, float] = {}
        self._lock = threading.Lock()

    def set_costs(self, costs: dict, source: str) -> None:
        with self._lock:
            self.costs = {str(k): float(v) for k, v in costs.items() if float(v) >= 0}
            self.source = source

    def plan(self, tasks, workers: int = 1) -> None:
        """The tasks this run will compute and the processes that share them."""
        with self._lock:
            self.tasks = [str(t) for t in tasks]
            self.workers = max(1, int(workers))
            self.running.clear()
            self.finished.clear()

    def begin(self, key: str) -> None:
        with self._lock:
            self.running[str(key)] = self.clock()

    def end(self, key: str) -> None:
        with self._lock:
            start = self.running.pop(str(key), None)
            if start is not None:
                self.finished[str(key)] = self.clock() - start

    def _expected(self, key: str) -> float | None:
        if key in self.costs:
            return self.costs[key]
        known = sorted(self.costs.values())
        return known[len(known) // 2] if known else None

    def estimate(self) -> tuple[float | None, str]:
        """(seconds left, how it was obtained) or (None, why it cannot be estimated)."""
        with self._lock:
            if self.tasks is None:
                return None, "no tasks planned yet"
            if not self.tasks:
                return 0.0, "nothing to compute, every item reused"
            if not any(t in self.costs for t in self.tasks):
                return None, "no measured cost for these tasks yet"
            now = self.clock()
            done = [(t, s) for t, s in self.finished.items() if self._expected(t)]
            if done:
                speed = sum(s for _, s in done) / sum(self._expected(t) for t, _ in done)
                how = "from measured costs and this run's speed"
            else:  # at least as slow as a running task that overran its cost
                speed = max(
                    [1.0]
                    + [(now - t0) / c for t, t0 in self.running.items() if (c := self._expected(t))]
                )
                how = "from the reference costs, none finished yet"
            rest = 0.0
            longest = 0.0
            for t in self.tasks:
                if t in self.finished:
                    continue
                c = speed * (self._expected(t) or 0.0)
                if t in self.running:
                    c = max(c - (now - self.running[t]), 0.0)
                    longest = max(longest, c)
                rest += c
            return max(rest / self.workers, longest), how


def costs_file() -> dict:
    """The shipped cost table (``data/reproduce_costs.json``): provenance and costs."""
    with resources.files("inerterlab.data").joinpath("reproduce_costs.json").open() as fh:
        return json.load(fh)


def known_costs(out: Path, quick: bool, parallel: bool) -> tuple[dict, str]:
    """Task costs for a run writing ``out``: the previous report's measured ones if it
    ran with the same settings kind, else the shipped table's; ({}, reason) if none."""
    mode = "parallel" if parallel else "serial"
    try:
        m = json.loads((Path(out) / "manifest.json").read_text())
        same = bool(m["settings"]["quick"]) == quick and m.get("task_mode") == mode
        if same and m.get("task_seconds"):
            return dict(m["task_seconds"]), "the previous run at this --out"
    except (OSError, ValueError, KeyError, TypeError):
        pass
    try:
        table = costs_file()
        entry = table["runs"].get(f"{'quick' if quick else 'full'} {mode}")
        if entry:
            return dict(entry["task_seconds"]), "the shipped cost table"
    except (OSError, ValueError, KeyError):
        pass
    return {}, "no measured costs"
