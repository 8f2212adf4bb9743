"""Device force on the model core's rig against scipy solve_ivp, measured in this run
(the figures against the device models' former kernel, measured by this script before
that kernel was deleted, are in docs/decisions.md, "The device rig on the model core").

1. First-compilation cost: a fresh interpreter with an empty numba cache runs one
   device force (each path) and reports the wall time of that first call.
2. Per-run time (median of 5, compiled, cached rig) for three devices over 10 s at
   500 Hz: hydraulic (thesis law, metal flywheel, x = 5 mm sin(2 pi t)), screw with
   0.2 mm backlash (2 Hz, 4 mm), rectifier with a free-wheeling flywheel and bearing
   drag 2e-3 N m s/rad (2 Hz, 4 mm).
3. Work-precision for the hydraulic device against scipy solve_ivp (Radau, LSODA) on
   the same equations, errors against Radau at rtol 1e-11.

Run: python benchmarks/bench_devices.py
"""

import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.integrate import solve_ivp

from inerterlab.devices import Motion, device_force, device_preset

FIRST_CALL = """
import time
t0 = time.perf_counter()
from inerterlab.devices import Motion, device_preset
{imp}
f(device_preset("hydraulic"), Motion.sine(frequency=1.0, amplitude=0.005), duration=1.0)
print(time.perf_counter() - t0)
"""


def first_call(imp: str) -> float:
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, NUMBA_CACHE_DIR=d)
        out = subprocess.run([sys.executable, "-c", FIRST_CALL.format(imp=imp)], env=env,
                             capture_output=True, text=True, check=True)  # fmt: skip
    return float(out.stdout.split()[-1])


def timed(fn, n=5):
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


print("1. first call with an empty numba cache [s] (import + compile + run)")
core_first = first_call("from inerterlab.devices import device_force as f")
print(f"   core rig:          {core_first:7.1f}")

t = np.arange(5001) / 500.0
CASES = [
    ("hydraulic, thesis law", device_preset("hydraulic"), Motion.sine(frequency=1.0, amplitude=0.005)),
    ("screw, 0.2 mm backlash", device_preset("screw", backlash=2e-4),
     Motion.sine(frequency=2.0, amplitude=0.004)),
    ("rectifier, free-wheeling, drag", device_preset("rectifier", freewheel=True, flywheel_drag=2e-3),
     Motion.sine(frequency=2.0, amplitude=0.004)),
]  # fmt: skip
print("\n2. per run, 10 s at 500 Hz, rtol 1e-8 [ms]")
for name, dev, mot in CASES:
    device_force(dev, mot, t=t, rtol=1e-8)  # compile and cache the rig
    tc, _ = timed(lambda d=dev, m=mot: device_force(d, m, t=t, rtol=1e-8, force_only=True))
    print(f"   {name:32s} {1e3 * tc:8.2f}")

dev, mot = CASES[0][1], CASES[0][2]
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
print("\n3. hydraulic device, 10 s: time, steps (core) or evaluations (scipy), error")
print(f"   {'solver':20s} {'rtol':>7s} {'time [s]':>10s} {'steps/nfev':>11s} {'max rel err':>12s}")
rows = []
for rtol in (1e-6, 1e-8):
    tk, res = timed(lambda rtol=rtol: device_force(dev, mot, t=t, rtol=rtol), n=3)
    rows.append(("core rig DP5(4)", rtol, tk, res.steps, np.abs(res.force - ref).max() / scale))
    for method in ("Radau", "LSODA"):
        ts, (fs, nfev) = timed(lambda m=method, rtol=rtol: scipy_run(m, rtol), n=1)
        rows.append((f"scipy {method}", rtol, ts, nfev, np.abs(fs - ref).max() / scale))
for name, rtol, tt, n, err in rows:
    print(f"   {name:20s} {rtol:7.0e} {tt:10.4f} {n:11d} {err:12.2e}")
base = {(name, rtol): tt for name, rtol, tt, _, _ in rows}
for rtol in (1e-6, 1e-8):
    c = base[("core rig DP5(4)", rtol)]
    print(f"   speed-up of the core rig at rtol {rtol:.0e}: {base[('scipy Radau', rtol)] / c:.0f}x "
          f"scipy Radau, {base[('scipy LSODA', rtol)] / c:.0f}x scipy LSODA")  # fmt: skip
