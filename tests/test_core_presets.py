"""Model core: the named quarter-car suspensions simulated by the core equal the
specialised quarter-car kernels (docs/model.md §5 and §11)."""

import numpy as np
import pytest

from inerterlab import simulate as sim
from inerterlab.excitation import bump, drop, sine
from inerterlab.simulate import SimulationOptions
from inerterlab import quarter_car as specialised
from inerterlab.systems import QUARTER_CAR_PRESETS, quarter_car

RTOL = 1e-10
#: Both integrators run at rtol 1e-10 with different step sequences, so their states
#: agree to a few 1e-8 of their range (measured up to 9e-8). The exception is the
#: thesis law under the sine, where the flywheel saturates every cycle: the specialised
#: kernel ends its steps on the saturation kink, the core steps across it under error
#: control only (measured 1.2e-6).
TOL = 3e-7
TOL_KINK = 5e-6
T = 2.0

INPUTS = {"drop": drop(), "bump": bump(), "sine": sine()}


def _compare(name, law, ex):
    old = sim.simulate(specialised(name, law=law), ex, T, options=SimulationOptions(rtol=RTOL))
    new = quarter_car(name, law=law).simulate(ex, T, rtol=RTOL, method="adaptive")
    names = ("wheel.x", "wheel.v", "body.x", "body.v")
    idx = [new.system.state_names.index(n) for n in names]
    d = np.abs(old.states[:, :4] - new.states[:, idx]).max(axis=0)
    scale = np.abs(old.states[:, :4]).max(axis=0)
    return float((d / scale).max()), old, new


@pytest.mark.parametrize("name", list(QUARTER_CAR_PRESETS))
@pytest.mark.parametrize("inp", list(INPUTS))
def test_preset_equals_specialised_kernel(name, inp):
    err, old, new = _compare(name, "thesis", INPUTS[inp])
    tol = TOL_KINK if (name == "afw" and inp == "sine") else TOL
    assert err < tol, (name, inp, err)
    acc = np.abs(old.body_acc - new.outputs["body_acc"]).max() / np.abs(old.body_acc).max()
    assert acc < tol
    assert new.method == "adaptive"


@pytest.mark.parametrize("name", ["afw", "device-afw"])
@pytest.mark.parametrize("law", ["momentum", "slider-dynamics"])
def test_preset_laws_equal_specialised_kernel(name, law):
    err, _, _ = _compare(name, law, bump())
    assert err < TOL


def test_preset_networks():
    assert QUARTER_CAR_PRESETS["afw"] == "k | c | afw"
    car = quarter_car("device")
    # system A: the series spring of the device and a massless node held by the damper
    assert car.state_names == ("wheel.x", "wheel.v", "body.x", "body.v", "hyd.n3.x")
    assert not car.linear
    assert quarter_car("cfw").linear
