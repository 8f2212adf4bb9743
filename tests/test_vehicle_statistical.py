"""Statistical (Gaussian-equivalent) linearisation of vehicles on the model core
(systems.gaussian, vehicles.stochastic.statistical_linearisation).

Oracles: each element's equivalent against the Gaussian expectation of its law's
derivative written out independently (closed forms, scipy quad over the element's own
Python law); a linear car is its own equivalent, equal to its spectral response to
1e-9; the fixed point satisfies its own equation; and a car with nonlinear corners
against the time integration of the same core car over a generated road (Monte Carlo
of one long road), where the linearisation about rest misses by far."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from inerterlab.elements import AdaptiveFlywheelInerter, Damper, Friction, GasSpring, Spring
from inerterlab.errors import ParameterError
from inerterlab.systems.equilibrium import linearise
from inerterlab.systems.gaussian import gaussian_gains, nonlinear_elements
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


@pytest.mark.slow
def test_nonlinear_corners_against_the_time_integration():
    net = _nonlinear_net()
    lin = statistical_linearisation(vehicle=HALF, model="half", speed=20.0, networks=net)
    sys = vehicle(HALF, networks=net, lift_off=False)
    rest = spectral_response(from_state_space(sys, linearise(sys), True), road_spectrum("C"), 20.0)
    step, V, L = 0.05, 20.0, HALF.wheelbase
    x, z, _ = generate_tracks(road_spectrum("C"), length=1300.0, step=step, track=1.5, seed=3)
    tx = np.arange(0.0, x[-1] - L, step)
    r = np.column_stack([np.interp(tx + L, x, z), np.interp(tx, x, z)])  # front, rear
    res = simulate(sys, r, step / V, rtol=1e-6)
    keep = res.time > 5.0
    for k in ("bounce_acc", "seat_acc", "front_deflection", "rear_deflection"):
        mc = math.sqrt(np.mean(res.outputs[k][keep] ** 2))
        # one road of 60 s: the sampling error of an RMS is a few per cent
        assert abs(lin.rms[k] / mc - 1.0) < 0.06, (k, lin.rms[k], mc)
    # the friction's slope at rest (F / v_eps) nearly locks the strut: far off
    mc = math.sqrt(np.mean(res.outputs["front_deflection"][keep] ** 2))
    assert abs(rest.rms["front_deflection"] / mc - 1.0) > 0.25
