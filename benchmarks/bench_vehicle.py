"""Full car with tyre lift-off and asymmetric dampers: the model core vs scipy solve_ivp
on a Python right-hand side.

2 s of the packaged example car at 20 m/s on an ISO 8608 class E road (tyres lift
off), dampers 1.6x in rebound and 0.6x in compression, road sampled every 1 ms. Prints
wall time (median of 3, first compiled call excluded) and the largest error of the
front-left suspension deflection relative to its peak, against the core at rtol 1e-11
(checked against scipy DOP853 on hand-written equations in tests/test_vehicle_time.py).
Run: python benchmarks/bench_vehicle.py
"""

import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from inerterlab.vehicles import (
    example_vehicle_path,
    generate_tracks,
    load_vehicle,
    road_inputs,
    road_spectrum,
)
from inerterlab.vehicles.simulation import simulate_vehicle

# the scipy baseline's equations: the hand-assembled M, C, K oracle of the tests
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from _vehicle_oracle import build  # noqa: E402

REBOUND, COMPRESSION = 1.6, 0.6
params = load_vehicle(example_vehicle_path())
car = build(params)
speed, dt = 20.0, 1e-3
x, zl, zr = generate_tracks(road_spectrum("E"), length=45.0, step=speed * dt, seed=5)
r = road_inputs(car, x, zl, zr, speed, dt)
t = dt * np.arange(r.shape[0])
out = car.outputs["front_left_deflection"].P


def timed(fn, n=3):
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        res = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), res


def core(rtol):
    res = simulate_vehicle(params, r, dt, rebound=REBOUND, compression=COMPRESSION, rtol=rtol)
    return res.outputs["front_left_deflection"], res.stats["rhs_calls"]


ref = core(1e-11)[0]
scale = np.abs(ref).max()

# scipy: the same equations written with the oracle's matrices, road by np.interp
M, C, K, Kr, Cr = car.matrices()
Minv = np.linalg.inv(M)
n = len(car.dofs)
static = car.static_tyre_loads()
struts = [c for c in car.connections if c.name.endswith("_strut")]
tyres = [c for c in car.connections if c.name.endswith("_tyre")]
slopes = np.vstack([np.diff(r, axis=0) / dt, np.zeros((1, r.shape[1]))])


def rhs(tt, xx):
    i = min(int(tt / dt), r.shape[0] - 2)
    slope = slopes[i]
    rr = r[i] + slope * (tt - i * dt)
    q, qd = xx[:n], xx[n:]
    f = -K @ q - C @ qd + Kr @ rr + Cr @ slope
    for con in struts:
        dd = con.u @ qd
        c = con.law.damping
        f += con.u * (c * dd - (REBOUND if dd > 0 else COMPRESSION) * c * dd)
    for con in tyres:
        _, c, k = con.law.mck()
        total = (
            static[con.name[:-5]] - k * (con.u @ q - con.v @ rr) - c * (con.u @ qd - con.v @ slope)
        )
        if total < 0:
            f -= con.u * total
    return np.concatenate([qd, Minv @ f])


A, Br, *_ = car.state_space()
x0 = -np.linalg.solve(A, Br @ r[0])


def scipy_run(method, rtol):
    sol = solve_ivp(rhs, (0, t[-1]), x0, method=method, t_eval=t, rtol=rtol, atol=1e-10)
    return sol.y[:n].T @ out, sol.nfev


print(f"{'solver':20s} {'rtol':>7s} {'time [s]':>10s} {'RHS calls':>10s} {'max rel err':>12s}")
rows = []
for rtol in (1e-4, 1e-6, 1e-8):
    tk, (y, calls) = timed(lambda rtol=rtol: core(rtol))
    rows.append(("inerterlab core", f"{rtol:g}", tk, calls, np.abs(y - ref).max() / scale))
    print("{:20s} {:>7s} {:10.4f} {:10d} {:12.2e}".format(*rows[-1]), flush=True)
for method, rtol in (("RK45", 1e-6), ("DOP853", 1e-8)):
    ts, (y, nfev) = timed(lambda m=method, rt=rtol: scipy_run(m, rt), n=1)
    rows.append((f"scipy {method}", f"{rtol:g}", ts, nfev, np.abs(y - ref).max() / scale))
    print("{:20s} {:>7s} {:10.4f} {:10d} {:12.2e}".format(*rows[-1]), flush=True)
lift = simulate_vehicle(params, r, dt, rebound=REBOUND, compression=COMPRESSION).lift_off_fraction
print(
    f"simulated {t[-1]:.2f} s; lift-off fraction per corner: "
    + ", ".join(f"{k} {v:.3f}" for k, v in lift.items())
)
