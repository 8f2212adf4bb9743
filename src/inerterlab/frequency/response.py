"""``frequency_response``: steady-state amplitude against forcing frequency.

One driver over five methods (docs/model.md §7, thesis ch. 7):

``brute``
    Time integration to a detected steady state at each frequency (see
    :mod:`inerterlab.frequency.brute`); the reference.
``shb``
    Single harmonic balance (7.8)-(7.14): one harmonic (plus the constant term, which
    vanishes for the symmetric systems of ch. 7), each point solved from rest.
``mhb``
    Multi-harmonic balance (7.17)-(7.22): H harmonics and the constant term, each point
    solved independently from rest.
``sihb``
    The scanning iterative multi-harmonic method (7.23)-(7.32): residual in time,
    coefficients by FFT, Newton steps that decrease the residual norm (7.31)-(7.32),
    scanning from f_max down to f_min and back up, each point started from the last.
``continuation``
    Pseudo-arclength continuation through folds with step adaptation.

Every harmonic-balance point carries its residual, a converged flag and, by Hill's
method, its stability. A point that fails is marked (``converged`` False,
``failure_reason``) and its amplitude is masked, never a number.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError, check_choice, check_positive
from ..resources import check_memory, check_work
from .brute import steady_state
from .continuation import continue_branch
from .first_order import half_peak_to_peak, make_first_order_engine
from .harmonic import FAILURE_REASONS, coefficients_by_fft, make_engine

__all__ = ["FrequencyResponse", "frequency_response", "nrmse", "frequency_grid", "METHODS"]

METHODS = ("brute", "shb", "mhb", "sihb", "continuation")
FIRST_ORDER_HARMONICS = 13  # default H of a first-order system (docs/decisions.md: accuracy)
DIRECTIONS = ("down", "up", "both")


@dataclass(frozen=True, kw_only=True, eq=False)
class FrequencyResponse:
    """Steady-state response against forcing frequency.

    Attributes
    ----------
    freq_hz : ndarray
        Forcing frequency f [Hz] (Omega = 2 pi f [rad/s]).
    amplitude_m : numpy.ma.MaskedArray
        Half peak-to-peak of the response degree of freedom [m] (X1 for ch. 7),
        masked where the point did not converge.
    coefficients : ndarray
        Shape (points, n_dof, 2H+1): [a0, a1, b1, ..., aH, bH] of
        x = a0 + sum a_h cos(h Omega t) + b_h sin(h Omega t) [m]. For ``brute``, the
        real-FFT coefficients of the last integrated period.
    residual : ndarray
        ||R(X)|| / ||R(0)||: harmonic-balance residual relative to the residual of the
        zero response; for ``brute`` the estimated relative distance to the periodic
        orbit.
    converged : ndarray of bool
    stable : numpy.ma.MaskedArray of bool
        Hill stability (masked where not converged or not computed); ``brute`` points
        are attractors, hence stable.
    max_multiplier : numpy.ma.MaskedArray
        Largest Floquet multiplier modulus exp(max Re(lambda) T) from Hill's method.
    failure_reason : tuple of str
        Empty string for converged points.
    direction : ndarray of str
        ``down`` or ``up`` (scan direction), for every point.
    iterations : ndarray of int
        Newton iterations (``brute``: integrated periods).
    method : str
    settings : dict
        Every setting used.
    """

    freq_hz: np.ndarray
    amplitude_m: np.ma.MaskedArray
    coefficients: np.ndarray
    residual: np.ndarray
    converged: np.ndarray
    stable: np.ma.MaskedArray
    max_multiplier: np.ma.MaskedArray
    failure_reason: tuple
    direction: np.ndarray
    iterations: np.ndarray
    method: str
    settings: dict = field(default_factory=dict)
    outputs: dict = field(default_factory=dict)
    output_units: dict = field(default_factory=dict)

    @property
    def omega(self) -> np.ndarray:
        """Forcing frequency [rad/s]."""
        return 2.0 * np.pi * self.freq_hz

    @property
    def harmonics(self) -> int:
        return (self.coefficients.shape[-1] - 1) // 2

    def __len__(self) -> int:
        return len(self.freq_hz)

    def branch(self, direction: str) -> FrequencyResponse:
        """The points of one scan direction (``down`` or ``up``)."""
        check_choice("direction", direction, ("down", "up"))
        return self._subset(self.direction == direction)

    def _subset(self, mask) -> FrequencyResponse:
        idx = np.flatnonzero(mask)
        return FrequencyResponse(
            freq_hz=self.freq_hz[idx],
            amplitude_m=self.amplitude_m[idx],
            coefficients=self.coefficients[idx],
            residual=self.residual[idx],
            converged=self.converged[idx],
            stable=self.stable[idx],
            max_multiplier=self.max_multiplier[idx],
            failure_reason=tuple(self.failure_reason[i] for i in idx),
            direction=self.direction[idx],
            iterations=self.iterations[idx],
            method=self.method,
            settings=dict(self.settings),
            outputs={k: v[idx] for k, v in self.outputs.items()},
            output_units=dict(self.output_units),
        )

    def first_harmonic(self, dof: int = 0) -> np.ma.MaskedArray:
        """|X1| = sqrt(a1^2 + b1^2) [m], the amplitude of the fundamental."""
        c = self.coefficients[:, dof]
        return np.ma.masked_array(np.hypot(c[:, 1], c[:, 2]), mask=~self.converged)

    def resonance(self, direction: str | None = None) -> dict:
        """Frequency [Hz] and amplitude [m] of the largest converged amplitude (Table 7.1).

        The maximum on the grid is refined by a parabola through it and its two
        neighbours when they are converged and on a uniform grid.
        """
        r = self if direction is None else self.branch(direction)
        ok = np.flatnonzero(r.converged)
        if ok.size == 0:
            raise ParameterError("direction", direction, "a direction with converged points")
        i = ok[np.argmax(r.amplitude_m.data[ok])]
        f, a = float(r.freq_hz[i]), float(r.amplitude_m.data[i])
        if 0 < i < len(r) - 1 and r.converged[i - 1] and r.converged[i + 1]:
            f0, f1, f2 = r.freq_hz[i - 1 : i + 2]
            a0, a1, a2 = r.amplitude_m.data[i - 1 : i + 2]
            if abs((f1 - f0) - (f2 - f1)) < 1e-9 * abs(f1) and a1 >= max(a0, a2):
                den = a0 - 2 * a1 + a2
                if den < 0:
                    d = 0.5 * (a0 - a2) / den
                    f = float(f1 + d * (f1 - f0))
                    a = float(a1 - 0.25 * (a0 - a2) * d)
        return {"freq_hz": f, "amplitude_m": a, "grid_freq_hz": float(r.freq_hz[i])}

    def to_dict(self) -> dict:
        """Plain lists (failed points: null amplitude, ``converged`` False); for JSON."""
        amp = [
            None if m else float(v)
            for v, m in zip(self.amplitude_m.data, self._mask(), strict=True)
        ]
        st = [
            None if m else bool(v)
            for v, m in zip(self.stable.data, np.ma.getmaskarray(self.stable), strict=True)
        ]
        out = {
            "method": self.method,
            "freq_hz": [float(f) for f in self.freq_hz],
            "amplitude_m": amp,
            "stable": st,
            "residual": [float(r) for r in self.residual],
            "converged": [bool(c) for c in self.converged],
            "direction": [str(d) for d in self.direction],
            "failure_reason": list(self.failure_reason),
        }
        if self.outputs:
            out["outputs"] = {
                name: [
                    None if m else float(v)
                    for v, m in zip(a.data, np.ma.getmaskarray(a), strict=True)
                ]
                for name, a in self.outputs.items()
            }
            out["output_units"] = dict(self.output_units)
        return out

    def _mask(self):
        return np.ma.getmaskarray(self.amplitude_m)

    def to_pandas(self):
        """A DataFrame, one row per point (nullable dtypes: failed points are <NA>)."""
        import pandas as pd

        d = self.to_dict()
        df = pd.DataFrame(
            {
                "freq_hz": d["freq_hz"],
                "amplitude_m": pd.array(d["amplitude_m"], dtype="Float64"),
                "stable": pd.array(d["stable"], dtype="boolean"),
                "residual": d["residual"],
                "converged": d["converged"],
                "direction": d["direction"],
                "iterations": self.iterations,
                "failure_reason": d["failure_reason"],
                **{k: pd.array(v, dtype="Float64") for k, v in d.get("outputs", {}).items()},
            }
        )
        df.attrs["method"] = self.method
        df.attrs["settings"] = dict(self.settings)
        return df

    def _summary(self) -> tuple[str, list[tuple[str, str]]]:
        from .._display import fmt, span

        ok = self.converged
        rows = [
            ("points", f"{len(self)} ({int(ok.sum())} converged)"),
            ("frequency", span(self.freq_hz.min(), self.freq_hz.max(), "Hz") if len(self) else "-"),
            ("harmonics", str(self.harmonics)),
        ]
        if ok.any():
            a = self.amplitude_m.data[ok]
            rows.append(("amplitude", span(a.min(), a.max(), "m")))
            r = self.resonance()
            rows.append(("peak", f"{fmt(r['amplitude_m'], 'm')} at {fmt(r['freq_hz'], 'Hz')}"))
        dirs = sorted(set(str(d) for d in self.direction))
        rows.append(("direction", ", ".join(dirs) if dirs else "-"))
        return f"frequency response, {self.method}", rows

    def __repr__(self) -> str:
        _, rows = self._summary()
        d = dict(rows)
        text = f"{d['points'].replace(' (', ' points (', 1)}, {d['frequency']}, H={d['harmonics']}"
        if "amplitude" in d:
            text += f", amplitude {d['amplitude']}, peak {d['peak']}"
        return f"<FrequencyResponse {self.method}: {text}>"

    def _repr_html_(self) -> str:
        from .._display import html_table

        return html_table(*self._summary())

    def to_xarray(self):
        """An xarray Dataset over ``point`` (frequency and direction as coordinates),
        with units; failed points are NaN in ``amplitude_m``."""
        import xarray as xr

        amp = np.ma.filled(self.amplitude_m.astype(float), np.nan)
        stable = np.ma.filled(self.stable.astype(float), np.nan)
        mult = np.ma.filled(self.max_multiplier.astype(float), np.nan)
        ds = xr.Dataset(
            {
                "amplitude_m": ("point", amp, {"units": "m", "long_name": "half peak-to-peak"}),
                "coefficients": (
                    ("point", "dof", "coefficient"),
                    self.coefficients,
                    {"units": "m", "long_name": "a0, a1, b1, ..., aH, bH"},
                ),
                "residual": ("point", self.residual, {"units": "1"}),
                "converged": ("point", self.converged),
                "stable": ("point", stable, {"units": "1", "long_name": "1 stable, 0 unstable"}),
                "max_multiplier": ("point", mult, {"units": "1"}),
                "iterations": ("point", self.iterations),
                "failure_reason": ("point", np.array(self.failure_reason, dtype=str)),
            },
            coords={
                "freq_hz": ("point", self.freq_hz, {"units": "Hz"}),
                "direction": ("point", self.direction.astype(str)),
            },
        )
        ds.attrs["method"] = self.method
        ds.attrs.update(
            {
                f"settings.{k}": (v if isinstance(v, int | float | str) else str(v))
                for k, v in self.settings.items()
            }
        )
        return ds

    def plot(self, ax=None, **kwargs):
        """Amplitude against frequency, both directions, unstable points marked."""
        from ._plot import plot_frequency_response

        return plot_frequency_response(self, ax=ax, **kwargs)


def frequency_grid(fmin: float, fmax: float, df: float) -> np.ndarray:
    """fmin, fmin + df, ... up to fmax [Hz] (fmax included when on the grid).

    Examples
    --------
    >>> frequency_grid(0.1, 0.5, 0.1).round(3).tolist()
    [0.1, 0.2, 0.3, 0.4, 0.5]
    """
    fmin = check_positive("fmin", fmin, "Hz")
    fmax = check_positive("fmax", fmax, "Hz")
    df = check_positive("df", df, "Hz")
    if not fmin < fmax:
        raise ParameterError("fmin", fmin, f"a frequency < fmax={fmax} Hz")
    count = math.floor((fmax - fmin) / df + 1e-9) + 1
    # each point keeps a few dozen numbers (coefficients, flags, residuals)
    check_memory(count * 32, what="frequency grid and its results", parameter="df", value=df)
    n = int(count) - 1
    return np.round(fmin + df * np.arange(n + 1), 12)


def _amplitudes(C) -> np.ndarray:
    return half_peak_to_peak(np.ascontiguousarray(C, dtype=float))


def estimate_operations(
    n_freqs: int,
    method: str,
    harmonics: int,
    *,
    direction: str = "up",
    stability: bool = True,
    max_iter: int = 30,
    steps_per_period: int = 2000,
    max_periods: int = 5000,
    n_dof: int = 1,
    hill: tuple[int, int, int] | None = None,
) -> float:
    """Rough floating point operations of :func:`frequency_response` (order of magnitude,
    an upper bound: every Newton iteration of ``max_iter`` counted).

    Per point and pass: Newton iterations on a system of (2H+1) n_dof unknowns plus the
    Hill stability matrix; brute force integrates up to 50 periods. The Hill matrix is
    twice the Newton system (a second-order system's, on every harmonic), or, with
    ``hill`` = (n, hs, K) (a first-order system: its n states on the harmonics 0..hs,
    the partials at K phases by forward differences), of size n (2 hs + 1), with the
    (n + 1) K evaluations of the right-hand side (about 100 n operations each) that
    assemble it.
    """
    n_pass = 2 if direction == "both" else 1
    size = (2.0 * float(harmonics) + 1.0) * n_dof
    if method == "brute":
        per_point = 50.0 * steps_per_period * min(max_periods, 50)
    else:
        if not stability:
            stab = 0.0
        elif hill is None:
            stab = 10 * (2 * size) ** 3
        else:
            n, hs, K = (float(v) for v in hill)
            stab = 10 * (n * (2 * hs + 1)) ** 3 + (n + 1) * K * 100 * n
        per_point = max_iter * (size**3 / 3 + 64 * size**2) + stab
    return float(n_freqs) * n_pass * per_point


def frequency_response(
    system,
    method: str = "sihb",
    *,
    freq_hz=None,
    fmin: float | None = None,
    fmax: float | None = None,
    df: float | None = None,
    harmonics: int | None = None,
    n_samples: int | None = None,
    direction: str | None = None,
    stability: bool = True,
    rtol: float = 1e-10,
    max_iter: int = 30,
    steps_per_period: int = 2000,
    brute_rtol: float = 1e-9,
    brute_start: str = "rest",
    max_periods: int = 5000,
    step: float = 0.02,
    amplitude: float | None = None,
    stability_harmonics: int | None = None,
) -> FrequencyResponse:
    """Steady-state frequency response of a periodically forced system.

    Parameters
    ----------
    system
        :class:`InerterSuspension` (e.g. ``chapter7_system(0.03)``),
        :class:`DuffingOscillator` or :class:`UserSystem`.
    method : {"brute", "shb", "mhb", "sihb", "continuation"}
    freq_hz : array, optional
        Frequencies [Hz]; otherwise ``fmin``, ``fmax`` and ``df`` [Hz] give the grid.
        For ``continuation`` only the end points are used.
    harmonics : int, optional
        H (default 1 for ``shb``, 15 for ``sihb``, 7 otherwise; ``brute`` uses it for
        the stored coefficients only).
    n_samples : int, optional
        Time samples per period N (default: smallest power of two >= 2 d H + 1).
    direction : {"down", "up", "both"}, optional
        Scan order (default ``both`` for ``sihb``, ``up`` otherwise). Only ``sihb`` and
        ``brute`` with ``brute_start="previous"`` depend on it.
    stability : bool
        Hill stability of each harmonic-balance point.
    rtol : float
        Newton tolerance on the update, relative to ||X|| + scale.
    max_iter : int
        Newton iterations per point.
    steps_per_period, brute_rtol, max_periods
        Brute-force settings (see :func:`inerterlab.frequency.brute.steady_state`).
    brute_start : {"rest", "previous"}
        Brute force from rest (thesis (7.5)) or from the last point's end state.
    step : float
        Initial continuation step (scaled arclength).
    amplitude : float, optional
        Road (input) displacement amplitude A [m], X1 = A sin(Omega t): required for
        first-order systems (a :class:`~inerterlab.suspension.QuarterCar` or a
        :class:`~inerterlab.frequency.quarter_car.FirstOrderSystem`), refused for the
        others (which carry their own forcing).
    stability_harmonics : int, optional
        First-order systems: harmonics 0..this of the Hill matrix used for stability
        (default 1; the exponents converge much faster than the response).

    For a first-order system the harmonics default to 13 (1 for ``shb``), every state is
    balanced, and ``outputs`` holds the half peak-to-peak of each named output
    (quarter car: body displacement [m], body acceleration [m/s^2], suspension
    deflection [m], tyre force [N]); ``amplitude_m`` is the body displacement.

    Returns
    -------
    FrequencyResponse

    Examples
    --------
    >>> from inerterlab.frequency import chapter7_system
    >>> fr = frequency_response(chapter7_system(0.01), "sihb", fmin=0.5, fmax=2.0, df=0.1,
    ...                         harmonics=7)
    >>> bool(fr.converged.all()), len(fr), sorted(set(fr.direction.tolist()))
    (True, 32, ['down', 'up'])
    >>> round(fr.resonance("down")["freq_hz"], 1)
    1.2
    """
    opts = dict(locals())
    check_choice("method", method, METHODS)
    opts["system"], opts["first_order"] = _resolve_system(system, amplitude)
    on_generic = getattr(opts["system"], "on_generic", None)
    n0 = _compiled_count(opts["system"])
    c0 = time.process_time()
    try:
        return _respond(**opts)
    finally:
        # a response on the generic code counts towards compiling the structure's own,
        # as an integration's time does; not a call that compiled (or loaded) a kernel
        if on_generic is not None and _compiled_count(opts["system"]) == n0:
            on_generic(time.process_time() - c0)


def _compiled_count(system) -> int:
    """How many compiled functions the first-order engine and the system's own hold
    (a count that grows while a call compiles)."""
    from .first_order import _TYPED

    n = len(_TYPED)
    for fn in (getattr(system, "rhs", None), getattr(system, "compiled_outputs", None)):
        n += len(getattr(fn, "signatures", ()))
    return n


def _respond(
    system, method, *, first_order, freq_hz, fmin, fmax, df, harmonics, n_samples, direction,
    stability, rtol, max_iter, steps_per_period, brute_rtol, brute_start, max_periods, step,
    amplitude, stability_harmonics,
) -> FrequencyResponse:  # fmt: skip
    """:func:`frequency_response` of a resolved system (``first_order``: a first-order
    system, else a second-order one)."""
    if harmonics is None:
        if first_order:
            harmonics = 1 if method == "shb" else FIRST_ORDER_HARMONICS
        else:
            harmonics = {"shb": 1, "sihb": 15}.get(method, 7)
    if isinstance(harmonics, bool) or not isinstance(harmonics, int | np.integer) or harmonics < 1:
        raise ParameterError("harmonics", harmonics, "an integer >= 1")
    if method == "shb" and harmonics != 1:
        raise ParameterError("harmonics", harmonics, "1 for method 'shb' (use 'mhb' for more)")
    if direction is None:
        direction = "both" if method == "sihb" else "up"
    check_choice("direction", direction, DIRECTIONS)
    check_choice("brute_start", brute_start, ("rest", "previous"))
    if freq_hz is None:
        if fmin is None or fmax is None or (df is None and method != "continuation"):
            raise ParameterError("freq_hz", None, "an array of frequencies, or fmin, fmax and df")
        freqs = frequency_grid(fmin, fmax, df if df is not None else (fmax - fmin))
    else:
        freqs = np.atleast_1d(np.asarray(freq_hz, dtype=float))
        if freqs.size == 0 or not np.all(np.isfinite(freqs)) or np.any(freqs <= 0):
            raise ParameterError("freq_hz", freq_hz, "finite frequencies > 0 Hz")
        freqs = np.unique(freqs)
    scale = amplitude if first_order else float(getattr(system, "displacement_scale", 1.0))
    hill = None
    n_dof = 1
    if first_order:
        # the unknowns: the states less the velocities of positions (their coefficients
        # follow from the positions'); the Hill matrix: every state on the stability
        # harmonics, its partials at the engine's phases (make_first_order_engine)
        n = int(system.n_states)
        n_dof = n - sum(1 for j in (getattr(system, "velocity_of", None) or ()) if j >= 0)
        sh = min(int(harmonics), 1) if stability_harmonics is None else stability_harmonics
        if not isinstance(sh, bool) and isinstance(sh, int | np.integer) and 0 <= sh <= harmonics:
            hill = (n, int(sh), max(256, int(n_samples or 0)))
        else:
            hill = (n, int(harmonics), 256)  # refused below, with its own message
    size = (2.0 * float(harmonics) + 1.0) * n_dof
    by_harmonics = size**3 > 1e4 * freqs.size
    check_work(
        estimate_operations(
            freqs.size,
            method,
            harmonics,
            direction=direction,
            stability=stability,
            max_iter=max_iter,
            steps_per_period=steps_per_period,
            max_periods=max_periods,
            n_dof=n_dof,
            hill=hill,
        ),  # fmt: skip
        what="frequency response",
        parameter="harmonics" if by_harmonics else "df",
        value=harmonics
        if by_harmonics
        else (df if df is not None else f"{freqs.size} frequencies"),
    )
    settings = {
        "method": method,
        "harmonics": int(harmonics),
        "direction": direction,
        "rtol": rtol,
        "system": repr(system),
    }
    orders = {"down": [("down", freqs[::-1])], "up": [("up", freqs)]}
    orders["both"] = orders["down"] + orders["up"]
    if method == "brute":
        settings.update(
            steps_per_period=steps_per_period, brute_rtol=brute_rtol,
            brute_start=brute_start, max_periods=max_periods,
        )  # fmt: skip
        passes = orders[direction] if brute_start == "previous" else orders[direction][:1]
        if first_order:
            settings["amplitude"] = amplitude
            return _brute_first_order(system, passes, harmonics, settings, amplitude)
        return _brute(system, passes, harmonics, settings)
    if first_order:
        engine = make_first_order_engine(system, int(harmonics), n_samples, amplitude)
        settings["amplitude"] = amplitude
        sh = min(int(harmonics), 1) if stability_harmonics is None else stability_harmonics
        if isinstance(sh, bool) or not isinstance(sh, int | np.integer) or not 0 <= sh <= harmonics:
            raise ParameterError(
                "stability_harmonics", sh, f"an integer 0 .. harmonics = {harmonics}"
            )
        settings["stability_harmonics"] = int(sh)
    else:
        if stability_harmonics is not None:
            raise ParameterError(
                "stability_harmonics", stability_harmonics, "no value (first-order systems only)"
            )
        engine = make_engine(system, int(harmonics), n_samples)  # Hill on every harmonic
    settings["n_samples"] = engine.basis.n_samples
    settings["engine"] = type(engine).__name__
    cold = engine.cold_start()
    if method == "continuation":
        settings["step"] = step
        w0, w1 = 2 * np.pi * freqs[0], 2 * np.pi * freqs[-1]
        if direction == "down":
            w0, w1 = w1, w0
        path = continue_branch(
            engine, cold, w0, w1, step=step, rtol=rtol, max_iter=max_iter, scale=scale
        )
        settings["continuation_message"] = path.message
        n = len(path.omega)
        ok = np.ones(n, dtype=bool)
        codes = np.zeros(n, dtype=np.int64)
        return _assemble(
            engine, system, path.omega, path.coefficients, ok, path.iterations, codes,
            np.array(["down" if direction == "down" else "up"] * n), method, settings,
            stability,
        )  # fmt: skip
    warm = method == "sihb"
    passes = orders[direction]
    omegas, coeffs, oks, its, codes, dirs = [], [], [], [], [], []
    X_start = cold.copy()
    for name, fr in passes:
        w = 2 * np.pi * fr
        out, ok, it, res, code = engine.sweep(w, X_start, rtol, max_iter, scale, warm)
        if warm and ok.any():
            X_start = out[np.flatnonzero(ok)[-1]].copy()
        omegas.append(w)
        coeffs.append(out)
        oks.append(ok)
        its.append(it)
        codes.append(code)
        dirs += [name] * len(w)
    return _assemble(
        engine, system, np.concatenate(omegas), np.concatenate(coeffs), np.concatenate(oks),
        np.concatenate(its), np.concatenate(codes), np.array(dirs), method, settings, stability,
    )  # fmt: skip


def _assemble(engine, system, omegas, coeffs, ok, its, codes, dirs, method, settings, stability):
    n = len(omegas)
    nd, size = engine.n_dof, engine.basis.size
    dof = int(getattr(system, "response_dof", 0))
    C = coeffs.reshape(n, nd, size)
    amp = _amplitudes(C[:, dof, :]) if n else np.zeros(0)
    res = engine.relative_residuals(omegas, coeffs) if n else np.zeros(0)
    stable = np.zeros(n, dtype=bool)
    mult = np.zeros(n)
    known = np.zeros(n, dtype=bool)
    outputs, units = {}, {}
    if stability and n:
        first = _same_solution(omegas, C, ok, SAME_SOLUTION * settings.get("rtol", 0.0))
        one = first == np.arange(n)  # the points whose stability is computed
        best, _ = engine.stability(
            omegas[one], coeffs[one], ok[one], settings.get("stability_harmonics")
        )
        best = best[np.cumsum(one) - 1][first]
        known = np.isfinite(best)
        stable = known & (best < 1e-7 * omegas)
        mult = np.where(known, np.exp(np.where(known, best, 0.0) * 2 * np.pi / omegas), 0.0)
    outputs, units = _first_order_outputs(engine, system, omegas, coeffs, ok)
    if outputs:
        amp = outputs[next(iter(outputs))].data
    reasons = tuple(
        "" if o else FAILURE_REASONS.get(int(c), "failed") for o, c in zip(ok, codes, strict=True)
    )
    return FrequencyResponse(
        freq_hz=omegas / (2 * np.pi),
        amplitude_m=np.ma.masked_array(amp, mask=~ok),
        coefficients=C,
        residual=res,
        converged=ok.astype(bool),
        stable=np.ma.masked_array(stable, mask=~known),
        max_multiplier=np.ma.masked_array(mult, mask=~known),
        failure_reason=reasons,
        direction=dirs,
        iterations=np.asarray(its, dtype=np.int64),
        method=method,
        settings=settings,
        outputs=outputs,
        output_units=units,
    )


#: two converged points at the same frequency are one solution (its stability computed
#: once) where their coefficients differ by at most this many times the solver's rtol,
#: relative to the larger of the two (decisions.md, stop 72)
SAME_SOLUTION = 100.0


def _same_solution(omegas, C, ok, tol) -> np.ndarray:
    """For each point, the first point (itself included) at the same Omega, converged
    like it, whose coefficients are within ``tol`` of its own relative to the larger
    norm: where the down and up scans meet one periodic solution."""
    n = len(omegas)
    first = np.arange(n)
    if tol <= 0.0:
        return first
    flat = C.reshape(n, -1)
    norm = np.linalg.norm(flat, axis=1)
    order = np.lexsort((np.arange(n), omegas))
    i = 0
    while i < n:
        j = i + 1
        while j < n and omegas[order[j]] == omegas[order[i]]:
            j += 1
        group = order[i:j]  # one frequency, in the order the points were solved
        for q, b in enumerate(group):
            if not ok[b]:
                continue
            for a in group[:q]:
                if ok[a] and first[a] == a and np.linalg.norm(flat[b] - flat[a]) <= tol * max(
                    norm[a], norm[b]
                ):
                    first[b] = a
                    break
        i = j
    return first


def _road_samples(omegas, amplitude, tau):
    """[X1, X1', X1''] at the phases tau for every Omega: (P, 3, N)."""
    w = np.asarray(omegas, dtype=float)[:, None]
    s, c = np.sin(tau)[None, :], np.cos(tau)[None, :]
    return np.stack([amplitude * s + 0.0 * w, amplitude * w * c, -amplitude * w * w * s], axis=1)


OUTPUT_PHASES = 128  # phases per period at which the outputs are evaluated


def _half_peak_to_peak_dense(samples: np.ndarray) -> np.ndarray:
    """Half peak-to-peak of periodic samples (P, K): extremes of their trigonometric
    interpolant (exact for a signal with fewer than K/2 harmonics)."""
    from .first_order import interpolant_half_peak_to_peak

    samples = np.ascontiguousarray(samples, dtype=float)
    k = samples.shape[1]
    hd = (k - 1) // 2
    c = coefficients_by_fft(samples, hd)
    return interpolant_half_peak_to_peak(
        samples, np.ascontiguousarray(c[:, 0]), np.ascontiguousarray(c[:, 1::2]),
        np.ascontiguousarray(c[:, 2::2]),
    )  # fmt: skip


def _first_order_outputs(engine, system, omegas, coeffs, ok):
    """Half peak-to-peak of the system's outputs (masked where not converged).

    The outputs are evaluated at OUTPUT_PHASES phases from the periodic states (the
    balanced Fourier series) through the system's own right-hand side, so an output
    with a kink (the inerter force at the flywheel's saturation speed) keeps it instead
    of being truncated to H harmonics; the extremes are those of the trigonometric
    interpolant of these samples."""
    fn = getattr(system, "output_samples", None)
    comp = getattr(system, "compiled_outputs", None)
    n = len(omegas)
    if (fn is None and comp is None) or n == 0:
        return {}, {}
    tau = 2.0 * np.pi * np.arange(OUTPUT_PHASES) / OUTPUT_PHASES
    if comp is not None:
        O = engine.compiled_outputs(comp, system.n_outputs, omegas, coeffs, tau)
        named = system.combine_outputs(O)
    else:
        xs, fs = engine.samples(omegas, coeffs, tau)
        named = fn(xs, fs, _road_samples(omegas, engine.amplitude, tau))
    mask = ~np.asarray(ok, dtype=bool)
    out = {}
    for name, v in named.items():
        v = np.asarray(v, dtype=float)
        amp = np.full(n, np.nan)
        good = np.all(np.isfinite(v), axis=1)
        if good.any():
            amp[good] = _half_peak_to_peak_dense(v[good])
        out[name] = np.ma.masked_array(amp, mask=mask | ~good)
    return out, dict(getattr(system, "output_units", {}))


def _resolve_system(system, amplitude):
    """(system, first_order): a quarter car becomes its first-order system."""
    from ..suspension.model import QuarterCar
    from .first_order import FirstOrderSystem, is_first_order
    from .quarter_car import from_core_system, quarter_car_system

    if isinstance(system, QuarterCar) or "model" in getattr(system, "info", {}):
        system = quarter_car_system(system)  # a named suspension
    elif (
        not isinstance(system, FirstOrderSystem)
        and hasattr(system, "tables")
        and hasattr(system, "output_names")
    ):
        system = from_core_system(system)  # a system of the model core
    if is_first_order(system):
        if amplitude is None:
            raise ParameterError("amplitude", None, "a road displacement amplitude > 0 m")
        check_positive("amplitude", amplitude, "m")
        return system, True
    if amplitude is not None:
        raise ParameterError(
            "amplitude",
            amplitude,
            "no value for this system (it carries its own forcing, e.g. chapter7_system(B))",
        )
    return system, False


def _scan(passes, settings, solve):
    """(direction, f [Hz], Omega [rad/s], solve(Omega, start)) of every brute-force point
    in scan order; ``solve`` returns the end state first, and ``start`` is the last
    point's end state with ``brute_start="previous"``, else None (rest)."""
    for name, fr in passes:
        y = None
        for f in fr:
            w = 2 * np.pi * f
            out = solve(w, y if settings["brute_start"] == "previous" else None)
            y = out[0]
            yield name, f, w, out


def _brute_response(freqs, amp, coeffs, residual, ok, dirs, its, settings, outputs=None,
                    units=None):  # fmt: skip
    """The brute-force result: settled points are attractors (stable), no multipliers."""
    ok = np.asarray(ok, dtype=bool)
    return FrequencyResponse(
        freq_hz=np.array(freqs),
        amplitude_m=np.ma.masked_array(np.asarray(amp, dtype=float), mask=~ok),
        coefficients=np.array(coeffs),
        residual=np.asarray(residual, dtype=float),
        converged=ok,
        stable=np.ma.masked_array(ok.copy(), mask=~ok),
        max_multiplier=np.ma.masked_array(np.zeros(len(ok)), mask=np.ones(len(ok), dtype=bool)),
        failure_reason=tuple("" if o else "no steady state within max_periods periods" for o in ok),
        direction=np.array(dirs),
        iterations=np.array(its, dtype=np.int64),
        method="brute",
        settings=settings,
        outputs=outputs or {},
        output_units=units or {},
    )


def _brute_first_order(system, passes, harmonics, settings, amplitude):
    """Brute force of a first-order system: RK4 on its right-hand side to steady state."""
    from .first_order import brute_force_point

    spp = int(settings["steps_per_period"])

    def solve(w, start):
        return brute_force_point(
            system, w, amplitude, steps_per_period=spp, rtol=settings["brute_rtol"],
            max_periods=settings["max_periods"], initial_state=start,
        )  # fmt: skip

    freqs, oks, its, dirs, coeffs, xs_all, omegas = ([] for _ in range(7))
    for name, f, w, (_, xs, ok, periods) in _scan(passes, settings, solve):
        freqs.append(f)
        omegas.append(w)
        oks.append(ok)
        its.append(periods)
        dirs.append(name)
        coeffs.append(coefficients_by_fft(xs, harmonics))
        xs_all.append(xs)
    ok = np.array(oks, dtype=bool)
    omegas = np.array(omegas)
    outputs, units = {}, {}
    fn = getattr(system, "output_samples", None)
    comp = getattr(system, "compiled_outputs", None)
    if (fn is not None or comp is not None) and len(omegas):
        from .first_order import outputs_at_states, rhs_samples

        X = np.stack(xs_all)  # (P, n, steps)
        tau = 2 * np.pi * np.arange(spp) / spp
        if comp is not None:
            O = np.stack(
                [outputs_at_states(system, w, amplitude, x, tau)
                 for w, x in zip(omegas, X, strict=True)]
            )  # fmt: skip
            named = system.combine_outputs(O)
        else:
            fs = np.stack(
                [rhs_samples(system, w, amplitude, x, tau) for w, x in zip(omegas, X, strict=True)]
            )
            named = fn(X, fs, _road_samples(omegas, amplitude, tau))
        for name, samples in named.items():
            hi, lo = np.max(samples, axis=1), np.min(samples, axis=1)
            outputs[name] = np.ma.masked_array(0.5 * (hi - lo), mask=~ok)
        units = dict(getattr(system, "output_units", {}))
    rs = int(getattr(system, "response_state", 0))
    amp = [0.5 * (x[rs].max() - x[rs].min()) for x in xs_all]
    return _brute_response(
        freqs, amp, coeffs, np.zeros(len(ok)), ok, dirs, its, settings, outputs, units
    )


def _brute(system, passes, harmonics, settings):
    """Brute force of a built-in or user system (:func:`~.brute.steady_state`)."""
    nd = int(system.n_dof)
    dof = int(getattr(system, "response_dof", 0))

    def solve(w, start):
        s = steady_state(
            system, w, initial_state=start,
            steps_per_period=settings["steps_per_period"], rtol=settings["brute_rtol"],
            max_periods=settings["max_periods"],
        )  # fmt: skip
        return s.state, s

    freqs, amps, oks, res, its, dirs, coeffs = ([] for _ in range(7))
    for name, f, _, (_, s) in _scan(passes, settings, solve):
        c = np.zeros((nd, 2 * harmonics + 1))
        c[dof] = coefficients_by_fft(s.samples, harmonics)
        freqs.append(f)
        amps.append(s.amplitude)
        oks.append(s.settled)
        res.append(s.distance)
        its.append(s.periods)
        dirs.append(name)
        coeffs.append(c)
    residual = np.where(np.isfinite(res), res, 1.0) if res else np.zeros(0)
    return _brute_response(freqs, amps, coeffs, residual, oks, dirs, its, settings)


def nrmse(
    result: FrequencyResponse,
    reference: FrequencyResponse,
    *,
    direction: str | None = "down",
    normalise_by: str = "method",
) -> float:
    """Normalised RMS error (7.16) of ``result`` against ``reference`` on common frequencies.

    E = sqrt(sum (A_ref - A)^2 / sum A^2) with A the method's amplitudes, as printed in
    (7.16) (``normalise_by="reference"`` divides by the reference instead). Only
    frequencies present (to 1e-9 Hz) and converged in both enter. ``direction`` picks
    one scan branch of each result when it has several.
    """
    check_choice("normalise_by", normalise_by, ("method", "reference"))
    a = _single(result, direction)
    b = _single(reference, direction)
    ka = {
        round(f, 9): v
        for f, v, ok in zip(a.freq_hz, a.amplitude_m.data, a.converged, strict=True)
        if ok
    }
    kb = {
        round(f, 9): v
        for f, v, ok in zip(b.freq_hz, b.amplitude_m.data, b.converged, strict=True)
        if ok
    }
    common = sorted(set(ka) & set(kb))
    if not common:
        raise ParameterError("reference", "no common converged frequencies", "overlapping grids")
    x = np.array([ka[k] for k in common])
    y = np.array([kb[k] for k in common])
    den = x if normalise_by == "method" else y
    return float(np.sqrt(np.sum((y - x) ** 2) / np.sum(den**2)))


def _single(r: FrequencyResponse, direction):
    dirs = set(r.direction.tolist())
    if len(dirs) > 1 and direction is not None:
        return r.branch(direction) if direction in dirs else r
    return r
