"""Exact steps of a linear network on a random road, against scipy.signal.lsim.

Case: the quarter car with the network ``k | (c - b)`` (k = 90 kN/m, c = 5 kN s/m,
b = 200 kg; an internal node between damper and inerter) on an ISO 8608 class C road
(seed 1) at 20 m/s, horizon 10 s, output every 1 ms.

* core: ``System.simulate`` (``method="auto"``: exact matrix-exponential steps, one
  per road segment edge and sample; the states, every output and the ride metrics),
  with its matrix exponentials kept between runs (as in a sweep over roads or seeds)
  and, "cold", computed afresh in every run;
* baseline: ``scipy.signal.lsim`` with first-order hold on the core's own state space
  (``System.linear_state_space``), written with the road displacement as its only input
  (z = x - B_v X1 obeys z' = A z + (A B_v + B_x) X1), so that linear interpolation of
  the input between the 1 kHz samples is exact for this road, which is linear between
  them; timed from the road object to the states at the samples (building the input
  samples included, the core's outputs and metrics not);
* accuracy: the largest state error relative to the state's range, of the core's exact
  steps against lsim and against the core's adaptive steps at rtol 1e-12.

Prints the medians (the three timed in turn in every round) and ``ratio: N`` = median lsim time / median core time (same run).

Usage: python benchmarks/bench_exact.py [--runs 21] (one BLAS and one numba thread, as
the report's workers run)
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # small products: threads only wait

import numpy as np  # noqa: E402
from scipy import signal  # noqa: E402

from inerterlab.excitation import iso8608, road_displacement  # noqa: E402
from inerterlab.systems import quarter_car  # noqa: E402
from inerterlab.systems.core import _exact_tables_cached  # noqa: E402


def _medians(fns, runs):
    """Median time of each function, run in turn in every round (a shared machine's
    load drifts: interleaving exposes the functions to the same load)."""
    for fn in fns:
        fn()
    ts = [[] for _ in fns]
    for _ in range(runs):
        for fn, out in zip(fns, ts, strict=True):
            t0 = time.perf_counter()
            fn()
            out.append(time.perf_counter() - t0)
    return [statistics.median(t) for t in ts]


def _err(a, b):
    return float((np.abs(a - b).max(axis=0) / np.ptp(b, axis=0)).max())


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=21)
    runs = ap.parse_args().runs
    car = quarter_car("k | (c - b)", {"k": 90e3, "c": 5e3, "b": 200.0})
    road, T = iso8608("C", 20.0, seed=1), 10.0
    t0 = time.perf_counter()
    res = car.simulate(road, T)
    print(f"first call (compilation or cache load): {time.perf_counter() - t0:.2f} s")
    print(f"core method: {res.method}, {res.stats}")
    A, B, _, _ = car.linear_state_space()
    assert not B[:, 2].any(), "no inertance at the road: the acceleration input is unused"
    x0 = res.states[0]

    def baseline():
        segs = road.segments(T)
        t = np.arange(int(round(T * 1000)) + 1) / 1000.0
        x1, _ = road_displacement(segs, t)
        ss = signal.StateSpace(A, (A @ B[:, 1] + B[:, 0])[:, None], np.eye(len(A)), B[:, 1:2])
        return signal.lsim(ss, x1, t, X0=x0 - B[:, 1] * x1[0], interp=True)[1]

    def cold():  # without the kept matrix exponentials (a new system or road grid)
        _exact_tables_cached.cache_clear()
        return car.simulate(road, T)

    t_lsim, t_core, t_cold = _medians((baseline, lambda: car.simulate(road, T), cold), runs)
    ref = car.simulate(road, T, method="adaptive", rtol=1e-12).states
    Y = res.states
    print(f"k | (c - b) / ISO 8608 C at 20 m/s, seed 1 / {T:g} s / samples every 1 ms")
    print(f"  lsim (first-order hold, states):          {t_lsim * 1e3:8.2f} ms (median of {runs})")
    print(f"  core simulate (exact steps, all outputs): {t_core * 1e3:8.2f} ms (median of {runs})")
    print(f"  the same, exponentials not kept (cold):   {t_cold * 1e3:8.2f} ms (median of {runs})")
    print(f"  core exact vs lsim, largest state error / state range:      {_err(Y, baseline()):.1e}")
    print(f"  core exact vs core adaptive rtol 1e-12, same measure:       {_err(Y, ref):.1e}")
    print(f"cold ratio: {t_lsim / t_cold:.1f}")
    print(f"ratio: {t_lsim / t_core:.1f}")


if __name__ == "__main__":
    main()
