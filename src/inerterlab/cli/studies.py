"""``inerterlab sweep`` and ``inerterlab optimize-ratio``: design studies (thesis 4.3, 6.3)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from ..errors import ParameterError
from ._common import emit_json, parse_float, print_table


def sweep_command(
    config: Annotated[
        Path, typer.Argument(help="Sweep description (TOML), see docs/guide/studies.md.")
    ],
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            help="Zarr store written chunk by chunk; rerunning the same command resumes it.",
        ),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option(
            help="Local workers (processes, or a local Dask cluster with --backend dask)."
        ),
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option(help="Address of a running Dask scheduler, e.g. tcp://10.0.0.5:8786."),
    ] = None,
    backend: Annotated[
        str | None,
        typer.Option(help="serial, processes (default) or dask (default with --scheduler)."),
    ] = None,
    netcdf: Annotated[
        Path | None, typer.Option(help="Also write the finished dataset to this netCDF file.")
    ] = None,
    json_out: Annotated[bool, typer.Option("--json", help="Print a JSON summary.")] = False,
    quiet: Annotated[bool, typer.Option(help="No progress bar.")] = False,
) -> None:
    """Run a parameter sweep: one dataset dimension per swept parameter, one variable
    per metric (SI units: accelerations m/s^2, deflections m, grip index -).

    Example: inerterlab sweep examples/sweep_example.toml --out ratio.zarr --workers 2
    """
    from ..errors import Interrupted
    from ..studies import SweepInterrupted, load_sweep_config, save_netcdf, sweep

    spec = load_sweep_config(config)
    if workers is not None:
        from ..studies.backends import check_workers

        check_workers("--workers", workers)
    t0 = time.perf_counter()
    try:
        ds = sweep(
            spec,
            store=out,
            backend=backend,
            workers=workers,
            scheduler=scheduler,
            progress=not quiet and not json_out,
        )
    except SweepInterrupted as exc:
        raise Interrupted(str(exc)) from None
    elapsed = time.perf_counter() - t0
    done = int(ds.attrs["points_ok"] + ds.attrs["points_failed"])
    computed = int(ds.attrs["points_computed"])
    before = done - computed
    if netcdf is not None:
        save_netcdf(ds, netcdf)
    summary = {
        "points": int(ds.attrs["points"]),
        "ok": int(ds.attrs["points_ok"]),
        "failed": int(ds.attrs["points_failed"]),
        "computed_now": computed,
        "resumed_from": before,
        "seconds": elapsed,
        "points_per_second": computed / elapsed if elapsed > 0 and computed else 0.0,
        "dims": {k: int(v) for k, v in ds.sizes.items()},
        "backend": ds.attrs.get("backend", ""),
        "store": str(out) if out else None,
        "netcdf": str(netcdf) if netcdf else None,
    }
    if json_out:
        emit_json(summary)
        return
    rows = [
        (
            "points (ok / failed / total)",
            f"{summary['ok']} / {summary['failed']} / {summary['points']}",
        ),
        ("computed in this run", f"{computed} (resumed from {before})"),
        ("dimensions", ", ".join(f"{k}={v}" for k, v in summary["dims"].items())),
        ("backend", summary["backend"]),
        ("time (s)", f"{elapsed:.2f}"),
        ("rate (points/s)", f"{summary['points_per_second']:.1f}"),
    ]
    if out:
        rows.append(("store", str(out)))
    if netcdf:
        rows.append(("netCDF", str(netcdf)))
    if summary["failed"]:
        reasons = sorted(set(ds.reason.where(ds.status == 2, drop=True).values.ravel()) - {""})
        rows.append(("first failure", reasons[0] if reasons else "?"))
    print_table(f"sweep {config.name}", rows)


def _parse_input_weights(text: str) -> tuple[tuple[str, float], ...]:
    parts = [p for p in text.split(",") if p.strip()]
    if len(parts) != 3:
        raise ParameterError(
            "--input-weights", text, "three weights x3,x4,x5 (drop, bump, sine) summing to 1"
        )
    vals = [parse_float("--input-weights", p) for p in parts]
    return tuple(zip(("drop", "bump", "sine"), vals, strict=True))


def optimize_ratio_command(
    device: Annotated[
        str,
        typer.Option(help="ideal (AFW on an ideal device, ch. 4) or hydraulic (system B, ch. 6)."),
    ] = "ideal",
    comfort_weight: Annotated[
        str, typer.Option(help="x1, weight of ride comfort in [0, 1]; grip gets 1 - x1 (4.30).")
    ] = "0.35",
    input_weights: Annotated[
        str,
        typer.Option(
            help="x3,x4,x5: weights of the drop, bump and sine inputs, summing to 1 (4.33)."
        ),
    ] = "0.1,0.5,0.4",
    cost: Annotated[
        str,
        typer.Option(
            help="thesis: (4.34) as printed (jumps at x = 0.2); continuous: jump removed."
        ),
    ] = "thesis",
    method: Annotated[
        str,
        typer.Option(
            help="on-demand: simulate at every ratio the optimiser asks for; "
            "interpolate: cubic splines through a sweep with --grid-step."
        ),
    ] = "on-demand",
    grid_step: Annotated[
        str, typer.Option(help="Changing-ratio step of the sweep for --method interpolate [-].")
    ] = "0.05",
    horizon: Annotated[str, typer.Option(help="Simulated time per point [s].")] = "10",
    sprung_mass: Annotated[str, typer.Option(help="Body mass M_v [kg].")] = "370",
    point: Annotated[
        str, typer.Option(help="Point function: quarter-car, or synthetic (a fast stand-in).")
    ] = "quarter-car",
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Optimal changing ratio x of the adaptive flywheel by Chebyshev goal programming
    (4.38)-(4.39), over 5 %-55 %, at M_v = 370 kg. Prints x, lambda, the performance
    (4.33, traditional suspension = 1), the cost (4.34) and the metrics at x.

    Example: inerterlab optimize-ratio --device ideal --comfort-weight 0.35 --json
    """
    from ..errors import check_choice
    from ..studies import PerformanceWeights, sweep
    from ..studies.ratio import (
        DEVICES,
        INPUTS,
        THESIS_OPTIMUM,
        InterpolatedRatioModel,
        optimize_ratio,
        ratio_model,
    )
    from ..studies.spec import check_weight

    check_choice("--device", device, tuple(DEVICES))
    check_choice("--method", method, ("on-demand", "interpolate"))
    x1 = check_weight("--comfort-weight", parse_float("--comfort-weight", comfort_weight))
    weights = PerformanceWeights(
        comfort=x1, grip=round(1.0 - x1, 12), inputs=_parse_input_weights(input_weights)
    )
    settings = {"sprung_mass": parse_float("--sprung-mass", sprung_mass)}
    if point == "quarter-car":
        settings["horizon"] = parse_float("--horizon", horizon)
    model, baseline = ratio_model(device, point=point, settings=settings)
    if method == "interpolate":
        step = parse_float("--grid-step", grid_step)
        if not 0.0 < step <= 0.125:
            raise ParameterError("--grid-step", grid_step, "a step in (0, 0.125]")
        from ..resources import check_memory

        check_memory(
            (0.5 / step + 1) * len(INPUTS),
            what="interpolation sweep (0.5 / grid-step ratios x inputs)",
            parameter="--grid-step",
            value=grid_step,
            bytes_per_value=64,
        )
        ds = sweep(
            {
                "point": point,
                "parameters": {
                    "changing_ratio": {"start": 0.05, "stop": 0.55, "step": step},
                    "input": list(INPUTS),
                },
                "settings": {**model.settings},
            },
            backend="serial",
        )
        model = InterpolatedRatioModel(ds)
    res = optimize_ratio(
        model,
        baseline,
        weights=weights,
        cost=cost,
        settings={**settings, "device": device, "method": method, "point": point},
    )
    out = res.to_dict()
    out["thesis_optimal_ratio"] = THESIS_OPTIMUM[device]
    if json_out:
        emit_json(out)
        return
    rows = [
        (
            "optimal changing ratio x (-)"
            + (f", at the {res.at_bound} bound" if res.at_bound else ""),
            f"{res.optimal_ratio:.4f} (thesis {THESIS_OPTIMUM[device]})",
        ),
        ("search range (-)", f"{res.bounds[0]:g} .. {res.bounds[1]:g}"),
        ("lambda (4.38) (-)", f"{res.lam:.4f}"),
        ("performance f_p (4.33) (-)", f"{res.performance:.4f}"),
        ("cost f_c (4.34) (-)", f"{res.cost:.4f}"),
    ]
    for name, m in res.metrics.items():
        rows.append((f"{name}: rms body acc (m/s^2)", f"{m['rms_body_acc']:.4f}"))
        rows.append((f"{name}: rms tyre grip index (-)", f"{m['rms_tyre_grip']:.4f}"))
        rows.append((f"{name}: rms deflection (m)", f"{m['rms_deflection']:.5f}"))
    print_table(f"optimal changing ratio, {device} device, {cost} cost", rows)
    if res.at_bound:
        print(f"note: {res.bound_note()}")


def register(app: typer.Typer) -> None:
    app.command("sweep")(sweep_command)
    app.command("optimize-ratio")(optimize_ratio_command)
