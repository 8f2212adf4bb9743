"""The vehicle on the model core against scipy, two cases timed in this run (median of 3,
compilation excluded).

1. ``bench_vehicle_afw.py``'s case: the packaged full car with a nylon adaptive-flywheel
   inerter at every corner and tyres that lift off, 60 s of class C at 20 m/s, road
   samples 2 ms apart. The core (:func:`inerterlab.systems.vehicle.simulate`, adaptive
   Dormand-Prince with lift-off and flywheel saturation as events) at rtol 1e-6 and
   1e-8; scipy RK45 at rtol 1e-6 on the same equations in Python over the first
   ``--scipy-span`` seconds, scaled to 60 s. Accuracy: largest error of the front-left
   deflection over the scipy span relative to its peak, against the core at rtol 1e-11.
   Also fixed classical Runge-Kutta steps (``fixed_method="rk4"``) of dt (one step per
   road sample) and dt/2, events located as in the adaptive runs.
2. The thesis hydraulic device (``k | c`` strut plus ``hyd``) at both front corners of
   the packaged car, 20 s of class C at 20 m/s: the core at rtol 1e-6 and RK4 at dt and
   dt/2 (target 100 ms), their errors against the core at rtol 1e-10; wall and CPU time
   (median of 5), and the ratio to the named baseline measured in this run: case 1's
   car (adaptive inerters at the four corners, no device) over the same 20 s by RK4 at
   one step per sample. Both cases' right-hand side compiled two ways: the generic code
   and the structure's own (``INERTERLAB_SPECIALISE`` never and always; a structure
   gets its own code once its runs have taken 2 s of CPU in a process, or at once when
   an earlier process compiled it), each compilation excluded.

Run: python benchmarks/bench_vehicle_core.py [--scipy-span 3] [--case 2]
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
from inerterlab.vehicles import Strut  # noqa: E402


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
    ap.add_argument("--case", type=int, choices=(1, 2), default=None, help="one case only")
    args = ap.parse_args()
    params, car, r, dt = setup()
    core = vehicle(params)
    print(f"load average at the start: {os.getloadavg()[0]:.1f}")
    if args.case != 2:
        case1(args, params, car, r, dt, core)
    if args.case != 1:
        case2(params, r, dt, core)


def case1(args, params, car, r, dt, core) -> None:
    print("case 1: adaptive inerters at four corners, 60 s class C at 20 m/s, dt 2 ms")
    runs = {
        "core DOPRI5 rtol 1e-6": dict(rtol=1e-6),
        "core DOPRI5 rtol 1e-8": dict(rtol=1e-8),
        "core RK4 fixed dt": dict(fixed_step=dt, fixed_method="rk4"),
        "core RK4 fixed dt/2": dict(fixed_step=dt / 2, fixed_method="rk4"),
    }
    t_core = {}
    for label, kw in runs.items():
        tc, res = timed(lambda kw=kw: simulate(core, r, dt, **kw))
        t_core[label] = (tc, res.stats)
    ns = int(round(args.scipy_span / dt)) + 1
    ref = simulate(core, r[:ns], dt, rtol=1e-11).outputs["front_left_deflection"]
    scale = float(np.abs(ref).max())
    e_core = {
        label: float(np.abs(simulate(core, r[:ns], dt, **kw).outputs["front_left_deflection"]
                            - ref).max() / scale)
        for label, kw in runs.items()
    }  # fmt: skip
    rhs = python_rhs(car, params, r[:ns], dt)
    A, Br, *_ = car.state_space()
    x0 = -np.linalg.solve(A, Br @ r[0])
    t0 = time.perf_counter()
    solve_ivp(rhs, (0, dt * (ns - 1)), x0, method="RK45", rtol=1e-6, atol=1e-10)
    t_scipy = (time.perf_counter() - t0) * 60.0 / (dt * (ns - 1))
    print(f"{'solver':30s} {'time 60 s [s]':>14s} {'scipy/this':>11s} {'max rel err':>12s}")
    for label, (tc, st) in t_core.items():
        print(f"{label:30s} {tc:14.4f} {t_scipy / tc:11.0f} {e_core[label]:12.2e}   "
              f"({st['steps']} steps, {st['rhs_calls']} rhs, {st['events']} events)")  # fmt: skip
    print(f"{'scipy RK45 rtol 1e-6 (scaled)':30s} {t_scipy:14.2f}")
    for label in ("core DOPRI5 rtol 1e-6", "core RK4 fixed dt"):
        print(f"ratio scipy RK45 / {label}: {t_scipy / t_core[label][0]:.0f} "
              f"({1e3 * t_core[label][0]:.0f} ms; targets: at most 30 ms, at least 3000)")  # fmt: skip



def case2(params, r, dt, core) -> None:
    print("\ncase 2: hydraulic device at both front corners, 20 s class C at 20 m/s, dt 2 ms")
    front = replace(params.front, strut=Strut(stiffness=params.front.strut.stiffness,
                    damping=params.front.strut.damping, device=HydraulicElement()))  # fmt: skip
    p2 = replace(params, front=front)
    n20 = int(round(20.0 / dt)) + 1
    r2 = r[:n20]
    core2 = vehicle(p2)
    fine = simulate(core2, r2, dt, rtol=1e-10)
    k = "front_left_deflection"
    rk4 = dict(fixed_step=dt, fixed_method="rk4")
    t_base = {}
    for tier in ("never", "always"):  # the generic code, then the structure's own
        os.environ["INERTERLAB_SPECIALISE"] = tier
        name = "generic code" if tier == "never" else "the structure's own code"
        # the named baseline: case 1's car (adaptive inerters at four corners, no
        # device), the same 20 s, RK4 at one step per sample, this tier
        wb, cb, resb = timed_cpu(lambda: simulate(core, r2, dt, **rk4))
        t_base[tier] = (wb, cb)
        print(f"[{name}] baseline, case 1's car without the device, RK4 fixed dt: "
              f"{1e3 * wb:.0f} ms wall, {1e3 * cb:.0f} ms CPU ({resb.stats['steps']} steps, "
              f"{resb.stats['rhs_calls']} rhs, {resb.stats['events']} events)")  # fmt: skip
        for label, kw in (("core DOPRI5 rtol 1e-6", dict(rtol=1e-6)),
                          ("core RK4 fixed dt", rk4),
                          ("core RK4 fixed dt/2", dict(fixed_step=dt / 2, fixed_method="rk4"))):
            w2, c2, res2 = timed_cpu(lambda kw=kw: simulate(core2, r2, dt, **kw))
            d = float(np.abs(res2.outputs[k] - fine.outputs[k]).max()
                      / np.abs(fine.outputs[k]).max())  # fmt: skip
            st = res2.stats
            print(f"[{name}] {label}: {1e3 * w2:.0f} ms wall, {1e3 * c2:.0f} ms CPU for 20 s; "
                  f"hydraulic / baseline {w2 / wb:.2f} (wall), {c2 / cb:.2f} (CPU); "
                  f"{st['steps']} steps, {st['rejected']} rejected, {st['rhs_calls']} rhs, "
                  f"{st['events']} events; target 100 ms; error of {k} against rtol 1e-10: "
                  f"{d:.1e} of its peak")  # fmt: skip
    os.environ.pop("INERTERLAB_SPECIALISE")
    print(f"load average at the end: {os.getloadavg()[0]:.1f}")


def timed_cpu(fn, n=5):
    """(median wall time, median CPU time, last result) of n calls after a first one."""
    fn()
    walls, cpus = [], []
    for _ in range(n):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    return statistics.median(walls), statistics.median(cpus), out

if __name__ == "__main__":
    main()
