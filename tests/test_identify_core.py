"""The identification's model: the model core's rig for every device it represents, the
device model's own integration for the rest (docs/model.md §4, docs/decisions.md
"Identification on the model core")."""

import dataclasses

import numpy as np
import pytest

import inerterlab.identify.fit as fit_module
from inerterlab.devices import RectifierDevice, ScrewDevice, device_force, device_preset
from inerterlab.identify import TestSpec, identify, simulate_rig
from inerterlab.identify.fit import _prepare, core_represents, predict_test

SPECS = [
    TestSpec(number=i, signal=s, frequency=f, amplitude=a, duration=2.0, purpose="identification")
    for i, (s, f, a) in enumerate([("triangle", 0.5, 0.02), ("sine", 2.0, 0.01), ("sine", 1.0, 0.02)])
]


def _prepared(device, seed=4, duration=2.0):
    data = simulate_rig(
        device, matrix=SPECS, sample_rate=500.0, max_duration=duration, noise=5.0, seed=seed
    )
    return [
        _prepare(t, window=0.01, detrend="none", reversal_window=0.24) for t in data.tests
    ]


def test_the_thesis_devices_are_identified_on_the_core():
    for name in ("hydraulic", "screw", "rectifier"):
        assert core_represents(device_preset(name))
    assert not core_represents(RectifierDevice(freewheel=True))
    assert not core_represents(ScrewDevice(backlash=1e-4))
    assert not core_represents(dataclasses.replace(device_preset("rectifier"), flywheel_drag=1e-3))


@pytest.mark.parametrize("name", ["hydraulic", "screw", "rectifier"])
def test_prediction_on_the_core_equals_the_device_model(name, monkeypatch):
    """The same prediction (the series device's start projected out) on the core's rig
    and on the device model's integration: two integrations of one model, whose
    difference falls with the tolerance. Measured, largest over three records, of the
    peak force: at rtol 1e-10 9.8e-8 (hydraulic), 4.6e-17 (screw), 1.4e-7 (rectifier);
    at rtol 1e-12 3.2e-10, 4.6e-17, 1.4e-9."""
    dev = device_preset(name)
    preps = _prepared(dev)
    diffs = {}
    for rtol in (1e-10, 1e-12):
        with monkeypatch.context() as m:
            core = [predict_test(dev, p, rtol=rtol) for p in preps]
            m.setattr(fit_module, "core_represents", lambda d: False)
            kernel = [predict_test(dev, p, rtol=rtol) for p in preps]
        diffs[rtol] = max(
            np.abs(c - k).max() / np.abs(k).max() for c, k in zip(core, kernel, strict=True)
        )
    assert diffs[1e-12] <= 1e-8
    if dev.series:  # the parallel screw's force is algebraic: equal to round-off
        assert diffs[1e-12] <= 0.1 * diffs[1e-10]


def test_a_free_wheeling_device_is_predicted_by_the_device_model():
    """The one-way clutch is a mode the core's elements do not have: the prediction is
    the device model's, exactly."""
    dev = RectifierDevice(freewheel=True)
    p = _prepared(dev, duration=1.0)[0]
    f0 = fit_module._initial_force_guess(p)
    base = device_force(dev, p.motion, t=p.t, rtol=1e-8, h_max=0.01, initial_force=f0).force
    got = fit_module._model_force(dev, p, rtol=1e-8, initial_force=f0)
    assert np.array_equal(got, base)


def test_identify_on_the_core_agrees_with_the_device_model(monkeypatch):
    """One short hydraulic campaign fitted on both models (the fit's rtol 1e-8): the
    estimates agree to a small fraction of their standard errors. Measured: 1.6e-4,
    2.2e-4 and 1.8e-4 standard errors; the standard errors to 1.2e-5 relative."""
    dev = device_preset("hydraulic")
    data = simulate_rig(
        dev, matrix=SPECS, sample_rate=500.0, max_duration=2.0, noise=5.0, seed=11
    )
    start = dataclasses.replace(dev, stiffness=dev.stiffness * 1.1, damping=dev.damping * 0.95)
    on_core = identify(data, start, method="joint")
    monkeypatch.setattr(fit_module, "core_represents", lambda d: False)
    on_kernel = identify(data, start, method="joint")
    for name, p in on_core.parameters.items():
        q = on_kernel.parameters[name]
        assert abs(p.value - q.value) <= 2e-3 * q.std_error, name
        assert p.std_error == pytest.approx(q.std_error, rel=1e-4)
