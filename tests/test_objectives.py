"""Objectives of the linear network optimiser: Wk-weighted body acceleration, peak
gains, road RMS values, infinite norms, inertance limits and simpler layouts."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
from scipy.integrate import quad

from inerterlab.excitation import ISO8608_BAND, ISO8608_CLASSES, ISO8608_N0
from inerterlab.iso2631 import WEIGHTINGS
from inerterlab.network_design import (
    band_limited_rms,
    evaluate,
    optimize_network,
    road_scale,
)
from inerterlab.networks import admittance_at
from inerterlab.suspension.network_linear import network_quarter_car

THESIS = dict(sprung_mass=370.0, unsprung_mass=25.0, tyre_stiffness=120e3, tyre_damping=1300.0)
USER = dict(sprung_mass=420.0, unsprung_mass=45.0, tyre_stiffness=250e3, tyre_damping=300.0)


def _direct(network, params, car, output):
    """H(j 2 pi f) from road velocity, from the two mass equations solved at each
    frequency with the network's admittance evaluated element by element (no
    polynomial of the car): m_s s v_s = Y (v_u - v_s),
    m_u s v_u = -Y (v_u - v_s) + (k_t/s + c_t)(w - v_u)."""
    ms, mu, kt, ct = (car[k] for k in ("sprung_mass", "unsprung_mass", "tyre_stiffness",
                                         "tyre_damping"))  # fmt: skip

    def h(f):
        s = 2j * math.pi * np.asarray(f, dtype=float)
        y = admittance_at(network, params, s)
        zt = kt / s + ct
        a, b = ms * s + y, mu * s + y + zt
        det = a * b - y * y
        vs, vu = y * zt / det, a * zt / det
        if output == "body_acc":
            return s * vs
        if output == "body_acc_wk":
            return s * vs * WEIGHTINGS["Wk"].response(f)
        if output == "tyre_load":
            return kt * (vu - 1.0) / s
        if output == "suspension_deflection":
            return (vs - vu) / s
        raise AssertionError(output)

    return h


def _integral(h, lo, hi, pieces=80):
    total = 0.0
    edges = np.geomspace(lo, hi, pieces + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for a, b in zip(edges[:-1], edges[1:], strict=True):
            total += quad(lambda f: abs(h(f)) ** 2, a, b, epsabs=0.0, epsrel=1e-13, limit=400)[0]
    return total


CASES = [
    ("k | c", {"k": 50e3, "c": 3000.0}, THESIS),
    ("k | (c - b)", {"k": 90e3, "c": 4647.0, "b": 640.0}, THESIS),
    ("k | c | b", {"k": 90e3, "c": 5000.0, "b": 206.3}, THESIS),  # body_acc infinite
    ("k | (b - (k1 | c))", {"k": 30e3, "k1": 20e3, "c": 1500.0, "b": 150.0}, USER),
]


@pytest.mark.parametrize("network, params, car", CASES)
def test_body_acc_wk_is_the_frequency_integral(network, params, car):
    """RMS of the Wk-weighted body acceleration on a class C road at 25 m/s (white road
    velocity, no band limits) = sqrt(int |H(j 2 pi f) Wk(f)|^2 S_v df), S_v one-sided
    (2 pi n0)^2 Gd(n0) V, by quadrature of the directly solved transfer."""
    speed = 25.0
    sv = (2 * math.pi * ISO8608_N0) ** 2 * ISO8608_CLASSES["C"] * speed
    h = _direct(network, params, car, "body_acc_wk")
    # Wk has a second-order high pass at 0.4 Hz and falls as f^-2 or faster above 100 Hz
    # while |H| of the body acceleration is at most constant: nothing beyond these ends
    ref = math.sqrt(_integral(h, 1e-4, 1e5) * sv)
    wk = evaluate(network, params, ["body_acc_wk"], **car)["body_acc_wk"]
    assert wk * road_scale("C", speed) == pytest.approx(ref, rel=1e-8)


def test_band_limited_rms_is_the_band_integral():
    """k | c | b with a damped tyre: body_acc infinite under white road velocity, finite
    over ISO 8608's band; tyre load (spring force) finite and equal to its integral."""
    network, params, car = CASES[2]
    speed = 20.0
    sv = (2 * math.pi * ISO8608_N0) ** 2 * ISO8608_CLASSES["B"] * speed
    q = network_quarter_car(network, **car)
    assert math.isinf(q.h2(params)["body_acc"])
    h = _direct(network, params, car, "body_acc")
    lo, hi = ISO8608_BAND[0] * speed, ISO8608_BAND[1] * speed
    ref = math.sqrt(_integral(h, lo, hi) * sv)
    assert band_limited_rms("body_acc", q, params, "B", speed) == pytest.approx(ref, rel=1e-8)
    t = _direct(network, params, car, "tyre_load")
    # |H|^2 of the tyre load falls as 1/f^2 at high frequency: the tail beyond F is
    # F |H(F)|^2
    tail = 1e6 * abs(t(1e6)) ** 2
    ref = math.sqrt((_integral(t, 1e-5, 1e6) + tail) * sv)
    val = evaluate(network, params, ["tyre_load"], **car)["tyre_load"] * road_scale("B", speed)
    assert val == pytest.approx(ref, rel=1e-7)


@pytest.mark.parametrize("network, params, car", CASES)
@pytest.mark.parametrize("output", ["body_acc", "body_acc_wk", "suspension_deflection"])
def test_peak_is_the_largest_gain_on_a_dense_grid(network, params, car, output):
    f = np.geomspace(1e-3, 1e4, 200_001)
    grid = np.abs(_direct(network, params, car, output)(f))
    peak = evaluate(network, params, [f"peak:{output}"], **car)[f"peak:{output}"]
    # the refined peak is the supremum: never below the grid, and the grid (ratio
    # 1.00008 between points) comes within its curvature of it
    assert peak >= grid.max() * (1 - 1e-12)
    assert peak == pytest.approx(max(grid.max(), abs(grid[-1])), rel=1e-6)


def _grid_check(res, network, objective, car, rel=1e-3):
    """No point of a 3^d grid of relative steps ``rel`` around the optimum (within the
    bounds) is better."""
    from itertools import product

    free = [k for k in res.parameters if k != "k"]
    best = res.objective
    for steps in product((-1, 0, 1), repeat=len(free)):
        p = dict(res.parameters)
        for k, s in zip(free, steps, strict=True):
            p[k] *= math.exp(s * rel)
        if p.get("b", 1.0) > 2000.0:
            continue
        v = evaluate(network, p, [objective], **car)[objective]
        assert v >= best * (1 - 1e-9), (steps, v, best)


@pytest.mark.parametrize(
    "network, objective",
    [
        ("k | (c - b)", "body_acc_wk"),
        ("k | (b - (k1 | c))", "body_acc_wk"),
        ("k | c", "peak:body_acc"),
        ("k | (c - b)", "peak:body_acc"),
        ("k | (c - b)", "tyre_load"),
    ],
)
def test_optimum_is_local_and_start_independent(network, objective):
    runs = [
        optimize_network(network, objective, fixed={"k": 30e3}, seed=s, compare=False, **USER)
        for s in (0, 7)
    ]
    r = runs[0]
    assert r.converged
    assert runs[1].objective == pytest.approx(r.objective, rel=1e-6)
    # the reported parameters reproduce the reported objective
    assert evaluate(network, r.parameters, [objective], **USER)[objective] == pytest.approx(
        r.objective, rel=1e-10
    )
    _grid_check(r, network, objective, USER)


def test_closed_form_kc_on_another_car_through_the_cli(capsys):
    """||body_acc||^2 = k sqrt((m_s + m_u) k_t) / m_s^2 at the optimal c of k | c without
    tyre damping: the car options reach the optimiser."""
    from inerterlab.cli import main

    ms, mu, kt, k = 420.0, 45.0, 250e3, 30e3
    rc = main(
        ["network", "optimize", "--network", "k | c", "--fix", f"k={k}",
         "--sprung-mass", str(ms), "--unsprung-mass", str(mu), "--tyre-stiffness", str(kt),
         "--tyre-damping", "0", "--json"]
    )  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    assert rc == 0
    assert out["objective"] == pytest.approx(math.sqrt(k * math.sqrt((ms + mu) * kt)) / ms, 1e-10)
    assert out["parameters"]["c"] == pytest.approx(k * math.sqrt((ms + mu) / kt), rel=1e-6)
    assert out["car"]["sprung_mass"] == ms


def test_road_rms_values_scale_the_norms():
    r = optimize_network("k | (c - b)", "body_acc_wk", fixed={"k": 50e3}, road=("D", 16.0))
    scale = math.pi * ISO8608_N0 * math.sqrt(2 * ISO8608_CLASSES["D"] * 16.0)
    assert r.rms["body_acc_wk"] == pytest.approx(scale * r.objective, rel=1e-14)
    assert r.unit == "m/s^2"
    assert "tyre_force (band 0.01-10 cycle/m)" in r.rms  # infinite under white velocity
    d = r.to_dict()
    assert d["road"]["class"] == "D" and d["norms"]["tyre_force"] is None


# ---------------------------------------------------------------------- infinite norms


def test_infinite_norms_say_why_and_offer_the_finite_alternative(capsys):
    from inerterlab.cli import main

    r = optimize_network("k | c | b", "body_acc", fixed={"k": 90e3}, compare=False)
    assert math.isinf(r.objective) and not r.converged
    assert "direct feed-through" in r.reason and "body_acc_wk" in r.reason
    assert "0.01-10 cycle/m" in r.reason
    # the tyre force with a tyre damper; without one it is the tyre-spring force
    v = evaluate("k | c", {"k": 5e4, "c": 3e3}, ["tyre_force", "tyre_load"], **THESIS)
    assert math.isinf(v["tyre_force"]) and math.isfinite(v["tyre_load"])
    v0 = evaluate("k | c", {"k": 5e4, "c": 3e3}, ["tyre_force", "tyre_load"],
                  **{**THESIS, "tyre_damping": 0.0})  # fmt: skip
    assert v0["tyre_force"] == pytest.approx(v0["tyre_load"], rel=1e-12)
    rc = main(["network", "h2", "--network", "k | c", "-p", "k=50000,c=3000"])
    out = capsys.readouterr().out
    assert rc == 0
    lines = [ln for ln in out.splitlines() if ln.startswith("tyre_force is infinite")]
    assert len(lines) == 1 and "tyre_load (the tyre-spring force" in lines[0]
    rc = main(["network", "h2", "--network", "k | c", "-p", "k=50000,c=3000", "--json",
               "--road-class", "C", "--speed", "20"])  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    assert out["tyre_force"] is None and "direct feed-through" in out["infinite"]["tyre_force"]
    assert out["rms"]["tyre_force (band 0.01-10 cycle/m)"] > out["rms"]["tyre_load"]


def test_unstable_car_is_named():
    """No damper anywhere (nor in the tyre): a marginally stable car, every norm and
    peak infinite, and the reason names the undamped sub-network."""
    car = {**THESIS, "tyre_damping": 0.0}
    v = evaluate("k | (k1 - b)", {"k": 5e4, "k1": 2e4, "b": 100.0}, **car)
    assert all(math.isinf(x) for x in v.values())
    from inerterlab.network_design import infinite_reason

    q = network_quarter_car("k | (k1 - b)", **car)
    why = infinite_reason("body_acc_wk", q, {"k": 5e4, "k1": 2e4, "b": 100.0})
    assert "not asymptotically stable" in why and "no damper" in why


# ---------------------------------------------------------------------- limits


def test_max_inertance_bounds_every_inerter():
    free = optimize_network("k | (c - b)", "body_acc", fixed={"k": 90e3}, compare=False)
    assert free.parameters["b"] > 300.0  # the unlimited optimum asks for more
    r = optimize_network(
        "k | (c - b)", "body_acc", fixed={"k": 90e3}, max_inertance=300.0, compare=False
    )
    assert r.parameters["b"] == pytest.approx(300.0, rel=1e-9)
    assert "b=high" in r.at_bound and r.objective > free.objective
    # the limit on a flywheel's linearised inertance r^2 I_min: a constraint
    a = optimize_network(
        "k | (c - afw)", "body_acc", fixed={"k": 90e3}, max_inertance=200.0, compare=False,
        starts=3,
    )  # fmt: skip
    from inerterlab.networks import linearise

    p = {"k": 90e3, "c": a.parameters["c"], "afw": {"ratio": a.parameters["afw.ratio"]}}
    _, vals = linearise("k | (c - afw)", p)
    assert vals["b_afw"] <= 200.0 * (1 + 1e-6)
    assert vals["b_afw"] == pytest.approx(200.0, rel=1e-4)  # active: the free one is 640


def test_constraints_on_new_quantities_hold():
    free = optimize_network("k | (c - b)", "body_acc_wk", fixed={"k": 50e3}, compare=False)
    lim = (
        0.9
        * evaluate("k | (c - b)", free.parameters, ["peak:suspension_deflection"])[
            "peak:suspension_deflection"
        ]
    )
    r = optimize_network(
        "k | (c - b)",
        "body_acc_wk",
        fixed={"k": 50e3},
        constraints={"peak:suspension_deflection": lim},
        compare=False,
    )
    got = evaluate("k | (c - b)", r.parameters, ["peak:suspension_deflection"])
    assert got["peak:suspension_deflection"] <= lim * (1 + 1e-6)
    assert r.objective >= free.objective * (1 - 1e-9)


def test_weighted_over_new_quantities_scores_one_at_the_reference():
    from inerterlab.network_design import _Problem
    from inerterlab.networks import parse_network

    k = 50e3
    c = k * math.sqrt(395.0 / 120e3)
    pb = _Problem(
        parse_network("k | c"), "weighted", {"k": k}, {},
        {}, {"body_acc_wk": 1, "tyre_load": 2, "peak:body_acc": 1}, {},
    )  # fmt: skip
    assert pb.value(pb.squares(np.log([c]))[0]) == pytest.approx(1.0, rel=1e-12)
    with pytest.raises(Exception, match="tyre_force"):
        _Problem(parse_network("k | c"), "weighted", {"k": k}, {}, {}, {"tyre_force": 1}, {})


# ---------------------------------------------------------------------- simpler layouts


def test_an_optimum_on_a_standin_bound_is_the_simpler_layout(capsys):
    """k | (k1 - c) optimised for body acceleration drives k1 to the top of its range:
    a rigid link, so the layout is k | c, reported as such with no improvement rather
    than a small negative one."""
    r = optimize_network("k | (k1 - c)", "body_acc", fixed={"k": 50e3})
    assert "k1=high" in r.at_bound
    assert r.simplified["network"] == "k | c"
    assert any("rigid link" in w for w in r.simplified["why"])
    assert r.improvement_vs["k | c"] == pytest.approx(0.0, abs=1e-6)
    kc = optimize_network("k | c", "body_acc", fixed={"k": 50e3}, compare=False)
    assert r.simplified["objective"] == pytest.approx(kc.objective, rel=1e-9)
    # an inerter driven to the bottom of its range is absent
    b = optimize_network("k | c | b", "body_acc_wk", fixed={"k": 50e3})
    if "b=low" in b.at_bound:
        assert b.simplified["network"] == "k | c"
        assert b.improvement_vs["k | c"] == pytest.approx(0.0, abs=1e-6)
    from inerterlab.cli import main

    rc = main(["network", "optimize", "--network", "k | (k1 - c)", "--fix", "k=50000"])
    out = capsys.readouterr().out
    assert rc == 0 and "simplifies to k | c" in out and "rigid link" in out


def test_simplify_tree():
    from inerterlab.network_design import _simplify
    from inerterlab.networks import parse_network

    t = parse_network("k | (k1 - c - b) | (c2 - b2)").tree
    assert _simplify(t, {"k1": "short"}).text() == "k | (c - b) | (c2 - b2)"
    assert _simplify(t, {"b": "open"}).text() == "k | (c2 - b2)"
    assert _simplify(t, {"c2": "short", "b": "open"}).text() == "k | b2"
    assert _simplify(parse_network("k | c").tree, {"c": "short"}) == "short"


def test_pareto_between_new_quantities(tmp_path):
    from inerterlab.network_design import pareto_figure, pareto_front

    ds = pareto_front(
        ["k | (c - b)"], ("body_acc_wk", "peak:suspension_deflection"), points=3,
        fixed={"k": 50e3},
    )  # fmt: skip
    ok = np.isfinite(ds["body_acc_wk"].values)
    assert ok.sum() >= 2
    lim = ds["limit_peak:suspension_deflection"].values[ok]
    assert np.all(ds["peak:suspension_deflection"].values[ok] <= lim * (1 + 1e-6))
    assert ds["peak:suspension_deflection"].attrs["units"] == "m/(m/s)"
    # a tighter limit costs comfort
    order = np.argsort(lim)
    wk = ds["body_acc_wk"].values[ok][order]
    assert np.all(np.diff(wk) <= 1e-9 * wk[0])
    pareto_figure(ds)


def test_body_acc_wk_agrees_with_the_state_space_route():
    """The thesis car's traditional suspension: the cascaded rational route equals the
    Wk-augmented state-space Lyapunov route of inerterlab.metrics."""
    from inerterlab import quarter_car
    from inerterlab.metrics import h2_norms

    ref = h2_norms(quarter_car("traditional")).norms["body_acc_wk"]
    v = evaluate("k | c", {"k": 90e3, "c": 5000.0}, ["body_acc_wk"])["body_acc_wk"]
    assert v == pytest.approx(ref, rel=1e-10)


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["--road-class", "C"], "--speed"),
        (["--road-class", "Z", "--speed", "20"], "--road-class"),
        (["--road-class", "C", "--speed", "-3"], "--speed"),
        (["--max-inertance", "heavy"], "max-inertance"),
        (["--max-inertance", "0kg"], "max-inertance"),
        (["--limit", "comfort=3"], "limit"),
        (["--limit", "body_acc_wk=-1"], "limit"),
        (["--objective", "peak:comfort"], "objective"),
        (["--axle", "rear"], "--axle"),
        (["--vehicle", "/nonexistent/car.toml"], "car.toml"),
    ],
)
def test_bad_options_exit_2(args, option, capsys):
    from inerterlab.cli import main

    rc = main(["network", "optimize", "--network", "k | (c - b)", "--fix", "k=50000", *args])
    err = capsys.readouterr().err
    assert rc == 2 and option in err and "Traceback" not in err


def test_plots_are_written(tmp_path, capsys):
    from inerterlab.cli import main

    h2, opt = tmp_path / "h2.png", tmp_path / "opt.png"
    assert main(["network", "h2", "--network", "k | (c - b)", "-p", "k=50000,c=2600,b=500",
                 "--plot", str(h2)]) == 0  # fmt: skip
    assert main(["network", "optimize", "--network", "k | (c - b)", "--fix", "k=50000",
                 "--objective", "body_acc_wk", "--road-class", "C", "--speed", "25",
                 "--plot", str(opt)]) == 0  # fmt: skip
    capsys.readouterr()
    assert h2.stat().st_size > 10_000 and opt.stat().st_size > 10_000
