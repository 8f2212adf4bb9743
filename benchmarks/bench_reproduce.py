"""Wall and CPU time of ``inerterlab reproduce``: serial (one process) against parallel.

Each run is a fresh ``inerterlab reproduce`` process writing to its own temporary
directory (nothing reused), so the times include imports and loading the compiled
kernels (run any reproduction once after an edit so that the kernels are compiled
before timing). The runs alternate serial, parallel, serial, ... so that a change of
load on a shared machine hits both alike; the medians are printed with the CPU time
of each run (the process and its workers): wall time close to CPU / workers means the
work was spread well, wall time above CPU means the run waited for the machine. The
numbers of the two reports are compared too: they must be identical.

    python benchmarks/bench_reproduce.py                 # the full report (minutes)
    python benchmarks/bench_reproduce.py --repeat 3      # medians of three runs each
    python benchmarks/bench_reproduce.py --quick         # the reduced report
    python benchmarks/bench_reproduce.py --quick --workers 2 --tables 7.1-7.4,5.A
    python benchmarks/bench_reproduce.py --keep DIR      # keep the last reports in DIR
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run(out: Path, workers: int, quick: bool, tables: str | None) -> tuple[float, float]:
    """Wall and CPU seconds of one reproduction (CPU of the process and its workers)."""
    cmd = [sys.executable, "-m", "inerterlab", "reproduce", "--out", str(out),
           "--workers", str(workers)]  # fmt: skip
    if quick:
        cmd.append("--quick")
    if tables:
        cmd += ["--tables", tables]
    cpu0 = _children_cpu()
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, env={**os.environ, "MPLBACKEND": "Agg"})
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"reproduce failed ({' '.join(cmd)}):\n{r.stderr[-2000:]}")
    return wall, _children_cpu() - cpu0


def largest_difference(a: Path, b: Path) -> tuple[int, float]:
    """Files compared and the largest |x - y| / max(1, |x|) over every number."""
    n, worst = 0, 0.0
    for sub in ("tables", "data"):
        for fa in sorted((a / sub).glob("*.csv")):
            da = pd.read_csv(fa, comment="#")
            db = pd.read_csv(b / sub / fa.name, comment="#")
            n += 1
            if da.shape != db.shape:
                return n, float("inf")
            for c in da.columns:
                if pd.api.types.is_numeric_dtype(da[c]):
                    x, y = da[c].to_numpy(float), db[c].to_numpy(float)
                    d = np.abs(x - y) / np.maximum(1.0, np.abs(x))
                    d = d[~(np.isnan(x) & np.isnan(y))]
                    worst = max(worst, float(np.max(d, initial=0.0)))
    return n, worst


def critical_path(out: Path) -> str:
    """The longest task of the parallel run and when the last one ended (manifest)."""
    tasks = json.loads((out / "manifest.json").read_text()).get("parallel_tasks") or []
    if not tasks:
        return "no parallel tasks recorded"
    longest = max(tasks, key=lambda t: t["end_s"] - t["start_s"])
    return (
        f"{len(tasks)} tasks, the last done {max(t['end_s'] for t in tasks):.1f} s after the "
        f"pool started; longest {longest['task']!r} {longest['end_s'] - longest['start_s']:.1f} s"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--tables", default=None)
    ap.add_argument("--workers", type=int, default=len(os.sched_getaffinity(0)))
    ap.add_argument("--repeat", type=int, default=1, help="runs of each kind (medians)")
    ap.add_argument("--keep", type=Path, default=None, help="copy the last two reports here")
    args = ap.parse_args()
    if args.repeat < 1:
        sys.exit("--repeat: at least 1")
    times: dict[str, list[tuple[float, float]]] = {"serial": [], "parallel": []}
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.repeat):
            for kind, w in (("serial", 1), ("parallel", args.workers)):
                out = Path(tmp) / f"{kind}{i}"
                wall, cpu = run(out, w, args.quick, args.tables)
                times[kind].append((wall, cpu))
                print(f"{kind:8s} run {i + 1}: {wall:7.1f} s wall, {cpu:7.1f} s CPU", flush=True)
        med = {k: (statistics.median(w for w, _ in v), statistics.median(c for _, c in v))
               for k, v in times.items()}  # fmt: skip
        last = args.repeat - 1
        print(f"serial   (1 process):   median {med['serial'][0]:7.1f} s wall, "
              f"{med['serial'][1]:7.1f} s CPU")  # fmt: skip
        print(f"parallel ({args.workers} processes): median {med['parallel'][0]:7.1f} s wall, "
              f"{med['parallel'][1]:7.1f} s CPU  (wall x{med['serial'][0] / med['parallel'][0]:.2f}"
              " of serial)")  # fmt: skip
        print("parallel run: " + critical_path(Path(tmp) / f"parallel{last}"))
        n, worst = largest_difference(Path(tmp) / f"serial{last}", Path(tmp) / f"parallel{last}")
        print(f"{n} CSV files compared: largest relative difference {worst:.3g}")
        load = os.getloadavg()
        print(f"load average now {load[0]:.2f} on {os.cpu_count()} CPUs "
              "(other work on the machine slows both runs)")  # fmt: skip
        if args.keep is not None:
            args.keep.mkdir(parents=True, exist_ok=True)
            for kind in ("serial", "parallel"):
                dest = args.keep / kind
                if dest.exists():
                    shutil.rmtree(dest)
                shutil.copytree(Path(tmp) / f"{kind}{last}", dest)
            print(f"reports kept in {args.keep}")


if __name__ == "__main__":
    main()
