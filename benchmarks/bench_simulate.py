"""Quarter-car simulation speed: compiled kernel against scipy solve_ivp.

Case (the speed goal of the simulator): ``afw`` quarter car (nylon flywheel, thesis law, M = 370 kg) under
``sine`` 0.05 m at 5 Hz, horizon 10 s, all metrics.

* fast: ``simulate_metrics`` on the model core (exact matrix-exponential steps while
  the flywheel is saturated, adaptive Dormand-Prince 5(4) through the transits, metric
  integrals as states, the 100 Hz Wk section advanced exactly), at the default rtol 1e-8
  and, for comparison, at 1e-7; median of many runs after compilation (wall clock, and
  CPU time of this process, which the other load on a shared machine inflates less);
* baseline: scipy ``solve_ivp`` DOP853 on the plain-Python right-hand side
  (``ReferenceRHS`` of the tests' oracle, ``tests/_quarter_car_oracle.py``), the same augmented ODE and
  the same tolerances; median of a few runs;
* accuracy: both against a scipy DOP853 run at rtol 1e-10 (worst relative error over
  the metrics);
* the model core on the same car (the network ``k | c | afw``,
  :func:`inerterlab.systems.quarter_car`): (a) its states at 10 Hz, the stepping alone
  (exact steps while the flywheel is saturated, Dormand-Prince through the transits),
  error against scipy DOP853 at rtol 1e-11; (b) every output at 1 kHz and the metrics
  from those samples. ``core stepping ratio`` and ``core ratio``: the scipy baseline's
  median over each;

* the fast case again once the structure's own code is compiled (a user's later runs of
  the car; the first runs of a structure use the generic code): its ratio, and whether
  its metrics equal the generic code's to the last bit.

The last line is ``ratio: N`` = median baseline time / median fast time (the generic
code: a car's first runs).

Usage: python benchmarks/bench_simulate.py [--fast-runs 50] [--slow-runs 3]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import _quarter_car_oracle as oracle  # noqa: E402
from inerterlab import quarter_car  # noqa: E402
from inerterlab.excitation import sine  # noqa: E402
from inerterlab.metrics import METRIC_KEYS  # noqa: E402
from inerterlab.simulate import SimulationOptions, simulate, simulate_metrics  # noqa: E402

KEYS = tuple(k for k in METRIC_KEYS if k != "tyre_lift_off")  # the numeric metrics


def worst(a: dict, b: dict) -> float:
    return max(abs(a[k] - b[k]) / abs(b[k]) for k in KEYS)


def timed(fn, runs: int) -> tuple[float, dict]:
    return timed_cpu(fn, runs)[0::2]


def timed_cpu(fn, runs: int) -> tuple[float, float, dict]:
    """Median wall-clock time, median CPU time of this process, last result."""
    walls, cpus, out = [], [], None
    for _ in range(runs):
        t, c = time.perf_counter(), time.process_time()
        out = fn()
        cpus.append(time.process_time() - c)
        walls.append(time.perf_counter() - t)
    return statistics.median(walls), statistics.median(cpus), out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--fast-runs", type=int, default=50)
    ap.add_argument("--slow-runs", type=int, default=3)
    ap.add_argument("--rtol", type=float, default=1e-8)
    args = ap.parse_args()
    car = quarter_car("afw", sprung_mass=370.0)
    ex = sine(0.05, 5.0)
    T = 10.0
    fast_opts = SimulationOptions(rtol=args.rtol)

    # the generic code for the first timings (a car's first runs), whatever the numba cache
    # holds: a structure's own code on disk from an earlier process would be loaded
    os.environ["INERTERLAB_SPECIALISE"] = "never"
    t0 = time.perf_counter()
    simulate_metrics(car, ex, 0.1, options=fast_opts)
    print(f"first call (compilation or cache load): {time.perf_counter() - t0:.2f} s")
    stats = simulate(car, ex, T, options=fast_opts, output="metrics").stats
    print(f"core steps: {stats}")

    t_fast, c_fast, m_fast = timed_cpu(
        lambda: simulate_metrics(car, ex, T, options=fast_opts), args.fast_runs
    )
    print(
        f"numba (exact steps + Dormand-Prince 5(4)), rtol {args.rtol:g}: median {1e3 * t_fast:.2f} ms "
        f"(CPU {1e3 * c_fast:.2f} ms) over {args.fast_runs} runs"
    )
    loose_rtol = 10.0 * args.rtol
    loose_opts = SimulationOptions(rtol=loose_rtol)
    loose_stats = simulate(car, ex, T, options=loose_opts, output="metrics").stats
    t_loose, c_loose, m_loose = timed_cpu(
        lambda: simulate_metrics(car, ex, T, options=loose_opts), args.fast_runs
    )
    print(
        f"numba (exact steps + Dormand-Prince 5(4)), rtol {loose_rtol:g}: median "
        f"{1e3 * t_loose:.2f} ms "
        f"(CPU {1e3 * c_loose:.2f} ms) over {args.fast_runs} runs; steps {loose_stats}"
    )
    t_full, m_slow = timed(
        lambda: oracle.simulate_metrics(car, ex, T, rtol=args.rtol), args.slow_runs
    )
    print(
        f"the tests' scipy oracle (solve_ivp DOP853 + peak location in Python), rtol {args.rtol:g}: "
        f"median {1e3 * t_full:.1f} ms over {args.slow_runs} runs"
    )
    # the named baseline: solve_ivp DOP853 on the same augmented ODE (metric integrals
    # as states, so the RMS metrics come out of the final state), no peak search
    import numpy as np
    from scipy.integrate import solve_ivp

    model = car.info["model"]  # the suspension's description

    def baseline():
        f = oracle.ReferenceRHS(model)
        f.seg = ex.segments(T)[0]
        y0 = np.r_[oracle.initial_state(model), np.zeros(oracle.N_METRIC_STATES)]
        return solve_ivp(
            f, (0.0, T), y0, method="DOP853", rtol=args.rtol,
            atol=args.rtol * oracle.state_scales(model),
        )  # fmt: skip

    t_slow, c_slow, sol = timed_cpu(baseline, args.slow_runs)
    rms_base = float(np.sqrt(sol.y[len(oracle.state_names(model)), -1] / T))
    print(
        f"baseline scipy solve_ivp DOP853, plain-Python RHS, rtol {args.rtol:g}: median "
        f"{1e3 * t_slow:.1f} ms (CPU {1e3 * c_slow:.1f} ms) over {args.slow_runs} runs "
        f"({sol.nfev} RHS calls); "
        f"rms_body_acc {rms_base:.10g} vs fast {m_fast['rms_body_acc']:.10g}"
    )
    m_ref = oracle.simulate_metrics(car, ex, T, rtol=1e-10)
    print(
        f"worst relative metric error vs scipy rtol 1e-10: fast {worst(m_fast, m_ref):.2e}, "
        f"fast at rtol {loose_rtol:g} {worst(m_loose, m_ref):.2e}, scipy {worst(m_slow, m_ref):.2e}"
    )
    print(f"fast vs scipy at the same tolerance: {worst(m_fast, m_slow):.2e}")
    # the model core on the same car (the network k | c | afw): exact steps while the
    # flywheel is saturated, Dormand-Prince with the saturation located as events through
    # the transits, the right-hand side compiled for the network's structure
    from inerterlab.systems import quarter_car as core_quarter_car

    del os.environ["INERTERLAB_SPECIALISE"]
    core = core_quarter_car("afw", sprung_mass=370.0)
    from inerterlab.suspension.model import model_of
    from inerterlab.systems import _compiled
    from inerterlab.systems.core import _ride_system
    from inerterlab.systems.quarter_car import system_of

    # the structures' own code: the bare car's (the core runs below) and that of the car
    # with the ride observers (what simulate_metrics integrates)
    ride = _ride_system(system_of(model_of(car)))
    t0 = time.perf_counter()
    _compiled.specialised(core.itab)
    _compiled.specialised(ride.itab)
    print(f"core, the structures' code (compilation or cache load): {time.perf_counter() - t0:.2f} s")
    core.simulate(ex, 0.1, rtol=args.rtol)
    # the fast case again, now that the structure's own code is compiled: what a user's
    # later runs of this car take (a process that has integrated a structure for 10 s of
    # CPU compiles it, inerterlab.systems._compiled); the same numbers
    tier = repr(_compiled.rhs_for(ride.itab, False))
    t_own, c_own, m_own = timed_cpu(
        lambda: simulate_metrics(car, ex, T, options=fast_opts), args.fast_runs
    )
    same = all(m_own[k] == m_fast[k] for k in KEYS)
    print(
        f"numba on the structure's own code ({tier}), rtol {args.rtol:g}: median "
        f"{1e3 * t_own:.2f} ms (CPU {1e3 * c_own:.2f} ms) over {args.fast_runs} runs; ratio "
        f"{t_slow / t_own:.0f} by wall time, {c_slow / c_own:.0f} by CPU time; the same metrics "
        f"to the last bit: {same}"
    )
    # (a) the states at 10 Hz (the stepping itself: what the metrics-as-states path of
    # the kernel above and the scipy baseline pay for), error against scipy DOP853 on
    # the plain-Python right-hand side at rtol 1e-11 (an independent implementation)
    ts = np.arange(101) / 10.0
    t_step, c_step, r_step = timed_cpu(
        lambda: core.simulate(ex, T, rtol=args.rtol, times=ts), args.fast_runs
    )
    f = oracle.ReferenceRHS(model)
    f.seg = ex.segments(T)[0]
    y0 = np.r_[oracle.initial_state(model), np.zeros(oracle.N_METRIC_STATES)]
    t_fine = np.arange(10001) / 1000.0  # the peaks from 1 kHz (10 Hz meets a 5 Hz sine
    tight = solve_ivp(f, (0.0, T), y0, method="DOP853", rtol=1e-11,  # in two phases only)
                      atol=1e-11 * oracle.state_scales(model), t_eval=t_fine)  # fmt: skip
    idx = [core.state_names.index(n) for n in ("wheel.x", "wheel.v", "body.x", "body.v")]
    ref4 = tight.y[:4].T
    peak = np.abs(ref4).max(axis=0)
    e_step = float((np.abs(r_step.states[:, idx] - ref4[::100]).max(axis=0) / peak).max())
    print(
        f"core (k | c | afw), states at 10 Hz, rtol {args.rtol:g}: median {1e3 * t_step:.2f} ms "
        f"(CPU {1e3 * c_step:.2f} ms); steps {r_step.stats}; largest state error / state "
        f"peak vs scipy DOP853 rtol 1e-11: {e_step:.1e}"
    )
    # (b) every output at 1 kHz and the metrics from those samples
    t_core, c_core, r_core = timed_cpu(lambda: core.simulate(ex, T, rtol=args.rtol), args.fast_runs)
    m_core = {k: r_core.metrics[k] for k in KEYS}
    print(
        f"core (k | c | afw), all outputs at 1 kHz and metrics from the samples, "
        f"rtol {args.rtol:g}: median "
        f"{1e3 * t_core:.2f} ms (CPU {1e3 * c_core:.2f} ms); steps {r_core.stats}; worst "
        f"relative metric error vs scipy rtol 1e-10 {worst(m_core, m_ref):.2e}"
    )
    print(
        f"core stepping ratio (states at 10 Hz vs the scipy baseline): {t_slow / t_step:.0f} "
        f"by wall time, {c_slow / c_step:.0f} by CPU time"
    )
    print(
        f"core ratio (1 kHz outputs and metrics vs the scipy baseline): {t_slow / t_core:.0f} "
        f"by wall time, {c_slow / c_core:.0f} by CPU time"
    )
    print(f"simulations per second per worker (fast): {1.0 / t_fast:.0f}")
    print(f"ratio: {t_slow / t_fast:.0f}")


if __name__ == "__main__":
    main()
