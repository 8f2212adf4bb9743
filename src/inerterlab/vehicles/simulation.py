"""Time simulation of a half or full car on the model core, with the ride metrics.

The vehicle is the core system of :func:`inerterlab.systems.vehicle.vehicle` (bodies
with bounce, pitch and roll, the seat, any element or network at a corner, tyres that
lift off as events, asymmetric dampers and strut friction as elements), integrated by
the core's Dormand-Prince pair with error control, or by fixed classical Runge-Kutta
steps (:func:`inerterlab.systems.vehicle.simulate`).
The road is given at samples ``dt`` apart and is linear between them (a first-order
hold: docs/decisions.md, "The vehicle's time domain on the core").

The ISO 2631-1 comfort figures are integrated as observer states beside the motion
(:mod:`inerterlab.systems.observers`): the Wk filter of the seat's (or, without a seat,
the body's bounce) acceleration, the integrals of a_w^2 and a_w^4, so the weighted RMS
and the vibration dose value are integrals as accurate as the motion, taken over the
time after the start-up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, check_nonnegative

__all__ = ["VehicleRun", "simulate_vehicle", "WK_SCALES"]

#: typical sizes of the comfort observers (absolute tolerance rtol x size): the Wk
#: filter's states, int a_w^2 [m^2/s^3], int a_w^4 [m^4/s^7] (as the quarter car's ride
#: observers, :data:`inerterlab.systems.observers.RIDE_SCALES`)
WK_SCALES = {"wk": 1e1, "i_wk": 1e-2, "i_wk4": 1e-3}


@dataclass(frozen=True, eq=False)
class VehicleRun:
    """A vehicle's time simulation.

    Attributes
    ----------
    time : ndarray
        The road samples' times [s].
    outputs : dict
        ``bounce_acc`` [m/s^2], ``pitch_acc``, ``roll_acc`` [rad/s^2], ``seat_acc``
        [m/s^2], ``<corner>_deflection`` [m], ``<corner>_tyre_load`` [N] (increase of
        the contact force) at the samples.
    contact_force : dict
        Corner -> contact force [N] (static load plus the tyre load; 0 while off the
        road with lift-off, negative where a linear tyre pulls).
    lift_off_fraction : dict
        Corner -> fraction of all samples with the contact force at zero or below [-].
    comfort : dict
        ``signal`` (``seat_acc`` or ``bounce_acc``), ``wk_rms`` [m/s^2], ``vdv``
        [m/s^1.75], ``crest_factor`` [-] (peak |a_w| at the samples over the RMS) and
        ``duration`` [s], all after the start-up ``warmup``.
    weighted : ndarray
        a_w [m/s^2] at the samples (the Wk filter from rest at t = 0).
    stats : dict
        The integrator's steps, rejected steps, right-hand sides and events.
    system : System
        The core vehicle with its comfort observers.
    """

    time: np.ndarray
    outputs: dict
    contact_force: dict
    lift_off_fraction: dict
    comfort: dict
    weighted: np.ndarray
    stats: dict
    system: object


def simulate_vehicle(parameters, r, dt: float, *, lift_off: bool = True, rebound: float = 1.0,
                     compression: float = 1.0, friction: float = 0.0,
                     friction_velocity: float = 1e-3, warmup: float = 0.0, rtol: float = 1e-6,
                     networks: dict | None = None, system=None,
                     fixed_step: float | None = None) -> VehicleRun:  # fmt: skip
    """Simulate the car ``parameters`` (HalfCar, FullCar or a vehicle file) over wheel
    heights ``r`` (n_t, stations) [m] sampled every ``dt`` [s], from rest in static
    equilibrium on the first heights.

    ``lift_off``: one-sided tyres (else linear tyres, which may pull); ``rebound`` and
    ``compression`` [-] the struts' damping factors while extending and shortening;
    ``friction`` [N] a Coulomb friction across every strut, regularised over
    ``friction_velocity`` [m/s]; ``warmup`` [s] the start-up left out of the comfort
    figures (at most half the run); ``rtol`` the integrator's relative tolerance;
    ``networks`` as :func:`inerterlab.systems.vehicle.vehicle`. ``system``: a core
    vehicle already built with these options (then ``parameters`` and the options are
    not read again). ``fixed_step`` [s]: classical Runge-Kutta steps of at most this
    length, ending on every road sample, without error control (``rtol`` unused; lift-off
    and the other switches still located; ``fixed_step = dt``: one step per sample,
    docs/guide/vehicles.md "Fixed steps"); None: the adaptive pair at ``rtol``."""
    from ..metrics import wk_state_space
    from ..systems import vehicle as core
    from ..systems.observers import Observer, weighted, with_observers

    check_nonnegative("warmup", warmup, "s")
    sys = system
    if sys is None:
        sys = core.vehicle(parameters, networks=networks, lift_off=bool(lift_off),
                           rebound=rebound, compression=compression, friction=friction,
                           friction_velocity=friction_velocity)  # fmt: skip
    signal = "seat_acc" if "seat" in sys.node_names else "bounce_acc"
    # the comfort observers' system, kept on the vehicle for its parameter rows: a
    # process that drives one car over many roads builds it (and its factored tables
    # and compiled code, kept on it) once
    got = sys.info.get("comfort_observed")
    if got is None or got[0] is not sys.ftab:
        channel = {"seat_acc": "seat.a", "bounce_acc": "bounce.a"}[signal]
        s = WK_SCALES
        obs, aw = weighted("wk", {channel: 1.0}, *wk_state_space(), scale=s["wk"])
        obs += [Observer("wk.i2", "square", aw, scale=s["i_wk"]),
                Observer("wk.i4", "fourth", aw, scale=s["i_wk4"])]  # fmt: skip
        got = (sys.ftab, with_observers(sys, obs), aw)
        sys.info["comfort_observed"] = got
    _, sys, aw = got
    if fixed_step is None:
        res = core.simulate(sys, r, dt, rtol=rtol)
    else:
        res = core.simulate(sys, r, dt, rtol=rtol, fixed_step=fixed_step, fixed_method="rk4")
    t = res.time
    names = sys.state_names
    col = {n: res.states[:, names.index(n)] for n in ("wk.i2", "wk.i4")}
    a_w = np.zeros(t.size)
    for k, c in aw.items():
        a_w += c * (res.states[:, names.index(k)] if k in names else res.signals[k])
    k0 = min(int(round(float(warmup) / float(dt))), t.size // 2)
    span = float(t[-1] - t[k0])
    if not span > 0:
        raise ParameterError("r", f"{t.size} samples", "a run longer than the start-up")
    i2 = max(float(col["wk.i2"][-1] - col["wk.i2"][k0]), 0.0)
    i4 = max(float(col["wk.i4"][-1] - col["wk.i4"][k0]), 0.0)
    wk_rms = math.sqrt(i2 / span)
    peak = float(np.max(np.abs(a_w[k0:])))
    comfort = {"signal": signal, "wk_rms": wk_rms, "vdv": i4**0.25,
               "crest_factor": peak / wk_rms if wk_rms > 0 else 0.0, "duration": span}  # fmt: skip
    return VehicleRun(t, res.outputs, res.contact_force, res.lift_off_fraction, comfort, a_w,
                      res.stats, sys)  # fmt: skip
