"""Prescribed terminal motions: sine, square velocity, triangle displacement, samples.

A :class:`Motion` describes the relative displacement x(t) [m] of the two terminals,
its velocity v(t) [m/s] and acceleration a(t) [m/s^2], all available at any time, so a
device model can be integrated with its own step control.

Signals
-------
``sine``
    x = A sin(2 pi f t): the velocity is v = A omega cos(omega t) (thesis (5.5)).
``triangle``
    Triangular displacement of amplitude A, x(0) = 0 rising: the velocity is a square
    wave of amplitude V = 4 A f (thesis 5.1.2 "triangular command displacement").
``square``
    Square velocity of amplitude V (thesis 5.1.3.1 "square command velocity"); the
    same motion as ``triangle`` with A = V / (4 f).

A real actuator cannot reverse its velocity in zero time, so both square-velocity
forms reverse along a linear velocity ramp of duration ``edge_time`` [s] centred on
the ideal switching instant (default 2 % of the period). Outside the ramps the
displacement equals the ideal triangle; inside, it is the matching parabola.

``samples``
    A measured record (t_i, x_i, v_i). The acceleration a_i and jerk j_i at the samples
    come from the velocities alone (seven-point central differences, sixth order). The
    velocity between samples is the quintic Hermite through (v_i, a_i, j_i) at both
    ends of the interval and the acceleration its derivative, so both are smooth and
    pass through the samples; the displacement is the quintic Hermite through
    (x_i, v_i, a_i). On a 10 Hz sine sampled at 200 Hz, x, v and a are within 3e-9, 3e-7
    and 7e-6 of their amplitudes (tests/test_devices.py). Noise on the displacement samples reaches
    x only: a second difference of x would multiply 1e-6 m of noise into about
    0.2 m/s^2 of acceleration at 200 Hz (docs/decisions.md, "Sampled motions").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba as nb
import numpy as np

from ..errors import ParameterError, check_choice, check_nonnegative, check_positive

__all__ = ["Motion", "SIGNALS", "motion_from_samples"]

SIGNALS = ("sine", "square", "triangle", "samples")
_KIND = {"sine": 0, "square": 1, "triangle": 1, "samples": 2}


@dataclass(frozen=True, kw_only=True, eq=False)
class Motion:
    """A prescribed relative terminal motion.

    Build it with :meth:`sine`, :meth:`square`, :meth:`triangle` or
    :func:`motion_from_samples`.

    Parameters
    ----------
    signal : str
        One of ``SIGNALS``.
    frequency : float
        f [Hz] (analytic signals).
    amplitude : float
        Displacement amplitude A [m] (analytic signals).
    edge_time : float
        Duration of the velocity reversal ramp [s] (square and triangle).
    samples : tuple of arrays or None
        (t [s], x [m], v [m/s]) for ``samples``.

    Examples
    --------
    >>> m = Motion.square(frequency=0.5, velocity_amplitude=0.01)
    >>> round(m.amplitude, 6), round(float(m.velocity(0.1)), 6)
    (0.005, 0.01)
    """

    signal: str
    frequency: float = 1.0
    amplitude: float = 0.0
    edge_time: float = 0.0
    samples: tuple | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        check_choice("signal", self.signal, SIGNALS)
        if self.signal != "samples":
            check_positive("frequency", self.frequency, "Hz")
            check_nonnegative("amplitude", self.amplitude, "m")
            e = check_nonnegative("edge_time", self.edge_time, "s")
            if self.signal != "sine" and not e < 0.5 / self.frequency:
                raise ParameterError("edge_time", e, f"a time in [0, {0.5 / self.frequency:g}) s")

    # -- constructors --------------------------------------------------------------
    @classmethod
    def sine(
        cls,
        *,
        frequency: float,
        amplitude: float | None = None,
        velocity_amplitude: float | None = None,
    ) -> Motion:
        """x = A sin(2 pi f t); give A [m] or the velocity amplitude V = A 2 pi f [m/s]."""
        f = check_positive("frequency", frequency, "Hz")
        a = _amplitude(amplitude, velocity_amplitude, 2.0 * math.pi * f)
        return cls(signal="sine", frequency=f, amplitude=a)

    @classmethod
    def triangle(
        cls,
        *,
        frequency: float,
        amplitude: float | None = None,
        velocity_amplitude: float | None = None,
        edge_time: float | None = None,
    ) -> Motion:
        """Triangular displacement, amplitude A [m] or square velocity amplitude V = 4 A f."""
        f = check_positive("frequency", frequency, "Hz")
        a = _amplitude(amplitude, velocity_amplitude, 4.0 * f)
        e = 0.02 / f if edge_time is None else edge_time
        return cls(signal="triangle", frequency=f, amplitude=a, edge_time=e)

    @classmethod
    def square(
        cls,
        *,
        frequency: float,
        velocity_amplitude: float | None = None,
        amplitude: float | None = None,
        edge_time: float | None = None,
    ) -> Motion:
        """Square velocity of amplitude V [m/s] (or displacement amplitude A = V / (4 f))."""
        f = check_positive("frequency", frequency, "Hz")
        a = _amplitude(amplitude, velocity_amplitude, 4.0 * f)
        e = 0.02 / f if edge_time is None else edge_time
        return cls(signal="square", frequency=f, amplitude=a, edge_time=e)

    # -- evaluation ----------------------------------------------------------------
    @property
    def velocity_amplitude(self) -> float:
        """Peak velocity [m/s] of an analytic signal."""
        if self.signal == "sine":
            return self.amplitude * 2.0 * math.pi * self.frequency
        if self.signal in ("square", "triangle"):
            return 4.0 * self.amplitude * self.frequency
        return float(np.max(np.abs(self.samples[2])))

    def kernel_args(self):
        """(kind, params[4], t_nodes, x_nodes, v_nodes) for the compiled kernels.

        Built once per motion (an identification drives the same motion thousands of
        times); the kernels only read the arrays (not flagged read-only: numba would
        compile other specialisations for read-only arrays).
        """
        cached = self.__dict__.get("_kernel_args")
        if cached is None:
            cached = self._build_kernel_args()
            self.__dict__["_kernel_args"] = cached  # frozen dataclass: bypass __setattr__
        return cached

    def _build_kernel_args(self):
        kind = _KIND[self.signal]
        par = np.array(
            [self.amplitude, self.frequency, self.edge_time, 0.0] if kind != 2 else [0.0] * 4,
            dtype=float,
        )
        if kind == 2:
            tn, xn, vn = (np.ascontiguousarray(a, dtype=float) for a in self.samples)
            vn = np.concatenate([vn, *_node_derivatives(tn, vn)])
        else:
            tn = xn = vn = np.zeros(1)
        return kind, par, tn, xn, vn

    def evaluate(self, t):
        """(x [m], v [m/s], a [m/s^2]) at times ``t`` [s]."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        kind, par, tn, xn, vn = self.kernel_args()
        return _evaluate_many(t, kind, par, tn, xn, vn)

    def displacement(self, t):
        """x(t) [m]."""
        return self._one(t, 0)

    def velocity(self, t):
        """v(t) [m/s]."""
        return self._one(t, 1)

    def acceleration(self, t):
        """a(t) [m/s^2]."""
        return self._one(t, 2)

    def _one(self, t, i):
        scalar = np.ndim(t) == 0
        out = self.evaluate(t)[i]
        return float(out[0]) if scalar else out

    def reversal_times(self, duration: float) -> np.ndarray:
        """Instants [s] in [0, duration] at which the velocity changes sign."""
        if self.signal == "sine":
            p = 1.0 / self.frequency
            k = np.arange(0, int(duration / p * 2) + 2)
            t = (0.25 + 0.5 * k) * p
        elif self.signal in ("square", "triangle"):
            p = 1.0 / self.frequency
            k = np.arange(0, int(duration / p * 2) + 2)
            t = (0.25 + 0.5 * k) * p
        else:
            ts, _, vs = self.samples
            s = np.sign(vs)
            idx = np.nonzero(s[1:] * s[:-1] < 0)[0]
            t = 0.5 * (ts[idx] + ts[idx + 1])
        return t[(t >= 0) & (t <= duration)]


def _node_derivatives(t, v):
    """(a, j): acceleration [m/s^2] and jerk [m/s^3] at the samples from the velocities
    alone, by seven-point central differences (sixth order on uniform spacing), five
    and three points nearer the ends and linear extrapolation at them. The displacements are
    left out: their second difference multiplies the displacement noise by about
    5 / h^2 (0.2 m/s^2 for 1e-6 m at 200 Hz)."""
    n = t.size
    a = np.empty_like(v)
    j = np.zeros_like(v)
    if n < 3:
        a[:] = (v[-1] - v[0]) / (t[-1] - t[0])
        return a, j
    hl, hr = t[1:-1] - t[:-2], t[2:] - t[1:-1]
    a[1:-1] = (v[2:] - v[:-2]) / (hl + hr)
    j[1:-1] = 2.0 * ((v[2:] - v[1:-1]) / hr - (v[1:-1] - v[:-2]) / hl) / (hl + hr)
    if n >= 5:
        h = 0.25 * (t[4:] - t[:-4])
        a[2:-2] = (-v[4:] + 8.0 * v[3:-1] - 8.0 * v[1:-3] + v[:-4]) / (12.0 * h)
        j[2:-2] = (-v[4:] + 16.0 * v[3:-1] - 30.0 * v[2:-2] + 16.0 * v[1:-3] - v[:-4]) / (
            12.0 * h * h
        )
    if n >= 7:  # seven points (sixth order) inside
        h = (t[6:] - t[:-6]) / 6.0
        a[3:-3] = (
            v[6:] - 9.0 * v[5:-1] + 45.0 * v[4:-2] - 45.0 * v[2:-4] + 9.0 * v[1:-5] - v[:-6]
        ) / (60.0 * h)
        j[3:-3] = (
            2.0 * (v[6:] + v[:-6])
            - 27.0 * (v[5:-1] + v[1:-5])
            + 270.0 * (v[4:-2] + v[2:-4])
            - 490.0 * v[3:-3]
        ) / (180.0 * h * h)
    for arr in (a, j):  # linear extrapolation to the ends
        arr[0] = 2.0 * arr[1] - arr[2]
        arr[-1] = 2.0 * arr[-2] - arr[-3]
    return a, j


def _amplitude(amplitude, velocity_amplitude, factor) -> float:
    if (amplitude is None) == (velocity_amplitude is None):
        raise ParameterError(
            "amplitude",
            amplitude,
            "exactly one of amplitude [m] and velocity_amplitude [m/s]",
        )
    if amplitude is not None:
        return check_nonnegative("amplitude", amplitude, "m")
    return check_nonnegative("velocity_amplitude", velocity_amplitude, "m/s") / factor


def motion_from_samples(time, displacement, velocity) -> Motion:
    """A :class:`Motion` through measured samples.

    Parameters
    ----------
    time : array
        Strictly increasing sample times [s].
    displacement, velocity : array
        x [m] and v [m/s] at those times (see :mod:`inerterlab.identify.filters` to
        derive one from the other).
    """
    t = np.asarray(time, dtype=float)
    x = np.asarray(displacement, dtype=float)
    v = np.asarray(velocity, dtype=float)
    if t.ndim != 1 or t.size < 2 or x.shape != t.shape or v.shape != t.shape:
        raise ParameterError("samples", f"shapes {t.shape}, {x.shape}, {v.shape}", "equal 1-D")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise ParameterError("samples", "non-finite value", "finite numbers")
    if np.any(np.diff(t) <= 0):
        raise ParameterError("time", "not strictly increasing", "strictly increasing times")
    return Motion(signal="samples", samples=(t, x, v))


@nb.njit(cache=True)
def motion_at(t, kind, par, tn, xn, vn):
    """(x, v, a) of a motion at time ``t`` (compiled; see :class:`Motion`)."""
    if kind == 0:
        a_, f = par[0], par[1]
        w = 2.0 * math.pi * f
        s, c = math.sin(w * t), math.cos(w * t)
        return a_ * s, a_ * w * c, -a_ * w * w * s
    if kind == 1:
        amp, f, tau = par[0], par[1], par[2]
        p = 1.0 / f
        vel = 4.0 * amp * f
        u = t - p * math.floor(t / p)  # phase time in [0, p)
        # ideal triangle: rising on [0, p/4) and [3p/4, p), falling between
        if u < 0.25 * p:
            x, v = vel * u, vel
        elif u < 0.75 * p:
            x, v = amp - vel * (u - 0.25 * p), -vel
        else:
            x, v = -amp + vel * (u - 0.75 * p), vel
        acc = 0.0
        # velocity ramps of duration tau centred on the switches at p/4 (+V -> -V) and
        # 3p/4 (-V -> +V); x is the parabola that joins the ideal triangle at both ends
        for k in range(2):
            tsw = 0.25 * p if k == 0 else 0.75 * p
            s_before = 1.0 if k == 0 else -1.0
            du = u - tsw
            if tau > 0.0 and abs(du) < 0.5 * tau:
                v = -2.0 * s_before * vel * du / tau
                x = s_before * amp - s_before * vel * (0.25 * tau + du * du / tau)
                acc = -2.0 * s_before * vel / tau
        return x, v, acc
    # sampled (vn holds v_i, then a_i, then j_i)
    n = tn.shape[0]
    if t <= tn[0]:
        return xn[0] + vn[0] * (t - tn[0]), vn[0], vn[n]
    if t >= tn[n - 1]:
        return xn[n - 1] + vn[n - 1] * (t - tn[n - 1]), vn[n - 1], vn[2 * n - 1]
    i = np.searchsorted(tn, t) - 1
    if i < 0:
        i = 0
    h = tn[i + 1] - tn[i]
    s = (t - tn[i]) / h
    # quintic Hermites in s = (t - t_i) / h: x through (x_i, v_i, a_i) and v through
    # (v_i, a_i, j_i); a = v'. Each is f0 + m0 s + c0 s^2 / 2 + k3 s^3 + k4 s^4 + k5 s^5
    # with k3..k5 from f, f' and f'' at s = 1 (_quintic)
    x = _quintic(s, xn[i], xn[i + 1], vn[i] * h, vn[i + 1] * h,
                 vn[n + i] * h * h, vn[n + i + 1] * h * h)[0]  # fmt: skip
    v, dv = _quintic(s, vn[i], vn[i + 1], vn[n + i] * h, vn[n + i + 1] * h,
                     vn[2 * n + i] * h * h, vn[2 * n + i + 1] * h * h)  # fmt: skip
    return x, v, dv / h


@nb.njit(cache=True, inline="always")
def _quintic(s, f0, f1, m0, m1, c0, c1):
    """(f, df/ds) at s of the quintic with f, df/ds, d2f/ds2 = (f0, m0, c0) at s = 0 and
    (f1, m1, c1) at s = 1."""
    d = f1 - f0
    k3 = 10.0 * d - 6.0 * m0 - 4.0 * m1 - 1.5 * c0 + 0.5 * c1
    k4 = -15.0 * d + 8.0 * m0 + 7.0 * m1 + 1.5 * c0 - c1
    k5 = 6.0 * d - 3.0 * m0 - 3.0 * m1 - 0.5 * c0 + 0.5 * c1
    f = f0 + s * (m0 + s * (0.5 * c0 + s * (k3 + s * (k4 + s * k5))))
    df = m0 + s * (c0 + s * (3.0 * k3 + s * (4.0 * k4 + s * 5.0 * k5)))
    return f, df


@nb.njit(cache=True)
def _evaluate_many(t, kind, par, tn, xn, vn):
    n = t.shape[0]
    x = np.empty(n)
    v = np.empty(n)
    a = np.empty(n)
    for i in range(n):
        x[i], v[i], a[i] = motion_at(t[i], kind, par, tn, xn, vn)
    return x, v, a
