"""An independent oracle for the tests: the brute-force steady state and the Floquet
multipliers of a frequency-domain system by scipy's ``solve_ivp`` (DOP853) on the
system's numpy residual (``system.evaluate``). It is not part of the package: the
package integrates every system by the compiled fixed-step RK4 of
:mod:`inerterlab.frequency.first_order` (``frequency.steady_state``,
``frequency.floquet_multipliers``). Another integrator (adaptive, eighth order, with
error control) on another evaluation of the equations (numpy, not the compiled form),
so agreement is a check of both.
"""

from __future__ import annotations

import math

import numpy as np

from inerterlab.frequency.brute import SteadyState

__all__ = ["acceleration", "steady_state", "floquet_multipliers"]


def acceleration(system, t: float, omega: float, x, xd) -> np.ndarray:
    """x'' [m/s^2] solving r(tau, x, x', x'') = 0 (r is affine in x'')."""
    n = int(system.n_dof)
    x = np.asarray(x, dtype=float).reshape(n, 1)
    xd = np.asarray(xd, dtype=float).reshape(n, 1)
    r0, _, _, ga = system.evaluate(np.array([omega * t]), omega, x, xd, np.zeros((n, 1)))
    return -np.linalg.solve(np.asarray(ga)[:, :, 0], np.asarray(r0)[:, 0])


def steady_state(system, omega: float, *, initial_state=None, rtol: float = 1e-9,
                 max_periods: int = 5000, keep_periods: int = 2) -> SteadyState:  # fmt: skip
    """``system`` at forcing frequency ``omega`` [rad/s] integrated period by period
    (DOP853, rtol 1e-10) until settled, with the package's settling test."""
    n = int(system.n_dof)
    y0 = np.zeros(2 * n) if initial_state is None else np.asarray(initial_state, dtype=float)
    scale = float(getattr(system, "displacement_scale", 1.0))
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
