"""Full car with tyre lift-off: compiled fixed-step RK4 vs scipy solve_ivp on a Python RHS.

2 s of the packaged example car at 20 m/s on an ISO 8608 class E road (tyres lift
off), dampers 1.6x in rebound and 0.6x in compression, road sampled every 1 ms. Prints
wall time (median of 3, first compiled call excluded) and the largest error of the
front-left suspension deflection relative to its peak, against the RK4 kernel with 32
substeps per sample (itself checked against scipy DOP853 in
tests/test_vehicle_nonlinear.py). Run: python benchmarks/bench_vehicle.py
"""

import statistics
import time

import numpy as np
from scipy.integrate import solve_ivp

from inerterlab.vehicles import (
    build,
    example_vehicle_path,
    generate_tracks,
    load_vehicle,
    road_inputs,
    road_spectrum,
)
from inerterlab.vehicles.nonlinear import simulate_nonlinear

REBOUND, COMPRESSION = 1.6, 0.6
car = build(load_vehicle(example_vehicle_path()))
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


def kernel(sub):
    res = simulate_nonlinear(car, r, dt, rebound=REBOUND, compression=COMPRESSION, substeps=sub)
    return res.outputs["front_left_deflection"]


ref = kernel(32)
scale = np.abs(ref).max()

# scipy: the same equations written with the model's matrices, road by np.interp
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


kernel(1)  # compile (or load the cache) outside the timings
print(f"{'solver':20s} {'rtol':>7s} {'time [s]':>10s} {'RHS calls':>10s} {'max rel err':>12s}")
rows = []
for sub in (1, 2, 4):
    tk, y = timed(lambda sub=sub: kernel(sub))
    rows.append(
        (
            f"inerterlab RK4 x{sub}",
            "-",
            tk,
            4 * sub * (r.shape[0] - 1),
            np.abs(y - ref).max() / scale,
        )
    )
    print("{:20s} {:>7s} {:10.4f} {:10d} {:12.2e}".format(*rows[-1]), flush=True)
for method, rtol in (("RK45", 1e-6), ("DOP853", 1e-8)):
    ts, (y, nfev) = timed(lambda m=method, rt=rtol: scipy_run(m, rt), n=1)
    rows.append((f"scipy {method}", f"{rtol:g}", ts, nfev, np.abs(y - ref).max() / scale))
    print("{:20s} {:>7s} {:10.4f} {:10d} {:12.2e}".format(*rows[-1]), flush=True)
lift = simulate_nonlinear(car, r, dt, rebound=REBOUND, compression=COMPRESSION).lift_off_fraction
print(
    f"simulated {t[-1]:.2f} s; lift-off fraction per corner: "
    + ", ".join(f"{k} {v:.3f}" for k, v in lift.items())
)
