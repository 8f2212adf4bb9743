"""The vehicle on the model core against the vehicle's own RK4 kernel and scipy.

Two cases, each timed in this run (median of 3, compilation excluded):

1. ``bench_vehicle_afw.py``'s case: the packaged full car with a nylon adaptive-flywheel
   inerter at every corner and tyres that lift off, 60 s of class C at 20 m/s, road
   samples 2 ms apart. The core (:func:`inerterlab.systems.vehicle.simulate`, adaptive
   Dormand-Prince with lift-off and flywheel saturation as events) at rtol 1e-6 and
   1e-8; the vehicle kernel's RK4 (one step per sample, as ``vehicle simulate`` runs);
   scipy RK45 at rtol 1e-6 on the same equations in Python over the first
   ``--scipy-span`` seconds, scaled to 60 s. Accuracy: largest error of the front-left
   deflection over the first 6 s relative to its peak, against the RK4 with 64 steps per
   sample.
2. The thesis hydraulic device (``k | c`` strut plus ``hyd``) at both front corners of
   the packaged car, 20 s of class C at 20 m/s: the core at rtol 1e-6 against the
   vehicle kernel's RK4 with 4 steps per sample (the device rig inside it).

Run: python benchmarks/bench_vehicle_core.py [--scipy-span 3]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).parent))

import numpy as np  # noqa: E402
from bench_vehicle_afw import python_rhs, setup  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

from inerterlab.elements import HydraulicElement  # noqa: E402
from inerterlab.systems.vehicle import simulate, vehicle  # noqa: E402
from inerterlab.vehicles import Strut, build  # noqa: E402
from inerterlab.vehicles.nonlinear import simulate_nonlinear  # noqa: E402


def timed(fn, n=3):
    fn()
    runs = []
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        runs.append(time.perf_counter() - t0)
    return statistics.median(runs), out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scipy-span", type=float, default=3.0)
    args = ap.parse_args()
    params, car, r, dt = setup()
    core = vehicle(params)
    print("case 1: adaptive inerters at four corners, 60 s class C at 20 m/s, dt 2 ms")
    t_rk4, _ = timed(lambda: simulate_nonlinear(car, r, dt))
    t_core = {}
    for rtol in (1e-6, 1e-8):
        t_core[rtol], res = timed(lambda rtol=rtol: simulate(core, r, dt, rtol=rtol))
        t_core[rtol] = (t_core[rtol], res.stats)
    n6 = int(round(6.0 / dt)) + 1
    ref = simulate_nonlinear(car, r[:n6], dt, substeps=64).outputs["front_left_deflection"]
    scale = float(np.abs(ref).max())

    def err(y):
        return float(np.abs(y[:n6] - ref).max() / scale)

    e_rk4 = err(simulate_nonlinear(car, r[:n6], dt).outputs["front_left_deflection"])
    e_core = {
        rt: err(simulate(core, r[:n6], dt, rtol=rt).outputs["front_left_deflection"])
        for rt in t_core
    }
    ns = int(round(args.scipy_span / dt)) + 1
    rhs = python_rhs(car, params, r[:ns], dt)
    A, Br, *_ = car.state_space()
    x0 = -np.linalg.solve(A, Br @ r[0])
    t0 = time.perf_counter()
    solve_ivp(rhs, (0, dt * (ns - 1)), x0, method="RK45", rtol=1e-6, atol=1e-10)
    t_scipy = (time.perf_counter() - t0) * 60.0 / (dt * (ns - 1))
    print(f"{'solver':30s} {'time 60 s [s]':>14s} {'scipy/this':>11s} {'max rel err 6 s':>16s}")
    print(f"{'vehicle RK4 kernel x1':30s} {t_rk4:14.4f} {t_scipy / t_rk4:11.0f} {e_rk4:16.2e}")
    for rt, (tc, st) in t_core.items():
        label = f"core DOPRI5 rtol {rt:g}"
        print(f"{label:30s} {tc:14.4f} {t_scipy / tc:11.0f} {e_core[rt]:16.2e}   "
              f"({st['steps']} steps, {st['rhs_calls']} rhs, {st['events']} events)")  # fmt: skip
    print(f"{'scipy RK45 rtol 1e-6 (scaled)':30s} {t_scipy:14.2f}")
    print(f"ratio core(1e-6) / vehicle RK4 kernel time: {t_core[1e-6][0] / t_rk4:.1f}")

    print("\ncase 2: hydraulic device at both front corners, 20 s class C at 20 m/s, dt 2 ms")
    front = replace(params.front, strut=Strut(stiffness=params.front.strut.stiffness,
                    damping=params.front.strut.damping, device=HydraulicElement()))  # fmt: skip
    p2 = replace(params, front=front)
    car2 = build(p2)
    n20 = int(round(20.0 / dt)) + 1
    r2 = r[:n20]
    core2 = vehicle(p2)
    t_old2, old2 = timed(lambda: simulate_nonlinear(car2, r2, dt, substeps=4))
    t_c2, res2 = timed(lambda: simulate(core2, r2, dt, rtol=1e-6))
    k = "front_left_deflection"
    d = float(np.abs(res2.outputs[k] - old2.outputs[k]).max() / np.abs(old2.outputs[k]).max())
    print(f"vehicle RK4 kernel x4: {1e3 * t_old2:.0f} ms; core DOPRI5 rtol 1e-6: "
          f"{1e3 * t_c2:.0f} ms ({res2.stats['steps']} steps); ratio core/kernel "
          f"{t_c2 / t_old2:.1f}; max difference of {k} {d:.1e} of its peak")  # fmt: skip


if __name__ == "__main__":
    main()
