"""The chapter 4-6 table runs on the quarter-car kernel and on the model core.

The report's Tables 4.1-4.9 and 6.1-6.9 simulate every named suspension of each chapter
at every sprung mass (340-400 kg) under drop, bump, sine and the smoothed bump for 10 s
(``inerterlab.report.ch4_6``). This runs that workload (or every ``--stride``-th run)
twice in the same process: the baseline is :func:`inerterlab.simulate.simulate_metrics`
(the specialised kernel, metrics integrated as states); the core is
``quarter_car(...).simulate(...)`` (the model core; its metrics come from whatever the
core provides, today the 1 kHz samples). Both at rtol 1e-8.

Prints the total times (wall and CPU), ``ratio: N`` = core time / kernel time (how
much slower the tables would be on the core), and the largest relative difference of each metric
between the two.

Usage: python benchmarks/bench_quarter_car_tables.py [--stride 1]
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

from inerterlab import quarter_car  # noqa: E402
from inerterlab.report.ch4_6 import HORIZON, INPUTS, MASSES, SMOOTHED_BUMP, SUSPENSIONS  # noqa: E402
from inerterlab.simulate import simulate_metrics  # noqa: E402

KEYS = ("rms_body_acc", "rms_tyre_grip", "rms_deflection", "rms_body_acc_wk", "vdv",
        "peak_body_acc", "peak_body_acc_wk", "peak_deflection", "min_tyre_force")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--stride", type=int, default=1, help="take every N-th run")
    stride = ap.parse_args().stride
    inputs = {**INPUTS, "bump-smoothed": SMOOTHED_BUMP}
    runs = [
        (s, m, name)
        for ch in ("4", "6")
        for s in SUSPENSIONS[ch]
        for m in MASSES
        for name in inputs
    ][::stride]
    cars = {(s, m): quarter_car(s, sprung_mass=m) for s, m, _ in runs}
    for s in {s for s, _, _ in runs}:  # compile both engines first
        simulate_metrics(quarter_car(s), inputs["sine"], 0.1)
        quarter_car(s).simulate(inputs["sine"], 0.1)
    t_kernel = t_core = c_kernel = c_core = 0.0
    worst = dict.fromkeys(KEYS, 0.0)
    for s, m, name in runs:
        car, ex = cars[(s, m)], inputs[name]
        t0, p0 = time.perf_counter(), time.process_time()
        a = simulate_metrics(car, ex, HORIZON)
        t1, p1 = time.perf_counter(), time.process_time()
        b = car.simulate(ex, HORIZON, rtol=1e-8).metrics
        t2, p2 = time.perf_counter(), time.process_time()
        t_kernel += t1 - t0
        t_core += t2 - t1
        c_kernel += p1 - p0
        c_core += p2 - p1
        for k in KEYS:
            if a.get(k) is not None and b.get(k) is not None:
                d = abs(a[k] - b[k]) / max(abs(a[k]), 1e-300)
                worst[k] = max(worst[k], d)
    print(f"{len(runs)} runs of {HORIZON:g} s (chapter 4 and 6 tables, rtol 1e-8)")
    print(f"  kernel (simulate_metrics): {t_kernel:8.2f} s wall, {c_kernel:8.2f} s CPU")
    print(f"  core (System.simulate):    {t_core:8.2f} s wall, {c_core:8.2f} s CPU")
    print(f"ratio: {t_core / t_kernel:.1f} (CPU {c_core / c_kernel:.1f})")
    print("largest relative metric difference, core against kernel:")
    for k, v in worst.items():
        print(f"  {k:18s} {v:.2e}")


if __name__ == "__main__":
    main()
