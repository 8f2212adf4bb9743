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


_HYD = '\n[front.device]\nkind = "hyd"\n'
_ROAD = dict(road_class="C", speed=20.0, length=60.0, dt=0.002, warmup=1.0, fixed_step=0.002)


def _hyd_car(path, damping="2200 N s/m"):
    text = example_vehicle_path().read_text().replace('damping = "2200 N s/m"', f'damping = "{damping}"')
    path.write_text(text + _HYD)
    return path


def test_a_road_point_reuses_the_car_and_gives_what_a_fresh_car_gives(tmp_path):
    """The road points of one process keep the built car (keyed on the file's content):
    the same numbers as the car built afresh for the road, and a changed file is a new
    car."""
    from inerterlab.vehicles.simulation import simulate_vehicle
    from inerterlab.vehicles.stochastic import _DEFAULTS, _SYSTEMS, _car, _one_road, _tracks

    path = _hyd_car(tmp_path / "hyd.toml")
    point = dict(_DEFAULTS, **_ROAD, vehicle=str(path), seed=4)
    _SYSTEMS.clear()
    first = _one_road(point, "full")
    second = _one_road(point, "full")
    assert len(_SYSTEMS) == 1
    assert first == second
    p = _car(str(path), "full")
    fresh = simulate_vehicle(p, _tracks(p, point, 4), 0.002, warmup=1.0, fixed_step=0.002)
    assert fresh.comfort["wk_rms"] ** 2 == pytest.approx(first["ms_comfort_wk"], rel=1e-12)
    keep = slice(500, None)
    assert float(np.mean(fresh.outputs["front_left_deflection"][keep] ** 2)) == pytest.approx(
        first["ms_front_left_deflection"], rel=1e-12
    )
    _hyd_car(path, damping="3000 N s/m")  # the file changes: another car
    other = _one_road(point, "full")
    assert len(_SYSTEMS) == 2
    assert other["ms_front_left_deflection"] != first["ms_front_left_deflection"]


def test_monte_carlo_in_worker_processes_equals_the_serial_run(tmp_path):
    """The workers, forked after the calling process built the car and loaded (or
    compiled) its code, give the serial run's numbers."""
    path = _hyd_car(tmp_path / "hyd.toml")
    kw = dict(vehicle=str(path), model="full", roads=4, **_ROAD)
    serial = monte_carlo(backend="serial", **kw)
    par = monte_carlo(backend="processes", workers=2, **kw)
    assert par.realisations == serial.realisations == 4
    for k, (v, (lo, hi)) in serial.rms.items():
        assert par.rms[k][0] == pytest.approx(v, rel=1e-12), k
        assert par.rms[k][1] == pytest.approx((lo, hi), rel=1e-12), k
