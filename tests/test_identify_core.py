"""The identification's model is the model core's rig for every device, free-wheeling
flywheel, backlash and bearing drag included (docs/model.md §4, docs/decisions.md
"The device rig on the model core")."""

import numpy as np
import pytest

import inerterlab.identify.fit as fit_module
from inerterlab.devices import RectifierDevice, ScrewDevice, device_force, device_preset
from inerterlab.identify import TestSpec, simulate_rig
from inerterlab.identify.fit import _prepare

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


@pytest.mark.parametrize(
    "dev",
    [
        RectifierDevice(freewheel=True, flywheel_drag=2e-3),
        ScrewDevice(backlash=2e-4),
        device_preset("hydraulic"),
    ],
    ids=["free-wheeling", "backlash", "hydraulic"],
)
def test_prediction_on_drive_runs_equals_the_simulation(dev):
    """The identification's runs of the rig on the measured drive (DriveRuns, the
    record's cubic pieces) against device_force on the same sampled motion (the rig's
    simulation): two routes through the core, equal to the integration tolerance.
    Measured at rtol 1e-10: below 1e-7 of the peak force."""
    p = _prepared(dev, duration=1.0)[0]
    f0 = fit_module._initial_force_guess(p)
    got = fit_module._model_force(dev, p, rtol=1e-10, initial_force=f0)
    ref = device_force(dev, p.motion, t=p.t, rtol=1e-10, initial_force=f0).force
    assert np.abs(got - ref).max() <= 1e-6 * np.abs(ref).max()
