"""Full car with an adaptive inerter at every corner: the model core vs scipy solve_ivp.

The packaged example car with, at each corner, a nylon adaptive-flywheel inerter in
parallel with the strut (changing ratio 28.5 %, thesis law, 150 kg at rest), tyres that
lift off, driven 60 s over an ISO 8608 class C road at 20 m/s (road sampled every
2 ms). Prints the wall time and the CPU time (medians of 7, compilation excluded: the
car's own compiled right-hand side, :func:`inerterlab.systems._compiled.specialised`, is
built or loaded before the timings, as a long study gets it after its first 2 s of CPU;
the load average beside them; and once, before it is built, RK4 at one step per sample
with the generic right-hand side, what a process's first runs get) for the 60 s run of the
core vehicle (:func:`inerterlab.systems.vehicle.simulate`, adaptive Dormand-Prince with
lift-off and flywheel saturation as events) at rtol 1e-6 and 1e-8, with fixed classical
Runge-Kutta steps (``fixed_method="rk4"``, no error control, the same events located)
of the road's sample interval dt (one step per sample) and of dt/2, and of
``vehicle simulate``'s route (:func:`inerterlab.vehicles.simulation.simulate_vehicle`:
the same with the ISO 2631 comfort observers as states), and of scipy's RK45 (rtol
1e-6) and DOP853 (rtol 1e-9) on the same
equations written in Python with the flywheel's numpy law
(:meth:`AdaptiveFlywheel.inertia`, not the compiled one) over the first ``--scipy-span``
seconds (default 6 s), scaled to 60 s; the ratio of the two per simulated second; and
the accuracy: the largest error of the front-left deflection over the scipy span,
relative to its peak, of each solver against DOP853 at rtol 1e-11. The ratios are given
in wall-clock time and in CPU time (on a loaded machine the CPU time is the steadier).

Run: python benchmarks/bench_vehicle_afw.py [--scipy-span 6]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

from inerterlab.systems import _compiled  # noqa: E402
from inerterlab.systems.vehicle import _factored, simulate, vehicle  # noqa: E402
from inerterlab.vehicles import (  # noqa: E402
    example_vehicle_path,
    generate_tracks,
    loads_vehicle,
    road_inputs,
    road_spectrum,
)
from inerterlab.vehicles.simulation import simulate_vehicle  # noqa: E402

# the scipy baseline's equations: the hand-assembled M, C, K oracle of the tests
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from _vehicle_oracle import build  # noqa: E402

#: timed runs of each solver (the median is printed: the machine may be shared)
RUNS = 7

ADAPTIVE = (
    'adaptive = { flywheel = "nylon", changing_ratio = 0.285, law = "thesis", '
    'rest_inertance = "150 kg" }\n'
)


def setup():
    text = example_vehicle_path().read_text()
    text = text.replace('inertance = "0 kg"\n', 'inertance = "0 kg"\n' + ADAPTIVE)
    params = loads_vehicle(text)
    car = build(params)
    speed, dt = 20.0, 2e-3
    length = 60.0 * speed + params.wheelbase + 2 * speed * dt
    x, zl, zr = generate_tracks(road_spectrum("C"), length=length, step=speed * dt, seed=11)
    r = road_inputs(car, x, zl, zr, speed, dt)[: int(round(60.0 / dt)) + 1]
    return params, car, r, dt


def python_rhs(car, params, r, dt):
    """The same equations in Python (numpy flywheel law), road linear between samples."""
    M0 = car.matrices()[0]
    n = len(car.dofs)
    static = car.static_tyre_loads()
    cons = car.connections
    slopes = np.vstack([np.diff(r, axis=0) / dt, np.zeros((1, r.shape[1]))])
    struts = []
    for c in cons:
        law = c.law
        a = getattr(law, "adaptive", None)
        if a is not None:
            struts.append((c.u, a.ratio, a.wheel, a.inertance_min))

    def rhs(t, x):
        i = min(int(t / dt), r.shape[0] - 2)
        slope = slopes[i]
        rr = r[i] + slope * (t - i * dt)
        q, qd = x[:n], x[n:]
        gen = np.zeros(n)
        for c in cons:
            b, cc, k = c.law.mck()
            d = c.u @ q - c.v @ rr
            dd = c.u @ qd - c.v @ slope
            f = k * d + cc * dd
            if c.name.endswith("_tyre"):
                f = min(f, static[c.name[:-5]])
            gen -= c.u * f
        M = M0.copy()
        for u, ratio, wheel, me0 in struts:
            v = u @ qd
            me = ratio**2 * wheel.inertia(abs(ratio * v))
            M += (me - me0) * np.outer(u, u)
        return np.concatenate([qd, np.linalg.solve(M, gen)])

    return rhs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scipy-span", type=float, default=6.0)
    args = ap.parse_args()
    params, car, r, dt = setup()
    t = dt * np.arange(r.shape[0])
    out = car.outputs["front_left_deflection"].P
    core = vehicle(params)
    # first RK4 with the generic right-hand side: what a process's first runs of a new
    # structure get (its own code comes after 2 s of CPU, or from the disk if an earlier
    # process compiled it)
    os.environ["INERTERLAB_SPECIALISE"] = "never"
    rk4 = lambda rr: simulate(core, rr, dt, fixed_step=dt, fixed_method="rk4")  # noqa: E731
    rk4(r[:10])
    gw, gc = [], []
    for _ in range(3):
        t0, c0 = time.perf_counter(), time.process_time()
        rk4(r)
        gw.append(time.perf_counter() - t0)
        gc.append(time.process_time() - c0)
    del os.environ["INERTERLAB_SPECIALISE"]
    # the structure's own code (compiled once per package version, then loaded from disk)
    tier = _compiled.specialised(_factored(core)[0])
    # and that of simulate_vehicle's system (the car with the comfort observers, another
    # structure, built by its first call and kept on the car): without it, its timings
    # are of the generic code, or of that code while its own compiles beside it
    simulate_vehicle(params, r[:10], dt, system=core)
    _compiled.specialised(_factored(core.info["comfort_observed"][1])[0])
    load = os.getloadavg()[0]
    solvers = {
        "core DOPRI5 rtol 1e-6": lambda rr: simulate(core, rr, dt, rtol=1e-6),
        "core DOPRI5 rtol 1e-8": lambda rr: simulate(core, rr, dt, rtol=1e-8),
        "simulate_vehicle 1e-6": lambda rr: simulate_vehicle(params, rr, dt, system=core),
        "core RK4 fixed dt": lambda rr: simulate(core, rr, dt, fixed_step=dt, fixed_method="rk4"),
        "core RK4 fixed dt/2": lambda rr: simulate(core, rr, dt, fixed_step=dt / 2,
                                                   fixed_method="rk4"),
    }  # fmt: skip
    times, cpus, stats = {}, {}, {}
    for name, fn in solvers.items():
        fn(r[:10])  # compile / load the cache
        fn(r)  # and one whole run untimed: the first solver's first runs paid for the
        # process's first large arrays (30 ms more for Dormand-Prince at 1e-6 than at 1e-8)
        runs, cpu = [], []
        for _ in range(RUNS):
            t0, c0 = time.perf_counter(), time.process_time()
            res = fn(r)
            runs.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        times[name], cpus[name] = statistics.median(runs), statistics.median(cpu)
        stats[name] = res.stats
    # accuracy over the scipy span against a tight DOP853 run of the Python equations
    ns = int(round(args.scipy_span / dt)) + 1
    rs, ts = r[:ns], t[:ns]
    rhs = python_rhs(car, params, rs, dt)
    A, Br, *_ = car.state_space()
    x0 = -np.linalg.solve(A, Br @ rs[0])
    ref = solve_ivp(rhs, (0, ts[-1]), x0, method="DOP853", t_eval=ts, rtol=1e-11, atol=1e-12)
    yref = ref.y[: len(car.dofs)].T @ out
    scale = float(np.abs(yref).max())
    print(f"simulated 60 s (core) and {ts[-1]:.1f} s (scipy) of class C at 20 m/s, dt {dt} s")
    print(f"load average (1 min) at the start of the timings: {load:.1f}; times: wall clock, "
          f"median of {RUNS} (CPU time of the process beside it)")  # fmt: skip
    print(f"core right-hand side: {tier!r}")
    print(f"{'solver':24s} {'time 60 s [s]':>14s} {'CPU [s]':>8s} {'scipy RK45/this':>16s} "
          f"{'max rel err':>12s}")  # fmt: skip
    errs = {}
    for name, fn in solvers.items():
        y = fn(rs).outputs["front_left_deflection"]
        errs[name] = float(np.abs(y - yref).max() / scale)
    base = {}
    for method, rtol in (("RK45", 1e-6), ("DOP853", 1e-9)):
        t0, c0 = time.perf_counter(), time.process_time()
        sol = solve_ivp(rhs, (0, ts[-1]), x0, method=method, t_eval=ts, rtol=rtol, atol=1e-10)
        el = (time.perf_counter() - t0) * 60.0 / ts[-1]
        cpu = (time.process_time() - c0) * 60.0 / ts[-1]
        e = float(np.abs(sol.y[: len(car.dofs)].T @ out - yref).max() / scale)
        base[method] = (el, e, cpu)
    for name in solvers:
        st = stats[name]
        print(f"{name:24s} {times[name]:14.4f} {cpus[name]:8.4f} {base['RK45'][0] / times[name]:16.0f} "
              f"{errs[name]:12.2e}   ({st['steps']} steps, {st['rhs_calls']} rhs, "
              f"{st['events']} events)")  # fmt: skip
    for method, (el, e, cpu) in base.items():
        print(f"{'scipy ' + method:24s} {el:14.2f} {cpu:8.2f} {'':16s} {e:12.2e}")
    first = next(iter(solvers))
    print(
        f"ratio scipy RK45 / core at rtol 1e-6: {base['RK45'][0] / times[first]:.0f} "
        f"(core {1e3 * times[first]:.0f} ms for 60 s)"
    )
    fx = "core RK4 fixed dt"
    print(
        f"ratio scipy RK45 / core RK4 one step per sample: {base['RK45'][0] / times[fx]:.0f} "
        f"(core {1e3 * times[fx]:.0f} ms for 60 s, error {errs[fx]:.1e} of the peak; "
        f"targets: at most 30 ms, at least 3000)"
    )
    print(
        f"core RK4 one step per sample with the generic right-hand side (a process's first "
        f"runs): {1e3 * statistics.median(gw):.0f} ms wall, {1e3 * statistics.median(gc):.0f} "
        f"ms CPU; scipy RK45 / that {base['RK45'][0] / statistics.median(gw):.0f} (wall), "
        f"{base['RK45'][2] / statistics.median(gc):.0f} (CPU)"
    )
    print(
        f"in CPU time: scipy RK45 / core at rtol 1e-6 {base['RK45'][2] / cpus[first]:.0f}, "
        f"scipy RK45 / core RK4 one step per sample {base['RK45'][2] / cpus[fx]:.0f} "
        f"(core {1e3 * cpus[first]:.0f} and {1e3 * cpus[fx]:.0f} ms of CPU)"
    )
    assert math.isfinite(errs[first])


if __name__ == "__main__":
    main()
