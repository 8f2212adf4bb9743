"""Global sensitivity of ride metrics to the device's parameters: Sobol indices.

Where :func:`~inerterlab.identify.propagate` asks how uncertain a metric is given the
fit, this asks which parameter the metric depends on over a whole range of values:
the first-order index S1_i is the share of the metric's variance explained by
parameter i alone, the total index ST_i the share that involves parameter i in any
way (alone or in interaction). The parameters are taken as independent and uniform
over their ranges. Sampling is Saltelli's scheme on a Sobol' sequence
(``SALib.sample.sobol``), N (D + 2) model runs for D parameters and N base samples;
the indices and their 95 % bootstrap half-widths come from ``SALib.analyze.sobol``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..errors import ParameterError

__all__ = ["SobolResult", "sobol_indices", "ride_sensitivity", "DEFAULT_RANGES"]

#: relative ranges (fraction of the car's value) of the device parameters and the
#: absolute range of the flywheel's changing ratio used by :func:`ride_sensitivity`
DEFAULT_RANGES = {"stiffness": 0.2, "damping": 0.2, "friction": 0.2, "changing_ratio": (0.2, 0.8)}


class SobolResult:
    """Sobol indices per output and parameter.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per (output, parameter): ``S1``, ``S1_conf``, ``ST``, ``ST_conf``
        (the ``_conf`` columns are 95 % bootstrap half-widths).
    bounds : dict
        Parameter -> (low, high).
    n : int
        Base samples; ``runs`` = model evaluations.
    """

    def __init__(self, table, bounds, n, runs):
        self.table = table
        self.bounds = bounds
        self.n = n
        self.runs = runs

    def to_pandas(self):
        return self.table

    def plot(self, *, title: str | None = None):
        """Bar chart of S1 and ST with their bootstrap half-widths, one panel per output
        (a :class:`matplotlib.figure.Figure`, built without pyplot)."""
        from matplotlib.figure import Figure

        outputs = list(dict.fromkeys(self.table["output"]))
        names = list(self.bounds)
        cols = min(3, len(outputs))
        rows = math.ceil(len(outputs) / cols)
        fig = Figure(figsize=(4.0 * cols, 3.0 * rows), layout="constrained")
        axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
        x = np.arange(len(names))
        for ax, out in zip(axes, outputs, strict=False):
            t = self.table[self.table["output"] == out].set_index("parameter").loc[names]
            ax.bar(x - 0.2, t["S1"], 0.4, yerr=t["S1_conf"], label="first order S1", capsize=2)
            ax.bar(x + 0.2, t["ST"], 0.4, yerr=t["ST_conf"], label="total ST", capsize=2)
            ax.set_xticks(x, names, rotation=20)
            ax.set_ylim(min(0.0, float(t[["S1", "ST"]].min().min()) - 0.05), 1.05)
            ax.set_title(out)
        for ax in axes[len(outputs) :]:
            ax.set_visible(False)
        axes[0].legend(loc="upper right", fontsize="small")
        if title:
            fig.suptitle(title)
        return fig


def sobol_indices(
    f: Callable,
    bounds: dict,
    *,
    n: int = 256,
    seed: int = 0,
    vectorized: bool = False,
) -> SobolResult:
    """First-order and total Sobol indices of every output of ``f``.

    Parameters
    ----------
    f : callable
        ``f(params: dict) -> {output: float}`` for one sample, or with
        ``vectorized=True`` ``f(X) -> {output: array}`` for the sample matrix X
        (rows = samples, columns in ``bounds`` order).
    bounds : dict
        Parameter -> (low, high) of its uniform range.
    n : int
        Base samples, a power of two (Sobol' sequence); N (D + 2) evaluations.
    seed : int
        Seed of the scrambled sequence and of the bootstrap.

    Outputs that are not finite at some sample are left out of the table (NaN
    indices would say nothing).
    """
    import pandas as pd
    from SALib.analyze import sobol as sobol_analyze
    from SALib.sample import sobol as sobol_sample

    names = list(bounds)
    if not names:
        raise ParameterError("bounds", bounds, "at least one parameter with a range")
    for k, b in bounds.items():
        lo, hi = (float(v) for v in b)
        if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
            raise ParameterError(f"bounds[{k!r}]", b, "a finite range (low, high) with high > low")
    n = int(n)
    if n < 8 or n & (n - 1):
        raise ParameterError("n", n, "a power of two >= 8")
    problem = {
        "num_vars": len(names),
        "names": names,
        "bounds": [[float(lo), float(hi)] for lo, hi in bounds.values()],
    }
    X = sobol_sample.sample(problem, n, calc_second_order=False, seed=seed)
    if vectorized:
        Y = {k: np.asarray(v, dtype=float) for k, v in f(X).items()}
    else:
        rows = [f(dict(zip(names, (float(v) for v in x), strict=True))) for x in X]
        Y = {
            k: np.array([math.nan if r[k] is None else float(r[k]) for r in rows]) for k in rows[0]
        }
    table = []
    for out, y in Y.items():
        if not np.all(np.isfinite(y)):
            continue
        if np.ptp(y) == 0:
            res = {
                "S1": np.zeros(len(names)),
                "S1_conf": np.zeros(len(names)),
                "ST": np.zeros(len(names)),
                "ST_conf": np.zeros(len(names)),
            }
        else:
            res = sobol_analyze.analyze(problem, y, calc_second_order=False, seed=seed)
        for i, name in enumerate(names):
            table.append(
                {
                    "output": out,
                    "parameter": name,
                    "S1": float(res["S1"][i]),
                    "S1_conf": float(res["S1_conf"][i]),
                    "ST": float(res["ST"][i]),
                    "ST_conf": float(res["ST_conf"][i]),
                }
            )
    bnds = {k: (float(b[0]), float(b[1])) for k, b in bounds.items()}
    return SobolResult(pd.DataFrame(table), bnds, n, X.shape[0])


def ride_sensitivity(
    car,
    excitation=None,
    horizon: float = 10.0,
    *,
    bounds: dict | None = None,
    n: int = 64,
    seed: int = 0,
    linear: bool = False,
    road_class: str = "C",
    speed: float = 20.0,
) -> SobolResult:
    """Sobol indices of a car's ride metrics to its device's parameters.

    ``car`` is a ``device`` or ``device-afw`` quarter car (the car with the identified
    device: :func:`~inerterlab.identify.propagate.device_car`). ``bounds`` maps
    ``stiffness``, ``damping``, ``friction`` and (``device-afw``) ``changing_ratio``
    to (low, high); by default +/- 20 % around the car's device values and a changing
    ratio of 0.2-0.8 (:data:`DEFAULT_RANGES`). Outputs: the simulated metrics over
    ``excitation`` (a drop, sine or ISO 8608 road) and, with ``linear``, the H2 norms
    and body resonance of the linearised car.
    """
    from ..suspension.model import model_of
    from .propagate import device_car, ride_metrics

    car = model_of(car)
    if bounds is None:
        bounds = {}
        for k in ("stiffness", "damping", "friction"):
            v = float(getattr(car.device, k))
            bounds[k] = (v * (1 - DEFAULT_RANGES[k]), v * (1 + DEFAULT_RANGES[k]))
        if car.suspension == "device-afw":
            bounds["changing_ratio"] = DEFAULT_RANGES["changing_ratio"]

    def f(params):
        return ride_metrics(
            device_car(car, params),
            excitation,
            horizon,
            linear=linear,
            road_class=road_class,
            speed=speed,
        )

    return sobol_indices(f, bounds, n=n, seed=seed)
