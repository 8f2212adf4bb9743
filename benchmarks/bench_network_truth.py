"""Wall time of the default ``inerterlab network truth`` study (3 layouts x 25 variants x
5 inputs, plus the optimised k | c on each input: 380 simulations of 10 s).

Runs the study on 2 local worker processes (the command's default backend) and, as the
baseline measured in the same run, serially in this process; prints both wall times,
their ratio, the largest difference between the two results (must be 0), the split of
the serial run's CPU time into the integrator and everything around it, and how many
structures had their right-hand side compiled during the run (0 when numba's cache
holds them all: a first run after installing or changing the package compiles them).

    python benchmarks/bench_network_truth.py
    python benchmarks/bench_network_truth.py --layout series --no-serial
"""

from __future__ import annotations

import argparse
import os
import resource
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
# the command's own setting (a user's run): the structures' code once a process has run
# one for a while, not at once (bench_sweep, imported below, sets ``always`` for its
# steady state; with it this study compiled all 19 structures up front, 112 s against
# 9 s)
os.environ.setdefault("INERTERLAB_SPECIALISE", "auto")

import numpy as np  # noqa: E402
from bench_sweep import _timed  # noqa: E402  (the same CPU-time wrapper)

from inerterlab.network_truth import LAYOUTS, TRUTH_METRICS, network_truth  # noqa: E402


def _compiled_structures() -> set[str]:
    from inerterlab.systems._compiled import _cache_dir

    d = _cache_dir()
    return {p.name for p in d.glob("s_*.done")} if d.exists() else set()


def _cpu_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--layout", action="append", choices=tuple(LAYOUTS), help="default all")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--serial", action=argparse.BooleanOptionalAction, default=True)
    args = ap.parse_args()
    layouts = tuple(args.layout or LAYOUTS)
    before = _compiled_structures()

    t0, c0, k0 = time.perf_counter(), time.process_time(), _cpu_children()
    par = network_truth(layouts=layouts, backend="processes", workers=args.workers)
    wall = time.perf_counter() - t0
    cpu = time.process_time() - c0 + _cpu_children() - k0
    n = int(par.dataset.status.size) + int(par.dataset.baseline.sizes["input"])
    print(
        f"{args.workers} processes: {n} simulations in {wall:6.1f} s wall "
        f"({cpu:6.1f} s CPU in all processes)"
    )
    if args.serial:
        from inerterlab.systems import _integrate, core

        spent = [0.0]
        _timed(_integrate, "integrate", spent)
        _timed(core, "_exact", spent)
        t0, c0 = time.perf_counter(), time.process_time()
        ser = network_truth(layouts=layouts, backend="serial")
        swall, scpu = time.perf_counter() - t0, time.process_time() - c0
        diff = max(
            float(np.nanmax(np.abs(ser.dataset[m].values - par.dataset[m].values)))
            for m in TRUTH_METRICS
        )
        print(f"      serial: {n} simulations in {swall:6.1f} s wall ({scpu:6.1f} s CPU)")
        print(
            f"speed-up {args.workers} processes / serial: {swall / wall:.2f}x; largest "
            f"difference between backends: {diff:g}"
        )
        print(
            f"split of the serial run (CPU): {spent[0]:.1f} s in the integrator, "
            f"{scpu - spent[0]:.1f} s around it (H2 designs, building the cars, imports, "
            f"the sweep and its results) = {100 * (scpu - spent[0]) / scpu:.1f} %"
        )
    new = len(_compiled_structures() - before)
    print(
        f"structures compiled during this run: {new} "
        f"({'numba cache warm' if new == 0 else 'compilation included in the times'}; "
        f"INERTERLAB_SPECIALISE={os.environ['INERTERLAB_SPECIALISE']}); "
        f"machine load (1-minute average) at the end: {os.getloadavg()[0]:.1f}"
    )
    if layouts == tuple(LAYOUTS):
        print(
            f"target: the default study <= 60 s on 2 cores: "
            f"{'met' if wall <= 60 else 'not met'} ({wall:.1f} s on {args.workers} processes)"
        )


if __name__ == "__main__":
    main()
