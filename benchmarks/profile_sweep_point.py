"""Where a sweep point's CPU time goes: bench_sweep.py's grid (the `afw` car, 10 s; the
car changes every three points), each function below wrapped to add up its CPU time
(nested functions count in their callers too), per point.

    python benchmarks/profile_sweep_point.py            # 90 points
    python benchmarks/profile_sweep_point.py --points 300
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("INERTERLAB_SPECIALISE", "always")
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from bench_sweep import grid  # noqa: E402

from inerterlab.studies.quarter_car import quarter_car_point  # noqa: E402

WRAPPED = {
    "inerterlab.systems._integrate": ["integrate"],
    "inerterlab.systems.core": [
        "_simulate", "_regime_tables", "_regime_system", "_read_rows", "_length_tables",
        "_expm_lengths", "_step_tables", "_exact_plan", "_ride_system",
        "_laid_out", "_initial",
    ],
    "inerterlab.systems.quarter_car": ["_build"],
}  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=90)
    args = ap.parse_args()
    spec = grid(10_000)
    fixed = spec.fixed()
    for i in (9000, 9001, 9002):  # compile or load the kernels, outside the timing
        quarter_car_point({**fixed, **spec.params_at(i)})
    spent: dict[str, float] = {}
    for mod_name, names in WRAPPED.items():
        mod = importlib.import_module(mod_name)
        for name in names:
            spent[name] = 0.0
            fn = getattr(mod, name)

            def timed(*a, _fn=fn, _name=name, **k):
                t0 = time.process_time()
                try:
                    return _fn(*a, **k)
                finally:
                    spent[_name] += time.process_time() - t0

            setattr(mod, name, timed)
    points = [{**fixed, **spec.params_at(i)} for i in range(args.points)]
    c0 = time.process_time()
    for p in points:
        quarter_car_point(p)
    dt = time.process_time() - c0
    n = args.points
    print(f"{n} points: {1e3 * dt / n:.3f} ms CPU per point (load {os.getloadavg()[0]:.1f})")
    for name, v in spent.items():
        print(f"  {name:18s} {1e3 * v / n:7.3f} ms")


if __name__ == "__main__":
    main()
