"""``inerterlab network ...``: linear suspension networks in the quarter car.

Subcommands: ``enumerate`` (every distinct network of a budget of elements), ``h2``
(norms of one network), ``optimize`` (H2-optimal parameters, one network or all of a
budget), ``pareto`` (fronts between two or three norms), ``truth`` (the optimised
layouts with nonlinear and real inerters in time simulations) and ``synthesize`` (the
H2-optimal positive-real admittance of a given degree and networks realising it).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Annotated

import typer

from ..networks import MAX_LAYOUTS
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
    seed_option,
    unread_note,
)

network_app = typer.Typer(
    name="network",
    help="Spring/damper/inerter networks as quarter-car suspensions: enumerate "
    "layouts, H2 norms, H2-optimal parameters, Pareto fronts. Networks are text: "
    "'|' parallel, '-' series (binds tighter), parentheses; k.. springs [N/m], "
    "c.. dampers [N s/m], b.. inerters [kg] and every registered element (fluid, fric, "
    "afw, hyd, ...; optimised through its linearisation about rest, parameters "
    "element.parameter). Example: 'k | (k1 - c - b)'.",
    no_args_is_help=True,
    rich_markup_mode=None,
)

SprungMass = Annotated[
    float, typer.Option("--sprung-mass", "--body-mass", help="Sprung mass m_s [kg].")
]
UnsprungMass = Annotated[float, typer.Option("--unsprung-mass", help="Unsprung mass m_u [kg].")]
TyreStiffness = Annotated[float, typer.Option("--tyre-stiffness", help="Tyre stiffness k_t [N/m].")]
TyreDamping = Annotated[float, typer.Option("--tyre-damping", help="Tyre damping c_t [N s/m].")]
Json = Annotated[bool, typer.Option("--json", help="Print JSON.")]
RoadClass = Annotated[
    str | None,
    typer.Option(
        "--road-class",
        help="ISO 8608 road class A-H (with --speed): also print RMS values on that road "
        "(waviness 2, no band limits: white road velocity; a quantity infinite there over "
        "the band 0.01-10 cycle/m).",
    ),
]
Speed = Annotated[float | None, typer.Option("--speed", help="Speed on --road-class [m/s].")]
Plot = Annotated[
    Path | None,
    output_option(
        "Figure (.png/.pdf/.svg): |H(f)| of the body acceleration against k | c, and "
        "its PSD with and without the Wk weighting.",
        "--plot",
    ),
]


def _car(ms, mu, kt, ct) -> dict:
    return dict(sprung_mass=ms, unsprung_mass=mu, tyre_stiffness=kt, tyre_damping=ct)


MaxLayouts = Annotated[
    int,
    typer.Option(
        help="Refuse a budget with more candidate layouts than this (counted before any "
        "work; raise it to run a larger budget on purpose)."
    ),
]


def _check_budget(dampers, inerters, springs, max_layouts: int, what: str) -> None:
    """The budget rule of :func:`~inerterlab.networks.enumerate_networks`, checked
    before any work, then a note when the work is large."""
    import sys

    from ..network_design import check_budget

    n = check_budget(dampers, inerters, springs, max_layouts, cli=True)
    if n["candidates"] > 20:
        print(
            f"inerterlab: note: {n['candidates']} candidate layouts to {what}; "
            "merging equal families alone can take minutes",
            file=sys.stderr,
        )


def _num(v):
    return v if v is None or math.isfinite(v) else None


@network_app.command("enumerate")
def enumerate_command(
    dampers: Annotated[int, typer.Option(help="At most this many dampers (0-4).")] = 1,
    inerters: Annotated[int, typer.Option(help="At most this many inerters (0-4).")] = 1,
    springs: Annotated[
        int, typer.Option(help="At most this many springs besides the main spring k (0-4).")
    ] = 2,
    merge: Annotated[
        bool,
        typer.Option(
            "--merge/--no-merge",
            help="Keep one of each family of equal admittances (numerical test; slow "
            "for budgets above 4-5 elements).",
        ),
    ] = True,
    max_layouts: MaxLayouts = MAX_LAYOUTS,
    json_out: Json = False,
) -> None:
    """List every distinct network k | (N) of a budget of elements in N.

    The main spring k is in parallel with the whole and alone sets the static
    stiffness; equivalent orderings, degenerate pairs (two elements of one kind
    directly in series or parallel) and, with --merge, other structures realising the
    same family of admittances are removed.
    Example: inerterlab network enumerate --dampers 1 --inerters 1 --springs 2 --json
    """
    from ..networks import enumerate_networks

    _check_budget(dampers, inerters, springs, max_layouts, "list")
    nets = enumerate_networks(
        dampers, inerters, springs, merge_equivalent=merge, max_layouts=max_layouts
    )
    out = [{"network": n.text, "parameters": list(n.names)} for n in nets]
    if json_out:
        emit_json(out)
        return
    _table(
        f"{len(nets)} networks: <= {dampers} damper(s), {inerters} inerter(s), "
        f"{springs} spring(s) besides k",
        ["#", "network", "parameters"],
        [(str(i + 1), n.text, ", ".join(n.names)) for i, n in enumerate(nets)],
    )


@network_app.command("h2")
def h2_command(
    network: Annotated[str, typer.Option(help="Network text, e.g. 'k | (k1 - c - b)'.")],
    param: Annotated[
        list[str], typer.Option("--param", "-p", help="name=value, repeatable or comma-separated.")
    ],
    sprung_mass: CarSprungMass = None,
    unsprung_mass: CarUnsprungMass = None,
    tyre_stiffness: CarTyreStiffness = None,
    tyre_damping: CarTyreDamping = None,
    vehicle: VehicleFile = None,
    axle: Axle = "front",
    road_class: RoadClass = None,
    speed: Speed = None,
    peaks: Annotated[
        bool, typer.Option("--peaks/--no-peaks", help="Also the peak gains |H(jw)|max.")
    ] = True,
    plot: Plot = None,
    json_out: Json = False,
) -> None:
    """H2 norms per unit white road velocity of the quarter car with a network, its peak
    gains and, with --road-class/--speed, RMS values on that ISO 8608 road.

    A network with other elements than springs, dampers and inerters is taken about
    rest (each element's declared linearisation; parameters element.parameter=value).
    Example: inerterlab network h2 --network 'k | c' -p k=90000,c=5000 --road-class C
    --speed 25
    """
    from ..errors import NetworkError
    from ..network_design import (
        QUANTITIES,
        TRANSFERS,
        _check_road,
        _parse_assignments,
        band_limited_rms,
        evaluate,
        infinite_reason,
        road_scale,
        unit_of,
    )
    from ..networks import linearise, parse_network
    from ..suspension.network_linear import network_quarter_car

    car = car_options(sprung_mass, unsprung_mass, tyre_stiffness, tyre_damping, vehicle, axle)
    road = _road(road_class, speed)
    net = parse_network(network)
    params = _parse_assignments(param, "parameter")
    lin = net
    if not net.is_linear:
        values = {}
        for k, v in params.items():
            try:
                values[k] = float(v)
            except ValueError:
                raise NetworkError(f"parameter {k}={v!r}: not a number") from None
        lin, params = linearise(net, values)
    q = network_quarter_car(lin, **car)
    names = list(QUANTITIES if peaks else TRANSFERS)
    vals = evaluate(lin, params, names, **car)
    out = {
        "network": net.text,
        "car": dict(car),
        "car_source": car.source,
        **{k: _num(vals[k]) for k in TRANSFERS},
        "units": {k: unit_of(k) for k in names},
        "per": "H2 norms per unit white road velocity (two-sided density 1 (m/s)^2 per "
        "rad/s); peak gains per m/s of road velocity",
    }
    if peaks:
        out["peaks"] = {k: _num(vals[k]) for k in names if k.startswith("peak:")}
    if lin is not net:
        out["linearised_about_rest"] = lin.text
        out["linear_parameters"] = params
    reasons = {k: infinite_reason(k, q, params, road) for k in names if not math.isfinite(vals[k])}
    if reasons:
        out["infinite"] = reasons
    out["states"] = len(q.polynomials(params)["den"]) - 1
    rms = {}
    if road is not None:
        cls, v = _check_road(road)
        sc = road_scale(cls, v)
        for k in TRANSFERS:
            if math.isfinite(vals[k]):
                rms[k] = sc * vals[k]
            elif "not asymptotically stable" not in reasons.get(k, ""):
                rms[f"{k} (band 0.01-10 cycle/m)"] = band_limited_rms(k, q, params, cls, v)
        out["road"] = {"class": cls, "speed": v, "units": "m/s"}
        out["rms"] = rms
    if plot is not None:
        from ..network_design import network_figure

        atomic_savefig(network_figure(lin, params, road=road, **car), plot)
        out["plot"] = str(plot)
    if json_out:
        emit_json(out)
        return
    rows = [
        (f"H2 {k} [{unit_of(k)}]", "infinite" if not math.isfinite(vals[k]) else f"{vals[k]:.6g}")
        for k in TRANSFERS
    ]
    if peaks:
        rows += [(f"{k} [{unit_of(k)}]", _fmt(vals[k])) for k in names if k.startswith("peak:")]
    if road is not None:
        from ..network_design import UNITS

        for k, v in rms.items():
            rows.append((f"RMS {k} [{UNITS[k.split(' ')[0]]}]", f"{v:.6g}"))
    rows.append(("states", str(out["states"])))
    about = f" linearised about rest as {lin.text}" if lin is not net else ""
    where = f", ISO 8608 class {road[0]} at {road[1]:g} m/s" if road is not None else ""
    print_table(
        f"{net.text}{about}: H2 norms per unit white road velocity, peak gains per m/s{where}",
        rows,
    )
    typer.echo(car.describe())
    for line in reasons.values():
        typer.echo(line)


def _road(road_class, speed):
    """(class, speed) from --road-class and --speed, both or neither."""
    from ..errors import ParameterError
    from ..network_design import _check_road

    if (road_class is None) != (speed is None):
        missing = "--speed" if speed is None else "--road-class"
        raise ParameterError(
            missing, None, "a value: --road-class and --speed go together (e.g. C and 25)"
        )
    if road_class is None:
        return None
    try:
        return _check_road((road_class, speed))
    except Exception as e:
        from ..errors import ParameterError as PE

        if isinstance(e, PE):
            name = "--speed" if e.name == "speed" else "--road-class"
            raise PE(name, e.value, e.valid) from None
        raise


def _limits(limit=None) -> dict:
    """--limit quantity=value (repeatable, or comma-separated): the one way to limit a
    quantity of the objectives (tyre_load [N], tyre_deflection [m], ...)."""
    from ..errors import ParameterError
    from ..network_design import QUANTITIES

    lim = {}
    for item in limit or []:
        for part in item.split(","):
            name, eq, value = part.partition("=")
            name = name.strip()
            if not eq or name not in QUANTITIES:
                raise ParameterError(
                    "limit", part, "quantity=value with a quantity of " + ", ".join(QUANTITIES)
                )
            try:
                v = float(value)
            except ValueError:
                raise ParameterError("limit", part, "quantity=<a number > 0>") from None
            if not (v > 0 and math.isfinite(v)):
                raise ParameterError("limit", part, "quantity=<a number > 0>")
            lim[name] = min(lim.get(name, v), v)
    return lim


def _inertance(text: str | None) -> float | None:
    """--max-inertance: '300kg', '300 kg' or '300' [kg]."""
    from ..errors import ParameterError

    if text is None:
        return None
    t = text.strip().lower().removesuffix("kg").strip()
    try:
        v = float(t)
    except ValueError:
        raise ParameterError("max-inertance", text, "an inertance in kg, e.g. 300kg") from None
    if not (v > 0 and math.isfinite(v)):
        raise ParameterError("max-inertance", text, "an inertance > 0 kg, e.g. 300kg")
    return v


@network_app.command("optimize")
def optimize_command(
    network: Annotated[str | None, typer.Option(help="Network text; omit with --all.")] = None,
    all_: Annotated[
        bool, typer.Option("--all", help="Every network of the budget (--dampers ...).")
    ] = False,
    objective: Annotated[
        str,
        typer.Option(
            help="H2 norm: body_acc, body_acc_wk (ISO 2631 Wk-weighted), tyre_deflection, "
            "tyre_load (k_t x tyre deflection), tyre_force (spring and damper), "
            "suspension_deflection; peak:<one of those> (largest gain over frequency); "
            "or weighted."
        ),
    ] = "body_acc",
    fix: Annotated[
        list[str] | None,
        typer.Option(help="Held parameter name=value, e.g. k=50000 (repeatable)."),
    ] = None,
    bound: Annotated[
        list[str] | None,
        typer.Option(help="Search range name=low:high, e.g. b=0:500 (repeatable)."),
    ] = None,
    weight: Annotated[
        list[str] | None,
        typer.Option(
            help="weighted only: quantity=w, e.g. body_acc_wk=1,tyre_load=1 (default equal "
            "on body_acc, tyre_deflection, suspension_deflection)."
        ),
    ] = None,
    limit: Annotated[
        list[str] | None,
        typer.Option(
            help="Constraint quantity=value on any quantity of the objectives, in its unit "
            "(H2 per unit white road velocity, peak per m/s), e.g. "
            "peak:suspension_deflection=0.05 (repeatable)."
        ),
    ] = None,
    max_inertance: Annotated[
        str | None,
        typer.Option(
            help="Upper limit of every inerter (and of the inertance of a device's "
            "linearisation), e.g. 300kg."
        ),
    ] = None,
    dampers: Annotated[int, typer.Option(help="--all: budget of dampers.")] = 1,
    inerters: Annotated[int, typer.Option(help="--all: budget of inerters.")] = 1,
    springs: Annotated[int, typer.Option(help="--all: budget of springs besides k.")] = 2,
    starts: Annotated[
        int, typer.Option(help="Starts for the local polish (evolution + best sample points).")
    ] = 8,
    seed: Annotated[int, seed_option("Seed of the Sobol sample.")] = 0,
    max_layouts: MaxLayouts = MAX_LAYOUTS,
    sprung_mass: CarSprungMass = None,
    unsprung_mass: CarUnsprungMass = None,
    tyre_stiffness: CarTyreStiffness = None,
    tyre_damping: CarTyreDamping = None,
    vehicle: VehicleFile = None,
    axle: Axle = "front",
    road_class: RoadClass = None,
    speed: Speed = None,
    plot: Plot = None,
    json_out: Json = False,
) -> None:
    """Optimal parameters of a network (global sample, then local polish).

    With --vehicle the main spring k is held at the vehicle strut's static stiffness
    unless --fix or --bound names k. An optimum on a bound that stands for a simpler
    layout (a spring or damper at the top of its range: rigid; an element at the bottom
    of its range: absent) is reported as that layout.

    Example: inerterlab network optimize --network 'k | (k1 - c - b)' --objective
    body_acc_wk --fix k=50000 --max-inertance 300kg --road-class C --speed 25
    """
    from ..errors import ParameterError
    from ..network_design import optimize_network
    from ..networks import enumerate_networks

    car = car_options(sprung_mass, unsprung_mass, tyre_stiffness, tyre_damping, vehicle, axle)
    road = _road(road_class, speed)
    cap = _inertance(max_inertance)
    lim = _limits(limit)
    if all_ == (network is not None):
        raise ParameterError("network", network, "a network text, or --all (not both)")
    fix = list(fix or [])
    held = None
    named = {p.split("=")[0].strip() for item in fix + list(bound or []) for p in item.split(",")}
    if car.spring is not None and "k" not in named:
        fix.append(f"k={car.spring!r}")
        held = car.spring
    if all_:
        from ..network_design import check_settings

        # every setting checked before the budget's note, so no note precedes an error
        check_settings(
            objective, weights=weight, starts=starts, seed=seed, max_inertance=cap, road=road
        )
        _check_budget(dampers, inerters, springs, max_layouts, "optimise")
    nets = (
        [n.text for n in enumerate_networks(dampers, inerters, springs, max_layouts=max_layouts)]
        if all_
        else [network]
    )
    results = [
        optimize_network(
            n,
            objective,
            fixed=fix or None,
            bounds=[b for b in (bound or []) if b.split("=")[0] in _names(n)] if all_ else bound,
            constraints=lim,
            weights=weight,
            starts=starts,
            seed=seed,
            max_inertance=cap,
            road=road,
            **car,
        )
        for n in nets
    ]
    if plot is not None:
        from ..network_design import network_figure

        best = min(results, key=lambda r: r.objective)
        shown = best.simplified.get("parameters") if best.simplified else None
        text = best.simplified["network"] if shown else best.network
        params = shown or best.parameters
        ref = optimize_network(
            "k | c",
            objective,
            fixed={k: v for k, v in params.items() if k == "k"},
            constraints=lim,
            weights=weight,
            seed=seed,
            compare=False,
            **car,
        )
        atomic_savefig(
            network_figure(
                text,
                params,
                reference=ref.parameters,
                road=road,
                title=f"{text}: optimum of {objective}",
                **car,
            ),
            plot,
        )
    if json_out:
        out = [_short(r) for r in results] if all_ else _short(results[0])
        extra = {"car": dict(car), "car_source": car.source}
        if held is not None:
            extra["k_held_at_vehicle_spring"] = held
        if all_:
            out = {"results": out, **extra}
        else:
            out.update(extra)
        emit_json(out)
        return
    unit = results[0].unit
    if all_:
        rows = [
            (
                r.network + (f" -> {r.simplified['network']}" if r.simplified else ""),
                _fmt(r.objective),
                "-"
                if r.improvement_vs.get("k | c") is None
                else f"{r.improvement_vs['k | c']:+.2f}",
                ", ".join(r.at_bound) or "-",
            )
            for r in sorted(results, key=lambda r: r.objective)
        ]
        _table(
            f"{objective} [{unit}]: optimal networks (-> the simpler layout an optimum on a "
            "bound stands for)",
            ["network", f"{objective} [{unit}]", "% vs k | c", "at bound"],
            rows,
        )
        typer.echo(car.describe())
        if held is not None:
            typer.echo(f"main spring k held at the vehicle's {held:g} N/m")
        for line in sorted({v for r in results for v in r.infinite.values()}):
            if line.startswith(objective + " "):
                typer.echo(line)
        return
    r = results[0]
    rows = [(f"objective {objective} [{unit}]", _fmt(r.objective))]
    rows += [
        (f"{k} [{r.units[k]}]" if r.units.get(k) else k, f"{v:.6g}")
        for k, v in r.parameters.items()
    ]
    from ..network_design import UNITS, unit_of

    rows += [(f"H2 {k} [{UNITS[k]}]", _fmt(v)) for k, v in r.norms.items()]
    used = {objective, *lim, *(w.split("=")[0].strip() for i in weight or [] for w in i.split(","))}
    rows += [(f"{k} [{unit_of(k)}]", _fmt(v)) for k, v in r.peaks.items() if k in used]
    for k, v in r.rms.items():
        rows.append((f"RMS {k} [{UNITS[k.split(' ')[0]]}]", f"{v:.6g}"))
    for k, v in r.improvement_vs.items():
        rows.append((f"improvement vs {k} [%]", "n/a" if v is None else f"{v:.3f}"))
    rows += [("converged", str(r.converged)), ("at bound", ", ".join(r.at_bound) or "-")]
    where = f"; RMS on ISO 8608 class {road[0]} at {road[1]:g} m/s" if road else ""
    print_table(f"optimal {r.network}: H2 per unit white road velocity, peaks per m/s{where}", rows)
    typer.echo(car.describe())
    if held is not None:
        typer.echo(f"main spring k held at the vehicle's {held:g} N/m")
    if r.max_inertance is not None:
        typer.echo(f"every inerter limited to {r.max_inertance:g} kg")
    if r.simplified:
        s = r.simplified
        typer.echo(
            f"simplifies to {s['network']}: "
            + "; ".join(s["why"])
            + (
                f"; optimised as such: {objective} = {_fmt(s['objective'])} {unit}"
                if s.get("objective") is not None
                else ""
            )
        )
    for line in r.infinite.values():
        typer.echo(line)
    if r.reason:
        typer.echo(f"note: {r.reason}")


def _table(title: str, columns: list[str], rows: list[tuple]) -> None:
    from rich.console import Console
    from rich.table import Table

    t = Table(title=title)
    for i, c in enumerate(columns):
        t.add_column(c, justify="left" if i == 0 or c == "network" else "right")
    for r in rows:
        t.add_row(*r)
    Console(width=max(100, Console().width)).print(t)


def _names(text: str) -> tuple:
    from ..networks import parse_network

    return parse_network(text).names


def _fmt(v: float) -> str:
    return "infinite" if not math.isfinite(v) else f"{v:.6g}"


def _short(r) -> dict:
    d = r.to_dict()
    out = {
        "network": d["network"],
        "objective": d["objective"],
        "parameters": d["parameters"],
        "units": d["units"],
        "norms": d["norms"],
        "improvement_vs": d["improvement_vs"],
        "converged": d["converged"],
        "at_bound": d["at_bound"],
    }
    out["unit"] = d["unit"]
    for k in (
        "peaks",
        "infinite",
        "road",
        "rms",
        "simplified",
        "max_inertance",
        "constraints",
        "reason",
    ):
        if k in d:
            out[k] = d[k]
    return out


@network_app.command("pareto")
def pareto_command(
    network: Annotated[list[str], typer.Option(help="Network text (repeatable).")],
    objectives: Annotated[
        str, typer.Option(help="Two or three outputs, comma-separated; the first is minimised.")
    ] = "body_acc,tyre_deflection",
    points: Annotated[int, typer.Option(help="Sweep points per constrained objective.")] = 10,
    fix: Annotated[
        list[str] | None, typer.Option(help="Held parameter name=value (repeatable).")
    ] = None,
    bound: Annotated[
        list[str] | None, typer.Option(help="Search range name=low:high (repeatable).")
    ] = None,
    sprung_mass: CarSprungMass = None,
    unsprung_mass: CarUnsprungMass = None,
    tyre_stiffness: CarTyreStiffness = None,
    tyre_damping: CarTyreDamping = None,
    vehicle: VehicleFile = None,
    axle: Axle = "front",
    csv: Annotated[Path | None, output_option("Write the fronts as CSV.")] = None,
    save: Annotated[Path | None, output_option("Write the Dataset (.nc).")] = None,
    plot: Annotated[Path | None, output_option("Figure of the fronts (.png/.pdf).")] = None,
    json_out: Json = False,
) -> None:
    """Pareto fronts between H2 norms for a set of networks (epsilon-constraint sweep).

    Example: inerterlab network pareto --network 'k | c' --network 'k | (k1 - c - b)'
    --objectives body_acc,tyre_deflection --fix k=50000 --csv front.csv --plot front.png
    """
    from ..errors import ParameterError
    from ..io import atomic_path
    from ..network_design import pareto_figure, pareto_front

    if points < 2 or points > 60:
        raise ParameterError("points", points, "an integer 2-60")
    objs = [o.strip() for o in objectives.split(",") if o.strip()]
    car = car_options(sprung_mass, unsprung_mass, tyre_stiffness, tyre_damping, vehicle, axle)
    fix = list(fix or [])
    named = {p.split("=")[0].strip() for item in fix + list(bound or []) for p in item.split(",")}
    if car.spring is not None and "k" not in named:
        fix.append(f"k={car.spring!r}")
    ds = pareto_front(network, objs, points=points, fixed=fix or None, bounds=bound, **car)
    df = ds.to_dataframe().reset_index().dropna(subset=objs)
    if csv is not None:
        atomic_write_text(csv, df.to_csv(index=False, float_format="%.10g"), "--csv")
    if save is not None:
        with atomic_path(save, suffix=".nc", option="--save") as tmp:
            ds.to_netcdf(tmp, engine="scipy")
    if plot is not None:
        atomic_savefig(pareto_figure(ds), plot)
    if json_out:
        emit_json(
            {
                "objectives": objs,
                "fronts": {
                    str(n): [
                        {o: float(g[o]) for o in objs} for _, g in df[df["network"] == n].iterrows()
                    ]
                    for n in ds["network"].values
                },
            }
        )
        return
    rows = []
    for n in ds["network"].values:
        sub = df[df["network"] == n]
        rows.append(
            (
                str(n),
                f"{len(sub)} points, {objs[0]} {sub[objs[0]].min():.4g}-{sub[objs[0]].max():.4g}"
                if len(sub)
                else "no feasible point",
            )
        )
    print_table(f"Pareto fronts {', '.join(objs)}", rows)
    typer.echo(car.describe())


@network_app.command("truth")
def truth_command(
    layout: Annotated[
        list[str] | None,
        typer.Option(help="Layout (repeatable): parallel, series, series-spring; default all."),
    ] = None,
    variant: Annotated[
        list[str] | None,
        typer.Option(
            help="Variant (repeatable): ideal, 'ideal-max x=X', 'afw x=X law=L', hydraulic, "
            "rectifier, screw, fluid; default the full list."
        ),
    ] = None,
    input_: Annotated[
        list[str] | None,
        typer.Option("--input", help="Input (repeatable): drop, bump, sine-1.5, sine-5, iso-c."),
    ] = None,
    stiffness_given: Annotated[
        float | None,
        typer.Option(
            "--stiffness",
            help="Static stiffness k [N/m] (default: the --vehicle strut's, else 90000).",
        ),
    ] = None,
    horizon: Annotated[float, typer.Option(help="Simulated time [s].")] = 10.0,
    seed: Annotated[int, seed_option("ISO 8608 road seed [-].")] = 1,
    out: Annotated[
        Path | None,
        typer.Option("--out", help="Folder of the Zarr stores; rerunning resumes the study."),
    ] = None,
    workers: Annotated[int | None, typer.Option(help="Worker processes.")] = None,
    backend: Annotated[str, typer.Option(help="serial, processes or dask.")] = "processes",
    csv: Annotated[Path | None, output_option("Write the comfort gains as CSV.")] = None,
    plot: Annotated[Path | None, output_option("Figure of the gains (.png/.pdf).")] = None,
    json_out: Json = False,
    quiet: Annotated[bool, typer.Option(help="No progress bar.")] = False,
    network: Annotated[
        str | None,
        typer.Option(
            help="Also study this network as layout 'custom' (e.g. printed by "
            "'network synthesize'); its inerter b is the one replaced. Needs --param."
        ),
    ] = None,
    param: Annotated[
        list[str] | None,
        typer.Option("--param", "-p", help="With --network: element values name=value,..."),
    ] = None,
    sprung_mass: CarSprungMass = None,
    unsprung_mass: CarUnsprungMass = None,
    tyre_stiffness: CarTyreStiffness = None,
    tyre_damping: CarTyreDamping = None,
    vehicle: VehicleFile = None,
    axle: Axle = "front",
) -> None:
    """Nonlinear truth of the H2-optimal layouts: the ideal inerter replaced by an adaptive
    flywheel, a real device or a fluid inerter, simulated on drop, bump, sine and ISO 8608
    inputs. Prints the comfort gain (ISO 2631 Wk RMS) in percent against the optimised
    k | c on the same input (positive: better) and plain-language findings.

    Example: inerterlab network truth --layout series --input bump --input iso-c --workers 2
    """
    from ..errors import Interrupted
    from ..network_truth import INPUTS, LAYOUTS, network_truth, variants

    stiffness = 90_000.0 if stiffness_given is None else stiffness_given
    from ..studies import SweepInterrupted
    from ..studies.backends import check_workers

    if workers is not None:
        check_workers("--workers", workers)
    car = car_options(sprung_mass, unsprung_mass, tyre_stiffness, tyre_damping, vehicle, axle)
    if car.spring is not None and stiffness_given is None:
        stiffness = car.spring
    try:
        from ..errors import ParameterError

        if (network is None) != (not param):
            raise ParameterError("network", network, "--network together with --param")
        custom = None if network is None else (network, ",".join(param))
        res = network_truth(
            custom=custom,
            layouts=tuple(layout or (() if custom else LAYOUTS)),
            variant_list=variant or variants(),
            inputs=tuple(input_ or INPUTS),
            stiffness=stiffness,
            horizon=horizon,
            seed=seed,
            store=out,
            backend=backend,
            workers=workers,
            progress=not quiet and not json_out,
            car={k: car[k] for k in car},
        )
    except SweepInterrupted as exc:
        raise Interrupted(str(exc)) from None
    g = res.gains["rms_body_acc_wk"]
    if res.unread_stores and not quiet and not json_out:
        print(unread_note("network truth", out, res.unread_stores), file=sys.stderr)
    if csv is not None:
        frame = g.to_dataframe(name="comfort_gain_percent").reset_index()
        atomic_write_text(csv, frame.to_csv(index=False), "--csv")
    if plot is not None:
        from ..network_truth import truth_figure

        atomic_savefig(truth_figure(res), plot)
    if json_out:
        emit_json({**res.to_dict(), "car_source": car.source, "stiffness": stiffness})
        return
    inputs = [str(i) for i in g.input.values]
    for lay in g.layout.values:
        rows = [
            (str(v), *(f"{float(g.sel(layout=lay, variant=v, input=i)):+.2f}" for i in inputs))
            for v in g.variant.values
        ]
        _table(
            f"{lay}: {res.layout_text(str(lay))}, comfort gain [%] vs optimised k | c",
            ["variant", *inputs],
            rows,
        )
    typer.echo(car.describe() + f"; static stiffness k {stiffness:g} N/m")
    for line in res.findings():
        typer.echo(line)


@network_app.command("synthesize")
def synthesize_command(
    degree: Annotated[int, typer.Option(help="McMillan degree n of Y0 (1, 2 or 3).")] = 2,
    objective: Annotated[
        str,
        typer.Option(
            help="body_acc, body_acc_wk, tyre_deflection, tyre_load (k_t x tyre "
            "deflection) or suspension_deflection."
        ),
    ] = "body_acc",
    fix_static: Annotated[
        str, typer.Option(help="Main spring (static stiffness) k=value [N/m].")
    ] = "k=90000",
    starts: Annotated[
        int | None,
        typer.Option(help="Independent differential evolutions (default 3; 10 for degree 3)."),
    ] = None,
    seed: Annotated[int, seed_option("Seed of the first evolution [-].")] = 0,
    compare: Annotated[
        bool,
        typer.Option(
            "--compare/--no-compare",
            help="Also optimise the enumerated layouts with deg Y0 <= n (gap in percent).",
        ),
    ] = True,
    dampers: Annotated[int, typer.Option(help="Comparison budget: dampers.")] = 1,
    inerters: Annotated[int, typer.Option(help="Comparison budget: inerters.")] = 1,
    springs: Annotated[int, typer.Option(help="Comparison budget: springs besides k.")] = 2,
    sprung_mass: SprungMass = 370.0,
    unsprung_mass: UnsprungMass = 25.0,
    tyre_stiffness: TyreStiffness = 120_000.0,
    tyre_damping: TyreDamping = 1300.0,
    json_out: Json = False,
) -> None:
    """H2-optimal positive-real admittance Y = k/s + Y0 (Y0 PR of degree n) and its networks.

    Prints the optimum, Y(s), the PR check, realisations (Foster, Cauer, catalogue,
    Bott-Duffin; Brune's element values) and the gap to the best enumerated layout.
    Example: inerterlab network synthesize --degree 2 --objective body_acc --fix-static k=90000
    """
    from ..errors import ParameterError
    from ..synthesis.design import synthesize_design

    name, _, value = fix_static.partition("=")
    if name.strip() != "k":
        raise ParameterError("fix-static", fix_static, "k=<static stiffness in N/m>, e.g. k=90000")
    try:
        k = float(value)
    except ValueError:
        raise ParameterError("fix-static", fix_static, "k=<a number > 0 in N/m>") from None
    if degree not in (1, 2, 3):
        raise ParameterError("degree", degree, "1, 2 or 3")
    for nm, v in (("dampers", dampers), ("inerters", inerters), ("springs", springs)):
        if not 0 <= v <= 3:
            raise ParameterError(nm, v, "an integer 0-3")
    out = synthesize_design(
        degree,
        objective,
        static_stiffness=k,
        starts=starts,
        seed=seed,
        compare=compare,
        budget=(dampers, inerters, springs),
        **_car(sprung_mass, unsprung_mass, tyre_stiffness, tyre_damping),
    )
    if json_out:
        emit_json(out)
        return
    _print_synthesis(out)


def _poly_text(c) -> str:
    n = len(c) - 1
    terms = [
        f"{v:.6g} s^{n - i}" if n - i > 1 else (f"{v:.6g} s" if n - i == 1 else f"{v:.6g}")
        for i, v in enumerate(c)
        if v != 0
    ]
    return " + ".join(terms) or "0"


def _print_synthesis(out: dict) -> None:
    unit = out["unit"]
    rows = [
        (
            f"optimum {out['objective_name']} [{unit}] (H2, unit white road velocity, linear)",
            _fmt(out["objective"]),
        ),
        ("static stiffness k [N/m]", f"{out['static_stiffness']:.6g}"),
        ("Y(s) = F/v [N s/m], s [rad/s]: numerator", _poly_text(out["numerator"])),
        ("Y(s) denominator", _poly_text(out["denominator"])),
        ("Y0(s) = Y - k/s numerator", _poly_text(out["y0_numerator"])),
        ("Y0(s) denominator", _poly_text(out["y0_denominator"])),
        ("positive real (grid, roots)", str(out["positive_real"]["positive_real"])),
        ("min Re Y0(jw) [N s/m]", f"{out['positive_real']['min_real_part']:.3g}"),
        ("evolutions: best of each", ", ".join(_fmt(v) for v in out["starts"])),
        (
            "evolutions within 1e-6 of the best",
            f"{sum(v <= out['objective'] * (1 + 1e-6) for v in out['starts'])} of "
            f"{len(out['starts'])}",
        ),
        ("search time [s]", f"{out['seconds']:.2f}"),
    ]
    chk = out.get("integral_check")
    rows.append(
        (
            "check: frequency integral of |H(jw)|^2, relative difference",
            "no end confirmed" if chk is None or chk != chk else f"{chk:.1e}",
        )
    )
    if out.get("at_bound"):
        rows.append(("warning", out["note"]))
    if "rounded" in out:
        rows.append(
            ("rounded Y0 (negligible coefficients 0): objective", _fmt(out["rounded"]["objective"]))
        )
    print_table(f"PR synthesis, degree {out['degree']}", rows)
    rrows = []
    for m, r in out["realisations"].items():
        if isinstance(r, str):
            rrows.append((m, "-", "-", r))
        else:
            rrows.append(
                (
                    m,
                    r["network"],
                    str(r["elements"]),
                    f"max rel. error {r['max_relative_error']:.1e}",
                )
            )
    _table(
        "Realisations (admittance checked at points on and off the imaginary axis)",
        ["method", "network", "elements", "check"],
        rrows,
    )
    for m, r in out["realisations"].items():
        if not isinstance(r, str):
            params = ",".join(f"{k}={v!r}" for k, v in r["parameters"].items())
            typer.echo(f"{m}: --network '{r['network']}' -p {params}")
    br = out.get("brune", {})
    if br.get("sections"):
        for i, sec in enumerate(br["sections"]):
            if sec["domain"] == "impedance":  # L: spring of stiffness 1/L, C: inerter
                parts = (
                    f"springs 1/L1 = {1 / sec['L1']:.6g}, 1/L3 = {1 / sec['L3']:.6g} N/m in "
                    f"series, shunt spring 1/L2 = {1 / sec['L2']:.6g} N/m - inerter "
                    f"C2 = {sec['C2']:.6g} kg"
                )
            else:  # the dual: L: inerter, C: spring of stiffness 1/C
                parts = (
                    f"inerters L1 = {sec['L1']:.6g}, L3 = {sec['L3']:.6g} kg in parallel "
                    f"positions, branch inerter L2 = {sec['L2']:.6g} kg | spring "
                    f"1/C2 = {1 / sec['C2']:.6g} N/m"
                )
            typer.echo(
                f"brune section {i + 1} of Y0 ({sec['domain']} form, w0 = {sec['w0']:.6g} "
                f"rad/s): {parts}; one value negative: needs a lever, no network text"
            )
    elif br:
        typer.echo(f"brune: {br.get('reason', 'no minimum function: no Brune section needed')}")
    cmp_ = out.get("comparison")
    if cmp_:
        if "layouts" in cmp_:
            b = cmp_["budget"]
            typer.echo(
                f"best enumerated layout with deg Y0 <= {out['degree']} (budget {b['dampers']} "
                f"damper(s), {b['inerters']} inerter(s), {b['springs']} spring(s) besides k, "
                f"{len(cmp_['layouts'])} layouts): {cmp_['best']}  {out['objective_name']} = "
                f"{_fmt(cmp_['best_objective'])} {unit}; PR optimum better by "
                + ("n/a" if cmp_.get("gap_percent") is None else f"{cmp_['gap_percent']:.3f} %")
            )
        else:
            typer.echo(f"comparison: {cmp_['reason']}")
    typer.echo(f"wall {out['seconds_total']:.2f} s")


def register(app: typer.Typer) -> None:
    app.add_typer(network_app, name="network")
