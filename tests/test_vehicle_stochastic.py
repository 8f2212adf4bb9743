"""Monte Carlo over road realisations and statistical linearisation of vehicles."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import quad

from inerterlab.vehicles import build, example_vehicle_path, load_vehicle
from inerterlab.vehicles.roads import road_spectrum
from inerterlab.vehicles.spectral import spectral_response
from inerterlab.vehicles.stochastic import (
    _friction_gain,
    _wilson,
    monte_carlo,
    statistical_linearisation,
)

SHORT = dict(road_class="C", speed=20.0, length=300.0, dt=0.002, warmup=2.0)


def test_friction_gain_is_the_gaussian_mean_of_g_v_over_variance():
    F, vf = 150.0, 0.02
    for sigma in (0.005, 0.05, 0.4):

        def integrand(v, sigma=sigma):
            pdf = math.exp(-0.5 * (v / sigma) ** 2) / (sigma * math.sqrt(2 * math.pi))
            return F * math.tanh(v / vf) * v * pdf

        exact = quad(integrand, -12 * sigma, 12 * sigma, limit=400, points=[0.0])[0] / sigma**2
        assert _friction_gain(sigma, F, vf) == pytest.approx(exact, rel=1e-8)
    # Coulomb limit v_f -> 0: F sqrt(2/pi) / sigma
    assert _friction_gain(0.3, F, 1e-6) == pytest.approx(F * math.sqrt(2 / math.pi) / 0.3, 1e-4)


def test_wilson_interval_known_values():
    lo, hi = _wilson(0, 10)
    assert lo == 0.0 and hi == pytest.approx(0.2775, abs=1e-4)
    lo, hi = _wilson(5, 10)
    assert (lo, hi) == pytest.approx((0.2366, 0.7634), abs=1e-4)


def test_linearisation_of_symmetric_linear_vehicle_is_the_vehicle():
    lin = statistical_linearisation(model="half", road_class="C", speed=15.0)
    params = load_vehicle(example_vehicle_path()).half_car()
    ref = spectral_response(build(params), road_spectrum("C"), 15.0)
    assert lin.converged
    assert lin.damping == {"front": params.front.strut.damping, "rear": params.rear.strut.damping}
    for k in ("bounce_acc", "front_deflection", "rear_tyre_load"):
        assert lin.rms[k] == pytest.approx(ref.rms[k], rel=1e-9)


def test_asymmetric_damper_linearises_to_the_mean_rate():
    lin = statistical_linearisation(model="full", rebound=1.6, compression=0.6)
    params = load_vehicle(example_vehicle_path())
    assert lin.converged
    assert lin.damping["front"] == pytest.approx(1.1 * params.front.strut.damping, rel=1e-12)
    # the rectified part sets the car down: every strut's mean deflection is negative
    # (more damping while extending pulls the strut shorter on average)
    assert all(lin.mean[f"{c}_deflection"] < 0 for c in ("front_left", "rear_right"))


def test_friction_fixed_point_is_self_consistent():
    lin = statistical_linearisation(model="full", friction=120.0, friction_velocity=0.01)
    params = load_vehicle(example_vehicle_path())
    assert lin.converged
    for axle in ("front", "rear"):
        c0 = getattr(params, axle).strut.damping
        assert lin.damping[axle] == pytest.approx(
            c0 + _friction_gain(lin.velocity_rms[axle], 120.0, 0.01), rel=1e-8
        )
        assert lin.damping[axle] > c0


@pytest.mark.slow
def test_monte_carlo_of_linear_vehicle_agrees_with_spectral_rms(tmp_path):
    # tyres bilateral, dampers symmetric, no friction: the time model is linear, so the
    # Monte Carlo RMS must agree with the spectral RMS within its sampling error
    mc = monte_carlo(model="half", roads=12, lift_off="off", store=tmp_path / "mc.zarr", **SHORT)
    lin = statistical_linearisation(model="half", road_class="C", speed=20.0)
    assert mc.realisations == 12
    for k, (val, (lo, hi)) in mc.rms.items():
        # the interval half-width is 1.96-2.2 standard errors: allow 2 half-widths
        half = 0.5 * (hi - lo)
        assert abs(val - lin.rms[k]) < 2.0 * half + 0.01 * val, k
        assert lo < val < hi
    # bilateral tyres: the time the dynamic load would exceed the static load is the
    # Gaussian tail of the linear tyre load
    for c, (_frac, (lo, hi)) in mc.lift_off_fraction.items():
        assert lo - 1e-5 <= lin.spectral.lift_off[c] <= hi + 1e-5, c
    # resume: the same study again computes nothing new and gives the same numbers
    again = monte_carlo(
        model="half", roads=12, lift_off="off", store=tmp_path / "mc.zarr", **SHORT
    )
    assert again.dataset.attrs["points_computed"] == 0
    assert again.rms == mc.rms


@pytest.mark.slow
def test_cli_monte_carlo_json_and_bad_input(capsys):
    from inerterlab.cli import main

    args = ["vehicle", "monte-carlo", "--model", "half", "--length", "200"]
    rc = main([*args, "--roads", "3", "--backend", "serial", "--json", "--rebound", "1.5"])
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    out = json.loads(cap.out)
    assert out["realisations"] == 3
    assert set(out["rms"]) == set(out["linearised"]["rms"])
    assert np.isfinite(out["linearised"]["error_percent"]["bounce_acc"])
    assert main([*args, "--roads", "1"]) == 2
    assert "roads" in capsys.readouterr().err
    assert main([*args, "--roads", "3", "--model", "quarter"]) == 2
    assert "model" in capsys.readouterr().err
