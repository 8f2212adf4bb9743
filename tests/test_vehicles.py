"""Linear half car and full car: structure, equivalences, closed forms, H2 and Monte Carlo."""

from __future__ import annotations

import math

import numpy as np
import pytest

from _vehicle_oracle import build
from inerterlab.errors import ParameterError
from inerterlab.vehicles import (
    Corner,
    FullCar,
    HalfCar,
    NetworkStrut,
    Seat,
    Strut,
    Tyre,
    linear_vehicle,
)
from inerterlab.vehicles.roads import generate_tracks, road_spectrum
from inerterlab.vehicles.spectral import (
    input_factor,
    output_psd,
    road_inputs,
    simulate,
    spectral_response,
    white_velocity_h2,
)

FRONT = Corner(
    unsprung_mass=40.0,
    strut=Strut(stiffness=25e3, damping=1500.0, inertance=60.0),
    tyre=Tyre(stiffness=200e3, damping=150.0),
)
REAR = Corner(
    unsprung_mass=45.0,
    strut=Strut(stiffness=22e3, damping=1400.0),
    tyre=Tyre(stiffness=210e3, damping=150.0),
)
SEAT = Seat(x=0.3, y=0.35, mass=80.0, stiffness=40e3, damping=900.0)


def full_car(**kw):
    base = dict(
        sprung_mass=1200.0,
        pitch_inertia=1800.0,
        roll_inertia=450.0,
        cg_to_front=1.2,
        cg_to_rear=1.4,
        front_track=1.5,
        rear_track=1.5,
        front=FRONT,
        rear=REAR,
        front_anti_roll=12e3,
        rear_anti_roll=5e3,
        seat=SEAT,
    )
    base.update(kw)
    return FullCar(**base)


def test_frequency_response_equals_state_space():
    # the hand-assembled oracle's response (its dynamic stiffnesses, no state space)
    # against the core car's state space
    v = linear_vehicle(full_car())
    f = np.array([0.3, 1.1, 4.0, 11.0, 40.0])
    H = build(full_car()).frequency_response(f)
    A, Br, Bd, Cy, Dr, Dd = v.state_space()
    for k, h in H.items():
        for i, fi in enumerate(f):
            s = 2j * math.pi * fi
            g = Cy[k] @ np.linalg.solve(s * np.eye(A.shape[0]) - A, Br + s * Bd) + Dr[k] + s * Dd[k]
            np.testing.assert_allclose(h[i], g, rtol=1e-10, atol=1e-12 * np.max(np.abs(h)))


def test_static_loads():
    car = full_car(seat=None, front_anti_roll=0.0, rear_anti_roll=0.0)
    loads = linear_vehicle(car).static_tyre_loads()
    g = car.gravity
    front = 0.5 * car.sprung_mass * g * 1.4 / 2.6 + FRONT.unsprung_mass * g
    rear = 0.5 * car.sprung_mass * g * 1.2 / 2.6 + REAR.unsprung_mass * g
    assert loads["front_left"] == pytest.approx(front, rel=1e-12)
    assert loads["rear_right"] == pytest.approx(rear, rel=1e-12)
    seated = linear_vehicle(full_car()).static_tyre_loads()
    total = (1200 + 80 + 2 * 40 + 2 * 45) * g
    assert sum(seated.values()) == pytest.approx(total, rel=1e-12)
    assert seated["front_left"] > seated["front_right"]  # seat on the left, ahead of the CG


def test_full_car_on_identical_tracks_equals_half_car():
    # seat on the centre line: an off-centre seat would couple roll into the bounce
    car = full_car(seat=Seat(x=0.3, y=0.0, mass=80.0, stiffness=40e3, damping=900.0))
    full, half = linear_vehicle(car), linear_vehicle(car.half_car())
    road = road_spectrum("C", coherence="identical")
    rf = spectral_response(full, road, 20.0)
    rh = spectral_response(half, road, 20.0)
    pairs = {
        "bounce_acc": ("bounce_acc", 1.0),
        "pitch_acc": ("pitch_acc", 1.0),
        "seat_acc": ("seat_acc", 1.0),
        "seat_acc_wk": ("seat_acc_wk", 1.0),
        "front_left_deflection": ("front_deflection", 1.0),
        "rear_right_deflection": ("rear_deflection", 1.0),
        "front_right_tyre_load": ("front_tyre_load", 0.5),
        "rear_left_tyre_load": ("rear_tyre_load", 0.5),
    }
    for kf, (kh, scale) in pairs.items():
        assert rf.rms[kf] == pytest.approx(scale * rh.rms[kh], rel=1e-9), kf
        np.testing.assert_allclose(rf.psd[kf], scale**2 * rh.psd[kh], rtol=1e-9, atol=0)
    assert rf.rms["roll_acc"] < 1e-9 * rf.rms["pitch_acc"]
    assert rf.static_load["front_left"] == pytest.approx(0.5 * rh.static_load["front"], rel=1e-9)


def test_isotropic_coherence_lies_between_the_limits():
    full = linear_vehicle(full_car())
    out = {
        c: spectral_response(full, road_spectrum("C", coherence=c), 20.0).rms
        for c in ("identical", "isotropic", "independent")
    }
    # the off-centre seat rolls the body even on identical tracks, but least there
    assert out["identical"]["roll_acc"] < out["isotropic"]["roll_acc"]
    assert 0 < out["isotropic"]["roll_acc"] < out["independent"]["roll_acc"]


@pytest.mark.parametrize("inertance", [0.0, 60.0])
def test_decoupled_half_car_equals_two_quarter_cars(inertance):
    """I_y = m a b puts the centre of percussion of each axle on the other: two quarter
    cars (the package's traditional one, or its cfw one for a strut with an inerter)."""
    from inerterlab import quarter_car
    from inerterlab.suspension import linear_quarter_car

    m, a, b = 1200.0, 1.2, 1.4
    front = Corner(
        unsprung_mass=80.0,
        strut=Strut(stiffness=50e3, damping=3000.0, inertance=inertance),
        tyre=Tyre(stiffness=4e5, damping=300.0),
    )
    rear = Corner(
        unsprung_mass=90.0,
        strut=Strut(stiffness=44e3, damping=2800.0, inertance=inertance),
        tyre=Tyre(stiffness=4.2e5, damping=250.0),
    )
    half = linear_vehicle(
        HalfCar(
            sprung_mass=m,
            pitch_inertia=m * a * b,
            cg_to_front=a,
            cg_to_rear=b,
            front=front,
            rear=rear,
        )
    )
    f = np.geomspace(0.1, 50.0, 60)
    s = 2j * math.pi * f
    H = half.frequency_response(f)
    body = {
        "front": H["bounce_acc"] - a * H["pitch_acc"],
        "rear": H["bounce_acc"] + b * H["pitch_acc"],
    }
    for j, (axle, corner, share) in enumerate((("front", front, b), ("rear", rear, a))):
        extra = {"inertance": inertance} if inertance else {}
        qc = linear_quarter_car(
            quarter_car(
                "cfw" if inertance else "traditional",
                **extra,
                sprung_mass=m * share / (a + b),
                unsprung_mass=corner.unsprung_mass,
                stiffness=corner.strut.stiffness,
                damping=corner.strut.damping,
                tyre_stiffness=corner.tyre.stiffness,
                tyre_damping=corner.tyre.damping,
            )
        )

        def tf(name, qc=qc):  # quarter car input is the road velocity: times s for height
            return np.array(
                [
                    si * (qc.C[name] @ np.linalg.solve(si * np.eye(4) - qc.A, qc.B) + qc.D[name])
                    for si in s
                ]
            )

        np.testing.assert_allclose(body[axle][:, j], tf("body_acc"), rtol=1e-9)
        np.testing.assert_allclose(
            H[f"{axle}_deflection"][:, j], tf("suspension_deflection"), rtol=1e-9
        )
        np.testing.assert_allclose(
            H[f"{axle}_tyre_load"][:, j],
            -(corner.tyre.stiffness + corner.tyre.damping * s) * tf("tyre_deflection"),
            rtol=1e-9,
        )
        other = 1 - j  # the other axle's road does not reach this end of the body
        assert np.max(np.abs(body[axle][:, other])) < 1e-9 * np.max(np.abs(body[axle][:, j]))


def test_body_natural_frequencies_closed_form():
    # Gillespie, Fundamentals of Vehicle Dynamics (1992), ch. 5 (pitch and bounce):
    # alpha = (kf + kr)/m, beta = (kr c - kf b)/m, gamma = (kf b^2 + kr c^2)/(m k^2),
    # w^2 = (alpha + gamma)/2 +/- sqrt((alpha - gamma)^2/4 + beta^2/k^2), k^2 = I/m,
    # with b, c his distances from the CG to the front and rear axle.
    m, iy, a, b, kf, kr = 1200.0, 1900.0, 1.15, 1.45, 48e3, 52e3
    car = HalfCar(
        sprung_mass=m,
        pitch_inertia=iy,
        cg_to_front=a,
        cg_to_rear=b,
        front=Corner(
            unsprung_mass=80, strut=Strut(stiffness=kf, damping=3e3), tyre=Tyre(stiffness=4e5)
        ),
        rear=Corner(
            unsprung_mass=80, strut=Strut(stiffness=kr, damping=3e3), tyre=Tyre(stiffness=4e5)
        ),
    )
    k2 = iy / m
    alpha, beta, gamma = (kf + kr) / m, (kr * b - kf * a) / m, (kf * a * a + kr * b * b) / (m * k2)
    root = math.sqrt((alpha - gamma) ** 2 / 4 + beta**2 / k2)
    want = np.sqrt([(alpha + gamma) / 2 - root, (alpha + gamma) / 2 + root]) / (2 * math.pi)
    np.testing.assert_allclose(linear_vehicle(car).natural_frequencies(rigid_tyres=True), want, rtol=1e-12)


def _h2_by_spectrum(vehicle, outputs):
    f = np.geomspace(1e-4, 1e5, 40001)
    m = len(vehicle.inputs)
    # independent unit white velocities (two-sided density 1): one-sided velocity PSD 2 per Hz
    fac = np.zeros((f.size, m, m), complex)
    for i in range(m):
        fac[:, i, i] = math.sqrt(2.0) / (2 * math.pi * f)
    psd = output_psd(vehicle, f, fac, outputs)
    out = {}
    for k, p in psd.items():
        body = np.trapezoid(p * f, np.log(f))
        tail_hi = p[-1] * f[-1]  # PSD ~ f^-2 above the last point
        tail_lo = p[0] * f[0]  # flat below the first one
        out[k] = math.sqrt(body + tail_hi + tail_lo)
    return out


@pytest.mark.parametrize(
    "inertance,tyre_damping,network",
    [(60.0, 0.0, None), (0.0, 200.0, None), (0.0, 0.0, "k | (b - (k1 | c))")],
)
def test_spectral_rms_equals_lyapunov_h2(inertance, tyre_damping, network):
    if network is None:
        strut = Strut(stiffness=50e3, damping=3000.0, inertance=inertance)
    else:  # a network strut with internal states (tests/test_vehicle_networks.py)
        strut = NetworkStrut(network, {"k": 50e3, "k1": 9e3, "c": 2500.0, "b": 120.0})
    corner = Corner(
        unsprung_mass=80.0,
        strut=strut,
        tyre=Tyre(stiffness=4e5, damping=tyre_damping),
    )
    car = HalfCar(
        sprung_mass=1200,
        pitch_inertia=1800,
        cg_to_front=1.2,
        cg_to_rear=1.4,
        front=corner,
        rear=corner,
        seat=Seat(x=0.3, mass=80, stiffness=40e3, damping=900),
    )
    v = linear_vehicle(car)
    h2 = white_velocity_h2(v)
    finite = [k for k, n in h2.items() if math.isfinite(n)]
    if tyre_damping > 0:  # the tyre load feeds through the road velocity
        assert h2["front_tyre_load"] == math.inf
        assert "feed-through" in h2.reasons["front_tyre_load"]
    else:
        assert len(finite) == len(h2)
    spec = _h2_by_spectrum(v, finite)
    for k in finite:
        assert spec[k] == pytest.approx(h2[k], rel=2e-5), k


def test_white_velocity_h2_flags_warp():
    # a full car on independent tracks: a warp step of the road leaves static deflections
    h2 = white_velocity_h2(linear_vehicle(full_car(front=REAR)))  # no inerter: no feed-through
    assert h2["front_left_deflection"] == math.inf
    assert "static" in h2.reasons["front_left_deflection"]
    assert "0.01-10 cycle/m" in h2.reasons["front_left_deflection"]
    assert math.isfinite(h2["bounce_acc"]) and "bounce_acc" not in h2.reasons


def test_monte_carlo_rms_agrees_with_spectral():
    """Time simulation on generated tracks vs the spectral RMS (isotropic coherence)."""
    car = full_car()
    veh = linear_vehicle(car)
    # band to 3 cycle/m: the sampled road, linear between samples 2 cm apart, then
    # carries the whole band (the flat PSD of the tyre damper force reaches 10 cycle/m)
    road = road_spectrum("C", band=(0.01, 3.0))
    speed, dt = 20.0, 1.0 / 1000.0
    spec = spectral_response(veh, road, speed)
    names = ["bounce_acc", "pitch_acc", "roll_acc", "seat_acc", "front_left_deflection",
             "rear_right_tyre_load"]  # fmt: skip
    runs = []
    for seed in range(6):
        x, zl, zr = generate_tracks(road, length=4000.0, step=speed * dt, track=1.5, seed=seed)
        r = road_inputs(veh, x, zl, zr, speed, dt)
        y = simulate(veh, r, dt, names)
        keep = slice(int(10.0 / dt), None)  # start-up transient gone after 10 s
        runs.append({k: math.sqrt(np.mean(y[k][keep] ** 2)) for k in names})
    for k in names:
        vals = np.array([run[k] for run in runs])
        mean, se = vals.mean(), vals.std(ddof=1) / math.sqrt(vals.size)
        # 4 standard errors, plus 0.5 % for the linear interpolation of the sampled road
        assert abs(mean - spec.rms[k]) < 4 * se + 0.005 * spec.rms[k], (k, mean, se, spec.rms[k])


def test_input_factor_shapes_and_delay():
    half = linear_vehicle(full_car().half_car())
    road = road_spectrum("B")
    f = np.array([1.0, 2.0])
    fac = input_factor(half, road, 10.0, f)
    assert fac.shape == (2, 2, 1)
    np.testing.assert_allclose(np.abs(fac[:, 1, 0]), np.abs(fac[:, 0, 0]))
    np.testing.assert_allclose(np.angle(fac[:, 1, 0]), np.angle(np.exp(-2j * math.pi * f * 0.26)))


def test_parameter_errors_name_the_parameter():
    with pytest.raises(ParameterError, match="sprung_mass"):
        full_car(sprung_mass=-1.0)
    with pytest.raises(ParameterError, match="front_track"):
        full_car(front_track=0.0)
    with pytest.raises(ParameterError, match="inertance"):
        Strut(stiffness=1.0, damping=1.0, inertance=-2.0)
    with pytest.raises(ParameterError, match="seat.mass"):
        Seat(mass=0.0, stiffness=1.0, damping=0.0)
    with pytest.raises(ParameterError, match="front"):
        full_car(front="soft")


def test_seat_total_value_combines_the_weighted_axes():
    res = spectral_response(linear_vehicle(full_car()), road_spectrum("C"), 20.0)
    r = res.rms
    want = math.sqrt(
        r["seat_acc_wk"] ** 2 + (0.4 * r["pitch_acc_we"]) ** 2 + (0.63 * r["roll_acc_we"]) ** 2
    )
    assert r["seat_total_value"] == pytest.approx(want, rel=1e-12)
    assert res.units["seat_total_value"] == "m/s^2"
    assert r["roll_acc_we"] < r["roll_acc"]  # We falls above 1 Hz
