"""``inerterlab design``: the layout, the amount and the real device for one car."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ._common import atomic_write_text, emit_json, seed_option, unread_note

_CAR_DEFAULTS = {
    "sprung_mass": 370.0,
    "unsprung_mass": 25.0,
    "tyre_stiffness": 120_000.0,
    "tyre_damping": 1300.0,
    "stiffness": 90_000.0,
}


def _quantity(option: str, text: str | None, dimension: str, unit: str) -> float | None:
    """A number in SI ``unit`` or a value with its unit ("300 kg", "20 mm")."""
    from ..errors import ParameterError
    from ..vehicles.config import parse_quantity

    if text is None:
        return None
    s = str(text).strip()
    try:
        return float(s)
    except ValueError:
        pass
    import re

    s = re.sub(r"^([-+]?[0-9.eE+-]+)([A-Za-z])", r"\1 \2", s)
    try:
        return parse_quantity(s, dimension)
    except ParameterError:
        raise ParameterError(
            option, text, f"a number in {unit} or a value with a unit of {dimension}"
        ) from None


def _budget(text: str) -> dict:
    from ..errors import ParameterError

    out = {"springs": 2, "dampers": 1, "inerters": 1}
    for part in text.split(","):
        name, eq, val = part.strip().partition("=")
        if not eq or name not in out:
            raise ParameterError("--budget", text, "springs=N,dampers=N,inerters=N (N 0-4)")
        try:
            n = int(val)
        except ValueError:
            raise ParameterError(
                "--budget", text, "springs=N,dampers=N,inerters=N (N 0-4)"
            ) from None
        if not 0 <= n <= 4:
            raise ParameterError("--budget", text, "springs=N,dampers=N,inerters=N (N 0-4)")
        out[name] = n
    if out["inerters"] < 1 or out["dampers"] < 1:
        raise ParameterError("--budget", text, "at least one damper and one inerter")
    return out


def _limits(items: list[str] | None) -> dict:
    from ..errors import ParameterError

    out = {}
    for it in items or []:
        name, eq, val = it.partition("=")
        name = name.strip()
        if not eq or name not in ("deflection", "tyre_load"):
            raise ParameterError("--limit", it, "deflection=<RMS in m> or tyre_load=<RMS in N>")
        if name in out:
            raise ParameterError("--limit", it, f"{name} given once")
        dim, unit = ("length", "m") if name == "deflection" else ("force", "N")
        x = _quantity(f"--limit {name}", val, dim, unit)
        if not x > 0:
            raise ParameterError(f"--limit {name}", val, f"a limit > 0 {unit}")
        out[name] = x
    return out


def _car_from_vehicle(path: Path, corner: str) -> dict:
    """The quarter car of one corner of a vehicle file (docs/guide/design.md)."""
    from ..design.vehicle import corner_car
    from ..errors import ParameterError
    from ..vehicles.config import load_vehicle

    if corner not in ("front", "rear"):
        raise ParameterError("--corner", corner, "front or rear")
    return corner_car(load_vehicle(path), corner)


def design_command(
    out: Annotated[
        Path,
        typer.Option("--out", help="Folder of the report, JSON and stores (resumes); required."),
    ],
    vehicle: Annotated[
        Path | None,
        typer.Option(
            help="Vehicle file (TOML): its half or full car is designed (the same layout at "
            "every corner, values per axle), or with --corner one corner as a quarter car."
        ),
    ] = None,
    corner: Annotated[
        str | None,
        typer.Option(
            help="With --vehicle: design this corner (front or rear) as a quarter car."
        ),
    ] = None,
    model: Annotated[
        str | None,
        typer.Option(
            help="quarter, half or full (default: the vehicle file's model, else quarter; "
            "half takes a full car's pitch-plane half car)."
        ),
    ] = None,
    sprung_mass: Annotated[str | None, typer.Option(help="Sprung mass per corner [kg].")] = None,
    unsprung_mass: Annotated[str | None, typer.Option(help="Unsprung mass [kg].")] = None,
    tyre_stiffness: Annotated[str | None, typer.Option(help="Tyre stiffness [N/m].")] = None,
    tyre_damping: Annotated[str | None, typer.Option(help="Tyre damping [N s/m].")] = None,
    spring_stiffness: Annotated[
        str | None, typer.Option(help="Main spring (static stiffness, held) [N/m].")
    ] = None,
    road_class: Annotated[str, typer.Option(help="ISO 8608 road class A-H.")] = "C",
    speed: Annotated[float, typer.Option(help="Speed [m/s].")] = 25.0,
    budget: Annotated[
        str, typer.Option(help="Elements of the layouts: springs=N,dampers=N,inerters=N.")
    ] = "springs=2,dampers=1,inerters=1",
    objective: Annotated[
        str, typer.Option(help="seat_wk, body_acc_wk, body_acc, tyre_load or weighted.")
    ] = "body_acc_wk",
    limit: Annotated[
        list[str] | None,
        typer.Option(help="Repeatable: deflection=<RMS m> or tyre_load=<RMS N> (units allowed)."),
    ] = None,
    max_inertance: Annotated[
        str, typer.Option(help="Largest inertance of any inerter [kg], e.g. 300kg.")
    ] = "2000 kg",
    devices: Annotated[
        str, typer.Option(help="Real devices to re-check: hydraulic,rectifier,screw,fluid or none.")
    ] = "hydraulic,rectifier,screw,fluid",
    synthesize: Annotated[
        int, typer.Option(help="Add the positive-real optimum of this degree (0: none, 1-3).")
    ] = 0,
    roads: Annotated[int, typer.Option(help="ISO 8608 road realisations per candidate.")] = 20,
    tune_roads: Annotated[
        int, typer.Option(help="Roads of the device tuning and requirement searches.")
    ] = 4,
    horizon: Annotated[float, typer.Option(help="Seconds of road per realisation [s].")] = 10.0,
    top: Annotated[int, typer.Option(help="Best linear layouts scored on roads.")] = 4,
    recheck: Annotated[int, typer.Option(help="Best layouts re-checked with each device.")] = 1,
    seed: Annotated[int, seed_option("First road seed [-].")] = 0,
    workers: Annotated[int, typer.Option(help="Worker processes.")] = 2,
    max_minutes: Annotated[
        float, typer.Option(help="Refuse a study estimated to take longer [min].")
    ] = 30.0,
    json_out: Annotated[bool, typer.Option("--json", help="Print the result as JSON.")] = False,
    quiet: Annotated[bool, typer.Option(help="No progress lines.")] = False,
) -> None:
    """Design a suspension for one car: enumerate the layouts of a budget, optimise each
    (H2, linear), re-check the best with real devices optimised with their parasitics in
    the loop, score every candidate by its expected value over ISO 8608 road realisations
    (time domain, 95 % interval), and write an HTML report and JSON.

    Example: inerterlab design --sprung-mass 420 --unsprung-mass 45 --tyre-stiffness 250e3
    --tyre-damping 0 --spring-stiffness 30e3 --road-class C --speed 25 --out my-design
    """
    import sys

    from ..design import DesignSettings, estimate, run_design
    from ..design.pipeline import check_out_folder
    from ..errors import Interrupted, ParameterError
    from ..studies import SweepInterrupted
    from ..studies.backends import check_workers

    if model not in (None, "quarter", "half", "full"):
        raise ParameterError("--model", model, "quarter, half or full")
    if corner is not None and corner not in ("front", "rear"):
        raise ParameterError("--corner", corner, "front or rear")
    if corner is not None and model in ("half", "full"):
        raise ParameterError("--corner", corner, f"not given with --model {model} (a corner "
                             "is designed as a quarter car)")  # fmt: skip
    if corner is not None:
        model = "quarter"
    if model in ("half", "full") and vehicle is None:
        raise ParameterError("--model", model, "quarter without --vehicle (a half or full car "
                             "comes from a vehicle file)")  # fmt: skip
    check_workers("--workers", workers)
    car = dict(_CAR_DEFAULTS)
    source = "options (thesis car defaults where not given)"
    vehicle_text, kind = "", "quarter"
    if vehicle is not None and model != "quarter":
        from ..design.vehicle import vehicle_car
        from ..io import CONFIG_SIZE_LIMIT, read_text_limited

        vehicle_text = read_text_limited(vehicle, "vehicle file", limit=CONFIG_SIZE_LIMIT)
        kind = vehicle_car(vehicle_text, model or "file", str(vehicle))["model"]
        given_car = [o for o, v in (("--sprung-mass", sprung_mass), ("--unsprung-mass", unsprung_mass),
                     ("--tyre-stiffness", tyre_stiffness), ("--tyre-damping", tyre_damping),
                     ("--spring-stiffness", spring_stiffness)) if v is not None]  # fmt: skip
        if given_car:
            raise ParameterError(given_car[0], "given", f"not given with a {kind}-car --vehicle "
                                 "(its values come from the file; or use --corner front|rear)")  # fmt: skip
        source = f"{vehicle}, {kind} car"
    elif vehicle is not None:
        corner = corner or "front"
        car.update(_car_from_vehicle(vehicle, corner))
        source = f"{vehicle}, {corner} corner"
    given = {
        "sprung_mass": _quantity("--sprung-mass", sprung_mass, "mass", "kg"),
        "unsprung_mass": _quantity("--unsprung-mass", unsprung_mass, "mass", "kg"),
        "tyre_stiffness": _quantity("--tyre-stiffness", tyre_stiffness, "stiffness", "N/m"),
        "tyre_damping": _quantity("--tyre-damping", tyre_damping, "damping", "N s/m"),
        "stiffness": _quantity("--spring-stiffness", spring_stiffness, "stiffness", "N/m"),
    }
    car.update({k: v for k, v in given.items() if v is not None})
    devs = () if devices.strip() in ("", "none") else tuple(d.strip() for d in devices.split(","))
    if not 0.1 <= max_minutes <= 10_000:
        raise ParameterError("--max-minutes", max_minutes, "0.1 to 10000 minutes")
    st = DesignSettings(
        **car,
        road_class=road_class,
        speed=speed,
        **_budget(budget),
        objective=objective,
        limits=_limits(limit),
        max_inertance=_quantity("--max-inertance", max_inertance, "mass", "kg"),
        devices=devs,
        synthesize=synthesize,
        roads=roads,
        tune_roads=tune_roads,
        horizon=horizon,
        seed=seed,
        top=top,
        recheck=recheck,
        source=source,
        vehicle=vehicle_text,
        model=kind,
    ).check()
    check_out_folder(out)
    est = estimate(st, workers)
    from ..resources import check_memory

    check_memory(
        est["bytes"] / 8, what="design study", parameter="--workers/--horizon", value=workers
    )
    if est["seconds"] > max_minutes * 60:
        raise ParameterError(
            "--max-minutes",
            max_minutes,
            f"at least {est['seconds'] / 60:.1f} min: this study is estimated at "
            f"{est['seconds'] / 60:.1f} min ({est['layouts']} layouts, {est['candidates']} "
            "candidates); raise --max-minutes or lower --roads, --horizon, --recheck or the budget",
        )

    def say(text):
        if not quiet and not json_out:
            print(text, file=sys.stderr, flush=True)

    say(f"design: estimated {est['seconds']:.0f} s on {workers} workers")
    try:
        bars = not quiet and not json_out and sys.stderr.isatty()
        result = run_design(st, out, workers=workers, progress=bars, say=say)
    except SweepInterrupted as exc:
        raise Interrupted(str(exc)) from None
    import json

    from ..design.report import figures, render_html

    say("design: report figures")
    figs = figures(result)
    atomic_write_text(
        out / "design.json",
        json.dumps(result, indent=1, default=_jsonable, allow_nan=False),
        "--out",
    )
    atomic_write_text(out / "report.html", render_html(result, figs), "--out")
    if result["unread_stores"]:
        say(unread_note("design", out / "stores", result["unread_stores"]))
    if json_out:
        emit_json(result)
        return
    _print(result, out)


def _jsonable(x):
    import math

    if isinstance(x, float) and not math.isfinite(x):
        return None
    raise TypeError(type(x).__name__)


def _print(result: dict, out: Path) -> None:
    from rich.console import Console
    from rich.table import Table
    from rich.text import Text

    obj = result["objective"]
    t = Table(
        title=Text(
            f"Design ranking: {obj['name']} [{obj['unit']}], {obj['time_domain']}; gain vs "
            "the optimised k | c on the same roads (positive: better)"
        )
    )
    for col in ("rank", "candidate", f"{obj['name']} [{obj['unit']}]", "gain vs k | c [%]",
                "deflection [m RMS]", "limits"):  # fmt: skip
        t.add_column(col)
    for r in result["ranking"]:
        t.add_row(
            str(r["rank"]),
            Text(r["label"]),
            f"{r['expected']:.4g} ± {r['interval95']:.2g}",
            f"{r['gain_percent']:+.2f} ± {r['gain_interval95']:.2f}",
            f"{r['rms_deflection']:.4g}",
            "met" if r["limits_met"] else "exceeded",
        )
    con = Console()
    con.print(t)
    for q in result["requirements"]:
        con.print(Text(f"{q['device']} in {q['layout']}: {q.get('text') or q.get('reason')}"))
    for n in result["notes"]:
        con.print(Text(f"note: {n}"))
    con.print(
        Text(
            f"report: {out / 'report.html'}  JSON: {out / 'design.json'}  ({result['seconds']:.1f} s)"
        )
    )


def register(app: typer.Typer) -> None:
    app.command("design")(design_command)
