"""Speed and accuracy of the scanning harmonic balance against brute-force time integration.

Chapter-7 system (7.1), metal flywheel, thesis law, B = 3 cm. Prints, from one run:
- time per frequency point of sihb (H = 15) over the thesis's full curve
  (0.005..10 Hz at 0.005 Hz = 2000 points, scanned down and up = 4000 solves), with and
  without Hill stability, for N = 128 (default) and N = 64 samples;
- time per point of brute force with the scipy DOP853 reference (rtol 1e-10; the tests'
  oracle, ``tests/_frequency_oracle.py``) and with the package's compiled RK4, on a few
  frequencies, and the ratios;
- the accuracy reached: NRMSE (7.16) of sihb against brute force on a subset.

Quarter car (afw, nylon flywheel, thesis law, road amplitude 1 cm), first-order harmonic
balance on the time simulation's right-hand side: 2000 points 0.5..20 Hz scanned down
and up (4000 solves) with Hill stability, the median of 3 runs (compilation excluded),
on the structure's own compiled code (the limit's case) and on the generic code;
brute force (RK4 on the same right-hand side to steady state) per point on a subset, the
ratio, and the NRMSE of every output against it.

Run: NUMBA_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_frequency.py
     [--only chapter7 | --only quarter-car] [--baseline SRC [--rounds 3]]

With ``--baseline SRC`` (the ``src`` folder of another checkout, e.g. the tree before a
change: ``git archive <commit> src | tar -x -C /tmp/base``) the timings alone are taken
in child processes, alternately on SRC and on this tree, ``--rounds`` times each, with the
ratio this tree / baseline (> 1: slower), so both are measured in the same run under the
same machine load. Every timing is the median of its repeats; the comparison prints the
median over the rounds (and the fastest).
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import numpy as np  # noqa: E402

import _frequency_oracle as oracle  # noqa: E402
from inerterlab.frequency import (  # noqa: E402
    chapter7_system,
    frequency_grid,
    frequency_response,
)


def timed(fn, repeat=3, best=False):
    """Median (or, with ``best``, the fastest) of ``repeat`` runs [s], and the result."""
    times = []
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return (min(times) if best else statistics.median(times)), out


def quarter_car_part() -> None:
    from inerterlab import quarter_car

    car = quarter_car("afw")
    amp = 0.01
    freqs = np.linspace(0.5, 20.0, 2000)
    # both tiers of the evaluation, named: the generic code (a first response of a car)
    # and the structure's own (a user's later responses of it: after 10 s of responses
    # or integrations on the generic code, inerterlab.systems._compiled); the same numbers
    mode = os.environ.get("INERTERLAB_SPECIALISE")
    os.environ["INERTERLAB_SPECIALISE"] = "never"
    frequency_response(car, "sihb", freq_hz=freqs[:20], amplitude=amp)  # compile
    t_gen, fr_gen = timed(lambda: frequency_response(car, "sihb", freq_hz=freqs, amplitude=amp))
    os.environ["INERTERLAB_SPECIALISE"] = "always"
    frequency_response(car, "sihb", freq_hz=freqs[:20], amplitude=amp)  # the structure's code
    frequency_response(car, "brute", freq_hz=[5.0], amplitude=amp, steps_per_period=400)
    t, fr = timed(lambda: frequency_response(car, "sihb", freq_hz=freqs, amplitude=amp))
    if mode is None:
        del os.environ["INERTERLAB_SPECIALISE"]
    else:
        os.environ["INERTERLAB_SPECIALISE"] = mode
    same = np.array_equal(fr.coefficients, fr_gen.coefficients)
    per = t / len(fr)
    print(
        f"quarter car afw, A = 1 cm: {len(freqs)} points 0.5..20 Hz scanned down and up "
        f"({len(fr)} solves), H={fr.harmonics}, N={fr.settings['n_samples']}, Hill stability "
        f"on (harmonics 0..{fr.settings['stability_harmonics']})"
    )
    print(
        f"  sihb on the structure's own code: {t:7.3f} s total (median of 3), "
        f"{1e3 * per:.4f} ms/point, converged "
        f"{int(fr.converged.sum())}/{len(fr)}, stable {int(fr.stable.sum())}, mean iterations "
        f"{fr.iterations.mean():.2f}, max relative residual {fr.residual.max():.1e}"
    )
    print(
        f"  sihb on the generic code (a car's first responses): {t_gen:7.3f} s total (median "
        f"of 3); the same coefficients to the last bit: {same}"
    )
    sub = np.array([0.5, 1.0, 1.3, 1.6, 2.0, 3.0, 5.0, 8.0, 9.5, 11.0, 14.0, 20.0])
    t_b, br = timed(
        lambda: frequency_response(
            car, "brute", freq_hz=sub, amplitude=amp, steps_per_period=4000, brute_rtol=1e-10
        ),
        1,
    )
    per_b = t_b / len(sub)
    print(
        f"  brute force (RK4, 4000 steps/period, settle rtol 1e-10) on {sub.tolist()} Hz: "
        f"{per_b:.4f} s/point; speed-up per point of sihb: {per_b / per:.0f}x"
    )
    # the former default H = 9 in the same run: cost ratio and pointwise accuracy
    t9, fr9 = timed(
        lambda: frequency_response(car, "sihb", freq_hz=freqs, amplitude=amp, harmonics=9)
    )
    print(f"  sihb H=9 (former default): {t9:7.3f} s total; H={fr.harmonics} costs {t / t9:.2f}x")
    for h_count in (9, fr.harmonics):
        hb = frequency_response(car, "sihb", freq_hz=sub, amplitude=amp, harmonics=h_count)
        worst = (0.0, "", 0.0)
        for d in ("down", "up"):
            h = hb.branch(d)
            order = np.argsort(h.freq_hz)
            for name in br.outputs:
                rel = np.abs(h.outputs[name].data[order] / br.outputs[name].data - 1.0)
                i = int(np.argmax(rel))
                worst = max(worst, (float(rel[i]), name, float(sub[i])))
        print(
            f"  H={h_count}: largest relative error of one point {100 * worst[0]:.3f} % "
            f"({worst[1]} at {worst[2]:g} Hz)"
        )
    hb = frequency_response(car, "sihb", freq_hz=sub, amplitude=amp)
    for d in ("down", "up"):
        h = hb.branch(d)
        order = np.argsort(h.freq_hz)
        errs = []
        for name in br.outputs:
            x, y = h.outputs[name].data[order], br.outputs[name].data
            errs.append(f"{name} {100 * np.sqrt(np.sum((x - y) ** 2) / np.sum(y**2)):.4f} %")
        print(f"  NRMSE vs brute force, scan {d}: " + ", ".join(errs))


def timings(only) -> dict:
    """The timings alone [s] (compilation excluded), for the same-run comparison."""
    out = {}
    if only != "chapter7":
        from inerterlab import quarter_car

        car = quarter_car("afw")
        freqs = np.linspace(0.5, 20.0, 2000)
        frequency_response(car, "sihb", freq_hz=freqs[:20], amplitude=0.01)
        frequency_response(car, "brute", freq_hz=[5.0], amplitude=0.01, steps_per_period=400)
        out["quarter car sihb, 4000 solves, stability on [s]"] = timed(
            lambda: frequency_response(car, "sihb", freq_hz=freqs, amplitude=0.01), 3
        )[0]
        sub = [1.0, 5.0, 11.0]
        out["quarter car RK4 brute force, per point [s]"] = timed(
            lambda: frequency_response(
                car,
                "brute",
                freq_hz=sub,
                amplitude=0.01,
                steps_per_period=4000,
                brute_rtol=1e-10,
            ),  # fmt: skip
            3,
        )[0] / len(sub)
    if only != "quarter-car":
        sys = chapter7_system(0.03)
        grid = frequency_grid(0.005, 10.0, 0.005)
        frequency_response(sys, "sihb", freq_hz=grid[:20], harmonics=15)
        frequency_response(sys, "sihb", freq_hz=grid[:20], harmonics=15, n_samples=64)
        frequency_response(sys, "sihb", freq_hz=grid[:20], harmonics=15, stability=True)
        frequency_response(sys, "brute", freq_hz=[1.0])
        for n, stab, reps in ((128, False, 5), (64, False, 5), (128, True, 2)):
            key = f"chapter 7 sihb H=15 N={n}, 4000 solves, stability {'on' if stab else 'off'} [s]"
            out[key] = timed(
                lambda n=n, stab=stab: frequency_response(
                    sys, "sihb", freq_hz=grid, harmonics=15, n_samples=n, stability=stab
                ),
                reps,
            )[0]
        for method, h in (("mhb", 7), ("shb", 1)):  # as the report runs them
            frequency_response(sys, method, freq_hz=grid[:20], harmonics=h, stability=False)
            out[f"chapter 7 {method} H={h}, 2000 solves from rest, stability off [s]"] = timed(
                lambda method=method, h=h: frequency_response(
                    sys, method, freq_hz=grid, harmonics=h, stability=False
                ),
                5,
            )[0]
        sub = np.array([0.3, 0.8, 1.15, 1.6, 2.5, 5.0])
        out["chapter 7 RK4 brute force, per point [s]"] = timed(
            lambda: frequency_response(sys, "brute", freq_hz=sub), 5
        )[0] / len(sub)
    return out


def compare(baseline: str, only, rounds: int) -> None:
    """Timings of the baseline tree and of this one, alternately in child processes."""
    import json
    import subprocess
    import sys
    from pathlib import Path

    here = str(Path(__file__).resolve().parents[1] / "src")
    runs: dict = {"baseline": [], "this tree": []}
    for _ in range(rounds):
        for name, src in (("baseline", baseline), ("this tree", here)):
            env = dict(os.environ, PYTHONPATH=src)
            cmd = [sys.executable, __file__, "--timings-json"]
            if only:
                cmd += ["--only", only]
            res = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
            runs[name].append(json.loads(res.stdout.strip().splitlines()[-1]))
    print(
        f"same-run comparison, {rounds} alternating child runs each (each timing the median "
        "of its repeats); median over the runs, the ratio of medians, then the fastest"
    )
    print(f"  baseline: {baseline}")
    print(f"  this tree: {here}")
    for key in runs["baseline"][0]:
        if not all(key in r for r in runs["this tree"]):
            continue
        old = statistics.median(r[key] for r in runs["baseline"])
        new = statistics.median(r[key] for r in runs["this tree"])
        fo = min(r[key] for r in runs["baseline"])
        fn = min(r[key] for r in runs["this tree"])
        print(
            f"  {key}: baseline {old:.4f}, this tree {new:.4f}, ratio {new / old:.3f} "
            f"(fastest {fo:.4f} -> {fn:.4f})"
        )


def main() -> None:
    import argparse
    import json

    ap = argparse.ArgumentParser()
    ap.add_argument("--only", choices=("chapter7", "quarter-car"), default=None)
    ap.add_argument("--baseline", default=None, help="src folder of the tree to compare with")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--timings-json", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    only = args.only
    if args.timings_json:
        print(json.dumps(timings(only)))
        return
    if args.baseline:
        compare(args.baseline, only, args.rounds)
        return
    if only != "chapter7":
        quarter_car_part()
    if only == "quarter-car":
        return
    sys = chapter7_system(0.03)
    grid = frequency_grid(0.005, 10.0, 0.005)
    # warm-up (numba compilation, cached on disk after the first run)
    frequency_response(sys, "sihb", freq_hz=grid[:20], harmonics=15)
    frequency_response(sys, "sihb", freq_hz=grid[:20], harmonics=15, n_samples=64)
    frequency_response(sys, "brute", freq_hz=[1.0])

    print("full thesis curve: 2000 points 0.005..10 Hz, scanned down and up (4000 solves)")
    results = {}
    for n, stab in ((128, False), (64, False), (128, True)):
        reps = 1 if stab else 3
        t, fr = timed(
            lambda n=n, stab=stab: frequency_response(
                sys, "sihb", freq_hz=grid, harmonics=15, n_samples=n, stability=stab
            ),
            reps,
        )
        results[(n, stab)] = (t, fr)
        print(
            f"  sihb H=15 N={n:3d} stability={'on ' if stab else 'off'}: {t:7.3f} s total, "
            f"{1e3 * t / len(fr):.4f} ms/point, converged {int(fr.converged.sum())}/{len(fr)}, "
            f"mean Newton iterations {fr.iterations.mean():.2f}"
        )

    sub = np.array([0.3, 0.8, 1.15, 1.6, 2.5, 5.0])
    t_scipy, a_scipy = timed(
        lambda: np.array([oracle.steady_state(sys, 2 * np.pi * f).amplitude for f in sub]), 1
    )
    t_rk4, b_rk4 = timed(lambda: frequency_response(sys, "brute", freq_hz=sub), 3)
    per_scipy, per_rk4 = t_scipy / len(sub), t_rk4 / len(sub)
    print(f"brute force on {len(sub)} points {sub.tolist()} Hz (from rest, settle rtol 1e-9):")
    print(f"  scipy DOP853 rtol 1e-10: {per_scipy:8.3f} s/point")
    print(f"  numba RK4              : {per_rk4:8.4f} s/point")
    print(
        "  RK4 vs scipy amplitude, max relative difference: "
        f"{np.max(np.abs(b_rk4.amplitude_m - a_scipy) / a_scipy):.2e}"
    )
    for (n, stab), (t, fr) in results.items():
        per = t / len(fr)
        print(
            f"speed-up per point, sihb N={n} stability={'on' if stab else 'off'}: "
            f"{per_scipy / per:9.0f}x vs scipy brute, {per_rk4 / per:7.0f}x vs RK4 brute"
        )
    for n in (128, 64):
        fr = results[(n, False)][1]
        sel = frequency_response(sys, "sihb", freq_hz=sub, harmonics=15, n_samples=n)
        on_grid = fr.branch("down")
        got = dict(zip(np.round(sel.freq_hz, 9), sel.amplitude_m.data, strict=True))
        a_sel = np.array([got[round(f, 9)] for f in sub])  # (7.16), the method's norm
        err = float(np.sqrt(np.sum((a_scipy - a_sel) ** 2) / np.sum(a_sel**2)))
        print(
            f"accuracy N={n}: NRMSE (7.16) vs scipy brute on the subset {100 * err:.4f} %"
            f" (full-curve peak {100 * on_grid.resonance()['amplitude_m']:.4f} cm at "
            f"{on_grid.resonance()['freq_hz']:.4f} Hz)"
        )


if __name__ == "__main__":
    main()
