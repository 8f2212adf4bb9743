"""The named quarter cars on a road -> :class:`SimulationResult` (docs/model.md §5).

The car runs on the model core (:mod:`inerterlab.systems`): the named suspension as a
network of :func:`inerterlab.quarter_car`, integrated by the core's compiled
Dormand-Prince 5(4) (or its exact steps where the car is linear) with events at the
elements' kinks, the ride metrics carried as observer states
(:func:`inerterlab.systems.observers.ride`: the metric integrals, the Wk filter, the
peaks located on the continuous extension). The tyre-damper impulse C_t x jump is
applied where the road jumps. Absolute tolerances are ``atol`` (default ``rtol``) times
a typical size of each state. The tests hold it against an oracle written apart from
the core (``tests/_quarter_car_oracle.py``: plain Python under scipy's ``solve_ivp``).

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
import types
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import ParameterError, check_choice, check_positive
from .excitation import Excitation
from .resources import check_memory
from .suspension.model import QuarterCar, model_of
from .systems.options import DEFAULT_OPTIONS, SimulationOptions

__all__ = [
    "SimulationOptions",
    "SimulationResult",
    "simulate",
    "simulate_metrics",
]

OUTPUTS = ("series", "metrics")


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
        Physical states at the samples, columns :attr:`state_names` (``wheel.x``,
        ``wheel.v``, ``body.x``, ``body.v``, then the suspension's own).
    state_names : tuple
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
    state_names: tuple = ()
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
        for name in self.state_names:
            if name not in units:
                units[name] = (
                    "m/s" if name.endswith(("_vel", "_rate", "_velocity", ".v", ".v_rel")) else "m"
                )
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
        for i, name in enumerate(self.state_names):
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
        out.update(horizon=self.horizon, rtol=self.options.rtol)
        return out

    def plot(self, **kwargs):
        """Figure of body acceleration, deflection and tyre force against time."""
        from .suspension.plot import plot_simulation

        return plot_simulation(self, **kwargs)


# -- the run -----------------------------------------------------------------------------
@dataclass
class _Run:
    values: dict  # the final values of the ride observers (systems.observers.ride)
    samples: dict | None  # time, states, state_names, body_acc, body_acc_wk, road, road_velocity
    stats: dict
    jumps: tuple = ()  # ((time [s], body velocity jump [m/s]), ...) where not zero
    not_finite: dict = field(default_factory=dict)  # the core's metrics that are not finite


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


#: the body velocity before a road step is read this long [s] before it (x max(1, t)),
#: on the continuous extension (an error of the acceleration times this)
_BEFORE_STEP = 1e-9


def _run(model, excitation, horizon, options, want_series) -> _Run:
    from .systems.core import _simulate
    from .systems.quarter_car import system_of

    sys_ = system_of(model)
    road = excitation.prepared(horizon)
    ts = _sample_times(horizon, options.sample_rate) if want_series else np.array([horizon])
    # where the body velocity jumps at a road step (an inertance between wheel and body):
    # the body velocity just before and at each step
    steps = []
    if sys_.info["velocity_jump_per_step"].get("body", 0.0) != 0.0:
        steps = [t for t, _ in road.steps if t < horizon]
    before = [t - _BEFORE_STEP * max(1.0, t) for t in steps if t > 0.0]
    times = np.union1d(ts, np.array(before + steps, float)) if steps else ts
    res = _simulate(sys_, excitation, horizon, options, times=times, ride=True)
    jumps = []
    if steps:
        iv = sys_.state_names.index("body.v")
        v = res.states[:, iv]
        acc = res.outputs["body.a"]
        for t in steps:
            after = v[np.searchsorted(times, t)]
            prior = 0.0
            if t > 0.0:  # the velocity read just before, carried to the step by a
                d = _BEFORE_STEP * max(1.0, t)
                j = np.searchsorted(times, t - d)
                prior = v[j] + acc[j] * (t - times[j])
            if after != prior:
                jumps.append((float(t), float(after - prior)))
    samples = None
    if want_series:
        pick = np.searchsorted(times, ts)
        o = res.outputs
        samples = dict(
            time=ts, states=res.states[pick], state_names=sys_.state_names,
            body_acc=o["body_acc"][pick], body_acc_wk=o["body_acc_wk"][pick],
            road=o["road.x"][pick], road_velocity=o["road.v"][pick],
        )  # fmt: skip
    values = {k: v for k, v in res.observed.items() if k.startswith("ride.")}
    stats = dict(res.stats, segments=len(road.segments))
    return _Run(
        values=values, samples=samples, stats=stats, jumps=tuple(jumps),
        not_finite=dict(res.not_finite),
    )  # fmt: skip


#: why a metric is not finite across a road step (the body acceleration holds a Dirac),
#: with the body velocity's jumps measured at the steps
_DIRAC_REASON = (
    "not finite: the body velocity jumps at a road step ({jumps}), so the body "
    "acceleration holds a Dirac impulse; compare rms_body_acc_wk, vdv, or an "
    "edge-smoothed pulse (bump(edge=...), --edge)"
)


def _not_finite(run: _Run) -> dict:
    """Metrics that are not finite for this run, with the reason: the model core's
    decision (:func:`inerterlab.systems.core._simulate`), the body's reason naming the
    velocity jumps measured here."""
    from .systems.core import listed_steps

    out = dict(run.not_finite)
    if run.jumps:
        why = _DIRAC_REASON.format(jumps=listed_steps(run.jumps, "m/s"))
        out.update({k: why for k in ("rms_body_acc", "peak_body_acc") if k in out})
    return out


def _metrics(
    model: QuarterCar, excitation: Excitation, run: _Run, horizon: float, not_finite=None
) -> dict:
    from .systems.observers import ride_metrics

    out = ride_metrics(run.values, horizon, model.parameters.static_tyre_load)
    if model.tyre_lift_off:
        out["min_tyre_force"] = max(out["min_tyre_force"], 0.0)  # it cannot pull
    if not_finite is None:
        not_finite = _not_finite(run)
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
    if not excitation.is_road:
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
    """A lower bound on the integration steps up to ``horizon``.

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
    segs = excitation.prepared(horizon).segments
    return float(np.count_nonzero(segs[:, 0] < horizon))


#: a long sine run (its lower bound of steps at least this fraction of max_steps) is
#: measured by a pilot integration before it starts
_PILOT_FRACTION = 2e-4
#: periods of each of the pilot's two legs
_PILOT_PERIODS = 10


def _sine_steps(
    model: QuarterCar, excitation: Excitation, horizon: float, options, want_series: bool
) -> float:
    """Steps the core takes for a sine up to ``horizon`` (:func:`sine_steps`)."""
    return sine_steps(
        lambda t: _attempts(_run(model, excitation, t, options, want_series).stats),
        excitation,
        horizon,
    )


def _attempts(stats: dict) -> int:
    """The steps a run counts against ``max_steps``: accepted and rejected ones."""
    return int(stats.get("steps", 0)) + int(stats.get("rejected") or 0)


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
    by a measured estimate (:func:`_sine_steps`)."""
    from .excitation import ISO8608Road

    check_sine_steps(
        lambda t: _attempts(_run(model, excitation, t, options, want_series).stats),
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
        Tolerance, method, sampling rate, step budget.
    output : {"series", "metrics"}
        ``metrics`` skips the sampled time series (faster, for sweeps).

    Returns
    -------
    SimulationResult
    """
    model = model_of(model)
    T = _check_inputs(model, excitation, horizon, options, output)
    want = output == "series"
    if want:  # the series' memory first: refused before any step is taken
        _sample_times(T, options.sample_rate)
    _check_step_budget(model, excitation, T, options, want)
    run = _run(model, excitation, T, options, want)
    kw: dict = {}
    if want:
        kw = dict(run.samples)
    nf = _not_finite(run)
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
    run = _run(model, excitation, T, options, False)
    return _metrics(model, excitation, run, T)


class _CallableModule(types.ModuleType):
    """This module; calling it (``inerterlab.simulate(car, road, T)``) calls :func:`simulate`."""

    def __call__(self, *args, **kwargs) -> SimulationResult:
        return simulate(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
