"""Monte Carlo over road realisations and statistical linearisation of vehicles."""

from __future__ import annotations

import json

import numpy as np
import pytest

from inerterlab.vehicles import example_vehicle_path, load_vehicle
from inerterlab.vehicles.linear import linear_vehicle
from inerterlab.vehicles.roads import road_spectrum
from inerterlab.vehicles.spectral import spectral_response
from inerterlab.vehicles.stochastic import (
    _wilson,
    monte_carlo,
    statistical_linearisation,
)

SHORT = dict(road_class="C", speed=20.0, length=300.0, dt=0.002, warmup=2.0)


def test_wilson_interval_known_values():
    lo, hi = _wilson(0, 10)
    assert lo == 0.0 and hi == pytest.approx(0.2775, abs=1e-4)
    lo, hi = _wilson(5, 10)
    assert (lo, hi) == pytest.approx((0.2366, 0.7634), abs=1e-4)


def test_linearisation_of_symmetric_linear_vehicle_is_the_vehicle():
    lin = statistical_linearisation(model="half", road_class="C", speed=15.0)
    params = load_vehicle(example_vehicle_path()).half_car()
    ref = spectral_response(linear_vehicle(params), road_spectrum("C"), 15.0)
    assert lin.converged and lin.equivalents == {}
    for k in ("bounce_acc", "front_deflection", "rear_tyre_load"):
        assert lin.rms[k] == pytest.approx(ref.rms[k], rel=1e-9)


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
