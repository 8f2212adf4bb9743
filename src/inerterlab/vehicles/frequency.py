"""Frequency response of a half or full car to a sine road, from its linear state space.

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
:func:`~inerterlab.systems.equilibrium.equilibrium`) is linearised about its static equilibrium (each
at its stiffness at rest; the result says so: its response to a finite amplitude
departs from this). A corner with an adaptive inerter or a device with internal nodes or
friction is refused, naming it (its response depends on the amplitude; the time
simulation, ``vehicle simulate``, takes it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, check_choice, check_positive
from .linear import LinearVehicle, linear_vehicle

__all__ = ["VehicleFrequencyResponse", "frequency_response", "PATTERNS"]

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
    """Steady-state response of a linear vehicle to a sine road (see the module).

    ``transfer``: name -> complex response per unit road amplitude over ``freq`` [Hz]
    (units :data:`UNITS`); :meth:`amplitudes`: |H| x ``amplitude`` [m, rad, m/s^2]."""

    freq: np.ndarray
    transfer: dict
    amplitude: float
    tracks: str
    axles: str | None
    speed: float | None
    kind: str
    linearised: bool = False

    @property
    def model(self) -> str:
        return "linearised about the static equilibrium" if self.linearised else "linear"

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
            cols[f"{k} phase [deg]"] = np.degrees(np.angle(h))
        return pd.DataFrame(cols)

    def peaks(self) -> dict:
        """name -> (frequency [Hz], amplitude [m, rad, m/s^2]) of the largest response."""
        out = {}
        for k, a in self.amplitudes().items():
            i = int(np.argmax(a))
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
            "phase_deg": {k: np.degrees(np.angle(h)).tolist() for k, h in self.transfer.items()},
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


def frequency_response(
    vehicle: LinearVehicle,
    freq,
    *,
    amplitude: float = 0.01,
    tracks: str = "in-phase",
    axles: str | None = None,
    speed: float | None = None,
) -> VehicleFrequencyResponse:
    """Heave, pitch, roll and seat acceleration of ``vehicle`` for a sine road of
    ``amplitude`` [m] at the frequencies ``freq`` [Hz] (module docstring).

    Front and rear: ``speed`` [m/s] (the rear wheels a wheelbase behind), or a rig
    with ``axles`` in-phase or anti-phase (default in-phase when no speed is given)."""
    a = check_positive("amplitude", amplitude, "m")
    check_choice("tracks", tracks, PATTERNS)
    if vehicle.kind == "half" and tracks != "in-phase":
        raise ParameterError("tracks", tracks, "'in-phase' for a half car (it has one track)")
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
    vehicle = as_linear(vehicle)
    lin = vehicle.linearised
    A, Br, Bd, Cy, Dr, Dd = vehicle.state_space(displacements=True)
    P = road_pattern(vehicle, f, tracks, axles, speed)
    acc = "seat_acc" if "seat_acc" in vehicle.outputs else "bounce_acc"
    names = ["heave", "pitch"] + (["roll"] if vehicle.kind == "full" else []) + [acc]
    out = {k: np.empty(f.size, complex) for k in names}
    eye = np.eye(A.shape[0])
    for i, fi in enumerate(f):
        s = 2j * math.pi * fi
        r = P[i]
        x = np.linalg.solve(s * eye - A, (Br + s * Bd) @ r)
        for k in names:
            out[k][i] = Cy[k] @ x + (Dr[k] + s * Dd[k]) @ r
    return VehicleFrequencyResponse(
        freq=f, transfer=out, amplitude=a, tracks=tracks, axles=axles, speed=speed,
        kind=vehicle.kind, linearised=lin,
    )  # fmt: skip
