"""Network struts in the half and full car: any linear network at each corner.

Checks are cross-method: the core car's state space with each network against the
hand-assembled oracle's frequency response from the network's admittance evaluated on
its tree (tests/_vehicle_oracle.py), the realisation of each network against Z(s), the decoupled half car against the model core's quarter car built
by the node formulation, the spectral RMS against the Lyapunov H2, and the compiled
RK4 against the exact discretisation of the linear model.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from _vehicle_oracle import build, dynamic_stiffness, internal_states, realisation
from inerterlab.errors import DataFileError, ParameterError
from inerterlab.vehicles import (
    Corner,
    FullCar,
    HalfCar,
    NetworkStrut,
    Strut,
    Tyre,
    example_vehicle_path,
    linear_vehicle,
    loads_vehicle,
)
from inerterlab.vehicles.roads import generate_tracks, road_spectrum
from inerterlab.vehicles.simulation import simulate_vehicle
from inerterlab.vehicles.spectral import road_inputs, simulate, white_velocity_h2

NETWORKS = [  # (text, values): each with internal nodes (internal states >= 1)
    ("k | (c - b)", {"k": 28e3, "c": 2200.0, "b": 150.0}),
    ("k | (b - (k1 | c))", {"k": 28e3, "k1": 9e3, "c": 2500.0, "b": 120.0}),
    ("k | (c - (b | k2))", {"k": 28e3, "c": 2400.0, "b": 90.0, "k2": 15e3}),
    ("(k | c) - k2", {"k": 30e3, "c": 2200.0, "k2": 300e3}),
    ("k | c | (b - k2)", {"k": 26e3, "c": 1800.0, "b": 60.0, "k2": 40e3}),
    ("k | ((c - b) | (c2 - k2))", {"k": 27e3, "c": 2000.0, "b": 80.0, "c2": 900.0, "k2": 20e3}),
]


def _tyre():
    return Tyre(stiffness=200e3, damping=80.0)


def _full(front, rear=None):
    rear = rear or Strut(stiffness=25e3, damping=2000.0)
    return FullCar(
        sprung_mass=1200.0,
        pitch_inertia=1800.0,
        roll_inertia=450.0,
        cg_to_front=1.15,
        cg_to_rear=1.45,
        front_track=1.52,
        rear_track=1.50,
        front=Corner(unsprung_mass=40.0, strut=front, tyre=_tyre()),
        rear=Corner(unsprung_mass=38.0, strut=rear, tyre=_tyre()),
        front_anti_roll=12e3,
        rear_anti_roll=4e3,
    )


def _ss_frf(car, f, name):
    A, Br, Bd, Cy, Dr, Dd = car.state_space()
    out = []
    for s in 2j * math.pi * np.asarray(f):
        x = np.linalg.solve(s * np.eye(A.shape[0]) - A, Br + s * Bd)
        out.append(Cy[name] @ x + Dr[name] + s * Dd[name])
    return np.array(out)


@pytest.mark.parametrize("text,values", NETWORKS)
def test_realisation_equals_the_admittance_on_the_tree(text, values):
    law = NetworkStrut(text, values)
    assert internal_states(law) >= 1
    s = 2j * math.pi * np.geomspace(0.05, 200.0, 25)
    b, c, k = law.mck()
    A, B, C = realisation(law)
    rest = np.array([C @ np.linalg.solve(si * np.eye(A.shape[0]) - A, B) for si in s])
    np.testing.assert_allclose(b * s**2 + c * s + k + rest, dynamic_stiffness(law, s), rtol=1e-10)
    assert law.static_stiffness() == pytest.approx(dynamic_stiffness(law, 1e-9j).real, rel=1e-6)
    car = linear_vehicle(_full(law))
    f = np.array([0.3, 1.1, 3.0, 9.5, 14.0, 40.0])
    # the oracle's response: each strut's dynamic stiffness on the tree, no state space
    frf = build(_full(law)).frequency_response(f)
    for name in ("bounce_acc", "pitch_acc", "roll_acc", "front_left_deflection",
                 "front_right_tyre_load", "rear_left_deflection"):  # fmt: skip
        ref = frf[name]
        np.testing.assert_allclose(
            _ss_frf(car, f, name), ref, rtol=1e-9, atol=1e-12 * abs(ref).max()
        )
    assert np.linalg.eigvals(car.state_space()[0]).real.max() < 0


def test_parallel_network_equals_the_strut_exactly():
    net = NetworkStrut("k | c | b", {"k": 28e3, "c": 2200.0, "b": 60.0})
    strut = Strut(stiffness=28e3, damping=2200.0, inertance=60.0)
    a, b = linear_vehicle(_full(net)), linear_vehicle(_full(strut))
    assert internal_states(net) == 0 and net.mck() == pytest.approx(strut.mck(), rel=1e-15)
    ha, hb = white_velocity_h2(a), white_velocity_h2(b)
    for key, v in hb.items():
        assert math.isfinite(ha[key]) == math.isfinite(v)
        if math.isfinite(v):
            assert ha[key] == pytest.approx(v, rel=1e-12), key
    assert a.static_tyre_loads() == pytest.approx(b.static_tyre_loads(), rel=1e-12)


@pytest.mark.parametrize("text,values", NETWORKS[:4])
def test_decoupled_half_car_equals_two_core_quarter_cars(text, values):
    """I_y = m a b decouples the axles; each must equal the model core's quarter car
    with the same network, built independently by the node formulation."""
    from inerterlab.systems import quarter_car

    m, a, b = 1200.0, 1.2, 1.4
    law = NetworkStrut(text, values)
    tyre = Tyre(stiffness=2.4e5, damping=200.0)
    corner = Corner(unsprung_mass=45.0, strut=law, tyre=tyre)
    half = linear_vehicle(HalfCar(sprung_mass=m, pitch_inertia=m * a * b, cg_to_front=a, cg_to_rear=b,
                         front=corner, rear=corner))  # fmt: skip
    f = np.geomspace(0.2, 40.0, 30)
    s = 2j * math.pi * f
    H = half.frequency_response(f)
    body = {
        "front": H["bounce_acc"] - a * H["pitch_acc"],
        "rear": H["bounce_acc"] + b * H["pitch_acc"],
    }
    for j, (axle, share) in enumerate((("front", b), ("rear", a))):
        qc = quarter_car(text, values, sprung_mass=m * share / (a + b), unsprung_mass=45.0,
                         tyre_stiffness=2.4e5, tyre_damping=200.0)  # fmt: skip
        # the core's transfers are per road velocity: times s for per road height
        np.testing.assert_allclose(body[axle][:, j], s * qc.transfer(2 * math.pi * f, "body.a"),
                                   rtol=1e-8)  # fmt: skip
        defl = s * (
            qc.transfer(2 * math.pi * f, "body.x") - qc.transfer(2 * math.pi * f, "wheel.x")
        )
        np.testing.assert_allclose(H[f"{axle}_deflection"][:, j], defl, rtol=1e-8)


def test_full_car_equals_half_car_with_networks():
    from inerterlab.vehicles.spectral import spectral_response

    car = _full(NetworkStrut(*NETWORKS[0]), NetworkStrut(*NETWORKS[2]))
    road = road_spectrum("C", coherence="identical")
    rf = spectral_response(linear_vehicle(car), road, 20.0)
    rh = spectral_response(linear_vehicle(car.half_car()), road, 20.0)
    assert rf.rms["bounce_acc"] == pytest.approx(rh.rms["bounce_acc"], rel=1e-9)
    assert rf.rms["front_left_deflection"] == pytest.approx(rh.rms["front_deflection"], rel=1e-9)
    assert rf.static_load["rear_right"] == pytest.approx(0.5 * rh.static_load["rear"], rel=1e-9)


def test_core_time_simulation_agrees_with_the_exact_linear_simulation():
    params = _full(NetworkStrut(*NETWORKS[0]), NetworkStrut(*NETWORKS[1]))
    car = linear_vehicle(params)
    speed, dt = 20.0, 1e-3
    x, zl, zr = generate_tracks(road_spectrum("B"), length=120.0, step=speed * dt, seed=3)
    r = road_inputs(car, x, zl, zr, speed, dt)[:3001]
    exact = simulate(car, r, dt)
    rk = simulate_vehicle(params, r, dt, lift_off=False, rtol=1e-11).outputs
    for name in ("bounce_acc", "front_left_deflection", "rear_right_deflection", "pitch_acc"):
        err = np.abs(rk[name] - exact[name]).max() / np.abs(exact[name]).max()
        assert err < 1e-8, (name, err)


def test_static_loads_use_the_static_stiffness():
    # k | (c - b) carries the car on k alone: the same static loads as the plain strut
    a = linear_vehicle(_full(NetworkStrut("k | (c - b)", {"k": 28e3, "c": 2200.0, "b": 150.0})))
    b = linear_vehicle(_full(Strut(stiffness=28e3, damping=2200.0)))
    assert a.static_tyre_loads() == pytest.approx(b.static_tyre_loads(), rel=1e-9)
    # a spring in series with a damper carries nothing at rest: a clear error
    maxwell = NetworkStrut("k - c", {"k": 28e3, "c": 2200.0})
    with pytest.raises(ParameterError, match="carries the car at rest"):
        linear_vehicle(_full(maxwell, maxwell)).static_tyre_loads()


def test_state_space_only_analyses_refuse_a_network_by_name():
    car = linear_vehicle(_full(NetworkStrut(*NETWORKS[0])))
    with pytest.raises(ParameterError, match="internal node front_left"):
        car.natural_frequencies()
    with pytest.raises(ParameterError, match="asymmetric damper needs a Strut"):
        r = np.zeros((10, 4))
        simulate_vehicle(_full(NetworkStrut(*NETWORKS[0])), r, 1e-3, rebound=1.5)


def test_bad_network_values_name_the_parameter():
    with pytest.raises(ParameterError, match="missing parameter"):
        NetworkStrut("k | (c - b)", {"k": 1.0, "c": 1.0})
    with pytest.raises(ParameterError, match="not a spring, damper or inerter"):
        NetworkStrut("k | afw", {"k": 1.0})
    with pytest.raises(ParameterError, match="> 0"):
        NetworkStrut("k | c", {"k": 1.0, "c": -3.0})


def _toml(front_strut: str) -> str:
    text = example_vehicle_path().read_text()
    old = 'stiffness = "28 kN/m"         # wheel rate\ndamping = "2200 N s/m"\ninertance = "0 kg"'
    assert old in text
    return text.replace(old, front_strut, 1)


def test_vehicle_file_takes_a_network_per_axle():
    car = loads_vehicle(
        _toml('network = "k | (c - b)"\nk = "28 kN/m"\nc = "2.2 kN s/m"\nb = "150 kg"')
    )
    law = car.front.strut
    assert isinstance(law, NetworkStrut) and law.network == "k | (c - b)"
    assert law.parameters == {"k": 28e3, "c": 2200.0, "b": 150.0}
    assert isinstance(car.rear.strut, Strut)
    assert linear_vehicle(car).state_space()[0].shape == (18, 18)  # 16 + one state per front wheel


@pytest.mark.parametrize(
    "strut,match",
    [
        ('network = "k | (c - b)"\nk = "28 kN/m"\nc = "2200 N s/m"', r"\[front\] b: missing"),
        ('network = "k | c"\nk = "28 kN/m"\nc = "2200 kg"', r"\[front\] c:"),
        (
            'network = "k | c"\nk = "28 kN/m"\nc = "2200 N s/m"\ndamping = "1 N s/m"',
            r"\[front\] damping: not with network",
        ),
        ('network = "k | (c -"\nk = "28 kN/m"', r"\[front\] network:"),
    ],
)
def test_vehicle_file_network_errors_name_key_and_line(strut, match):
    with pytest.raises(DataFileError, match=match) as e:
        loads_vehicle(_toml(strut), source="car.toml")
    assert "car.toml" in str(e.value)


def test_damped_modes_match_the_undamped_ones_as_damping_vanishes():
    light = Strut(stiffness=28e3, damping=1e-3)  # the smallest damping a Damper takes
    car = linear_vehicle(
        FullCar(
            sprung_mass=1200.0, pitch_inertia=1800.0, roll_inertia=450.0, cg_to_front=1.15,
            cg_to_rear=1.45, front_track=1.52, rear_track=1.50,
            front=Corner(unsprung_mass=40.0, strut=light, tyre=Tyre(stiffness=2e5)),
            rear=Corner(unsprung_mass=38.0, strut=Strut(stiffness=25e3, damping=1e-3),
                        tyre=Tyre(stiffness=2e5)),
        )
    )  # fmt: skip
    from inerterlab.vehicles.spectral import modes

    osc, real = modes(car)
    assert not real
    fn = [m.natural_hz for m in osc]
    np.testing.assert_allclose(fn, car.natural_frequencies(rigid_tyres=False), rtol=1e-9)
    np.testing.assert_allclose([m.damped_hz for m in osc], fn, rtol=1e-9)
    assert all(m.damping_ratio < 1e-5 for m in osc)


def test_strut_only_analyses_refuse_network_struts_by_name(tmp_path):
    from inerterlab.vehicles.design import vehicle_with

    path = tmp_path / "car.toml"
    path.write_text(_toml('network = "k | (c - b)"\nk = "28 kN/m"\nc = "2.2 kN s/m"\nb = "150 kg"'))
    with pytest.raises(ParameterError, match="front_damping"):
        vehicle_with(loads_vehicle(path.read_text()), front_damping=3000.0)


def test_cli_modes_and_spectral_take_a_network_file(tmp_path):
    import json
    import subprocess
    import sys

    path = tmp_path / "car.toml"
    path.write_text(_toml('network = "k | (c - b)"\nk = "28 kN/m"\nc = "2.2 kN s/m"\nb = "150 kg"'))
    run = [sys.executable, "-m", "inerterlab", "vehicle"]
    out = subprocess.run(run + ["modes", "--vehicle", str(path), "--json"],
                         capture_output=True, text=True, check=True)  # fmt: skip
    data = json.loads(out.stdout)
    from inerterlab.vehicles.spectral import modes

    osc, real = modes(linear_vehicle(loads_vehicle(path.read_text())))
    assert data["rigid_tyres_hz"] is None
    assert len(data["damped_modes"]) + len(data["real_modes"]) == len(osc) + len(real)
    got = [m["damped_frequency_hz"] for m in data["damped_modes"]]
    assert got == pytest.approx([m.damped_hz for m in osc])
    out = subprocess.run(run + ["spectral", "--vehicle", str(path), "--json"],
                         capture_output=True, text=True, check=True)  # fmt: skip
    rms = json.loads(out.stdout)
    assert "bounce_acc" in json.dumps(rms)


def test_design_over_network_elements(tmp_path):
    from inerterlab.vehicles.design import (
        design_parameters,
        optimize_vehicle,
        spectral_metrics,
        vehicle_with,
    )

    path = tmp_path / "car.toml"
    path.write_text(_toml('network = "k | (c - b)"\nk = "28 kN/m"\nc = "2.2 kN s/m"\nb = "150 kg"'))
    base = loads_vehicle(path.read_text())
    names = design_parameters(base)
    assert names["front_b"] == "kg" and names["front_c"] == "N s/m" and "rear_damping" in names
    assert "front_damping" not in names
    moved = vehicle_with(base, front_b=80.0, rear_damping=1500.0)
    assert moved.front.strut.parameters["b"] == 80.0 and moved.rear.strut.damping == 1500.0
    with pytest.raises(ParameterError, match="front_k, front_c, front_b"):
        vehicle_with(base, front_x=1.0)
    res = optimize_vehicle(vehicle=str(path), parameters=("front_b",),
                           bounds={"front_b": (10.0, 1000.0)}, starts=2)  # fmt: skip
    # no point of a log grid over the bounds is better than the optimum
    grid = np.geomspace(10.0, 1000.0, 41)
    best = min(spectral_metrics(vehicle_with(base, front_b=b))["comfort_wk"] for b in grid)
    assert res.value <= best * (1 + 1e-9)
    assert res.value == pytest.approx(
        spectral_metrics(vehicle_with(base, front_b=res.parameters["front_b"]))["comfort_wk"]
    )


def test_statistical_linearisation_of_network_struts(tmp_path):
    """A linear network strut with an internal node is its own Gaussian equivalent: the
    linearisation is the car's spectral response."""
    from inerterlab.vehicles.linear import linear_vehicle
    from inerterlab.vehicles.spectral import spectral_response
    from inerterlab.vehicles.stochastic import statistical_linearisation

    series = tmp_path / "series.toml"
    series.write_text(
        _toml('network = "k | (c - b)"\nk = "28 kN/m"\nc = "2.2 kN s/m"\nb = "150 kg"')
    )
    lin = statistical_linearisation(vehicle=str(series), points=800)
    car = linear_vehicle(loads_vehicle(series.read_text()))
    exact = spectral_response(car, road_spectrum("C"), 20.0, freq=lin.spectral.freq)
    assert lin.iterations == 0 and lin.equivalents == {}
    assert lin.spectral.rms["bounce_acc"] == pytest.approx(exact.rms["bounce_acc"], rel=1e-12)


def test_default_design_parameters_are_the_dampers(tmp_path):
    from inerterlab.vehicles.design import default_parameters

    text = _toml(
        'network = "k | (c - b) | c2"\nk = "28 kN/m"\nc = "2.2 kN s/m"\nb = "150 kg"\nc2 = "300 N s/m"'
    )
    assert default_parameters(loads_vehicle(text)) == ["front_c", "front_c2", "rear_damping"]
    plain = loads_vehicle(example_vehicle_path().read_text())
    assert default_parameters(plain) == ["front_damping", "rear_damping"]
