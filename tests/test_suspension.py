"""Quarter-car models: the factory and its validation."""

import pytest

from inerterlab import quarter_car
from inerterlab.errors import ParameterError
from inerterlab.suspension import QuarterCarParameters


def test_factory_and_validation():
    car = quarter_car("afw", sprung_mass=370, changing_ratio=0.3).info["model"]
    assert car.flywheel.changing_ratio == pytest.approx(0.3)
    assert quarter_car("cfw").info["model"].inertance == pytest.approx(961.66**2 * 2.231e-4, rel=1e-4)
    assert quarter_car("cfw", inertance=150.0).info["model"].inertance == pytest.approx(150.0)
    assert quarter_car("device-afw", law="slider-dynamics").state_names[-2:] == (
        "hyd.afw.slider_radius",
        "hyd.afw.slider_rate",
    )
    with pytest.raises(ParameterError, match="suspension"):
        quarter_car("magic")
    with pytest.raises(ParameterError, match="inertance"):
        quarter_car("afw", inertance=100.0)
    with pytest.raises(ParameterError, match="changing_ratio"):
        quarter_car("traditional", changing_ratio=0.2)
    with pytest.raises(ParameterError, match="sprung_mass"):
        QuarterCarParameters(sprung_mass=-1)
    with pytest.raises(ParameterError, match="law"):
        quarter_car("afw", law="magic")
