"""Helpers shared by the command modules: JSON output, tables, atomic files."""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer

from ..errors import SEED_MAX, InerterlabError, ParameterError, check_seed
from ..io import atomic_path
from ..io import atomic_write_text as atomic_write_text


def _clean(obj: Any, where: str = "") -> Any:
    if isinstance(obj, dict):
        return {str(k): _clean(v, f"{where}.{k}" if where else str(k)) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v, f"{where}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist(), where)
    if isinstance(obj, np.generic):
        return _clean(obj.item(), where)
    if isinstance(obj, float) and not math.isfinite(obj):
        raise InerterlabError(
            f"result {where or 'value'} is {obj} (not a finite number): the computation "
            "left the range of floating point numbers for these inputs; nothing was printed"
        )
    return obj


def emit_json(obj: Any) -> None:
    """Print ``obj`` as one JSON object; refuses NaN and infinities."""
    sys.stdout.write(json.dumps(_clean(obj), allow_nan=False) + "\n")


def atomic_savefig(fig: Any, path: str | os.PathLike, option: str = "--plot") -> Path:
    """Save a matplotlib figure atomically (format from the suffix, PNG without one)."""
    suffix = Path(path).suffix.lstrip(".").lower() or "png"
    formats = fig.canvas.get_supported_filetypes()
    if suffix not in formats:
        raise ParameterError(
            option, str(path), "a figure file ending in ." + ", .".join(sorted(formats))
        )
    with atomic_path(path, suffix="." + suffix, option=option) as tmp:
        fig.savefig(tmp, format=suffix, dpi=120, bbox_inches="tight")
    return Path(path)


def unread_note(command: str, folder: Path, names: list[str]) -> str:
    """The line that names a study's stores it did not read (made with other settings or
    another version) and their size on disk, for the user to delete if they wish."""
    size = sum(
        f.stat().st_size for n in names for f in (Path(folder) / n).rglob("*") if f.is_file()
    )
    return (
        f"{command}: {len(names)} store{'s' if len(names) != 1 else ''} in {folder} "
        f"({size / 1e6:.1f} MB) not read by this study (made with other settings or "
        f"another version of inerterlab), left in place for you to delete: {', '.join(names)}"
    )


def print_table(title: str, rows: list[tuple[str, str]]) -> None:
    """Readable two-column table on standard output."""
    from rich.console import Console
    from rich.table import Table
    from rich.text import Text

    # plain Text, not console markup: "[kg]" and "[m/s^2]" are units, not style tags
    t = Table(title=Text(title))
    t.add_column("quantity")
    t.add_column("value", justify="right")
    for k, v in rows:
        t.add_row(Text(str(k)), Text(str(v)))
    Console().print(t)


def _seed_callback(ctx: Any, param: Any, value: Any) -> Any:
    if value is None:
        return value
    return check_seed(param.opts[0].lstrip("-"), value)


def output_file(ctx: Any, param: Any, value: Any) -> Any:
    """The check of every option that names a file to write, as the command line is
    read (before any work): not empty, not a directory, and in a folder that exists
    (a mistyped folder is refused, never made: :func:`inerterlab.io.output_target`)."""
    if value is None:
        return value
    from ..io import output_target

    output_target(value, param.opts[0])
    return value


def output_option(help_text: str, *names: str) -> Any:
    """The one definition of every option that names a file to write: checked by
    :func:`output_file` as the command line is read."""
    import typer

    return typer.Option(*names, help=help_text, callback=output_file)


def seed_option(help_text: str, *names: str) -> Any:
    """The one definition of every random seed option: an integer 0 ... 2**32 - 1."""
    import typer

    return typer.Option(*names, help=f"{help_text} (0-{SEED_MAX})", callback=_seed_callback)


def parse_float(name: str, text: str) -> float:
    """Parse a CLI number, raising a ParameterError naming the option."""
    try:
        x = float(text)
    except (TypeError, ValueError):
        raise ParameterError(name, text, "a finite number") from None
    if not math.isfinite(x):
        raise ParameterError(name, text, "a finite number")
    return x


# ---------------------------------------------------------------------------------------
# the quarter car of every command: options or a vehicle file

#: the default quarter car of every command: the thesis car (4.16)
THESIS_CAR = {
    "sprung_mass": 370.0,
    "unsprung_mass": 25.0,
    "tyre_stiffness": 120_000.0,
    "tyre_damping": 1300.0,
}
_CAR_OPTS = {
    "sprung_mass": ("--sprung-mass", "kg"),
    "unsprung_mass": ("--unsprung-mass", "kg"),
    "tyre_stiffness": ("--tyre-stiffness", "N/m"),
    "tyre_damping": ("--tyre-damping", "N s/m"),
}


def _car_option(flag: str, symbol: str, unit: str, *more: str) -> Any:
    return typer.Option(
        flag,
        *more,
        help=f"{symbol} [{unit}] of the quarter car (default: the --vehicle file's corner, "
        f"else the thesis car's {THESIS_CAR[flag[2:].replace('-', '_')]:g}).",
    )


# the option types every command with a quarter car shares
CarSprungMass = Annotated[
    float | None, _car_option("--sprung-mass", "Sprung mass m_s", "kg", "--body-mass")
]
CarUnsprungMass = Annotated[float | None, _car_option("--unsprung-mass", "Unsprung mass m_u", "kg")]
CarTyreStiffness = Annotated[
    float | None, _car_option("--tyre-stiffness", "Tyre stiffness k_t", "N/m")
]
CarTyreDamping = Annotated[float | None, _car_option("--tyre-damping", "Tyre damping c_t", "N s/m")]
VehicleFile = Annotated[
    Path | None,
    typer.Option(
        "--vehicle",
        help="Vehicle TOML file (docs/guide/vehicles.md): its quarter car, one wheel of "
        "--axle (that wheel's share of the sprung mass, its unsprung mass and tyre; "
        "the strut's static stiffness is the main spring k). Car options given as "
        "well override the file's values.",
    ),
]
Axle = Annotated[str, typer.Option("--axle", help="front or rear: the wheel of --vehicle.")]


class QuarterCar(dict):
    """The quarter car chosen by :func:`car_options`: a dict of ``sprung_mass``,
    ``unsprung_mass``, ``tyre_stiffness``, ``tyre_damping`` (the keywords of every
    quarter-car function) with ``source`` (one line saying where the values come from)
    and ``spring``, ``damping`` (the vehicle strut's static stiffness [N/m] and damping
    [N s/m]; None without a vehicle file) as attributes."""

    source: str = "thesis car (4.16)"
    spring: float | None = None
    damping: float | None = None

    def describe(self) -> str:
        """One line: where the car comes from and its four values with units."""
        vals = ", ".join(f"{k} {self[k]:g} {_CAR_OPTS[k][1]}" for k in _CAR_OPTS)
        return f"quarter car: {self.source} ({vals})"


def vehicle_quarter_car(path, axle: str = "front") -> dict:
    """The quarter car of one wheel of a vehicle file (:mod:`inerterlab.vehicles.config`).

    Full car: the wheel's static share of the sprung mass, m b / (2 (a + b)) at the front
    and m a / (2 (a + b)) at the rear (a, b the distances of the centre of gravity to the
    axles), the wheel's unsprung mass, tyre and strut. Half car (an axle lumps both
    wheels): half of the axle's share and of its unsprung mass, tyre and strut, so a wheel
    of either model gives the same quarter car. Returns the four car keywords and
    ``spring``/``damping`` of the strut (static stiffness, damping at rest)."""
    from ..errors import check_choice
    from ..vehicles.config import load_vehicle
    from ..vehicles.parameters import FullCar

    check_choice("--axle", axle, ("front", "rear"))
    v = load_vehicle(path)
    corner = getattr(v, axle)
    a, b = v.cg_to_front, v.cg_to_rear
    share = v.sprung_mass * (b if axle == "front" else a) / (a + b)
    per = 1.0 if isinstance(v, FullCar) else 0.5  # a half car's axle is two wheels
    strut = corner.strut
    return {
        "sprung_mass": share / 2.0,
        "unsprung_mass": corner.unsprung_mass * per,
        "tyre_stiffness": corner.tyre.stiffness * per,
        "tyre_damping": corner.tyre.damping * per,
        "spring": float(strut.static_stiffness()) * per,
        "damping": float(strut.mck()[1]) * per,
    }


def car_options(
    sprung_mass: float | None = None,
    unsprung_mass: float | None = None,
    tyre_stiffness: float | None = None,
    tyre_damping: float | None = None,
    vehicle=None,
    axle: str = "front",
) -> QuarterCar:
    """The quarter car of a command from its car options (the one rule of every command):
    the thesis car (4.16), or the wheel ``axle`` of the vehicle file ``vehicle``
    (:func:`vehicle_quarter_car`), with each option given explicitly in place of the
    default's or the file's value. Values are checked (positive, physical range) with
    the option named."""
    from ..errors import ParameterError, check_nonnegative, check_physical, check_positive

    given = {
        "sprung_mass": sprung_mass,
        "unsprung_mass": unsprung_mass,
        "tyre_stiffness": tyre_stiffness,
        "tyre_damping": tyre_damping,
    }
    out = QuarterCar(THESIS_CAR)
    if vehicle is not None:
        vals = vehicle_quarter_car(vehicle, axle)
        out.update({k: vals[k] for k in THESIS_CAR})
        out.spring = vals["spring"]
        out.damping = vals["damping"]
        out.source = f"{Path(vehicle).name}, one {axle} wheel"
    elif axle != "front":
        raise ParameterError("--axle", axle, "no value without --vehicle")
    changed = [k for k, v in given.items() if v is not None]
    for k in changed:
        flag, unit = _CAR_OPTS[k]
        v = given[k]
        if k == "tyre_damping":
            check_nonnegative(flag, v, unit)
        else:
            check_positive(flag, v, unit)
        quantity = {"kg": "mass", "N/m": "stiffness", "N s/m": "damping"}[unit]
        check_physical(flag, v, quantity, zero=k == "tyre_damping")
        out[k] = float(v)
    if changed:
        opts = ", ".join(_CAR_OPTS[k][0] for k in changed)
        out.source = f"{out.source} with {opts}" if vehicle is not None else f"options {opts}"
        if vehicle is None and len(changed) < len(given):
            out.source += ", the rest from the thesis car (4.16)"
    return out
