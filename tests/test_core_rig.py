"""Model core: the same element gives the same force in a rig and in a quarter car, and
the composite devices equal the device models of inerterlab.devices."""

import numpy as np
import pytest

from inerterlab.devices import Motion, device_force, device_preset
from inerterlab.elements import HydraulicElement
from inerterlab.excitation import sine
from inerterlab.systems import quarter_car, rig


def test_same_element_same_force_in_rig_and_quarter_car():
    hyd = HydraulicElement(flywheel="nylon", law="momentum")
    car = quarter_car("k | c | hyd", {"k": 90e3, "c": 2e3, "hyd": hyd})
    res = car.simulate(sine(0.03, 3.0), 1.0, rtol=1e-10)
    r = rig(hyd)
    qn = [n for n in car.node_names if n.startswith("hyd.")]
    rn = [n for n in r.node_names if n.startswith("hyd.")]
    assert len(qn) == len(rn) == 1
    out_r = np.empty(len(r.output_names))
    names = list(car.output_names)
    checked = 0
    for j in range(50, res.time.size, 97):
        o = {n: res.outputs[n][j] for n in names}
        x = np.zeros(r.n_states)
        for s, name in enumerate(r.state_names):
            node, _, q = name.rpartition(".")
            qc = {"hyd.n2": qn[0]}.get(node, node)
            x[s] = o[f"{qc}.{q}"] - o[f"wheel.{q}"]
        road = np.array([o[f"body.{q}"] - o[f"wheel.{q}"] for q in ("x", "v", "a")])
        r.outputs(0.0, x, road, *r.tables, out_r)
        for e in r.element_names:
            fr = out_r[r.output_names.index(f"{e}.force")]
            fq = o[f"{e}.force"]
            assert abs(fr - fq) <= 1e-9 * max(abs(fq), 1.0), (e, fr, fq)
            checked += 1
    assert checked > 30


@pytest.mark.parametrize("law", ["thesis", "momentum"])
def test_screw_device_in_rig_equals_device_model(law):
    """The ball screw (parallel, no internal states under these laws) against
    devices.device_force on the same sine motion."""
    dev = device_preset("screw", law=law)
    motion = Motion.sine(frequency=2.0, amplitude=0.004)
    ref = device_force(dev, motion, duration=1.0, rtol=1e-10)
    res = rig(dev).simulate(sine(0.004, 2.0), 1.0, rtol=1e-10)
    assert np.allclose(res.time, ref.t)
    f = res.outputs["force"]
    assert np.abs(f - ref.force).max() <= 1e-8 * np.abs(ref.force).max()


@pytest.mark.parametrize("name", ["hydraulic", "rectifier"])
def test_series_device_in_rig_equals_device_model(name):
    """Series device from the device model's initial state (steady motion: the spring
    carries the damper and friction force of the initial velocity). Measured 2.9e-8
    (hydraulic) and 1.3e-8 (rectifier, flywheel coupled), both integrators at 1e-10."""
    import math

    dev = device_preset(name)
    motion = Motion.sine(frequency=2.0, amplitude=0.004)
    ref = device_force(dev, motion, duration=1.0, rtol=1e-10)
    r = rig(dev)
    v0 = 0.004 * 2.0 * math.pi * 2.0
    f0 = dev.damping * v0 + dev.friction * math.tanh(v0 / dev.friction_velocity)
    x0 = np.zeros(r.n_states)
    node = r.state_names[0].rpartition(".")[0]  # the node between spring and branch
    x0[r.state_names.index(f"{node}.x")] = -f0 / dev.stiffness
    x0[r.state_names.index(f"{node}.v")] = v0
    res = r.simulate(sine(0.004, 2.0), 1.0, rtol=1e-10, x0=x0)
    f = res.outputs["force"]
    assert np.abs(f - ref.force).max() <= 1e-7 * np.abs(ref.force).max()
