"""Vehicle modes against closed forms.

A symmetric half car (a = b, identical axles) splits into two independent 2-DOF
quarter cars: bounce (sprung mass m/2 per axle) and pitch (sprung mass I/(2 a^2) on
each axle's strut, the wheels in anti-phase). Each has the characteristic polynomial

    (M s^2 + c s + k)(m_u s^2 + c s + k + k_t) - (c s + k)^2 = 0,

whose roots, found here by numpy.roots from the hand-written coefficients, are the car's
eigenvalues, with no state space involved."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from inerterlab.vehicles import Corner, HalfCar, Strut, Tyre, linear_vehicle
from inerterlab.vehicles.spectral import modes


def _car(c):
    axle = Corner(unsprung_mass=80.0, strut=Strut(stiffness=50e3, damping=c),
                  tyre=Tyre(stiffness=400e3))  # fmt: skip
    p = HalfCar(sprung_mass=1100.0, pitch_inertia=1500.0, cg_to_front=1.3, cg_to_rear=1.3,
                front=axle, rear=axle)  # fmt: skip
    return p, linear_vehicle(p)


def _quarter_roots(M, m, k, c, kt):
    a = np.array([M, c, k])
    b = np.array([m, c, k + kt])
    cross = np.array([c, k])
    poly = np.polymul(a, b)
    poly[-3:] -= np.polymul(cross, cross)
    return np.roots(poly)


def _closed_form(p, c):
    M_b = 0.5 * p.sprung_mass
    M_p = p.pitch_inertia / (2 * p.cg_to_front**2)
    args = (p.front.unsprung_mass, 50e3, c, 400e3)
    return np.concatenate([_quarter_roots(M_b, *args), _quarter_roots(M_p, *args)])


@pytest.mark.parametrize("c", [3e3, 4.5e3, 25e3])
def test_modes_of_a_symmetric_half_car_are_the_quarter_car_roots(c):
    p, car = _car(c)
    osc, real = modes(car)
    want = _closed_form(p, c)
    tol = 1e-9 * np.abs(want).max()
    w_osc = sorted((z for z in want if z.imag > tol), key=lambda z: z.imag)
    w_real = sorted((z.real for z in want if abs(z.imag) <= tol), key=lambda r: -r)
    assert len(osc) == len(w_osc) and len(real) == len(w_real)
    for m, z in zip(osc, w_osc, strict=True):
        assert m.damped_hz == pytest.approx(z.imag / (2 * math.pi), rel=1e-9)
        assert m.natural_hz == pytest.approx(abs(z) / (2 * math.pi), rel=1e-9)
        assert m.damping_ratio == pytest.approx(-z.real / abs(z), rel=1e-9)
        # the damped frequency is below the undamped one by sqrt(1 - zeta^2)
        assert m.damped_hz == pytest.approx(m.natural_hz * math.sqrt(1 - m.damping_ratio**2))
    for m, r in zip(real, w_real, strict=True):
        assert m.decay_rate == pytest.approx(-r, rel=1e-9)
        assert m.time_constant == pytest.approx(-1.0 / r, rel=1e-9)
    if c == 25e3:  # heavy damping: the body modes become real (overdamped) pairs
        assert len(real) >= 2


def test_cli_modes_prints_damped_frequency_and_real_modes(tmp_path):
    """The command's JSON and text carry Im(lambda)/2pi, the damping ratio and the real
    modes; at zeta ~ 0.35 the damped frequency is visibly below |lambda|/2pi."""
    run = [sys.executable, "-m", "inerterlab", "vehicle", "modes", "--json"]
    data = json.loads(subprocess.run(run, capture_output=True, text=True, check=True).stdout)
    from inerterlab.vehicles import example_vehicle_path, load_vehicle

    osc, real = modes(linear_vehicle(load_vehicle(example_vehicle_path())))
    assert [m["damped_frequency_hz"] for m in data["damped_modes"]] == pytest.approx(
        [m.damped_hz for m in osc], rel=1e-12
    )
    assert [m["decay_rate_per_s"] for m in data["real_modes"]] == pytest.approx(
        [m.decay_rate for m in real], rel=1e-12
    )
    text = subprocess.run(run[:-1], capture_output=True, text=True, check=True).stdout
    assert "Im(lambda)/2pi [Hz]" in text and "damping ratio" in text and "real (overdamped) modes" in text
