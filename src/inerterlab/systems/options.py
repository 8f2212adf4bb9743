"""How to integrate: one frozen object for every time simulation (docs/model.md §11).

:meth:`inerterlab.systems.System.simulate`, :func:`inerterlab.simulate.simulate`,
:func:`inerterlab.simulate.simulate_metrics` and :meth:`inerterlab.systems.DriveRuns.force`
take it as ``options=``. Derive a variant with ``dataclasses.replace``.

>>> opts = SimulationOptions(rtol=1e-10, max_step=1e-3)
>>> opts.method, opts.rtol
('auto', 1e-10)
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

from ..errors import ParameterError, check_choice, check_positive

__all__ = ["SimulationOptions", "DEFAULT_OPTIONS", "METHODS", "FIXED_METHODS",
           "IgnoredOptionWarning"]  # fmt: skip

METHODS = ("auto", "adaptive", "exact")
FIXED_METHODS = ("dopri5", "rk4")


class IgnoredOptionWarning(UserWarning):
    """An option the chosen system or analysis does not use."""


@dataclass(frozen=True, kw_only=True)
class SimulationOptions:
    """How to integrate.

    Parameters
    ----------
    rtol : float
        Relative tolerance, in [1e-14, 1e-2].
    atol : float or None
        Absolute tolerance of each state as a multiple of its typical size
        (``System.state_scales``); None: ``rtol``.
    method : {"auto", "adaptive", "exact"}
        ``adaptive``: Dormand-Prince 5(4) with error control; ``exact``:
        matrix-exponential steps (linear systems on piecewise-linear roads); ``auto``:
        exact where they are cheap, adaptive otherwise.
    sample_rate : float
        Output sampling rate [Hz] of the time series.
    max_steps : int
        Give up (ConvergenceError) after this many steps.
    max_step : float
        Longest step [s] of the adaptive integrator (inf: no limit).
    fixed_step : float or None
        Take steps of this length [s] without error control (events, road edges and
        samples still end steps); None: adaptive.
    fixed_method : {"dopri5", "rk4"}
        The tableau of the fixed steps. ``dopri5``: the Dormand-Prince pair's order-5
        solution, inside the adaptive driver (every system). ``rk4``: classical
        Runge-Kutta of order 4 in its own driver (:func:`._integrate.integrate_fixed`:
        four right-hand sides a step; where the system has switching functions, they
        are read at each step's end too, their crossings located on the step's own
        continuous extension and the step taken again to them), for the vehicles of
        :func:`inerterlab.systems.vehicle.simulate` on their sampled roads; needs
        ``fixed_step``.
    """

    rtol: float = 1e-8
    atol: float | None = None
    method: str = "auto"
    sample_rate: float = 1000.0
    max_steps: int = 10_000_000
    max_step: float = math.inf
    fixed_step: float | None = None
    fixed_method: str = "dopri5"

    def __post_init__(self) -> None:
        r = check_positive("rtol", self.rtol)
        if not 1e-14 <= r <= 1e-2:
            raise ParameterError("rtol", self.rtol, "a relative tolerance in [1e-14, 1e-2]")
        if self.atol is not None:
            check_positive("atol", self.atol)
        check_choice("method", self.method, METHODS)
        check_positive("sample_rate", self.sample_rate, "Hz")
        if isinstance(self.max_steps, bool) or not isinstance(self.max_steps, int) or (
            self.max_steps < 1
        ):
            raise ParameterError("max_steps", self.max_steps, "an integer >= 1")
        if self.max_step != math.inf:
            check_positive("max_step", self.max_step, "s")
        if self.fixed_step is not None:
            check_positive("fixed_step", self.fixed_step, "s")
            if self.method == "exact":
                raise ParameterError("fixed_step", self.fixed_step, "None with method='exact'")
        check_choice("fixed_method", self.fixed_method, FIXED_METHODS)
        if self.fixed_method != "dopri5" and self.fixed_step is None:
            raise ParameterError(
                "fixed_method", self.fixed_method, "'dopri5' unless fixed_step is set [s]"
            )

    @property
    def atol_factor(self) -> float:
        """The absolute tolerance per unit of a state's typical size."""
        return self.rtol if self.atol is None else float(self.atol)

    @property
    def step_control(self):
        """(longest step, fixed step or 0) as the compiled integrator reads them."""
        import numpy as np

        return np.array([float(self.max_step), float(self.fixed_step or 0.0)])

    def warn_ignored(self, where: str, *names: str) -> None:
        """Warn once for each option in ``names`` that differs from its default:
        ``where`` does not use it."""
        for n in names:
            if getattr(self, n) != getattr(DEFAULT_OPTIONS, n):
                warnings.warn(
                    f"{n}={getattr(self, n)!r} is ignored by {where}",
                    IgnoredOptionWarning,
                    stacklevel=3,
                )


DEFAULT_OPTIONS = SimulationOptions()
