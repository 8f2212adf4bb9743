"""Frequency response of half and full cars (vehicles.frequency, vehicle frequency-response).

The state-space route is checked against a direct solve of
(-w^2 M + j w C + K) Q = (K_r + j w C_r) r from the hand-assembled matrices
(tests/_vehicle_oracle.py), against the
closed-form quarter-car transmissibility that a symmetric half car splits into, and the
full car on identical tracks against its half car."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from _vehicle_oracle import build
from inerterlab.elements import HydraulicElement
from inerterlab.errors import ParameterError
from inerterlab.vehicles import (
    Corner,
    FullCar,
    HalfCar,
    Seat,
    Strut,
    Tyre,
    example_vehicle_path,
    load_vehicle,
)
from inerterlab.vehicles.frequency import frequency_response, road_pattern
from inerterlab.vehicles.linear import linear_vehicle

FREQ = np.geomspace(0.3, 30.0, 57)


def _direct(veh, freq, pattern):
    """Q per unit amplitude by solving the second-order equations at each frequency."""
    M, C, K, Kr, Cr = veh.matrices()
    out = []
    for f, r in zip(freq, pattern, strict=True):
        w = 2 * math.pi * f
        out.append(np.linalg.solve(-(w**2) * M + 1j * w * C + K, (Kr + 1j * w * Cr) @ r))
    return np.array(out)


CASES = [
    ("full", dict(tracks="in-phase", speed=20.0)),
    ("full", dict(tracks="anti-phase", speed=15.0)),
    ("full", dict(tracks="anti-phase", axles="in-phase")),
    ("full", dict(tracks="in-phase", axles="anti-phase")),
    ("half", dict(speed=25.0)),
    ("half", dict(axles="anti-phase")),
]


@pytest.mark.parametrize(("model", "kw"), CASES)
def test_state_space_response_equals_the_direct_solve(model, kw):
    params = load_vehicle(example_vehicle_path())
    p = params if model == "full" else params.half_car()
    veh = linear_vehicle(p)
    fr = frequency_response(veh, FREQ, amplitude=0.02, **kw)
    P = road_pattern(veh, FREQ, kw.get("tracks", "in-phase"), kw.get("axles"), kw.get("speed"))
    ref = build(p)  # the hand-assembled M, C, K of the oracle
    Q = _direct(ref, FREQ, P)
    want = {"heave": Q[:, 0], "pitch": Q[:, 1]}
    if model == "full":
        want["roll"] = Q[:, 2]
    w = 2 * math.pi * FREQ
    want["seat_acc"] = -(w**2) * Q[:, ref.dofs.index("seat")]
    assert set(fr.transfer) == set(want)
    for k, q in want.items():
        scale = np.abs(q).max()
        assert np.abs(fr.transfer[k] - q).max() <= 1e-9 * scale, k
        np.testing.assert_allclose(
            fr.amplitudes()[k], 0.02 * np.abs(q), rtol=1e-9, atol=1e-12 * scale
        )


def _symmetric_half(seat=None):
    axle = Corner(unsprung_mass=80.0, strut=Strut(stiffness=50e3, damping=4e3),
                  tyre=Tyre(stiffness=400e3, damping=100.0))  # fmt: skip
    return HalfCar(sprung_mass=1100.0, pitch_inertia=1500.0, cg_to_front=1.3, cg_to_rear=1.3,
                   front=axle, rear=axle, seat=seat)  # fmt: skip


def _quarter(M, f, m=80.0, k=50e3, c=4e3, kt=400e3, ct=100.0):
    """X_s / X_r of the 2-DOF quarter car (closed form)."""
    s = 2j * math.pi * f
    zs, zt = c * s + k, ct * s + kt
    return zs * zt / ((M * s * s + zs) * (m * s * s + zs + zt) - zs * zs)


def test_symmetric_half_car_is_two_quarter_cars():
    p = _symmetric_half()
    veh = linear_vehicle(p)
    heave = frequency_response(veh, FREQ, axles="in-phase")
    np.testing.assert_allclose(heave.transfer["heave"], _quarter(550.0, FREQ), rtol=1e-10)
    assert np.abs(heave.transfer["pitch"]).max() <= 1e-12
    pitch = frequency_response(veh, FREQ, axles="anti-phase")
    # the front wheel up by 1 lowers the nose by -a theta: -a theta = X_s/X_r
    Mp = p.pitch_inertia / (2 * p.cg_to_front**2)
    np.testing.assert_allclose(-1.3 * pitch.transfer["pitch"], _quarter(Mp, FREQ), rtol=1e-10)
    assert np.abs(pitch.transfer["heave"]).max() <= 1e-12
    # seat-less: the acceleration printed is the body's at its centre of gravity
    w = 2 * math.pi * FREQ
    np.testing.assert_allclose(
        heave.transfer["bounce_acc"], -(w**2) * _quarter(550.0, FREQ), rtol=1e-10
    )


def test_wheelbase_filter_of_the_half_car():
    """At speed V the heave of a symmetric half car is X_s/X_r (1 + e^{-j w L/V})/2:
    nothing where the wavelength is 2L/(2i+1)."""
    veh = linear_vehicle(_symmetric_half())
    V, L = 20.0, 2.6
    fr = frequency_response(veh, FREQ, speed=V)
    delay = np.exp(-2j * math.pi * FREQ * L / V)
    np.testing.assert_allclose(
        fr.transfer["heave"], _quarter(550.0, FREQ) * (1 + delay) / 2, rtol=1e-10, atol=1e-14
    )
    null = frequency_response(veh, [V / (2 * L)], speed=V)
    assert abs(null.transfer["heave"][0]) <= 1e-12


def test_full_car_on_identical_tracks_is_the_half_car():
    corner = Corner(unsprung_mass=40.0, strut=Strut(stiffness=25e3, damping=1800.0),
                    tyre=Tyre(stiffness=200e3))  # fmt: skip
    rear = Corner(unsprung_mass=36.0, strut=Strut(stiffness=22e3, damping=1600.0),
                  tyre=Tyre(stiffness=200e3))  # fmt: skip
    full = FullCar(sprung_mass=1200.0, pitch_inertia=1800.0, roll_inertia=450.0,
                   cg_to_front=1.15, cg_to_rear=1.45, front_track=1.52, rear_track=1.50,
                   front=corner, rear=rear, front_anti_roll=8e3,
                   seat=Seat(x=0.3, y=0.0, mass=80.0, stiffness=60e3, damping=800.0))  # fmt: skip
    a = frequency_response(linear_vehicle(full), FREQ, speed=18.0)
    b = frequency_response(linear_vehicle(full.half_car()), FREQ, speed=18.0)
    for k in ("heave", "pitch", "seat_acc"):
        np.testing.assert_allclose(
            a.transfer[k], b.transfer[k], rtol=1e-9, atol=1e-12 * np.abs(b.transfer[k]).max()
        )
    assert np.abs(a.transfer["roll"]).max() <= 1e-12
    roll = frequency_response(linear_vehicle(full), FREQ, tracks="anti-phase", speed=18.0)
    assert np.abs(roll.transfer["heave"]).max() <= 1e-12 * np.abs(roll.transfer["roll"]).max()


def test_refusals():
    params = load_vehicle(example_vehicle_path())
    half = linear_vehicle(params.half_car())
    with pytest.raises(ParameterError, match="tracks.*half car"):
        frequency_response(half, FREQ, tracks="anti-phase")
    with pytest.raises(ParameterError, match="axles"):
        frequency_response(half, FREQ, axles="in-phase", speed=10.0)
    with pytest.raises(ParameterError, match="amplitude"):
        frequency_response(half, FREQ, amplitude=-1.0)
    dev = _symmetric_half()
    dev = dev.replace(front=Corner(unsprung_mass=80.0, tyre=Tyre(stiffness=4e5),
                                   strut=Strut(stiffness=5e4, damping=4e3, device=HydraulicElement())))  # fmt: skip
    with pytest.raises(ParameterError, match=r"front\.dev\..*Coulomb friction"):
        frequency_response(dev, FREQ)


def test_cli_frequency_response(tmp_path):
    run = [sys.executable, "-m", "inerterlab", "vehicle", "frequency-response", "--speed", "20",
           "--points", "40", "--json", "--csv", str(tmp_path / "fr.csv")]  # fmt: skip
    data = json.loads(subprocess.run(run, capture_output=True, text=True, check=True).stdout)
    veh = linear_vehicle(load_vehicle(example_vehicle_path()))
    fr = frequency_response(veh, np.geomspace(0.5, 25.0, 40), speed=20.0)
    np.testing.assert_allclose(data["amplitude"]["roll"], fr.amplitudes()["roll"], rtol=1e-12)
    assert data["amplitude_units"]["seat_acc"] == "m/s^2" and data["model"] == "linear"
    import pandas as pd

    table = pd.read_csv(tmp_path / "fr.csv")
    np.testing.assert_allclose(table["pitch amplitude [rad]"], fr.amplitudes()["pitch"], rtol=1e-12)
    bad = subprocess.run(
        run[:5] + ["--model", "half", "--tracks", "anti-phase"], capture_output=True, text=True
    )
    assert bad.returncode == 2 and "half car" in bad.stderr and "Traceback" not in bad.stderr
