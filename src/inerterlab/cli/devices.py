"""``inerterlab device-force``: force of a real device for a prescribed motion, the
device running as its network of elements on the model core's rig."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ._common import atomic_write_text, emit_json, output_option, parse_float, print_table


def _opt_float(name: str, text: str | None, *, positive: bool = False, nonneg: bool = False):
    if text is None:
        return None
    from ..errors import ParameterError

    x = parse_float(name, text)
    if positive and x <= 0:
        raise ParameterError(name, text, "a finite number > 0")
    if nonneg and x < 0:
        raise ParameterError(name, text, "a finite number >= 0")
    return x


def device_force_command(
    device: Annotated[
        str, typer.Option(help="hydraulic (3.15), screw (3.38) or rectifier (5.3).")
    ] = "hydraulic",
    flywheel: Annotated[
        str | None,
        typer.Option(help="Flywheel preset (default: metal, nylon, nylon-large by device)."),
    ] = None,
    law: Annotated[
        str, typer.Option(help="Force law: thesis, momentum or slider-dynamics.")
    ] = "thesis",
    signal: Annotated[
        str, typer.Option(help="sine (displacement), square (velocity) or triangle (displacement).")
    ] = "sine",
    freq: Annotated[str, typer.Option(help="Signal frequency [Hz].")] = "1.0",
    amplitude: Annotated[str | None, typer.Option(help="Displacement amplitude [m].")] = None,
    velocity_amplitude: Annotated[
        str | None, typer.Option(help="Velocity amplitude [m/s] (instead of --amplitude).")
    ] = None,
    duration: Annotated[str, typer.Option(help="Record length [s].")] = "2.0",
    sample_rate: Annotated[str, typer.Option(help="Output samples per second [Hz].")] = "1000",
    freewheel: Annotated[
        bool, typer.Option(help="Rectifier only: flywheel free-wheels when r|v_a| < omega.")
    ] = False,
    flywheel_drag: Annotated[
        str | None,
        typer.Option(help="Rectifier only: flywheel bearing drag c_d [N m s/rad] (default 0)."),
    ] = None,
    backlash: Annotated[
        str | None,
        typer.Option(help="Screw only: total backlash rho_1 + rho_2 [m], (3.36) (default 0)."),
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print t, force, equivalent_mass as JSON.")
    ] = False,
    csv: Annotated[
        Path | None,
        output_option("Write t, force, equivalent_mass to a CSV file."),
    ] = None,
) -> None:
    """Force [N] and equivalent mass [kg] of a real device against time [s].

    Example: inerterlab device-force --device hydraulic --flywheel metal --law thesis
    --signal sine --freq 1 --amplitude 0.01 --duration 2 --json
    """
    import numpy as np

    from ..devices import Motion, device_force, device_preset
    from ..errors import ParameterError, check_choice

    check_choice("device", device, ("hydraulic", "screw", "rectifier"))
    check_choice("signal", signal, ("sine", "square", "triangle"))
    f = _opt_float("freq", freq, positive=True)
    a = _opt_float("amplitude", amplitude, nonneg=True)
    va = _opt_float("velocity-amplitude", velocity_amplitude, nonneg=True)
    d = _opt_float("duration", duration, positive=True)
    fs = _opt_float("sample-rate", sample_rate, positive=True)
    if (a is None) == (va is None):
        raise ParameterError(
            "amplitude", amplitude, "exactly one of --amplitude [m] and --velocity-amplitude [m/s]"
        )
    if d * fs > 2_000_000:
        raise ParameterError(
            "duration", duration, f"at most {2_000_000 / fs:g} s at this sample rate"
        )
    changes = {"law": law}
    if freewheel:
        if device != "rectifier":
            raise ParameterError("freewheel", True, "only with --device rectifier")
        changes["freewheel"] = True
    drag = _opt_float("flywheel-drag", flywheel_drag, nonneg=True)
    if drag is not None:
        if device != "rectifier":
            raise ParameterError("flywheel-drag", flywheel_drag, "only with --device rectifier")
        changes["flywheel_drag"] = drag
    play = _opt_float("backlash", backlash, nonneg=True)
    if play is not None:
        if device != "screw":
            raise ParameterError("backlash", backlash, "only with --device screw")
        changes["backlash"] = play
    dev = device_preset(device, flywheel_preset=flywheel, **changes)
    maker = {"sine": Motion.sine, "square": Motion.square, "triangle": Motion.triangle}[signal]
    motion = maker(frequency=f, amplitude=a, velocity_amplitude=va)
    res = device_force(dev, motion, duration=d, sample_rate=fs)
    if csv is not None:
        rows = np.column_stack([res.t, res.force, res.equivalent_mass])
        lines = ["t,force,equivalent_mass"] + [f"{t:.9g},{F:.9g},{m:.9g}" for t, F, m in rows]
        atomic_write_text(csv, "\n".join(lines) + "\n", option="--csv")
    if json_out:
        emit_json({"t": res.t, "force": res.force, "equivalent_mass": res.equivalent_mass})
        return
    print_table(
        f"device-force: {device}, {dev.flywheel.name} flywheel, {law} law, {signal} {f:g} Hz",
        [
            ("samples", str(res.t.size)),
            ("force min [N]", f"{res.force.min():.6g}"),
            ("force max [N]", f"{res.force.max():.6g}"),
            ("force rms [N]", f"{float(np.sqrt(np.mean(res.force**2))):.6g}"),
            (
                "equivalent mass [kg]",
                f"{res.equivalent_mass.min():.5g} .. {res.equivalent_mass.max():.5g}",
            ),
            ("work done [J]", f"{res.work[-1]:.6g}"),
            ("energy dissipated [J]", f"{res.dissipated[-1]:.6g}"),
            ("free-wheeling [% of samples]", f"{100.0 * res.freewheeling.mean():.3g}"),
            ("csv", str(csv) if csv else "-"),
        ],
    )


def register(app: typer.Typer) -> None:
    app.command("device-force")(device_force_command)
