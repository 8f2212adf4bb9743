"""Sweeps and optimisation over vehicle parameters (spectral method)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from inerterlab.errors import ParameterError
from inerterlab.studies import sweep
from inerterlab.vehicles import example_vehicle_path, load_vehicle
from inerterlab.vehicles.design import optimize_vehicle, spectral_metrics, vehicle_with


def test_sweep_point_equals_direct_evaluation():
    ds = sweep(
        {
            "point": "vehicle-spectral",
            "parameters": {"front_damping": [1500.0, 3000.0], "rear_inertance": [0.0, 80.0]},
        },
        backend="serial",
    )
    base = load_vehicle(example_vehicle_path())
    direct = spectral_metrics(vehicle_with(base, front_damping=3000.0, rear_inertance=80.0))
    got = ds.sel(front_damping=3000.0, rear_inertance=80.0)
    for k, v in direct.items():
        assert float(got[k]) == pytest.approx(v, rel=1e-12), k
    assert float(ds.comfort_wk.sel(front_damping=1500.0, rear_inertance=0.0)) != pytest.approx(
        direct["comfort_wk"], rel=1e-3
    )


def test_optimum_reproduces_its_value_and_no_neighbour_is_better():
    res = optimize_vehicle(parameters=("front_damping", "rear_damping"))
    base = load_vehicle(example_vehicle_path())
    again = spectral_metrics(vehicle_with(base, **res.parameters))["comfort_wk"]
    assert again == pytest.approx(res.value, rel=1e-12)
    assert res.value < res.baseline["comfort_wk"]
    assert not res.at_bound
    for df in (0.97, 1.03):
        for dr in (0.97, 1.0, 1.03):
            p = {
                "front_damping": res.parameters["front_damping"] * df,
                "rear_damping": res.parameters["rear_damping"] * dr,
            }
            assert spectral_metrics(vehicle_with(base, **p))["comfort_wk"] >= res.value * (
                1 - 1e-9
            )
    # the result does not depend on the sample seed
    other = optimize_vehicle(parameters=("front_damping", "rear_damping"), seed=5)
    for k, v in res.parameters.items():
        assert other.parameters[k] == pytest.approx(v, rel=1e-3)


def test_limits_are_met_and_active():
    free = optimize_vehicle(parameters=("front_damping", "rear_damping"))
    cap = 0.9 * free.metrics["rear_deflection"]
    res = optimize_vehicle(
        parameters=("front_damping", "rear_damping"), limits={"rear_deflection": cap}
    )
    assert res.feasible
    assert res.metrics["rear_deflection"] <= cap * (1 + 1e-6)
    assert res.metrics["rear_deflection"] == pytest.approx(cap, rel=1e-4)  # active
    assert res.value > free.value


def test_bad_names_and_cli(capsys):
    with pytest.raises(ParameterError, match="parameters"):
        optimize_vehicle(parameters=("front_colour",))
    with pytest.raises(ParameterError, match="objective"):
        optimize_vehicle(objective="speed")
    from inerterlab.cli import main

    rc = main(["vehicle", "optimize", "--parameter", "rear_damping", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and set(out["parameters"]) == {"rear_damping"}
    assert np.isfinite(out["value"])
    assert main(["vehicle", "optimize", "--limit", "rear_deflection"]) == 2
    assert "limit" in capsys.readouterr().err
