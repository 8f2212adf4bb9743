"""Numerical failures are caught and explained, never returned as numbers."""

import pytest

from inerterlab import ConvergenceError
from inerterlab.excitation import sine
from inerterlab.simulate import SimulationOptions, simulate
from inerterlab.suspension import quarter_car


def test_step_budget_exhaustion_is_a_clear_error():
    car = quarter_car("afw", sprung_mass=370)
    with pytest.raises(ConvergenceError, match="max_steps=50"):
        simulate(car, sine(0.05, 5.0), 2.0, options=SimulationOptions(max_steps=50))
