"""Numerical failures are caught and explained, never returned as numbers."""

import pytest

from inerterlab import ConvergenceError, quarter_car
from inerterlab.excitation import sine
from inerterlab.simulate import SimulationOptions, simulate


def test_step_budget_exhaustion_is_a_clear_error():
    car = quarter_car("afw", sprung_mass=370)
    with pytest.raises(ConvergenceError, match="max_steps=50"):
        simulate(car, sine(0.05, 5.0), 2.0, options=SimulationOptions(max_steps=50))


def test_fit_that_does_not_converge_is_a_clear_error():
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from inerterlab.devices import ScrewDevice
    from inerterlab.flywheels import constant_flywheel
    from inerterlab.identify import identify
    from test_identify import _linear_dataset

    start = ScrewDevice(
        stiffness=5000.0, damping=1000.0, friction=50.0, flywheel=constant_flywheel(1e-12),
        friction_velocity=1e-6,
    )  # fmt: skip
    with pytest.raises(ConvergenceError, match="max_nfev=2"):
        identify(_linear_dataset(), start, loss="linear", max_nfev=2)
