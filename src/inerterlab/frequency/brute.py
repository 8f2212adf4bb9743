"""Brute force: time integration to a detected steady state, and Floquet multipliers.

The reference the harmonic-balance methods are measured against (thesis 7.3). The
thesis integrates 500 periods from rest and keeps the last two; here each forcing
period is integrated in turn until the periodic orbit has settled (the estimated
distance of the state to the periodic orbit, from the contraction between successive
periods, is below ``rtol`` relative to the response size, for two periods running),
and the half peak-to-peak of the response over those periods is the amplitude.

Two backends:

``numba``
    Classical Runge-Kutta (RK4) with a fixed step, ``steps_per_period`` per period and
    at least 400 steps per period of the fastest linear mode (h |s|_max <= 0.016), on
    the system's own right-hand side (``system.first_order()``): the one period
    integrator of :mod:`inerterlab.frequency.first_order`. Built-in systems only. Against ``scipy`` at rtol 1e-10 the amplitudes agree to
    about 1e-6 relative on the chapter-7 system (tests/test_frequency_ch7.py,
    benchmarks/bench_frequency.py).
``scipy``
    ``solve_ivp`` with DOP853 at rtol 1e-10, atol 1e-12 x scale; any system; about
    one second per frequency point on the chapter-7 system.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import check_choice
from .first_order import rk4_period, steady_state_point

__all__ = ["SteadyState", "steady_state", "floquet_multipliers", "acceleration"]


@dataclass(frozen=True)
class SteadyState:
    """Result of one brute-force point."""

    amplitude: float
    settled: bool
    periods: int
    state: np.ndarray
    distance: float
    samples: np.ndarray | None = None


def acceleration(system, t: float, omega: float, x, xd) -> np.ndarray:
    """x'' [m/s^2] solving r(tau, x, x', x'') = 0 (r is affine in x'')."""
    n = int(system.n_dof)
    x = np.asarray(x, dtype=float).reshape(n, 1)
    xd = np.asarray(xd, dtype=float).reshape(n, 1)
    r0, _, _, ga = system.evaluate(np.array([omega * t]), omega, x, xd, np.zeros((n, 1)))
    return -np.linalg.solve(np.asarray(ga)[:, :, 0], np.asarray(r0)[:, 0])


def _fastest_rate(system, omega: float) -> float:
    """|s|_max of the system linearised at rest [1/s]."""
    n = int(system.n_dof)
    z = np.zeros((n, 1))
    _, gx, gv, ga = system.evaluate(np.array([0.0]), omega, z, z, z)
    M, C, K = (np.asarray(g)[:, :, 0] for g in (ga, gv, gx))
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def _steps(system, omega: float, steps_per_period: int) -> int:
    period = 2.0 * math.pi / omega
    rate = max(_fastest_rate(system, omega), 1e-12)
    return int(max(steps_per_period, math.ceil(period * rate / 0.016)))


def steady_state(
    system,
    omega: float,
    *,
    initial_state=None,
    backend: str = "numba",
    steps_per_period: int = 2000,
    rtol: float = 1e-9,
    max_periods: int = 5000,
    keep_periods: int = 2,
) -> SteadyState:
    """Integrate ``system`` at forcing frequency ``omega`` [rad/s] to its steady state.

    Parameters
    ----------
    system
        A built-in system (both backends) or a :class:`UserSystem` (``scipy`` only).
    omega : float
        Forcing frequency [rad/s].
    initial_state : array, optional
        [x, x'] at t = 0 (default: rest, thesis (7.5)).
    backend : {"numba", "scipy"}
        Fixed-step RK4 (fast) or DOP853 at rtol 1e-10 (slow reference).
    steps_per_period : int
        Minimum RK4 steps per forcing period (``numba`` backend).
    rtol : float
        Settling tolerance, relative to the response size.
    max_periods : int
        Give up (settled=False) after this many periods.
    keep_periods : int
        Settled periods the amplitude is taken over (the thesis keeps 2).
    """
    check_choice("backend", backend, ("numba", "scipy"))
    n = int(system.n_dof)
    y0 = np.zeros(2 * n) if initial_state is None else np.asarray(initial_state, dtype=float)
    scale = float(getattr(system, "displacement_scale", 1.0))
    if backend == "numba" and hasattr(system, "first_order"):
        form = system.first_order()
        nst = _steps(system, omega, steps_per_period)
        amp_in = form.input_amplitude
        y, _, ok, periods, dist, hi, lo = steady_state_point(
            form, float(omega), amp_in, y0, steps=nst, rtol=rtol, max_periods=max_periods,
            keep_periods=keep_periods,
        )  # fmt: skip
        _, xs = rk4_period(form, float(omega), amp_in, y, nst)
        return SteadyState(
            float(0.5 * (hi[0] - lo[0])), bool(ok), int(periods), y, float(dist), xs[0]
        )
    return _steady_state_scipy(system, omega, y0, rtol, max_periods, keep_periods, scale)


def _steady_state_scipy(system, omega, y0, rtol, max_periods, keep_periods, scale):
    from scipy.integrate import solve_ivp

    n = int(system.n_dof)
    dof = int(getattr(system, "response_dof", 0))
    period = 2.0 * math.pi / omega

    def rhs(t, y):
        return np.concatenate([y[n:], acceleration(system, t, omega, y[:n], y[n:])])

    y = y0.copy()
    calm, prev, dist = 0, np.inf, np.inf
    hi, lo = -np.inf, np.inf
    grid = np.linspace(0.0, period, 4001)
    xs = None
    for k in range(max_periods):
        sol = solve_ivp(
            rhs, (0.0, period), y, method="DOP853", rtol=1e-10, atol=1e-12 * scale,
            dense_output=True,
        )  # fmt: skip
        xs = sol.sol(grid)[dof]
        yn = sol.y[:, -1]
        size = max(np.max(np.abs(xs)), scale)
        change = max(np.max(np.abs(yn[:n] - y[:n])), np.max(np.abs(yn[n:] - y[n:])) / omega)
        change /= size
        rho = change / prev if prev > 0 else 0.0
        prev = change
        dist = max(change * rho / (1.0 - rho) if rho < 0.999 else np.inf, change)
        y = yn
        if dist < rtol:
            calm += 1
        else:
            calm, hi, lo = 0, -np.inf, np.inf
        hi, lo = max(hi, xs.max()), min(lo, xs.min())
        if calm >= keep_periods:
            return SteadyState(0.5 * (hi - lo), True, k + 1, y, dist, xs[:-1])
    return SteadyState(0.5 * (hi - lo), False, max_periods, y, dist, xs[:-1])


def floquet_multipliers(system, omega: float, state0, *, rtol: float = 1e-11) -> np.ndarray:
    """Floquet multipliers of the periodic orbit through ``state0`` = [x(0), x'(0)].

    The monodromy matrix is the derivative of the one-period map, by central
    differences of DOP853 integrations (rtol ``rtol``); independent of harmonic balance,
    so it cross-checks Hill's method.
    """
    from scipy.integrate import solve_ivp

    n = int(system.n_dof)
    period = 2.0 * math.pi / omega

    def rhs(t, y):
        return np.concatenate([y[n:], acceleration(system, t, omega, y[:n], y[n:])])

    def flow(y):
        s = solve_ivp(rhs, (0.0, period), y, method="DOP853", rtol=rtol, atol=rtol * 1e-3)
        return s.y[:, -1]

    y0 = np.asarray(state0, dtype=float)
    mono = np.empty((2 * n, 2 * n))
    for j in range(2 * n):
        h = 1e-6 * (abs(y0[j]) + 1e-3 * (omega if j >= n else 1.0))
        e = np.zeros(2 * n)
        e[j] = h
        mono[:, j] = (flow(y0 + e) - flow(y0 - e)) / (2 * h)
    return np.linalg.eigvals(mono)
