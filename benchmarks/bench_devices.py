"""Device force: compiled Dormand-Prince kernel vs scipy solve_ivp (Radau, LSODA).

Prints time, steps/evaluations and max force error against a tight reference
(solve_ivp Radau at rtol 1e-11) for the hydraulic device, thesis law, metal flywheel,
x = 0.005 sin(2 pi 1 t) for 10 s sampled at 500 Hz. Run: python benchmarks/bench_devices.py
"""

import math
import statistics
import time

import numpy as np
from scipy.integrate import solve_ivp

from inerterlab.devices import Motion, device_force, device_preset

dev = device_preset("hydraulic")
mot = Motion.sine(frequency=1.0, amplitude=0.005)
t = np.arange(5001) / 500.0
fw, r = dev.flywheel, dev.transmission.ratio
k, b, f, eps = dev.stiffness, dev.damping, dev.friction, dev.friction_velocity


def rhs(tt, y):
    v = 0.005 * 2 * math.pi * math.cos(2 * math.pi * tt)
    fin = k * y[0] - b * y[1] - f * math.tanh(y[1] / eps)
    return [v - y[1], fin / (r * r * fw.inertia(r * y[1]))]


first = device_force(dev, mot, t=t)
y0 = [first.spring_deflection[0], first.branch_velocity[0]]


def scipy_run(method, rtol):
    sol = solve_ivp(rhs, (0, t[-1]), y0, method=method, t_eval=t, rtol=rtol, atol=1e-12)
    return k * sol.y[0], sol.nfev


ref, _ = scipy_run("Radau", 1e-11)
scale = np.abs(ref).max()


def timed(fn, n=3):
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


rows = []
for rtol in (1e-6, 1e-8):
    tk, res = timed(lambda rtol=rtol: device_force(dev, mot, t=t, rtol=rtol))
    rows.append(("inerterlab DP5(4)", rtol, tk, res.steps, np.abs(res.force - ref).max() / scale))
    for method in ("Radau", "LSODA"):
        ts, (fs, nfev) = timed(lambda m=method, rtol=rtol: scipy_run(m, rtol), n=1)
        rows.append((f"scipy {method}", rtol, ts, nfev, np.abs(fs - ref).max() / scale))
print(f"{'solver':20s} {'rtol':>7s} {'time [s]':>10s} {'steps/nfev':>11s} {'max rel err':>12s}")
for name, rtol, tt, n, err in rows:
    print(f"{name:20s} {rtol:7.0e} {tt:10.4f} {n:11d} {err:12.2e}")
base = {rtol: tt for name, rtol, tt, _, _ in rows if name == "scipy Radau"}
for name, rtol, tt, _, _ in rows:
    if name.startswith("inerterlab"):
        print(f"speed-up vs scipy Radau at rtol {rtol:.0e}: {base[rtol] / tt:.1f}x")
