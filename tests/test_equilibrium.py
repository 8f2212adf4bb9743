"""Static equilibrium under gravity (systems.equilibrium) with nonlinear springs.

Checked against the element laws evaluated directly (not through the compiled system),
against closed forms, and the small-amplitude response about the equilibrium against
the linearisation there."""

from __future__ import annotations

import math

import numpy as np
import pytest

from inerterlab.elements import BumpStop, GasSpring
from inerterlab.errors import NetworkError
from inerterlab.excitation import sine
from inerterlab.systems import equilibrium, quarter_car

CAR = dict(sprung_mass=370.0, unsprung_mass=25.0, tyre_stiffness=120e3, tyre_damping=0.0)
G = 9.81
GAS = {"pressure": 2e6, "area": 3e-3, "volume": 1e-3, "exponent": 1.4}


def test_quarter_car_on_a_gas_spring_closed_form():
    """The tyre takes the whole weight (M + m) g / k_t; the gas spring the body's,
    at the compression where p0 A ((V0/V)^n - 1) = M g."""
    car = quarter_car("gas | c", {"gas": GAS, "c": 3e3}, **CAR)
    eq = equilibrium(car, gravity=G)
    M, m = CAR["sprung_mass"], CAR["unsprung_mass"]
    L = GAS["volume"] / GAS["area"]
    y = L * ((1.0 + M * G / (GAS["pressure"] * GAS["area"])) ** (-1.0 / GAS["exponent"]) - 1.0)
    wheel = -(M + m) * G / CAR["tyre_stiffness"]
    assert eq.extensions["gas"] == pytest.approx(y, rel=1e-12)
    assert eq.displacements["wheel"] == pytest.approx(wheel, rel=1e-12)
    assert eq.displacements["body"] == pytest.approx(wheel + y, rel=1e-12)
    # the nonlinear balance from the element's own law, to 1e-9 of the weight
    gas = GasSpring(**GAS)
    body = -gas.force(eq.displacements["body"] - eq.displacements["wheel"]) - M * G
    wheel_bal = (
        gas.force(eq.extensions["gas"]) - CAR["tyre_stiffness"] * eq.displacements["wheel"] - m * G
    )
    assert abs(body) <= 1e-9 * eq.weight and abs(wheel_bal) <= 1e-9 * eq.weight
    assert eq.residual <= 1e-9 * eq.weight
    # the gas spring is much stiffer loaded than at its free length
    k_rest = GAS["exponent"] * GAS["pressure"] * GAS["area"] ** 2 / GAS["volume"]
    k_eq = eq.system.elements[car.element_names.index("gas")].rest_network()[1]["k"]
    assert k_eq == pytest.approx(gas.tangent(y), rel=1e-14) and k_eq > 2.0 * k_rest


def test_about_rest_is_the_gravity_loaded_system():
    """The rebased system's right-hand side at a state xi equals the force balance with
    gravity at the absolute state (equilibrium + xi), from the element laws."""
    c = 3e3
    car = quarter_car("gas | c", {"gas": GAS, "c": c}, **CAR)
    eq = equilibrium(car, gravity=G)
    sys = eq.system
    assert sys.state_names == ("wheel.x", "wheel.v", "body.x", "body.v")
    gas = GasSpring(**GAS)
    rng = np.random.default_rng(1)
    M, m, kt = CAR["sprung_mass"], CAR["unsprung_mass"], CAR["tyre_stiffness"]
    for _ in range(5):
        xi = rng.normal(scale=[0.01, 0.3, 0.03, 0.5])
        out = np.empty(4)
        sys.rhs(0.0, xi, np.zeros(3), *sys.tables, out)
        xw = eq.displacements["wheel"] + xi[0]
        xb = eq.displacements["body"] + xi[2]
        f = gas.force(xb - xw) + c * (xi[3] - xi[1])
        ab = (-f - M * G) / M
        aw = (f - kt * xw - m * G) / m
        np.testing.assert_allclose(out, [xi[1], aw, xi[3], ab], rtol=1e-9, atol=1e-9 * G)
    zero = np.empty(4)
    sys.rhs(0.0, np.zeros(4), np.zeros(3), *sys.tables, zero)
    assert np.abs(zero).max() <= 1e-9 * G


def test_linearisation_about_the_equilibrium_is_the_tangent_car():
    car = quarter_car("gas | c", {"gas": GAS, "c": 3e3}, **CAR)
    eq = equilibrium(car, gravity=G)
    k = GasSpring(**GAS).tangent(eq.extensions["gas"])
    A, B, C, D = eq.linear_state_space()
    A0, B0, C0, D0 = quarter_car("k | c", {"k": k, "c": 3e3}, **CAR).linear_state_space()
    for a, b in ((A, A0), (B, B0), (C, C0), (D, D0)):
        np.testing.assert_allclose(a, b, rtol=1e-7, atol=1e-7 * np.abs(b).max())


def test_small_motion_about_the_equilibrium_is_the_linearisation():
    """A 10 um road sine about the loaded rest: the body's steady response equals the
    linearised transfer at that rest (the gas spring's tangent there)."""
    car = quarter_car("gas | c", {"gas": GAS, "c": 3e3}, **CAR)
    eq = equilibrium(car, gravity=G)
    amp, f = 1e-5, 1.5
    w = 2 * math.pi * f
    res = eq.system.simulate(sine(amp, f), 8.0, rtol=1e-11, sample_rate=200.0)
    A, B, C, D = eq.linear_state_space()
    i = eq.system.output_names.index("body.x")
    u = amp * np.array([1.0, 1j * w, -(w**2)])
    H = C[i] @ np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B @ u) + D[i] @ u
    t = res.time
    ref = np.imag(H * np.exp(1j * w * t))
    late = t >= 6.0
    err = np.abs(res.outputs["body.x"][late] - ref[late]).max()
    assert err <= 1e-3 * np.abs(ref[late]).max()
    # and not the spring at its free length (the test can tell them apart)
    k0 = GAS["exponent"] * GAS["pressure"] * GAS["area"] ** 2 / GAS["volume"]
    A0, B0, C0, D0 = quarter_car("k | c", {"k": k0, "c": 3e3}, **CAR).linear_state_space()
    H0 = C0[i] @ np.linalg.solve(1j * w * np.eye(4) - A0, B0 @ u) + D0[i] @ u
    assert abs(abs(H0) - abs(H)) > 0.05 * abs(H)


def test_internal_node_and_bump_stop_balance():
    """A soft spring and a bump stop beside it, in series with a spring; the body rests
    on the bump stop. Every node balances by the element laws to 1e-9 of the weight."""
    bump = {"stiffness": 2e4, "clearance": 0.02, "progression": 0.02}
    params = {"k": 1.5e4, "c": 2e3, "k2": 8e4, "bump": bump}
    car = quarter_car("k2 - ((k | bump) | c)", params, **CAR)
    eq = equilibrium(car, gravity=G)
    b = BumpStop(**bump)
    y = eq.extensions["bump"]
    assert y < -bump["clearance"]  # resting on the stop
    M = CAR["sprung_mass"]
    top = -1.5e4 * y - b.force(y)  # what the spring and the stop push up with
    assert abs(top - M * G) <= 1e-9 * eq.weight
    assert abs(-8e4 * eq.extensions["k2"] - M * G) <= 1e-9 * eq.weight
    k = eq.system.elements[car.element_names.index("bump")].rest_network()[1]["k"]
    assert k == pytest.approx(b.tangent(y), rel=1e-14)


def test_out_of_range_equilibria_are_refused():
    weak = dict(GAS, pressure=2e5, stroke=0.15)  # would need 0.25 m under 370 kg
    car = quarter_car("gas | c", {"gas": weak, "c": 3e3}, **CAR)
    with pytest.raises(NetworkError, match=r"gas \(gas spring\).*beyond its stroke.*bottoms out"):
        equilibrium(car)
    soft = {"k": 2e3, "c": 2e3, "bump": {"stiffness": 2e3, "clearance": 0.01, "progression": 0.01}}
    with pytest.raises(NetworkError, match=r"bump \(progressive bump stop\).*beyond its travel"):
        equilibrium(quarter_car("k | bump | c", soft, **CAR))
    with pytest.raises(NetworkError, match="body is held by no spring"):
        equilibrium(quarter_car("c", {"c": 2e3}, **CAR))


def test_node_between_damper_and_inerter_stays():
    """A massless node that no spring touches carries nothing at rest: it stays at 0."""
    car = quarter_car("gas | (c - b)", {"gas": GAS, "c": 2e3, "b": 100.0}, **CAR)
    eq = equilibrium(car, gravity=G)
    assert eq.forces["gas"] == pytest.approx(-CAR["sprung_mass"] * G, rel=1e-12)
    inner = [n for n in car.node_names if n not in ("road", "wheel", "body")]
    assert inner and all(eq.displacements[n] == 0.0 for n in inner)


def test_linear_car_equilibrium_is_the_static_deflection():
    car = quarter_car("k | c | b", {"k": 5e4, "c": 2e3, "b": 100.0}, **CAR)
    eq = equilibrium(car, gravity=G)
    M, m = CAR["sprung_mass"], CAR["unsprung_mass"]
    assert eq.extensions["k"] == pytest.approx(-M * G / 5e4, rel=1e-12)
    assert eq.system.ftab is not car.ftab or eq.system is not car
    np.testing.assert_array_equal(eq.system.ftab, car.ftab)  # linear: nothing to rebase
    assert eq.displacements["wheel"] == pytest.approx(-(M + m) * G / 120e3, rel=1e-12)


def test_harmonic_balance_about_the_equilibrium_is_the_linearisation():
    """The core's harmonic balance runs on the system about rest unchanged: at 2 um the
    body amplitude equals |H| of the linearisation there (the tangent, not the spring
    at its free length)."""
    from inerterlab.frequency import frequency_response

    car = quarter_car("gas | c", {"gas": GAS, "c": 3e3}, **CAR)
    eq = equilibrium(car, gravity=G)
    freqs, amp = np.array([1.0, 2.0, 6.0]), 2e-6
    fr = frequency_response(eq.system, "sihb", freq_hz=freqs, amplitude=amp, direction="up")
    assert np.asarray(fr.converged).all()
    A, B, C, D = eq.linear_state_space()
    i = eq.system.output_names.index("body.x")
    want = []
    for f in freqs:
        w = 2 * math.pi * f
        u = amp * np.array([1.0, 1j * w, -(w**2)])
        want.append(abs(C[i] @ np.linalg.solve(1j * w * np.eye(4) - A, B @ u) + D[i] @ u))
    np.testing.assert_allclose(np.asarray(fr.amplitude_m), want, rtol=2e-3)
