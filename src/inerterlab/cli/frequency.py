"""``inerterlab frequency-response``: steady-state response of the ch. 7 system (7.1)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import ParameterError
from ._common import atomic_savefig, atomic_write_text, emit_json, print_table


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


def frequency_response_command(
    method: Annotated[
        str, typer.Option(help="brute, shb, mhb, sihb (scan down and up) or continuation.")
    ] = "sihb",
    amplitude: Annotated[
        float, typer.Option(help="Base displacement amplitude B [m], X0 = B sin(2 pi f t).")
    ] = 0.01,
    fmin: Annotated[float, typer.Option(help="Lowest frequency [Hz].")] = 0.1,
    fmax: Annotated[float, typer.Option(help="Highest frequency [Hz].")] = 3.0,
    df: Annotated[float, typer.Option(help="Frequency step [Hz].")] = 0.05,
    harmonics: Annotated[
        int | None,
        typer.Option(help="Harmonics H (default: 1 for shb, 15 for sihb, 7 otherwise)."),
    ] = None,
    samples: Annotated[
        int | None, typer.Option(help="Time samples per period N (default from the aliasing rule).")
    ] = None,
    flywheel: Annotated[
        str, typer.Option(help="Flywheel preset: metal, nylon, nylon-large, or none (no inerter).")
    ] = "metal",
    law: Annotated[
        str, typer.Option(help="Inertia law: thesis (default), momentum, thesis-literal.")
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
    csv: Annotated[Path | None, typer.Option(help="Write one row per point to this CSV.")] = None,
    plot: Annotated[
        Path | None, typer.Option(help="Write amplitude against frequency to this figure.")
    ] = None,
) -> None:
    """Amplitude of X1 [m] (half peak-to-peak) against frequency [Hz] for the body on
    spring K = 90 kN/m, damper C = 5000 N s/m and flywheel inerter (r = 961.66 rad/m)
    over a moving base (thesis 7.1). Failed points are reported with converged=false and
    a null amplitude.

    Example: inerterlab frequency-response --method sihb --amplitude 0.03 --fmin 0.1
    --fmax 3 --df 0.05 --harmonics 15 --json
    """
    from ..frequency import chapter7_system, frequency_grid, frequency_response

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
    system = chapter7_system(amplitude, preset=flywheel, law=law)
    grid = frequency_grid(fmin, fmax, df) if method != "continuation" else None
    if grid is not None:
        _note_if_long(grid.size, method, harmonics, direction, not no_stability)
    fr = frequency_response(
        system,
        method,
        freq_hz=grid,
        fmin=fmin,
        fmax=fmax,
        harmonics=harmonics,
        n_samples=samples,
        direction=direction,
        stability=not no_stability,
    )
    out = fr.to_dict()
    out["settings"] = {
        k: v for k, v in fr.settings.items() if isinstance(v, str | int | float | bool)
    }
    out["amplitude_input_m"] = amplitude
    out["flywheel"] = flywheel
    out["law"] = law
    out["failed_points"] = int((~fr.converged).sum())
    if csv is not None:
        atomic_write_text(csv, fr.to_pandas().to_csv(index=False), option="--csv")
        out["csv"] = str(csv)
    if plot is not None:
        fig = fr.plot()
        fig.axes[0].set_title(f"B = {100 * amplitude:g} cm, {flywheel} flywheel, {law} law")
        atomic_savefig(fig, plot)
        out["plot"] = str(plot)
    if json_out:
        emit_json(out)
        return
    rows = []
    for d in dict.fromkeys(fr.direction.tolist()):
        if fr.branch(d).converged.any():
            pk = fr.resonance(d)
            rows.append(
                (f"resonance, scan {d} [Hz]", f"{pk['freq_hz']:.4f}"),
            )
            rows.append((f"peak amplitude, scan {d} [m]", f"{pk['amplitude_m']:.6g}"))
    rows.append(("points (failed)", f"{len(fr)} ({out['failed_points']})"))
    rows.append(("max relative residual", f"{fr.residual[fr.converged].max():.2e}"))
    print_table(f"frequency response, {method}, B = {amplitude:g} m", rows)


def register(app: typer.Typer) -> None:
    app.command("frequency-response")(frequency_response_command)
