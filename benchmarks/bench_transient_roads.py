"""Exact steps in the linear regimes on roads that stop driving the car: the rule of
``core._regime_pays`` against the regime steps forced.

The ``afw`` quarter car (its flywheel saturates: a linear regime, docs/guide/core.md)
with its ride metrics over 10 s on the drop, the bump and the 5 Hz sine. Two ways:

* ``auto``: the default. On the drop and the bump the road's last segment starts before
  half the horizon, so the run takes the adaptive steps throughout and builds no regime
  tables; on the sine it takes exact steps while the flywheel is saturated;
* ``forced`` (the baseline): the regime steps on every road, as before stop 67
  (``core.REGIME_FREE_DECAY`` set below zero for the measurement).

Printed per input: CPU medians of ``--runs`` runs, with a new car at every run (the
sprung mass varied: the regime system and its tables built every time, as in a sweep
or a fit) and with one car run again (its tables kept); steps (of them exact); the
worst relative difference of the ride metrics from scipy's DOP853 at rtol 1e-11; and
the ratio forced / auto (the speed-up, above 1 where the rule pays).

    python benchmarks/bench_transient_roads.py [--runs 40]
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import _quarter_car_oracle as oracle  # noqa: E402

os.environ.setdefault("INERTERLAB_SPECIALISE", "always")  # the structure's code throughout

from inerterlab import quarter_car  # noqa: E402
from inerterlab.excitation import bump, drop, sine  # noqa: E402
from inerterlab.simulate import simulate, simulate_metrics  # noqa: E402
from inerterlab.systems import core  # noqa: E402

T = 10.0
KEYS = ("rms_body_acc", "rms_tyre_grip", "rms_body_acc_wk", "vdv", "peak_body_acc",
        "peak_deflection")  # fmt: skip
RULE = core.REGIME_FREE_DECAY


@contextlib.contextmanager
def regime_steps(forced: bool):
    """The rule (``forced`` False) or the regime steps on every road, restored after."""
    core.REGIME_FREE_DECAY = -1.0 if forced else RULE
    try:
        yield
    finally:
        core.REGIME_FREE_DECAY = RULE


_MASSES = iter(340.0 + 1e-3 * i for i in range(10**6))


def runs_of(ex, runs: int, fresh: bool, forced: bool) -> float:
    """CPU median of ``runs`` metric runs of the `afw` car on ``ex``; ``fresh``: a new
    car at every run, of a sprung mass no run has had before in this process (the
    process keeps tables by their content: a car met again would find them)."""
    times = []
    car = quarter_car("afw", sprung_mass=370.0)
    with regime_steps(forced):
        for _ in range(runs + 3):
            if fresh:  # a new car: its regime system and tables are built again
                car = quarter_car("afw", sprung_mass=next(_MASSES))
            c = time.process_time()
            simulate_metrics(car, ex, T)
            times.append(time.process_time() - c)
    return statistics.median(times[3:])  # the first runs load the compiled code


def error(car, ex, forced: bool, ref: dict) -> tuple[float, dict]:
    with regime_steps(forced):
        m = simulate_metrics(car, ex, T)
        stats = simulate(car, ex, T, output="metrics").stats
    # (a metric that is not finite across a road step is None both ways)
    return max(abs(m[k] - ref[k]) / abs(ref[k]) for k in KEYS if ref[k] is not None), stats


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=40)
    args = ap.parse_args()
    car = quarter_car("afw", sprung_mass=370.0)
    print(f"afw quarter car, ride metrics over {T:g} s, rtol 1e-8; CPU medians of {args.runs} runs")
    for name, ex in (("drop", drop(0.05)), ("bump", bump(0.05)), ("sine 5 Hz", sine(0.05, 5.0))):
        ref = oracle.simulate_metrics(car, ex, T, rtol=1e-11)
        cells = {}
        for forced in (False, True):
            err, st = error(car, ex, forced, ref)
            new = runs_of(ex, args.runs, True, forced)
            same = runs_of(ex, args.runs, False, forced)
            cells[forced] = (new, same)
            way = "forced" if forced else "auto  "
            print(
                f"  {name:9s} {way}: new car {1e3 * new:6.2f} ms, same car {1e3 * same:6.2f} ms; "
                f"steps {st['steps']} ({st['exact_steps']} exact); worst metric error vs "
                f"scipy DOP853 rtol 1e-11 {err:.1e}"
            )
        (a_new, a_same), (f_new, f_same) = cells[False], cells[True]
        print(
            f"  {name:9s} ratio forced / auto: new car {f_new / a_new:.2f}, "
            f"same car {f_same / a_same:.2f}"
        )


if __name__ == "__main__":
    main()
