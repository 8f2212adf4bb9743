"""``inerterlab vehicle ...``: linear half car and full car on random roads."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from ._common import emit_json, output_option, print_table, seed_option

_HELP = """Linear half car and full car (SI units: RMS accelerations [m/s^2], pitch and
roll accelerations [rad/s^2], deflections [m], tyre loads [N]).

Example: inerterlab vehicle spectral --vehicle car.toml --road-class C --speed 20 --json
"""

_VEHICLE = typer.Option(
    "--vehicle", help="Vehicle TOML file (units on every value); default: the packaged example."
)
_JSON = typer.Option("--json", help="Print the result as one JSON object.")
_FIXED_STEP = typer.Option(
    help="Classical Runge-Kutta (RK4) steps of at most this length [s], in "
    "[dt/100, 0.1], ending on every road sample (the --dt: one step per sample), "
    "without error control; lift-off and the other switches still "
    "located. Default: adaptive."
)


def _parameters(path: Path | None, model: str):
    """The HalfCar or FullCar of the vehicle file (``model``: file, half or full)."""
    from ..errors import check_choice
    from ..vehicles.config import example_vehicle_path, load_vehicle

    check_choice("model", model, ("file", "half", "full"))
    params = load_vehicle(path if path is not None else example_vehicle_path())
    if model == "half" and hasattr(params, "half_car"):
        params = params.half_car()
    elif model == "full" and not hasattr(params, "half_car"):
        from ..errors import ParameterError

        raise ParameterError("model", model, "'half' or 'file' for a half-car file")
    return params


def _load(path: Path | None, model: str, linear: bool = True):
    """(parameters, vehicle): the core car about its static equilibrium
    (:func:`~inerterlab.vehicles.linear.linear_vehicle`) for the linear analyses; it
    refuses a car that does not rest."""
    from ..vehicles.linear import linear_vehicle

    params = _parameters(path, model)
    return params, linear_vehicle(params)


#: most frequencies of the spectral grid (a response matrix per frequency is kept)
MAX_POINTS = 200_000

#: fewest road samples a time simulation accepts (length / (speed x dt))
MIN_ROAD_SAMPLES = 64


def _check_samples(count: float, speed: float, dt: float, length: float | None) -> None:
    """Refuse a road of too few samples, naming the options that set the count."""
    from ..errors import ParameterError

    if not count >= MIN_ROAD_SAMPLES:
        opts = "speed, dt" + (", length" if length is not None else "")
        shown = f"speed={speed:g} m/s, dt={dt:g} s" + (
            f", length={length:g} m" if length is not None else ""
        )
        raise ParameterError(
            opts,
            shown,
            f"a road of at least {MIN_ROAD_SAMPLES} samples of speed x dt metres "
            f"(these give {count:.3g})",
        )


def _road(road_class: str | None, gd_n0: str | None, coherence: str):
    from ..errors import ParameterError
    from ..vehicles.roads import RoadSpectrum, road_spectrum
    from ._common import parse_float

    coh: str | float = coherence
    if coherence not in ("isotropic", "identical", "independent"):
        coh = parse_float("coherence", coherence)
    if gd_n0 is not None:
        if road_class is not None:
            raise ParameterError("gd-n0", gd_n0, "either --road-class or --gd-n0, not both")
        return RoadSpectrum(gd_n0=parse_float("gd-n0", gd_n0), coherence=coh)
    return road_spectrum(road_class or "C", coherence=coh)


def _fmt(x: float) -> str:
    return f"{x:.4g}"


def _table(title: str, rows) -> None:
    """print_table (plain text: unit brackets are printed as they are)."""
    print_table(title, rows)


def spectral_command(
    vehicle: Annotated[Path | None, _VEHICLE] = None,
    model: Annotated[
        str, typer.Option(help="file (as the file says), half (lump each axle) or full.")
    ] = "file",
    road_class: Annotated[
        str | None, typer.Option(help="ISO 8608 class A-H (geometric mean Gd(n0)); default C.")
    ] = None,
    gd_n0: Annotated[
        str | None, typer.Option("--gd-n0", help="Gd(n0) [m^3] instead of a class.")
    ] = None,
    speed: Annotated[float, typer.Option(help="Speed V [m/s].")] = 20.0,
    coherence: Annotated[
        str,
        typer.Option(help="Left/right tracks: isotropic, identical, independent or a number 0-1."),
    ] = "isotropic",
    points: Annotated[int, typer.Option(help="Frequencies of the log grid [-].")] = 4000,
    json_out: Annotated[bool, _JSON] = False,
    plot: Annotated[
        Path | None,
        output_option("Figure (.png/.pdf): the PSDs of the seat (or bounce) acceleration "
                      "with and without Wk, of the pitch acceleration and of each corner's "
                      "suspension deflection."),
    ] = None,
) -> None:  # fmt: skip
    """RMS of every output on an ISO 8608 road by the spectral method (no time simulation).

    Road band 0.01-10 cycle/m, waviness 2; rear wheels delayed by wheelbase/V.
    Also prints the Wk-weighted seat acceleration [m/s^2] and, per corner, the
    static tyre load [N] and the probability that the Gaussian dynamic load exceeds it.

    Example: inerterlab vehicle spectral --vehicle car.toml --road-class C --speed 20 --json
    """
    from ..errors import check_positive
    from ..vehicles.spectral import spectral_response

    params, veh = _load(vehicle, model, linear=True)
    road = _road(road_class, gd_n0, coherence)
    check_positive("speed", speed, "m/s")
    if not 16 <= points <= MAX_POINTS:
        from ..errors import ParameterError

        raise ParameterError("points", points, f"an integer in [16, {MAX_POINTS}]")
    res = spectral_response(veh, road, speed, points=points)
    out = res.to_dict()
    out.update(model=veh.kind, gd_n0=road.gd_n0, coherence=road.coherence)
    if plot is not None:
        from ._common import atomic_savefig

        atomic_savefig(_spectral_figure(veh, res, road, speed), plot)
        out["plot"] = str(plot)
    if json_out:
        emit_json(out)
        return
    rows = [(f"{k} [{res.units[k]}]", _fmt(v)) for k, v in res.rms.items()]
    rows += [(f"{c}_static_load [N]", _fmt(res.static_load[c])) for c in veh.corners]
    rows += [(f"{c}_lift_off_probability [-]", f"{res.lift_off[c]:.3g}") for c in veh.corners]
    _table(f"{veh.kind} car, Gd(n0) = {road.gd_n0:.3g} m^3, V = {speed:g} m/s: RMS values", rows)


def _spectral_figure(veh, res, road, speed):
    """PSDs of the spectral method's outputs on log axes (one-sided, per Hz)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 4))
    ax1, ax2 = fig.subplots(1, 2)
    acc = "seat_acc" if "seat_acc" in res.psd else "bounce_acc"
    ax1.loglog(res.freq, res.psd[acc], label=f"{acc} [(m/s^2)^2/Hz]")
    ax1.loglog(res.freq, res.psd[f"{acc}_wk"], "--", label=f"{acc}, Wk weighted")
    ax1.loglog(res.freq, res.psd["pitch_acc"], ":", label="pitch_acc [(rad/s^2)^2/Hz]")
    for c in veh.corners:
        ax2.loglog(res.freq, res.psd[f"{c}_deflection"], label=f"{c} deflection [m^2/Hz]")
    for ax in (ax1, ax2):
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel("one-sided PSD")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"{veh.kind} car, Gd(n0) = {road.gd_n0:.3g} m^3, V = {speed:g} m/s "
                 "(spectral method, linear)")  # fmt: skip
    fig.tight_layout()
    return fig


def modes_command(
    vehicle: Annotated[Path | None, _VEHICLE] = None,
    model: Annotated[str, typer.Option(help="file, half or full (see spectral).")] = "file",
    json_out: Annotated[bool, _JSON] = False,
) -> None:
    """Modes of the linear car: undamped natural frequencies [Hz] (body and seat on
    rigid tyres, whole car), and from the eigenvalues lambda of the state space every
    damped mode: its damped frequency Im(lambda)/2pi [Hz], damping ratio
    -Re(lambda)/|lambda| [-] and undamped natural frequency |lambda|/2pi [Hz]; and the
    real (overdamped) modes with their decay rate -lambda [1/s] and time constant [s].

    A car with network struts that have internal nodes has no undamped mass-spring
    model: only its modes from the state space are printed.

    Example: inerterlab vehicle modes --vehicle car.toml
    """
    from ..vehicles.spectral import modes

    params, veh = _load(vehicle, model, linear=True)
    lin = veh.linearised  # gas springs, bump stops: their stiffness at rest
    what = "the car linearised about its static equilibrium" if lin else "the linear model"
    plain = veh.plain
    rigid = veh.natural_frequencies(rigid_tyres=True).tolist() if plain else None
    whole = veh.natural_frequencies(rigid_tyres=False).tolist() if plain else None
    osc, real = modes(veh)
    if json_out:
        emit_json(
            {
                "model": veh.kind,
                "linearised_about_equilibrium": lin,
                "rigid_tyres_hz": rigid,
                "whole_car_hz": whole,
                "damped_modes": [m.to_dict() for m in osc],
                "real_modes": [m.to_dict() for m in real],
            }
        )
        return
    if plain:
        if lin:
            print("gas springs and bump stops at their stiffness at rest (linearised):")
        print("undamped, rigid tyres [Hz]: " + ", ".join(f"{f:.3f}" for f in rigid))
        print("undamped, whole car   [Hz]: " + ", ".join(f"{f:.3f}" for f in whole))
    print(f"{veh.kind} car, modes of {what} (eigenvalues lambda of the state space):")
    print(f"  {'mode':>4}  {'Im(lambda)/2pi [Hz]':>19}  {'damping ratio [-]':>17}  {'|lambda|/2pi [Hz]':>17}")
    for i, m in enumerate(osc):
        print(f"  {i + 1:>4}  {m.damped_hz:>19.3f}  {m.damping_ratio:>17.3f}  {m.natural_hz:>17.3f}")
    if real:
        print("real (overdamped) modes:")
        print(f"  {'mode':>4}  {'decay rate -lambda [1/s]':>24}  {'time constant [s]':>17}")
        for i, m in enumerate(real):
            print(f"  {i + 1:>4}  {m.decay_rate:>24.4g}  {m.time_constant:>17.4g}")
    else:
        print("real (overdamped) modes: none")


def frequency_response_command(
    vehicle: Annotated[Path | None, _VEHICLE] = None,
    model: Annotated[str, typer.Option(help="file, half or full (see spectral).")] = "file",
    amplitude: Annotated[float, typer.Option(help="Road amplitude A [m], r = A sin(2 pi f t).")] = 0.01,
    tracks: Annotated[
        str, typer.Option(help="Full car: right track in-phase (heave) or anti-phase (roll).")
    ] = "in-phase",
    axles: Annotated[
        str | None,
        typer.Option(help="Rig without --speed: rear axle in-phase (heave) or anti-phase (pitch)."),
    ] = None,
    speed: Annotated[
        float | None,
        typer.Option(help="Drive at V [m/s]: the rear wheels a wheelbase behind (no --axles)."),
    ] = None,
    fmin: Annotated[float, typer.Option(help="Lowest frequency [Hz].")] = 0.5,
    fmax: Annotated[float, typer.Option(help="Highest frequency [Hz].")] = 25.0,
    points: Annotated[int, typer.Option(help="Frequencies, log spaced [-].")] = 200,
    method: Annotated[
        str,
        typer.Option(
            help="auto (linear car: state space; nonlinear corners: harmonic balance), "
            "linear or harmonic-balance."
        ),
    ] = "auto",
    harmonics: Annotated[
        int | None, typer.Option(help="Harmonics of the harmonic balance [-] (default 7).")
    ] = None,
    json_out: Annotated[bool, _JSON] = False,
    csv: Annotated[Path | None, output_option("Write one row per frequency to this CSV.")] = None,
    plot: Annotated[Path | None, output_option("Write the amplitudes to this figure.")] = None,
) -> None:
    """Heave [m], pitch [rad], roll [rad] and seat acceleration [m/s^2] amplitudes of the
    car on a sine road of amplitude A, and per unit road amplitude, over a log grid of
    frequencies (steady state).

    Front and rear move together on a rig (--axles in-phase, default), against each other
    (--axles anti-phase), or as on the road at --speed V (the rear wheels see the road
    wheelbase/V later). A linear car's response comes from its state space; a car with a
    nonlinear element at a corner (gas spring, bump stop, quadratic damper, adaptive
    inerter) from the harmonic balance of the whole car at this amplitude, its amplitude
    the half peak-to-peak of the steady response (--method harmonic-balance forces it,
    --method linear takes the linearisation about the static equilibrium). Friction is
    refused by the balance (use vehicle simulate). Prints each response's peak; --csv for
    every row.

    Example: inerterlab vehicle frequency-response --vehicle car.toml --tracks anti-phase --csv fr.csv
    """
    import numpy as np

    from ..errors import ParameterError, check_positive
    from ..vehicles.frequency import UNITS, frequency_response
    from ._common import atomic_savefig, atomic_write_text

    params = _parameters(vehicle, model)
    lo = check_positive("fmin", fmin, "Hz")
    hi = check_positive("fmax", fmax, "Hz")
    if not hi > lo:
        raise ParameterError("fmax", fmax, f"a frequency above fmin = {fmin:g} Hz")
    if not 2 <= points <= MAX_POINTS:
        raise ParameterError("points", points, f"an integer in [2, {MAX_POINTS}]")
    if harmonics is not None and not 1 <= harmonics <= 50:
        raise ParameterError("harmonics", harmonics, "an integer in [1, 50]")
    fr = frequency_response(
        params, np.geomspace(lo, hi, points), amplitude=amplitude, tracks=tracks, axles=axles,
        speed=speed, method=method, harmonics=harmonics,
    )  # fmt: skip
    out = fr.to_dict()
    if csv is not None:
        atomic_write_text(csv, fr.to_frame().to_csv(index=False), option="--csv")
        out["csv"] = str(csv)
    if plot is not None:
        fig = fr.plot()
        atomic_savefig(fig, plot)
        out["plot"] = str(plot)
    if json_out:
        emit_json(out)
        return
    rows = []
    for k, (f, a) in fr.peaks().items():
        unit = out["amplitude_units"][k]
        rows.append((f"peak {k} amplitude [{unit}]", f"{a:.4g} at {f:.3f} Hz"))
        rows.append((f"  per road amplitude [{UNITS[k]}]", f"{a / fr.amplitude:.4g}"))
    if fr.failed:
        rows.append(("frequencies where the balance failed [-]", str(fr.failed)))
    _table(f"frequency response ({fr.model}): {fr.input_label()}", rows)
    for key in ("csv", "plot"):
        if key in out:
            print(f"wrote {out[key]}")


def road_command(
    profile: Annotated[
        Path,
        typer.Option(
            help="Column file (a header 'distance [m],elevation [mm]', units m, cm, mm, km "
            "for the distance and m, cm, mm for the elevation; evenly spaced) or OpenCRG file "
            "(.crg, the reference line v = 0)."
        ),
    ],
    lateral: Annotated[
        float,
        typer.Option(
            help="OpenCRG only: lateral position v of the profile [m], left positive, "
            "inside the file's lateral range."
        ),
    ] = 0.0,
    track: Annotated[
        str | None,
        typer.Option(help="Column file with a left and a right track only: left or right."),
    ] = None,
    free_waviness: Annotated[
        bool, typer.Option(help="Fit the waviness w too (ISO 8608 class uses w = 2).")
    ] = False,
    json_out: Annotated[bool, _JSON] = False,
) -> None:
    """ISO 8608 class (fitted Gd(n0) [m^3]) and IRI [m/km] of a measured profile.

    Example: inerterlab vehicle road --profile profile.csv --json
    """
    from ..vehicles.roads import fit_iso8608, iri, read_profile_csv

    if profile.suffix.lower() == ".crg":
        from ..vehicles.crg import read_crg_profile

        if track is not None:
            from ..errors import ParameterError

            raise ParameterError("track", track, "no --track for an OpenCRG file (use --lateral)")
        x, z = read_crg_profile(profile, lateral=lateral)
    else:
        if lateral != 0.0:
            from ..errors import ParameterError

            raise ParameterError("lateral", lateral, "0 for a column file (OpenCRG only)")
        x, z = read_profile_csv(profile, track=track)
    fit = fit_iso8608(x, z, waviness=None if free_waviness else 2.0)
    out = {**fit, "iri_m_per_km": iri(x, z), "length_m": float(x[-1] - x[0])}
    if json_out:
        emit_json(out)
        return
    _table(
        f"road profile {profile.name}",
        [
            ("Gd(n0) [m^3]", f"{out['gd_n0']:.3g}"),
            ("waviness [-]", f"{out['waviness']:.3g}"),
            ("ISO 8608 class", out["road_class"]),
            ("IRI [m/km]", f"{out['iri_m_per_km']:.3g}"),
            ("length [m]", f"{out['length_m']:.6g}"),
        ],
    )


def generate_command(
    output: Annotated[
        Path,
        output_option(
            "File to write: .csv (distance [m], left [m], right [m]) or .crg (OpenCRG)."
        ),
    ],
    road_class: Annotated[str, typer.Option(help="ISO 8608 class A-H.")] = "C",
    length: Annotated[float, typer.Option(help="Profile length [m].")] = 1000.0,
    step: Annotated[float, typer.Option(help="Sample spacing [m].")] = 0.05,
    track: Annotated[float, typer.Option(help="Distance between the tracks [m].")] = 1.5,
    seed: Annotated[int, seed_option("Random seed [-].")] = 0,
) -> None:
    """Write a left/right pair of ISO 8608 tracks with isotropic coherence (CSV or OpenCRG).

    Example: inerterlab vehicle generate --output road.csv --road-class D --length 500
    """
    import numpy as np

    from ..errors import ParameterError
    from ..vehicles.roads import generate_tracks, road_spectrum
    from ._common import atomic_write_text

    kind = output.suffix.lower()
    if kind not in (".csv", ".crg") and str(output) != "-":
        raise ParameterError(
            "output",
            str(output),
            "a file name ending in .csv (columns distance, left, right [m]) or .crg (OpenCRG)",
        )
    x, zl, zr = generate_tracks(
        road_spectrum(road_class), length=length, step=step, track=track, seed=seed
    )
    if kind == ".crg":
        from ..io import atomic_path
        from ..vehicles.crg import write_crg_tracks

        with atomic_path(output, suffix=".crg", option="--output") as tmp:
            write_crg_tracks(tmp, x, zl, zr, track, comment=f"ISO 8608 class {road_class}")
    else:
        rows = "\n".join(f"{a:.6f},{b:.9e},{c:.9e}" for a, b, c in zip(x, zl, zr, strict=True))
        atomic_write_text(output, "distance [m],left [m],right [m]\n" + rows + "\n", "--output")
    print(f"wrote {output} ({x.size} samples, rms left {np.std(zl) * 1e3:.3g} mm)")


def simulate_command(
    vehicle: Annotated[Path | None, _VEHICLE] = None,
    model: Annotated[str, typer.Option(help="file, half or full (see spectral).")] = "file",
    road_class: Annotated[str, typer.Option(help="ISO 8608 class A-H.")] = "C",
    road_file: Annotated[
        Path | None,
        typer.Option(
            help="Drive over this road instead: OpenCRG (.crg, tracks at +/- track/2) or a "
            "column file with a header 'distance [m],left [mm],right [mm]' (units m, cm, mm; "
            "right optional)."
        ),
    ] = None,
    speed: Annotated[float, typer.Option(help="Speed V [m/s].")] = 20.0,
    length: Annotated[float, typer.Option(help="Generated road length [m].")] = 2000.0,
    dt: Annotated[float, typer.Option(help="Road sample interval [s].")] = 0.002,
    seed: Annotated[int, seed_option("Random seed of the road [-].")] = 0,
    lift_off: Annotated[
        bool,
        typer.Option(
            "--lift-off",
            help="Tyres cannot pull: contact force max(0, ...) (lift-off and landing as events).",
        ),
    ] = False,
    rebound: Annotated[
        float, typer.Option(help="Damping factor while a strut extends [-] (1: linear).")
    ] = 1.0,
    compression: Annotated[
        float, typer.Option(help="Damping factor while a strut shortens [-] (1: linear).")
    ] = 1.0,
    fixed_step: Annotated[float | None, _FIXED_STEP] = None,
    json_out: Annotated[bool, _JSON] = False,
) -> None:
    """Time simulation on a generated or a given road (a check on the spectral RMS values).

    Prints the RMS of every output, the seat's (or body's) ISO 2631-1 Wk-weighted RMS
    [m/s^2], VDV [m/s^1.75] and crest factor [-]. The first 5 s (start-up) are left out
    of every number. The car is the model core's (adaptive Dormand-Prince, rtol 1e-6, or
    RK4 steps with --fixed-step);
    the road is its samples joined by straight lines (a generated road's series at the
    wheels, a road file's profile read at the wheels); the Wk-weighted RMS and the VDV
    are integrated beside the motion. Beside each value on a generated road: the
    spectral RMS of the linear car, or, when the car is nonlinear (--lift-off,
    --rebound/--compression, adaptive inerters), the RMS of its Gaussian-equivalent
    (statistical) linearisation, labelled "linearised". Per corner: with --lift-off the
    fraction of time the tyre is off the road [-]; without it, the fraction of time
    the linear tyre's contact force is negative (it would lift off) [-], beside the
    Gaussian probability of that. A device at a corner has no linear comparison.

    Example: inerterlab vehicle simulate --vehicle car.toml --road-class C --speed 20
    """
    import numpy as np

    from ..errors import ParameterError, check_positive
    from ..systems.vehicle import _stations
    from ..vehicles.linear import OUTPUT_UNITS
    from ..vehicles.roads import read_track_pair, road_spectrum
    from ..vehicles.simulation import simulate_vehicle
    from ..vehicles.spectral import generated_road, road_inputs, spectral_response

    params = _parameters(vehicle, model)
    v = check_positive("speed", speed, "m/s")
    h = check_positive("dt", dt, "s")
    if fixed_step is not None and not h / 100.0 <= fixed_step <= 0.1:
        raise ParameterError(
            "fixed-step", fixed_step, f"a step in [{h / 100:g}, 0.1] s (dt/100 on)"
        )
    full = hasattr(params, "front_track")
    width = 0.5 * (params.front_track + params.rear_track) if full else 1.5
    struts = [st[3].strut for st in _stations(params)[1]]
    adaptive = any(getattr(st, "adaptive", None) is not None for st in struts)
    devices = any(getattr(st, "device", None) is not None for st in struts)
    nonlinear = lift_off or rebound != 1.0 or compression != 1.0 or devices or adaptive
    if road_file is None:
        check_positive("length", length, "m")
        # the states and every node and element output at each sample (a full car with
        # its comfort observers: about 40 states and 100 outputs): at most 1e6 samples
        if length / (v * h) > 1_000_000:
            raise ParameterError(
                "length", length, f"at most {1e6 * v * h:g} m at this speed and dt"
            )
        _check_samples(length / (v * h), v, h, length)
        road = road_spectrum(road_class)
        r = generated_road(params, road, length=length, speed=v, dt=h, track=width, seed=seed)
    else:
        road = None
        # the file's own samples: the wheels are read off them once, by linear interpolation
        x, zl, zr = read_track_pair(road_file, width)
        if (x[-1] - x[0]) / (v * h) > 5_000_000:
            raise ParameterError("dt", dt, "a step giving at most 5e6 samples of the road")
        _check_samples(x.size, v, h, None)

        class _Axles:  # road_inputs reads the wheelbase and the kind
            parameters = params
            kind = "full" if full else "half"

        r = road_inputs(_Axles, x, zl, zr, v, h, periodic=False)
        _check_samples(r.shape[0], v, h, None)  # the wheels' samples over the file's length
    nt = r.shape[0]
    run = simulate_vehicle(params, r, h, lift_off=lift_off, rebound=rebound,
                           compression=compression, warmup=5.0, fixed_step=fixed_step)  # fmt: skip
    y = run.outputs
    keep = slice(min(int(5.0 / h), nt // 2), None)
    rms = {k: math.sqrt(float((s[keep] ** 2).mean())) for k, s in y.items()}
    acc = run.comfort["signal"]
    out = {
        "rms": rms,
        f"{acc}_wk": run.comfort["wk_rms"],
        "vdv": run.comfort["vdv"],
        "crest_factor": run.comfort["crest_factor"],
        "duration_s": run.comfort["duration"],
        "model": "nonlinear" if nonlinear else "linear",
    }
    # contact force = static load + dynamic tyre load; 0 while a one-sided tyre is off
    frac = {c: float(np.mean(f[keep] <= 0.0)) for c, f in run.contact_force.items()}
    frac_key = "lift_off_fraction" if lift_off else "negative_contact_fraction"
    out[frac_key] = frac
    ref, ref_name, gauss = None, None, None
    if road is not None and not devices:
        if nonlinear:
            from ..vehicles.stochastic import statistical_linearisation

            lin = statistical_linearisation(
                vehicle="" if vehicle is None else str(vehicle),
                model="full" if full else "half",
                road_class=road_class,
                speed=v,
                rebound=rebound,
                compression=compression,
            )
            ref, ref_name, gauss = lin.rms, "linearised", lin.lift_off
            out["linearisation_converged"] = lin.converged
        else:
            from ..vehicles.linear import linear_vehicle

            spec = spectral_response(linear_vehicle(params), road, v)
            ref, ref_name, gauss = spec.rms, "spectral", spec.lift_off
        out[f"{ref_name}_rms"] = {k: ref[k] for k in rms}
        out[f"{acc}_wk_{ref_name}"] = ref[f"{acc}_wk"]
        out["lift_off_probability_gaussian"] = gauss
    if json_out:
        emit_json(out)
        return

    label = ref_name
    if out.get("linearisation_converged") is False:
        label = "linearised, NOT converged"

    def cell(k, value):
        return f"{value:.4g}" + (f" ({label} {ref[k]:.4g})" if ref else "")

    def unit(k):
        return next(u for q, u in OUTPUT_UNITS.items() if k == q or k.endswith("_" + q))

    rows = [(f"{k} [{unit(k)}]", cell(k, rms[k])) for k in rms]
    rows += [
        (f"{acc}_wk [m/s^2]", cell(f"{acc}_wk", out[f"{acc}_wk"])),
        ("VDV [m/s^1.75]", f"{out['vdv']:.4g}"),
        ("crest factor [-]", f"{out['crest_factor']:.3g}"),
    ]
    for c, val in frac.items():
        text = f"{val:.3g}" + (f" (Gaussian {gauss[c]:.3g})" if gauss else "")
        rows.append((f"{c}_{frac_key} [-]", text))
    what = "time off the road" if lift_off else "negative contact: time the linear tyre pulls"
    _table(
        f"{out['model']} time simulation, {out['duration_s']:.0f} s after the start-up "
        f"(fractions: {what})",
        rows,
    )


def monte_carlo_command(
    vehicle: Annotated[Path | None, _VEHICLE] = None,
    model: Annotated[str, typer.Option(help="half or full.")] = "full",
    road_class: Annotated[str, typer.Option(help="ISO 8608 class A-H.")] = "C",
    speed: Annotated[float, typer.Option(help="Speed V [m/s].")] = 20.0,
    length: Annotated[float, typer.Option(help="Road length per realisation [m].")] = 1200.0,
    dt: Annotated[float, typer.Option(help="Road sample interval [s].")] = 0.002,
    rtol: Annotated[float, typer.Option(help="Relative tolerance of the integration [-].")] = 1e-6,
    fixed_step: Annotated[float | None, _FIXED_STEP] = None,
    warmup: Annotated[float, typer.Option(help="Start-up left out of each road [s].")] = 5.0,
    roads: Annotated[int, typer.Option(help="Number of road realisations [-].")] = 100,
    first_seed: Annotated[int, seed_option("Seed of the first road [-].")] = 0,
    lift_off: Annotated[
        bool, typer.Option("--lift-off/--no-lift-off", help="One-sided tyre contact.")
    ] = True,
    rebound: Annotated[float, typer.Option(help="Damping factor while extending [-].")] = 1.0,
    compression: Annotated[float, typer.Option(help="Damping factor while shortening [-].")] = 1.0,
    friction: Annotated[float, typer.Option(help="Strut Coulomb friction [N].")] = 0.0,
    friction_velocity: Annotated[
        float, typer.Option(help="Friction regularisation velocity [m/s].")
    ] = 0.01,
    out: Annotated[
        Path | None,
        typer.Option("--out", help="Zarr store of the per-road results; a rerun resumes it."),
    ] = None,
    workers: Annotated[int | None, typer.Option(help="Worker processes.")] = None,
    backend: Annotated[
        str, typer.Option(help="serial, processes or dask (the sweep backends).")
    ] = "processes",
    json_out: Annotated[bool, _JSON] = False,
    quiet: Annotated[bool, typer.Option(help="No progress bar.")] = False,
) -> None:
    """Monte Carlo over ISO 8608 road realisations of the nonlinear vehicle (lift-off,
    asymmetric dampers, strut friction), with 95 % intervals, against the statistical
    (Gaussian equivalent) linearisation of the same vehicle.

    Prints per output the Monte Carlo RMS [SI units] with its 95 % interval, the
    linearisation's RMS and its error in percent (not for a vehicle with a device at a
    corner, which has no Gaussian equivalent here); per corner the fraction of time off
    the road and the probability that a road lifts the tyre at least once, beside the
    one-sided Gaussian probability of the linearised contact force going negative. With
    --no-lift-off the tyres are linear: the fraction of time each pulls (negative
    contact force) instead, and no lift-off probability.

    Example: inerterlab vehicle monte-carlo --roads 1000 --workers 2 --out mc.zarr
    """
    from ..errors import Interrupted, ParameterError, check_positive, check_seed
    from ..studies import SweepInterrupted
    from ..studies.backends import check_workers
    from ..vehicles.stochastic import monte_carlo, statistical_linearisation

    if workers is not None:
        check_workers("--workers", workers)
    v = check_positive("speed", speed, "m/s")
    h = check_positive("dt", dt, "s")
    if not 2 <= roads <= 1_000_000:
        raise ParameterError("roads", roads, "an integer in [2, 1000000]")
    check_seed("first-seed", first_seed, roads)  # every road's seed fits
    check_positive("length", length, "m")
    if not 1e-12 <= rtol <= 1e-2:
        raise ParameterError("rtol", rtol, "a relative tolerance in [1e-12, 1e-2]")
    if fixed_step is not None and not h / 100.0 <= fixed_step <= 0.1:
        raise ParameterError(
            "fixed-step", fixed_step, f"a step in [{h / 100:g}, 0.1] s (dt/100 on)"
        )
    # the states and every node and element output at each sample, per worker (a full
    # car with its comfort observers: about 40 states and 100 outputs): at most 1e6
    if length / (v * h) > 1_000_000:
        raise ParameterError("length", length, f"at most {1e6 * v * h:g} m at this speed and dt")
    _check_samples(length / (v * h), v, h, length)
    path = "" if vehicle is None else str(vehicle)
    from ..systems.vehicle import _stations

    params = _parameters(vehicle, model)
    devices = any(st[3].strut.device is not None for st in _stations(params)[1]
                  if hasattr(st[3].strut, "device"))  # fmt: skip
    settings = dict(
        road_class=road_class,
        speed=v,
        length=length,
        dt=h,
        rtol=rtol,
        fixed_step=fixed_step or 0.0,
        warmup=warmup,
        lift_off="on" if lift_off else "off",
        rebound=rebound,
        compression=compression,
        friction=friction,
        friction_velocity=friction_velocity,
    )
    try:
        mc = monte_carlo(
            vehicle=path,
            model=model,
            roads=roads,
            first_seed=first_seed,
            store=out,
            backend=backend,
            workers=workers,
            progress=not quiet and not json_out,
            **settings,
        )
    except SweepInterrupted as exc:
        raise Interrupted(str(exc)) from None
    result = mc.to_dict()
    lin = None
    if devices:
        # no Gaussian equivalent of a device's internal dynamics: Monte Carlo alone
        result["linearised"] = None
    else:
        lin = statistical_linearisation(
            vehicle=path,
            model=model,
            road_class=road_class,
            speed=v,
            rebound=rebound,
            compression=compression,
            friction=friction,
            friction_velocity=friction_velocity,
        )
        result["linearised"] = {
            "rms": {k: lin.rms[k] for k in mc.rms},
            "error_percent": {k: 100.0 * (lin.rms[k] / mc.rms[k][0] - 1.0) for k in mc.rms},
            "damping": lin.damping,
            "lift_off_probability_gaussian": lin.lift_off,
            "converged": lin.converged,
        }
    if json_out:
        emit_json(result)
        return
    units = {"bounce_acc": "m/s^2", "pitch_acc": "rad/s^2", "seat_acc_wk": "m/s^2"}
    rows = []
    for k, (val, (lo, hi)) in mc.rms.items():
        unit = units.get(k, "m" if k.endswith("deflection") else "N")
        cell = f"{val:.4g} ({lo:.4g}-{hi:.4g})"
        if lin is not None:
            err = result["linearised"]["error_percent"][k]
            cell += f"; linearised {lin.rms[k]:.4g} ({err:+.1f} %)"
        rows.append((f"{k} [{unit}]", cell))
    for c, (val, (lo, hi)) in mc.lift_off_fraction.items():
        gauss = "" if lin is None else f"; Gaussian {lin.lift_off[c]:.3g}"
        if mc.lift_off:
            p, (plo, phi) = mc.lift_off_probability[c]
            rows.append(
                (
                    f"{c} lift-off [-]",
                    f"time {val:.3g} ({lo:.3g}-{hi:.3g}){gauss}; "
                    f"roads {p:.3g} ({plo:.3g}-{phi:.3g})",
                )
            )
        else:
            rows.append(
                (f"{c}_negative_contact_fraction [-]", f"{val:.3g} ({lo:.3g}-{hi:.3g}){gauss}")
            )
    title = f"Monte Carlo over {mc.realisations} roads, 95 % intervals"
    if not mc.lift_off:
        title += " (linear tyres: negative contact = time the tyre pulls)"
    _table(title, rows)


def optimize_command(
    vehicle: Annotated[Path | None, _VEHICLE] = None,
    objective: Annotated[
        str, typer.Option(help="Metric to minimise: comfort_wk, bounce_acc, front_deflection, ...")
    ] = "comfort_wk",
    parameter: Annotated[
        list[str] | None,
        typer.Option(
            help="Design parameter (repeatable): front_/rear_ + stiffness, damping, inertance, "
            "or + an element name of a network strut (front_b); default the dampers of both "
            "axles (front_damping, or front_c... of a network)."
        ),
    ] = None,
    bound: Annotated[
        list[str] | None, typer.Option(help="Bounds name=low:high (repeatable), SI units.")
    ] = None,
    limit: Annotated[
        list[str] | None,
        typer.Option(help="Upper limit metric=value (repeatable), e.g. front_deflection=0.01."),
    ] = None,
    road_class: Annotated[str, typer.Option(help="ISO 8608 class A-H.")] = "C",
    speed: Annotated[float, typer.Option(help="Speed V [m/s].")] = 20.0,
    json_out: Annotated[bool, _JSON] = False,
) -> None:
    """Strut parameters that minimise one RMS value of the linear vehicle on an ISO 8608
    road (spectral method), within bounds and under upper limits on others.

    Example: inerterlab vehicle optimize --parameter rear_damping --limit rear_deflection=0.01
    """
    from ..errors import ParameterError
    from ..vehicles.design import optimize_vehicle
    from ._common import parse_float

    def pairs(items, what):
        out = {}
        for it in items or []:
            if "=" not in it:
                raise ParameterError(what, it, "name=value")
            k, v = it.split("=", 1)
            if k.strip() in out:
                raise ParameterError(what, it, f"each name once ({k.strip()} was given twice)")
            out[k.strip()] = v.strip()
        return out

    bounds = {}
    for k, v in pairs(bound, "bound").items():
        if ":" not in v:
            raise ParameterError(f"bound {k}", v, "low:high")
        lo, hi = v.split(":", 1)
        bounds[k] = (parse_float(f"bound {k}", lo), parse_float(f"bound {k}", hi))
    limits = {k: parse_float(f"limit {k}", v) for k, v in pairs(limit, "limit").items()}
    res = optimize_vehicle(
        vehicle="" if vehicle is None else str(vehicle),
        objective=objective,
        parameters=tuple(parameter) if parameter else None,
        bounds=bounds,
        limits=limits,
        road_class=road_class,
        speed=speed,
    )
    if json_out:
        emit_json(res.to_dict())
        return
    from ..vehicles.config import example_vehicle_path, load_vehicle
    from ..vehicles.design import design_parameters

    units = design_parameters(load_vehicle(vehicle or example_vehicle_path()))
    rows = [(f"{k} [{units[k]}]", f"{v:.5g}") for k, v in res.parameters.items()]
    rows += [
        (f"{k} (file's value)", f"{res.metrics[k]:.5g} ({res.baseline[k]:.5g})")
        for k in res.metrics
    ]
    rows += [("feasible", str(res.feasible)), ("at bound", ", ".join(res.at_bound) or "-")]
    _table(f"minimum of {objective} (SI units; deflections m, loads N)", rows)


def example_command() -> None:
    """Print the packaged example vehicle file (units on every value [kg, m, N/m, N s/m]).

    Example: inerterlab vehicle example > car.toml
    """
    from ..vehicles.config import example_vehicle_path

    print(example_vehicle_path().read_text(encoding="utf-8"), end="")


def register(app: typer.Typer) -> None:
    group = typer.Typer(name="vehicle", help=_HELP, no_args_is_help=True, rich_markup_mode=None)
    group.command("spectral")(spectral_command)
    group.command("simulate")(simulate_command)
    group.command("modes")(modes_command)
    group.command("frequency-response")(frequency_response_command)
    group.command("monte-carlo")(monte_carlo_command)
    group.command("optimize")(optimize_command)
    group.command("road")(road_command)
    group.command("generate")(generate_command)
    group.command("example")(example_command)
    app.add_typer(group, name="vehicle")
