"""Chebyshev (min-max) goal programming over one continuous design variable.

Given objectives f_1(x), ..., f_k(x) to be minimised over an interval, each is first
normalised by its own best (smallest) and worst (largest) value over the interval,

    g_i(x) = (f_i(x) - f_i,best) / (f_i,worst - f_i,best)   in [0, 1],

so 0 means "as good as this objective can be on its own" and 1 "as bad as it gets". The
compromise is the x that makes the largest normalised deviation as small as possible:

    min  lambda   subject to   g_i(x) <= lambda  for every i,

which is the form of the thesis's (4.36)-(4.37) and (4.38)-(4.39).

The solver brackets the answer on a grid of the objectives themselves (not of any
sweep), refines it with a bounded scalar minimisation of max_i g_i(x), and polishes it
with SLSQP on the epigraph form above. Objectives may be discontinuous at known
``breakpoints`` (the printed cost (4.34) jumps at x = 0.2); those points are added to
the grid, together with points just beside them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from ..errors import ParameterError

__all__ = ["GoalProgrammingResult", "chebyshev_goal_programming", "extremes"]


@dataclass(frozen=True, kw_only=True)
class GoalProgrammingResult:
    """Solution of a Chebyshev goal programme.

    Attributes
    ----------
    x : float
        The compromise design variable.
    lam : float
        lambda = max_i g_i(x), the largest normalised deviation at ``x``.
    values : tuple of float
        f_i(x).
    normalised : tuple of float
        g_i(x).
    best, worst : tuple of float
        f_i,best and f_i,worst over the interval.
    best_x, worst_x : tuple of float
        Where they are reached.
    """

    x: float
    lam: float
    values: tuple[float, ...]
    normalised: tuple[float, ...]
    best: tuple[float, ...]
    worst: tuple[float, ...]
    best_x: tuple[float, ...]
    worst_x: tuple[float, ...]


def _grid(lo: float, hi: float, n: int, breakpoints: Sequence[float]) -> np.ndarray:
    pts = [np.linspace(lo, hi, n)]
    eps = 1e-9 * (hi - lo)
    for b in breakpoints:
        if lo < b < hi:
            pts.append(np.array([b - eps, b, b + eps]))
    return np.unique(np.concatenate(pts))


def _refine_min(f, xs: np.ndarray, fx: np.ndarray, xtol: float) -> tuple[float, float]:
    """Refine the grid minimum of f on the bracket formed by its two neighbours."""
    k = int(np.argmin(fx))
    best_x, best_f = float(xs[k]), float(fx[k])
    a, b = xs[max(k - 1, 0)], xs[min(k + 1, len(xs) - 1)]
    if b > a:
        res = optimize.minimize_scalar(f, bounds=(a, b), method="bounded", options={"xatol": xtol})
        if res.fun < best_f:
            best_x, best_f = float(res.x), float(res.fun)
    return best_x, best_f


def extremes(
    f: Callable[[float], float],
    bounds: tuple[float, float],
    *,
    grid: int = 101,
    breakpoints: Sequence[float] = (),
    xtol: float = 1e-9,
) -> tuple[float, float, float, float]:
    """Smallest and largest value of ``f`` on ``bounds``: (x_min, f_min, x_max, f_max)."""
    lo, hi = bounds
    xs = _grid(lo, hi, grid, breakpoints)
    fx = np.array([f(x) for x in xs])
    x_min, f_min = _refine_min(f, xs, fx, xtol)
    x_max, neg = _refine_min(lambda x: -f(x), xs, -fx, xtol)
    return x_min, f_min, x_max, -neg


def chebyshev_goal_programming(
    objectives: Sequence[Callable[[float], float]],
    bounds: tuple[float, float],
    *,
    grid: int = 101,
    breakpoints: Sequence[float] = (),
    xtol: float = 1e-9,
) -> GoalProgrammingResult:
    """Solve min lambda s.t. g_i(x) <= lambda over ``bounds`` (module docstring).

    Parameters
    ----------
    objectives : sequence of callables
        Each maps x to a float to be minimised.
    bounds : (float, float)
        Interval of x.
    grid : int
        Points of the bracketing grid (the answer does not depend on it once the
        minimum is bracketed; refinement takes it to ``xtol``).
    breakpoints : sequence of float
        x values where an objective may jump.

    Examples
    --------
    Two objectives x and (1 - x)^2 on [0, 1] are already normalised; the compromise is
    where they cross, x = (3 - sqrt 5)/2:

    >>> r = chebyshev_goal_programming([lambda x: x, lambda x: (1 - x) ** 2], (0.0, 1.0))
    >>> round(r.x, 6), round(r.lam, 6)
    (0.381966, 0.381966)
    """
    lo, hi = float(bounds[0]), float(bounds[1])
    if not lo < hi:
        raise ParameterError("bounds", bounds, "an interval (low, high) with low < high")
    if not objectives:
        raise ParameterError("objectives", objectives, "at least one objective")
    ext = [extremes(f, (lo, hi), grid=grid, breakpoints=breakpoints, xtol=xtol) for f in objectives]
    best = tuple(e[1] for e in ext)
    worst = tuple(e[3] for e in ext)

    def normalised(x: float) -> np.ndarray:
        out = np.empty(len(objectives))
        for i, f in enumerate(objectives):
            span = worst[i] - best[i]
            out[i] = 0.0 if span <= 0 else (f(x) - best[i]) / span
        return out

    def lam(x: float) -> float:
        return float(np.max(normalised(x)))

    xs = _grid(lo, hi, grid, breakpoints)
    lx = np.array([lam(x) for x in xs])
    x_opt, l_opt = _refine_min(lam, xs, lx, xtol)

    # polish on the epigraph form: variables (x, lambda), constraints lambda - g_i(x) >= 0
    res = optimize.minimize(
        lambda z: z[1],
        x0=np.array([x_opt, l_opt]),
        method="SLSQP",
        bounds=[(lo, hi), (None, None)],
        constraints=[{"type": "ineq", "fun": lambda z: z[1] - normalised(z[0])}],
        options={"ftol": 1e-12, "maxiter": 200},
    )
    if res.success:
        x_new = float(np.clip(res.x[0], lo, hi))
        l_new = lam(x_new)
        if l_new < l_opt - 1e-13:
            x_opt, l_opt = x_new, l_new
    values = tuple(float(f(x_opt)) for f in objectives)
    return GoalProgrammingResult(
        x=x_opt,
        lam=l_opt,
        values=values,
        normalised=tuple(float(v) for v in normalised(x_opt)),
        best=best,
        worst=worst,
        best_x=tuple(e[0] for e in ext),
        worst_x=tuple(e[2] for e in ext),
    )
