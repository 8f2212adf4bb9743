"""Identification on the model core against the device model's own integration.

The three campaigns of the main job's table 5.A (``inerterlab reproduce``): each device's
Appendix A matrix simulated at 500 Hz, records cut to 10 s, 5 N noise and 300 N reversal
spikes (seed 5), fitted jointly from a start 20 % / 10 % / 10 % off, with the library's
defaults. Each campaign is fitted twice per repeat, alternating: on the model core's rig
(what ``identify`` does for every device the core represents) and on
``devices.device_force`` (the baseline: the device model's compiled integration, which
``identify`` used before). Prints the median time of each, the ratio core / device
model, the number of model runs, and the largest difference of the estimates in
standard errors.

    python benchmarks/bench_identify.py                 # the main job's campaigns
    python benchmarks/bench_identify.py --quick         # records cut to 2 s
    python benchmarks/bench_identify.py --repeats 3 --devices hydraulic
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import time
from unittest import mock

import inerterlab.identify.fit as fit_module
from inerterlab.devices import device_preset
from inerterlab.identify import identify, simulate_rig, test_matrix

MATRIX = {"hydraulic": "appendix-a1", "screw": "appendix-a2", "rectifier": "appendix-a2"}


def campaign(name: str, duration: float):
    dev = device_preset(name)
    data = simulate_rig(
        dev, matrix=test_matrix(MATRIX[name]), sample_rate=500.0, max_duration=duration,
        noise=5.0, spikes=True, seed=5,
    )  # fmt: skip
    start = dataclasses.replace(
        dev, stiffness=dev.stiffness * 1.2, damping=dev.damping * 0.9, friction=dev.friction * 1.1
    )
    return data, start


def fit(data, start, engine: str):
    """(seconds, model runs, result) of one fit on ``engine`` ("core" or "device")."""
    runs = {"n": 0}
    inner = fit_module._model_force

    def counted(*a, **k):
        runs["n"] += 1
        return inner(*a, **k)

    with mock.patch.object(fit_module, "_model_force", counted):
        if engine == "device":
            with mock.patch.object(fit_module, "core_represents", lambda d: False):
                t0 = time.perf_counter()
                res = identify(data, start, method="joint")
        else:
            t0 = time.perf_counter()
            res = identify(data, start, method="joint")
        return time.perf_counter() - t0, runs["n"], res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="records cut to 2 s")
    ap.add_argument("--devices", default="hydraulic,screw,rectifier")
    args = ap.parse_args()
    duration = 2.0 if args.quick else 10.0
    print(f"{'device':10s} {'device model [s]':>16s} {'core [s]':>9s} {'core/device':>12s} "
          f"{'runs (device, core)':>20s} {'max |diff| / se':>16s}")  # fmt: skip
    for name in args.devices.split(","):
        data, start = campaign(name, duration)
        fit(data, start, "core")  # compiled and warm
        fit(data, start, "device")
        td, tc = [], []
        for _ in range(args.repeats):
            t, nd, rd = fit(data, start, "device")
            td.append(t)
            t, nc, rc = fit(data, start, "core")
            tc.append(t)
        diff = max(
            abs(p.value - rd.parameters[k].value) / rd.parameters[k].std_error
            for k, p in rc.parameters.items()
        )
        md, mc = statistics.median(td), statistics.median(tc)
        print(f"{name:10s} {md:16.2f} {mc:9.2f} {mc / md:12.2f} {f'{nd}, {nc}':>20s} "
              f"{diff:16.2e}")  # fmt: skip


if __name__ == "__main__":
    main()
