"""Vehicle with tyre lift-off and asymmetric dampers (fixed-step Runge-Kutta, numba)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from inerterlab.errors import ParameterError
from inerterlab.vehicles import (
    build,
    example_vehicle_path,
    generate_tracks,
    load_vehicle,
    road_inputs,
    road_spectrum,
    simulate,
)
from inerterlab.vehicles.nonlinear import simulate_nonlinear

CAR = build(load_vehicle(example_vehicle_path()))


def _road(road_class, speed, dt, length, seed=1):
    x, zl, zr = generate_tracks(
        road_spectrum(road_class), length=length, step=speed * dt, seed=seed
    )
    return road_inputs(CAR, x, zl, zr, speed, dt)


def test_linear_settings_reproduce_the_exact_linear_simulation():
    dt = 1e-3
    r = _road("C", 20.0, dt, 300.0)
    lin = simulate(CAR, r, dt)
    res = simulate_nonlinear(CAR, r, dt, tyre_lift_off=False)
    for k, y in lin.items():
        assert np.max(np.abs(res.outputs[k] - y)) < 2e-6 * np.max(np.abs(y)), k


def test_no_lift_off_on_a_smooth_road():
    dt = 1e-3
    r = _road("B", 20.0, dt, 200.0)
    a = simulate_nonlinear(CAR, r, dt, tyre_lift_off=True)
    b = simulate_nonlinear(CAR, r, dt, tyre_lift_off=False)
    assert all(v == 0.0 for v in a.lift_off_fraction.values())
    np.testing.assert_array_equal(a.outputs["bounce_acc"], b.outputs["bounce_acc"])


def _reference(r, dt, rebound, compression):
    """scipy DOP853 on an independent matrix form of the same equations."""
    M, C, K, Kr, Cr = CAR.matrices()
    Minv = np.linalg.inv(M)
    n = len(CAR.dofs)
    static = CAR.static_tyre_loads()
    struts = [c for c in CAR.connections if c.name.endswith("_strut")]
    tyres = [c for c in CAR.connections if c.name.endswith("_tyre")]

    def rhs(t, x, r0, slope):
        q, qd = x[:n], x[n:]
        rr = r0 + slope * t
        f = -K @ q - C @ qd + Kr @ rr + Cr @ slope
        for con in struts:  # replace the symmetric damping by the asymmetric one
            dd = con.u @ qd
            c = con.law.damping
            f += con.u * c * dd - con.u * (rebound if dd > 0 else compression) * c * dd
        for con in tyres:
            b, c, k = con.law.mck()
            d = con.u @ q - con.v @ rr
            dd = con.u @ qd - con.v @ slope
            total = static[con.name[:-5]] - k * d - c * dd
            if total < 0:  # the linear terms pulled the wheel down by -total too much
                f -= con.u * total
        return np.concatenate([qd, Minv @ f])

    A, Br, *_ = CAR.state_space()
    x = -np.linalg.solve(A, Br @ r[0])
    out = [x]
    for i in range(r.shape[0] - 1):
        slope = (r[i + 1] - r[i]) / dt
        sol = solve_ivp(
            rhs, (0, dt), x, method="DOP853", rtol=1e-11, atol=1e-13, args=(r[i], slope)
        )
        x = sol.y[:, -1]
        out.append(x)
    return np.array(out)


def test_lift_off_and_asymmetric_damping_against_scipy():
    dt, speed = 1e-3, 30.0
    r = _road("F", speed, dt, 15.0, seed=3)  # about 0.45 s with many lift-offs
    res = simulate_nonlinear(CAR, r, dt, rebound=1.6, compression=0.6, substeps=8)
    assert max(res.lift_off_fraction.values()) > 0.1
    ref = _reference(r, dt, 1.6, 0.6)
    n = len(CAR.dofs)
    defl = ref[:, :n] @ CAR.outputs["front_left_deflection"].P
    err = np.max(np.abs(res.outputs["front_left_deflection"] - defl)) / np.max(np.abs(defl))
    assert err < 1e-5
    for corner, f in res.contact_force.items():
        assert f.min() >= 0.0, corner


def test_rebound_damping_lowers_the_body():
    # more damping in rebound than in compression: the struts extend more slowly than
    # they compress and settle shorter on average ("jacking down")
    dt = 1e-3
    r = _road("D", 20.0, dt, 600.0)
    res = simulate_nonlinear(CAR, r, dt, tyre_lift_off=False, rebound=2.0, compression=0.5)
    sym = simulate_nonlinear(CAR, r, dt, tyre_lift_off=False)
    keep = slice(2000, None)
    assert np.mean(res.outputs["front_left_deflection"][keep]) < -1e-4
    assert abs(np.mean(sym.outputs["front_left_deflection"][keep])) < 3e-4


def test_errors():
    r = np.zeros((10, 4))
    with pytest.raises(ParameterError, match="rebound"):
        simulate_nonlinear(CAR, r, 1e-3, rebound=0.0)
    with pytest.raises(ParameterError, match="r="):
        simulate_nonlinear(CAR, np.zeros((10, 2)), 1e-3)
