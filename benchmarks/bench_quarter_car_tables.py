"""The chapter 4-6 table runs on the model core against scipy's solve_ivp (the oracle).

The report's Tables 4.1-4.9 and 6.1-6.9 simulate every named suspension of each chapter
at every sprung mass (340-400 kg) under drop, bump, sine and the smoothed bump for 10 s
(``inerterlab.report.ch4_6``). This runs that workload (every ``--stride``-th run; the
oracle is slow) twice in the same process: on the model core
(:func:`inerterlab.simulate.simulate_metrics`, the ride metrics integrated as observer
states) and on scipy's ``solve_ivp`` (DOP853) over the independent plain-Python
equations (``tests/_quarter_car_oracle.py``, the baseline). Both at rtol 1e-8.

Prints the total times (wall and CPU), ``ratio: N`` = scipy time / core time (how many
times faster the core is), the core's time for all 168 runs, and the largest relative
difference of each metric between the two (the least tyre force relative to the
static load, of which it is a difference).

The specialised quarter-car kernel these tables ran on before (deleted) measured
1.01 s wall, 0.39 s CPU for the 168 runs (docs/decisions.md, "One engine for the
quarter car").

Usage: python benchmarks/bench_quarter_car_tables.py [--stride 12]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import _quarter_car_oracle as oracle  # noqa: E402
from inerterlab import quarter_car  # noqa: E402
from inerterlab.report.ch4_6 import HORIZON, INPUTS, MASSES, SMOOTHED_BUMP, SUSPENSIONS  # noqa: E402
from inerterlab.simulate import simulate_metrics  # noqa: E402

KEYS = ("rms_body_acc", "rms_tyre_grip", "rms_deflection", "rms_body_acc_wk", "vdv",
        "peak_body_acc", "peak_body_acc_wk", "peak_deflection", "min_tyre_force")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--stride", type=int, default=12, help="take every N-th run for the oracle")
    stride = ap.parse_args().stride
    inputs = {**INPUTS, "bump-smoothed": SMOOTHED_BUMP}
    runs = [
        (s, m, name)
        for ch in ("4", "6")
        for s in SUSPENSIONS[ch]
        for m in MASSES
        for name in inputs
    ]
    cars = {(s, m): quarter_car(s, sprung_mass=m) for s, m, _ in runs}
    for s in {s for s, _, _ in runs}:  # compile first
        simulate_metrics(quarter_car(s), inputs["sine"], 0.1)
    t_all, c_all = time.perf_counter(), time.process_time()
    for s, m, name in runs:
        simulate_metrics(cars[(s, m)], inputs[name], HORIZON)
    t_all, c_all = time.perf_counter() - t_all, time.process_time() - c_all
    t_core = t_ref = c_core = c_ref = 0.0
    worst = dict.fromkeys(KEYS, 0.0)
    some = runs[::stride]
    for s, m, name in some:
        car, ex = cars[(s, m)], inputs[name]
        load = car.info["model"].parameters.static_tyre_load
        t0, p0 = time.perf_counter(), time.process_time()
        a = simulate_metrics(car, ex, HORIZON)
        t1, p1 = time.perf_counter(), time.process_time()
        b = oracle.simulate_metrics(car, ex, HORIZON, rtol=1e-8)
        t2, p2 = time.perf_counter(), time.process_time()
        t_core += t1 - t0
        t_ref += t2 - t1
        c_core += p1 - p0
        c_ref += p2 - p1
        for k in KEYS:
            if a.get(k) is not None and b.get(k) is not None:
                scale = load if k == "min_tyre_force" else max(abs(b[k]), 1e-300)
                worst[k] = max(worst[k], abs(a[k] - b[k]) / scale)
    print(f"all {len(runs)} runs of {HORIZON:g} s on the model core (rtol 1e-8): "
          f"{t_all:.2f} s wall, {c_all:.2f} s CPU")  # fmt: skip
    print(f"{len(some)} of them (every {stride}th) on both engines, rtol 1e-8:")
    print(f"  model core (simulate_metrics):     {t_core:8.2f} s wall, {c_core:8.2f} s CPU")
    print(f"  scipy solve_ivp DOP853 (oracle):   {t_ref:8.2f} s wall, {c_ref:8.2f} s CPU")
    print(f"ratio: {t_ref / t_core:.1f} (CPU {c_ref / c_core:.1f}) = oracle time / core time")
    print("largest relative metric difference, core against the oracle (both rtol 1e-8):")
    for k, v in worst.items():
        print(f"  {k:18s} {v:.2e}")


if __name__ == "__main__":
    main()
