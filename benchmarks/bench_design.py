"""Wall time of the default quarter-car ``inerterlab design`` study.

Default study: the thesis car (370 kg / 25 kg, tyre 120 kN/m and 1300 N s/m, main
spring 90 kN/m), ISO 8608 class C at 25 m/s, budget 2 springs, 1 damper, 1 inerter
(17 layouts), objective body_acc_wk, four devices (hydraulic, rectifier, screw, fluid)
re-checked in the best single-inerter layout where the device acts, 20 roads of 10 s
per candidate, device requirements by the ITP crossing, the HTML report with its
figures; 2 worker processes.

Prints, each measured in this run:
- the warm-up (loading the compiled kernels in this process, one simulation and one
  H2 optimisation), which a fresh process pays once;
- the study into a fresh folder (every stage computed) against the target of 90 s,
  with the wall and CPU seconds of each stage (CPU of this process and its workers: the
  sum, less sensitive to other work on the machine than the wall time) and the load
  average;
- the same study rerun into the same folder (every stage read from its stores), and
  the ratio fresh / resumed.

With ``--model full`` (or ``half``): the same study for the packaged example vehicle
(docs/guide/vehicles.md) as a full (half) car, objective seat_wk (the same layout at
every corner, values per axle; vehicle simulations on the roads); it prints the fresh
time and its stages against the quarter car's target (the issue asks only to state it).

Run: python benchmarks/bench_design.py [--workers 2] [--model quarter|half|full]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path


def _cpu() -> float:
    """CPU seconds of this process and of its finished worker processes."""
    from inerterlab.design.pipeline import process_cpu

    return process_cpu()


def _stages(res: dict, figures: tuple) -> str:
    """Each stage's wall and CPU seconds (the CPU of this process and its workers)."""
    cpu = res.get("stage_cpu_seconds", {})
    parts = [f"{k} {v:.1f} / {cpu.get(k, float('nan')):.1f}"
             for k, v in res["stage_seconds"].items()]  # fmt: skip
    parts.append(f"report figures {figures[0]:.1f} / {figures[1]:.1f}")
    return ", ".join(parts)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--model", choices=("quarter", "half", "full"), default="quarter")
    args = ap.parse_args()
    if args.model != "quarter":
        vehicle_study(args.model, args.workers)
        return

    t = time.perf_counter()
    from inerterlab import excitation as ex
    from inerterlab.design import DesignSettings, run_design
    from inerterlab.design.report import figures, render_html
    from inerterlab.network_design import optimize_network
    from inerterlab.systems import quarter_car

    quarter_car("k | c", {"k": 9e4, "c": 3e3}).simulate(ex.iso8608("C", 25.0), horizon=2.0)
    optimize_network("k | (c - b)", "body_acc", fixed={"k": 9e4}, compare=False)
    warm = time.perf_counter() - t

    st = DesignSettings(objective="body_acc_wk")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "design"
        times, stages, fig_s, cpu = [], [], [], []
        load0 = os.getloadavg()[0]
        for _ in range(2):
            t = time.perf_counter()
            c = _cpu()
            res = run_design(st, out, workers=args.workers)
            t1 = time.perf_counter()
            c1 = _cpu()
            figs = figures(res)
            (out / "report.html").write_text(render_html(res, figs))
            times.append(time.perf_counter() - t)
            cpu.append(_cpu() - c)
            fig_s.append((time.perf_counter() - t1, _cpu() - c1))
            stages.append(res)
    fresh, resumed = times
    best = res["ranking"][0]
    print(f"warm-up (compiled kernels, one simulation, one H2 optimisation): {warm:.1f} s")
    print(f"load average (1 min) at the start {load0:.1f}, at the end {os.getloadavg()[0]:.1f} "
          f"(other work on the machine); CPU of the fresh study {cpu[0]:.1f} s "
          f"(this process and its workers; / {args.workers} = {cpu[0] / args.workers:.1f} s)")
    print(
        f"default design study, fresh folder, {args.workers} workers: {fresh:.1f} s "
        f"(target 90 s: {'met' if fresh <= 90 else 'missed'}); "
        f"{len(res['layouts'])} layouts, {len(res['ranking'])} candidates x {st.roads} roads"
    )
    print("  stages, wall / CPU (s): " + _stages(stages[0], fig_s[0]))
    print(
        f"same study resumed from its stores: {resumed:.1f} s; fresh / resumed = {fresh / resumed:.1f}"
    )
    print(
        f"best: {best['label']}: {best['objective']} {best['expected']:.4g} "
        f"+- {best['interval95']:.2g} {best['unit']} (expected value, 95 % interval), "
        f"{best['gain_percent']:+.2f} +- {best['gain_interval95']:.2f} % vs k | c"
    )


def vehicle_study(model: str, workers: int) -> None:
    import warnings

    from inerterlab.design import DesignSettings, run_design
    from inerterlab.design.report import figures, render_html
    from inerterlab.vehicles import example_vehicle_path

    warnings.simplefilter("ignore", RuntimeWarning)  # scipy's Lyapunov near-singular notes
    st = DesignSettings(vehicle=example_vehicle_path().read_text(), model=model,
                        objective="seat_wk")  # fmt: skip
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "design"
        t = time.perf_counter()
        c = _cpu()
        res = run_design(st, out, workers=workers)
        t1 = time.perf_counter()
        c1 = _cpu()
        figs = figures(res)
        (out / "report.html").write_text(render_html(res, figs))
        fresh = time.perf_counter() - t
        cpu = _cpu() - c
        fig_s = (time.perf_counter() - t1, _cpu() - c1)
    best = res["ranking"][0]
    print(f"load average (1 min) at the start {load0:.1f}, at the end {os.getloadavg()[0]:.1f} "
          f"(other work on the machine); CPU {cpu:.1f} s (this process and its workers)")  # fmt: skip
    print(
        f"{model}-car design study (example vehicle, seat_wk, budget 2/1/1, four devices, "
        f"{st.roads} roads of {st.horizon:g} s), fresh folder, {workers} workers: {fresh:.1f} s "
        f"(the quarter car's target is 90 s; this time is stated, not targeted); "
        f"{len(res['layouts'])} layouts, {len(res['ranking'])} candidates"
    )
    print("  stages, wall / CPU (s): " + _stages(res, fig_s))
    print(
        f"best: {best['label']}: {best['objective']} {best['expected']:.4g} "
        f"+- {best['interval95']:.2g} {best['unit']} (expected value, 95 % interval), "
        f"{best['gain_percent']:+.2f} +- {best['gain_interval95']:.2f} % vs k | c"
    )


if __name__ == "__main__":
    main()
