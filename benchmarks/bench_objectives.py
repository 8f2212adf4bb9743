"""Cost of the optimiser's quantities per candidate, against the plain H2 norms.

Network ``k | (b - (k1 | c))`` on the thesis car, 4000 random parameter sets evaluated in
one compiled batch (as the optimiser's sample and evolution do): the three original H2
norms (the baseline, measured in the same run), the Wk-weighted body acceleration
(eight more states, block Lyapunov/Sylvester solve), one peak gain (801-point grid and
golden-section refinement), all twelve quantities; then one whole ``optimize_network``
per objective. Prints medians over repeated blocks and the ratio to the baseline.

Run: NUMBA_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_objectives.py
"""

from __future__ import annotations

import os
import statistics
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from inerterlab.network_design import QUANTITIES, _need, _squares, optimize_network  # noqa: E402
from inerterlab.suspension.network_linear import network_quarter_car  # noqa: E402

NET = "k | (b - (k1 | c))"


def median_time(fn, repeat=5):
    fn()  # compile / warm up
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    q = network_quarter_car(NET)
    rng = np.random.default_rng(0)
    n = 4000
    T = np.column_stack(
        [
            np.full(n, 90e3),
            np.exp(rng.uniform(np.log(10), np.log(1000), n)),  # b
            np.exp(rng.uniform(np.log(1e4), np.log(1e6), n)),  # k1
            np.exp(rng.uniform(np.log(300), np.log(2e4), n)),  # c
        ]
    )
    sets = {
        "H2 body_acc, tyre_deflection, suspension_deflection": ["body_acc"],
        "H2 body_acc_wk": ["body_acc_wk"],
        "peak:body_acc": ["peak:body_acc"],
        "all twelve quantities": list(QUANTITIES),
    }
    base = None
    print(f"{NET}, thesis car, {n} candidates per batch")
    for label, names in sets.items():
        need = _need(names)
        t = median_time(lambda need=need: _squares(q, T, need))
        base = base or t
        print(f"  {label:55s} {1e6 * t / n:8.2f} us/candidate  x{t / base:6.2f}")
    print("one optimize_network (k held; 8 starts, evolution, polish):")
    ref = None
    for obj in ("body_acc", "body_acc_wk", "peak:body_acc"):
        t = median_time(
            lambda obj=obj: optimize_network(NET, obj, fixed={"k": 90e3}, compare=False), 3
        )
        ref = ref or t
        print(f"  {obj:55s} {t:8.2f} s            x{t / ref:6.2f}")


if __name__ == "__main__":
    main()
