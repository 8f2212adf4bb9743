"""Model core speed and accuracy against the specialised quarter-car kernel.

Cases:

* ``afw`` preset (nylon flywheel, thesis law) under ``sine`` 0.05 m at 5 Hz, horizon
  5 s, time series at 1 kHz. Baseline: the specialised kernel
  (:func:`inerterlab.simulate.simulate`, numba backend); core: the same suspension as
  the network ``k | c | afw`` (:func:`inerterlab.systems.quarter_car`): ``auto``
  (exact steps while the flywheel is saturated, Dormand-Prince 5(4) through the
  transits) and ``adaptive`` (Dormand-Prince throughout); all at rtol 1e-8. Accuracy:
  each against the specialised kernel at rtol 1e-11 (largest state error relative to
  the state's peak).
* linear network ``k | (c - b)`` with an internal node on an ISO 8608 class C road at
  20 m/s, 10 s: the core's exact matrix-exponential steps against its adaptive steps at
  rtol 1e-8; accuracy against adaptive steps at rtol 1e-12.

Prints the median times and ``ratio: N`` = median baseline time / median core time.

Usage: python benchmarks/bench_core.py [--runs 7]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from inerterlab import quarter_car  # noqa: E402
from inerterlab.excitation import iso8608, sine  # noqa: E402
from inerterlab.simulate import SimulationOptions, simulate  # noqa: E402

NAMES = ("wheel.x", "wheel.v", "body.x", "body.v")


def _median(fn, runs):
    fn()
    ts = []
    for _ in range(runs):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def _err(a, b):
    return float((np.abs(a - b).max(axis=0) / np.abs(b).max(axis=0)).max())


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=7)
    runs = ap.parse_args().runs
    ex, T = sine(), 5.0
    old = quarter_car("afw")  # simulate() runs the kernel on its description
    core = quarter_car("afw")
    idx = [core.state_names.index(n) for n in NAMES]
    ref = simulate(old, ex, T, options=SimulationOptions(rtol=1e-11)).states[:, :4]
    opts = SimulationOptions(rtol=1e-8)
    t_old = _median(lambda: simulate(old, ex, T, options=opts), runs)
    t_new = _median(lambda: core.simulate(ex, T, rtol=1e-8), runs)
    t_dp = _median(lambda: core.simulate(ex, T, rtol=1e-8, method="adaptive"), runs)
    e_old = _err(simulate(old, ex, T, options=opts).states[:, :4], ref)
    r_new = core.simulate(ex, T, rtol=1e-8)
    e_new = _err(r_new.states[:, idx], ref)
    e_dp = _err(core.simulate(ex, T, rtol=1e-8, method="adaptive").states[:, idx], ref)
    print(f"afw / sine 5 Hz / {T:g} s, rtol 1e-8")
    print(f"  specialised kernel: {t_old * 1e3:8.1f} ms   error {e_old:.1e}")
    print(f"  core (auto)       : {t_new * 1e3:8.1f} ms   error {e_new:.1e}   {r_new.stats}")
    print(f"  core (adaptive)   : {t_dp * 1e3:8.1f} ms   error {e_dp:.1e}")
    print(f"  core (auto) / specialised time: {t_new / t_old:.2f}")
    lin = quarter_car("k | (c - b)", {"k": 90e3, "c": 5e3, "b": 200.0})
    road, T2 = iso8608("C", 20.0, seed=1), 10.0
    ref2 = lin.simulate(road, T2, method="adaptive", rtol=1e-12).states
    t_ad = _median(lambda: lin.simulate(road, T2, method="adaptive", rtol=1e-8), runs)
    t_ex = _median(lambda: lin.simulate(road, T2, method="exact"), runs)
    e_ad = _err(lin.simulate(road, T2, method="adaptive", rtol=1e-8).states, ref2)
    e_ex = _err(lin.simulate(road, T2, method="exact").states, ref2)
    print(f"k | (c - b) / ISO 8608 C at 20 m/s / {T2:g} s")
    print(f"  adaptive rtol 1e-8: {t_ad * 1e3:8.1f} ms   error {e_ad:.1e}")
    print(f"  exact steps       : {t_ex * 1e3:8.1f} ms   error {e_ex:.1e}")
    print(f"ratio: {t_old / t_new:.2f}")


if __name__ == "__main__":
    main()
