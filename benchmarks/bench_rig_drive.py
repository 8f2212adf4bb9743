"""A rig test's record as the drive of the model core, against the device kernel.

For each device: the default rig's 2 Hz, 4 mm sine sampled at 500 Hz for 2 s with sensor
noise (1 um, 0.1 mm/s), driving (a) ``devices.device_force`` on the sampled motion (the
device model's own integration, the baseline), (b) ``systems.rig(device).simulate`` on
``excitation.drive_series`` of the same samples (every output) and (c)
``systems.DriveRuns(drive).force`` (the force only, segments built once: what the
identification runs). Prints the median time of each over alternating runs, the ratios
to the baseline, the steps, and the largest force difference relative to the peak (all
at rtol 1e-10 for the accuracy, at the identification's rtol 1e-8 for the time).
Run: python benchmarks/bench_rig_drive.py [--repeats N]
"""

import argparse
import math
import statistics
import time

import numpy as np

from inerterlab.devices import device_force, device_preset, motion_from_samples
from inerterlab.excitation import drive_series
from inerterlab.systems import DriveRuns, rig

FS = 500.0


def record(seed=1, duration=2.0):
    t = np.arange(int(round(duration * FS)) + 1) / FS
    w, amp = 2.0 * math.pi * 2.0, 0.004
    rng = np.random.default_rng(seed)
    x = amp * np.sin(w * t) + 1e-6 * rng.standard_normal(t.size)
    v = amp * w * np.cos(w * t) + 1e-4 * rng.standard_normal(t.size)
    return t, x, v


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=9)
    args = ap.parse_args()
    t, x, v = record()
    motion, drive = motion_from_samples(t, x, v), drive_series(t, x, v)
    runs = DriveRuns(drive)
    print(f"{'device':10s} {'kernel [ms]':>12s} {'core [ms]':>10s} {'core/kernel':>12s} "
          f"{'runs [ms]':>10s} {'runs/kernel':>12s} {'core steps':>11s} "
          f"{'max diff/peak':>14s}")  # fmt: skip
    for name in ("screw", "hydraulic", "rectifier"):
        dev = device_preset(name)
        r = rig(dev)
        x0 = np.zeros(r.n_states)
        if dev.series:  # spring unloaded, branch moving with the drive: initial_force=0
            node = r.state_names[0].rpartition(".")[0]
            x0[r.state_names.index(f"{node}.x")] = x[0]
            x0[r.state_names.index(f"{node}.v")] = v[0]

        def kernel(rtol, dev=dev):
            return device_force(
                dev, motion, t=t, rtol=rtol, h_max=0.01, initial_force=0.0, force_only=True
            )

        def core(rtol, r=r, x0=x0):
            return r.simulate(drive, t[-1], rtol=rtol, sample_rate=FS, x0=x0)

        def lean(rtol, r=r, x0=x0):
            return runs.force(r, x0, rtol=rtol)

        ref, res = kernel(1e-10), core(1e-10)
        diff = np.abs(res.outputs["force"] - ref).max() / np.abs(ref).max()
        diff = max(diff, np.abs(lean(1e-10) - ref).max() / np.abs(ref).max())
        kernel(1e-8), core(1e-8), lean(1e-8)  # compiled and warm
        tk, tc, tl = [], [], []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            kernel(1e-8)
            tk.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            steps = core(1e-8).stats.get("steps", 0)
            tc.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            lean(1e-8)
            tl.append(time.perf_counter() - t0)
        mk, mc, ml = statistics.median(tk), statistics.median(tc), statistics.median(tl)
        print(f"{name:10s} {1e3 * mk:12.2f} {1e3 * mc:10.2f} {mc / mk:12.2f} {1e3 * ml:10.2f} "
              f"{ml / mk:12.2f} {steps:11d} {diff:14.2e}")  # fmt: skip


if __name__ == "__main__":
    main()
