"""Exact steps in the linear regimes on sampled roads: when ``auto`` takes them.

The ``afw`` quarter car (its flywheel saturates: a linear regime, docs/guide/core.md)
with its ride observers, 10 s of the class C road of ``iso8608("C", 20.0, seed=1)``
resampled at even spacings (``road_series``: segments of that length). Three ways:

* ``auto``: the default (since stop 62: exact steps in the regime only where the road's
  segments are at least ``core.REGIME_SEGMENT_MIN`` = 10 ms long on average);
* ``adaptive``: ``method="adaptive"``, Dormand-Prince alone (the baseline);
* ``forced``: exact steps in the regime on every road (``REGIME_SEGMENT_MIN`` set to 0
  for the run: what ``auto`` did before).

Printed per spacing: CPU medians of ``--runs`` runs (the regime tables kept between
runs, as on one car), steps (of them exact), and the worst relative difference of the
ride metrics from a run at rtol 1e-11. Then a sweep's case, a new car at every run (the
changing ratio varied: the regime tables built every time) on the 1 ms road.

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
from inerterlab.systems import core  # noqa: E402

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
    saved = core.REGIME_SEGMENT_MIN
    if how == "forced":
        core.REGIME_SEGMENT_MIN = 0.0
    try:
        opts = SimulationOptions(method="adaptive" if how == "adaptive" else "auto")
        res = simulate(car, ex, T, options=opts, output="metrics")
        return res.metrics(), res.stats
    finally:
        core.REGIME_SEGMENT_MIN = saved


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
        for how in ("auto", "adaptive", "forced"):
            m, st = run(car, ex, how)  # the tables built, the code loaded
            sec = cpu_median(lambda how=how, ex=ex: run(car, ex, how), args.runs)
            cells[how] = sec
            print(f"  segments {1e3 * dt:4.0f} ms  {how:8s} {1e3 * sec:7.2f} ms  steps "
                  f"{st['steps']:5d} ({st.get('exact_steps', 0):4d} exact)  error "
                  f"{worst(m, ref):.1e}")  # fmt: skip
        print(f"  segments {1e3 * dt:4.0f} ms  ratio adaptive / auto: "
              f"{cells['adaptive'] / cells['auto']:.2f}, forced / auto: "
              f"{cells['forced'] / cells['auto']:.2f}")  # fmt: skip
    # a sweep's case: a new car every run on the 1 ms road (its regime tables built anew)
    ratios = np.linspace(0.05, 0.55, 24)
    cars = [quarter_car("afw", changing_ratio=float(x)) for x in ratios]
    out = {}
    for how in ("auto", "forced"):
        saved = core.REGIME_SEGMENT_MIN
        if how == "forced":
            core.REGIME_SEGMENT_MIN = 0.0
        try:
            simulate_metrics(cars[0], iso, T)
            c = time.process_time()
            for car_i in cars[1:]:
                simulate_metrics(car_i, iso, T)
            out[how] = (time.process_time() - c) / (len(cars) - 1)
        finally:
            core.REGIME_SEGMENT_MIN = saved
    print(f"new car every run, iso8608 C at 20 m/s (1 ms segments): auto {1e3 * out['auto']:.1f} ms"
          f", forced {1e3 * out['forced']:.1f} ms a run; ratio forced / auto "
          f"{out['forced'] / out['auto']:.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
