"""The changing-ratio study of thesis sections 4.3 and 6.3.

* :func:`performance_function` - (4.30)-(4.33): for each input, body acceleration and tyre
  grip index divided by those of the traditional suspension under the same input,
  weighted x1 (comfort) and x2 (grip); the inputs are then weighted x3, x4, x5.
  Suspension deflection is left out, as in the thesis (it hardly depends on the ratio).
* :data:`COST_FUNCTIONS` - the printed cost (4.34) (``thesis``: 1 + 0.8x up to x = 0.2,
  then 1.16 + (x + 0.8)^2, which jumps from 1.16 to 2.16 at 0.2) and ``continuous``,
  the same curve with the jump removed: 1 + 0.8x up to 0.2, then 0.16 + (x + 0.8)^2.
* :func:`optimize_ratio` - Chebyshev goal programming (4.38)-(4.39) over a continuous
  changing ratio: performance and cost are each normalised by their own best and worst
  value over the studied range (5-55 %), and the ratio minimising the larger of the two
  normalised values is returned.

The metrics at any ratio come from a *ratio model*: :class:`OnDemandRatioModel` runs the
point function at exactly the requested ratio (so the answer does not depend on any
grid), :class:`InterpolatedRatioModel` interpolates a changing-ratio sweep with cubic
splines.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ParameterError, check_choice
from .goal import GoalProgrammingResult, chebyshev_goal_programming
from .points import point_function
from .spec import PerformanceWeights

__all__ = [
    "COST_FUNCTIONS",
    "COST_BREAKPOINTS",
    "DEVICES",
    "THESIS_OPTIMUM",
    "THESIS_RATIOS",
    "INPUTS",
    "cost_thesis",
    "cost_continuous",
    "performance_function",
    "comfort_metric_for",
    "OnDemandRatioModel",
    "InterpolatedRatioModel",
    "baseline_metrics",
    "RatioOptimum",
    "optimize_ratio",
    "ratio_model",
]

INPUTS = ("drop", "bump", "sine")
#: device name of the CLI -> suspension of the quarter car
DEVICES = {"ideal": "afw", "hydraulic": "device-afw"}
#: the thesis's optimal changing ratios (4.3.4.2 and 6.3.4.1)
THESIS_OPTIMUM = {"ideal": 0.258, "hydraulic": 0.316}
#: changing ratios of tables 4.10-4.12 and 6.10-6.12
THESIS_RATIOS = tuple(round(0.05 * k, 2) for k in range(1, 12))
RATIO_BOUNDS = (0.05, 0.55)


def cost_thesis(x: float) -> float:
    """Cost (4.34) as printed: 1 + 0.8x for x <= 0.2, else 1.16 + (x + 0.8)^2 [-].

    Discontinuous at x = 0.2 (1.16 from the left, 2.16 from the right); kept as printed.

    Examples
    --------
    >>> round(cost_thesis(0.2), 6), round(cost_thesis(0.2 + 1e-12), 6)
    (1.16, 2.16)
    """
    return 1.0 + 0.8 * x if x <= 0.2 else 1.16 + (x + 0.8) ** 2


def cost_continuous(x: float) -> float:
    """(4.34) with its jump removed: 1 + 0.8x for x <= 0.2, else 0.16 + (x + 0.8)^2 [-].

    Equal to the printed curve up to 0.2 and the printed curve lowered by 1 above it,
    so it is continuous (value 1.16 at 0.2) and keeps the printed growth rate.

    Examples
    --------
    >>> round(cost_continuous(0.2), 6), round(cost_continuous(0.2 + 1e-12), 6)
    (1.16, 1.16)
    """
    return 1.0 + 0.8 * x if x <= 0.2 else 0.16 + (x + 0.8) ** 2


COST_FUNCTIONS: dict[str, Callable[[float], float]] = {
    "thesis": cost_thesis,
    "continuous": cost_continuous,
}
COST_BREAKPOINTS = (0.2,)


def performance_function(
    metrics: Mapping[str, Mapping[str, float]],
    baseline: Mapping[str, Mapping[str, float]],
    weights: PerformanceWeights,
    *,
    comfort_metric: str = "rms_body_acc",
    grip_metric: str = "rms_tyre_grip",
) -> float:
    """Overall performance f_p (4.33) built from the per-input functions (4.30)-(4.32).

    f_p = sum over inputs j of w_j [x1 a_j / a_j,trad + x2 g_j / g_j,trad], with a the
    body acceleration and g the tyre grip index; smaller is better, 1 is the
    traditional suspension.

    Examples
    --------
    >>> m = {"drop": {"rms_body_acc": 1.0, "rms_tyre_grip": 1.0}}
    >>> b = {"drop": {"rms_body_acc": 2.0, "rms_tyre_grip": 4.0}}
    >>> w = PerformanceWeights(comfort=0.5, grip=0.5, inputs=(("drop", 1.0),))
    >>> performance_function(m, b, w)
    0.375
    """
    total = 0.0
    for name, w in weights.inputs:
        if w == 0.0:
            continue
        m, b = metrics[name], baseline[name]
        cm = comfort_metric_for(m, b, comfort_metric)
        total += w * (
            weights.comfort * m[cm] / b[cm] + weights.grip * m[grip_metric] / b[grip_metric]
        )
    return float(total)


#: the comfort metric used for an input where the chosen one is not finite (the
#: unweighted body acceleration across a road step with an inerter)
FINITE_COMFORT_METRIC = "rms_body_acc_wk"


def _finite(v) -> bool:
    return v is not None and math.isfinite(float(v))


def comfort_metric_for(metrics: Mapping[str, float], baseline: Mapping[str, float], name: str) -> str:
    """``name``, or the Wk-weighted RMS where ``name`` is not finite for this input.

    Across a rectangular road step an inerter between wheel and body passes an impulse
    to the body, so its unweighted RMS acceleration is infinite (reported as ``None`` or
    NaN). The comfort ratio of that input is then taken on the ISO 2631 Wk-weighted RMS,
    for the candidate and the traditional baseline alike, so the ratio stays a ratio of
    like quantities.

    >>> comfort_metric_for({"rms_body_acc": None}, {"rms_body_acc": 1.0}, "rms_body_acc")
    'rms_body_acc_wk'
    """
    if _finite(metrics.get(name)) and _finite(baseline.get(name)):
        return name
    return FINITE_COMFORT_METRIC


class OnDemandRatioModel:
    """Metrics at any changing ratio, by running the point function there (cached).

    Parameters
    ----------
    point : str
        Point function name.
    settings : dict
        Fixed parameters (suspension, sprung mass, horizon, ...).
    inputs : sequence of str
        Inputs to evaluate at each ratio.
    """

    def __init__(self, point: str, settings: Mapping[str, Any], inputs: Sequence[str] = INPUTS):
        self.point = point_function(point)
        self.settings = dict(settings)
        self.inputs = tuple(inputs)
        self.evaluations = 0
        self._cache: dict[float, dict] = {}
        for key, value in self.settings.items():
            self.point.check_parameter(f"settings.{key}", key, value)

    def __call__(self, x: float) -> dict[str, dict[str, float]]:
        key = float(x)
        if key not in self._cache:
            out = {}
            for name in self.inputs:
                params = {**self.point.defaults, **self.settings, "input": name}
                params["changing_ratio"] = key
                self.evaluations += 1
                res = self.point.function(params)
                # None stays None: not finite across a road step
                out[name] = {k: (None if v is None else float(v)) for k, v in res.items()}
            self._cache[key] = out
        return self._cache[key]


class InterpolatedRatioModel:
    """Metrics at any changing ratio from a sweep over (changing_ratio, input).

    Each metric of each input is interpolated with a not-a-knot cubic spline in the
    changing ratio; evaluation outside the swept range is refused.

    Parameters
    ----------
    dataset : xarray.Dataset
        A sweep result with dimensions ``changing_ratio`` and ``input`` (others must
        have length 1). Every point must have status ok.
    """

    def __init__(self, dataset, metrics: Sequence[str] | None = None):
        from scipy.interpolate import CubicSpline

        ds = dataset.squeeze(drop=True)
        if set(ds.status.dims) != {"changing_ratio", "input"}:
            raise ParameterError(
                "dataset", dict(ds.sizes), "a sweep over changing_ratio and input only"
            )
        if int((ds.status != 1).sum()) > 0:
            bad = ds.reason.where(ds.status != 1, drop=True).values.ravel()
            raise ParameterError(
                "dataset", "failed points", f"a sweep without failed points ({bad[0]})"
            )
        xs = np.asarray(ds.changing_ratio.values, dtype=float)
        if len(xs) < 4:
            raise ParameterError("changing_ratio", list(xs), "at least 4 swept ratios")
        self.bounds = (float(xs.min()), float(xs.max()))
        names = metrics or [v for v in ds.data_vars if v not in ("status", "reason")]
        self.inputs = tuple(str(i) for i in ds.input.values)
        self._splines = {}
        for i in self.inputs:
            for m in names:
                ys = np.asarray(ds[m].sel(input=i).transpose("changing_ratio").values, float)
                # a metric that is not finite across a road step is NaN at every ratio
                self._splines[(i, m)] = CubicSpline(xs, ys) if np.all(np.isfinite(ys)) else None

    def __call__(self, x: float) -> dict[str, dict[str, float]]:
        lo, hi = self.bounds
        if not lo - 1e-12 <= x <= hi + 1e-12:
            raise ParameterError("changing_ratio", x, f"a ratio in the swept range [{lo}, {hi}]")
        out: dict[str, dict[str, float]] = {i: {} for i in self.inputs}
        for (i, m), s in self._splines.items():
            out[i][m] = None if s is None else float(s(x))
        return out


def baseline_metrics(
    point: str, settings: Mapping[str, Any], inputs: Sequence[str] = INPUTS
) -> dict[str, dict[str, float]]:
    """Metrics of the ``traditional`` suspension for each input (the divisors of (4.30)-(4.32))."""
    pf = point_function(point)
    out = {}
    for name in inputs:
        params = {**pf.defaults, **dict(settings), "input": name, "suspension": "traditional"}
        out[name] = {
            k: (None if v is None else float(v)) for k, v in pf.function(params).items()
        }
    return out


@dataclass(frozen=True, kw_only=True)
class RatioOptimum:
    """The optimal changing ratio and what it gives.

    Attributes
    ----------
    optimal_ratio : float
        x [-].
    lam : float
        lambda of (4.38): the larger normalised deviation at x.
    performance, cost : float
        f_p(x) (4.33) and f_c(x) (4.34).
    metrics : dict
        Input -> metric -> value at x.
    baseline : dict
        The traditional suspension's metrics.
    goal : GoalProgrammingResult
        Best/worst values used for the normalisation.
    """

    optimal_ratio: float
    lam: float
    performance: float
    cost: float
    metrics: dict
    baseline: dict
    weights: PerformanceWeights
    cost_function: str
    goal: GoalProgrammingResult
    settings: dict = field(default_factory=dict)
    bounds: tuple[float, float] = RATIO_BOUNDS

    @property
    def at_bound(self) -> str | None:
        """``"lower"`` or ``"upper"`` if the optimum sits on that end of the search
        range (within 1e-6 of its width), else None: the range, not the trade-off,
        then decides the answer."""
        lo, hi = self.bounds
        tol = 1e-6 * (hi - lo)
        if self.optimal_ratio <= lo + tol:
            return "lower"
        if self.optimal_ratio >= hi - tol:
            return "upper"
        return None

    def bound_note(self) -> str:
        """One sentence on the optimum's position in the search range ("" if inside)."""
        side = self.at_bound
        if side is None:
            return ""
        value = self.bounds[0 if side == "lower" else 1]
        return (
            f"the optimum is at the {side} bound of the search range "
            f"{self.bounds[0]:g}-{self.bounds[1]:g} (x = {value:g}): the compromise lies at "
            f"the edge of the range searched, and a wider range could move it"
        )

    def __repr__(self) -> str:
        where = f", at the {self.at_bound} bound" if self.at_bound else ""
        return (
            f"<RatioOptimum x={self.optimal_ratio:.4g}{where} (range {self.bounds[0]:g}-"
            f"{self.bounds[1]:g}), lambda={self.lam:.4g}, performance={self.performance:.4g}, "
            f"cost={self.cost:.4g} ({self.cost_function})>"
        )

    def _repr_html_(self) -> str:
        from .._display import html_table

        rows = [
            ("optimal changing ratio x", f"{self.optimal_ratio:.4g}"
             + (f" (at the {self.at_bound} bound)" if self.at_bound else "")),
            ("search range", f"{self.bounds[0]:g} .. {self.bounds[1]:g}"),
            ("lambda (4.38)", f"{self.lam:.4g}"),
            ("performance (4.33)", f"{self.performance:.4g}"),
            (f"cost (4.34, {self.cost_function})", f"{self.cost:.4g}"),
        ]  # fmt: skip
        return html_table("optimal changing ratio", rows)

    def to_xarray(self):
        """Metrics at the optimum and of the traditional suspension, by input and metric."""
        import xarray as xr

        from ..metrics import METRIC_UNITS

        inputs = list(self.metrics)
        names = sorted({k for v in self.metrics.values() for k in v})
        at = [[self.metrics[i].get(k, np.nan) for k in names] for i in inputs]
        base = [[self.baseline.get(i, {}).get(k, np.nan) for k in names] for i in inputs]
        ds = xr.Dataset(
            {
                "optimum": (("input", "metric"), np.asarray(at, dtype=float)),
                "baseline": (("input", "metric"), np.asarray(base, dtype=float)),
                "units": ("metric", [METRIC_UNITS.get(k, "") for k in names]),
            },
            coords={"input": inputs, "metric": names},
        )
        ds.attrs.update(
            optimal_ratio=self.optimal_ratio,
            at_bound=self.at_bound or "none",
            lam=self.lam,
            performance=self.performance,
            cost=self.cost,
            cost_function=self.cost_function,
        )
        return ds

    def to_dict(self) -> dict:
        """JSON-ready summary (the ``optimize-ratio --json`` output)."""
        g = self.goal
        return {
            "optimal_ratio": self.optimal_ratio,
            "at_bound": self.at_bound,
            "search_range": list(self.bounds),
            "lambda": self.lam,
            "performance": self.performance,
            "cost": self.cost,
            "metrics": self.metrics,
            "baseline": self.baseline,
            "normalisation": {
                "performance_best": g.best[0],
                "performance_worst": g.worst[0],
                "cost_best": g.best[1],
                "cost_worst": g.worst[1],
                "performance_best_ratio": g.best_x[0],
                "performance_worst_ratio": g.worst_x[0],
            },
            "weights": self.weights.to_dict(),
            "cost_function": self.cost_function,
            "settings": self.settings,
        }


def optimize_ratio(
    model: Callable[[float], Mapping[str, Mapping[str, float]]],
    baseline: Mapping[str, Mapping[str, float]],
    *,
    weights: PerformanceWeights | None = None,
    cost: str = "thesis",
    bounds: tuple[float, float] = RATIO_BOUNDS,
    comfort_metric: str = "rms_body_acc",
    grip_metric: str = "rms_tyre_grip",
    grid: int = 101,
    settings: Mapping[str, Any] | None = None,
) -> RatioOptimum:
    """Optimal changing ratio by Chebyshev goal programming (4.38)-(4.39).

    Parameters
    ----------
    model : callable
        x -> input -> metric -> value (:class:`OnDemandRatioModel` or
        :class:`InterpolatedRatioModel`).
    baseline : dict
        Traditional suspension's metrics per input (:func:`baseline_metrics`).
    weights : PerformanceWeights
        x1..x5 (default 0.35, 0.65, 0.1, 0.5, 0.4).
    cost : {"thesis", "continuous"}
        Cost function (4.34) as printed, or its continuous variant.
    bounds : (float, float)
        Range of changing ratios over which best and worst values are taken (5-55 %).
    grid : int
        Bracketing grid of the optimiser (not a sweep grid).
    """
    weights = weights or PerformanceWeights()
    check_choice("cost", cost, tuple(COST_FUNCTIONS))
    cost_fn = COST_FUNCTIONS[cost]

    def perf(x: float) -> float:
        return performance_function(
            model(x), baseline, weights, comfort_metric=comfort_metric, grip_metric=grip_metric
        )

    goal = chebyshev_goal_programming(
        [perf, cost_fn], bounds, grid=grid, breakpoints=COST_BREAKPOINTS
    )
    x = goal.x
    used = {name for name, w in weights.inputs}
    return RatioOptimum(
        optimal_ratio=x,
        lam=goal.lam,
        performance=goal.values[0],
        cost=goal.values[1],
        metrics={k: dict(v) for k, v in model(x).items() if k in used},
        baseline={k: dict(v) for k, v in baseline.items() if k in used},
        weights=weights,
        cost_function=cost,
        goal=goal,
        settings=dict(settings or {}),
        bounds=(float(bounds[0]), float(bounds[1])),
    )


def ratio_model(
    device: str = "ideal",
    *,
    point: str = "quarter-car",
    settings: Mapping[str, Any] | None = None,
    inputs: Sequence[str] = INPUTS,
) -> tuple[OnDemandRatioModel, dict]:
    """An on-demand ratio model and the baseline for ``device`` ("ideal" or "hydraulic").

    ``settings`` are extra fixed parameters (e.g. ``horizon``); the sprung mass defaults
    to 370 kg as in tables 4.10-4.12 and 6.10-6.12.
    """
    check_choice("device", device, tuple(DEVICES))
    s = {"sprung_mass": 370.0, **dict(settings or {})}
    model = OnDemandRatioModel(point, {**s, "suspension": DEVICES[device]}, inputs)
    return model, baseline_metrics(point, s, inputs)
