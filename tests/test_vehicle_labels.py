"""What `vehicle simulate` and `vehicle monte-carlo` print beside their values: the
linearisation of a nonlinear car, and lift-off as the one-sided event it is."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.stats import norm

from inerterlab.cli import main
from inerterlab.vehicles import example_vehicle_path, linear_vehicle, load_vehicle
from inerterlab.vehicles.roads import road_spectrum
from inerterlab.vehicles.simulation import simulate_vehicle
from inerterlab.vehicles.spectral import generated_road, spectral_response
from inerterlab.vehicles.stochastic import statistical_linearisation

ADAPTIVE = 'adaptive = { flywheel = "nylon", changing_ratio = 0.285, rest_inertance = "150 kg" }\n'


def _json(capsys, args):
    rc = main(args)
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    return json.loads(cap.out)


def test_spectral_lift_off_is_the_one_sided_gaussian_tail():
    car = linear_vehicle(load_vehicle(example_vehicle_path()).half_car())
    res = spectral_response(car, road_spectrum("E"), 20.0)
    for c in car.corners:
        f0, sigma = res.static_load[c], res.rms[f"{c}_tyre_load"]
        # P(F0 + F_dyn < 0) for F_dyn ~ N(0, sigma^2), by scipy's normal distribution
        assert res.lift_off[c] == pytest.approx(norm.cdf(-f0 / sigma), rel=1e-12)
        assert 1e-3 < res.lift_off[c] < 0.2  # a road where the tail is measurable


@pytest.mark.slow
def test_linear_tyre_pulls_as_often_as_the_gaussian_tail_says():
    # a linear car on a class E road: the fraction of time its contact force is negative,
    # simulated over 6 roads, against the spectral (Gaussian, one-sided) probability;
    # the two-sided value is twice as large and far outside
    p = load_vehicle(example_vehicle_path()).half_car()
    car = linear_vehicle(p)
    road = road_spectrum("E")
    spec = spectral_response(car, road, 20.0)
    static = car.static_tyre_loads()
    fr = {c: [] for c in car.corners}
    for seed in range(6):
        g = generated_road(p, road, length=2000.0, speed=20.0, dt=0.002, track=1.5, seed=seed)
        res = simulate_vehicle(p, g, 0.002, lift_off=False)
        for c in car.corners:
            load = res.outputs[f"{c}_tyre_load"][2500:]
            fr[c].append(np.mean(static[c] + load < 0.0))
    for c in car.corners:
        vals = np.array(fr[c])
        se = vals.std(ddof=1) / math.sqrt(vals.size)
        assert abs(vals.mean() - spec.lift_off[c]) < 4 * se + 0.05 * spec.lift_off[c], (c, vals)


def test_simulate_fractions_leave_out_the_start_up_and_say_what_they_are(capsys, tmp_path):
    base = ["vehicle", "simulate", "--model", "half", "--road-class", "F", "--length", "200",
            "--json"]  # fmt: skip
    one = _json(capsys, [*base, "--lift-off"])
    # recomputed here: the same road and car, after 5 s
    p = load_vehicle(example_vehicle_path()).half_car()
    g = generated_road(p, road_spectrum("F"), length=200.0, speed=20.0, dt=0.002, track=1.5,
                       seed=0)  # fmt: skip
    res = simulate_vehicle(p, g, 0.002, lift_off=True)
    keep = slice(min(2500, g.shape[0] // 2), None)
    for c in ("front", "rear"):
        want = float(np.mean(res.contact_force[c][keep] <= 0.0))
        assert one["lift_off_fraction"][c] == pytest.approx(want, abs=1e-12)
        assert one["lift_off_fraction"][c] != pytest.approx(res.lift_off_fraction[c], abs=1e-9)
    # a nonlinear car with two-sided tyres: no lift-off fraction, the linear tyre's
    # negative-force fraction under its own name, and the Gaussian one beside it
    two = _json(capsys, [*base, "--rebound", "1.6", "--compression", "0.6"])
    assert "lift_off_fraction" not in two
    assert set(two["negative_contact_fraction"]) == {"front", "rear"}
    assert set(two["lift_off_probability_gaussian"]) == {"front", "rear"}


@pytest.mark.slow
def test_monte_carlo_without_lift_off_reports_no_lift_off_probability(capsys):
    args = ["vehicle", "monte-carlo", "--model", "half", "--road-class", "E", "--length",
            "300", "--roads", "4", "--backend", "serial", "--no-lift-off", "--json"]  # fmt: skip
    out = _json(capsys, args)
    assert "lift_off_probability" not in out and "lift_off_fraction" not in out
    lin = out["linearised"]["lift_off_probability_gaussian"]
    for c, v in out["negative_contact_fraction"].items():
        # the linear tyre pulls a few per cent of the time, as the Gaussian tail says
        assert 0.0 < v["value"] < 0.5
        assert v["value"] == pytest.approx(lin[c], rel=0.5)
    rc = main([*args[:-1]])
    text = capsys.readouterr().out
    assert rc == 0 and "rear_negative_contact_fraction" in text and "; roads" not in text


def test_simulate_adaptive_car_is_nonlinear_beside_its_linearisation(capsys, tmp_path):
    from inerterlab.systems.equilibrium import linearise
    from inerterlab.systems.gaussian import equivalent_system, gaussian_gains, nonlinear_elements
    from inerterlab.systems.vehicle import vehicle
    from inerterlab.vehicles.linear import from_state_space

    text = example_vehicle_path().read_text()
    car_file = tmp_path / "afw.toml"
    car_file.write_text(text.replace('inertance = "0 kg"\n', 'inertance = "0 kg"\n' + ADAPTIVE))
    args = ["vehicle", "simulate", "--vehicle", str(car_file), "--road-class", "C",
            "--length", "400", "--json"]  # fmt: skip
    out = _json(capsys, args)
    # the adaptive law runs even without --lift-off; the value beside it is the
    # Gaussian-equivalent linearisation, not the car at the rest inertance
    assert out["model"] == "nonlinear"
    assert "spectral_rms" not in out
    lin = statistical_linearisation(vehicle=str(car_file), model="full", road_class="C")
    for k, v in out["linearised_rms"].items():
        assert v == pytest.approx(lin.rms[k], rel=1e-12)
    # one 15 s road: the linearisation within 6 % of the simulation on comfort, where
    # the car at rest inertance is far below
    sim, eq = out["seat_acc_wk"], out["seat_acc_wk_linearised"]
    assert abs(eq / sim - 1.0) < 0.06
    # the car at the rest inertance: each adaptive inerter's slope at rest (sigma 0)
    sys = vehicle(load_vehicle(car_file), lift_off=False)
    rested = equivalent_system(sys, {e: gaussian_gains(sys, e, 0.0)
                                     for e, _, _ in nonlinear_elements(sys)})  # fmt: skip
    at_rest = from_state_space(rested, linearise(rested), True)
    rest = spectral_response(at_rest, road_spectrum("C"), 20.0).rms
    assert rest["seat_acc_wk"] < 0.9 * sim
    main(args[:-1])
    assert "linearised" in capsys.readouterr().out
