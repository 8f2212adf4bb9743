"""The device models' own compiled integration (``_kernels``), kept only to compare the
model core against it before it is deleted."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ConvergenceError, ParameterError, check_positive
from . import _kernels as K
from .models import Device, HydraulicDevice, RectifierDevice, ScrewDevice
from .motion import Motion

__all__ = ["device_force", "DeviceForceResult", "parameter_vector"]

_LAW = {"thesis": 0, "momentum": 1, "slider-dynamics": 2}


@dataclass(frozen=True, kw_only=True, eq=False)
class DeviceForceResult:
    """Force of a device against time.

    Attributes
    ----------
    t : ndarray
        Time [s].
    force : ndarray
        F = F_1 - F_2 [N], the force on the terminals.
    displacement, velocity, acceleration : ndarray
        Prescribed terminal motion x [m], v [m/s], a [m/s^2].
    equivalent_mass : ndarray
        r^2 I [kg] of the flywheel at each time (for ``slider-dynamics`` from the
        actual slider radius).
    spring_deflection : ndarray
        x_k [m] of the series spring (series devices; zeros for the screw).
    branch_velocity : ndarray
        v_a [m/s] through the inertance branch (the terminal velocity for the screw).
    slider_position, slider_rate : ndarray
        l [m], l' [m/s] (``slider-dynamics``; the quasi-static l otherwise).
    flywheel_speed : ndarray
        omega [rad/s] of the flywheel.
    work, dissipated, stored : ndarray
        Work done on the device [J] since t[0], energy dissipated [J] and the change
        of stored energy [J] (spring + flywheel) since t[0].
    freewheeling : ndarray of bool
        True where the rectifier's flywheel runs free.
    steps : int
        Accepted and rejected integrator steps.
    """

    t: np.ndarray
    force: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    equivalent_mass: np.ndarray
    spring_deflection: np.ndarray
    branch_velocity: np.ndarray
    slider_position: np.ndarray
    slider_rate: np.ndarray
    flywheel_speed: np.ndarray
    work: np.ndarray
    dissipated: np.ndarray
    stored: np.ndarray
    freewheeling: np.ndarray
    steps: int

    @property
    def energy_residual(self) -> np.ndarray:
        """work - stored - dissipated [J]: zero for energy-consistent laws."""
        return self.work - self.stored - self.dissipated

    _UNITS = {
        "force": "N",
        "displacement": "m",
        "velocity": "m/s",
        "acceleration": "m/s^2",
        "equivalent_mass": "kg",
        "spring_deflection": "m",
        "branch_velocity": "m/s",
        "slider_position": "m",
        "slider_rate": "m/s",
        "flywheel_speed": "rad/s",
        "work": "J",
        "dissipated": "J",
        "stored": "J",
    }

    def _summary(self) -> tuple[str, list[tuple[str, str]]]:
        from .._display import fmt, span

        rows = [
            ("samples", str(self.t.size)),
            ("time", span(self.t[0], self.t[-1], "s")),
            ("force", span(self.force.min(), self.force.max(), "N")),
            ("force rms", fmt(float(np.sqrt(np.mean(self.force**2))), "N")),
            ("equivalent mass", span(self.equivalent_mass.min(), self.equivalent_mass.max(), "kg")),
            ("work done", fmt(self.work[-1], "J")),
        ]
        return "device force", rows

    def __repr__(self) -> str:
        _, rows = self._summary()
        d = dict(rows)
        return (
            f"<DeviceForceResult {d['samples']} samples over {d['time']}: force {d['force']}, "
            f"equivalent mass {d['equivalent mass']}>"
        )

    def _repr_html_(self) -> str:
        from .._display import html_table

        return html_table(*self._summary())

    def to_xarray(self):
        """Every series as an xarray Dataset over time, with units."""
        import xarray as xr

        data = {k: ("t", getattr(self, k), {"units": u}) for k, u in self._UNITS.items()}
        data["freewheeling"] = ("t", self.freewheeling)
        ds = xr.Dataset(data, coords={"t": ("t", self.t, {"units": "s"})})
        ds.attrs["steps"] = int(self.steps)
        return ds

    def to_pandas(self):
        """The time series as a pandas DataFrame (SI units in the column names)."""
        import pandas as pd

        return pd.DataFrame(
            {
                "t [s]": self.t,
                "force [N]": self.force,
                "displacement [m]": self.displacement,
                "velocity [m/s]": self.velocity,
                "equivalent_mass [kg]": self.equivalent_mass,
            }
        )

    def plot(self, ax=None):
        """Force against time (delegates to :mod:`inerterlab.plotting`)."""
        from ..plotting import _plt

        plt = _plt()
        if ax is None:
            _, ax = plt.subplots(figsize=(8, 3.5))
        ax.plot(self.t, self.force)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("force [N]")
        return ax


def parameter_vector(device: Device) -> np.ndarray:
    """The flat parameter vector the compiled kernels read (see ``_kernels``)."""
    fw, tr = device.flywheel, device.transmission
    P = np.zeros(K.NPAR)
    P[K.SERIES] = 1.0 if device.series else 0.0
    P[K.LAW] = _LAW[device.law]
    P[K.RATIO] = tr.ratio
    P[K.STIFF] = device.stiffness
    P[K.DAMP] = device.damping
    P[K.FRIC] = device.friction
    P[K.VEPS] = device.friction_velocity
    P[K.BACKLASH] = device.backlash
    P[K.FREEWHEEL] = 1.0 if device.freewheel else 0.0
    P[K.FWDRAG] = getattr(device, "flywheel_drag", 0.0)
    P[K.FW0 : K.FW0 + 8] = (
        fw.rest_inertia,
        fw.inertia_coefficient,
        fw.spring_stiffness,
        fw.slider_mass,
        fw.slider_min,
        fw.slider_max,
        fw.saturation_speed,
        fw.power,
    )
    if device.law == "slider-dynamics":
        P[K.SD0 : K.SD0 + 9] = device.slider_dynamics.coefficients(fw)
    else:
        P[K.SD0 + 1] = fw.n_sliders
    return P


def _initial_state(device: Device, P: np.ndarray, x0: float, v0: float, a0: float):
    fw, r = device.flywheel, device.transmission.ratio
    y = np.zeros(K.NSTATE)
    om = r * v0
    l0 = float(fw.slider_position(om))
    y[2] = l0
    if not device.series:
        y[0], y[1] = x0, v0
        return y
    # steady motion before t0: the branch moves with the terminals and the spring
    # carries the branch force, damper + friction + bearing drag of the flywheel
    # (torque c_d omega, a force c_d r^2 v at the terminals) + inertia at the current
    # acceleration
    if device.law == "momentum":
        m = r * r * float(fw.momentum_inertia(om))
    else:
        m = r * r * (fw.rest_inertia + fw.inertia_coefficient * l0**fw.power)
    fb = device.damping * v0 + device.friction * math.tanh(v0 / device.friction_velocity)
    fb += P[K.FWDRAG] * r * r * v0
    y[0] = (fb + m * a0) / device.stiffness
    y[1] = v0
    y[6] = abs(om)
    return y


def device_force(
    device: Device,
    motion: Motion,
    *,
    duration: float | None = None,
    sample_rate: float = 1000.0,
    t=None,
    rtol: float = 1e-7,
    h_max: float | None = None,
    event_tol: float = 1e-7,
    max_steps: int = 50_000_000,
    initial_force: float | None = None,
    force_only: bool = False,
) -> DeviceForceResult:
    """Predict the force of ``device`` for the terminal ``motion``.

    Parameters
    ----------
    device : HydraulicDevice, ScrewDevice or RectifierDevice
    motion : Motion
        Prescribed relative displacement x(t) [m] (velocity and acceleration follow).
    duration : float
        Length of the record [s] (default: one period, or the whole sampled record).
    sample_rate : float
        Output samples per second [Hz].
    t : array, optional
        Explicit increasing output times [s] (overrides duration and sample_rate).
    rtol : float
        Relative tolerance of the adaptive integrator; absolute tolerances follow from
        the device's force scale.
    h_max : float, optional
        Largest step [s] (default: a fiftieth of the period, at most 1e-3 s).
    event_tol : float
        Precision [s] to which a free-wheeling switch of the rectifier is located.
    initial_force : float, optional
        Series devices: start with the spring carrying this force [N] (e.g. the measured
        force at the first sample). By default the device starts as if it had been
        moving steadily with the terminals: the spring carries damper + friction +
        flywheel bearing drag (c_d r^2 v) + inertia force at the initial velocity and
        acceleration.
    force_only : bool
        Return only the force array [N] (the same numbers), skipping the other series
        of the result; for identification, which runs a device thousands of times.

    Returns
    -------
    DeviceForceResult (or the force array with ``force_only``)

    Examples
    --------
    >>> from inerterlab.devices import device_preset, Motion
    >>> res = device_force(device_preset("screw"), Motion.sine(frequency=1.0, amplitude=0.005),
    ...                    duration=1.0, sample_rate=100)
    >>> res.force.shape
    (101,)
    """
    if not isinstance(device, HydraulicDevice | ScrewDevice | RectifierDevice):
        raise ParameterError("device", device, "a HydraulicDevice, ScrewDevice or RectifierDevice")
    if not isinstance(motion, Motion):
        raise ParameterError("motion", motion, "a Motion")
    if device.freewheel and device.damping <= 0:
        raise ParameterError("damping", device.damping, "> 0 N s/m with freewheel=True")
    if t is not None:
        t_out = np.asarray(t, dtype=float)
        if t_out.ndim != 1 or t_out.size < 1 or not np.all(np.isfinite(t_out)):
            raise ParameterError("t", "array", "a 1-D array of finite times [s]")
        if np.any(np.diff(t_out) <= 0):
            raise ParameterError("t", "not increasing", "strictly increasing times [s]")
    else:
        fs = check_positive("sample_rate", sample_rate, "Hz")
        if duration is None:
            if motion.signal == "samples":
                ts = motion.samples[0]
                duration = float(ts[-1] - ts[0])
            else:
                duration = 1.0 / motion.frequency
        d = check_positive("duration", duration, "s")
        n = int(round(d * fs)) + 1
        if n > 50_000_000:
            raise ParameterError("duration", duration, "at most 5e7 samples at this rate")
        t0 = float(motion.samples[0][0]) if motion.signal == "samples" else 0.0
        t_out = t0 + np.arange(n) / fs
    kind, par, tn, xn, vn = motion.kernel_args()
    P = parameter_vector(device)
    x0, v0, a0 = (float(q[0]) for q in motion.evaluate(t_out[:1]))
    y0 = _initial_state(device, P, x0, v0, a0)
    if initial_force is not None and device.series:
        from ..errors import check_finite

        y0[0] = check_finite("initial_force", initial_force) / device.stiffness
    if h_max is None:
        h_max = 1e-3 if motion.signal == "samples" else min(1e-3, 0.02 / motion.frequency)
    h_max = check_positive("h_max", h_max, "s")
    check_positive("rtol", rtol)
    f_scale = max(
        device.friction + device.damping * max(motion.velocity_amplitude, 1e-6),
        device.stiffness * 1e-9,
        1.0,
    )
    atol = np.array(
        [
            rtol * f_scale / device.stiffness,  # x_k [m]
            rtol * max(motion.velocity_amplitude, 1e-6),  # v_a [m/s]
            rtol * device.flywheel.slider_max,  # l [m]
            rtol * device.flywheel.slider_max * 100.0,  # l' [m/s]
            rtol * 1e-3,  # W [J]
            rtol * 1e-3,  # D [J]
            rtol * device.transmission.ratio * max(motion.velocity_amplitude, 1e-6),
        ]
    )
    if not device.series and device.law != "slider-dynamics" and motion.signal == "samples":
        # the force is algebraic in the measured motion; the tracked x, v and the energy
        # integrals need no step control (their integrands are piecewise cubic in t)
        atol[[0, 1, 4, 5]] = np.inf
    ys, force, meq, modes, status, steps = K.integrate(
        t_out,
        y0,
        0,
        P,
        kind,
        par,
        tn,
        xn,
        vn,
        float(rtol),
        atol,
        float(h_max),
        float(event_tol),
        int(max_steps),
    )
    if status != 0:
        why = "too many steps" if status == 1 else "step size underflow"
        raise ConvergenceError(
            f"device_force: integration stopped at t={t_out[len(force) - 1]:.6g} s ({why}); "
            "check the parameters or raise max_steps"
        )
    if force_only:
        return force
    x, v, a = motion.evaluate(t_out)
    law = _LAW[device.law]
    r = device.transmission.ratio
    e_fw = K.flywheel_energies(ys, modes, law, r, P)
    spring = 0.5 * device.stiffness * ys[:, 0] ** 2  # x_k, or x for the screw
    stored = spring + e_fw
    free = modes == 1
    omega = np.where(free, ys[:, 6], r * np.abs(ys[:, 1]))
    if device.law == "slider-dynamics":
        lpos = ys[:, 2]
    else:
        lpos = np.asarray(device.flywheel.slider_position(omega), dtype=float)
    series = device.series
    return DeviceForceResult(
        t=t_out,
        force=force,
        displacement=x,
        velocity=v,
        acceleration=a,
        equivalent_mass=meq,
        spring_deflection=ys[:, 0] if series else np.zeros_like(t_out),
        branch_velocity=ys[:, 1] if series else v,
        slider_position=lpos,
        slider_rate=ys[:, 3],
        flywheel_speed=omega,
        work=ys[:, 4],
        dissipated=ys[:, 5],
        stored=stored - stored[0],
        freewheeling=free,
        steps=int(steps),
    )
