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
    A measured record (t_i, x_i, v_i), interpolated by the cubic Hermite polynomial
    through the displacements with the velocities as slopes, so v(t) = dx/dt exactly and
    x, v pass through every sample. The acceleration is taken at the samples from the
    fourth-order formula a_i = 2 (x_{i+1} - 2 x_i + x_{i-1}) / h^2 - (v_{i+1} - v_{i-1}) / (2 h)
    (exact for quartics; the Hermite's own second derivative is only second order and
    discontinuous at the samples) and interpolated linearly in between.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba as nb
import numpy as np

from ..errors import ParameterError, check_choice, check_nonnegative, check_positive
from ..excitation import Excitation

__all__ = ["Motion", "MotionDrive", "SIGNALS", "motion_from_samples"]

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
            vn = np.concatenate([vn, _node_acceleration(tn, xn, vn)])
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

    def drive(self, start: float = 0.0) -> MotionDrive:
        """The motion from time ``start`` [s] on as the drive of a core rig
        (:func:`inerterlab.systems.rig`), whose time 0 is ``start``: moving as the motion
        moves there (no velocity jump at the start)."""
        return MotionDrive(motion=self, start=float(start))

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


@dataclass(frozen=True, kw_only=True, eq=False)
class MotionDrive(Excitation):
    """A :class:`Motion` from ``start`` [s] on, as road segments of the model core
    (:mod:`inerterlab.excitation`): a sine is one sine segment; the square and triangle
    motions are pieces of constant acceleration (the straight flanks and the parabolic
    reversals) and a sampled motion its cubic Hermite pieces, both written as measured
    drive pieces (kind 2), so the integrator runs through their edges without a
    restart."""

    motion: Motion
    start: float = 0.0
    name = "motion"
    quarter_car_kernels = False

    def _at_start(self):
        x, v, _ = self.motion.evaluate(np.array([self.start]))
        return float(x[0]), float(v[0])

    def initial_road(self, horizon: float) -> float:
        return self._at_start()[0]

    def initial_road_velocity(self, horizon: float) -> float:
        return self._at_start()[1]

    def end_time(self) -> float:
        if self.motion.signal == "samples":
            return float(self.motion.samples[0][-1]) - self.start
        return math.inf

    def describe(self) -> dict:
        return {"input": "motion", "signal": self.motion.signal, "start": self.start}

    def segments(self, horizon: float) -> np.ndarray:
        m, t0 = self.motion, self.start
        if m.signal == "sine":
            w = 2.0 * math.pi * m.frequency
            return np.array([[0.0, horizon, 1.0, 0.0, 0.0, m.amplitude, w, w * t0]])
        if m.signal == "samples":  # the measured drive's pieces, from ``start`` on
            from ..excitation import DriveSeries

            ts, xs, vs = m.samples
            _, _, _, _, vn = m.kernel_args()
            first = float(ts[0])
            drive = DriveSeries(time=ts - first, displacement=xs, velocity=vs,
                                acceleration=vn[ts.size :])  # fmt: skip
            segs = drive.segments(max(t0 - first + horizon, float(ts[-1] - first)))
            segs[:, :2] += first - t0
            segs = segs[(segs[:, 1] > 0.0) & (segs[:, 0] < horizon)]
            if segs[0, 0] > 0.0:  # before the first sample: its velocity
                lead = [0.0, segs[0, 0], 0.0, xs[0] - vs[0] * segs[0, 0], vs[0], 0, 0, 0, 0]
                segs = np.vstack([np.array([lead]), segs])
            elif segs[0, 0] < 0.0:  # restate the first piece about time 0
                _restart_piece(segs[0])
            segs[-1, 1] = horizon
            return segs
        # square and triangle: the flanks and the ramps, each of constant acceleration
        p, tau = 1.0 / m.frequency, m.edge_time
        k0 = math.floor(t0 / p)
        edges = [0.0]
        k = k0
        while True:
            for c in (0.25, 0.75):
                for d in ((-0.5 * tau, 0.5 * tau) if tau > 0 else (0.0,)):
                    te = (k + c) * p + d - t0
                    if 0.0 < te < horizon:
                        edges.append(te)
            if (k + 1) * p - t0 >= horizon:
                break
            k += 1
        edges = np.array(sorted(set(edges)) + [horizon])
        ta, tb = edges[:-1], edges[1:]
        x, v, _ = m.evaluate(ta + t0)
        _, _, a = m.evaluate(0.5 * (ta + tb) + t0)
        seg = np.zeros((ta.size, 9))
        seg[:, 0], seg[:, 1], seg[:, 2] = ta, tb, 2.0
        seg[:, 3], seg[:, 4], seg[:, 5] = x, v, 0.5 * a
        seg[:, 7], seg[:, 8] = a, a
        return seg


def _restart_piece(seg) -> None:
    """Restate a road piece (linear or kind-2 cubic) that starts before time 0 as one
    starting at 0 with the same displacement, velocity and acceleration."""
    u0 = -seg[0]
    if seg[2] == 0.0:
        seg[3] += seg[4] * u0
    else:
        x0, c1, c2, c3 = seg[3], seg[4], seg[5], seg[6]
        seg[3] = x0 + u0 * (c1 + u0 * (c2 + u0 * c3))
        seg[4] = c1 + u0 * (2.0 * c2 + 3.0 * u0 * c3)
        seg[5] = c2 + 3.0 * c3 * u0
        seg[7] += (seg[8] - seg[7]) * u0 / (seg[1] - seg[0])
    seg[0] = 0.0


def _node_acceleration(t, x, v):
    """Acceleration [m/s^2] at the samples, from the velocity samples alone: the
    five-point central difference (fourth order on uniform spacing), its one-sided
    fourth-order forms at the two samples next to each end.

    The displacement is not used: a difference that reads it (the second difference
    2 (x+ - 2 x + x-) / h^2) multiplies displacement sensor noise by about 5/h^2, 1.2 m/s^2
    per micrometre at 500 Hz, which an inertance then turns into force noise; the
    velocity stencil multiplies velocity noise by about 0.95/h (docs/decisions.md, "The
    sampled acceleration from the velocity channel")."""
    a = np.empty_like(v)
    n = t.size
    if n < 5:
        a[:] = (v[-1] - v[0]) / (t[-1] - t[0])
        return a
    h = 0.25 * (t[4:] - t[:-4])  # the mean spacing over each five-sample stencil
    a[2:-2] = (v[:-4] - 8.0 * v[1:-3] + 8.0 * v[3:-1] - v[4:]) / (12.0 * h)
    h0 = 0.25 * (t[4] - t[0])
    h1 = 0.25 * (t[-1] - t[-5])
    w0 = np.array([-25.0, 48.0, -36.0, 16.0, -3.0]) / 12.0
    w1 = np.array([-3.0, -10.0, 18.0, -6.0, 1.0]) / 12.0
    a[0] = (w0 @ v[:5]) / h0
    a[1] = (w1 @ v[:5]) / h0
    a[-1] = -(w0 @ v[-1:-6:-1]) / h1
    a[-2] = -(w1 @ v[-1:-6:-1]) / h1
    return a


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
    # sampled: cubic Hermite through (t_i, x_i) with slopes v_i (vn holds v_i, then a_i)
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
    x0, x1, m0, m1 = xn[i], xn[i + 1], vn[i] * h, vn[i + 1] * h
    s2, s3 = s * s, s * s * s
    x = (
        (2 * s3 - 3 * s2 + 1) * x0
        + (s3 - 2 * s2 + s) * m0
        + (-2 * s3 + 3 * s2) * x1
        + (s3 - s2) * m1
    )
    dx = (
        (6 * s2 - 6 * s) * x0
        + (3 * s2 - 4 * s + 1) * m0
        + (-6 * s2 + 6 * s) * x1
        + (3 * s2 - 2 * s) * m1
    )
    acc = (1.0 - s) * vn[n + i] + s * vn[n + i + 1]
    return x, dx / h, acc


@nb.njit(cache=True)
def _evaluate_many(t, kind, par, tn, xn, vn):
    n = t.shape[0]
    x = np.empty(n)
    v = np.empty(n)
    a = np.empty(n)
    for i in range(n):
        x[i], v[i], a[i] = motion_at(t[i], kind, par, tn, xn, vn)
    return x, v, a
