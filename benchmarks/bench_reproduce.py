"""Wall time of ``inerterlab reproduce``: serial (one process) against parallel.

Each run is a fresh ``inerterlab reproduce`` process writing to its own temporary
directory (nothing reused), so the times include imports and loading the compiled
kernels. The numbers of the two reports are compared too: they must be identical.

    python benchmarks/bench_reproduce.py                 # the full report, twice (minutes)
    python benchmarks/bench_reproduce.py --quick         # the reduced report
    python benchmarks/bench_reproduce.py --quick --workers 2 --tables 7.1-7.4,5.A
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd


def run(out: Path, workers: int, quick: bool, tables: str | None) -> float:
    cmd = [sys.executable, "-m", "inerterlab", "reproduce", "--out", str(out),
           "--workers", str(workers)]  # fmt: skip
    if quick:
        cmd.append("--quick")
    if tables:
        cmd += ["--tables", tables]
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, env={**os.environ, "MPLBACKEND": "Agg"})
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"reproduce failed ({' '.join(cmd)}):\n{r.stderr[-2000:]}")
    return wall


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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--tables", default=None)
    ap.add_argument("--workers", type=int, default=len(os.sched_getaffinity(0)))
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        serial = run(Path(tmp) / "serial", 1, args.quick, args.tables)
        print(f"serial   (1 process):   {serial:7.1f} s wall", flush=True)
        par = run(Path(tmp) / "parallel", args.workers, args.quick, args.tables)
        print(f"parallel ({args.workers} processes): {par:7.1f} s wall  (x{serial / par:.2f})")
        n, worst = largest_difference(Path(tmp) / "serial", Path(tmp) / "parallel")
        print(f"{n} CSV files compared: largest relative difference {worst:.3g}")
        load = os.getloadavg()
        print(f"load average now {load[0]:.2f} on {os.cpu_count()} CPUs "
              "(other work on the machine slows both runs)")  # fmt: skip


if __name__ == "__main__":
    main()
