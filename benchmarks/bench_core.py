"""Model core speed and accuracy: the ``afw`` car against an independent reference, against
scipy.signal.lsim, generic against per-structure code, and the cost of compilation.

Cases:

* ``afw`` preset (nylon flywheel, thesis law) under ``sine`` 0.05 m at 5 Hz, horizon
  5 s, time series at 1 kHz, all at rtol 1e-8: :func:`inerterlab.simulate.simulate` (the
  model core with the ride metrics as observers, the samples and the metrics a user
  gets); :meth:`System.simulate` of the same car (the network ``k | c | afw``,
  :func:`inerterlab.quarter_car`) by ``auto`` (exact steps while the flywheel is
  saturated, Dormand-Prince 5(4) through the transits) and ``adaptive`` (Dormand-Prince
  throughout). Accuracy: each against scipy ``solve_ivp`` DOP853 at rtol 1e-11 on the
  plain-Python right-hand side (``ReferenceRHS`` of ``tests/_quarter_car_oracle.py``, an
  implementation independent of the core), largest state error relative to the state's
  peak. (Until the specialised quarter-car kernel was deleted, the first line was that
  kernel and the reference its own run at rtol 1e-11.) Then the core's right-hand side
  compiled generically (the structure read from a table) against the one compiled for
  this structure, same run, states at 10 Hz over 10 s.
* linear network ``k | (c - b)`` with an internal node on an ISO 8608 class C road at
  20 m/s, 10 s, samples every 1 ms: the core's exact matrix-exponential steps (the
  states at every sample, and the ride metrics integrated as observers over the exact
  steps: Wk filter in the augmented matrix, squares, fourth powers and peaks from
  Gauss-Legendre nodes; then also every output at every sample, which the result
  computes when first read) against ``scipy.signal.lsim``
  (first-order hold, exact for this road; the states only) on the core's own state
  space, and its adaptive steps at rtol 1e-8; accuracy (states, and the worst
  relative error of the ride metrics) against adaptive steps at rtol 1e-12.
* ``--compile-cost``: in a fresh process with an empty numba cache, the time to the
  first simulation (every kernel compiled, the generic right-hand side) and to the
  second (the structure's own right-hand side compiled).

Prints the median CPU times (the linear network's also in wall time) and ``ratio: N`` =
median lsim CPU time / median core CPU time for the linear network (the issue's "10x
lsim" figure; ``ratio (wall):`` the same in wall time). Every timed function runs once
before the rounds, then once in each round in turn, so lsim and the core see the same
load and each finds the caches as the other left them; a core call after the first
reads what its system keeps by content (state space, plan, tables), as a user's second
call on the same system does.

Usage: python benchmarks/bench_core.py [--runs 7] [--compile-cost] [--only-linear]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # small products: threads only wait

import numpy as np  # noqa: E402
from scipy import signal  # noqa: E402

from inerterlab import quarter_car  # noqa: E402
from inerterlab.excitation import iso8608, road_displacement, sine  # noqa: E402
from inerterlab.simulate import SimulationOptions, simulate  # noqa: E402
from inerterlab.systems import _compiled, _integrate  # noqa: E402

NAMES = ("wheel.x", "wheel.v", "body.x", "body.v")


def _medians(fns, runs, wall=None):
    """Median CPU time of each function, run in turn in every round (a shared machine's
    load drifts: interleaving exposes the functions to the same load); ``wall``: a list
    that receives the median wall-clock times too."""
    for fn in fns:
        fn()
    ts = [[] for _ in fns]
    ws = [[] for _ in fns]
    for _ in range(runs):
        for fn, out, wout in zip(fns, ts, ws, strict=True):
            w0, t0 = time.perf_counter(), time.process_time()
            fn()
            out.append(time.process_time() - t0)
            wout.append(time.perf_counter() - w0)
    if wall is not None:
        wall[:] = [statistics.median(w) for w in ws]
    return [statistics.median(t) for t in ts]


def _err(a, b):
    return float((np.abs(a - b).max(axis=0) / np.abs(b).max(axis=0)).max())


_COLD = """
import time
t0, c0 = time.perf_counter(), time.process_time()
from inerterlab.excitation import iso8608, sine
from inerterlab.systems import _compiled, quarter_car, rig
core = quarter_car("afw")
t1, c1 = time.perf_counter(), time.process_time()
core.simulate(sine(), 0.2)
t2, c2 = time.perf_counter(), time.process_time()
_compiled.specialised(core.itab)
t3, c3 = time.perf_counter(), time.process_time()
rig("k | c", {"k": 1e4, "c": 100.0}).simulate(sine(0.01, 2.0), 0.2)
quarter_car("k | (c - b)", {"k": 9e4, "c": 5e3, "b": 200.0}).simulate(iso8608(), 0.5)
t4, c4 = time.perf_counter(), time.process_time()
print(f"{t1 - t0:.1f} {c1 - c0:.1f} {t2 - t1:.1f} {c2 - c1:.1f} {t3 - t2:.1f} {c3 - c2:.1f} "
      f"{t4 - t3:.1f} {c4 - c3:.1f}")
"""


def compile_cost() -> None:
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, NUMBA_CACHE_DIR=d)
        out = subprocess.run(
            [sys.executable, "-c", _COLD], env=env, capture_output=True, text=True, check=True
        ).stdout.split()
        print("compilation, a fresh process with an empty cache, wall (CPU) seconds:")
        print(f"  import {out[0]} ({out[1]}); the afw car's first simulation (every kernel it "
              f"needs, generic right-hand side) {out[2]} ({out[3]}); its structure's own "
              f"right-hand side {out[4]} ({out[5]}); then a rig and a linear car on an ISO "
              f"road {out[6]} ({out[7]})")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--compile-cost", action="store_true")
    ap.add_argument("--only-linear", action="store_true", help="the linear network only")
    args = ap.parse_args()
    runs = args.runs
    if args.compile_cost:
        compile_cost()
    if not args.only_linear:
        afw_cases(runs)
    linear_case(runs)


def afw_cases(runs: int) -> None:
    from scipy.integrate import solve_ivp

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
    import _quarter_car_oracle as oracle

    ex, T = sine(), 5.0
    car = quarter_car("afw")  # simulate() runs it with the ride observers
    core = quarter_car("afw")
    idx = [core.state_names.index(n) for n in NAMES]
    model = car.info["model"]  # the suspension's description, for the reference
    f = oracle.ReferenceRHS(model)
    f.seg = ex.segments(T)[0]
    y0 = np.r_[oracle.initial_state(model), np.zeros(oracle.N_METRIC_STATES)]
    ts = np.arange(int(round(T * 1000)) + 1) / 1000.0  # the 1 kHz samples
    ref = solve_ivp(f, (0.0, T), y0, method="DOP853", rtol=1e-11,
                    atol=1e-11 * oracle.state_scales(model), t_eval=ts).y[:4].T  # fmt: skip
    opts = SimulationOptions(rtol=1e-8)
    _compiled.specialised(core.itab)  # the structure's own code (compiled or loaded)
    t_sim, t_new, t_dp = _medians(
        (
            lambda: simulate(car, ex, T, options=opts),
            lambda: core.simulate(ex, T, rtol=1e-8),
            lambda: core.simulate(ex, T, rtol=1e-8, method="adaptive"),
        ),
        runs,
    )
    e_sim = _err(simulate(car, ex, T, options=opts).states[:, :4], ref)
    r_new = core.simulate(ex, T, rtol=1e-8)
    e_new = _err(r_new.states[:, idx], ref)
    e_dp = _err(core.simulate(ex, T, rtol=1e-8, method="adaptive").states[:, idx], ref)
    print(f"afw / sine 5 Hz / {T:g} s, rtol 1e-8, CPU time; errors against scipy DOP853 "
          "at rtol 1e-11 on the plain-Python right-hand side")  # fmt: skip
    print(f"  simulate() (ride metrics as observers): {t_sim * 1e3:8.2f} ms   error {e_sim:.1e}")
    print(f"  System.simulate, auto                 : {t_new * 1e3:8.2f} ms   error {e_new:.1e}   "
          f"{r_new.stats}")  # fmt: skip
    print(f"  System.simulate, adaptive             : {t_dp * 1e3:8.2f} ms   error {e_dp:.1e}")
    # generic against per-structure right-hand side, the same integrator
    ts = np.arange(101) / 10.0
    spec = _compiled.specialised(core.itab)  # compiled, or loaded from the cache
    gen = _compiled.generic()

    def run_with(rhs):
        def go():
            _integrate.rhs_for = lambda itab, count=True: rhs
            try:
                return core.simulate(ex, 10.0, rtol=1e-8, times=ts)
            finally:
                _integrate.rhs_for = _compiled.rhs_for

        return go

    t_gen, t_spec = _medians((run_with(gen), run_with(spec)), runs)
    same = np.array_equal(run_with(gen)().states, run_with(spec)().states)
    print("afw / sine 5 Hz / 10 s, states at 10 Hz, rtol 1e-8, CPU time")
    print(f"  generic right-hand side      : {t_gen * 1e3:8.2f} ms")
    print(f"  compiled for the structure   : {t_spec * 1e3:8.2f} ms   (states bit-identical: {same})")
    print(f"  generic / per-structure time : {t_gen / t_spec:.2f}")


def linear_case(runs: int) -> None:
    """A linear network on a random road against scipy.signal.lsim."""
    lin = quarter_car("k | (c - b)", {"k": 90e3, "c": 5e3, "b": 200.0})
    road, T2 = iso8608("C", 20.0, seed=1), 10.0
    res = lin.simulate(road, T2)
    A, B, _, _ = lin.linear_state_space()
    assert not B[:, 2].any(), "no inertance at the road: the acceleration input is unused"
    x0 = res.states[0]

    def lsim():
        segs = road.segments(T2)
        t = np.arange(int(round(T2 * 1000)) + 1) / 1000.0
        x1, _ = road_displacement(segs, t)
        ss = signal.StateSpace(A, (A @ B[:, 1] + B[:, 0])[:, None], np.eye(len(A)), B[:, 1:2])
        return signal.lsim(ss, x1, t, X0=x0 - B[:, 1] * x1[0], interp=True)[1]

    ref2_res = lin.simulate(road, T2, method="adaptive", rtol=1e-12)
    ref2 = ref2_res.states
    wall: list = []
    t_lsim, t_ex, t_out, t_ad = _medians(
        (
            lsim,
            lambda: lin.simulate(road, T2, method="exact"),
            lambda: lin.simulate(road, T2, method="exact").outputs["body_acc"],
            lambda: lin.simulate(road, T2, method="adaptive", rtol=1e-8),
        ),
        runs,
        wall,
    )
    e_ad = _err(lin.simulate(road, T2, method="adaptive", rtol=1e-8).states, ref2)
    e_ex = _err(lin.simulate(road, T2, method="exact").states, ref2)
    e_ls = _err(res.states, lsim())
    # the ride metrics, integrated as observers over the exact steps
    m_ex, m_ref = lin.simulate(road, T2, method="exact").metrics, ref2_res.metrics
    e_m = max(
        abs(m_ex[k] - v) / abs(v) for k, v in m_ref.items() if isinstance(v, float) and v != 0.0
    )
    w_lsim, w_ex, w_out, w_ad = wall
    print(f"k | (c - b) / ISO 8608 C at 20 m/s / {T2:g} s / samples every 1 ms, CPU time "
          f"(wall time), medians of {runs} interleaved rounds, load {os.getloadavg()[0]:.1f}")
    print(f"  scipy.signal.lsim (FOH, states):   {t_lsim * 1e3:8.2f} ms ({w_lsim * 1e3:.2f})")
    print(f"  core exact steps (states, ride metrics as observers): {t_ex * 1e3:8.2f} ms "
          f"({w_ex * 1e3:.2f})   error {e_ex:.1e} (vs lsim {e_ls:.1e}), metrics {e_m:.1e}")
    print(f"  the same, every output read too (computed on first read): {t_out * 1e3:8.2f} ms "
          f"({w_out * 1e3:.2f})")
    print(f"  core adaptive rtol 1e-8:           {t_ad * 1e3:8.2f} ms ({w_ad * 1e3:.2f})   "
          f"error {e_ad:.1e}")
    print(f"ratio (wall): {w_lsim / w_ex:.1f}")
    print(f"ratio: {t_lsim / t_ex:.1f}")


if __name__ == "__main__":
    main()
