"""The vehicle's frequency response and what is built on it: one batched solve against a
loop over frequencies.

Cases (the example full car of ``inerterlab.vehicles.example_vehicle_path()``):

* ``LinearVehicle.frequency_response`` at 1500 logarithmic frequencies from 0.1 to 80
  Hz, every output: the package (``h2.resolvent_solve``, a block of frequencies per
  batched LAPACK solve) against the baseline written here, a Python loop that solves
  (s I - A) X = Br + s Bd with ``numpy.linalg.solve`` at each frequency and forms each
  output (what the package did before, docs/decisions.md "One frequency-domain solve").
  Accuracy: the largest difference between the two, relative to the largest response.
* ``optimize_vehicle(parameters=("front_damping", "rear_damping"))`` (the spectral
  comfort objective, about 200 evaluations of the response): the package's time, and
  the time with the baseline loop put in place of the package's response in the same
  run; the optimum of both (they must agree to rounding).

Prints median CPU times and ``ratio: N`` = baseline / package for each case.

Usage: python benchmarks/bench_vehicle_frequency.py [--runs 7] [--optimize-runs 1]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from inerterlab.vehicles import example_vehicle_path, linear_vehicle, load_vehicle  # noqa: E402
from inerterlab.vehicles.design import optimize_vehicle  # noqa: E402
from inerterlab.vehicles.linear import LinearVehicle  # noqa: E402


def loop_response(self, freq_hz, outputs=None) -> dict:
    """The baseline: one ``numpy.linalg.solve`` per frequency, in Python."""
    A, Br, Bd, Cy, Dr, Dd = self._ss
    f = np.atleast_1d(np.asarray(freq_hz, dtype=float))
    names = list(outputs or self.outputs)
    out = {k: np.empty((f.size, Br.shape[1]), complex) for k in names}
    eye = np.eye(A.shape[0])
    for i, fi in enumerate(f):
        s = 2j * math.pi * fi
        X = np.linalg.solve(s * eye - A, Br + s * Bd)
        for k in names:
            out[k][i] = Cy[k] @ X + Dr[k] + s * Dd[k]
    return out


def _cpu(fn):
    t = time.process_time()
    r = fn()
    return time.process_time() - t, r


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--optimize-runs", type=int, default=1)
    a = ap.parse_args()

    car = linear_vehicle(load_vehicle(example_vehicle_path()))
    f = np.geomspace(0.1, 80.0, 1500)
    package = LinearVehicle.frequency_response
    car.frequency_response(f)  # warm: the state space is built once per car
    loop_response(car, f)
    tp, tb = [], []
    for _ in range(a.runs):
        t, hp = _cpu(lambda: package(car, f))
        tp.append(t)
        t, hb = _cpu(lambda: loop_response(car, f))
        tb.append(t)
    peak = max(np.max(np.abs(h)) for h in hb.values())
    err = max(np.max(np.abs(hp[k] - hb[k])) for k in hb) / peak
    mp, mb = statistics.median(tp), statistics.median(tb)
    print(f"full car, {car._ss[0].shape[0]} states, "
          f"{f.size} frequencies, {len(hb)} outputs")  # fmt: skip
    print(f"  frequency response: package {mp * 1e3:.2f} ms CPU, loop {mb * 1e3:.2f} ms CPU "
          f"(medians of {a.runs}); ratio: {mb / mp:.1f}")  # fmt: skip
    print(f"  largest difference: {err:.2e} of the largest response")

    po, bo = [], []
    for _ in range(a.optimize_runs):
        t, rp = _cpu(lambda: optimize_vehicle(parameters=("front_damping", "rear_damping")))
        po.append(t)
        LinearVehicle.frequency_response = loop_response
        try:
            t, rb = _cpu(lambda: optimize_vehicle(parameters=("front_damping", "rear_damping")))
        finally:
            LinearVehicle.frequency_response = package
        bo.append(t)
    mp, mb = statistics.median(po), statistics.median(bo)
    print(f"  optimize_vehicle(front_damping, rear_damping): package {mp:.2f} s CPU, loop "
          f"{mb:.2f} s CPU (medians of {a.optimize_runs}); ratio: {mb / mp:.1f}")  # fmt: skip
    print(f"  optimum comfort_wk (spectral, expected value, m/s^2): package {rp.value:.15g}, "
          f"loop {rb.value:.15g}, relative difference {abs(rp.value / rb.value - 1):.1e}")  # fmt: skip


if __name__ == "__main__":
    main()
