"""Frequency response of a half or full car to a sine road: from its linear state space,
or by the harmonic balance of the core car where a corner is nonlinear.

Every wheel's road height is r_i(t) = A Re(p_i e^{j w t}) with the road amplitude A [m]
and a complex pattern p over the wheels (front, rear for a half car; front_left,
front_right, rear_left, rear_right for a full car):

* ``tracks``: the right track equals the left (``in-phase``, a heave input) or its
  negative (``anti-phase``, a roll input); full car only (a half car has one track);
* front and rear: either a rig that drives the axles ``in-phase`` (heave) or
  ``anti-phase`` (pitch), or the car driven at ``speed`` V over the road, where the rear
  wheels see what the front wheels saw a wheelbase earlier, p_rear = p_front e^{-j w L/V}
  (what a ride engineer measures on the road: the wheelbase filter makes heave vanish and
  pitch peak where the wavelength is 2L / odd integer, and the reverse at L / integer).

The responses are steady-state complex amplitudes per unit road amplitude,
H(j w) = C (j w I - A)^-1 (B_r + j w B_d) p + (D_r + j w D_d) p, taken from the state
space of :meth:`~inerterlab.vehicles.linear.LinearVehicle.state_space` (the core vehicle about
its static equilibrium): ``heave`` (the
body's bounce at its centre of gravity) [m/m], ``pitch`` [rad/m] (positive: nose down,
the model's sign), ``roll`` [rad/m] (full car; positive: left side up) and
``seat_acc`` [(m/s^2)/m] (the body's acceleration at its centre of gravity,
``bounce_acc``, for a car without a seat). Their magnitudes times A are the response
amplitudes (half peak-to-peak). A car resting on gas springs or bump stops
(Newton's method on the whole nonlinear balance,
:func:`~inerterlab.systems.equilibrium.equilibrium`) is there linearised about its
static equilibrium (each at its stiffness at rest; the result says so).

Nonlinear corners (``method="harmonic-balance"``, and ``auto`` for a car with a
nonlinear element): the core car (tyres always in contact, about its static equilibrium)
is balanced on the one engine of :mod:`inerterlab.frequency` at the road amplitude,
every wheel driven through the road pattern (:func:`pattern_rows`: a gain, a phase and a
delay per wheel; :func:`inerterlab.frequency.quarter_car.from_core_system`). Each
response is the half peak-to-peak of the steady periodic output divided by the road
amplitude (no phase). Friction is refused there (it switches within millimetres per
second, beyond a truncated Fourier series; the time simulation, ``vehicle simulate``,
takes it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, check_choice, check_positive
from ..h2 import resolvent_solve
from .linear import LinearVehicle, linear_vehicle

__all__ = ["VehicleFrequencyResponse", "frequency_response", "pattern_rows", "PATTERNS", "METHODS"]

#: relative phase of the right track to the left, and of a rig's rear axle to the front
PATTERNS = ("in-phase", "anti-phase")

UNITS = {
    "heave": "m/m",
    "pitch": "rad/m",
    "roll": "rad/m",
    "seat_acc": "(m/s^2)/m",
    "bounce_acc": "(m/s^2)/m",
}
AMPLITUDE_UNITS = {"heave": "m", "pitch": "rad", "roll": "rad", "seat_acc": "m/s^2",
                   "bounce_acc": "m/s^2"}  # fmt: skip


@dataclass(frozen=True)
class VehicleFrequencyResponse:
    """Steady-state response of a vehicle to a sine road (see the module).

    ``transfer``: name -> response per unit road amplitude over ``freq`` [Hz] (units
    :data:`UNITS`): complex from the linear state space, or from the harmonic balance
    the half peak-to-peak of the steady response divided by the road amplitude (real;
    NaN where the balance failed); :meth:`amplitudes`: |H| x ``amplitude`` [m, rad,
    m/s^2]."""

    freq: np.ndarray
    transfer: dict
    amplitude: float
    tracks: str
    axles: str | None
    speed: float | None
    kind: str
    linearised: bool = False
    #: harmonics of the balance (None: the linear state space)
    harmonics: int | None = None
    #: frequencies where the balance did not converge (NaN there)
    failed: int = 0

    @property
    def model(self) -> str:
        if self.harmonics is not None:
            return f"harmonic balance, {self.harmonics} harmonics"
        return "linearised about the static equilibrium" if self.linearised else "linear"

    @property
    def phased(self) -> bool:
        """True where the responses carry a phase (the linear route); the harmonic
        balance gives half peak-to-peak amplitudes."""
        return self.harmonics is None

    def amplitudes(self) -> dict:
        return {k: np.abs(h) * self.amplitude for k, h in self.transfer.items()}

    def input_label(self) -> str:
        rear = f"rear delayed by wheelbase/V, V = {self.speed:g} m/s" if self.speed else (
            f"rig, axles {self.axles}"
        )  # fmt: skip
        tracks = f", tracks {self.tracks}" if self.kind == "full" else ""
        return f"{self.kind} car, road amplitude {self.amplitude:g} m{tracks}, {rear}"

    def to_frame(self):
        """One row per frequency: amplitudes [m, rad, m/s^2], transmissibilities per unit
        road amplitude and phases [deg] (linear model)."""
        import pandas as pd

        cols = {"frequency [Hz]": self.freq}
        amp = self.amplitudes()
        for k, h in self.transfer.items():
            cols[f"{k} amplitude [{AMPLITUDE_UNITS[k]}]"] = amp[k]
            cols[f"{k} per road amplitude [{UNITS[k]}]"] = np.abs(h)
            if self.phased:
                cols[f"{k} phase [deg]"] = np.degrees(np.angle(h))
        return pd.DataFrame(cols)

    def peaks(self) -> dict:
        """name -> (frequency [Hz], amplitude [m, rad, m/s^2]) of the largest response."""
        out = {}
        for k, a in self.amplitudes().items():
            if not np.isfinite(a).any():
                out[k] = (math.nan, math.nan)
                continue
            i = int(np.nanargmax(a))
            out[k] = (float(self.freq[i]), float(a[i]))
        return out

    def to_dict(self) -> dict:
        amp = self.amplitudes()
        return {
            "model": self.model,
            "vehicle": self.kind,
            "road_amplitude_m": self.amplitude,
            "tracks": self.tracks if self.kind == "full" else None,
            "axles": self.axles,
            "speed_m_per_s": self.speed,
            "frequency_hz": self.freq.tolist(),
            "amplitude": {k: a.tolist() for k, a in amp.items()},
            "amplitude_units": {k: AMPLITUDE_UNITS[k] for k in amp},
            "per_road_amplitude": {k: np.abs(h).tolist() for k, h in self.transfer.items()},
            "per_road_amplitude_units": {k: UNITS[k] for k in amp},
            "phase_deg": {k: np.degrees(np.angle(h)).tolist() for k, h in self.transfer.items()}
            if self.phased else None,
            "harmonics": self.harmonics,
            "failed_frequencies": self.failed,
            "peaks": {
                k: {"frequency_hz": f, "amplitude": a, "unit": AMPLITUDE_UNITS[k]}
                for k, (f, a) in self.peaks().items()
            },
        }

    def plot(self):
        """Figure: each response's amplitude [m, rad, m/s^2] against frequency [Hz]."""
        from ..plotting import _plt

        plt = _plt()
        amp = self.amplitudes()
        fig, axes = plt.subplots(len(amp), 1, figsize=(7, 2.2 * len(amp)), sharex=True)
        for ax, (k, a) in zip(np.atleast_1d(axes), amp.items(), strict=True):
            ax.loglog(self.freq, a, lw=1.2)
            ax.set_ylabel(f"{k} [{AMPLITUDE_UNITS[k]}]")
            ax.grid(True, which="both", lw=0.3)
        np.atleast_1d(axes)[0].set_title(f"{self.input_label()} ({self.model})", fontsize=9)
        np.atleast_1d(axes)[-1].set_xlabel("frequency [Hz]")
        return fig


def as_linear(vehicle) -> LinearVehicle:
    """``vehicle`` as a :class:`~inerterlab.vehicles.linear.LinearVehicle` (from its
    parameters, a HalfCar or FullCar, where it is not one)."""
    if isinstance(vehicle, LinearVehicle):
        return vehicle
    return linear_vehicle(getattr(vehicle, "parameters", vehicle))


def _core(vehicle):
    """The core vehicle (tyres always in contact, about its static equilibrium) of a
    LinearVehicle, a core half or full car, or a HalfCar / FullCar."""
    from ..systems import System
    from ..systems.vehicle import vehicle as core_vehicle

    if isinstance(vehicle, LinearVehicle):
        return vehicle.system
    if isinstance(vehicle, System):
        if vehicle.kind not in ("half_car", "full_car"):
            raise ParameterError("vehicle", vehicle.kind, "a half or full car")
        return vehicle
    return core_vehicle(getattr(vehicle, "parameters", vehicle), lift_off=False)


def pattern_rows(kind: str, tracks: str, axles: str | None, speed, wheelbase: float):
    """(n_roads, 3) gain, phase [rad] and delay [s] of every wheel's road for the
    harmonic balance: road k is A g sin(Omega t + phase - Omega delay); the same inputs
    as :func:`road_pattern` (which gives them as complex numbers per frequency)."""
    rear = [1.0, 0.0, wheelbase / speed] if speed is not None else (
        [1.0, 0.0 if axles == "in-phase" else math.pi, 0.0]
    )  # fmt: skip
    front = [1.0, 0.0, 0.0]
    if kind == "half":
        return np.array([front, rear])
    side = 0.0 if tracks == "in-phase" else math.pi
    return np.array([front, [1.0, side, 0.0], rear, [1.0, rear[1] + side, rear[2]]])


def road_pattern(vehicle: LinearVehicle, freq, tracks: str, axles: str | None, speed):
    """(n_freq, n_inputs) complex road heights per unit amplitude at each wheel."""
    f = np.asarray(freq, float)
    if speed is not None:
        rear = np.exp(-2j * math.pi * f * vehicle.parameters.wheelbase / speed)
    else:
        rear = np.full(f.size, 1.0 if axles == "in-phase" else -1.0, complex)
    if vehicle.kind == "half":
        return np.column_stack([np.ones(f.size), rear])
    side = 1.0 if tracks == "in-phase" else -1.0
    return np.column_stack([np.ones(f.size), side * np.ones(f.size), rear, side * rear])


#: the routes of :func:`frequency_response`
METHODS = ("auto", "linear", "harmonic-balance")
#: harmonics of the balance unless asked (a vehicle's nonlinear corners are mild)
VEHICLE_HARMONICS = 7


def frequency_response(
    vehicle,
    freq,
    *,
    amplitude: float = 0.01,
    tracks: str = "in-phase",
    axles: str | None = None,
    speed: float | None = None,
    method: str = "auto",
    harmonics: int | None = None,
) -> VehicleFrequencyResponse:
    """Heave, pitch, roll and seat acceleration of ``vehicle`` for a sine road of
    ``amplitude`` [m] at the frequencies ``freq`` [Hz] (module docstring).

    Front and rear: ``speed`` [m/s] (the rear wheels a wheelbase behind), or a rig
    with ``axles`` in-phase or anti-phase (default in-phase when no speed is given).
    ``method``: ``linear`` (the state space about the static equilibrium),
    ``harmonic-balance`` (the core car's steady state at this amplitude, its response
    the half peak-to-peak of each output, with ``harmonics`` harmonics, default
    :data:`VEHICLE_HARMONICS`) or ``auto`` (linear for a linear car, the harmonic
    balance for one with a nonlinear element at a corner). ``vehicle``: a
    :class:`~inerterlab.vehicles.linear.LinearVehicle`, a HalfCar or FullCar, or a core
    half or full car (:func:`inerterlab.systems.vehicle.vehicle` with ``lift_off=False``)."""
    a = check_positive("amplitude", amplitude, "m")
    check_choice("tracks", tracks, PATTERNS)
    check_choice("method", method, METHODS)
    if speed is not None:
        speed = check_positive("speed", speed, "m/s")
        if axles is not None:
            raise ParameterError(
                "axles", axles, "no axles with a speed (the wheelbase sets the rear's phase)"
            )
    else:
        axles = check_choice("axles", axles or "in-phase", PATTERNS)
    f = np.asarray(freq, dtype=float)
    if f.ndim != 1 or f.size < 1 or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ParameterError("freq", "grid", "positive finite frequencies [Hz]")
    if method == "linear" or (method == "auto" and isinstance(vehicle, LinearVehicle)):
        return _linear(as_linear(vehicle), f, a, tracks, axles, speed)
    sys = _core(vehicle)
    if method == "auto" and sys.linear:
        return _linear(as_linear(vehicle if not hasattr(vehicle, "info") else
                                 sys.info["parameters"]), f, a, tracks, axles, speed)  # fmt: skip
    return _balance(sys, f, a, tracks, axles, speed, harmonics)


def _names(kind: str, seat: bool) -> list:
    return ["heave", "pitch"] + (["roll"] if kind == "full" else []) + (
        ["seat_acc"] if seat else ["bounce_acc"]
    )  # fmt: skip


def _check_tracks(kind: str, tracks: str) -> None:
    if kind == "half" and tracks != "in-phase":
        raise ParameterError("tracks", tracks, "'in-phase' for a half car (it has one track)")


def _linear(vehicle: LinearVehicle, f, a, tracks, axles, speed) -> VehicleFrequencyResponse:
    _check_tracks(vehicle.kind, tracks)
    A, Br, Bd, Cy, Dr, Dd = vehicle.state_space(displacements=True)
    P = road_pattern(vehicle, f, tracks, axles, speed)
    names = _names(vehicle.kind, "seat_acc" in vehicle.outputs)
    s = 2j * math.pi * f
    x = resolvent_solve(A, s, np.einsum("fnw,fw->fn", Br[None] + s[:, None, None] * Bd[None], P))
    out = {
        k: x @ Cy[k] + np.einsum("fw,fw->f", Dr[k][None] + s[:, None] * Dd[k][None], P)
        for k in names
    }
    return VehicleFrequencyResponse(
        freq=f, transfer=out, amplitude=a, tracks=tracks, axles=axles, speed=speed,
        kind=vehicle.kind, linearised=vehicle.linearised,
    )  # fmt: skip


#: core output of each response of the harmonic balance
_CORE_OUTPUT = {"heave": "bounce.x", "pitch": "pitch.x", "roll": "roll.x",
                "seat_acc": "seat.a", "bounce_acc": "bounce.a"}  # fmt: skip


def _balance(sys, f, a, tracks, axles, speed, harmonics) -> VehicleFrequencyResponse:
    """The harmonic balance of the core car ``sys`` on the one engine
    (:func:`inerterlab.frequency.frequency_response`, ``sihb``: each point starts from the
    last converged one), every wheel driven through the road pattern."""
    from ..elements import kernel_law
    from ..frequency import frequency_response as balance
    from ..frequency.quarter_car import from_core_system

    kind = "full" if len(sys.info["body"]) == 3 else "half"
    _check_tracks(kind, tracks)
    for name, el in zip(sys.element_names, sys.elements, strict=True):
        if kernel_law(el).bounded:
            raise ParameterError(
                name, el.description,
                "an element the harmonic balance resolves (friction switches within "
                "millimetres per second, beyond a truncated Fourier series); the time "
                "simulation, vehicle simulate, takes it",
            )  # fmt: skip
    H = VEHICLE_HARMONICS if harmonics is None else harmonics
    P = pattern_rows(kind, tracks, axles, speed, sys.info["parameters"].wheelbase)
    fo = from_core_system(sys, pattern=P)
    res = balance(fo, "sihb", freq_hz=f, amplitude=a, harmonics=H, direction="up",
                  stability=False)  # fmt: skip
    order = np.argsort(f)
    names = _names(kind, "seat" in sys.node_names)
    out = {}
    for k in names:
        amp = np.ma.filled(res.outputs[_CORE_OUTPUT[k]].astype(float), np.nan)
        vals = np.empty(f.size)
        vals[order] = amp / a
        out[k] = vals
    failed = int((~res.converged).sum())
    return VehicleFrequencyResponse(
        freq=f, transfer=out, amplitude=a, tracks=tracks, axles=axles, speed=speed,
        kind=kind, linearised=False, harmonics=int(H), failed=failed,
    )  # fmt: skip
