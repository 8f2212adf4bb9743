"""Where the compiled code's time goes, by function (a profile, not a benchmark).

A sampling profile (Linux ``perf``) of one workload, its samples attributed to numba's
compiled functions. perf sees numba's machine code as anonymous memory without symbols,
so this script runs the workload in a child process with a scratch numba cache
directory (numba keeps a library's object file only when it compiles it, so every kernel
is compiled afresh: a few minutes), reads each compiled library's symbols from its object
file (``nm``) and the address it was loaded at, and attributes each sample taken while
the workload repeats (after compilation) to the function that holds it. numba's
reference counting (``NRT_incref``/``NRT_decref``: an atomic operation per array a
reference-counted function takes, views or loops over) is its own line; the Python
around the compiled code is ``libpython``; ``libm`` is the complex exponential and the
like.

Workloads:

* ``quarter-car``: the case of ``bench_simulate.py`` (the ``afw`` car, 5 cm 5 Hz sine,
  10 s, the ride observers, one sample at the horizon);
* ``quarter-car-states``: the same car without observers;
* ``vehicle-rk4``, ``vehicle-dopri``: the full car of ``bench_vehicle_afw.py`` (60 s),
  classical Runge-Kutta one step per sample, Dormand-Prince at rtol 1e-6;
* ``vehicle-comfort``: the same car through ``simulate_vehicle`` (``vehicle simulate``'s
  route: Dormand-Prince at rtol 1e-6 with the ISO 2631 comfort observers as states).

Usage: python benchmarks/profile_jit.py quarter-car [--seconds 10] [--top 25]
(needs ``perf`` and ``nm``).
"""

from __future__ import annotations

import argparse
import bisect
import collections
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

WORKLOADS = ("quarter-car", "quarter-car-states", "vehicle-rk4", "vehicle-dopri", "vehicle-comfort")


def _workload(name: str):
    """The function that runs the workload once."""
    import numpy as np

    if name.startswith("quarter-car"):
        from inerterlab.excitation import sine
        from inerterlab.systems import quarter_car
        from inerterlab.systems.core import _simulate
        from inerterlab.systems.observers import ride, with_observers
        from inerterlab.systems.options import SimulationOptions

        base = quarter_car("afw", sprung_mass=370.0)
        sys_ = with_observers(base, ride(base)) if name == "quarter-car" else base
        ex, opts, at = sine(0.05, 5.0), SimulationOptions(rtol=1e-8), np.array([10.0])
        return lambda: _simulate(sys_, ex, 10.0, opts, times=at, ride=False)
    sys.path.insert(0, str(Path(__file__).parent))
    from bench_vehicle_afw import setup

    from inerterlab.systems.vehicle import simulate, vehicle

    params, _, r, dt = setup()
    core = vehicle(params)
    if name == "vehicle-rk4":
        return lambda: simulate(core, r, dt, fixed_step=dt, fixed_method="rk4")
    if name == "vehicle-comfort":
        from inerterlab.vehicles.simulation import simulate_vehicle

        return lambda: simulate_vehicle(params, r, dt, system=core)
    return lambda: simulate(core, r, dt, rtol=1e-6)


def _symbols(path: str) -> None:
    """Write (address, size, name) of every function in the compiled libraries of the
    package's kernels, and numba's reference counting, to ``path``."""
    from numba.core.registry import CPUDispatcher
    from numba.core.runtime.nrt import rtsys

    rows = []
    for mname, mod in list(sys.modules.items()):
        if not mname.startswith("inerterlab"):
            continue
        for attr, obj in list(vars(mod).items()):
            if not isinstance(obj, CPUDispatcher):
                continue
            for cres in obj.overloads.values():
                lib = cres.library
                try:
                    blob = lib._get_compiled_object()
                except RuntimeError:  # loaded from a cache: no object file kept
                    continue
                entry = cres.fndesc.llvm_func_name
                with tempfile.NamedTemporaryFile(suffix=".o", delete=False) as fh:
                    fh.write(blob)
                out = subprocess.run(
                    ["nm", "-S", "--defined-only", fh.name], capture_output=True, text=True
                ).stdout
                os.unlink(fh.name)
                syms = {}
                for line in out.splitlines():
                    p = line.split()
                    if len(p) == 4 and p[2] in "tT":
                        syms[p[3]] = (int(p[0], 16), int(p[1], 16))
                if entry not in syms:
                    continue
                base = lib.get_pointer_to_function(entry) - syms[entry][0]
                label = f"{mname.rsplit('.', 1)[-1]}.{attr}"
                rows += [(base + off, size, label) for off, size in syms.values()]
    for name in ("NRT_incref", "NRT_decref"):
        rows.append((rtsys.library.get_pointer_to_function(name), 16, "numba reference counting"))
    with open(path, "w") as fh:
        for a, s, label in sorted(rows):
            fh.write(f"{a} {s} {label}\n")


def child(args) -> None:
    run = _workload(args.workload)
    run()  # compile
    run()
    print(f"START {time.monotonic():.6f}", flush=True)
    t0 = time.monotonic()
    n = 0
    while time.monotonic() - t0 < args.seconds:
        run()
        n += 1
    print(f"STOP {time.monotonic():.6f} {n}", flush=True)
    _symbols(args.symbols)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("workload", choices=WORKLOADS)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--symbols", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(args)
        return
    with tempfile.TemporaryDirectory() as tmp:
        data, sym = os.path.join(tmp, "perf.data"), os.path.join(tmp, "symbols.txt")
        env = dict(os.environ, NUMBA_CACHE_DIR=os.path.join(tmp, "numba"),
                   INERTERLAB_SPECIALISE="always", NUMBA_NUM_THREADS="1")  # fmt: skip
        cmd = ["perf", "record", "-q", "-k", "mono", "-F", "1999", "-o", data, "--",
               sys.executable, __file__, args.workload, "--child", "--seconds",
               str(args.seconds), "--symbols", sym]  # fmt: skip
        print(f"compiling every kernel afresh, then {args.seconds:g} s of {args.workload}")
        out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True).stdout
        marks = {line.split()[0]: line.split()[1:] for line in out.splitlines() if line[:4] in ("STAR", "STOP")}
        t0, t1, runs = float(marks["START"][0]), float(marks["STOP"][0]), int(marks["STOP"][1])
        table = []
        for line in open(sym):
            a, s, label = line.rstrip("\n").split(" ", 2)
            table.append((int(a), int(s), label))
        starts = [r[0] for r in table]
        script = subprocess.run(["perf", "script", "-i", data, "-F", "time,ip,dso"],
                                capture_output=True, text=True, check=True).stdout  # fmt: skip
        count: collections.Counter = collections.Counter()
        total = 0
        for line in script.splitlines():
            p = line.split()
            if len(p) < 3 or not t0 <= float(p[0].rstrip(":")) <= t1:
                continue
            total += 1
            ip, dso = int(p[1], 16), p[2]
            i = bisect.bisect_right(starts, ip) - 1
            if i >= 0 and ip < table[i][0] + table[i][1]:
                count[table[i][2]] += 1
            elif "perf-" in dso or "JIT" in dso:
                count["compiled, not attributed"] += 1
            else:
                count[os.path.basename(dso.strip("()")).split(".so")[0]] += 1
    print(f"{runs} runs in {t1 - t0:.1f} s ({1e3 * (t1 - t0) / max(runs, 1):.2f} ms of wall time a run); "
          f"{total} samples; share of the samples:")  # fmt: skip
    for label, c in count.most_common(args.top):
        print(f"  {100.0 * c / max(total, 1):5.1f} %  {label}")


if __name__ == "__main__":
    main()
