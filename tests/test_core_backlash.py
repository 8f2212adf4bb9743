"""Backlash (a contact spring with free play) in the model core: the dead-zone law in
the rig, a spring when the play is zero, the quarter car against an independent scipy
integration of the same equations, the harmonic balance against brute-force time
integration, and the networks and values the core refuses."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from inerterlab.errors import ParameterError
from inerterlab.excitation import bump, road_displacement, sine
from inerterlab.networks import NetworkError, linearise
from inerterlab.systems import quarter_car, rig

GAP = {"stiffness": 2e5, "free_play": 0.004}
CAR = dict(sprung_mass=370.0, unsprung_mass=25.0, tyre_stiffness=120e3, tyre_damping=1300.0)


def dead_zone(k, p, x):
    g = 0.5 * p
    return np.where(x > g, k * (x - g), np.where(x < -g, k * (x + g), 0.0))


def test_rig_force_is_the_dead_zone_law():
    r = rig("gap", {"gap": dict(GAP)})
    res = r.simulate(sine(0.005, 2.0), 1.0)
    x = res.outputs["drive.x"]
    assert x.max() > 0.004 and x.min() < -0.004  # both contacts and the play are crossed
    f = dead_zone(GAP["stiffness"], GAP["free_play"], x)
    np.testing.assert_allclose(res.outputs["force"], f, rtol=1e-12, atol=1e-9)
    assert np.mean(res.outputs["force"] == 0.0) > 0.1


def test_no_play_is_a_spring_to_the_bit():
    params = {"k": 9e4, "c": 3e3, "b": 200.0}
    a = quarter_car("k | c | (gap - b)", dict(params, gap={"stiffness": 2e5, "free_play": 0.0}))
    b = quarter_car("k | c | (k1 - b)", dict(params, k1=2e5))
    assert a.linear and b.linear
    road = bump(0.05, duration=0.1, edge="half-cosine", edge_width=0.02)
    ra, rb = a.simulate(road, 1.0), b.simulate(road, 1.0)
    for q in ("body.x", "body.a", "wheel.x"):
        np.testing.assert_array_equal(ra.outputs[q], rb.outputs[q])
    # and the admittance-based linear analysis sees the spring
    net, values = linearise(
        "k | c | (gap - b)", dict(params, gap={"stiffness": 2e5, "free_play": 0.0}), exact=True
    )
    assert net.text == "k | c | (k_gap - b)" and values["k_gap"] == 2e5


def test_quarter_car_with_backlash_matches_scipy_reference():
    """body -gap- n -b- wheel, the node n carrying the inerter: written out by hand and
    integrated by scipy's DOP853 at rtol 1e-11, against the core's adaptive steps."""
    k, c, b = 9e4, 3e3, 200.0
    kg, p = GAP["stiffness"], GAP["free_play"]
    car = quarter_car("k | c | (gap - b)", {"k": k, "c": c, "gap": dict(GAP), "b": b}, **CAR)
    assert not car.linear
    road = bump(0.05, duration=0.3, edge="half-cosine", edge_width=0.05)
    T = 2.0
    res = car.simulate(road, T, rtol=1e-10)
    segs = road.segments(T)
    ms, mu, kt, ct = (CAR[n] for n in ("sprung_mass", "unsprung_mass", "tyre_stiffness",
                                       "tyre_damping"))  # fmt: skip

    def f(t, y):
        xs, vs, xu, vu, xn, vn = y
        xr, vr = (float(q[0]) for q in road_displacement(segs, np.array([t])))
        fg = float(dead_zone(kg, p, xs - xn))
        fs = k * (xs - xu) + c * (vs - vu)
        au = (fs + fg - kt * (xu - xr) - ct * (vu - vr)) / mu
        return [vs, (-fs - fg) / ms, vu, au, vn, au + fg / b]

    ref = solve_ivp(f, (0, T), np.zeros(6), method="DOP853", rtol=1e-11, atol=1e-13,
                    t_eval=res.time, max_step=2e-3)  # fmt: skip
    assert ref.success
    peak = np.abs(ref.y[0]).max()
    assert np.abs(res.outputs["body.x"] - ref.y[0]).max() <= 1e-6 * peak
    assert np.abs(res.outputs["wheel.x"] - ref.y[2]).max() <= 1e-6 * np.abs(ref.y[2]).max()
    # the play matters here: with the play closed the body moves visibly otherwise
    closed = quarter_car("k | c | (k1 - b)", {"k": k, "c": c, "k1": kg, "b": b}, **CAR)
    other = closed.simulate(road, T, rtol=1e-10).outputs["body.x"]
    assert np.abs(other - ref.y[0]).max() > 1e-2 * peak


def test_harmonic_balance_agrees_with_brute_force():
    from inerterlab.frequency import frequency_response

    car = quarter_car("k | c | (gap - b)", {"k": 9e4, "c": 3e3, "gap": dict(GAP), "b": 200.0})
    freqs = np.array([2.0, 3.0, 5.0, 8.0, 12.0])
    # 9 harmonics: with the default 13 the Newton iteration from rest stalls at 2 and 3 Hz
    # on this dead zone (reported as not converged, docs/decisions.md); 9 resolve it
    hb = frequency_response(
        car, "sihb", freq_hz=freqs, amplitude=0.01, direction="up", harmonics=9
    )
    br = frequency_response(
        car, "brute", freq_hz=freqs, amplitude=0.01, steps_per_period=4000, brute_rtol=1e-10
    )
    assert np.asarray(hb.converged).all() and np.asarray(br.converged).all()
    x, y = np.asarray(hb.amplitude_m), np.asarray(br.amplitude_m)
    assert np.sqrt(np.sum((x - y) ** 2) / np.sum(y**2)) <= 1e-3


def test_refused_networks_and_values():
    with pytest.raises(NetworkError, match=r"backlash \(gap\).*massless node held only"):
        quarter_car("k | c | (k1 - gap)", {"k": 9e4, "c": 3e3, "k1": 1e5, "gap": dict(GAP)})
    with pytest.raises(ParameterError, match="gap.free_play"):
        quarter_car("k | c | (gap - b)", {"k": 9e4, "c": 3e3, "b": 200.0,
                                          "gap": {"stiffness": 2e5, "free_play": -1e-3}})  # fmt: skip
    with pytest.raises(ParameterError, match="gap.free_play"):
        quarter_car("k | c | (gap - b)", {"k": 9e4, "c": 3e3, "b": 200.0, "gap": 2e5})
    car = quarter_car("k | c | (gap - b)", {"k": 9e4, "c": 3e3, "gap": dict(GAP), "b": 200.0})
    with pytest.raises(NetworkError):
        car.linear_state_space()


def test_vehicle_corner_with_backlash_scales_stiffness_not_play():
    from inerterlab.vehicles.parameters import corner_device

    d = corner_device("k1 | c1 | (gap - b)", {"k1": 1e4, "c1": 1e3, "gap": dict(GAP), "b": 100.0})
    gap = {n: e for n, e, _, _ in d.scaled(2.0).edges}["gap"]
    assert gap.stiffness == 2 * GAP["stiffness"] and gap.free_play == GAP["free_play"]
