"""Adaptive-flywheel inerters at the corners of a vehicle."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from _vehicle_oracle import build
from inerterlab.errors import DataFileError
from inerterlab.systems.gaussian import gaussian_gains, nonlinear_elements
from inerterlab.systems.vehicle import vehicle
from inerterlab.vehicles import example_vehicle_path, loads_vehicle
from inerterlab.vehicles.simulation import simulate_vehicle


def _text(adaptive: str, axle: str | None = None) -> str:
    text = example_vehicle_path().read_text()
    line = f"adaptive = {{ {adaptive} }}\n"
    if axle is None:
        return text.replace('inertance = "0 kg"\n', 'inertance = "0 kg"\n' + line)
    head = f"[{axle}]"
    i = text.index(head)
    j = text.index('inertance = "0 kg"\n', i) + len('inertance = "0 kg"\n')
    return text[:j] + line + text[j:]


def _road(n=1500, dt=0.002, seed=4):
    rng = np.random.default_rng(seed)
    t = dt * np.arange(n)
    z = 0.01 * np.sin(2 * np.pi * 1.3 * t) + 0.004 * np.sin(2 * np.pi * 7.0 * t)
    z += 0.002 * np.convolve(rng.standard_normal(n), np.ones(5) / 5, "same")
    return np.column_stack([z, np.roll(z, 3), np.roll(z, 60), np.roll(z, 63)])


def test_file_gives_each_axle_its_own_inerter():
    p = loads_vehicle(
        _text('flywheel = "nylon", changing_ratio = 0.3, rest_inertance = "150 kg"', "front")
    )
    assert p.front.strut.adaptive is not None and p.rear.strut.adaptive is None
    a = p.front.strut.adaptive
    assert a.inertance_min == pytest.approx(150.0, rel=1e-12)
    assert a.wheel.changing_ratio == pytest.approx(0.3, rel=1e-9)
    # the linear model sees the rest inertance
    assert p.front.strut.mck()[0] == pytest.approx(150.0, rel=1e-12)


@pytest.mark.parametrize(
    ("entry", "where"),
    [
        ('flywheel = "nylon"', "rest_inertance"),
        ('rest_inertance = "150 kg", colour = "red"', "colour"),
        ('rest_inertance = "150 m"', "rest_inertance"),
        ('rest_inertance = "150 kg", law = "slider-dynamics"', "law"),
    ],
)
def test_bad_adaptive_table_names_key_and_line(entry, where):
    with pytest.raises(DataFileError) as e:
        loads_vehicle(_text(entry, "rear"), "car.toml")
    assert where in str(e.value) and "car.toml" in str(e.value)


def test_vanishing_changing_ratio_is_the_constant_inerter():
    # x -> 0: the adaptive inerter is a constant one of its rest inertance
    tiny = loads_vehicle(_text('changing_ratio = 1e-9, rest_inertance = "150 kg"'))
    const = loads_vehicle(
        example_vehicle_path().read_text().replace('inertance = "0 kg"', 'inertance = "150 kg"')
    )
    r = _road()
    a = simulate_vehicle(tiny, r, 0.002, rtol=1e-10)
    b = simulate_vehicle(const, r, 0.002, rtol=1e-10)
    for k in ("bounce_acc", "front_left_deflection", "rear_right_tyre_load"):
        scale = np.abs(b.outputs[k]).max()
        assert np.abs(a.outputs[k] - b.outputs[k]).max() < 1e-7 * scale, k


@pytest.mark.slow
def test_adaptive_car_matches_independent_python_integration():
    """The core vehicle (rtol 1e-10) against DOP853 (rtol 1e-10) on the equations
    written in Python with the assembled mass matrix and the flywheel's numpy law (not
    the compiled one)."""
    # thesis law: the inertance is continuous in v (a kink at saturation); the momentum
    # law's inertance jumps at saturation, where fixed and adaptive steps differ at O(h)
    params = loads_vehicle(
        _text('changing_ratio = 0.45, law = "thesis", rest_inertance = "200 kg"')
    )
    car = build(params)  # the hand-assembled oracle (tests/_vehicle_oracle.py)
    dt, r = 0.002, _road(n=250)
    M0 = car.matrices()[0]
    n = len(car.dofs)
    slopes = np.vstack([np.diff(r, axis=0) / dt, np.zeros((1, 4))])
    Mk = [c for c in car.connections]
    ad = [(c.u, c.law.adaptive) for c in Mk if getattr(c.law, "adaptive", None) is not None]
    assert len(ad) == 4

    def rhs(t, x):
        i = min(int(t / dt), r.shape[0] - 2)
        rr = r[i] + slopes[i] * (t - i * dt)
        q, qd = x[:n], x[n:]
        gen = np.zeros(n)
        for c in Mk:
            _, cc, k = c.law.mck()
            gen -= c.u * (k * (c.u @ q - c.v @ rr) + cc * (c.u @ qd - c.v @ slopes[i]))
        M = M0.copy()
        for u, a in ad:
            me = a.ratio**2 * a.wheel.inertia(abs(a.ratio * (u @ qd)))
            M += (me - a.inertance_min) * np.outer(u, u)
        return np.concatenate([qd, np.linalg.solve(M, gen)])

    A, Br, *_ = car.state_space()
    x0 = -np.linalg.solve(A, Br @ r[0])
    t = dt * np.arange(r.shape[0])
    sol = solve_ivp(rhs, (0, t[-1]), x0, method="DOP853", t_eval=t, rtol=1e-10, atol=1e-12)
    P = car.outputs["front_left_deflection"].P
    y = sol.y[:n].T @ P

    res = simulate_vehicle(params, r, dt, lift_off=False, rtol=1e-10)
    err = np.abs(res.outputs["front_left_deflection"] - y).max() / np.abs(y).max()
    assert err < 1e-6  # DOP853 steps over the inertance's kinks at saturation
    # and the adaptive law matters here: the constant-inertance car differs by far more
    lin = simulate_vehicle(
        loads_vehicle(_text('changing_ratio = 1e-9, rest_inertance = "200 kg"')),
        r,
        dt,
        lift_off=False,
    )
    assert np.abs(lin.outputs["front_left_deflection"] - y).max() / np.abs(y).max() > 100 * err


def test_gaussian_equivalent_inertance_limits():
    """The statistical linearisation's equivalent inertance of the adaptive element
    (systems/gaussian.py, from the compiled law) against the Python law: its rest value,
    its saturated value and the Gaussian average by direct quadrature."""
    p = loads_vehicle(_text('changing_ratio = 0.4, rest_inertance = "100 kg"'))
    a = p.front.strut.adaptive
    sys = vehicle(p, lift_off=False)
    e = {name: i for i, name, _ in nonlinear_elements(sys)}["front_left.afw"]
    assert gaussian_gains(sys, e, 0.0) == pytest.approx(100.0, rel=1e-12)
    assert gaussian_gains(sys, e, 1e-5) == pytest.approx(100.0, rel=1e-6)
    # far beyond saturation the flywheel sits at I_max: inertance 100 / (1 - 0.4)
    v_sat = a.wheel.saturation_speed / a.ratio
    assert gaussian_gains(sys, e, 1e4 * v_sat) == pytest.approx(100.0 / 0.6, rel=1e-3)
    # in between: the Gaussian average by direct quadrature of the Python law
    sigma = 0.8 * v_sat
    v = np.linspace(-10 * sigma, 10 * sigma, 20001)
    me = a.ratio**2 * a.wheel.inertia(np.abs(a.ratio * v))
    pdf = np.exp(-0.5 * (v / sigma) ** 2) / (sigma * math.sqrt(2 * math.pi))
    assert gaussian_gains(sys, e, sigma) == pytest.approx(np.trapezoid(me * pdf, v), rel=1e-6)
