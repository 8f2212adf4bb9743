"""One simulation driver over two integration backends -> :class:`SimulationResult`.

Backends (docs/model.md §5):

``numba`` (default)
    Compiled kernel (:mod:`inerterlab.suspension._kernels`): exact matrix-exponential
    steps wherever the car is linear (no inerter, a constant one, a saturated flywheel),
    adaptive Dormand-Prince 5(4) elsewhere, with the metric integrals and the Wk filter
    as extra states; dense output only for the sampled time series and the peaks.
``scipy``
    :func:`scipy.integrate.solve_ivp` (``DOP853`` by default) on the plain-Python
    right-hand side :class:`inerterlab.suspension.reference.ReferenceRHS`: the
    reference the fast backend is tested against.

Both integrate piecewise between the excitation's segment edges, restart at each edge
and apply the tyre-damper impulse C_t * jump where the road jumps. Absolute tolerances
are ``rtol`` times a typical size of each state (``QuarterCar.state_scales``).

Examples
--------
>>> from inerterlab import quarter_car
>>> from inerterlab.excitation import sine
>>> res = simulate(quarter_car("traditional"), sine(), 1.0, output="metrics")
>>> sorted(res.metrics())[:3]
['crest_factor', 'min_tyre_force', 'peak_body_acc']
"""

from __future__ import annotations

import math
import sys
import threading
import time
import types
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import ConvergenceError, ParameterError, check_choice, check_positive
from .excitation import ROAD_JUMP_RTOL, Excitation, road_displacement, road_scale, road_steps
from .metrics import wk_sections, wk_state_space
from .resources import check_memory
from .suspension.model import N_METRIC_STATES, QuarterCar, model_of

__all__ = [
    "SimulationOptions",
    "SimulationResult",
    "simulate",
    "simulate_metrics",
    "BACKENDS",
]

BACKENDS = ("numba", "scipy")
WK_TOLERANCE_FACTOR = 1e4  # absolute tolerance of the Wk filter states / the others'
OUTPUTS = ("series", "metrics")


@dataclass(frozen=True, kw_only=True)
class SimulationOptions:
    """How to integrate.

    Parameters
    ----------
    backend : {"numba", "scipy"}
        Compiled kernel (exact steps and Dormand-Prince 5(4)) or scipy ``solve_ivp`` on
        a Python right-hand side.
    rtol : float
        Relative tolerance; absolute tolerances are rtol x the typical size of each
        state. At the default 1e-8 the numba backend's metrics agree with a scipy
        DOP853 run at 1e-10 to better than 1e-6 (tests/test_simulate.py).
    method : str
        scipy method (``DOP853``, ``RK45``, ``Radau``, ...); ignored by ``numba``.
    sample_rate : float
        Output sampling rate [Hz] of the time series (>= 1000 recommended).
    refine_peaks : bool
        Locate peaks between steps on the continuous extension (numba backend);
        without it peaks are the largest values at step ends.
    max_steps : int
        Give up (ConvergenceError) after this many steps (scipy backend: after 16 x
        this many right-hand-side evaluations, about as many steps of DOP853).
    time_limit : float or None
        Give up (ConvergenceError) after this many seconds of integration (scipy
        backend, checked every 256 evaluations); None for no limit. The compiled
        backend is bounded by ``max_steps`` alone.
    exact_steps : bool
        Numba backend: advance the linear phases (no inerter, a constant one, or a
        saturated flywheel under the thesis or momentum law; not with tyre lift-off)
        by the matrix exponential in steps of 10, 5, 2.5 or 1.25 ms instead of
        Runge-Kutta steps, never across an output sample. Exact up to round-off; metric
        integrals by Gauss-Legendre sums inside each step.
    """

    backend: str = "numba"
    rtol: float = 1e-8
    method: str = "DOP853"
    sample_rate: float = 1000.0
    refine_peaks: bool = True
    max_steps: int = 10_000_000
    exact_steps: bool = True
    time_limit: float | None = None

    def __post_init__(self) -> None:
        check_choice("backend", self.backend, BACKENDS)
        r = check_positive("rtol", self.rtol)
        if not 1e-14 <= r <= 1e-2:
            raise ParameterError("rtol", self.rtol, "a relative tolerance in [1e-14, 1e-2]")
        check_choice("method", self.method, ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA"))
        check_positive("sample_rate", self.sample_rate, "Hz")
        if not isinstance(self.max_steps, int) or self.max_steps < 1:
            raise ParameterError("max_steps", self.max_steps, "an integer >= 1")
        if self.time_limit is not None:
            check_positive("time_limit", self.time_limit, "s")


DEFAULT_OPTIONS = SimulationOptions()

#: units of the sampled series of a :class:`SimulationResult` ("1" = dimensionless)
SERIES_UNITS = {
    "time": "s",
    "road": "m",
    "road_velocity": "m/s",
    "unsprung_disp": "m",
    "sprung_disp": "m",
    "unsprung_vel": "m/s",
    "sprung_vel": "m/s",
    "body_acc": "m/s^2",
    "body_acc_wk": "m/s^2",
    "deflection": "m",
    "tyre_force": "N",
    "tyre_grip": "1",
}


@dataclass(frozen=True, kw_only=True, eq=False)
class SimulationResult:
    """A quarter-car simulation: metrics and (optionally) the sampled time series.

    Attributes
    ----------
    model : QuarterCar
    excitation : Excitation
    horizon : float
        T [s].
    options : SimulationOptions
    values : dict
        The metrics (see :meth:`metrics`).
    time : ndarray or None
        Sample times [s] (None for ``output="metrics"``).
    states : ndarray or None
        Physical states at the samples, columns ``model.state_names``.
    body_acc, body_acc_wk, road, road_velocity : ndarray or None
        a3 [m/s^2], Wk-weighted a3 [m/s^2], X1 [m], X1' [m/s] at the samples.
    stats : dict
        Steps, rejected steps, right-hand-side calls, segments.
    """

    model: QuarterCar
    excitation: Excitation
    horizon: float
    options: SimulationOptions
    values: dict
    time: np.ndarray | None = None
    states: np.ndarray | None = None
    body_acc: np.ndarray | None = None
    body_acc_wk: np.ndarray | None = None
    road: np.ndarray | None = None
    road_velocity: np.ndarray | None = None
    stats: dict = field(default_factory=dict)
    body_velocity_jumps: tuple = ()
    not_finite: dict = field(default_factory=dict)

    def _summary(self) -> tuple[str, list[tuple[str, str]]]:
        from ._display import fmt
        from .metrics import METRIC_UNITS

        title = f"{self.model.suspension} on {self.excitation.name}, T = {self.horizon:g} s"
        rows = [
            (k, "not finite" if self.values[k] is None else fmt(self.values[k], METRIC_UNITS.get(k, "")))
            for k in self.values
        ]
        rows.append(("samples", str(0 if self.time is None else self.time.size)))
        return title, rows

    def __repr__(self) -> str:
        title, rows = self._summary()
        keys = ("rms_body_acc", "rms_tyre_grip", "rms_deflection", "rms_body_acc_wk", "samples")
        shown = ", ".join(f"{k}={v}" for k, v in rows if k in keys)
        return f"<SimulationResult {title}: {shown}>"

    def _repr_html_(self) -> str:
        from ._display import html_table

        return html_table(*self._summary())

    def metrics(self) -> dict:
        """Ride metrics over the horizon.

        Keys: ``rms_body_acc`` [m/s^2] (4.15), ``rms_tyre_grip`` [-] (4.20)-(4.21),
        ``rms_deflection`` [m] (4.25)-(4.26), ``rms_body_acc_wk`` [m/s^2] (ISO 2631-1
        Wk), ``vdv`` [m/s^1.75], ``crest_factor`` [-] (of the weighted acceleration),
        ``peak_body_acc``, ``peak_body_acc_wk`` [m/s^2], ``peak_deflection`` [m],
        ``min_tyre_force`` [N] (static load minus the tyre's dynamic force; unclipped
        without lift-off, so negative where the tyre would pull, and capped at 0 with
        ``tyre_lift_off=True``), ``tyre_lift_off`` (True if the tyre force reached zero).

        Across a road step with an inerter between wheel and body the body velocity
        jumps (:attr:`body_velocity_jumps`) and the body acceleration holds a Dirac:
        ``rms_body_acc`` and ``peak_body_acc`` are then not finite and are ``None``,
        with the reason in :attr:`not_finite`. The Wk-weighted values, VDV and crest
        factor include the jump exactly (docs/model.md §5, road steps).
        """
        return dict(self.values)

    # -- derived series -------------------------------------------------------------
    def _need_series(self) -> None:
        if self.time is None:
            raise ParameterError("output", "metrics", "output='series' to get time series")

    @property
    def deflection(self) -> np.ndarray:
        """Suspension deflection X3 - X2 [m] at the samples."""
        self._need_series()
        return self.states[:, 2] - self.states[:, 0]

    @property
    def tyre_force(self) -> np.ndarray:
        """Tyre contact force [N] (static load included; >= 0 with lift-off on)."""
        self._need_series()
        q = self.model.parameters
        dyn = q.tyre_stiffness * (self.states[:, 0] - self.road) + q.tyre_damping * (
            self.states[:, 1] - self.road_velocity
        )
        f = q.static_tyre_load - dyn
        return np.maximum(f, 0.0) if self.model.tyre_lift_off else f

    @property
    def tyre_grip(self) -> np.ndarray:
        """Tyre grip index K_t (X2 - X1)/((M + M_t) g) [-] (4.20)."""
        self._need_series()
        q = self.model.parameters
        return q.tyre_stiffness * (self.states[:, 0] - self.road) / q.static_tyre_load

    def series_units(self) -> dict:
        """Unit of every column of :meth:`to_pandas` (and variable of :meth:`to_xarray`);
        states of the slider-dynamics law by their name (``_pos`` m, ``_rate`` m/s)."""
        units = dict(SERIES_UNITS)
        for name in self.model.state_names:
            if name not in units:
                units[name] = "m/s" if name.endswith(("_vel", "_rate", "_velocity")) else "m"
        return units

    def to_pandas(self, *, units_in_names: bool = False):
        """Time series as a pandas DataFrame indexed by time [s] (SI units).

        ``units_in_names=True`` writes the unit into each column name
        (``body_acc [m/s^2]``, ``tyre_grip [-]``, index ``time [s]``), as
        ``inerterlab simulate --save`` does in its CSV files.
        """
        import pandas as pd

        self._need_series()
        data = {
            "road": self.road,
            "road_velocity": self.road_velocity,
        }
        for i, name in enumerate(self.model.state_names):
            data[name] = self.states[:, i]
        data.update(
            body_acc=self.body_acc,
            body_acc_wk=self.body_acc_wk,
            deflection=self.deflection,
            tyre_force=self.tyre_force,
            tyre_grip=self.tyre_grip,
        )
        df = pd.DataFrame(data, index=pd.Index(self.time, name="time"))
        df.attrs.update(self.settings())
        if units_in_names:
            u = self.series_units()
            df = df.rename(
                columns=lambda c: f"{c} [{'-' if u[c] == '1' else u[c]}]" if c in u else c
            )
            df.index.name = "time [s]"
        return df

    def to_xarray(self):
        """Time series as an xarray Dataset with units and the settings as attributes."""
        import xarray as xr

        df = self.to_pandas()
        ds = xr.Dataset.from_dataframe(df)
        for k, u in self.series_units().items():
            if k in ds:
                ds[k].attrs["units"] = u
        ds["time"].attrs["units"] = "s"
        ds.attrs.update(
            {
                k: (str(v) if isinstance(v, bool) or v is None else v)
                for k, v in self.settings().items()
            }
        )
        return ds

    def settings(self) -> dict:
        """Everything that defines this run, flattened for file headers."""
        out = {f"model.{k}": v for k, v in self.model.describe().items()}
        out.update({f"input.{k}": v for k, v in self.excitation.describe().items()})
        out.update(horizon=self.horizon, backend=self.options.backend, rtol=self.options.rtol)
        return out

    def plot(self, **kwargs):
        """Figure of body acceleration, deflection and tyre force against time."""
        from .suspension.plot import plot_simulation

        return plot_simulation(self, **kwargs)


# -- backends --------------------------------------------------------------------------
@dataclass
class _Run:
    integrals: np.ndarray
    peaks: np.ndarray  # a3, -a3, aw, -aw, z, -z, tyre force
    samples: tuple | None  # (time, full state rows, a3)
    stats: dict
    jumps: tuple = ()  # ((time [s], body velocity jump [m/s]), ...) where not zero


def _initial_state(model: QuarterCar, excitation: Excitation, horizon: float):
    x1 = excitation.initial_road(horizon)
    du, ds = excitation.initial_displacements
    phys = model.initial_state(unsprung=x1 + du, sprung=x1 + ds)
    return np.concatenate([phys, np.zeros(N_METRIC_STATES)]), x1


#: arrays of this many floats per output sample are kept for a time series (states,
#: accelerations, road, forces and the derived columns of ``to_pandas``), generously
_SERIES_VALUES_PER_SAMPLE = 64


def _sample_times(horizon: float, rate: float) -> np.ndarray:
    n_samples = horizon * rate + 1.0
    # refuse up front a series that cannot fit, with the estimate, instead of failing late
    check_memory(
        n_samples * _SERIES_VALUES_PER_SAMPLE,
        what="sampled time series (horizon x sample_rate)",
        parameter="horizon",
    )
    n = int(math.floor(horizon * rate + 1e-9))
    return np.arange(n + 1) / rate


_WK: dict = {}


def _wk():
    if not _WK:
        _WK["ss"] = wk_state_space()
        _WK["sections"] = np.ascontiguousarray(wk_sections())
    return _WK["ss"]


def _wk_sections():
    _wk()
    return _WK["sections"]


_XBUF = threading.local()


def _exact_step_buffers(n_p: int, n_wk: int):
    """The exact-step set-up kept between runs of this thread (K.x_buffers): the kernel
    rebuilds it only when the linear system or the road kind changes, so a sweep whose
    points share a system (inputs, seeds) builds it once. Per thread: a set-up is
    written by one kernel call at a time."""
    from .suspension import _kernels as K

    key = (n_p, n_wk)
    buf = getattr(_XBUF, "buffers", None)
    if buf is None or _XBUF.key != key:
        _XBUF.buffers, _XBUF.key = K.x_buffers(n_p, n_wk), key
    return _XBUF.buffers


def _run_numba(model, excitation, horizon, options, want_series) -> _Run:
    from .suspension import _kernels as K

    y, x1 = _initial_state(model, excitation, horizon)
    segs = np.ascontiguousarray(excitation.segments(horizon), dtype=float)
    # the Wk filter states get a 1e4x looser absolute tolerance (decisions.md): the
    # filter is linear and stable and would otherwise set the step size. Its 100 Hz
    # section and the a_w integrals are advanced exactly by the kernel, outside the
    # error norm. 1e4 keeps every metric within 3e-7 of the rtol 1e-10 reference on the
    # suspension x input x law matrix
    scales = model.state_scales.copy()
    n = model.n_states
    scales[n + 3 : n + 11] *= WK_TOLERANCE_FACTOR
    atol = options.rtol * scales
    wk = _wk_sections()
    ts = _sample_times(horizon, options.sample_rate) if want_series else np.empty(0)
    out_y = np.empty((ts.size, y.size))
    out_a3 = np.empty(ts.size)
    peaks = np.empty(K.N_PEAKS)
    stats = np.zeros(7, dtype=np.int64)
    jumps = np.zeros(len(segs))
    status = K.integrate(
        model.kernel_parameters, segs, y, float(x1), float(horizon), float(options.rtol), atol,
        wk, ts, out_y, out_a3, peaks, stats, jumps, ROAD_JUMP_RTOL * road_scale(segs),
        bool(options.refine_peaks),
        int(options.max_steps), bool(options.exact_steps),
        *_exact_step_buffers(model.kernel_parameters.size, wk.size),
    )  # fmt: skip
    if status != K.OK:
        why = {
            K.TOO_MANY_STEPS: f"more than max_steps={options.max_steps} steps",
            K.STEP_TOO_SMALL: "the step size fell below round-off (stiff or discontinuous equations)",
            K.NOT_FINITE: "the solution is not finite (unstable parameters?)",
        }[status]
        hint = (
            "shorten --horizon (in Python: raise SimulationOptions.max_steps)"
            if status == K.TOO_MANY_STEPS
            else "try --backend scipy on the command line (in Python: "
            "SimulationOptions(backend='scipy', method='Radau') for stiff cases)"
        )
        raise ConvergenceError(f"numba backend stopped: {why}; {hint}")
    st = {
        "steps": int(stats[0]),
        "rejected": int(stats[1]),
        "rhs_calls": int(stats[2]),
        "kink_restarts": int(stats[3]),
        "exact_steps": int(stats[4]),
        "kink_steps": int(stats[5]),
        "exact_setups": int(stats[6]),
        "segments": len(segs),
    }
    samples = (ts, out_y, out_a3) if want_series else None
    jl = tuple(
        (float(segs[i, 0]), float(jumps[i]))
        for i in np.flatnonzero(jumps)
        if segs[i, 0] < horizon
    )
    return _Run(integrals=y[model.n_states :], peaks=peaks, samples=samples, stats=st, jumps=jl)


def _run_scipy(model, excitation, horizon, options, want_series) -> _Run:
    from scipy.integrate import solve_ivp
    from scipy.optimize import minimize_scalar

    from .suspension.reference import ReferenceRHS

    f = ReferenceRHS(model)
    y, x_prev = _initial_state(model, excitation, horizon)
    segs = excitation.segments(horizon)
    atol = options.rtol * model.state_scales
    peaks = np.full(7, -np.inf)
    ts = _sample_times(horizon, options.sample_rate) if want_series else np.empty(0)
    out_y = np.empty((ts.size, y.size))
    out_a3 = np.empty(ts.size)
    isamp = 0
    nsteps = nfev = 0
    jumps = []
    tol = ROAD_JUMP_RTOL * road_scale(segs)
    budget = {"calls": 0, "t": 0.0}
    max_calls = 16 * options.max_steps
    deadline = None if options.time_limit is None else time.monotonic() + options.time_limit

    class _OverBudget(Exception):
        pass

    def rhs(t, yy):
        # step and time limits: solve_ivp itself has neither
        budget["calls"] += 1
        budget["t"] = t
        if budget["calls"] > max_calls:
            raise _OverBudget(
                f"more than max_steps={options.max_steps} steps "
                f"({max_calls} right-hand-side evaluations)"
            )
        if deadline is not None and budget["calls"] % 256 == 0 and time.monotonic() > deadline:
            raise _OverBudget(f"the time limit of {options.time_limit:g} s was reached")
        return f(t, yy)

    def q_of(t, yy):
        a3, aw, z, ft = f.outputs(t, yy)
        return np.array([a3, -a3, aw, -aw, z, -z, ft])

    for seg in segs:
        t0, t1 = float(seg[0]), float(min(seg[1], horizon))
        f.seg = seg
        xs, _ = f.road(seg, t0)
        if abs(xs - x_prev) > tol:
            dv3 = f.apply_jump(y, xs - x_prev)
            if dv3 != 0.0 and t0 < horizon:
                jumps.append((t0, float(dv3)))
        x_prev, _ = f.road(seg, t1)
        if t1 <= t0:
            continue
        try:
            sol = solve_ivp(
                rhs,
                (t0, t1),
                y,
                method=options.method,
                rtol=options.rtol,
                atol=atol,
                dense_output=True,
            )
        except _OverBudget as exc:
            raise ConvergenceError(
                f"scipy {options.method} stopped at t = {budget['t']:.6g} s of "
                f"{horizon:g} s: {exc}; the equations are stiff or the horizon is long "
                "(try --backend numba, a shorter --horizon, or a larger --time-limit)"
            ) from None
        if sol.status != 0:
            raise ConvergenceError(f"scipy {options.method} failed: {sol.message}")
        nsteps += sol.t.size - 1
        nfev += sol.nfev
        # peaks: values at step ends and midpoints, then local maxima refined on the
        # dense output
        tt = np.concatenate([sol.t, 0.5 * (sol.t[1:] + sol.t[:-1])])
        order = np.argsort(tt)
        tt = tt[order]
        yy = sol.sol(tt)
        yy[:, 0] = sol.y[:, 0]
        yy[:, -1] = sol.y[:, -1]
        qs = np.array([q_of(t, yy[:, i]) for i, t in enumerate(tt)])
        for j in range(7):
            col = qs[:, j]
            top = col.max()
            peaks[j] = max(peaks[j], top)
            if col.size < 3:
                continue
            interior = np.where((col[1:-1] >= col[:-2]) & (col[1:-1] >= col[2:]))[0] + 1
            span = max(abs(top), 1e-300)
            for i in interior:
                if col[i] < top - 1e-2 * span:
                    continue
                res = minimize_scalar(
                    lambda t, j=j, s=sol.sol: -q_of(t, s(t))[j],
                    bounds=(tt[i - 1], tt[i + 1]),
                    method="bounded",
                    options={"xatol": 1e-13 * max(1.0, t1)},
                )
                peaks[j] = max(peaks[j], -res.fun)
        if want_series:
            last = t1 >= horizon
            while isamp < ts.size and (ts[isamp] < t1 or (last and ts[isamp] <= t1)):
                if ts[isamp] >= t0:
                    ys = sol.sol(ts[isamp]) if ts[isamp] > t0 else sol.y[:, 0]
                    out_y[isamp] = ys
                    out_a3[isamp] = f.outputs(ts[isamp], ys)[0]
                isamp += 1
        y = sol.y[:, -1].copy()
        if t1 >= horizon:
            break
    st = {"steps": nsteps, "rejected": None, "rhs_calls": nfev, "segments": len(segs)}
    samples = (ts, out_y, out_a3) if want_series else None
    return _Run(
        integrals=y[model.n_states :], peaks=peaks, samples=samples, stats=st, jumps=tuple(jumps)
    )


_BACKEND_FUNCS: dict[str, Callable[..., _Run]] = {"numba": _run_numba, "scipy": _run_scipy}


#: why a metric is not finite across a road step (the body acceleration holds a Dirac)
_DIRAC_REASON = (
    "not finite: the body velocity jumps at a road step ({jumps}), so the body "
    "acceleration holds a Dirac impulse; compare rms_body_acc_wk, vdv, or an "
    "edge-smoothed pulse (bump(edge=...), --edge)"
)


def _listed(items, unit: str) -> str:
    text = ", ".join(f"{v:+.4g} {unit} at t = {t:g} s" for t, v in items[:4])
    return text + (f", ... ({len(items)} in all)" if len(items) > 4 else "")


def _not_finite(model: QuarterCar, excitation: Excitation, run: _Run, horizon: float) -> dict:
    """Metrics that are not finite for this run, with the reason."""
    out = {}
    if run.jumps:
        why = _DIRAC_REASON.format(jumps=_listed(run.jumps, "m/s"))
        out.update(rms_body_acc=why, peak_body_acc=why)
    if model.parameters.tyre_damping > 0 and not model.tyre_lift_off:
        x1 = excitation.initial_road(horizon)
        down = [(t, j) for t, j in road_steps(excitation.segments(horizon), x1, horizon) if j < 0]
        if down:
            out["min_tyre_force"] = (
                f"not finite: the road steps down ({_listed(down, 'm')}) and the tyre damper "
                "would pull the wheel with a Dirac impulse C_t x step; model lift-off "
                "(tyre_lift_off=True, --lift-off) or smooth the edges (bump(edge=...), --edge)"
            )
    return out


def _metrics(
    model: QuarterCar, excitation: Excitation, run: _Run, horizon: float, not_finite=None
) -> dict:
    I = run.integrals
    pk = run.peaks
    w = model.parameters.static_tyre_load
    rms_wk = math.sqrt(max(I[11], 0.0) / horizon)
    peak_wk = max(pk[2], pk[3])
    min_force = float(w - pk[6])
    if model.tyre_lift_off:
        min_force = max(min_force, 0.0)  # the contact force is capped: it cannot pull
    out = {
        "rms_body_acc": math.sqrt(max(I[0], 0.0) / horizon),
        "rms_tyre_grip": math.sqrt(max(I[1], 0.0) / horizon),
        "rms_deflection": math.sqrt(max(I[2], 0.0) / horizon),
        "rms_body_acc_wk": rms_wk,
        "vdv": max(I[12], 0.0) ** 0.25,
        "crest_factor": peak_wk / rms_wk if rms_wk > 0 else 0.0,
        "peak_body_acc": float(max(pk[0], pk[1])),
        "peak_body_acc_wk": float(peak_wk),
        "peak_deflection": float(max(pk[4], pk[5])),
        "min_tyre_force": min_force,
        "tyre_lift_off": bool(pk[6] >= w),
    }
    if not_finite is None:
        not_finite = _not_finite(model, excitation, run, horizon)
    for key in not_finite:
        out[key] = None
        if key == "min_tyre_force":
            out["tyre_lift_off"] = True  # the contact force demanded goes below zero
    return out


def _check_inputs(model: Any, excitation: Any, horizon: Any, options: Any, output: str) -> float:
    if not isinstance(excitation, Excitation):
        raise ParameterError(
            "excitation", excitation, "an Excitation (drop(), bump(), sine(), iso8608(), ...)"
        )
    if not excitation.quarter_car_kernels:
        raise ParameterError(
            "excitation",
            excitation.name,
            "a road input (drop, bump, sine, ISO 8608, series); a measured drive runs on "
            "the core systems: inerterlab.systems.rig(...).simulate(drive, ...)",
        )
    if not isinstance(options, SimulationOptions):
        raise ParameterError("options", options, "a SimulationOptions")
    check_choice("output", output, OUTPUTS)
    T = check_positive("horizon", horizon, "s")
    excitation.check_horizon(T, stacklevel=3)
    return T


def _minimum_steps(excitation: Excitation, horizon: float) -> float:
    """A lower bound on the integration steps of either backend up to ``horizon``.

    Each road segment begun before the horizon starts a step of its own (the road is
    integrated segment by segment), and a sine needs at least four steps per period
    (measured: 8 or more at rtol 1e-3, the loosest tolerance accepted).
    """
    from .excitation import ISO8608Road, Sine

    if isinstance(excitation, Sine):
        return 1.0 + 4.0 * float(excitation.frequency) * horizon
    if isinstance(excitation, ISO8608Road):
        length = horizon * float(excitation.speed)
        if excitation.length is not None:
            length = min(length, float(excitation.length))
        return length / float(excitation.spatial_step)
    segs = excitation.segments(horizon)
    return float(np.count_nonzero(segs[:, 0] < horizon))


#: a long sine run (its lower bound of steps at least this fraction of max_steps) is
#: measured by a pilot integration before it starts
_PILOT_FRACTION = 2e-4
#: periods of each of the pilot's two legs
_PILOT_PERIODS = 10


def _sine_steps(
    model: QuarterCar, excitation: Excitation, horizon: float, options, want_series: bool
) -> float:
    """Steps the numba backend takes for a sine up to ``horizon`` (:func:`sine_steps`)."""
    return sine_steps(
        lambda t: _run_numba(model, excitation, t, options, want_series).stats["steps"],
        excitation,
        horizon,
    )


def sine_steps(steps_to, excitation: Excitation, horizon: float) -> float:
    """Steps an integrator takes for a sine up to ``horizon``, measured: the steps
    ``steps_to(t)`` of the first 2 N periods plus the rate of the second N (the settled
    periodic motion, whose step pattern repeats every period) over the rest of the
    horizon. Within 5 % of the real count of both engines (tests/test_reliability_core.py)."""
    t1 = _PILOT_PERIODS / float(excitation.frequency)
    s1 = steps_to(t1)
    s2 = steps_to(2 * t1)
    return s2 + max(s2 - s1, 1) / t1 * (horizon - 2 * t1)


def check_sine_steps(steps_to, excitation, horizon: float, rtol: float, max_steps: int) -> None:
    """Refuse a long sine whose measured step estimate (:func:`sine_steps`) passes
    ``max_steps``; a short one (below :data:`_PILOT_FRACTION` of the budget by the lower
    bound of four steps per period, or within 2 N periods) is not measured."""
    from .excitation import Sine

    if not isinstance(excitation, Sine):
        return
    need = _minimum_steps(excitation, horizon)
    if need > max_steps:
        raise ParameterError(
            "horizon",
            horizon,
            f"at most {horizon * max_steps / need:.3g} s for this input: it needs at least "
            f"{need:.3g} integration steps (four per sine period), the step budget is "
            f"max_steps={max_steps}",
        )
    if need < _PILOT_FRACTION * max_steps:
        return
    if horizon <= 2 * _PILOT_PERIODS / float(excitation.frequency):
        return
    est = sine_steps(steps_to, excitation, horizon)
    if est > max_steps:
        raise ParameterError(
            "horizon",
            horizon,
            f"at most {horizon * max_steps / est:.3g} s for this sine and "
            f"rtol={rtol:g}: it needs about {est:.3g} integration steps "
            f"(measured over its first {2 * _PILOT_PERIODS} periods), the step budget "
            f"is max_steps={max_steps}",
        )


def _check_step_budget(
    model: QuarterCar, excitation: Excitation, horizon: float, options, want_series: bool
) -> None:
    """Refuse up front a run whose step count must exceed ``options.max_steps``: by a
    lower bound (one step per road segment, four per sine period) and, for a long sine
    on the numba backend, by a measured estimate (:func:`_sine_steps`)."""
    from .excitation import ISO8608Road

    if options.backend == "numba":
        check_sine_steps(
            lambda t: _run_numba(model, excitation, t, options, want_series).stats["steps"],
            excitation,
            horizon,
            options.rtol,
            options.max_steps,
        )
    need = _minimum_steps(excitation, horizon)
    if need > options.max_steps:
        at = (
            f" at speed={float(excitation.speed):g} m/s (or a lower speed)"
            if isinstance(excitation, ISO8608Road)
            else ""
        )
        raise ParameterError(
            "horizon",
            horizon,
            f"at most {horizon * options.max_steps / need:.3g} s for this input{at}: it needs "
            f"at least {need:.3g} integration steps (one per road segment, four per sine "
            f"period), the step budget is max_steps={options.max_steps}",
        )


def simulate(
    model: QuarterCar,
    excitation: Excitation,
    horizon: float = 10.0,
    *,
    options: SimulationOptions = DEFAULT_OPTIONS,
    output: str = "series",
) -> SimulationResult:
    """Simulate ``model`` on ``excitation`` from t = 0 to ``horizon`` [s].

    Parameters
    ----------
    model : System
        A named quarter car from :func:`inerterlab.quarter_car` (or its description,
        ``info["model"]``).
    excitation : Excitation
        :func:`~inerterlab.excitation.drop`, ``bump``, ``sine``, ``iso8608``, a road series.
    horizon : float
        T [s], 10 s by default (docs/model.md §5).
    options : SimulationOptions
        Backend, tolerance, sampling rate.
    output : {"series", "metrics"}
        ``metrics`` skips the sampled time series (faster, for sweeps).

    Returns
    -------
    SimulationResult
    """
    model = model_of(model)
    T = _check_inputs(model, excitation, horizon, options, output)
    want = output == "series"
    _check_step_budget(model, excitation, T, options, want)
    run = _BACKEND_FUNCS[options.backend](model, excitation, T, options, want)
    kw: dict = {}
    if want:
        ts, ys, a3 = run.samples
        n = model.n_states
        wa, wb, wc, wd = _wk()
        segs = excitation.segments(T)
        x1, v1 = road_displacement(segs, ts)
        kw = dict(
            time=ts,
            states=ys[:, :n].copy(),
            body_acc=a3,
            body_acc_wk=ys[:, n + 3 : n + 11] @ wc + wd * a3,
            road=x1,
            road_velocity=v1,
        )
    nf = _not_finite(model, excitation, run, T)
    return SimulationResult(
        model=model,
        excitation=excitation,
        horizon=T,
        options=options,
        values=_metrics(model, excitation, run, T, nf),
        stats=run.stats,
        body_velocity_jumps=run.jumps,
        not_finite=nf,
        **kw,
    )


def simulate_metrics(
    model: QuarterCar,
    excitation: Excitation,
    horizon: float = 10.0,
    *,
    options: SimulationOptions = DEFAULT_OPTIONS,
) -> dict:
    """Metrics only (the fast path for sweeps): ``simulate(..., output="metrics").metrics()``."""
    model = model_of(model)
    T = _check_inputs(model, excitation, horizon, options, "metrics")
    _check_step_budget(model, excitation, T, options, False)
    run = _BACKEND_FUNCS[options.backend](model, excitation, T, options, False)
    return _metrics(model, excitation, run, T)


class _CallableModule(types.ModuleType):
    """This module; calling it (``inerterlab.simulate(car, road, T)``) calls :func:`simulate`."""

    def __call__(self, *args, **kwargs) -> SimulationResult:
        return simulate(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
