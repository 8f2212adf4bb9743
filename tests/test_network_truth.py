"""The nonlinear-truth study of optimised suspension layouts."""

from __future__ import annotations

import json
import math

import pytest

from inerterlab.elements import AdaptiveFlywheelInerter, FluidInerter
from inerterlab.errors import ParameterError
from inerterlab.network_truth import (
    FLUID,
    LAYOUTS,
    _fluid_parameters,
    _network_for,
    network_truth,
    truth_point,
    variants,
)
from inerterlab.systems import quarter_car

DESIGN = {"k": 90_000.0, "k1": 40_000.0, "c": 4647.0, "b": 640.0}


def test_fluid_geometry_gives_the_inertance_and_poiseuille_loss():
    p = _fluid_parameters(640.0)
    assert FluidInerter(**p).inertance == pytest.approx(640.0, rel=1e-12)
    d1, d2 = FLUID["piston_diameter"], FLUID["channel_diameter"]
    a1, a2 = math.pi * d1**2 / 4, math.pi * d2**2 / 4
    # channel length from b = rho l A1^2 / A2, then Hagen-Poiseuille
    length = 640.0 * a2 / (FLUID["density"] * a1**2)
    dp_per_flow = 128 * FLUID["viscosity"] * length / (math.pi * d2**4)
    assert p["damping"] == pytest.approx(dp_per_flow * a1 * a1, rel=1e-12)
    # quadratic loss: K rho u^2 / 2 on the piston, u = v A1/A2
    assert p["quadratic"] == pytest.approx(
        0.5 * FLUID["loss_coefficient"] * FLUID["density"] * a1 * (a1 / a2) ** 2, rel=1e-12
    )


def test_every_variant_builds_a_car_with_the_inertance_asked_for():
    for layout in LAYOUTS.values():
        for v in variants():
            design = DESIGN if "k1" in layout else {k: DESIGN[k] for k in ("k", "c", "b")}
            text, params = _network_for(layout, design, v)
            quarter_car(text, params)  # builds (a bad network would raise)
            if v.startswith("afw"):
                el = AdaptiveFlywheelInerter(**params["afw"])
                assert el.inertance_min == pytest.approx(640.0, rel=1e-12)
            if v.startswith("ideal-max"):
                x = float(v.split("x=")[1])
                assert params["b"] == pytest.approx(640.0 / (1 - x), rel=1e-12)
    with pytest.raises(ParameterError, match="variant"):
        _network_for(LAYOUTS["series"], DESIGN, "afw x=1.5 law=thesis")
    with pytest.raises(ParameterError, match="variant"):
        _network_for(LAYOUTS["series"], DESIGN, "magnet")


def test_vanishing_adaptivity_is_the_ideal_inerter():
    common = dict(layout="series", input="bump", stiffness=90_000.0, horizon=3.0, seed=1)
    ideal = truth_point({**common, "variant": "ideal"})
    afw = truth_point({**common, "variant": "afw x=1e-07 law=thesis"})
    for k, v in ideal.items():
        assert afw[k] == pytest.approx(v, rel=1e-5), k


@pytest.mark.slow
def test_study_gains_survival_and_resume(tmp_path):
    kw = dict(
        layouts=("series",),
        variant_list=["ideal", "afw x=0.285 law=thesis", "screw"],
        inputs=("bump",),
        horizon=3.0,
        store=tmp_path / "truth",
    )
    res = network_truth(**kw)
    g = res.gains["rms_body_acc_wk"]
    assert float(res.survival.sel(layout="series", variant="ideal", input="bump")) == 1.0
    # the gain is the direct comparison of two simulations
    common = dict(input="bump", stiffness=90_000.0, horizon=3.0, seed=1)
    base = truth_point({**common, "layout": "baseline", "variant": "ideal"})
    screw = truth_point({**common, "layout": "series", "variant": "screw"})
    expect = 100 * (1 - screw["rms_body_acc_wk"] / base["rms_body_acc_wk"])
    assert float(g.sel(layout="series", variant="screw", input="bump")) == pytest.approx(
        expect, rel=1e-12
    )
    assert res.findings()
    again = network_truth(**kw)
    assert again.dataset.attrs["points_computed"] == 0
    json.dumps(again.to_dict())
    # another horizon into the same folder: its sweeps are computed into stores of their
    # own (the first study's stay, and still resume)
    names = sorted(p.name for p in (tmp_path / "truth").iterdir())
    assert [n.split("-")[0] for n in names] == ["baseline", "layouts"]
    assert again.unread_stores == []
    other = network_truth(**{**kw, "horizon": 2.0})
    assert other.dataset.attrs["points_computed"] == 3
    assert len(list((tmp_path / "truth").iterdir())) == 4
    assert other.unread_stores == names  # the first study's, left in place
    g2 = other.gains["rms_body_acc_wk"].sel(layout="series", variant="screw", input="bump")
    short = {**common, "horizon": 2.0}
    base2 = truth_point({**short, "layout": "baseline", "variant": "ideal"})
    screw2 = truth_point({**short, "layout": "series", "variant": "screw"})
    assert float(g2) == pytest.approx(
        100 * (1 - screw2["rms_body_acc_wk"] / base2["rms_body_acc_wk"]), rel=1e-12
    )
    last = network_truth(**kw)
    assert last.dataset.attrs["points_computed"] == 0
    assert sorted(set(p.name for p in (tmp_path / "truth").iterdir()) - set(names)) == (
        last.unread_stores
    )


@pytest.mark.slow
def test_cli_truth(capsys, tmp_path):
    from inerterlab.cli import main

    args = ["network", "truth", "--layout", "series", "--input", "bump", "--horizon", "2"]
    rc = main([*args, "--variant", "ideal", "--backend", "serial", "--json"])
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    out = json.loads(cap.out)
    assert "series" in out["comfort_gain_percent"]
    assert main([*args, "--variant", "magnet", "--backend", "serial"]) == 2
    assert "variant" in capsys.readouterr().err


@pytest.mark.slow
def test_linear_limit_reproduces_the_linear_optimum_on_a_long_road():
    """x -> 0 adaptive inerter in the H2-optimal series layout, simulated over ISO 8608
    class C roads: the RMS body acceleration equals the linear spectral prediction over
    the road's band within the statistical error of the realisations."""
    import numpy as np

    from inerterlab.excitation import ISO8608_BAND, ISO8608_CLASSES, ISO8608_N0, iso8608
    from inerterlab.network_truth import layout_parameters
    from inerterlab.suspension.network_linear import network_quarter_car

    net = LAYOUTS["series"]
    design = layout_parameters(net)
    text, params = _network_for(net, design, "afw x=1e-07 law=thesis")
    car = quarter_car(text, params)
    speed = 20.0
    rms = []
    for seed in range(4):
        res = car.simulate(iso8608("C", speed, seed=seed, length=1400.0), horizon=60.0)
        rms.append(res.metrics["rms_body_acc"])
    rms = np.array(rms)
    # spectral prediction: road velocity PSD (one-sided, per Hz) is flat,
    # (2 pi n0)^2 Gd(n0) V, between V n_lo and V n_hi
    f = np.geomspace(ISO8608_BAND[0] * speed, ISO8608_BAND[1] * speed, 20001)
    h = network_quarter_car(net).transfer(design, 2 * np.pi * f)["body_acc"]
    s_w = (2 * np.pi * ISO8608_N0) ** 2 * ISO8608_CLASSES["C"] * speed
    pred = math.sqrt(np.trapezoid(np.abs(h) ** 2 * s_w * f, np.log(f)))
    ms = rms**2
    se = ms.std(ddof=1) / math.sqrt(ms.size)
    assert abs(ms.mean() - pred**2) < 4 * se + 0.01 * pred**2


def test_metrics_only_gives_the_sampled_runs_metrics():
    """One sample at the horizon instead of 1 kHz: the same observers, so the adaptive
    steps give the same metrics to round-off; the exact steps of a linear car break at
    fewer points, which moves the Gauss-Legendre sums of the observers by <= 1e-6."""
    from inerterlab.excitation import bump, sine

    values = {k: DESIGN[k] for k in ("k", "c")}
    car = quarter_car("k | (c - b)", {**values, "b": DESIGN["b"]})  # linear: exact steps
    afw = quarter_car(
        "k | (c - afw)",
        {**values, "afw": {"flywheel": "nylon", "changing_ratio": 0.3, "ratio": 50.0}},
    )
    for system, road, tol in ((car, bump(0.05), 1e-6), (afw, sine(0.05, 5.0), 1e-12)):
        full = system.simulate(road, horizon=2.0)
        one = system.simulate(road, horizon=2.0, metrics_only=True)
        assert one.time.tolist() == [2.0] and full.time.size == 2001
        assert one.method == full.method
        for k in ("rms_body_acc_wk", "vdv", "rms_tyre_grip", "rms_deflection"):
            assert one.metrics[k] == pytest.approx(full.metrics[k], rel=tol, abs=0.0)
    with pytest.raises(ParameterError, match="metrics_only"):
        car.simulate(bump(0.05), horizon=1.0, times=[0.5, 1.0], metrics_only=True)
