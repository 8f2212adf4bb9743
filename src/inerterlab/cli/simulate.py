"""``inerterlab simulate`` and ``inerterlab h2``: quarter-car ride metrics."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path
from typing import Annotated

import typer

from ..io import atomic_path
from ..metrics import METRIC_KEYS, METRIC_UNITS
from ._common import (
    Axle,
    CarSprungMass,
    CarTyreDamping,
    CarTyreStiffness,
    CarUnsprungMass,
    VehicleFile,
    atomic_savefig,
    atomic_write_text,
    emit_json,
    output_option,
    print_table,
    seed_option,
)

_CAR_HELP = "Quarter car (SI units; base values of thesis (4.16))."
_JSON_KEYS = METRIC_KEYS


def _car_kwargs(sprung_mass, unsprung_mass, stiffness, damping, tyre_stiffness, tyre_damping):
    return dict(
        sprung_mass=sprung_mass,
        unsprung_mass=unsprung_mass,
        stiffness=stiffness,
        damping=damping,
        tyre_stiffness=tyre_stiffness,
        tyre_damping=tyre_damping,
    )


def _save_series(result, path: Path) -> None:
    from ..errors import ParameterError

    suffix = path.suffix.lower()
    if suffix == ".csv":
        df = result.to_pandas(units_in_names=True)
        header = "".join(f"# {k}: {v}\n" for k, v in result.settings().items())
        atomic_write_text(path, header + df.to_csv(float_format="%.10g"), option="--save")
    elif suffix == ".nc":
        ds = result.to_xarray()
        with atomic_path(path, suffix=".nc", option="--save") as tmp:
            ds.to_netcdf(tmp, engine="scipy")  # netCDF3 via scipy: no HDF5 library needed
    else:
        raise ParameterError("save", str(path), "a file name ending in .csv or .nc")


def _parse_params(items) -> dict:
    """``name=value`` pairs (repeatable or comma-separated) -> dict; numbers as floats."""
    from ..errors import ParameterError

    out: dict = {}
    for item in items or []:
        for part in str(item).split(","):
            if not part.strip():
                continue
            key, eq, val = part.partition("=")
            key, val = key.strip(), val.strip()
            if not eq or not key or not val:
                raise ParameterError("param", part, "name=value, e.g. k=90000 or afw.law=momentum")
            if key in out:
                raise ParameterError("param", part, f"each name once ({key} was given twice)")
            try:
                out[key] = float(val)
            except ValueError:
                out[key] = val
    return out


def _simulate_network(
    network, params, ex, horizon, car, preset, method, rtol, json_out, save, plot=None
):
    """``simulate --network``: the model core's quarter car."""
    from ..systems import QUARTER_CAR_PRESETS, quarter_car

    kw = preset if network in QUARTER_CAR_PRESETS else {}
    if network not in QUARTER_CAR_PRESETS:  # a network gives its own spring and damper
        car = {k: v for k, v in car.items() if k not in ("stiffness", "damping")}
    sys_ = quarter_car(network, params, **car, **kw)
    res = sys_.simulate(ex, horizon, rtol=rtol, method=method)
    m = res.metrics
    if save is not None:
        import pandas as pd

        from ._common import atomic_write_text as _write

        df = pd.DataFrame({"time": res.time, **res.outputs})
        _write(save, df.to_csv(index=False, float_format="%.10g"), option="--save")
    if plot is not None:
        atomic_savefig(res.plot(), plot)
    out = {k: m[k] for k in _JSON_KEYS}
    out.update(
        network=network,
        input=ex.name,
        horizon=horizon,
        method=res.method,
        states=sys_.n_states,
        road_steps=[{"time": t, "jump": j} for t, j in res.road_steps],
        metrics_from="integrated as observer states (peaks located between steps)",
    )
    if res.not_finite:
        out["not_finite"] = dict(res.not_finite)
    if plot is not None:
        out["plot"] = str(plot)
    if json_out:
        emit_json(out)
        return

    def cell(v):
        return "not finite" if v is None else str(v) if isinstance(v, bool) else f"{v:.6g}"

    rows = [(k, cell(m[k])) for k in _JSON_KEYS]
    print_table(f"{network} on {ex.name}, T = {horizon:g} s ({res.method} steps)", rows)
    for k, why in res.not_finite.items():
        print(f"{k}: {why}")


def simulate_command(
    suspension: Annotated[
        str, typer.Option(help="traditional, cfw, afw, device (system A) or device-afw (system B).")
    ] = "afw",
    input_: Annotated[
        str,
        typer.Option(
            "--input",
            help="drop, bump, sine, iso8608 or a road CSV file with units in its header "
            "(time [s] or distance [m], displacement [m|mm|cm]).",
        ),
    ] = "sine",
    sprung_mass: Annotated[
        float, typer.Option("--sprung-mass", "--body-mass", help="Sprung mass M_v [kg].")
    ] = 370.0,
    unsprung_mass: Annotated[float, typer.Option(help="Unsprung mass M_t [kg].")] = 25.0,
    stiffness: Annotated[float, typer.Option(help="Suspension stiffness K [N/m].")] = 90_000.0,
    damping: Annotated[float, typer.Option(help="Suspension damping C [N s/m].")] = 5000.0,
    tyre_stiffness: Annotated[float, typer.Option(help="Tyre stiffness K_t [N/m].")] = 120_000.0,
    tyre_damping: Annotated[float, typer.Option(help="Tyre damping C_t [N s/m].")] = 1300.0,
    changing_ratio: Annotated[
        float | None, typer.Option(help="Changing ratio x in (0, 1) of the adaptive flywheel.")
    ] = None,
    law: Annotated[
        str, typer.Option(help="Inertia law: thesis, momentum, slider-dynamics.")
    ] = "thesis",
    amplitude: Annotated[
        float, typer.Option(help="Height of drop/bump or sine amplitude [m].")
    ] = 0.05,
    freq: Annotated[float, typer.Option(help="Sine frequency [Hz].")] = 5.0,
    duration: Annotated[float, typer.Option(help="Bump duration [s].")] = 0.01,
    shape: Annotated[str, typer.Option(help="Bump shape: rectangular or 1-cos.")] = "rectangular",
    edge: Annotated[
        str,
        typer.Option(
            help="Edges of the rectangular bump: step (the road jumps), ramp or half-cosine."
        ),
    ] = "step",
    edge_width: Annotated[
        float,
        typer.Option(help="Width of each smoothed bump edge [s] (with --edge ramp/half-cosine)."),
    ] = 0.0,
    horizon: Annotated[float, typer.Option(help="Simulated time T [s].")] = 10.0,
    road_class: Annotated[str, typer.Option("--class", help="ISO 8608 road class A-H.")] = "C",
    speed: Annotated[
        float | None,
        typer.Option(
            help="Vehicle speed [m/s] on the ISO 8608 road (default 20) or on a road file "
            "given over distance."
        ),
    ] = None,
    seed: Annotated[int, seed_option("Seed of the ISO 8608 road.")] = 0,
    lift_off: Annotated[
        bool, typer.Option("--lift-off", help="Let the tyre leave the road.")
    ] = False,
    rtol: Annotated[float, typer.Option(help="Relative tolerance.")] = 1e-8,
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    save: Annotated[Path | None, output_option("Write the time series (.csv or .nc).")] = None,
    plot: Annotated[
        Path | None,
        output_option("Figure of acceleration, deflection, tyre force."),
    ] = None,
    network: Annotated[
        str | None,
        typer.Option(
            help="Suspension network between body and wheel, simulated by the model core, "
            "e.g. 'k | (c - b)' or 'k | c | afw' (elements k, c, b, fric, afw, hyd, screw, "
            "rect, fluid); a named suspension is also accepted."
        ),
    ] = None,
    param: Annotated[
        list[str] | None,
        typer.Option(
            "--param",
            "-p",
            help="With --network: element parameter name=value (k=90000, afw.law=momentum); "
            "repeatable or comma-separated.",
        ),
    ] = None,
    method: Annotated[
        str,
        typer.Option(
            help="auto, adaptive (Dormand-Prince 5(4)) or exact (matrix-exponential steps; "
            "linear cars only)."
        ),
    ] = "auto",
) -> None:
    """Simulate a quarter car on a road input and print its ride metrics.

    Example: inerterlab simulate --suspension afw --input sine --json;
    inerterlab simulate --network "k | (c - b)" --param k=90000 --param c=5000 --param b=200
    """
    from ..errors import ParameterError as _PE

    if network is None and param:
        raise _PE("param", param[0], "no value without --network")
    from ..excitation import RoadTooShortWarning, bump, drop, iso8608, read_road_csv, sine
    from ..simulate import SimulationOptions, simulate
    from ..systems import quarter_car

    if network is None:
        car = quarter_car(
            suspension,
            changing_ratio=changing_ratio,
            law=law,
            tyre_lift_off=lift_off,
            **_car_kwargs(
                sprung_mass, unsprung_mass, stiffness, damping, tyre_stiffness, tyre_damping
            ),
        )
    if input_ == "drop":
        ex = drop(amplitude)
    elif input_ == "bump":
        ex = bump(amplitude, duration=duration, shape=shape, edge=edge, edge_width=edge_width)
    elif input_ == "sine":
        ex = sine(amplitude, freq)
    elif input_ == "iso8608":
        ex = iso8608(road_class, 20.0 if speed is None else speed, seed=seed)
    else:
        ex = read_road_csv(input_, speed=speed)
    if network is not None:
        if lift_off:
            raise _PE("--lift-off", True, "not with --network (a named suspension only)")
        carv = _car_kwargs(
            sprung_mass, unsprung_mass, stiffness, damping, tyre_stiffness, tyre_damping
        )
        preset = {"law": law, "changing_ratio": changing_ratio}
        _simulate_network(
            network, _parse_params(param), ex, horizon, carv, preset, method, rtol, json_out, save,
            plot,
        )  # fmt: skip
        return
    want_series = save is not None or plot is not None
    opts = SimulationOptions(rtol=rtol, method=method)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RoadTooShortWarning)
        res = simulate(
            car, ex, horizon, options=opts, output="series" if want_series else "metrics"
        )
    for w in caught:
        if issubclass(w.category, RoadTooShortWarning):
            print(f"inerterlab: warning: {w.message}", file=sys.stderr)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    m = res.metrics()
    if save is not None:
        _save_series(res, save)
    if plot is not None:
        atomic_savefig(res.plot(), plot)
    if json_out:
        out = {k: m[k] for k in _JSON_KEYS}
        out.update(suspension=suspension, input=ex.name, horizon=horizon, law=res.model.effective_law)
        if res.not_finite:
            out["not_finite"] = dict(res.not_finite)
        out["body_velocity_jumps"] = [{"time": t, "jump": dv} for t, dv in res.body_velocity_jumps]
        if save is not None:
            out["saved"] = str(save)
        if plot is not None:
            out["plot"] = str(plot)
        emit_json(out)
        return

    def label(k: str) -> str:
        unit = METRIC_UNITS.get(k, "")
        return f"{k} [{'-' if unit == '1' else unit}]" if unit else k

    def _cell(v):
        if v is None:
            return "not finite"
        return str(v) if isinstance(v, bool) else f"{v:.6g}"

    rows = [(label(k), _cell(m[k])) for k in _JSON_KEYS]
    rows += [
        (f"body velocity jump at {t:g} s [m/s]", f"{dv:+.6g}") for t, dv in res.body_velocity_jumps
    ]
    print_table(f"{suspension} on {ex.name}, T = {horizon:g} s", rows)
    for k, why in res.not_finite.items():
        print(f"{k}: {why}")


def h2_command(
    suspension: Annotated[
        str, typer.Option(help="traditional or cfw (linear suspensions).")
    ] = "traditional",
    inertance: Annotated[
        float | None, typer.Option(help="cfw only: inertance b [kg] (default r^2 x 2.231e-4).")
    ] = None,
    sprung_mass: CarSprungMass = None,
    unsprung_mass: CarUnsprungMass = None,
    stiffness: Annotated[
        float | None,
        typer.Option(help="Suspension stiffness [N/m] (default: the --vehicle strut's, else 90000)."),
    ] = None,
    damping: Annotated[
        float | None,
        typer.Option(help="Suspension damping [N s/m] (default: the --vehicle strut's, else 5000)."),
    ] = None,
    tyre_stiffness: CarTyreStiffness = None,
    tyre_damping: CarTyreDamping = None,
    vehicle: VehicleFile = None,
    axle: Axle = "front",
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    plot: Annotated[
        Path | None,
        output_option("Figure (.png/.pdf): |H(f)| of the body acceleration against k | c, "
                      "and its PSD with and without the Wk weighting."),
    ] = None,
) -> None:  # fmt: skip
    """H2 norms from unit white road velocity (Lyapunov equation, no time stepping).

    Infinite norms (direct feed-through) are printed as "infinite" (null in JSON) with
    the reason under "infinite". Example: inerterlab h2 --suspension cfw --tyre-damping
    0 --json. Any network: inerterlab network h2 --network 'k | (c - b)' -p ...
    """
    from ..errors import ParameterError
    from ..metrics import h2_norms
    from ..network_design import unit_of
    from ..systems import quarter_car
    from ._common import car_options

    car = car_options(sprung_mass, unsprung_mass, tyre_stiffness, tyre_damping, vehicle, axle)
    if suspension not in ("traditional", "cfw"):
        raise ParameterError(
            "suspension", suspension, "'traditional' or 'cfw' (linear suspensions)"
        )
    if stiffness is None:
        stiffness = car.spring if car.spring is not None else 90_000.0
    if damping is None:
        damping = car.damping if car.damping is not None else 5000.0
    extra = {"inertance": inertance} if inertance is not None else {}
    model = quarter_car(
        suspension,
        **_car_kwargs(car["sprung_mass"], car["unsprung_mass"], stiffness, damping,
                      car["tyre_stiffness"], car["tyre_damping"]),
        **extra,
    )  # fmt: skip
    n = h2_norms(model)
    out = {k: n.norms[k] for k in ("body_acc", "tyre_deflection", "suspension_deflection")}
    out.update(tyre_grip=n.norms["tyre_grip"], body_acc_wk=n.norms["body_acc_wk"])
    units = {k: unit_of(k) for k in ("body_acc", "tyre_deflection", "suspension_deflection",
                                     "body_acc_wk")}  # fmt: skip
    units["tyre_grip"] = "-"
    if n.infinite:
        out["infinite"] = dict(n.infinite)
    out["units"] = units
    out["per"] = "H2 norms per unit white road velocity (two-sided density 1 (m/s)^2 per rad/s)"
    out["car"] = car.describe()
    if plot is not None:
        from ..network_design import network_figure

        params = {"k": stiffness, "c": damping}
        if suspension == "cfw":
            params["b"] = float(model.elements[model.element_names.index("b")].inertance)
        net = "k | c | b" if suspension == "cfw" else "k | c"
        atomic_savefig(network_figure(net, params, **dict(car)), plot)
        out["plot"] = str(plot)
    if json_out:
        emit_json(out)
        return
    rows = [(f"{k} [{units[k]}]", "infinite" if v is None else f"{v:.6g}")
            for k, v in out.items() if k in units]  # fmt: skip
    print_table(f"H2 norms, {suspension}, unit white road velocity", rows)
    print(car.describe())
    for k, why in n.infinite.items():
        print(f"{k}: {why}")


def register(app: typer.Typer) -> None:
    app.command("simulate", help=_CAR_HELP + " " + (simulate_command.__doc__ or ""))(
        simulate_command
    )
    app.command("h2")(h2_command)
