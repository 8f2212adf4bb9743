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

With ``--model quarter``: the quarter car's ``body_acc_wk`` (the RMS of the ISO 2631-1
Wk-weighted body acceleration, H2 by Lyapunov with the Wk filter as states) in the H2
optimiser of ``inerterlab network optimize`` / the design's layout stage, for every
layout of the default budget (2 springs, 1 damper, 1 inerter) on the thesis car with the
main spring held at 90 kN/m:

- exact: the adjoint of the cascade's Lyapunov equations
  (``h2.h2_rational_filtered_gradient``), the optimiser's route;
- baseline: central differences in the leaves' logarithms (one compiled batch of
  2 n + 1 values per gradient), the optimiser's former route for this objective.

Prints per layout and in total the CPU seconds of the whole optimisation (Sobol sample,
differential evolution, polish), the optima, and the ratio baseline / exact; and the
CPU time of one gradient by each route.

Run: python benchmarks/bench_design_gradient.py [--model full|half|quarter] [layout ...]
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
    ap.add_argument("--model", choices=("full", "half", "quarter"), default="full")
    ap.add_argument("layouts", nargs="*")
    args = ap.parse_args()
    if args.model == "quarter":
        quarter(args.layouts)
        return
    args.layouts = args.layouts or ["k | c", "k | (c - b)", "k | c | (k1 - b)",
                                    "k | (b - (k1 | c))"]  # fmt: skip
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


def quarter(layouts) -> None:
    from inerterlab import network_design as nd
    from inerterlab.networks import enumerate_networks
    from inerterlab.suspension.network_linear import network_quarter_car

    car = {"sprung_mass": 370.0, "unsprung_mass": 25.0, "tyre_stiffness": 120e3,
           "tyre_damping": 1300.0}  # fmt: skip
    layouts = layouts or [n.text for n in enumerate_networks(1, 1, 2)]
    exact_set = nd._EXACT
    central_set = tuple(i for i in exact_set if i != nd.QUANTITIES.index("body_acc_wk"))

    def run(route, net):
        nd._EXACT = exact_set if route == "exact" else central_set
        try:
            c0 = time.process_time()
            r = nd.optimize_network(net, "body_acc_wk", fixed={"k": 9e4}, compare=False,
                                    simplify=False, **car)  # fmt: skip
            return time.process_time() - c0, r
        finally:
            nd._EXACT = exact_set

    # one gradient by each route (a layout with six leaves), after a first call of each
    q = network_quarter_car("k | c | (k1 - b) | (c1 - k2)", **car)
    th = q.theta({"k": 5e4, "c": 2e3, "k1": 3e4, "b": 80.0, "c1": 900.0, "k2": 4e4})
    g = np.empty(len(th))
    per = {}
    for route in ("exact", "central"):
        nd._EXACT = exact_set if route == "exact" else central_set
        nd._quantity_gradient(q, th, 3, g)
        c0 = time.process_time()
        for _ in range(2000):
            nd._quantity_gradient(q, th, 3, g)
        per[route] = (time.process_time() - c0) / 2000
    nd._EXACT = exact_set
    run("exact", "k | c")  # compiled kernels loaded before timing
    print(f"load average (1 min) at the start {os.getloadavg()[0]:.1f} (other work on the machine)")
    print(f"one gradient of body_acc_wk^2 (6 leaves): exact {1e6 * per['exact']:.0f} us CPU, "
          f"central differences {1e6 * per['central']:.0f} us, ratio "
          f"{per['central'] / per['exact']:.1f}")  # fmt: skip
    tot = {"exact": 0.0, "central": 0.0}
    worst = 0.0
    for net in layouts:
        row = {route: run(route, net) for route in ("exact", "central")}
        (ce, re_), (cc, rc) = row["exact"], row["central"]
        tot["exact"] += ce
        tot["central"] += cc
        if math.isfinite(re_.objective) and math.isfinite(rc.objective):
            worst = max(worst, abs(re_.objective / rc.objective - 1.0))
        print(f"{net:>26}: exact {ce:5.2f} s CPU, body_acc_wk {re_.objective:.10g} | central "
              f"differences {cc:5.2f} s, {rc.objective:.10g} | ratio {cc / ce:.2f}")  # fmt: skip
    print(f"total: exact {tot['exact']:.1f} s CPU, central differences {tot['central']:.1f} s CPU, "
          f"ratio {tot['central'] / tot['exact']:.2f}; largest relative difference of the optima "
          f"{worst:.1e} (body_acc_wk H2 norm per unit white road velocity [m/s^2], thesis car, "
          f"k = 90 kN/m held)")  # fmt: skip


if __name__ == "__main__":
    main()
