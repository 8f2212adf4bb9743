"""Sweep throughput: the `afw` quarter car (10 s horizon) on the serial backend and on
2 local worker processes, same grid, same store layout.

Prints points/s for each, their ratio (baseline: the serial backend measured in the same
run), and the largest difference between the two results (must be 0: the backends
evaluate the same function on the same points). The serial run is split into the time
inside the integrator (the compiled integration calls: adaptive steps, exact steps) and
everything around it (the point function, the car's description and core system, the
observers, the metrics, the sweep machinery and the store writes).

    python benchmarks/bench_sweep.py            # 10,000 points
    python benchmarks/bench_sweep.py --points 200
"""

from __future__ import annotations

import argparse
import math
import os
import tempfile
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
# the steady state of a long sweep: the right-hand side compiled for the car's structure
# from the first point on (by default a process compiles it once its integrations of
# the structure have taken 2 s, which would put that compilation inside the timing)
os.environ.setdefault("INERTERLAB_SPECIALISE", "always")

import numpy as np  # noqa: E402

from inerterlab.studies import sweep, sweep_spec  # noqa: E402
from inerterlab.studies.quarter_car import quarter_car_point  # noqa: E402


def grid(points: int):
    n_mass = 10
    n_ratio = max(1, math.ceil(points / (3 * n_mass)))
    return sweep_spec(
        "quarter-car",
        parameters={
            "changing_ratio": {"start": 0.05, "stop": 0.55, "num": n_ratio},
            "sprung_mass": {"start": 340.0, "stop": 400.0, "num": n_mass},
            "input": ["drop", "bump", "sine"],
        },
        settings={"suspension": "afw", "horizon": 10.0},
    )


def _timed(module, name: str, spent: list) -> None:
    """Wrap ``module.name`` so that its CPU time is added to ``spent[0]``."""
    fn = getattr(module, name)

    def timed(*args, **kwargs):
        t0 = time.process_time()
        try:
            return fn(*args, **kwargs)
        finally:
            spent[0] += time.process_time() - t0

    setattr(module, name, timed)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=10_000)
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    spec = grid(args.points)
    # compile the kernels (or load them from numba's cache) once in this process: the
    # worker processes are forked from it and inherit the compiled code, so neither
    # timing below includes compilation; its cost is reported here
    t0 = time.perf_counter()
    quarter_car_point({**spec.fixed(), **spec.params_at(0)})
    print(f"first point (compilation or cache load): {time.perf_counter() - t0:.2f} s")
    # and the store's own first use (importing zarr, its codecs and event loop: about
    # 0.9 s of CPU once per process, which would otherwise land in the serial timing)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        sweep(sweep_spec("synthetic", parameters={"changing_ratio": [0.1]}),
              store=os.path.join(tmp, "first.zarr"), backend="serial")  # fmt: skip
    print(f"first store (imports, once per process): {time.perf_counter() - t0:.2f} s")
    # the time inside the integrator: the compiled integration calls of the core
    from inerterlab.systems import _integrate, core

    spent = [0.0]
    _timed(_integrate, "integrate", spent)  # adaptive steps (and exact steps in regimes)
    _timed(core, "_exact", spent)  # matrix-exponential steps of a linear system
    rates, results, serial = {}, {}, None
    with tempfile.TemporaryDirectory() as tmp:
        for name, kw in (
            ("serial", {"backend": "serial"}),
            (f"{args.workers} processes", {"backend": "processes", "workers": args.workers}),
        ):
            spent[0] = 0.0
            t0, c0 = time.perf_counter(), time.process_time()
            ds = sweep(spec, store=os.path.join(tmp, name.replace(" ", "_") + ".zarr"), **kw)
            dt = time.perf_counter() - t0
            rates[name] = spec.size / dt
            results[name] = ds
            if serial is None:  # CPU times of this process: the split does not see the load
                serial = (time.process_time() - c0, spent[0])
            print(
                f"{name:>12}: {spec.size} points in {dt:7.2f} s = {rates[name]:8.1f} points/s "
                f"(ok {ds.attrs['points_ok']}, failed {ds.attrs['points_failed']})"
            )
    dt, inside = serial
    print(
        f"split of the serial run (CPU time per point): {1e3 * inside / spec.size:.3f} ms in "
        f"the integrator, {1e3 * (dt - inside) / spec.size:.3f} ms around it (point "
        f"function, description, core system, observers, metrics, sweep machinery, store) "
        f"= {100 * (dt - inside) / dt:.1f} % of the time"
    )
    print(f"machine load (1-minute average) at the end: {os.getloadavg()[0]:.1f}")
    a, b = results.values()
    diff = max(
        float(np.nanmax(np.abs(a[m].values - b[m].values)))
        for m in ("rms_body_acc", "rms_tyre_grip")
    )
    base, par = rates.values()
    print(
        f"speed-up {args.workers} processes / serial: {par / base:.2f}x; "
        f"largest difference between backends: {diff:g}"
    )
    # machinery overhead alone: the same grid on the closed-form synthetic point function
    syn = sweep_spec("synthetic", parameters={k: list(v) for k, v in spec.parameters})
    with tempfile.TemporaryDirectory() as tmp:
        c0 = time.process_time()
        sweep(syn, store=os.path.join(tmp, "serial.zarr"), backend="serial")
        machinery = (time.process_time() - c0) / syn.size
    print(
        f"  of the {1e3 * (dt - inside) / spec.size:.3f} ms around the integrator: "
        f"{1e3 * machinery:.3f} ms the sweep machinery and the store (the same grid on the "
        f"closed-form synthetic point function, serial), "
        f"{1e3 * ((dt - inside) / spec.size - machinery):.3f} ms the point function"
    )
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        sweep(syn, store=os.path.join(tmp, "s.zarr"), backend="processes", workers=args.workers)
        dt = time.perf_counter() - t0
    print(
        f"machinery overhead (synthetic points, Zarr store, {args.workers} processes): "
        f"{1e6 * dt / syn.size:.0f} us per point = {syn.size / dt:.0f} points/s"
    )
    print(
        f"target >= 2000 points/s with 2 workers on the model core: "
        f"{'met' if par >= 2000 else 'not met'} "
        f"({par:.1f} points/s; one 10 s simulation takes {1e3 / base:.1f} ms serially)"
    )


if __name__ == "__main__":
    main()
