"""Where the time of ``bench_simulate.py``'s fast case goes (a profile, not a benchmark).

The case: the ``afw`` quarter car (M = 370 kg), 5 cm 5 Hz sine, 10 s, all metrics
(``simulate_metrics`` on the model core with the ride observers,
one sample at the horizon), rtol 1e-8. Printed, CPU time of this process, median of
``--runs`` runs after compilation:

* the whole call, and the compiled integration alone (``_integrate.integrate``), so the
  Python around it is their difference; which tier of the right-hand side it used;
* the same integration with the generic and with the per-structure right-hand side;
* the stepping without observers (the car's own states, one sample at the horizon);
* every step a Dormand-Prince one (no exact steps in the saturated regime);
* one right-hand side (the structure's code through its function pointer, in a loop),
  with and without the observers' derivatives, and the switching functions;
* the step statistics of each (steps, of them exact, rejected, right-hand sides, events).

Usage: python benchmarks/profile_simulate.py [--runs 30] [--rtol 1e-8]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numba as nb  # noqa: E402
import numpy as np  # noqa: E402

from inerterlab import quarter_car  # noqa: E402
from inerterlab.excitation import sine  # noqa: E402
from inerterlab.simulate import SimulationOptions, simulate_metrics  # noqa: E402
from inerterlab.systems import _compiled, _integrate, _kernel  # noqa: E402


def cpu_median(fn, runs: int) -> tuple[float, object]:
    cpus, out = [], None
    for _ in range(runs):
        c = time.process_time()
        out = fn()
        cpus.append(time.process_time() - c)
    return statistics.median(cpus), out


@nb.njit(cache=False)
def _rhs_loop(ev, n, t, x, road, itab, ftab, W, dx, imp, obs):
    ok = True
    for i in range(n):
        ok &= ev(t + 1e-9 * i, x, road, itab, ftab, W, dx, imp)
        if obs:
            _kernel.observe(itab, ftab, W, x, dx, False)
    return ok


@nb.njit(cache=False)
def _switch_loop(n, itab, ftab, W, sw):
    c = 0
    for _ in range(n):
        c += _kernel.switches(itab, ftab, W, sw)
    return c


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=30)
    ap.add_argument("--rtol", type=float, default=1e-8)
    args = ap.parse_args()
    car = quarter_car("afw", sprung_mass=370.0)
    ex = sine(0.05, 5.0)
    T = 10.0
    opts = SimulationOptions(rtol=args.rtol)
    simulate_metrics(car, ex, T, options=opts)  # compile, build the tables

    # the integration's arguments, captured from one call
    captured: list = []
    spent: list = []
    orig = _integrate.integrate

    def spy(*a, **k):
        captured.append((a, k, a[3].copy()))
        c = time.process_time()
        out = orig(*a, **k)
        spent.append(time.process_time() - c)
        return out

    _integrate.integrate = spy
    try:
        t_all, _ = cpu_median(lambda: simulate_metrics(car, ex, T, options=opts), args.runs)
    finally:
        _integrate.integrate = orig
    t_int = statistics.median(spent)
    a, k, y_start = captured[-1]
    assert not k
    itab = a[0]
    print(f"simulate_metrics: CPU {1e3 * t_all:.3f} ms; the compiled integration "
          f"{1e3 * t_int:.3f} ms; around it {1e3 * (t_all - t_int):.3f} ms "
          f"(tier used: {_compiled.rhs_for(itab, False)!r})")  # fmt: skip

    def run(ev, XE=None):
        """One integration with the right-hand side ``ev`` (a fresh state and
        statistics); ``XE``: replace the exact-step tables (an empty one: none)."""
        (itab_, ftab_, segs, y, x1, T_, rtol, atol, imp_unit, jump_ok, jump_tol, ts, Y, _,
         jumps, max_steps, v_before, vjump_tol, vjumps, XE0, XG, keys, thr, idx, cls, xq,
         ctl, *rest) = a  # fmt: skip
        xlev = rest[0] if len(rest) > 0 and rest[0] is not None else _integrate._NO_LEVELS
        xo = rest[1] if len(rest) > 1 and rest[1] is not None else _integrate._NO_XOBS
        st = np.zeros(5, np.int64)
        ro = _integrate._readonly(itab_)
        _integrate._integrate(
            ev, ro, _integrate._readonly(ftab_), segs, y_start.copy(), x1, T_, rtol, atol, imp_unit,
            jump_ok, jump_tol, ts, np.zeros_like(Y), st, np.zeros_like(jumps), max_steps,
            v_before, vjump_tol, np.zeros_like(vjumps), XE0 if XE is None else XE, XG, keys,
            thr, idx, cls, xlev, xq, ctl, xo, _integrate._split_of(itab_, ftab_, y.size),
            (ro, *_integrate.NO_SPLIT),
        )  # fmt: skip
        return st

    def show(label, ev, XE=None):
        run(ev, XE)
        c, st = cpu_median(lambda: run(ev, XE), args.runs)
        print(f"{label}: CPU {1e3 * c:.3f} ms; steps {st[0]} (exact {st[4]}), rejected "
              f"{st[1]}, right-hand sides {st[2]}, events {st[3]}")  # fmt: skip
        return c, st

    gen = _compiled.generic()
    spec = _compiled.specialised(itab)
    show("integration, generic right-hand side", gen)
    c_spec, st_spec = show("integration, per-structure right-hand side", spec)
    XE = a[19]
    show("integration, per-structure, no exact steps", spec, np.empty((0,) + XE.shape[1:]))

    # the stepping without observers: the car's own states, one sample at the horizon
    base = car  # the core system itself (quarter_car returns one)
    base_opts = dict(rtol=args.rtol, times=[T])
    base.simulate(ex, T, **base_opts)
    c, r = cpu_median(lambda: base.simulate(ex, T, **base_opts), args.runs)
    print(f"the car without observers (System.simulate, states at 10 s): CPU {1e3 * c:.3f} ms; "
          f"{r.stats}")  # fmt: skip

    # one right-hand side, at a state inside the flywheel's band (the transits)
    ftab = _integrate._readonly(a[1])
    ro = _integrate._readonly(itab)
    x = y_start.copy()
    road = np.zeros(_kernel.road_layout_of(itab)[0])
    road[1] = 0.05 * 2 * np.pi * 5.0 * 0.3
    W = np.empty(_kernel.work_size(itab))
    dx = np.empty(x.size)
    imp = np.empty(0)
    n = 200_000
    for ev, name in ((spec, "per-structure"), (gen, "generic")):
        for obs in (False, True):
            _rhs_loop(ev, 10, 0.0, x, road, ro, ftab, W, dx, imp, obs)
            c = time.process_time()
            _rhs_loop(ev, n, 0.0, x, road, ro, ftab, W, dx, imp, obs)
            c = time.process_time() - c
            print(f"one right-hand side, {name}{', with the observers' if obs else ''}: "
                  f"{1e9 * c / n:.0f} ns")  # fmt: skip
    sw = np.empty(2 * itab[_kernel.I_NE])
    _switch_loop(10, ro, ftab, W, sw)
    c = time.process_time()
    _switch_loop(n, ro, ftab, W, sw)
    print(f"the switching functions: {1e9 * (time.process_time() - c) / n:.0f} ns")
    print(f"states {x.size}, of them the car's {base.n_states}; per-structure integration "
          f"{1e3 * c_spec:.3f} ms over {st_spec[0] - st_spec[4]} Dormand-Prince steps, "
          f"{st_spec[4]} exact")  # fmt: skip


if __name__ == "__main__":
    main()
