"""``inerterlab rig-simulate`` and ``inerterlab identify``: rig data and identification."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ._common import (
    atomic_savefig,
    atomic_write_text,
    emit_json,
    parse_float,
    print_table,
    seed_option,
)


def rig_simulate_command(
    device: Annotated[
        str, typer.Option(help="hydraulic, screw or rectifier (thesis identified values).")
    ] = "hydraulic",
    flywheel: Annotated[
        str | None, typer.Option(help="Flywheel preset (default by device).")
    ] = None,
    law: Annotated[str, typer.Option(help="Force law of the simulated device.")] = "thesis",
    matrix: Annotated[
        str, typer.Option(help="Test matrix: appendix-a1 or appendix-a2.")
    ] = "appendix-a1",
    sample_rate: Annotated[str, typer.Option(help="Samples per second [Hz].")] = "500",
    noise: Annotated[str, typer.Option(help="Force sensor noise, standard deviation [N].")] = "5",
    spikes: Annotated[str, typer.Option(help="Direction-reversal force spikes: on or off.")] = "on",
    spike_size: Annotated[str, typer.Option(help="Spike size [N].")] = "300",
    spike_width: Annotated[str, typer.Option(help="Spike width [s].")] = "0.02",
    seed: Annotated[int, seed_option("Random seed.")] = 0,
    max_duration: Annotated[
        str | None, typer.Option(help="Cut each record to this length [s].")
    ] = None,
    columns: Annotated[
        str, typer.Option(help="Motion columns: both, displacement or velocity.")
    ] = "both",
    out: Annotated[
        Path,
        typer.Option(
            help="Output directory (test CSV files + manifest.csv): new, empty or an earlier "
            "data set of inerterlab, replaced as a whole; any other folder is refused."
        ),
    ] = Path("rig-data"),
    json_out: Annotated[bool, typer.Option("--json", help="Print a JSON summary.")] = False,
) -> None:
    """Simulate a rig campaign (thesis Appendix A) on a device model and write it to --out.

    Example: inerterlab rig-simulate --device hydraulic --flywheel metal --matrix appendix-a1
    --noise 5 --spikes on --seed 1 --out DIR
    """
    from ..devices import device_preset
    from ..errors import ParameterError, check_choice
    from ..identify import simulate_rig, write_rig_data

    check_choice("spikes", spikes, ("on", "off"))
    fs = parse_float("sample-rate", sample_rate)
    md = parse_float("max-duration", max_duration) if max_duration is not None else None
    if md is not None and md <= 0:
        raise ParameterError("max-duration", max_duration, "a finite number > 0 s")
    from ..identify.data import check_rig_output

    check_rig_output(out)  # before the work: refuse a folder that is not ours to replace
    dev = device_preset(device, flywheel_preset=flywheel, law=law)
    ds = simulate_rig(
        dev,
        matrix=matrix,
        sample_rate=fs,
        noise=parse_float("noise", noise),
        spikes=spikes == "on",
        spike_size=parse_float("spike-size", spike_size),
        spike_width=parse_float("spike-width", spike_width),
        seed=seed,
        max_duration=md,
        columns=columns,
    )
    header = (
        "simulated rig data (inerterlab rig-simulate); not a measurement\n"
        + ", ".join(f"{k}={v}" for k, v in ds.meta.items())
        + f", matrix={matrix}"
    )
    write_rig_data(ds, out, header=header)
    summary = {
        "out": str(out),
        "tests": len(ds.tests),
        "identification": len(ds.select("identification")),
        "validation": len(ds.select("validation")),
        "samples": int(sum(t.t.size for t in ds.tests)),
        **ds.meta,
    }
    if json_out:
        emit_json(summary)
        return
    print_table(f"rig-simulate -> {out}", [(k, str(v)) for k, v in summary.items()])


#: measured cost of one model evaluation per sample in a fit [floating point operations]
_OPS_PER_SAMPLE_EVALUATION = 430.0


def _check_fit_size(ds, bootstrap: int) -> None:
    """Refuse a fit that would run for hours; say so when it will take minutes.

    The estimate uses a cost per sample and model evaluation measured on the default
    campaign (about 1e6 samples fitted in 45 s of computing).
    """
    import sys

    from ..resources import check_work

    n = sum(int(t.t.size) for t in ds.tests)
    ops = n * 100.0 * (bootstrap + 1) * _OPS_PER_SAMPLE_EVALUATION
    check_work(
        ops,
        what="identification (samples x model evaluations x refits)",
        parameter="--bootstrap" if bootstrap else "--data",
        value=bootstrap if bootstrap else f"{n} samples",
    )
    minutes = ops / 1e9 / 60
    if minutes > 1:
        print(
            f"inerterlab: note: fitting {n} samples x {bootstrap + 1} fit(s); "
            f"expect minutes, not seconds (estimate: {minutes:.1f} min of computing)",
            file=sys.stderr,
        )


def identify_command(
    device: Annotated[
        str, typer.Option(help="Model structure: hydraulic, screw or rectifier.")
    ] = "hydraulic",
    flywheel: Annotated[
        str | None, typer.Option(help="Flywheel preset (default by device).")
    ] = None,
    law: Annotated[str, typer.Option(help="Force law of the model.")] = "thesis",
    data: Annotated[
        Path, typer.Option(help="Directory with manifest.csv/.toml and test CSV files.")
    ] = Path("rig-data"),
    method: Annotated[str, typer.Option(help="thesis (staged, ch. 5) or joint.")] = "joint",
    loss: Annotated[
        str, typer.Option(help="linear, soft_l1, huber or cauchy (robust to spikes).")
    ] = "cauchy",
    fix: Annotated[
        list[str] | None, typer.Option(help="Keep a parameter at its preset value (repeatable).")
    ] = None,
    bootstrap: Annotated[
        int, typer.Option(help="Bootstrap refits over the identification tests.")
    ] = 0,
    reversal_window: Annotated[
        str | None,
        typer.Option(
            help="Leave out this time [s] after each velocity reversal (spikes); default "
            "the device's: 0.24 s hydraulic and rectifier, 0.16 s screw."
        ),
    ] = None,
    interval: Annotated[
        str,
        typer.Option(
            help="95 % intervals: sandwich (autoregressive noise within tests, calibrated "
            "in the coverage study of the guide) or jackknife (over tests, conservative)."
        ),
    ] = "sandwich",
    report: Annotated[
        Path | None, typer.Option(help="Write plots and tables to this directory.")
    ] = None,
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    propagate: Annotated[
        Path | None,
        typer.Option(
            help="Car file (TOML): carry the parameter covariance to the ride metrics "
            "of this quarter car with the identified device."
        ),
    ] = None,
    network: Annotated[
        str | None,
        typer.Option(
            help="Fit a network instead of a device, on the model core's rig, e.g. "
            "'k | c | b' (with --param and --free)."
        ),
    ] = None,
    param: Annotated[
        list[str] | None,
        typer.Option(help="With --network: name=value (repeatable), e.g. k=90000."),
    ] = None,
    free: Annotated[
        list[str] | None,
        typer.Option(help="With --network: a parameter to fit (repeatable or k,c,b)."),
    ] = None,
    initial_state: Annotated[
        str,
        typer.Option(
            help="With --network: project out every internal state's free response (all) "
            "or the internal displacements only (displacements: nodes start with the drive)."
        ),
    ] = "all",
) -> None:
    """Identify stiffness [N/m], damping [N s/m] and friction [N] from rig data.

    Starts from the thesis's identified values of the device.
    Example: inerterlab identify --device hydraulic --flywheel metal --data DIR --json.
    With --network, the named parameters of any network instead:
    inerterlab identify --network "k | c | b" --param k=2e6,c=7000,b=100 --free k,c,b
    """
    from ..devices import device_preset
    from ..errors import ParameterError
    from ..identify import identify, load_rig_data

    if bootstrap < 0:
        raise ParameterError("bootstrap", bootstrap, "an integer >= 0")
    if network is not None:
        _identify_network(
            network, param, free, data, loss, reversal_window, interval, json_out,
            initial_state,
            other={"--method": method != "joint", "--fix": bool(fix),
                   "--bootstrap": bootstrap > 0, "--propagate": propagate is not None,
                   "--report": report is not None, "--flywheel": flywheel is not None},
        )  # fmt: skip
        return
    if param or free or initial_state != "all":
        what = "param" if param else "free" if free else "initial-state"
        raise ParameterError(what, (param or free or [initial_state])[0], "used only with --network")
    dev = device_preset(device, flywheel_preset=flywheel, law=law)
    car_file = None
    if propagate is not None:
        from ..identify.carfile import load_car_file

        car_file = load_car_file(propagate)  # a bad file fails before the fit
    ds = load_rig_data(data)
    _check_fit_size(ds, bootstrap)
    fit = identify(
        ds,
        dev,
        method=method,
        loss=loss,
        fixed=tuple(fix or ()),
        bootstrap=bootstrap,
        reversal_window=(
            None if reversal_window is None else parse_float("reversal-window", reversal_window)
        ),
        interval=interval,
    )
    out = fit.to_dict()
    if car_file is not None:
        from ..identify import propagate as propagate_fit

        ride = propagate_fit(
            fit,
            car_file.car,
            car_file.excitation,
            car_file.horizon,
            method=car_file.method,
            n=car_file.draws,
            seed=car_file.seed,
            linear=car_file.linear,
            road_class=car_file.road_class,
            speed=car_file.speed,
        )
        out["ride_metrics"] = {
            k: {
                "value": v["value"],
                "ci95": None if v["ci95"] is None else list(v["ci95"]),
                "std": v["std"],
                "unit": v["unit"],
            }
            for k, v in ride.items()
        }
        out["ride_metrics_method"] = car_file.method
    if report is not None:
        report.mkdir(parents=True, exist_ok=True)
        atomic_write_text(report / "parameters.csv", fit.to_pandas().to_csv(index=False))
        atomic_write_text(report / "validation.csv", fit.validation_frame().to_csv(index=False))
        ident = [i for i, tv in enumerate(fit.tests) if tv.purpose == "identification"][:3]
        valid = [i for i, tv in enumerate(fit.tests) if tv.purpose == "validation"][:6]
        import matplotlib.pyplot as plt

        for i in ident + valid:
            fig = fit.plot(i)
            atomic_savefig(fig, report / f"fit_{Path(fit.tests[i].name).stem}.png")
            plt.close(fig)
        out["report"] = str(report)
    if json_out:
        emit_json(out)
        return
    _, rows = fit._summary()
    for k, v in out.get("ride_metrics", {}).items():
        ci = v["ci95"]
        text = "not finite"
        if ci is not None:
            text = f"{v['value']:.6g}  (95 %: {ci[0]:.6g} .. {ci[1]:.6g})"
        rows.append((k, text))
    print_table(f"identify: {device}, {method} method, {loss} loss", rows)


def _identify_network(network, param, free, data, loss, reversal_window, interval, json_out,
                      initial_state, other) -> None:  # fmt: skip
    """``identify --network``: :func:`inerterlab.identify.identify_network`."""
    from ..errors import ParameterError
    from ..identify import identify_network, load_rig_data
    from .simulate import _parse_params

    for option, given in other.items():
        if given:
            raise ParameterError(
                option.lstrip("-"), "given", f"not with --network ({option} is for devices)"
            )
    from ..errors import check_unique

    names = [n.strip() for item in free or [] for n in str(item).split(",") if n.strip()]
    if not names:
        raise ParameterError("free", None, "at least one --free name with --network")
    check_unique("free", names)
    params = _parse_params(param)
    ds = load_rig_data(data)
    _check_fit_size(ds, 0)
    kw = {}
    if reversal_window is not None:
        kw["reversal_window"] = parse_float("reversal-window", reversal_window)
    fit = identify_network(
        ds, network, params, free=names, loss=loss, interval=interval,
        initial_state=initial_state, **kw,
    )  # fmt: skip
    if json_out:
        emit_json(fit.to_dict())
        return
    title, rows = fit._summary()
    print_table(title, rows)


def register(app: typer.Typer) -> None:
    app.command("rig-simulate")(rig_simulate_command)
    app.command("identify")(identify_command)
