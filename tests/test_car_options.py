"""The quarter car of every command: defaults, vehicle files and explicit options."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from inerterlab.cli import main
from inerterlab.cli._common import THESIS_CAR, car_options, vehicle_quarter_car
from inerterlab.errors import ParameterError
from inerterlab.suspension.network_linear import network_quarter_car
from inerterlab.vehicles.config import example_vehicle_path

SEDAN = example_vehicle_path()

HALF = """
model = "half"
sprung_mass = "1200 kg"
pitch_inertia = "1800 kg m^2"
cg_to_front = "1.15 m"
cg_to_rear = "1.45 m"

[front]
unsprung_mass = "80 kg"
stiffness = "56 kN/m"
damping = "4400 N s/m"
tyre_stiffness = "400 kN/m"
tyre_damping = "100 N s/m"

[rear]
unsprung_mass = "76 kg"
stiffness = "50 kN/m"
damping = "4000 N s/m"
tyre_stiffness = "400 kN/m"
tyre_damping = "100 N s/m"
"""


def test_defaults_vehicle_and_overrides(tmp_path):
    assert dict(car_options()) == THESIS_CAR
    front = car_options(vehicle=SEDAN)
    # static share of the sprung mass on one front wheel: m b / (2 (a + b))
    assert front["sprung_mass"] == pytest.approx(1200 * 1.45 / (2 * 2.6), rel=1e-14)
    assert front["unsprung_mass"] == 40.0 and front["tyre_stiffness"] == 200e3
    assert (front.spring, front.damping) == (28e3, 2200.0)
    rear = car_options(vehicle=SEDAN, axle="rear", tyre_damping=0.0)
    assert rear["sprung_mass"] == pytest.approx(1200 * 1.15 / (2 * 2.6), rel=1e-14)
    assert rear["tyre_damping"] == 0.0 and "--tyre-damping" in rear.source
    # a half car's axle lumps two wheels: one wheel of it is the same quarter car
    half = tmp_path / "half.toml"
    half.write_text(HALF)
    h = vehicle_quarter_car(half, "front")
    for k in ("sprung_mass", "unsprung_mass", "tyre_stiffness"):
        assert h[k] == pytest.approx(front[k], rel=1e-14)
    assert h["spring"] == pytest.approx(28e3)
    with pytest.raises(ParameterError, match="--axle"):
        car_options(axle="rear")
    with pytest.raises(ParameterError, match="--sprung-mass"):
        car_options(sprung_mass=-5.0)
    with pytest.raises(ParameterError, match="--tyre-stiffness"):
        car_options(tyre_stiffness=1e15)


def test_truth_takes_the_car_options(capsys):
    """`network truth --sprung-mass` was "No such option"; the car reaches the design
    and the simulation (the optimised k | c of that car is the baseline)."""
    from inerterlab.network_design import optimize_network

    args = ["network", "truth", "--layout", "series", "--variant", "ideal", "--input", "bump",
            "--horizon", "1", "--backend", "serial", "--json", "--sprung-mass", "420",
            "--unsprung-mass", "45", "--tyre-stiffness", "250000", "--stiffness", "30000"]  # fmt: skip
    rc = main(args)
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    out = json.loads(cap.out)
    car = dict(THESIS_CAR, sprung_mass=420.0, unsprung_mass=45.0, tyre_stiffness=250e3)
    assert out["car"] == car
    kc = optimize_network("k | c", "body_acc", fixed={"k": 30e3}, compare=False, **car)
    assert out["parameters"]["baseline"]["c"] == pytest.approx(kc.parameters["c"], rel=1e-9)
    series = optimize_network("k | (c - b)", "body_acc", fixed={"k": 30e3}, compare=False, **car)
    assert out["parameters"]["series"]["b"] == pytest.approx(series.parameters["b"], rel=1e-6)


def test_frequency_response_of_a_vehicle_wheel_is_its_linear_transfer(capsys):
    """The traditional (linear) quarter car of a vehicle file's wheel under a sine road:
    the single-harmonic balance is exact, |x_s| = A |H_a(j w)| / w with H_a the body
    acceleration per road velocity of k | c with the file's strut and tyre."""
    rc = main(
        ["frequency-response", "--system", "quarter-car", "--suspension", "traditional",
         "--method", "shb", "--fmin", "0.5", "--fmax", "3", "--df", "0.5",
         "--amplitude", "0.01", "--vehicle", str(SEDAN), "--json"]
    )  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    assert rc == 0
    car = car_options(vehicle=SEDAN)
    q = network_quarter_car("k | c", **car)
    w = 2 * np.pi * np.array(out["freq_hz"])
    h = q.transfer({"k": car.spring, "c": car.damping}, w)["body_acc"]
    np.testing.assert_allclose(out["outputs"]["body_displacement"], 0.01 * np.abs(h) / w, rtol=1e-8)
    # and differs from the thesis car's, as a lighter-sprung, softer car should
    rc = main(
        ["frequency-response", "--system", "quarter-car", "--suspension", "traditional",
         "--method", "shb", "--fmin", "0.5", "--fmax", "3", "--df", "0.5", "--json"]
    )  # fmt: skip
    thesis = json.loads(capsys.readouterr().out)
    assert not np.allclose(
        thesis["outputs"]["body_displacement"], out["outputs"]["body_displacement"], rtol=1e-2
    )


def test_h2_and_optimize_take_a_vehicle(capsys):
    rc = main(["network", "h2", "--network", "k | c", "-p", "k=28000,c=2200", "--vehicle",
               str(SEDAN), "--json"])  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["car_source"] == "vehicle_sedan.toml, one front wheel"
    car = car_options(vehicle=SEDAN)
    ref = network_quarter_car("k | c", **car).h2({"k": 28e3, "c": 2200.0})
    assert out["body_acc"] == pytest.approx(ref["body_acc"], rel=1e-12)
    # optimize: the main spring is held at the vehicle's strut
    rc = main(["network", "optimize", "--network", "k | c", "--vehicle", str(SEDAN), "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["parameters"]["k"] == 28e3 and out["k_held_at_vehicle_spring"] == 28e3


@pytest.mark.slow
def test_truth_on_another_car_matches_its_band_limited_prediction():
    """The baseline k | c of a heavier, stiffer-tyred car simulated by the truth study on
    ISO 8608 class C roads at 20 m/s: the Wk-weighted RMS body acceleration equals the
    linear prediction over the road's band for that car (within the scatter of three
    60 s roads), and not the thesis car's."""
    from inerterlab.network_design import band_limited_rms
    from inerterlab.network_truth import layout_parameters, truth_point

    car = dict(sprung_mass=600.0, unsprung_mass=60.0, tyre_stiffness=300e3, tyre_damping=0.0)
    ms = []
    for seed in (1, 2, 3):
        m = truth_point({"layout": "baseline", "variant": "ideal", "input": "iso-c",
                         "stiffness": 40e3, "horizon": 60.0, "seed": seed, **car})  # fmt: skip
        ms.append(m["rms_body_acc_wk"] ** 2)
    ms = np.array(ms)
    design = layout_parameters("k | c", 40e3, car)
    pred = band_limited_rms("body_acc_wk", network_quarter_car("k | c", **car), design, "C", 20.0)
    se = ms.std(ddof=1) / math.sqrt(ms.size)
    assert abs(ms.mean() - pred**2) < 4 * se + 0.03 * pred**2
    d0 = layout_parameters("k | c", 40e3)
    other = band_limited_rms("body_acc_wk", network_quarter_car("k | c"), d0, "C", 20.0)
    assert abs(other**2 - pred**2) > 4 * se + 0.03 * pred**2


def test_truth_on_a_vehicle_wheel_uses_its_strut(capsys):
    args = ["network", "truth", "--layout", "series", "--variant", "ideal", "--input", "bump",
            "--horizon", "1", "--backend", "serial", "--json", "--vehicle", str(SEDAN),
            "--axle", "rear"]  # fmt: skip
    rc = main(args)
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    out = json.loads(cap.out)
    rear = car_options(vehicle=SEDAN, axle="rear")
    assert out["stiffness"] == 25e3 and out["car"] == dict(rear)
    assert out["car_source"] == "vehicle_sedan.toml, one rear wheel"
    assert out["parameters"]["series"]["k"] == 25e3
