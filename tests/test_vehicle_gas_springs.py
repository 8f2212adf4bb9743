"""Vehicles resting on gas springs (the core car's rest by systems.equilibrium's Newton).

The half car's axle loads are statically determinate, so each gas spring's compression
has a closed form; a half car with pitch inertia m a b splits into two quarter cars,
which the core quarter car on the same gas spring (systems.equilibrium) reproduces in
the time domain; small motions about the rest equal the car on the gas springs'
tangent stiffness there."""

from __future__ import annotations

import numpy as np
import pytest

from inerterlab.elements import GasSpring
from inerterlab.errors import NetworkError
from inerterlab.vehicles import (
    Corner,
    FullCar,
    HalfCar,
    Strut,
    Tyre,
    example_vehicle_path,
    linear_vehicle,
    loads_vehicle,
)
from inerterlab.vehicles.roads import generate_tracks, road_spectrum
from inerterlab.vehicles.simulation import simulate_vehicle
from inerterlab.vehicles.spectral import road_inputs, simulate

M, A, B, G = 1200.0, 1.2, 1.4, 9.81
MU = 45.0
TYRE = Tyre(stiffness=2.4e5, damping=200.0)
GAS = GasSpring(pressure=2.5e6, area=4e-3, volume=1.2e-3)


def _half(gas=GAS, k=0.0):
    corner = Corner(unsprung_mass=MU, strut=Strut(stiffness=k, damping=1500.0, device=gas), tyre=TYRE)
    return HalfCar(sprung_mass=M, pitch_inertia=M * A * B, cg_to_front=A, cg_to_rear=B,
                   front=corner, rear=corner)  # fmt: skip


def _compression(load, gas=GAS):
    """Closed form: p0 A ((V0/(V0 - A c))^n - 1) = load."""
    L = gas.volume / gas.area
    return L * (1.0 - (1.0 + load / (gas.pressure * gas.area)) ** (-1.0 / gas.exponent))


def test_half_car_on_gas_springs_statics():
    car = linear_vehicle(_half())
    eq, sys = car.equilibrium, car.system
    front_load, rear_load = M * G * B / (A + B), M * G * A / (A + B)
    for name, load in (("front", front_load), ("rear", rear_load)):
        assert eq.extensions[f"{name}.dev.gas"] == pytest.approx(-_compression(load), rel=1e-10)
        # the gas spring now sits at that compression: no force at rest
        gas = sys.elements[sys.element_names.index(f"{name}.dev.gas")]
        assert gas.operating_point == pytest.approx(-_compression(load), rel=1e-10)
        # the balance by the element law, to 1e-9 of the weight
        assert abs(-GAS.force(gas.operating_point) - load) <= 1e-9 * M * G
    loads = car.static_tyre_loads()
    assert loads["front"] == pytest.approx(front_load + MU * G, rel=1e-12)
    assert loads["rear"] == pytest.approx(rear_load + MU * G, rel=1e-12)


def test_full_car_on_gas_springs_and_anti_roll_bars():
    corner = Corner(unsprung_mass=MU / 2, strut=Strut(stiffness=5e3, damping=800.0,
                    device=GasSpring(pressure=2.5e6, area=2e-3, volume=0.6e-3)), tyre=Tyre(stiffness=1.2e5))  # fmt: skip
    full = FullCar(sprung_mass=M, pitch_inertia=1800.0, roll_inertia=450.0, cg_to_front=A,
                   cg_to_rear=B, front_track=1.5, rear_track=1.5, front=corner, rear=corner,
                   front_anti_roll=1e4)  # fmt: skip
    car = linear_vehicle(full)
    loads = car.static_tyre_loads()
    total = (M + 4 * MU / 2) * G
    assert sum(loads.values()) == pytest.approx(total, rel=1e-12)
    assert loads["front_left"] == pytest.approx(loads["front_right"], rel=1e-12)
    # the full car on identical tracks rests like its half car
    half = linear_vehicle(full.half_car())
    np.testing.assert_allclose(
        2 * loads["front_left"], half.static_tyre_loads()["front"], rtol=1e-12
    )


def _road(car, dt, n, amp):
    x, zl, zr = generate_tracks(road_spectrum("C"), length=80.0, step=20.0 * dt, seed=3)
    r = road_inputs(car, x, zl, zr, 20.0, dt)[:n]
    r = r - r[0]
    return amp * r / np.abs(r).max()


def test_small_motion_equals_the_tangent_car():
    """1e-5 m of road: the nonlinear simulation about the rest equals the linear car
    whose struts are the gas springs' tangents n p A^2 / V at the static compression."""
    car = linear_vehicle(_half())
    dt = 1e-3
    r = _road(car, dt, 3001, 1e-5)
    y = simulate_vehicle(_half(), r, dt, lift_off=False, rtol=1e-10).outputs
    cf, cr = _compression(M * G * B / (A + B)), _compression(M * G * A / (A + B))
    kf, kr = GAS.tangent(-cf), GAS.tangent(-cr)
    lin = linear_vehicle(HalfCar(
        sprung_mass=M, pitch_inertia=M * A * B, cg_to_front=A, cg_to_rear=B,
        front=Corner(unsprung_mass=MU, strut=Strut(stiffness=kf, damping=1500.0), tyre=TYRE),
        rear=Corner(unsprung_mass=MU, strut=Strut(stiffness=kr, damping=1500.0), tyre=TYRE),
    ))  # fmt: skip
    ref = simulate(lin, r, dt)
    for k in ("front_deflection", "rear_deflection", "bounce_acc", "pitch_acc"):
        err = np.abs(y[k] - ref[k]).max() / np.abs(ref[k]).max()
        assert err < 2e-3, (k, err)
    # the tangent matters: the spring at its free length is far off
    assert kf > 1.5 * GAS.tangent(0.0)


@pytest.mark.slow
def test_decoupled_half_car_on_gas_springs_equals_the_core_quarter_car():
    from inerterlab.excitation import road_series
    from inerterlab.systems import equilibrium, quarter_car

    half = linear_vehicle(_half(k=10e3))
    dt = 1e-3
    r = _road(half, dt, 3001, 0.03)  # large motion: the gas law, not its tangent
    t = dt * np.arange(r.shape[0])
    veh = simulate_vehicle(_half(k=10e3), r, dt, lift_off=False, rtol=1e-10).outputs
    qc = quarter_car("k | c | gas", {"k": 10e3, "c": 1500.0, "gas": GAS},
                     **{"sprung_mass": M * B / (A + B), "unsprung_mass": MU,
                          "tyre_stiffness": 2.4e5, "tyre_damping": 200.0, "gravity": G})  # fmt: skip
    eq = equilibrium(qc)
    assert eq.extensions["gas"] == pytest.approx(half.equilibrium.extensions["front.dev.gas"],
                                                 rel=1e-10)  # fmt: skip
    core = eq.system.simulate(road_series(t, r[:, 0]), horizon=t[-1], rtol=1e-10, sample_rate=1 / dt)
    defl = core.outputs["body.x"] - core.outputs["wheel.x"]
    err = np.abs(veh["front_deflection"] - defl).max() / np.abs(defl).max()
    assert err < 1e-7, err
    # and far from linear at this amplitude: over the largest deflection the gas force
    # departs from its tangent by more than 1 %
    y0, d = eq.extensions["gas"], np.abs(defl).max()
    k_t = GAS.tangent(y0)
    assert abs(GAS.force(y0 - d) - GAS.force(y0) + k_t * d) > 0.01 * k_t * d


def test_out_of_range_and_file_input():
    weak = GasSpring(pressure=3e5, area=4e-3, volume=1.2e-3, stroke=0.1)
    with pytest.raises(NetworkError, match=r"front\.dev\.gas \(gas spring\).*beyond its stroke"):
        linear_vehicle(_half(weak))
    text = example_vehicle_path().read_text() + (
        '\n[front.device]\nkind = "gas"\npressure = "25 bar"\narea = "40 cm^2"\n'
        'volume = "1.2e-3 m^3"\n'
    )
    car = linear_vehicle(loads_vehicle(text))
    sys = car.system
    gas = sys.elements[sys.element_names.index("front_left.dev.gas")]
    assert gas.pressure == pytest.approx(2.5e6) and gas.area == pytest.approx(4e-3)
    assert gas.operating_point < 0.0  # compressed by its share of the weight
    loads = car.static_tyre_loads()
    weight = car.equilibrium.weight  # body, wheels and seat; 0 on pitch, roll
    assert sum(loads.values()) == pytest.approx(weight, rel=1e-12)


def _tangent_half():
    cf, cr = _compression(M * G * B / (A + B)), _compression(M * G * A / (A + B))
    return linear_vehicle(HalfCar(
        sprung_mass=M, pitch_inertia=M * A * B, cg_to_front=A, cg_to_rear=B,
        front=Corner(unsprung_mass=MU, strut=Strut(stiffness=GAS.tangent(-cf), damping=1500.0), tyre=TYRE),
        rear=Corner(unsprung_mass=MU, strut=Strut(stiffness=GAS.tangent(-cr), damping=1500.0), tyre=TYRE),
    ))  # fmt: skip


def test_frequency_response_and_modes_are_the_linearisation_about_rest():
    """A car on gas springs: its linear frequency response (``method="linear"``; the
    default balances it at the amplitude, tests/test_vehicle_harmonic.py) and modes are
    those of the car on the tangent stiffnesses (closed-form compressions), and say they
    are linearised.
    The core car is linearised about its Newton equilibrium by central differences
    with Richardson's extrapolation (systems.equilibrium.linearise): equal to the
    closed-form tangents to its accuracy, 1e-8 relative."""
    from inerterlab.vehicles.frequency import frequency_response
    from inerterlab.vehicles.linear import linear_vehicle
    from inerterlab.vehicles.spectral import modes

    car, ref = linear_vehicle(_half()), _tangent_half()
    freq = np.geomspace(0.5, 20.0, 31)
    fr = frequency_response(car, freq, speed=20.0, method="linear")
    fr0 = frequency_response(ref, freq, speed=20.0)
    assert fr.linearised and fr.to_dict()["model"] == "linearised about the static equilibrium"
    assert not fr0.linearised
    for k in fr0.transfer:
        np.testing.assert_allclose(fr.transfer[k], fr0.transfer[k], rtol=1e-8)
    lin = linear_vehicle(_half())
    yes = lin.linearised
    assert lin.equilibrium.residual <= 1e-9 * lin.equilibrium.weight
    osc, real = modes(lin)
    osc0, real0 = modes(ref)
    assert yes and len(osc) == len(osc0) and len(real) == len(real0)
    np.testing.assert_allclose([m.damped_hz for m in osc], [m.damped_hz for m in osc0], rtol=1e-8)
