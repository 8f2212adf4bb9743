"""CPU time of the vehicle design's layout search: exact gradients against central
differences, the same search otherwise, measured in the same run.

For each layout of a list (default: four of the default budget's) at every corner of
the packaged example full car, objective seat_wk on ISO 8608 class C at 25 m/s, the
per-axle values (main spring held at the wheel rate) are searched by L-BFGS-B in their
logarithms from the geometric middle of the element's design range, with

- the exact gradient (``design.vehicle.linear_objective_gradient``: adjoint Lyapunov
  equations, the core matrices' derivatives), the design's route;
- the baseline: central differences of the objective with step 1e-4 in the
  logarithms (the design's former route; 2 n evaluations per gradient).

Prints per layout and in total the process CPU seconds, the objective evaluations and
the optimum of each, and the ratio baseline / exact.

Run: python benchmarks/bench_design_gradient.py [--model full|half] [layout ...]
"""

from __future__ import annotations

import argparse
import math
import os
import time
import warnings

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--model", choices=("full", "half"), default="full")
    ap.add_argument("layouts", nargs="*", default=["k | c", "k | (c - b)", "k | c | (k1 - b)",
                                                   "k | (b - (k1 | c))"])  # fmt: skip
    args = ap.parse_args()
    warnings.simplefilter("ignore", RuntimeWarning)
    from scipy.optimize import minimize

    from inerterlab.design.vehicle import (
        AXLES,
        axle_stiffness,
        linear_objective,
        linear_objective_gradient,
        vehicle_car,
    )
    from inerterlab.network_design import design_parameters
    from inerterlab.vehicles import example_vehicle_path

    car = vehicle_car(example_vehicle_path().read_text(), "file" if args.model == "full" else "half")
    ks = axle_stiffness(car)
    print(f"load average (1 min) at the start {os.getloadavg()[0]:.1f} (other work on the machine)")
    tot = {"exact": 0.0, "central": 0.0}
    for net in args.layouts:
        dp = design_parameters(net)
        names = [n for n in dp if n != "k"]
        var = [f"{a}_{n}" for a in AXLES for n in names]
        lo = np.array([math.log(dp[n].design[0]) for _a in AXLES for n in names])
        hi = np.array([math.log(dp[n].design[1]) for _a in AXLES for n in names])

        def values(x, var=var, lo=lo, hi=hi):
            out = {f"{a}_k": ks[a] for a in AXLES}
            out.update(dict(zip(var, np.exp(np.clip(x, lo, hi)), strict=True)))
            return out

        count = [0]

        def f(x, net=net, values=values, count=count):
            count[0] += 1
            v = linear_objective(car, net, values(x), "seat_wk", "C", 25.0)
            return v if math.isfinite(v) else 1e6

        def fd(x, f=f):
            g = np.empty(x.size)
            for i in range(x.size):
                e = np.zeros(x.size)
                e[i] = 1e-4
                g[i] = (f(x + e) - f(x - e)) / 2e-4
            return g

        def fg(x, net=net, values=values, var=var, count=count):
            count[0] += 1
            v, g = linear_objective_gradient(car, net, values(x), "seat_wk", "C", 25.0, var)
            return (v, g) if math.isfinite(v) else (1e6, np.zeros(x.size))

        row = {}
        for name, kw in (("exact", dict(fun=fg, jac=True)), ("central", dict(fun=f, jac=fd))):
            count[0] = 0
            c0 = time.process_time()
            r = minimize(x0=0.5 * (lo + hi), method="L-BFGS-B", bounds=list(zip(lo, hi, strict=True)),
                         options={"maxiter": 100, "ftol": 1e-10, "gtol": 1e-5}, **kw)  # fmt: skip
            cpu = time.process_time() - c0
            tot[name] += cpu
            row[name] = (cpu, count[0], float(r.fun), r.nit)
        e, c = row["exact"], row["central"]
        print(f"{net:>22}: exact {e[0]:6.2f} s CPU, {e[1]:4d} evaluations, {e[3]:3d} iterations, "
              f"seat_wk {e[2]:.8g} m/s^2 | central differences {c[0]:6.2f} s, {c[1]:4d} evaluations, "
              f"{c[3]:3d} iterations, seat_wk {c[2]:.8g} m/s^2 | ratio {c[0] / e[0]:.1f}")  # fmt: skip
    print(f"total: exact {tot['exact']:.1f} s CPU, central differences {tot['central']:.1f} s CPU, "
          f"ratio {tot['central'] / tot['exact']:.1f} (seat_wk, {args.model} car, RMS linear "
          f"under white road velocity, class C at 25 m/s)")  # fmt: skip


if __name__ == "__main__":
    main()
