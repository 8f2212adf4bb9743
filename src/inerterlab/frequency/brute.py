"""Brute force: time integration to a detected steady state, and Floquet multipliers.

The reference the harmonic-balance methods are measured against (thesis 7.3). The
thesis integrates 500 periods from rest and keeps the last two; here each forcing
period is integrated in turn until the periodic orbit has settled (the estimated
distance of the state to the periodic orbit, from the contraction between successive
periods, is below ``rtol`` relative to the response size, for two periods running),
and the half peak-to-peak of the response over those periods is the amplitude.

The integrator is classical Runge-Kutta (RK4) with a fixed step, ``steps_per_period``
per period and at least 400 steps per period of the fastest linear mode
(h |s|_max <= 0.016), on the system's compiled first-order form
(``system.first_order()``): the period integrator of
:mod:`inerterlab.frequency.first_order`, for the built-in systems, the quarter car and a
:class:`UserSystem` alike. The Floquet multipliers come from the same integrator's
monodromy matrix. The tests hold both against scipy's DOP853 at rtol 1e-10 on the
system's numpy residual (``tests/_frequency_oracle.py``): amplitudes to about 1e-6
relative on the chapter-7 system (tests/test_frequency_ch7.py,
benchmarks/bench_frequency.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .first_order import monodromy_multipliers, rk4_period, steady_state_point

__all__ = ["SteadyState", "steady_state", "floquet_multipliers"]


@dataclass(frozen=True)
class SteadyState:
    """Result of one brute-force point."""

    amplitude: float
    settled: bool
    periods: int
    state: np.ndarray
    distance: float
    samples: np.ndarray | None = None


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
    steps_per_period: int = 2000,
    rtol: float = 1e-9,
    max_periods: int = 5000,
    keep_periods: int = 2,
) -> SteadyState:
    """Integrate ``system`` at forcing frequency ``omega`` [rad/s] to its steady state.

    Parameters
    ----------
    system
        A built-in system, a quarter car's or a :class:`UserSystem`.
    omega : float
        Forcing frequency [rad/s].
    initial_state : array, optional
        [x, x'] at t = 0 (default: rest, thesis (7.5)).
    steps_per_period : int
        Minimum RK4 steps per forcing period.
    rtol : float
        Settling tolerance, relative to the response size.
    max_periods : int
        Give up (settled=False) after this many periods.
    keep_periods : int
        Settled periods the amplitude is taken over (the thesis keeps 2).
    """
    n = int(system.n_dof)
    y0 = np.zeros(2 * n) if initial_state is None else np.asarray(initial_state, dtype=float)
    form = system.first_order()
    nst = _steps(system, omega, steps_per_period)
    amp_in = form.input_amplitude
    y, _, ok, periods, dist, hi, lo = steady_state_point(
        form, float(omega), amp_in, y0, steps=nst, rtol=rtol, max_periods=max_periods,
        keep_periods=keep_periods,
    )  # fmt: skip
    _, xs = rk4_period(form, float(omega), amp_in, y, nst)
    return SteadyState(float(0.5 * (hi[0] - lo[0])), bool(ok), int(periods), y, float(dist), xs[0])


def floquet_multipliers(
    system, omega: float, state0, *, steps_per_period: int = 4000
) -> np.ndarray:
    """Floquet multipliers of the periodic orbit through ``state0`` = [x(0), x'(0)].

    The monodromy matrix is the derivative of the one-period map by central
    differences, each period integrated by the brute force's RK4 (at least
    ``steps_per_period`` steps, and 400 per period of the fastest linear mode);
    independent of the harmonic balance, so it cross-checks Hill's method.
    """
    form = system.first_order()
    return monodromy_multipliers(
        form, float(omega), form.input_amplitude, np.asarray(state0, dtype=float),
        steps_per_period=_steps(system, omega, steps_per_period),
    )  # fmt: skip
