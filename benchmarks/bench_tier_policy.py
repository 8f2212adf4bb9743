"""A first sweep of a new structure: when its own compiled code pays.

A user's sweep of the ``afw`` quarter car (the grid of ``bench_sweep.py``, 10 s runs) on
2 worker processes, the generic kernels compiled, the structure's own code not yet on
disk, under the three settings of ``INERTERLAB_SPECIALISE``:

* ``never``: the generic code throughout (baseline);
* ``always``: the structure's code compiled at the first run (one worker compiles, the
  other waits for it and loads it);
* ``auto`` (the default): the structure's code once a process has run it for
  ``SPECIALISE_AFTER_SECONDS`` of CPU with the generic code (one worker compiles, the
  other goes on with the generic code meanwhile).

Everything runs in a scratch numba cache (a temporary directory, removed at the end):
the kernels are compiled there first (about a minute), and the structures' code is
removed from it before each sweep. Prints per size and setting the wall time, the
workers' CPU time, the number of structures compiled, and the ratio of ``auto``'s wall
time to the better of the other two (the policy's cost against hindsight; at most 2 by
its design).

    python benchmarks/bench_tier_policy.py                 # 3000 and 20000 points
    python benchmarks/bench_tier_policy.py --points 3000
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))

_SWEEP = """
import json, os, resource, sys, tempfile, time
sys.path.insert(0, {here!r})
from bench_sweep import grid
from inerterlab.studies import sweep
spec = grid({points})
with tempfile.TemporaryDirectory() as tmp:
    t0 = time.perf_counter()
    ds = sweep(spec, store=os.path.join(tmp, "s.zarr"), backend="processes", workers=2)
    dt = time.perf_counter() - t0
r = resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps(dict(points=spec.size, wall=dt, cpu=r.ru_utime + r.ru_stime,
                      ok=int(ds.attrs["points_ok"]))))
"""

_WARM = """
import sys
sys.path.insert(0, {here!r})
from bench_sweep import grid
from inerterlab.studies.quarter_car import quarter_car_point
spec = grid(30)
quarter_car_point({{**spec.fixed(), **spec.params_at(0)}})
"""


def _run(code: str, cache: str, tier: str) -> str:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, INERTERLAB_SPECIALISE=tier, NUMBA_NUM_THREADS="1")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(f"benchmark run failed:\n{out.stderr[-2000:]}")
    return out.stdout


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, nargs="+", default=[3000, 20000])
    args = ap.parse_args()
    cache = tempfile.mkdtemp(prefix="inerterlab-bench-cache-")
    try:
        print("compiling the kernels into a scratch cache (generic code) ...", flush=True)
        _run(_WARM.format(here=HERE), cache, "never")
        for n in args.points:
            walls = {}
            for tier in ("never", "always", "auto"):
                for d in glob.glob(os.path.join(cache, "structures*")):  # the scratch cache's
                    shutil.rmtree(d)
                got = json.loads(_run(_SWEEP.format(here=HERE, points=n), cache, tier))
                done = len(glob.glob(os.path.join(cache, "structures", "s_*.done")))
                walls[tier] = got["wall"]
                print(
                    f"{got['points']:6d} points, {tier:>6}: {got['wall']:6.1f} s wall "
                    f"({got['points'] / got['wall']:5.0f} points/s), workers' CPU "
                    f"{got['cpu']:6.1f} s, structures compiled {done}, ok {got['ok']}",
                    flush=True,
                )
            best = min(walls["never"], walls["always"])
            print(
                f"{n:6d} points: auto / best of never and always (wall): {walls['auto'] / best:.2f}"
            )
    finally:
        shutil.rmtree(cache, ignore_errors=True)


if __name__ == "__main__":
    main()
