"""Exact steps in the linear regimes on sampled roads, against the adaptive steps alone.

The ``afw`` quarter car (its flywheel saturates: a linear regime, docs/guide/core.md)
with its ride observers, 10 s of the class C road of ``iso8608("C", 20.0, seed=1)``
resampled at even spacings (``road_series``: segments of that length). Two ways:

* ``auto``: the default, exact steps while the flywheel is saturated (since stop 64
  across the edges of a sampled road: each step ends on the next edge at the latest);
* ``adaptive``: ``method="adaptive"``, Dormand-Prince alone (the baseline).

Printed per spacing: CPU medians of ``--runs`` runs (the regime tables kept between
runs, as on one car), steps (of them exact), the worst relative difference of the ride
metrics from a run at rtol 1e-11, and the ratio adaptive / auto (the speed-up). Then a
sweep's case, a new car at every run (the changing ratio varied: the regime tables
built every time) on the 1 ms road.

    python benchmarks/bench_sampled_roads.py [--runs 7]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("INERTERLAB_SPECIALISE", "always")  # the structure's code throughout

import numpy as np  # noqa: E402

from inerterlab import quarter_car  # noqa: E402
from inerterlab.excitation import iso8608, road_displacement, road_series  # noqa: E402
from inerterlab.simulate import SimulationOptions, simulate, simulate_metrics  # noqa: E402

T = 10.0
KEYS = ("rms_body_acc", "rms_body_acc_wk", "vdv", "peak_body_acc", "peak_deflection")


def cpu_median(fn, runs: int) -> float:
    w = []
    for _ in range(runs):
        c = time.process_time()
        fn()
        w.append(time.process_time() - c)
    return statistics.median(w)


def run(car, ex, how: str):
    """(metrics, stats) of one run ``how``."""
    res = simulate(car, ex, T, options=SimulationOptions(method=how), output="metrics")
    return res.metrics(), res.stats


def worst(m, ref) -> float:
    return max(abs(m[k] - ref[k]) / abs(ref[k]) for k in KEYS)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=7)
    args = ap.parse_args()
    car = quarter_car("afw")
    iso = iso8608("C", 20.0, seed=1)
    segs = iso.prepared(T).segments
    print("afw car, ride metrics, 10 s of class C road resampled; CPU medians "
          f"of {args.runs} runs (ms); steps (exact); worst relative metric error vs rtol 1e-11")  # fmt: skip
    for dt in (0.001, 0.002, 0.005, 0.01, 0.02, 0.05):
        t = np.arange(0.0, T + dt / 2, dt)
        ex = road_series(t, road_displacement(segs, t)[0])
        ref = simulate(car, ex, T, options=SimulationOptions(method="adaptive", rtol=1e-11),
                       output="metrics").metrics()  # fmt: skip
        cells = {}
        for how in ("auto", "adaptive"):
            m, st = run(car, ex, how)  # the tables built, the code loaded
            sec = cpu_median(lambda how=how, ex=ex: run(car, ex, how), args.runs)
            cells[how] = sec
            print(f"  segments {1e3 * dt:4.0f} ms  {how:8s} {1e3 * sec:7.2f} ms  steps "
                  f"{st['steps']:5d} ({st.get('exact_steps', 0):4d} exact)  error "
                  f"{worst(m, ref):.1e}")  # fmt: skip
        print(f"  segments {1e3 * dt:4.0f} ms  ratio adaptive / auto: "
              f"{cells['adaptive'] / cells['auto']:.2f}")  # fmt: skip
    # a sweep's case: a new car every run on the 1 ms road (its regime tables built anew)
    ratios = np.linspace(0.05, 0.55, 24)
    cars = [quarter_car("afw", changing_ratio=float(x)) for x in ratios]
    out = {}
    for how in ("auto", "adaptive"):
        opts = SimulationOptions(method=how)
        simulate_metrics(cars[0], iso, T, options=opts)
        c = time.process_time()
        for car_i in cars[1:]:
            simulate_metrics(car_i, iso, T, options=opts)
        out[how] = (time.process_time() - c) / (len(cars) - 1)
    print(f"new car every run, iso8608 C at 20 m/s (1 ms segments): auto {1e3 * out['auto']:.1f} ms"
          f", adaptive {1e3 * out['adaptive']:.1f} ms a run; ratio adaptive / auto "
          f"{out['adaptive'] / out['auto']:.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
