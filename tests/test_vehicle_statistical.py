"""Statistical (Gaussian-equivalent) linearisation of vehicles on the model core
(systems.gaussian, vehicles.stochastic.statistical_linearisation).

Oracles: each element's equivalent against the Gaussian expectation of its law's
derivative written out independently (closed forms, scipy quad over the element's own
Python law); a linear car is its own equivalent, equal to its spectral response to
1e-9; the fixed point satisfies its own equation; and a car with nonlinear corners
against the time integration of the same core car over a generated road (Monte Carlo
of one long road), where the linearisation about rest misses by far. A rectifying law's
mean force (asymmetric dampers) against the closed form and a quadrature of the law, and
the mean offset it builds up against the time integration: the exact static balance of
the simulated mean forces, and the linearised means within the sampling error plus the
Gaussian closure's error measured in the same run."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from inerterlab.elements import (
    AdaptiveFlywheelInerter,
    AsymmetricDamper,
    Damper,
    Friction,
    GasSpring,
    Spring,
)  # fmt: skip
from inerterlab.errors import ParameterError
from inerterlab.systems.equilibrium import linearise, loaded_rest
from inerterlab.systems.gaussian import gaussian_gains, mean_force, nonlinear_elements
from inerterlab.systems.vehicle import simulate, vehicle
from inerterlab.vehicles import example_vehicle_path, load_vehicle
from inerterlab.vehicles.linear import from_state_space, linear_vehicle
from inerterlab.vehicles.roads import generate_tracks, road_spectrum
from inerterlab.vehicles.spectral import spectral_response
from inerterlab.vehicles.stochastic import statistical_linearisation

HALF = load_vehicle(example_vehicle_path()).half_car()
GAS = GasSpring(pressure=2.5e6, area=4e-3, volume=1.2e-3)


def _gauss(f, sigma, centre=0.0):
    pdf = lambda x: math.exp(-0.5 * (x / sigma) ** 2) / (sigma * math.sqrt(2 * math.pi))  # noqa: E731
    return quad(lambda x: f(x) * pdf(x), -12 * sigma, 12 * sigma, limit=400, points=[centre])[0]


def _element(sys, name):
    return sys.element_names.index(name)


def test_equivalents_of_the_element_laws():
    k = HALF.front.strut.stiffness
    net = {"front": ("gas | c | fric", {"gas": GAS, "c": Damper(damping=1200.0, quadratic=3000.0),
                                        "fric": Friction(force=150.0, velocity=0.02)}),
           "rear": ("k | c | afw", {"k": Spring(stiffness=k), "c": Damper(damping=2000.0),
                                    "afw": AdaptiveFlywheelInerter()})}  # fmt: skip
    sys = vehicle(HALF, networks=net, lift_off=False)
    found = {name: arg for _, name, arg in nonlinear_elements(sys)}
    assert found == {"front.gas": "displacement", "front.c": "velocity",
                     "front.fric": "velocity", "rear.afw": "acceleration"}  # fmt: skip
    s = 0.3
    # quadratic damper: c + c2 E[|v|^3] / s^2 = c + 2 sqrt(2/pi) c2 s
    got = gaussian_gains(sys, _element(sys, "front.c"), s)
    assert got == pytest.approx(1200.0 + 2 * math.sqrt(2 / math.pi) * 3000.0 * s, rel=1e-9)
    # friction: F E[sech^2(v / v_f)] / v_f
    want = 150.0 / 0.02 * _gauss(lambda v: 1.0 / math.cosh(v / 0.02) ** 2, s)
    assert gaussian_gains(sys, _element(sys, "front.fric"), s) == pytest.approx(want, rel=1e-7)
    # the gas spring about its static compression: E[F'(y0 + y)]
    gas = sys.elements[_element(sys, "front.gas")]
    y0, sy = gas.operating_point, 0.01
    want = _gauss(lambda y: GAS.tangent(y0 + y), sy)
    assert gaussian_gains(sys, _element(sys, "front.gas"), sy) == pytest.approx(want, rel=1e-10)
    # adaptive inerter: E[m_e(v)], its inertance rising from r^2 I_min
    afw = AdaptiveFlywheelInerter()
    rest = gaussian_gains(sys, _element(sys, "rear.afw"), 0.0)
    assert rest == pytest.approx(afw.inertance_min, rel=1e-12)
    assert gaussian_gains(sys, _element(sys, "rear.afw"), 0.5) > rest


def test_a_linear_car_is_its_own_equivalent():
    for params, model in ((HALF, "half"), (load_vehicle(example_vehicle_path()), "full")):
        lin = statistical_linearisation(vehicle=params, model=model, road_class="D", speed=15.0)
        ref = spectral_response(linear_vehicle(params), road_spectrum("D"), 15.0)
        assert lin.converged and lin.iterations == 0 and lin.equivalents == {}
        assert set(lin.rms) == set(ref.rms)
        for k, v in ref.rms.items():
            assert lin.rms[k] == pytest.approx(v, rel=1e-9), k
        for c, p in ref.lift_off.items():
            assert lin.lift_off[c] == pytest.approx(p, rel=1e-9, abs=1e-300)


def _nonlinear_net():
    return {
        "front": ("k | c | fric", {"k": Spring(stiffness=HALF.front.strut.stiffness),
                                   "c": Damper(damping=1200.0, quadratic=3000.0),
                                   "fric": Friction(force=150.0, velocity=0.01)}),
        "rear": ("k | c", {"k": Spring(stiffness=HALF.rear.strut.stiffness),
                           "c": Damper(damping=1000.0, quadratic=3000.0)}),
    }  # fmt: skip


def test_the_fixed_point_satisfies_its_equation_and_bad_input_is_refused():
    lin = statistical_linearisation(vehicle=HALF, model="half", networks=_nonlinear_net(),
                                    points=1500)  # fmt: skip
    assert lin.converged and lin.vehicle.linearised
    sys = vehicle(HALF, networks=_nonlinear_net(), lift_off=False)
    for name, (arg, g) in lin.equivalents.items():
        assert arg == "velocity"
        assert g == pytest.approx(gaussian_gains(sys, _element(sys, name), lin.argument_rms[name]),
                                  rel=1e-8)  # fmt: skip
    assert set(lin.damping) == {"front.c", "front.fric", "rear.c"}
    d = lin.to_dict()
    assert d["equivalents"]["front.fric"]["unit"] == "N s/m" and d["converged"]
    with pytest.raises(ParameterError, match="model"):
        statistical_linearisation(vehicle=HALF, model="quarter")
    with pytest.raises(ParameterError, match="speed"):
        statistical_linearisation(vehicle=HALF, model="half", speed=-1.0)


def _drive(sys, rtol):
    """The half car ``sys`` over 1300 m of a class C road at 20 m/s (one realisation)."""
    step, V, L = 0.05, 20.0, HALF.wheelbase
    x, z, _ = generate_tracks(road_spectrum("C"), length=1300.0, step=step, track=1.5, seed=3)
    tx = np.arange(0.0, x[-1] - L, step)
    r = np.column_stack([np.interp(tx + L, x, z), np.interp(tx, x, z)])  # front, rear
    return simulate(sys, r, step / V, rtol=rtol)


@pytest.mark.slow
def test_nonlinear_corners_against_the_time_integration():
    net = _nonlinear_net()
    lin = statistical_linearisation(vehicle=HALF, model="half", speed=20.0, networks=net)
    sys = vehicle(HALF, networks=net, lift_off=False)
    rest = spectral_response(from_state_space(sys, linearise(sys), True), road_spectrum("C"), 20.0)
    res = _drive(sys, rtol=1e-6)
    keep = res.time > 5.0
    for k in ("bounce_acc", "seat_acc", "front_deflection", "rear_deflection"):
        mc = math.sqrt(np.mean(res.outputs[k][keep] ** 2))
        # one road of 60 s: the sampling error of an RMS is a few per cent
        assert abs(lin.rms[k] / mc - 1.0) < 0.06, (k, lin.rms[k], mc)
    # the friction's slope at rest (F / v_eps) nearly locks the strut: far off
    mc = math.sqrt(np.mean(res.outputs["front_deflection"][keep] ** 2))
    assert abs(rest.rms["front_deflection"] / mc - 1.0) > 0.25


def test_the_mean_force_of_a_rectifying_law():
    k = HALF.front.strut.stiffness
    c1, c2 = 2600.0, 900.0
    net = {"front": ("k | asym | fric", {"k": Spring(stiffness=k),
                                         "asym": AsymmetricDamper(rebound=c1, compression=c2),
                                         "fric": Friction(force=150.0, velocity=0.02)}),
           "rear": ("k | c", {"k": Spring(stiffness=k), "c": Damper(damping=1200.0,
                                                                   quadratic=3000.0)})}  # fmt: skip
    sys = vehicle(HALF, networks=net, lift_off=False)
    e = _element(sys, "front.asym")
    for s in (0.05, 0.3, 1.7):
        closed = (c1 - c2) * s / math.sqrt(2 * math.pi)
        law = _gauss(lambda v: (c1 if v > 0 else c2) * v, s)  # the law written out here
        got = mean_force(sys, e, s)
        assert got == pytest.approx(closed, rel=1e-10)
        assert got == pytest.approx(law, rel=1e-8)
        # its Gaussian equivalent is the mean damping (the law is positively homogeneous)
        assert gaussian_gains(sys, e, s) == pytest.approx(0.5 * (c1 + c2), rel=1e-10)
    # odd laws have no mean force
    for name in ("front.fric", "rear.c"):
        assert abs(mean_force(sys, _element(sys, name), 0.3)) < 1e-9
    with pytest.raises(ParameterError, match="front.k"):
        mean_force(sys, _element(sys, "front.k"), 0.3)


def test_a_constant_load_in_a_strut_sets_the_car_down_in_closed_form():
    # a tension T inside the front strut is an internal force pair: the tyres carry
    # nothing of it (no net force or moment on the car), so the front wheel stays and the
    # front spring takes -T, the strut shortening by T / k_f; the rear strut is unmoved
    sys = vehicle(HALF, lift_off=False)
    T = 500.0
    x = loaded_rest(sys, {_element(sys, "front.k"): T})
    Cy = linear_vehicle(HALF)._ss[3]
    k_f = HALF.front.strut.stiffness
    assert float(Cy["front_deflection"] @ x) == pytest.approx(-T / k_f, rel=1e-9)
    assert abs(float(Cy["rear_deflection"] @ x)) < 1e-9 * T / k_f
    for c in ("front", "rear"):
        assert abs(float(Cy[f"{c}_tyre_load"] @ x)) < 1e-9 * T


@pytest.mark.slow
def test_the_mean_offset_of_asymmetric_dampers_against_the_time_integration():
    """Half car with 1.6/0.6 asymmetric dampers on a class C road (the law is positively
    homogeneous, so the ratios do not depend on the road class)."""
    lin = statistical_linearisation(vehicle=HALF, model="half", road_class="C", speed=20.0,
                                    rebound=1.6, compression=0.6, points=1500)  # fmt: skip
    sys = vehicle(HALF, lift_off=False, rebound=1.6, compression=0.6)
    res = _drive(sys, rtol=1e-7)
    keep = res.time > 5.0
    sig = {k: v[keep] for k, v in res.signals.items()}
    # 1. exact in the simulation: a stationary response has mean accelerations zero, so
    # its mean deflections are the static balance of the mean damper forces it produced
    # (the residual is the mean acceleration (v(T) - v(0)) / T over 60 s: << 1 %)
    sim_forces = {_element(sys, f"{c}.asym"): float(sig[f"{c}.asym.force"].mean())
                  for c in ("front", "rear")}  # fmt: skip
    x_bar = loaded_rest(sys, sim_forces)
    Cy = lin.vehicle._ss[3]
    for c in ("front", "rear"):
        d = res.outputs[f"{c}_deflection"][keep]
        assert float(Cy[f"{c}_deflection"] @ x_bar) == pytest.approx(d.mean(), rel=1e-2), c
    # 2. the linearisation: its mean force (c1 - c2) sigma_v / sqrt(2 pi) differs from the
    # simulated one only by the Gaussian closure, whose two parts are measured here: the
    # error of sigma_v, and the non-Gaussian shape of v (E|v| against sqrt(2/pi) sigma_v,
    # exact for a Gaussian v); allowed, with 3 standard errors of the simulated mean (8
    # batch means)
    for c in ("front", "rear"):
        v = sig[f"body_{c}.v"] - sig[f"wheel_{c}.v"]
        s_sim = float(np.sqrt(np.mean(v**2)))
        shape = abs(float(np.mean(np.abs(v))) / (s_sim * math.sqrt(2 / math.pi)) - 1.0)
        spread = abs(lin.argument_rms[f"{c}.asym"] / s_sim - 1.0)
        assert shape < 0.05 and spread < 0.05, (c, shape, spread)  # the closure holds
        d = res.outputs[f"{c}_deflection"][keep]
        batches = np.array([b.mean() for b in np.array_split(d, 8)])
        se = batches.std(ddof=1) / math.sqrt(8) / abs(d.mean())
        tol = 3 * se + shape + spread
        F = float(sig[f"{c}.asym.force"].mean())
        assert lin.mean_forces[f"{c}.asym"] == pytest.approx(F, rel=tol), c
        assert lin.mean[f"{c}_deflection"] == pytest.approx(d.mean(), rel=tol), c
        # the RMS about the static equilibrium, sqrt(mean^2 + sigma^2)
        ms = np.array([np.mean(b**2) for b in np.array_split(d, 8)])
        se_rms = 0.5 * ms.std(ddof=1) / math.sqrt(8) / ms.mean()
        rms = math.sqrt(np.mean(d**2))
        assert lin.rms[f"{c}_deflection"] == pytest.approx(rms, rel=3 * se_rms + shape + spread)
        # without the offset the deflection would be far below (about 20 %)
        assert lin.spectral.rms[f"{c}_deflection"] / rms < 0.85
    # the accelerations carry no mean
    assert lin.mean["bounce_acc"] == 0.0 and lin.rms["bounce_acc"] == lin.spectral.rms["bounce_acc"]
