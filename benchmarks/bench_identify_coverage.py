"""Coverage of the identification intervals over simulated campaigns.

For each device, N campaigns (seeds 1..N) are simulated with the ``rig-simulate``
defaults (5 N force noise, 1e-6 m and 1e-5 m/s motion noise, 300 N spikes of 20 ms)
and identified with the ``identify`` defaults (joint fit, Cauchy loss, the device's
reversal window: 0.24 s hydraulic and rectifier, 0.16 s screw, ``--reversal-window``;
starting from the true values as the CLI does from the
thesis values). Per device, parameter and interval method (``sandwich`` and
``jackknife``, both from the same fit; the sandwich is the default) it prints

* coverage: the fraction of campaigns whose 95 % interval holds the true value;
* mean error in standard errors: mean of (estimate - truth) / std_error (bias
  relative to the stated precision; near 0 when unbiased);
* width ratio: mean interval width / empirical 95 % spread of the estimates (the
  2.5-97.5 percentile range over campaigns); near 1 when the intervals are as wide
  as the scatter they claim, > 1 conservative, < 1 overconfident.

Default campaign (reduced, documented in docs/guide/identification.md): the device's
Appendix A matrix (appendix-a1 for the hydraulic device, appendix-a2 for screw and
rectifier) with every record cut to 2 s, sampled at the rig's 500 Hz (at 200 Hz, the
former default, the error of the sampled motion alone biased the screw's stiffness by
-0.2 standard errors; docs/decisions.md). ``--full`` uses the whole records (1-5 min
per hydraulic or rectifier campaign).

``--design B``: the study of a designed campaign. For each device, the D-optimal choice of
B tests of its matrix (:func:`inerterlab.identify.design_campaign` at the true values,
with the study's record length and rate) is made once and stored in
OUT/<device>/design.json; every campaign then runs only those tests, all used for the
identification. The summary adds the mean interval width, to set beside a run of the
full matrix (the same command without ``--design``, another OUT).

``--engine network``: each campaign is fitted with
:func:`inerterlab.identify.identify_network` instead, the device written as its
composite element on the model core's rig (:func:`inerterlab.systems.device_network`),
with the same reversal window: the calibration of the network fit's intervals, with its
initial state projected out per internal state.

Each campaign's result is written as JSON (atomically) to
OUT/<device>/seed_<seed>.json; a rerun with the same OUT and settings only computes
the campaigns that are missing, so an interrupted run resumes. The settings are stored
in OUT/settings.json with the inputs the campaigns are computed from (a hash of every
file of the package, code and data, and the versions of the numerical libraries); a
rerun with other settings or inputs is refused.

    python benchmarks/bench_identify_coverage.py --campaigns 200 --workers 2 --out cov
    python benchmarks/bench_identify_coverage.py --campaigns 10 --devices screw
    python benchmarks/bench_identify_coverage.py --campaigns 200 --workers 2 --design 8 --out cov_d8
    python benchmarks/bench_identify_coverage.py --campaigns 40 --engine network --out cov_net
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from inerterlab._provenance import library_versions, source_hash  # noqa: E402
from inerterlab.devices import device_preset  # noqa: E402
from inerterlab.identify import (  # noqa: E402
    design_campaign,
    identify,
    identify_network,
    simulate_rig,
    test_matrix,
)
from inerterlab.identify.fit import INTERVALS, default_reversal_window  # noqa: E402
from inerterlab.io import atomic_write_text  # noqa: E402
from inerterlab.systems import device_network  # noqa: E402

MATRIX = {"hydraulic": "appendix-a1", "screw": "appendix-a2", "rectifier": "appendix-a2"}
PARAMS = ("stiffness", "damping", "friction")


def run_campaign(device: str, seed: int, settings: dict) -> dict:
    dev = device_preset(device)
    matrix = MATRIX[device]
    if settings.get("design"):
        matrix = _design_tests(device, settings["design_tests"][device])
    data = simulate_rig(
        dev,
        matrix=matrix,
        seed=seed,
        sample_rate=settings["sample_rate"],
        max_duration=settings["max_duration"],
    )
    t0 = time.perf_counter()
    key = str  # the fit's name of each parameter
    if settings.get("engine") == "network":
        # the device as a composite element on the model core's rig
        text, params = device_network(dev)
        window = settings.get("reversal_window")
        fit = identify_network(
            data, text, params, free=[f"{text}.{n}" for n in PARAMS],
            reversal_window=default_reversal_window(dev) if window is None else window,
        )  # fmt: skip

        def key(n, text=text):
            return f"{text}.{n}"
    else:
        fit = identify(data, dev, reversal_window=settings.get("reversal_window", 0.1))
    out = {
        "device": device,
        "seed": seed,
        "seconds": time.perf_counter() - t0,
        "tests": [t.number for t in matrix] if settings.get("design") else None,
    }
    # the default interval method at the top level, every method under "intervals"
    # (computed from the same fit)
    out["intervals"] = {}
    for m in INTERVALS:
        f = fit.with_intervals(m)
        rec = {}
        for n in PARAMS:
            p = f.parameters[key(n)]
            rec[n] = {
                "truth": float(getattr(dev, n)),
                "value": p.value,
                "ci95": list(p.ci95),
                "std_error": p.std_error,
                "quantile": p.quantile,
            }
        out["intervals"][m] = rec
        if m == fit.interval_method:
            out.update(rec)
    return out


def _design_tests(device: str, numbers: list) -> list:
    """The designed campaign: the chosen tests of the device's matrix, each used for the
    identification."""
    by_number = {t.number: t for t in test_matrix(MATRIX[device])}
    return [dataclasses.replace(by_number[n], purpose="identification") for n in numbers]


def _design(device: str, budget: int, settings: dict, out: Path) -> list:
    """Test numbers of the D-optimal campaign of ``budget`` tests (computed once, then
    read from OUT/<device>/design.json)."""
    path = out / device / "design.json"
    if path.exists():
        rec = json.loads(path.read_text())
        if rec["budget"] == budget:
            return rec["tests"]
    t0 = time.perf_counter()
    d = design_campaign(
        device_preset(device),
        budget,
        matrix=MATRIX[device],
        sample_rate=settings["sample_rate"],
        max_duration=settings["max_duration"],
        reversal_window=settings.get("reversal_window"),
    )
    numbers = [t.number for t in d.chosen]
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(
        path,
        json.dumps(
            {
                "budget": budget,
                "tests": numbers,
                "efficiency": d.efficiency(),
                "predicted_se_ratio": dict(
                    zip(
                        d.names,
                        map(float, d.standard_errors("chosen") / d.standard_errors("full")),
                        strict=True,
                    )
                ),
                "seconds": time.perf_counter() - t0,
            }
        ),
    )
    return numbers


def _cache(out: Path, device: str, seed: int) -> Path:
    return out / device / f"seed_{seed:04d}.json"


def _work(args):
    device, seed, settings, out = args
    res = run_campaign(device, seed, settings)
    path = _cache(Path(out), device, seed)
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, json.dumps(res))
    return res


def summarise(results: list, interval: str | None = None) -> list:
    """Coverage, mean error / standard error and width ratio per parameter, for the
    intervals of method ``interval`` (default: those the campaign's fit printed)."""
    if interval is not None:
        results = [r["intervals"][interval] for r in results if interval in r.get("intervals", {})]
    rows = []
    for n in PARAMS:
        truth = np.array([r[n]["truth"] for r in results])
        val = np.array([r[n]["value"] for r in results])
        lo = np.array([r[n]["ci95"][0] for r in results])
        hi = np.array([r[n]["ci95"][1] for r in results])
        se = np.array([r[n]["std_error"] for r in results])
        cover = float(np.mean((lo <= truth) & (truth <= hi)))
        z = (val - truth) / np.where(se > 0, se, np.nan)
        spread = float(np.subtract(*np.percentile(val, [97.5, 2.5])))
        width = float(np.mean(hi - lo))
        rows.append(
            {
                "parameter": n,
                "campaigns": len(results),
                "coverage": cover,
                "mean_error_se": float(np.nanmean(z)),
                "width_ratio": width / spread if spread > 0 else math.nan,
                "mean_width": width,
            }
        )
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--campaigns", type=int, default=200)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--devices", default="hydraulic,screw,rectifier")
    ap.add_argument("--out", type=Path, default=Path("bench-identify-coverage"))
    ap.add_argument("--full", action="store_true", help="whole records at 500 Hz")
    ap.add_argument("--max-duration", type=float, default=2.0, help="[s], reduced campaign")
    ap.add_argument("--sample-rate", type=float, default=500.0, help="[Hz], reduced campaign")
    ap.add_argument(
        "--design",
        type=int,
        default=None,
        metavar="B",
        help="study the D-optimal campaign of B tests of each matrix instead of the whole matrix",
    )
    ap.add_argument(
        "--reversal-window",
        type=float,
        default=None,
        help="[s] left out after each velocity reversal (default: identify's, per device)",
    )
    ap.add_argument(
        "--engine",
        choices=("device", "network"),
        default="device",
        help="fit with identify (the device kernel) or identify_network (the device as a "
        "composite element on the model core's rig)",
    )
    args = ap.parse_args(argv)
    devices = [d.strip() for d in args.devices.split(",") if d.strip()]
    for d in devices:
        if d not in MATRIX:
            ap.error(f"unknown device {d!r}: expected hydraulic, screw or rectifier")
    if args.campaigns < 2:
        ap.error("--campaigns must be at least 2")
    settings = (
        {"max_duration": None, "sample_rate": 500.0}
        if args.full
        else {"max_duration": args.max_duration, "sample_rate": args.sample_rate}
    )
    settings["reversal_window"] = args.reversal_window
    if args.engine == "network":
        settings["engine"] = "network"
    if args.design is not None:
        if args.design < 3:
            ap.error("--design must be at least 3 (the free parameters)")
        settings["design"] = args.design
    args.out.mkdir(parents=True, exist_ok=True)
    sfile = args.out / "settings.json"
    inputs = {"package_files": source_hash(), "libraries": library_versions()}
    if sfile.exists():
        old = json.loads(sfile.read_text())
        old_inputs = old.pop("inputs", None) if isinstance(old, dict) else None
        if old != settings:
            print(
                f"{sfile}: results were computed with {old}, not {settings}; use another --out",
                file=sys.stderr,
            )
            return 2
        if old_inputs != inputs:
            changed = (
                ", ".join(k for k in inputs if (old_inputs or {}).get(k) != inputs[k]) or "inputs"
            )
            print(
                f"{sfile}: results were computed from other inputs ({changed} changed since); "
                "use another --out to compute them with this code and data",
                file=sys.stderr,
            )
            return 2
    else:
        atomic_write_text(sfile, json.dumps({**settings, "inputs": inputs}))
    if args.design is not None:
        settings["design_tests"] = {}
        for d in devices:
            settings["design_tests"][d] = _design(d, args.design, settings, args.out)
            rec = json.loads((args.out / d / "design.json").read_text())
            print(
                f"{d}: designed campaign of {args.design} tests {rec['tests']} "
                f"(D-efficiency {rec['efficiency']:.3f}; predicted standard errors "
                + ", ".join(f"{k} {v:.2f}" for k, v in rec["predicted_se_ratio"].items())
                + " x the whole matrix's)",
                flush=True,
            )
    results = {d: [] for d in devices}
    todo = []
    for d in devices:
        for seed in range(1, args.campaigns + 1):
            path = _cache(args.out, d, seed)
            if path.exists():
                results[d].append(json.loads(path.read_text()))
            else:
                todo.append((d, seed, settings, str(args.out)))
    cached = sum(len(v) for v in results.values())
    print(
        f"campaigns: {args.campaigns} per device, {cached} cached, {len(todo)} to run, "
        f"{args.workers} worker(s); records "
        + (
            "whole at 500 Hz"
            if args.full
            else f"cut to {settings['max_duration']:g} s at {settings['sample_rate']:g} Hz"
        ),
        flush=True,
    )
    t0 = time.perf_counter()
    if todo:
        if args.workers > 1:
            with ProcessPoolExecutor(args.workers) as ex:
                futs = [ex.submit(_work, a) for a in todo]
                for f in as_completed(futs):
                    r = f.result()
                    results[r["device"]].append(r)
        else:
            for a in todo:
                r = _work(a)
                results[r["device"]].append(r)
    print(f"wall time {time.perf_counter() - t0:.0f} s", flush=True)
    print(
        f"{'device':10s} {'parameter':10s} {'N':>4s} {'coverage':>9s} {'mean err/se':>12s} "
        f"{'width ratio':>12s} {'mean width':>12s}  interval"
    )
    for d in devices:
        rs = sorted(results[d], key=lambda r: r["seed"])
        for m in INTERVALS:
            for row in summarise(rs, m):
                print(
                    f"{d:10s} {row['parameter']:10s} {row['campaigns']:4d} {row['coverage']:9.3f} "
                    f"{row['mean_error_se']:+12.3f} {row['width_ratio']:12.3f} "
                    f"{row['mean_width']:12.5g}  {m}"
                )
        secs = [r["seconds"] for r in rs]
        print(f"{d:10s} identify: median {np.median(secs):.1f} s per campaign")
    return 0


if __name__ == "__main__":
    sys.exit(main())
