"""``inerterlab frequency-response``: steady-state response of the ch. 7 system (7.1) or
of a quarter car (docs/model.md §5, §7)."""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Annotated

import typer

from ..errors import ParameterError
from ._common import (
    Axle,
    CarSprungMass,
    CarTyreDamping,
    CarTyreStiffness,
    CarUnsprungMass,
    VehicleFile,
    atomic_savefig,
    atomic_write_text,
    car_options,
    emit_json,
    output_option,
    print_table,
)


def _note_if_long(n, method, harmonics, direction, stability) -> None:
    """Say on standard error when a run is estimated to take minutes (it prints nothing
    until it is done)."""
    import sys

    from ..frequency.response import estimate_operations

    h = harmonics if harmonics is not None else {"shb": 1, "sihb": 15}.get(method, 7)
    if not isinstance(h, int) or h < 1:
        return  # refused with a message by frequency_response
    d = direction or ("both" if method == "sihb" else "up")
    from ..resources import WORK_LIMIT

    ops = estimate_operations(n, method, h, direction=d, stability=stability)
    minutes = ops / 1e9 / 60
    if minutes > 1 and ops < WORK_LIMIT:  # beyond the limit the run is refused instead
        print(
            f"inerterlab: note: {n} frequencies with {method}; expect minutes, not seconds "
            f"(estimate: {minutes:.1f} min of computing)",
            file=sys.stderr,
        )


SYSTEMS = ("chapter7", "quarter-car")


def frequency_response_command(
    system: Annotated[
        str,
        typer.Option(
            help="chapter7 (body over a moving base, thesis 7.1) or quarter-car "
            "(the time simulation's quarter car, road X1 = A sin(2 pi f t))."
        ),
    ] = "chapter7",
    suspension: Annotated[
        str | None,
        typer.Option(help="Quarter car: traditional, cfw or afw (default afw)."),
    ] = None,
    network: Annotated[
        str | None,
        typer.Option(
            help="Quarter car of the model core with this suspension network, e.g. "
            "'k | (c - b)' (element values by --param)."
        ),
    ] = None,
    param: Annotated[
        list[str] | None,
        typer.Option(help="name=value element value of --network (repeatable)."),
    ] = None,
    method: Annotated[
        str, typer.Option(help="brute, shb, mhb, sihb (scan down and up) or continuation.")
    ] = "sihb",
    amplitude: Annotated[
        float,
        typer.Option(help="Base (road) displacement amplitude B [m], X0 = B sin(2 pi f t)."),
    ] = 0.01,
    fmin: Annotated[float, typer.Option(help="Lowest frequency [Hz].")] = 0.1,
    fmax: Annotated[float, typer.Option(help="Highest frequency [Hz].")] = 3.0,
    df: Annotated[float, typer.Option(help="Frequency step [Hz].")] = 0.05,
    harmonics: Annotated[
        int | None,
        typer.Option(
            help="Harmonics H (default: 1 for shb, 15 for sihb, 7 otherwise; 9 for the "
            "quarter car)."
        ),
    ] = None,
    samples: Annotated[
        int | None, typer.Option(help="Time samples per period N (default from the aliasing rule).")
    ] = None,
    flywheel: Annotated[
        str | None,
        typer.Option(
            help="Flywheel preset: metal (default), nylon, nylon-large, or none (no "
            "inerter); quarter car: nylon (default), metal, nylon-large."
        ),
    ] = None,
    law: Annotated[
        str,
        typer.Option(
            help="Inertia law: thesis (default), momentum, thesis-literal; quarter car: "
            "thesis, momentum, slider-dynamics."
        ),
    ] = "thesis",
    direction: Annotated[
        str | None, typer.Option(help="down, up or both (default both for sihb, else up).")
    ] = None,
    no_stability: Annotated[
        bool, typer.Option("--no-stability", help="Skip Hill stability (faster).")
    ] = False,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON object (SI units, Hz).")
    ] = False,
    csv: Annotated[Path | None, output_option("Write one row per point to this CSV.")] = None,
    plot: Annotated[
        Path | None,
        output_option("Write amplitude against frequency to this figure."),
    ] = None,
    sprung_mass: CarSprungMass = None,
    unsprung_mass: CarUnsprungMass = None,
    tyre_stiffness: CarTyreStiffness = None,
    tyre_damping: CarTyreDamping = None,
    vehicle: VehicleFile = None,
    axle: Axle = "front",
) -> None:
    """Amplitude of X1 [m] (half peak-to-peak) against frequency [Hz] for the body on
    spring K = 90 kN/m, damper C = 5000 N s/m and flywheel inerter (r = 961.66 rad/m)
    over a moving base (thesis 7.1). Failed points are reported with converged=false and
    a null amplitude.

    With --system quarter-car the response of the quarter car of the time simulation
    (same equations) to a sine road: half peak-to-peak body displacement [m], body
    acceleration [m/s^2], suspension deflection [m] and tyre force [N] per frequency.

    Example: inerterlab frequency-response --method sihb --amplitude 0.03 --fmin 0.1
    --fmax 3 --df 0.05 --harmonics 15 --json

    The quarter car is the thesis car (4.16) unless --vehicle (one wheel of a vehicle
    file; its strut's spring and damper are then the suspension's k and c) or the car
    options say otherwise.

    Example: inerterlab frequency-response --system quarter-car --suspension afw
    --amplitude 0.01 --fmin 0.5 --fmax 20 --df 0.1 --json
    """
    from ..errors import check_choice
    from ..frequency import chapter7_system

    check_choice("--system", system, SYSTEMS)
    if system != "quarter-car":
        for name, value in (
            ("--suspension", suspension),
            ("--network", network),
            ("--sprung-mass", sprung_mass),
            ("--unsprung-mass", unsprung_mass),
            ("--tyre-stiffness", tyre_stiffness),
            ("--tyre-damping", tyre_damping),
            ("--vehicle", vehicle),
        ):
            if value is not None:
                raise ParameterError(name, value, "no value unless --system quarter-car")
        if param:
            raise ParameterError("--param", param[0], "no value unless --system quarter-car")
    elif network is not None and suspension is not None:
        raise ParameterError("--network", network, "no value together with --suspension")
    elif param and network is None:
        raise ParameterError("--param", param[0], "no value without --network")
    if harmonics is not None and harmonics < 1:
        raise ParameterError("--harmonics", harmonics, "an integer >= 1")
    if samples is not None and samples < 3:
        raise ParameterError("--samples", samples, "an integer >= 2*harmonics+1")
    for name, value in (("--fmin", fmin), ("--fmax", fmax), ("--df", df)):
        if not value > 0:
            raise ParameterError(name, value, "a frequency > 0 Hz")
    if not fmin < fmax:
        raise ParameterError("--fmin", fmin, f"a frequency < --fmax={fmax} Hz")
    if not amplitude > 0:
        raise ParameterError("--amplitude", amplitude, "a displacement > 0 m")
    if system == "quarter-car":
        car = car_options(sprung_mass, unsprung_mass, tyre_stiffness, tyre_damping, vehicle, axle)
        return _quarter_car(
            suspension or "afw", flywheel or "nylon", law, method, amplitude, fmin, fmax, df,
            harmonics, samples, direction, no_stability, json_out, csv, plot, network, param,
            car,
        )  # fmt: skip
    flywheel = flywheel or "metal"
    _respond(
        chapter7_system(amplitude, preset=flywheel, law=law), method, amplitude, fmin, fmax,
        df, harmonics, samples, direction, no_stability, json_out, csv, plot,
        extra={"system": "chapter7", "flywheel": flywheel, "law": law},
        title=f"B = {100 * amplitude:g} cm, {flywheel} flywheel, {law} law",
        summary=partial(_print_resonances, method=method, amplitude=amplitude),
        road=False,
    )  # fmt: skip


def _respond(
    system, method, amplitude, fmin, fmax, df, harmonics, samples, direction, no_stability,
    json_out, csv, plot, extra, title, summary, car=None, road=True,
) -> None:  # fmt: skip
    """The response of ``system`` over the command's grid, written to the JSON, CSV and
    figure asked for (``title`` on the figure), else summarised on standard output by
    ``summary(fr)`` (and the car described). ``road``: ``amplitude`` is the road's, given
    to the response; else the system carries its own forcing of that amplitude."""
    from ..frequency import frequency_grid, frequency_response

    grid = frequency_grid(fmin, fmax, df) if method != "continuation" else None
    if grid is not None:
        _note_if_long(grid.size, method, harmonics, direction, not no_stability)
    fr = frequency_response(
        system, method, freq_hz=grid, fmin=fmin, fmax=fmax, harmonics=harmonics,
        n_samples=samples, direction=direction, stability=not no_stability,
        amplitude=amplitude if road else None,
    )  # fmt: skip
    out = fr.to_dict()
    out["settings"] = {
        k: v for k, v in fr.settings.items() if isinstance(v, str | int | float | bool)
    }
    out.update(extra)
    out["amplitude_input_m"] = amplitude
    out["failed_points"] = int((~fr.converged).sum())
    if csv is not None:
        atomic_write_text(csv, fr.to_pandas().to_csv(index=False), option="--csv")
        out["csv"] = str(csv)
    if plot is not None:
        fig = fr.plot()
        fig.axes[0].set_title(title)
        atomic_savefig(fig, plot)
        out["plot"] = str(plot)
    if json_out:
        emit_json(out)
        return
    summary(fr)
    if car is not None:
        print(car.describe())


def _print_resonances(fr, method, amplitude) -> None:
    """The resonance and peak of each scan, the points and the largest residual."""
    rows = []
    for d in dict.fromkeys(fr.direction.tolist()):
        if fr.branch(d).converged.any():
            pk = fr.resonance(d)
            rows.append((f"resonance, scan {d} [Hz]", f"{pk['freq_hz']:.4f}"))
            rows.append((f"peak amplitude, scan {d} [m]", f"{pk['amplitude_m']:.6g}"))
    rows.append(("points (failed)", f"{len(fr)} ({int((~fr.converged).sum())})"))
    rows.append(("max relative residual", f"{fr.residual[fr.converged].max():.2e}"))
    print_table(f"frequency response, {method}, B = {amplitude:g} m", rows)


def _network_car(network, param, car=None):
    """The model core's quarter car with ``network`` and ``--param name=value`` values."""
    from ._common import parse_float

    params = {}
    for item in param or []:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise ParameterError("--param", item, "name=value")
        params[name.strip()] = parse_float(f"--param {name.strip()}", value)
    from ..systems import quarter_car

    return quarter_car(network, params, **({} if car is None else dict(car)))


def _quarter_car(
    suspension, flywheel, law, method, amplitude, fmin, fmax, df, harmonics, samples,
    direction, no_stability, json_out, csv, plot, network=None, param=None, car=None,
):  # fmt: skip
    from ..errors import check_choice
    from ..frequency.quarter_car import SMOOTH_SUSPENSIONS
    from ..systems import SUSPENSIONS, quarter_car
    from ._common import THESIS_CAR

    values = dict(THESIS_CAR if car is None else car)
    extra_car = {"car": values}
    if car is not None:
        extra_car["car_source"] = car.source
    if network is not None:
        qc = _network_car(network, param, values)
        return _respond(
            qc, method, amplitude, fmin, fmax, df, harmonics, samples, direction,
            no_stability, json_out, csv, plot, {"system": "quarter-car", "network": network,
            **extra_car}, f"quarter car, {network}, A = {100 * amplitude:g} cm",
            partial(_print_points, title=f"quarter car, {network}, {method}, A = {amplitude:g} m"),
            car,
        )  # fmt: skip
    check_choice("--suspension", suspension, SUSPENSIONS)
    if suspension not in SMOOTH_SUSPENSIONS:
        raise ParameterError(
            "--suspension",
            suspension,
            "traditional, cfw or afw for a frequency response (the real device's friction "
            "switches too sharply for a Fourier series; use `inerterlab simulate` with a "
            "sine road)",
        )
    kwargs = {"law": law, **values}
    if car is not None and car.spring is not None:
        kwargs["stiffness"] = car.spring
        kwargs["damping"] = car.damping
        extra_car["strut"] = {"stiffness": car.spring, "damping": car.damping}
    if suspension == "afw":
        kwargs["flywheel"] = flywheel
    qc = quarter_car(suspension, **kwargs).info["model"]
    extra = {"system": "quarter-car", "suspension": suspension, **extra_car}
    if suspension == "afw":
        extra.update(flywheel=flywheel, law=law)
    return _respond(
        qc, method, amplitude, fmin, fmax, df, harmonics, samples, direction, no_stability,
        json_out, csv, plot, extra, f"quarter car, {suspension}, A = {100 * amplitude:g} cm",
        partial(_print_points, title=f"quarter car, {suspension}, {method}, A = {amplitude:g} m"),
        car,
    )  # fmt: skip


def _print_points(fr, title) -> None:
    """One row per point with units (failed points: '-')."""
    import numpy as np

    short = {
        "body_displacement": "body disp",
        "body_acceleration": "body acc",
        "suspension_deflection": "deflection",
        "tyre_force": "tyre force",
    }
    names = list(fr.outputs)
    heads = ["f [Hz]", "scan"]
    heads += [f"{short.get(n, n)} [{fr.output_units.get(n, '')}]" for n in names]
    heads += ["stable", "converged", "residual"]
    rows = []
    for i in range(len(fr)):
        cells = [f"{fr.freq_hz[i]:.5g}", str(fr.direction[i])]
        for n in names:
            a = fr.outputs[n]
            cells.append("-" if np.ma.getmaskarray(a)[i] else f"{a.data[i]:.5g}")
        known = not np.ma.getmaskarray(fr.stable)[i]
        cells.append(("yes" if fr.stable.data[i] else "no") if known else "-")
        cells += ["yes" if fr.converged[i] else "no", f"{fr.residual[i]:.1e}"]
        rows.append(cells)
    widths = [max(len(h), *(len(r[j]) for r in rows)) for j, h in enumerate(heads)]
    print(title)
    print("  ".join(h.rjust(w) for h, w in zip(heads, widths, strict=True)))
    for r in rows:
        print("  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)))


def register(app: typer.Typer) -> None:
    app.command("frequency-response")(frequency_response_command)
