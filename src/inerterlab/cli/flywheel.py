"""``inerterlab flywheel``: inertia, slider law and equivalent mass of a flywheel."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ._common import atomic_savefig, emit_json, output_option, print_table


def flywheel_command(
    preset: Annotated[
        str,
        typer.Option(help="Flywheel preset: metal (Table 3.1), nylon (3.3), nylon-large (5.4)."),
    ] = "nylon",
    law: Annotated[
        str,
        typer.Option(
            help="Inertia law: published (3.6/3.25), geometry (3.1-3.5/3.19-3.24), thesis-literal."
        ),
    ] = "published",
    changing_ratio: Annotated[
        float | None,
        typer.Option(
            help="Variant with this changing ratio x in (0, 1), keeping I_min and l(omega)."
        ),
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON object (SI units).")
    ] = False,
    plot: Annotated[
        Path | None,
        output_option("Write a figure of inertia and slider position against speed."),
    ] = None,
) -> None:
    """Inertia [kg m^2], changing ratio, saturation speed [rad/s] and equivalent mass [kg].

    Example: inerterlab flywheel --preset nylon --json
    """
    from ..flywheels import flywheel
    from ..transmissions import TRANSMISSIONS, transmission

    fw = flywheel(preset, law=law, changing_ratio=changing_ratio)
    out = fw.summary()
    out["preset"] = preset
    out["law"] = law
    out["equivalent_mass"] = {
        name: [
            transmission(name).ratio ** 2 * fw.inertia_min,
            transmission(name).ratio ** 2 * fw.inertia_max,
        ]
        for name in TRANSMISSIONS
    }
    out["transmission_ratio"] = {name: transmission(name).ratio for name in TRANSMISSIONS}
    if plot is not None:
        from ..plotting import plot_flywheel

        fig = plot_flywheel(fw)
        atomic_savefig(fig, plot)
        out["plot"] = str(plot)
    if json_out:
        emit_json(out)
        return
    rows = [
        ("inertia_min [kg m^2]", f"{fw.inertia_min:.6g}"),
        ("inertia_max [kg m^2]", f"{fw.inertia_max:.6g}"),
        ("changing_ratio [%]", f"{100 * fw.changing_ratio:.3f}"),
        ("saturation_speed [rad/s]", f"{fw.saturation_speed:.4g}"),
        ("slider travel [m]", f"{fw.slider_min:.4g} .. {fw.slider_max:.4g}"),
    ]
    for name, (lo, hi) in out["equivalent_mass"].items():
        rows.append((f"equivalent mass, {name} [kg]", f"{lo:.5g} .. {hi:.5g}"))
    print_table(f"flywheel {preset} ({law} law)", rows)


def register(app: typer.Typer) -> None:
    app.command("flywheel")(flywheel_command)
