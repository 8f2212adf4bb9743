"""ISO 2631-1 frequency weightings and whole-body vibration values.

Each weighting of ISO 2631-1:1997 (Annex A, Table A.1 of the transfer-function
parameters; the same definitions are repeated in ISO 8041) is a product of four analog
filters in p = j 2 pi f, with w_i = 2 pi f_i:

    band limiting, high pass  Hh = 1 / (1 + sqrt2 w1/p + (w1/p)^2)
    band limiting, low pass   Hl = 1 / (1 + sqrt2 p/w2 + (p/w2)^2)
    a-v transition            Ht = (1 + p/w3) / (1 + p/(Q4 w4) + (p/w4)^2)
    upward step               Hs = (1 + p/(Q5 w5) + (p/w5)^2) / (1 + p/(Q6 w6) + (p/w6)^2) (w5/w6)^2

A frequency given as ``None`` stands for infinity (the factor drops out). The step is
written with the (w5/w6)^2 factor, so it rises from (w5/w6)^2 at low frequency to 1.

Values computed here (ISO 2631-1 clauses 6 to 8 and 9 for motion sickness):

* weighted RMS a_w, the vibration total value a_v = sqrt(sum (k_i a_wi)^2) with the
  axis multipliers k_i of :data:`AXIS_MULTIPLIERS`;
* the vibration dose value VDV = (int a_w^4 dt)^(1/4) [m/s^1.75];
* the motion sickness dose value MSDV = (int a_w^2 dt)^(1/2) [m/s^1.5], a_w weighted
  with Wf;
* the crest factor max|a_w| / a_w and the maximum transient vibration value (running
  RMS with the linear 1 s window, MTVV).

The integrals over a sampled record (the RMS, VDV, MSDV) take the trapezoidal rule over
its span T = (n - 1)/fs: second order in the sampling interval, and exact for a periodic
signal over whole periods (the mean of the n squares would be off by about 1/n). These
are the package's one set of statistics of sampled signals (:func:`inerterlab.metrics.series_metrics` and the design
studies' vehicle runs use them); the simulations integrate the same quantities as
observer states instead.

Discrete filtering uses the exact discretisation of the analog filter for a signal
linear between samples (first-order hold, the default) or the bilinear transform, and
starts from rest: the analog filter's states are zero at the first sample (nothing is
assumed before it). This is the package's one Wk and its one filter of sampled
signals: ``inerterlab.metrics`` (its Wk weighting, state space and
``weighted_acceleration``) and the quarter car's ride observers read them from here.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .errors import ParameterError, check_choice, check_positive

__all__ = [
    "Weighting",
    "WEIGHTINGS",
    "AXIS_MULTIPLIERS",
    "weighting",
    "weighting_magnitude",
    "weight",
    "rms",
    "weighted_rms",
    "vibration_total_value",
    "vibration_dose_value",
    "motion_sickness_dose_value",
    "crest_factor",
    "running_rms",
    "mtvv",
]


@dataclass(frozen=True, kw_only=True)
class Weighting:
    """Parameters of one ISO 2631-1 weighting (frequencies [Hz], ``None`` = infinite).

    Parameters
    ----------
    name : str
        "Wk", "Wd", ...
    f1, f2 : float or None
        Corner frequencies of the band-limiting high pass and low pass.
    f3, f4, q4 : float or None
        a-v transition: zero at f3, pole pair at f4 with quality q4.
    f5, q5, f6, q6 : float or None
        Upward step: zero pair at f5 (q5), pole pair at f6 (q6).
    """

    name: str
    f1: float | None = None
    f2: float | None = None
    f3: float | None = None
    f4: float | None = None
    q4: float | None = None
    f5: float | None = None
    q5: float | None = None
    f6: float | None = None
    q6: float | None = None

    def __post_init__(self) -> None:
        for key in ("f1", "f2", "f3", "f4", "q4", "f5", "q5", "f6", "q6"):
            v = getattr(self, key)
            if v is not None:
                check_positive(f"{self.name}.{key}", v)
        if self.f4 is not None and self.q4 is None:
            raise ParameterError(f"{self.name}.q4", None, "a quality factor > 0 when f4 is set")
        if (self.f5 is None) != (self.f6 is None):
            raise ParameterError(f"{self.name}.f5", self.f5, "f5 and f6 both set or both None")
        if self.f5 is not None and (self.q5 is None or self.q6 is None):
            raise ParameterError(f"{self.name}.q5", self.q5, "q5 and q6 > 0 when f5, f6 are set")

    # -- the standard's formula ---------------------------------------------------------
    def response(self, freq_hz):
        """Complex weighting at ``freq_hz`` [Hz], evaluated term by term as written."""
        f = np.asarray(freq_hz, dtype=float)
        p = 2j * math.pi * f
        h = np.ones_like(p)
        with np.errstate(divide="ignore", invalid="ignore"):
            if self.f1 is not None:
                w1 = 2 * math.pi * self.f1
                h = h / (1.0 + math.sqrt(2.0) * w1 / p + (w1 / p) ** 2)
            if self.f2 is not None:
                w2 = 2 * math.pi * self.f2
                h = h / (1.0 + math.sqrt(2.0) * p / w2 + (p / w2) ** 2)
        num = 1.0 if self.f3 is None else 1.0 + p / (2 * math.pi * self.f3)
        if self.f4 is None:
            den = 1.0
        else:
            w4 = 2 * math.pi * self.f4
            den = 1.0 + p / (self.q4 * w4) + (p / w4) ** 2
        h = h * num / den
        if self.f5 is not None:
            w5, w6 = 2 * math.pi * self.f5, 2 * math.pi * self.f6
            h = (
                h
                * (1.0 + p / (self.q5 * w5) + (p / w5) ** 2)
                / (1.0 + p / (self.q6 * w6) + (p / w6) ** 2)
                * (w5 / w6) ** 2
            )
        return np.where(f == 0, 0.0 if self.f1 is not None else h, h)

    def magnitude(self, freq_hz):
        """|W(f)| [-]."""
        return np.abs(self.response(freq_hz))

    # -- filter forms -------------------------------------------------------------------
    def sections(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """Analog second-order sections (b, a), coefficients of s^2, s, 1."""
        out = []
        r2 = math.sqrt(2.0)
        if self.f1 is not None:
            w1 = 2 * math.pi * self.f1
            out.append((np.array([1.0, 0.0, 0.0]), np.array([1.0, r2 * w1, w1 * w1])))
        if self.f2 is not None:
            w2 = 2 * math.pi * self.f2
            out.append((np.array([0.0, 0.0, w2 * w2]), np.array([1.0, r2 * w2, w2 * w2])))
        if self.f4 is not None:
            w4 = 2 * math.pi * self.f4
            a = np.array([1.0, w4 / self.q4, w4 * w4])
            if self.f3 is None:
                b = np.array([0.0, 0.0, w4 * w4])
            else:
                w3 = 2 * math.pi * self.f3
                b = np.array([0.0, w4 * w4 / w3, w4 * w4])
            out.append((b, a))
        elif self.f3 is not None:
            raise ParameterError(f"{self.name}.f4", None, "a pole pair f4 when f3 is set")
        if self.f5 is not None:
            w5, w6 = 2 * math.pi * self.f5, 2 * math.pi * self.f6
            # (w5/w6)^2 folded in: the ratio of monic quadratics
            out.append(
                (np.array([1.0, w5 / self.q5, w5 * w5]), np.array([1.0, w6 / self.q6, w6 * w6]))
            )
        return out

    def state_space(self):
        """(A, B, C, D) of the cascade of :meth:`sections`.

        Each section (b2 s^2 + b1 s + b0)/(s^2 + a1 s + w0^2) has the states
        q1 = w0^2/den u and q2 = q1'/w0, both of the size of the input, so the matrices
        stay well scaled from 0.08 Hz to 100 Hz.
        """
        A = np.zeros((0, 0))
        B = np.zeros((0, 1))
        C = np.zeros((1, 0))
        D = np.ones((1, 1))
        for (b2, b1, b0), (_, a1, a0) in self.sections():
            w0 = math.sqrt(a0)
            a2 = np.array([[0.0, w0], [-w0, -a1]])
            bb = np.array([[0.0], [w0]])
            c2 = np.array([[(b0 - b2 * a0) / a0, (b1 - b2 * a1) / w0]])
            d2 = np.array([[b2]])
            n1, n2 = A.shape[0], 2
            An = np.zeros((n1 + n2, n1 + n2))
            An[:n1, :n1] = A
            An[n1:, :n1] = bb @ C
            An[n1:, n1:] = a2
            A = An
            B = np.vstack([B, bb @ D])
            C = np.hstack([d2 @ C, c2])
            D = d2 @ D
        return A, B, C, D

    def hold_response(self, signal, dt: float) -> np.ndarray:
        """Weighted signal of the uniform samples ``signal`` dt [s] apart, linear between
        them (first-order hold), the filter at rest at the first sample: the exact
        discretisation x_{i+1} = Ad x_i + Bd0 u_i + Bd1 u_{i+1} of the cascade's state
        space (:meth:`state_space`), run compiled. The filter of sampled signals of
        :meth:`filter` (``"foh"``), :func:`inerterlab.metrics.weighted_acceleration` and
        the quarter car's metrics from samples."""
        from .systems._integrate import foh_response

        Ad, Bd0, Bd1, C, D = _hold_tables(self, float(dt))
        out = np.empty(np.size(signal))
        foh_response(Ad, Bd0, Bd1, C, D, np.ascontiguousarray(signal, float), out)
        return out

    def filter(self, signal, fs: float, method: str = "foh") -> np.ndarray:
        """Weighted signal of ``signal`` sampled at ``fs`` [Hz]; the filter starts from
        rest at the first sample.

        From rest: every state of the analog filter is zero at t = 0, when the signal
        starts at its first sample (a step from 0 to x[0] if x[0] != 0), as an analog
        weighting switched on at the first sample would see it; nothing is assumed
        before t = 0. ``"foh"``: exact discretisation of the whole cascade for a signal
        linear between samples (:meth:`hold_response`); ``"bilinear"``: the Tustin
        transform of the whole cascade (the same as per section, without prewarping),
        run in modal form, one first-order complex recursion per pole, so no
        high-order polynomial is ever formed, each mode started from the discrete state
        that is the analog filter at rest, xi_0 = -(h/2) B x[0].
        """
        from scipy.signal import lfilter

        fs = check_positive("fs", fs, "Hz")
        check_choice("method", method, ("foh", "bilinear"))
        x = np.asarray(signal, dtype=float)
        if x.ndim != 1 or x.size < 2 or not np.all(np.isfinite(x)):
            raise ParameterError(
                "signal", f"array of shape {x.shape}", "a finite 1-D array of >= 2 samples"
            )
        if method == "foh":
            return self.hold_response(x, 1.0 / fs)
        A, B, C, D = self.state_space()
        n = A.shape[0]
        h = 1.0 / fs
        # Tustin, state xi_k = (I - hA/2) x(t_k) - (h/2) B u_k
        ima = np.eye(n) - 0.5 * h * A
        Ad = np.linalg.solve(ima, np.eye(n) + 0.5 * h * A)
        Bd = np.linalg.solve(ima, h * B)
        Cd = np.linalg.solve(ima.T, C.T).T
        Dd = D + 0.5 * C @ Bd
        xi0 = -0.5 * h * B[:, 0] * x[0]
        lam, V = np.linalg.eig(Ad)
        b = np.linalg.solve(V, Bd[:, 0])
        s0 = np.linalg.solve(V, xi0.astype(complex))
        c = Cd[0] @ V
        y = Dd[0, 0] * x
        done = np.zeros(lam.size, bool)
        for i in range(lam.size):  # complex pairs: one recursion and twice its real part
            if done[i]:
                continue
            mode, _ = lfilter([0.0, b[i]], [1.0, -lam[i]], x.astype(complex), zi=[s0[i]])
            mode = c[i] * mode
            if abs(lam[i].imag) > 0:
                gap = np.abs(lam - lam[i].conj())
                gap[done] = np.inf
                gap[i] = np.inf
                done[int(np.argmin(gap))] = True
                y = y + 2.0 * mode.real
            else:
                y = y + mode.real
            done[i] = True
        return y


@functools.lru_cache(maxsize=32)
def _hold_tables(w: Weighting, dt: float):
    """(Ad, Bd0, Bd1, C, D) of :meth:`Weighting.hold_response` for samples dt [s]
    apart: the exponential of [[A dt, B dt, 0], [0, 0, 1], [0, 0, 0]] (Bd1 its last
    column, Bd0 its middle one less Bd1), kept for the last few (weighting, dt)."""
    from scipy.linalg import expm

    A, B, C, D = w.state_space()
    n = A.shape[0]
    M = np.zeros((n + 2, n + 2))
    M[:n, :n] = A * dt
    M[:n, n] = np.ravel(B) * dt
    M[n, n + 1] = 1.0
    E = expm(M)
    Bd1 = np.ascontiguousarray(E[:n, n + 1])
    return (np.ascontiguousarray(E[:n, :n]), np.ascontiguousarray(E[:n, n]) - Bd1, Bd1,
            np.ascontiguousarray(np.ravel(C), dtype=float), float(np.ravel(D)[0]))  # fmt: skip


#: ISO 2631-1:1997 Annex A, Table A.1 (parameters of the weighting transfer functions)
WEIGHTINGS = {
    "Wk": Weighting(
        name="Wk", f1=0.4, f2=100.0, f3=12.5, f4=12.5, q4=0.63, f5=2.37, q5=0.91, f6=3.35, q6=0.91
    ),
    "Wd": Weighting(name="Wd", f1=0.4, f2=100.0, f3=2.0, f4=2.0, q4=0.63),
    "Wf": Weighting(
        name="Wf", f1=0.08, f2=0.63, f3=None, f4=0.25, q4=0.86, f5=0.0625, q5=0.80, f6=0.1, q6=0.80
    ),
    "Wc": Weighting(name="Wc", f1=0.4, f2=100.0, f3=8.0, f4=8.0, q4=0.63),
    "We": Weighting(name="We", f1=0.4, f2=100.0, f3=1.0, f4=1.0, q4=0.63),
    "Wj": Weighting(name="Wj", f1=0.4, f2=100.0, f5=3.75, q5=0.91, f6=5.32, q6=0.91),
}

#: Axis weightings and multipliers k (ISO 2631-1:1997 clause 7, health, and clause 8,
#: comfort); rotational multipliers in m/rad.
AXIS_MULTIPLIERS = {
    "health-seated": {"x": ("Wd", 1.4), "y": ("Wd", 1.4), "z": ("Wk", 1.0)},
    "comfort-seat": {
        "x": ("Wd", 1.0),
        "y": ("Wd", 1.0),
        "z": ("Wk", 1.0),
        "rx": ("We", 0.63),
        "ry": ("We", 0.40),
        "rz": ("We", 0.20),
    },
    "comfort-seat-back": {"x": ("Wc", 0.8), "y": ("Wd", 0.5), "z": ("Wd", 0.4)},
    "comfort-feet": {"x": ("Wk", 0.25), "y": ("Wk", 0.25), "z": ("Wk", 0.4)},
    "comfort-standing": {"x": ("Wd", 1.0), "y": ("Wd", 1.0), "z": ("Wk", 1.0)},
}


def weighting(name: str) -> Weighting:
    """The weighting called ``name`` (one of :data:`WEIGHTINGS`)."""
    check_choice("weighting", name, tuple(WEIGHTINGS))
    return WEIGHTINGS[name]


def weighting_magnitude(name: str, freq_hz):
    """|W(f)| of weighting ``name`` at ``freq_hz`` [Hz].

    Examples
    --------
    >>> round(float(weighting_magnitude("Wk", 1.0)), 3)
    0.482
    """
    return weighting(name).magnitude(freq_hz)


def weight(signal, fs: float, name: str = "Wk", method: str = "foh") -> np.ndarray:
    """Weighted signal a_w of ``signal`` sampled at ``fs`` [Hz] (see :meth:`Weighting.filter`)."""
    return weighting(name).filter(signal, fs, method)


def _integral(values, fs: float) -> float:
    """int x dt of samples ``values`` at ``fs`` [Hz] by the trapezoidal rule."""
    x = np.asarray(values, dtype=float)
    return float((np.sum(x) - 0.5 * (x[0] + x[-1])) / fs)


def _samples(signal, name: str = "signal") -> np.ndarray:
    a = np.asarray(signal, dtype=float)
    if a.ndim != 1 or a.size < 2:
        raise ParameterError(name, f"shape {a.shape}", "one-dimensional, at least two samples")
    return a


def rms(signal) -> float:
    """sqrt(1/T int x^2 dt) of evenly spaced samples over their span T (trapezoidal
    rule; the sampling rate cancels) [units of the signal].

    >>> rms([0.0, 1.0, 0.0, -1.0, 0.0])  # the samples of sin over a period: sqrt(1/2)
    0.7071067811865476
    """
    a = _samples(signal)
    return math.sqrt(max(_integral(a * a, 1.0), 0.0) / (a.size - 1))


def weighted_rms(signal, fs: float, name: str = "Wk", method: str = "foh") -> float:
    """a_w = sqrt(1/T int a_w(t)^2 dt) of the weighted signal [units of the signal]
    (:func:`rms` of :func:`weight`)."""
    return rms(weight(signal, fs, name, method))


def vibration_total_value(values: dict, posture: str = "comfort-seat") -> float:
    """a_v = sqrt(sum (k_i a_wi)^2) from weighted RMS values per axis (ISO 2631-1 (8)).

    ``values`` maps axis names of the posture ("x", "y", "z", "rx", ...) to a_w.
    """
    check_choice("posture", posture, tuple(AXIS_MULTIPLIERS))
    axes = AXIS_MULTIPLIERS[posture]
    total = 0.0
    for axis, aw in values.items():
        check_choice("axis", axis, tuple(axes))
        total += (axes[axis][1] * float(aw)) ** 2
    return math.sqrt(total)


def vibration_dose_value(weighted, fs: float) -> float:
    """VDV = (int a_w^4 dt)^(1/4) [m/s^1.75] of samples at ``fs`` [Hz] (trapezoidal rule)."""
    a = _samples(weighted, "weighted")
    return max(_integral(a**4, check_positive("fs", fs, "Hz")), 0.0) ** 0.25


def motion_sickness_dose_value(weighted_wf, fs: float) -> float:
    """MSDV = (int a_w^2 dt)^(1/2) [m/s^1.5] of a Wf-weighted vertical acceleration
    sampled at ``fs`` [Hz] (trapezoidal rule)."""
    a = _samples(weighted_wf, "weighted_wf")
    return math.sqrt(max(_integral(a * a, check_positive("fs", fs, "Hz")), 0.0))


def crest_factor(weighted) -> float:
    """max |a_w| / :func:`rms` (a_w) [-] of evenly spaced samples; 0 for a signal
    that is zero throughout."""
    a = _samples(weighted, "weighted")
    r = rms(a)
    return float(np.max(np.abs(a)) / r) if r > 0 else 0.0


def running_rms(weighted, fs: float, tau: float = 1.0) -> np.ndarray:
    """Running RMS with the linear window of length ``tau`` [s] (ISO 2631-1 (2))."""
    a = np.asarray(weighted, dtype=float)
    n = max(1, int(round(check_positive("tau", tau, "s") * fs)))
    c = np.concatenate([[0.0], np.cumsum(a * a)])
    lo = np.maximum(np.arange(1, a.size + 1) - n, 0)
    return np.sqrt((c[1:] - c[lo]) / n)


def mtvv(weighted, fs: float, tau: float = 1.0) -> float:
    """Maximum transient vibration value: the largest running RMS (ISO 2631-1 (3))."""
    return float(np.max(running_rms(weighted, fs, tau)))
