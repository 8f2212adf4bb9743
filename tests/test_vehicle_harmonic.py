"""Frequency response of half and full cars by harmonic balance (vehicles.frequency,
``method="harmonic-balance"``): every wheel's road driven through a pattern of gain,
phase and delay on the one engine of inerterlab.frequency.

Oracles: a linear car's balance equals |H(j 2 pi f)| x amplitude from its state space
(the transfer of vehicles.linear, independent of the balance) to 1e-9 (in-phase and
anti-phase tracks and axles, the wheelbase delay at a speed); a car with nonlinear
corners (a gas spring carrying the load, a quadratic damper) equals the time
integration of the same core car (systems.vehicle.simulate, adaptive Dormand-Prince at
rtol 1e-10) run to steady state, NRMSE of the amplitudes <= 0.1 %."""

from __future__ import annotations

import math

import numpy as np
import pytest

from inerterlab.elements import Damper, GasSpring
from inerterlab.errors import ParameterError
from inerterlab.systems.vehicle import simulate, vehicle
from inerterlab.vehicles import example_vehicle_path, load_vehicle
from inerterlab.vehicles.frequency import frequency_response, pattern_rows

FREQ = np.geomspace(0.6, 18.0, 7)


@pytest.mark.parametrize(
    ("model", "kw"),
    [
        ("full", dict(tracks="anti-phase", speed=15.0)),
        ("full", dict(tracks="in-phase", axles="anti-phase")),
        ("half", dict(speed=25.0)),
    ],
)
def test_balance_of_a_linear_car_equals_the_state_space(model, kw):
    p = load_vehicle(example_vehicle_path())
    p = p if model == "full" else p.half_car()
    lin = frequency_response(p, FREQ, amplitude=0.02, method="linear", **kw)
    hb = frequency_response(p, FREQ, amplitude=0.02, method="harmonic-balance", harmonics=3, **kw)
    assert hb.failed == 0 and hb.model == "harmonic balance, 3 harmonics"
    assert set(hb.transfer) == set(lin.transfer)
    for k, h in lin.transfer.items():
        want = np.abs(h) * 0.02
        got = hb.amplitudes()[k]
        assert np.max(np.abs(got - want)) <= 1e-9 * want.max(), k


def _nonlinear_half():
    p = load_vehicle(example_vehicle_path()).half_car()
    front = ("gas | c", {"gas": GasSpring(pressure=2.5e6, area=4e-3, volume=1.2e-3),
                         "c": Damper(damping=1200.0, quadratic=4000.0)})  # fmt: skip
    return vehicle(p, networks={"front": front}, lift_off=False)


def _steady_amplitudes(sys, f, amp, rows, names):
    """Half peak-to-peak of each output over the last two periods of a time integration
    from rest, the roads sampled 400 times a period (linear between samples)."""
    w = 2 * math.pi * f
    periods = max(12.0, 8.0 * f)  # > 8 s, the slowest body mode decayed
    dt = 1.0 / (400 * f)
    t = np.arange(int(round(periods / (f * dt))) + 1) * dt
    r = np.column_stack([g * amp * np.sin(w * t + ph - w * d) for g, ph, d in rows])
    res = simulate(sys, r, dt, rtol=1e-10)
    tail = t >= t[-1] - 2.0 / f
    return {k: 0.5 * np.ptp(res.signals[c][tail]) for k, c in names.items()}


@pytest.mark.slow
def test_balance_of_nonlinear_corners_equals_time_integration():
    sys = _nonlinear_half()
    assert not sys.linear
    amp, speed = 0.02, 20.0
    freq = np.array([0.9, 1.4, 2.5, 6.0, 11.0])
    hb = frequency_response(sys, freq, amplitude=amp, speed=speed, harmonics=9)
    assert hb.model == "harmonic balance, 9 harmonics" and hb.failed == 0
    rows = pattern_rows("half", "in-phase", None, speed, sys.info["parameters"].wheelbase)
    names = {"heave": "bounce.x", "pitch": "pitch.x", "seat_acc": "seat.a"}
    ref = {k: [] for k in names}
    for f in freq:
        for k, v in _steady_amplitudes(sys, f, amp, rows, names).items():
            ref[k].append(v)
    lin = frequency_response(load_vehicle(example_vehicle_path()).half_car(), freq,
                             amplitude=amp, speed=speed)  # fmt: skip
    for k in names:
        a, b = hb.amplitudes()[k], np.array(ref[k])
        e = math.sqrt(np.sum((a - b) ** 2) / np.sum(a**2))
        assert e <= 1e-3, (k, e)
        # and the nonlinear corner matters here (not a linear car in disguise)
        assert np.max(np.abs(a - lin.amplitudes()[k]) / a.max()) > 0.02, k


def test_auto_takes_the_balance_for_nonlinear_corners_and_refuses_bad_input():
    sys = _nonlinear_half()
    fr = frequency_response(sys, [1.0, 2.0], amplitude=0.01, axles="anti-phase", harmonics=3)
    assert fr.harmonics == 3 and not fr.phased
    d = fr.to_dict()
    assert d["phase_deg"] is None and d["model"].startswith("harmonic balance")
    with pytest.raises(ParameterError, match="method"):
        frequency_response(sys, [1.0], method="exact")
    with pytest.raises(ParameterError, match="tracks"):
        frequency_response(sys, [1.0], tracks="anti-phase")


def test_cli_balances_a_car_on_a_gas_spring(tmp_path):
    from inerterlab.cli import main

    car = tmp_path / "gas.toml"
    car.write_text(example_vehicle_path().read_text() + '\n[front.device]\nkind = "gas"\n'
                   'pressure = "25 bar"\narea = "40 cm^2"\nvolume = "1.2e-3 m^3"\n')  # fmt: skip
    out = tmp_path / "fr.csv"
    args = ["vehicle", "frequency-response", "--vehicle", str(car), "--model", "half",
            "--points", "3", "--fmin", "1", "--fmax", "4", "--harmonics", "3", "--csv", str(out)]  # fmt: skip
    assert main(args) == 0
    import pandas as pd

    table = pd.read_csv(out)
    p = load_vehicle(car).half_car()
    fr = frequency_response(p, np.geomspace(1.0, 4.0, 3), harmonics=3)
    assert fr.model == "harmonic balance, 3 harmonics"
    np.testing.assert_allclose(table["heave amplitude [m]"], fr.amplitudes()["heave"], rtol=1e-9)
    assert not any("phase" in c for c in table.columns)
    assert main([*args[:-2], "--method", "fourier"]) == 2
