"""Monte Carlo of the full car with a real device at the front: the time it takes,
measured (not extrapolated), with the baseline of one road run serially in this process.

The car is the packaged example full car with the thesis hydraulic device (its
identified defaults and its metal flywheel; ``[front.device] kind = "hyd"``) at both
front corners, written to a vehicle file in a temporary folder. Each road is one ISO
8608 realisation (class C, ``--length`` m at 20 m/s, samples 2 ms apart, tyres that lift
off, the ISO 2631-1 comfort observers, the first 5 s left out) driven through the
package's Monte Carlo route (:func:`inerterlab.vehicles.stochastic.monte_carlo`, the
sweep's worker processes), by RK4 at one step per road sample (``--fixed-step 0.002``,
what ``inerterlab vehicle monte-carlo --fixed-step 0.002`` runs) or adaptively
(``--fixed-step 0``, rtol 1e-6).

Printed: the baseline (CPU and wall time of one road in this process, median of
``--serial`` roads, after the preparation the Monte Carlo makes before its workers
start, so on the same compiled code); the Monte Carlo's roads,
workers, wall time, CPU time (this process plus its workers), CPU and wall time per
road, and the ratio of the serial road's wall time to the Monte Carlo's wall time per
road (what the workers gain), and the ratio of their CPU times per road (a worker's
road can cost less than the serial one: then the wall ratio exceeds the workers'
number); then the expected values: RMS over
the roads with its 95 % interval (a t interval on the mean square), the fraction of
time each front tyre is off the road and the probability that a road lifts it (Wilson
95 %).

Run: python benchmarks/bench_vehicle_monte_carlo.py [--roads 1000] [--workers 2]
     [--store mc.zarr]   (a store keeps every finished chunk: a rerun resumes it and
                          then times only what was left)
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import tempfile
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

from inerterlab.vehicles.config import example_vehicle_path  # noqa: E402
from inerterlab.vehicles.stochastic import (  # noqa: E402
    _DEFAULTS,
    _one_road,
    _prepare,
    monte_carlo,
)

DEVICE = '\n[front.device]               # both front corners\nkind = "hyd"\n'


def vehicle_file(folder: Path) -> Path:
    """The packaged example car with the hydraulic device at the front."""
    text = example_vehicle_path().read_text()
    head, sep, rest = text.partition("\n[rear]")
    if not sep:
        raise SystemExit("the packaged example car has no [rear] table")
    path = folder / "hyd_front.toml"
    path.write_text(head.rstrip("\n") + "\n" + DEVICE + sep + rest)
    return path


def cpu() -> float:
    """CPU time [s] of this process and of its waited-for children."""
    me = resource.getrusage(resource.RUSAGE_SELF)
    ch = resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + ch.ru_utime + ch.ru_stime


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--roads", type=int, default=20, help="road realisations (>= 2)")
    ap.add_argument("--workers", type=int, default=2, help="worker processes")
    ap.add_argument("--fixed-step", type=float, default=0.002,
                    help="RK4 step [s]; 0: adaptive at rtol 1e-6")  # fmt: skip
    ap.add_argument("--length", type=float, default=1200.0, help="road length [m]")
    ap.add_argument("--serial", type=int, default=3, help="roads of the serial baseline")
    ap.add_argument("--store", type=Path, default=None, help="Zarr store (resumes)")
    args = ap.parse_args()
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        path = vehicle_file(Path(tmp))
        settings = dict(length=args.length, fixed_step=args.fixed_step)
        how = (f"RK4 at a fixed step of {args.fixed_step * 1e3:g} ms" if args.fixed_step
               else f"adaptive Dormand-Prince at rtol {_DEFAULTS['rtol']:g}")  # fmt: skip
        print(f"full car, hydraulic device (kind hyd, identified defaults, metal flywheel) at "
              f"both front corners; class {_DEFAULTS['road_class']}, {args.length:g} m at "
              f"{_DEFAULTS['speed']:g} m/s ({args.length / _DEFAULTS['speed']:g} s), dt "
              f"{_DEFAULTS['dt'] * 1e3:g} ms, {how}; load average {load[0]:.1f} at the start")  # fmt: skip
        point = dict(_DEFAULTS, vehicle=str(path), **settings)
        # what the Monte Carlo does before its workers start (build the car, load the
        # compiled code, compile the structure's own right-hand side if the study pays
        # for it): the baseline runs on the code the workers will run
        _prepare(str(path), "full", args.roads, 0, settings)
        walls, cpus = [], []
        for k in range(args.serial):
            c0, t0 = time.process_time(), time.perf_counter()
            _one_road(dict(point, seed=10_001 + k), "full")
            walls.append(time.perf_counter() - t0)
            cpus.append(time.process_time() - c0)
        w1, c1 = statistics.median(walls), statistics.median(cpus)
        print(f"baseline, one road serially in this process (median of {args.serial}): "
              f"{w1:.3f} s wall, {c1:.3f} s CPU")  # fmt: skip

        c0, t0 = cpu(), time.perf_counter()
        res = monte_carlo(vehicle=str(path), model="full", roads=args.roads, store=args.store,
                          backend="processes", workers=args.workers, **settings)  # fmt: skip
        wall, used = time.perf_counter() - t0, cpu() - c0
    n = args.roads
    print(f"Monte Carlo: {n} roads ({res.realisations} succeeded), {args.workers} workers: "
          f"{wall:.1f} s wall, {used:.1f} s CPU (this process and its workers); per road "
          f"{wall / n:.3f} s wall, {used / n:.3f} s CPU; serial road / Monte Carlo wall per "
          f"road: {w1 / (wall / n):.2f} on {args.workers} workers, CPU per road serial / "
          f"Monte Carlo: {c1 / (used / n):.2f} (above 1: a worker's road costs less than the "
          f"serial one, so the wall ratio can exceed the workers' number); load average "
          f"{os.getloadavg()[0]:.1f} at the end")  # fmt: skip
    print("expected values over the roads (RMS about static equilibrium, 95 % interval):")
    units = {"bounce_acc": "m/s^2", "pitch_acc": "rad/s^2", "seat_acc_wk": "m/s^2"}
    for name, (val, (lo, hi)) in res.rms.items():
        unit = units.get(name, "m" if name.endswith("deflection") else "N")
        print(f"  {name:26s} {val:.6g} {unit}  [{lo:.6g}, {hi:.6g}]")
    for c in ("front_left", "front_right"):
        f, (lo, hi) = res.lift_off_fraction[c]
        p, (plo, phi) = res.lift_off_probability[c]
        print(f"  {c} time off the road {f:.4g} [{lo:.4g}, {hi:.4g}] (fraction of time); "
              f"roads that lift it {p:.3g} [{plo:.3g}, {phi:.3g}] (probability)")  # fmt: skip


if __name__ == "__main__":
    main()
