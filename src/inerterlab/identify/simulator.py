"""A simulated test rig: Appendix A test matrices run on any device model.

The thesis's measurements are not public. :func:`simulate_rig` produces the same kind
of data set from a device model: for each test of a matrix it prescribes the motion
(``triangle`` = triangular displacement, i.e. square velocity; ``sine`` = sinusoidal
displacement; amplitudes are displacement amplitudes [m] as printed in Appendix A),
computes the device force with :func:`~inerterlab.devices.device_force` and adds

* white Gaussian sensor noise on force (``noise`` [N]), displacement
  (``displacement_noise`` [m]) and velocity (``velocity_noise`` [m/s]);
* a force spike at every reversal of the terminal velocity, which the thesis
  attributes to air in the hydraulic supply and in the device (ch. 5.1.4, 5.3): a
  decaying oscillation  S s exp(-tau / w) sin(pi tau / w)  for tau >= 0 after the
  reversal, with size ``spike_size`` S [N], width ``spike_width`` w [s] and s the sign
  of the new velocity. Spikes are part of the measured force only, never of the model.

Everything random comes from ``numpy.random.default_rng(seed)``.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from importlib import resources

import numpy as np

from ..devices import Motion, device_force
from ..errors import ParameterError, check_choice, check_nonnegative, check_positive
from .data import RigDataSet, RigTest

__all__ = ["MATRICES", "TestSpec", "test_matrix", "simulate_rig"]

MATRICES = ("appendix-a1", "appendix-a2")


@dataclass(frozen=True, kw_only=True)
class TestSpec:
    """One planned rig test: signal, frequency [Hz], amplitude [m], length [s], purpose."""

    number: int
    signal: str
    frequency: float
    amplitude: float
    duration: float
    purpose: str

    __test__ = False  # not a pytest class

    @property
    def name(self) -> str:
        return f"test_{self.number:03d}_{self.signal}_{self.frequency:g}Hz_{self.amplitude:g}m.csv"

    def motion(self) -> Motion:
        if self.signal == "sine":
            return Motion.sine(frequency=self.frequency, amplitude=self.amplitude)
        if self.signal == "triangle":
            return Motion.triangle(frequency=self.frequency, amplitude=self.amplitude)
        return Motion.square(frequency=self.frequency, amplitude=self.amplitude)


def test_matrix(name: str = "appendix-a1") -> list[TestSpec]:
    """The tests of thesis Appendix A, table 1 (``appendix-a1``) or 2 (``appendix-a2``).

    Read from the transcription ``inerterlab/data/appendix_a.csv``.

    Examples
    --------
    >>> m = test_matrix("appendix-a1")
    >>> len(m), m[0].signal, m[0].duration
    (68, 'triangle', 100.0)
    """
    check_choice("matrix", name, MATRICES)
    text = resources.files("inerterlab.data").joinpath("appendix_a.csv").read_text()
    rows = [r for r in csv.DictReader(ln for ln in text.splitlines() if not ln.startswith("#"))]
    return [
        TestSpec(
            number=int(r["test"]),
            signal=r["signal"],
            frequency=float(r["frequency_hz"]),
            amplitude=float(r["amplitude_m"]),
            duration=float(r["duration_s"]),
            purpose=r["purpose"],
        )
        for r in rows
        if r["matrix"] == name
    ]


def _spikes(t, reversals, velocity_sign, size, width):
    out = np.zeros_like(t)
    for tr in reversals:
        tau = t - tr
        m = (tau >= 0) & (tau < 8 * width)
        s = velocity_sign(tr + 1e-9)
        out[m] += size * s * np.exp(-tau[m] / width) * np.sin(math.pi * tau[m] / width)
    return out


def simulate_rig(
    device,
    *,
    matrix: str | list[TestSpec] = "appendix-a1",
    sample_rate: float = 500.0,
    noise: float = 5.0,
    displacement_noise: float = 1e-6,
    velocity_noise: float = 1e-5,
    spikes: bool = True,
    spike_size: float = 300.0,
    spike_width: float = 0.02,
    seed: int = 0,
    max_duration: float | None = None,
    columns: str = "both",
    rtol: float = 1e-9,
) -> RigDataSet:
    """Run a test matrix on ``device`` and return the simulated measurements.

    Parameters
    ----------
    device : HydraulicDevice, ScrewDevice or RectifierDevice
        The "true" device.
    matrix : str or list of TestSpec
        ``appendix-a1``, ``appendix-a2`` or an explicit list of tests.
    sample_rate : float
        Samples per second [Hz].
    noise, displacement_noise, velocity_noise : float
        Standard deviations of the sensor noise [N], [m], [m/s].
    spikes : bool
        Add the direction-reversal force spikes.
    spike_size, spike_width : float
        Peak scale S [N] and width w [s] of a spike.
    seed : int
        Seed of the random generator.
    max_duration : float, optional
        Cut every record to at most this length [s] (quick runs).
    columns : {"both", "displacement", "velocity"}
        Which motion columns the files carry.
    rtol : float
        Tolerance of the device integration (tight: the data must be more exact than
        the identification can resolve).
    """
    tests = test_matrix(matrix) if isinstance(matrix, str) else list(matrix)
    if not tests:
        raise ParameterError("matrix", matrix, "a non-empty list of tests")
    fs = check_positive("sample_rate", sample_rate, "Hz")
    for name, val in (
        ("noise", noise),
        ("displacement_noise", displacement_noise),
        ("velocity_noise", velocity_noise),
        ("spike_size", spike_size),
    ):
        check_nonnegative(name, val)
    check_positive("spike_width", spike_width, "s")
    check_choice("columns", columns, ("both", "displacement", "velocity"))
    if max_duration is not None:
        check_positive("max_duration", max_duration, "s")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ParameterError("seed", seed, "an integer >= 0")
    from ..resources import check_memory

    total = sum(
        fs * (t.duration if max_duration is None else min(t.duration, max_duration)) for t in tests
    )
    # time, force, displacement, velocity and the solver's copies, then the CSV text
    check_memory(total * 16, what="simulated rig records", parameter="sample_rate", value=fs)
    rng = np.random.default_rng(seed)
    out = []
    for spec in tests:
        mot = spec.motion()
        dur = spec.duration if max_duration is None else min(spec.duration, max_duration)
        t = np.arange(int(round(dur * fs)) + 1) / fs
        clean = device_force(device, mot, t=t, rtol=rtol, force_only=True)
        xs, vs, _ = mot.evaluate(t)
        force = clean + noise * rng.standard_normal(t.size)
        if spikes and spike_size > 0:
            force = force + _spikes(
                t,
                mot.reversal_times(dur),
                lambda tt, m=mot: np.sign(m.velocity(tt)),
                spike_size,
                spike_width,
            )
        x = xs + displacement_noise * rng.standard_normal(t.size)
        v = vs + velocity_noise * rng.standard_normal(t.size)
        out.append(
            RigTest(
                name=spec.name,
                signal=spec.signal,
                frequency=spec.frequency,
                amplitude=spec.amplitude,
                purpose=spec.purpose,
                t=t,
                force=force,
                displacement=None if columns == "velocity" else x,
                velocity=None if columns == "displacement" else v,
            )
        )
    meta = {
        "device": device.kind,
        "flywheel": device.flywheel.name,
        "law": device.law,
        "stiffness": device.stiffness,
        "damping": device.damping,
        "friction": device.friction,
        "sample_rate": fs,
        "noise": noise,
        "spikes": bool(spikes),
        "spike_size": spike_size,
        "spike_width": spike_width,
        "seed": seed,
    }
    return RigDataSet(tests=tuple(out), source="simulated", meta=meta)
