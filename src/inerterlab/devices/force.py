"""Force of a real device for a prescribed terminal motion: :func:`device_force`."""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, check_positive
from ..excitation import RoadTooShortWarning
from ..slider_dynamics import SliderDynamics, stored_energy
from .models import Device, HydraulicDevice, RectifierDevice, ScrewDevice
from .motion import Motion

__all__ = ["device_force", "device_rig", "initial_state", "DeviceForceResult"]


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


@functools.lru_cache(maxsize=32)
def device_rig(device: Device):
    """The model core's rig (:func:`inerterlab.systems.rig`) holding ``device``: its
    composite element (hydraulic, screw or rectifier) between the drive and the ground.
    Devices are frozen, so equal devices share one compiled rig."""
    if device.law == "slider-dynamics" and device.slider_dynamics != SliderDynamics():
        raise ParameterError(
            "slider_dynamics", device.slider_dynamics, "the default SliderDynamics() (the "
            "network elements take the default slider options)",
        )  # fmt: skip
    from ..systems import rig

    return rig(device)


def _flywheel_speed_state(sys) -> int | None:
    name = next((n for n in sys.state_names if n.endswith(".flywheel_speed")), None)
    return None if name is None else sys.state_names.index(name)


def initial_state(
    device: Device, sys, x0: float, v0: float, a0: float, initial_force: float | None = None
) -> np.ndarray:
    """The rig's state (``sys`` = :func:`device_rig`) for a device that has been moving
    steadily with its terminals up to now (displacement x0 [m], velocity v0 [m/s],
    acceleration a0 [m/s^2]): for a series device the spring carries the branch force,
    damper + friction + bearing drag (c_d r^2 v0) + inertia force, or ``initial_force``
    [N] where given; the sliders sit at their quasi-static radius, a free-wheeling
    flywheel turns with the shaft."""
    fw, r = device.flywheel, device.transmission.ratio
    om = r * v0
    l0 = float(fw.slider_position(om))
    y = np.zeros(sys.n_states)
    for i, name in enumerate(sys.state_names):
        if name.endswith(".slider_radius"):
            y[i] = l0
        elif name.endswith(".flywheel_speed"):
            y[i] = abs(om)
    if not device.series:
        return y
    if initial_force is None:
        if device.law == "momentum":
            m = r * r * float(fw.momentum_inertia(om))
        else:
            m = r * r * (fw.rest_inertia + fw.inertia_coefficient * l0**fw.power)
        fb = device.damping * v0 + device.friction * math.tanh(v0 / device.friction_velocity)
        fb += getattr(device, "flywheel_drag", 0.0) * r * r * v0
        xk = (fb + m * a0) / device.stiffness
    else:
        from ..errors import check_finite

        xk = check_finite("initial_force", initial_force) / device.stiffness
    node = _branch_node(sys)
    y[sys.state_names.index(f"{node}.x")] = x0 - xk
    y[sys.state_names.index(f"{node}.v")] = v0
    return y


def _branch_node(sys) -> str:
    """The node between a series device's spring and its branch."""
    return next(n for n in sys.state_names if n.endswith(".x")).rpartition(".")[0]


def device_force(
    device: Device,
    motion: Motion,
    *,
    duration: float | None = None,
    sample_rate: float = 1000.0,
    t=None,
    rtol: float = 1e-9,
    max_steps: int = 10_000_000,
    initial_force: float | None = None,
    force_only: bool = False,
) -> DeviceForceResult:
    """Predict the force of ``device`` for the terminal ``motion``.

    The device runs as a network of elements on the model core's rig
    (:func:`device_rig`): its composite element (:mod:`inerterlab.elements`) between the
    drive, which follows ``motion``, and the ground; the one-way clutch, the screw's
    backlash and the bearing drag are elements of it.

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
        Relative tolerance of the adaptive integrator (absolute tolerances: rtol times
        the rig's state scales). The rig's states are node displacements, of the size of
        the motion, while a series device's force is its spring's stiffness times the
        small difference of two of them: 1e-9 keeps that force to about 1e-6 of itself.
    max_steps : int
        Largest number of integrator steps.
    initial_force : float, optional
        Series devices: start with the spring carrying this force [N] (e.g. the measured
        force at the first sample). By default the device starts as if it had been
        moving steadily with the terminals: the spring carries damper + friction +
        flywheel bearing drag (c_d r^2 v) + inertia force at the initial velocity and
        acceleration.
    force_only : bool
        Return only the force array [N], from the rig without the energy ledger's
        observer states (the result's force to the integration tolerance: the observers
        take part in the step control); for identification and the rig simulator, which
        run a device many times.

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
    check_positive("rtol", rtol)
    sys = device_rig(device) if force_only else _ledger_rig(device)
    start = float(t_out[0])
    x0, v0, a0 = (float(q[0]) for q in motion.evaluate(t_out[:1]))
    y0 = initial_state(
        device, sys, x0, v0, a0, initial_force if device.series else None
    )
    times = t_out - start
    horizon = max(float(times[-1]), 1e-12)
    with warnings.catch_warnings():  # a sampled motion is held at its last velocity
        warnings.simplefilter("ignore", RoadTooShortWarning)
        res = sys.simulate(
            motion.drive(start), horizon, rtol=float(rtol), method="adaptive",
            max_steps=int(max_steps), x0=y0, times=times,
        )  # fmt: skip
    force = np.asarray(res.outputs["force"], dtype=float)
    if force_only:
        return force
    return _result(device, sys, motion, t_out, res, force)


def _result(device, sys, motion, t_out, res, force) -> DeviceForceResult:
    x, v, a = motion.evaluate(t_out)
    fw, r = device.flywheel, device.transmission.ratio
    Y = res.states
    names = sys.state_names
    if device.series:
        node = _branch_node(sys)
        xk = res.outputs["drive.x"] - Y[:, names.index(f"{node}.x")]
        va = Y[:, names.index(f"{node}.v")]
    else:
        xk = np.zeros_like(t_out)
        va = v
    jw = _flywheel_speed_state(sys)
    coupled = r * np.abs(va)
    omega = coupled if jw is None else Y[:, jw]
    free = np.zeros(t_out.size, bool) if jw is None else omega - coupled > 1e-9 * omega
    if device.law == "slider-dynamics":
        lpos = Y[:, [i for i, n in enumerate(names) if n.endswith(".slider_radius")][0]]
        lrate = Y[:, [i for i, n in enumerate(names) if n.endswith(".slider_rate")][0]]
        meq = r * r * (fw.rest_inertia + fw.inertia_coefficient * lpos**2)
    else:
        lpos = np.asarray(fw.slider_position(omega), dtype=float)
        lrate = np.zeros_like(t_out)
        meq = r * r * np.asarray(fw.inertia(omega), dtype=float)
    stored = _stored_energy(device, xk if device.series else x, omega, lpos, lrate)
    work, dissipated = _ledger(device, sys, res, stored)
    return DeviceForceResult(
        t=t_out,
        force=force,
        displacement=x,
        velocity=v,
        acceleration=a,
        equivalent_mass=meq,
        spring_deflection=xk,
        branch_velocity=va,
        slider_position=lpos,
        slider_rate=lrate,
        flywheel_speed=omega,
        work=work,
        dissipated=dissipated,
        stored=stored - stored[0],
        freewheeling=free,
        steps=int(res.stats.get("steps", 0) + res.stats.get("rejected", 0)),
    )


def _stored_energy(device, spring_x, omega, lpos, lrate) -> np.ndarray:
    """Spring + flywheel energy [J]: 1/2 I omega^2 (thesis law), with the slider
    springs at their quasi-static radius (momentum), or the sliders' own kinetic,
    spring and stop energy (slider-dynamics)."""
    fw = device.flywheel
    e = 0.5 * device.stiffness * spring_x**2
    if device.law == "slider-dynamics":
        c = device.slider_dynamics.coefficients(fw)
        return e + np.array(
            [
                stored_energy(l, ld, w, c[0], c[1], c[2], c[3], c[4], c[5], c[7])
                for l, ld, w in zip(lpos, lrate, omega, strict=True)
            ]
        )
    e = e + 0.5 * np.asarray(fw.inertia(omega)) * omega**2
    if device.law == "momentum":
        e = e + np.asarray(fw.spring_energy(omega))
    return e


def _ledger(device, sys, res, stored) -> tuple[np.ndarray, np.ndarray]:
    """(work done on the device [J], energy dissipated [J]) since t_out[0], from the
    ledger's observers (:func:`_ledger_rig`): the work the drive does; the dissipation
    the work done on the dampers, the friction and the bearing drag (a damper beside a
    coupled flywheel, c_d omega_f^2 behind a one-way clutch), and for
    ``slider-dynamics`` the flywheel's own losses, the work done on it less the change
    of its stored energy (the law conserves energy: tests/test_devices.py checks those
    losses against the slider law's own loss rate)."""
    names = sys.state_names

    def col(name):
        q = res.states[:, names.index(name)]
        return q - q[0]

    work = col("energy.input")
    dissipated = np.zeros_like(work)
    for name, el in zip(sys.element_names, sys.elements, strict=True):
        if el.ROLE == "dissipative":
            dissipated += col(f"energy.{name}")
        elif f"loss.{name}" in names:
            dissipated += col(f"loss.{name}")
        elif device.law == "slider-dynamics" and el.ROLE == "inertial":
            spring = 0.5 * device.stiffness * (
                res.outputs["drive.x"] - res.outputs[f"{_branch_node(sys)}.x"]
                if device.series else res.outputs["drive.x"]
            ) ** 2  # fmt: skip
            e_fw = stored - spring
            dissipated += col(f"energy.{name}") - (e_fw - e_fw[0])
    return work, dissipated


@functools.lru_cache(maxsize=32)
def _ledger_rig(device: Device):
    """:func:`device_rig` with the energy ledger's observers: the work done on each
    element and by the drive (:func:`inerterlab.systems.observers.energy`), and for a
    flywheel behind a one-way clutch its bearing drag's loss, the integral of
    c_d omega_f^2 over its own speed."""
    from ..systems.observers import Observer, energy

    sys = device_rig(device)
    obs = list(energy(sys, scale=1e-2))
    for name, el in zip(sys.element_names, sys.elements, strict=True):
        if getattr(el, "drag", 0.0) > 0.0 and f"{name}.flywheel_speed" in sys.state_names:
            sig = {f"{name}.flywheel_speed": math.sqrt(el.drag)}
            obs.append(Observer(f"loss.{name}", "square", sig, scale=1e-2))
    return sys.with_observers(obs)
