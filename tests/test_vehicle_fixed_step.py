"""Fixed steps of the vehicle: classical Runge-Kutta (``fixed_method="rk4"``,
systems/_integrate.py ``_fixed_rk4``; the vehicle commands' ``--fixed-step``): fourth-order convergence
through lift-off and flywheel saturation against the adaptive pair at a tight tolerance
(which only holds where every crossing is located: a step across a kink of the force law
is first-order accurate there), the events found, the fixed Dormand-Prince steps' convergence
through lift-off, and the options' checks."""

from __future__ import annotations

import numpy as np
import pytest

from inerterlab.errors import ParameterError
from inerterlab.systems import vehicle as core
from inerterlab.systems.options import SimulationOptions
from inerterlab.vehicles import (
    example_vehicle_path,
    generate_tracks,
    linear_vehicle,
    loads_vehicle,
    road_inputs,
    road_spectrum,
)
from inerterlab.vehicles.simulation import simulate_vehicle
from test_vehicle_time import HALF, _road


def _err(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def _order(sys, r, dt, key, steps):
    """Errors of ``key`` (relative to its peak) of RK4 at each fixed step against the
    adaptive pair at rtol 1e-12, and the runs."""
    ref = core.simulate(sys, r, dt, rtol=1e-12)
    runs = [core.simulate(sys, r, dt, fixed_step=h, fixed_method="rk4") for h in steps]
    return [_err(x.outputs[key], ref.outputs[key]) for x in runs], runs, ref


def test_rk4_converges_at_fourth_order_through_lift_off():
    """Half car on class F at 30 m/s (tyres off the road about a tenth of the time):
    halving the step divides the error by about 16 or more; every lift-off and landing
    is found (the adaptive reference's count), and no contact force goes negative."""
    dt = 2e-3
    r = _road("F", 30.0, dt, 30.0, seed=3)
    sys = core.vehicle(HALF)
    errs, runs, ref = _order(sys, r, dt, "front_deflection", (dt, dt / 2, dt / 4))
    assert max(ref.lift_off_fraction.values()) > 0.05
    assert ref.stats["events"] > 10
    for x in runs:
        assert x.stats["events"] == ref.stats["events"]
        assert x.stats["rejected"] == 0
        for corner, f in x.contact_force.items():
            assert f.min() >= -1e-9 * f.max(), corner
    assert errs[0] < 1e-2
    assert errs[0] / errs[1] > 10 and errs[1] / errs[2] > 10, errs  # order 4: 16


def test_fixed_dopri5_converges_through_lift_off():
    """The fixed Dormand-Prince steps on the same car and road: a step that crosses a
    lift-off or landing is taken again from its start to the crossing. Cut instead on the
    extension of the attempt that ran past the switch, the front deflection's error fell
    by about 4 per halving (1.8e-4, 4.1e-5, 1.1e-5: second order); now it is about 2000x
    smaller at dt and falls by 7.6 and 12.4 (9.0e-8, 1.2e-8, 9.6e-10), the rear's by 30
    and 22 (1.9e-8, 6.4e-10, 2.9e-11), with the reference's events."""
    dt = 2e-3
    r = _road("F", 30.0, dt, 30.0, seed=3)
    sys = core.vehicle(HALF)
    ref = core.simulate(sys, r, dt, rtol=1e-12)
    runs = [core.simulate(sys, r, dt, fixed_step=h) for h in (dt, dt / 2, dt / 4)]
    assert ref.stats["events"] > 10
    for x in runs:
        assert x.stats["events"] == ref.stats["events"]
    front = [_err(x.outputs["front_deflection"], ref.outputs["front_deflection"]) for x in runs]
    rear = [_err(x.outputs["rear_deflection"], ref.outputs["rear_deflection"]) for x in runs]
    assert front[0] < 1e-6 and rear[0] < 1e-6, (front, rear)
    # order 3 or more over the two halvings (64); second order gave 16
    assert front[0] / front[2] > 64 and min(front[0] / front[1], front[1] / front[2]) > 6, front
    assert rear[0] / rear[1] > 8 and rear[1] / rear[2] > 8, rear


def test_rk4_on_the_full_car_with_adaptive_inerters():
    """The example full car with an adaptive-flywheel inerter at every corner (the
    speed benchmark's car) on class C: saturation and lift-off events, order 4."""
    text = example_vehicle_path().read_text()
    text = text.replace(
        'inertance = "0 kg"\n',
        'inertance = "0 kg"\nadaptive = { flywheel = "nylon", changing_ratio = 0.285, '
        'law = "thesis", rest_inertance = "150 kg" }\n',
    )
    params = loads_vehicle(text)
    # the road's wheel inputs read only the geometry: the plain car's linear model serves
    car = linear_vehicle(loads_vehicle(example_vehicle_path().read_text()))
    dt, speed = 2e-3, 20.0
    x, zl, zr = generate_tracks(road_spectrum("C"), length=60.0, step=speed * dt, seed=11)
    r = road_inputs(car, x, zl, zr, speed, dt)[:1001]
    sys = core.vehicle(params)
    errs, runs, ref = _order(sys, r, dt, "front_left_deflection", (dt, dt / 2, dt / 4))
    assert ref.stats["events"] > 20
    assert all(x.stats["events"] == ref.stats["events"] for x in runs)
    assert errs[0] < 1e-3
    assert errs[0] / errs[1] > 8 and errs[1] / errs[2] > 8, errs


def test_one_step_per_sample_and_the_comfort_observers():
    """``simulate_vehicle(fixed_step=dt)``: one step per sample plus one per event; the
    observers' comfort figures within 1e-3 of the adaptive run's at rtol 1e-10."""
    dt = 2e-3
    r = _road("E", 20.0, dt, 40.0, seed=4)
    fix = simulate_vehicle(HALF, r, dt, fixed_step=dt)
    tight = simulate_vehicle(HALF, r, dt, rtol=1e-10)
    assert fix.stats["steps"] == r.shape[0] - 1 + fix.stats["events"]
    for k in ("wk_rms", "vdv"):
        assert abs(fix.comfort[k] / tight.comfort[k] - 1.0) < 1e-3, k


def test_fixed_method_options():
    """rk4 needs a step; a name outside the two is refused; System.simulate, which runs
    the fixed Dormand-Prince steps only, warns that it ignores rk4."""
    from inerterlab.elements import Spring
    from inerterlab.excitation import bump
    from inerterlab.systems import base_excited
    from inerterlab.systems.options import IgnoredOptionWarning

    rig = base_excited(100.0, "k", {"k": Spring(stiffness=1e4)})
    with pytest.warns(IgnoredOptionWarning, match="fixed_method"):
        rig.simulate(bump(0.01), 0.1, fixed_step=1e-3, fixed_method="rk4")
    with pytest.raises(ParameterError, match="fixed_method"):
        SimulationOptions(fixed_method="rk4")  # no step given
    with pytest.raises(ParameterError, match="fixed_method"):
        SimulationOptions(fixed_step=1e-3, fixed_method="euler")
    assert SimulationOptions(fixed_step=1e-3, fixed_method="rk4").fixed_method == "rk4"


def test_rk4_continuous_extension():
    """The events of the RK4 driver are located on the step's own continuous extension
    (``_integrate._rk4_dense``, from its four stages): at theta = 1 it is the step, at 0
    its start, and in between it is third order, its error falling by about 16 per
    halving of the step on a smooth nonlinear oscillator (against a tight scipy run)."""
    from scipy.integrate import solve_ivp

    from inerterlab.systems._integrate import _rk4_dense

    def f(t, y):
        return np.array([y[1], -np.sin(y[0]) - 0.3 * y[1] + np.cos(2.0 * t)])

    y0 = np.array([0.5, 0.2])
    errs = []
    for h in (0.1, 0.05, 0.025):
        k1 = f(0.0, y0)
        k2 = f(0.5 * h, y0 + 0.5 * h * k1)
        k3 = f(0.5 * h, y0 + 0.5 * h * k2)
        k4 = f(h, y0 + h * k3)
        out = np.empty(2)
        _rk4_dense(y0, k1, k2, k3, k4, h, 1.0, out)
        step = y0 + h / 6.0 * (k1 + 2.0 * (k2 + k3) + k4)
        assert np.allclose(out, step, rtol=1e-15, atol=1e-15)
        _rk4_dense(y0, k1, k2, k3, k4, h, 0.0, out)
        assert np.array_equal(out, y0)
        ths = np.linspace(0.1, 0.9, 9)
        ref = solve_ivp(f, (0.0, h), y0, t_eval=ths * h, rtol=1e-13, atol=1e-15).y.T
        err = 0.0
        for th, yr in zip(ths, ref, strict=True):
            _rk4_dense(y0, k1, k2, k3, k4, h, th, out)
            err = max(err, float(np.max(np.abs(out - yr))))
        errs.append(err)
    assert errs[0] / errs[1] > 12 and errs[1] / errs[2] > 12, errs  # local error O(h^4)
