"""Model core: the named quarter-car suspensions, built by the one ``quarter_car`` as
networks of the core, equal an independent oracle at tight tolerance (docs/model.md §5,
§11): the plain-Python equations of ``tests/_quarter_car_oracle.py`` integrated by
scipy's DOP853."""

import numpy as np
import pytest

import _quarter_car_oracle as oracle
from inerterlab import quarter_car
from inerterlab.errors import ParameterError
from inerterlab.excitation import bump, drop, iso8608, sine
from inerterlab.systems import QUARTER_CAR_PRESETS, SUSPENSIONS

RTOL = 1e-11
#: both integrations at rtol 1e-11: states and body acceleration agree to 1e-7 of their
#: peak (measured: at most 2e-9, the momentum law's kinks)
TOL = 1e-7
INPUTS = {
    "drop": (drop(), 2.0),
    "bump": (bump(), 2.0),
    "sine": (sine(), 2.0),
    "iso": (iso8608(seed=1), 1.0),
}
CORE_STATES = ("wheel.x", "wheel.v", "body.x", "body.v")


def _compare(car, ex, horizon):
    """Largest difference of the four body and wheel states and of the body
    acceleration, each relative to its peak, between the core and the oracle."""
    res = car.simulate(ex, horizon, rtol=RTOL, method="adaptive", sample_rate=200.0)
    ref = oracle.simulate(car, ex, horizon, rtol=RTOL, sample_rate=200.0)
    assert np.array_equal(ref.time, res.time)
    ys, a3 = ref.states, ref.body_acc
    idx = [car.state_names.index(n) for n in CORE_STATES]
    d = np.abs(ys[:, :4] - res.states[:, idx]).max(axis=0) / np.abs(ys[:, :4]).max(axis=0)
    acc = np.abs(a3 - res.outputs["body_acc"]).max() / np.abs(a3).max()
    return float(max(d.max(), acc))


@pytest.mark.parametrize("name", SUSPENSIONS)
@pytest.mark.parametrize("inp", list(INPUTS))
def test_preset_equals_oracle(name, inp):
    ex, horizon = INPUTS[inp]
    err = _compare(quarter_car(name), ex, horizon)
    assert err < TOL, (name, inp, err)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["afw", "device-afw"])
@pytest.mark.parametrize("law", ["momentum", "slider-dynamics"])
@pytest.mark.parametrize("inp", list(INPUTS))
def test_preset_laws_equal_oracle(name, law, inp):
    ex, horizon = INPUTS[inp]
    err = _compare(quarter_car(name, law=law), ex, horizon)
    assert err < TOL, (name, law, inp, err)


OPTIONS = [
    ("traditional", {"sprung_mass": 340.0, "tyre_damping": 0.0, "stiffness": 70e3}),
    ("cfw", {"inertance": 150.0, "damping": 4000.0}),
    ("cfw", {"inertia": 3e-4, "unsprung_mass": 35.0}),
    ("afw", {"changing_ratio": 0.3, "sprung_mass": 400.0}),
    ("afw", {"flywheel": "metal", "flywheel_law": "geometry", "tyre_stiffness": 150e3}),
    ("device", {"friction_velocity": 2e-3, "gravity": 9.8}),
    ("device-afw", {"changing_ratio": 0.55}),
]


@pytest.mark.parametrize(("name", "options"), OPTIONS)
def test_preset_options_equal_oracle(name, options):
    """The options of a named suspension reach the core's network and car."""
    err = _compare(quarter_car(name, **options), bump(), 1.5)
    assert err < TOL, (name, options, err)


def test_preset_networks():
    assert QUARTER_CAR_PRESETS["afw"] == "k | c | afw"
    car = quarter_car("device")
    # system A: the series spring of the device and a massless node held by the damper
    assert car.state_names == ("wheel.x", "wheel.v", "body.x", "body.v", "hyd.n3.x")
    assert not car.linear
    assert quarter_car("cfw").linear
    assert car.info["model"].suspension == "device"


def test_params_override_a_preset():
    """``params`` replaces a named suspension's element values."""
    a = quarter_car("traditional", {"c": 4000.0})
    b = quarter_car("traditional", damping=4000.0)
    assert np.array_equal(a.ftab, b.ftab)


def test_network_text_takes_car_values_only():
    car = quarter_car("k | (c - b)", {"k": 9e4, "c": 5e3, "b": 200.0}, sprung_mass=340.0)
    assert car.info["car"]["sprung_mass"] == 340.0
    assert "model" not in car.info
    with pytest.raises(ParameterError, match="stiffness"):
        quarter_car("k | c", {"k": 9e4, "c": 5e3}, stiffness=8e4)
    with pytest.raises(ParameterError, match="changing_ratio"):
        quarter_car("k | c", {"k": 9e4, "c": 5e3}, changing_ratio=0.3)
    with pytest.raises(ParameterError, match="sprung_mass"):
        quarter_car("traditional", sprung_mass=-1.0)
