"""What the reversal spikes do to the estimates, against the reversal window.

For each device and seed the reduced campaign (Appendix A matrix, records cut to 2 s at
200 Hz, ``rig-simulate`` noise) is simulated twice with the same noise draws, with and
without the reversal spikes, and each is identified with every window. The difference
of the two estimates is the spikes' doing; it is printed in units of the (sandwich)
standard error of the spiky fit, per seed and averaged.

    python benchmarks/study_identify_reversal_window.py --seeds 3
"""

from __future__ import annotations

import argparse
import os
import sys

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from inerterlab.devices import device_preset  # noqa: E402
from inerterlab.identify import identify, simulate_rig  # noqa: E402

MATRIX = {"hydraulic": "appendix-a1", "screw": "appendix-a2", "rectifier": "appendix-a2"}
PARAMS = ("stiffness", "damping", "friction")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--devices", default="screw,hydraulic,rectifier")
    ap.add_argument("--windows", default="0.1,0.12,0.16,0.2", help="[s], comma separated")
    args = ap.parse_args(argv)
    windows = [float(w) for w in args.windows.split(",")]
    print("| device | window [s] | " + " | ".join(PARAMS) + " |")
    print("|---|---|" + "---|" * len(PARAMS))
    for name in args.devices.split(","):
        dev = device_preset(name)
        effect = {(w, n): [] for w in windows for n in PARAMS}
        for seed in range(1, args.seeds + 1):
            fits = {}
            for spikes in (False, True):
                data = simulate_rig(
                    dev,
                    matrix=MATRIX[name],
                    seed=seed,
                    sample_rate=200.0,
                    max_duration=2.0,
                    spikes=spikes,
                )
                for w in windows:
                    fit = identify(data, dev, reversal_window=w, interval="sandwich")
                    fits[spikes, w] = fit.parameters
            for w in windows:
                for n in PARAMS:
                    d = fits[True, w][n].value - fits[False, w][n].value
                    effect[w, n].append(d / fits[True, w][n].std_error)
        for w in windows:
            cells = [
                " ".join(f"{z:+.3f}" for z in effect[w, n])
                + f" (mean {np.mean(effect[w, n]):+.3f})"
                for n in PARAMS
            ]
            print(f"| {name} | {w:g} | " + " | ".join(cells) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
