"""``inerterlab design``: statistics, the road scale, the study's claims and the CLI."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from inerterlab.cli import main
from inerterlab.design import DesignSettings, road_velocity_scale, run_design
from inerterlab.design.scoring import (
    crossing,
    device_network,
    expected,
    objective_of,
    paired_gain,
    simulate_candidate,
)

# a user's car (heavier body, stiffer tyre than the thesis car), no tyre damping so
# every layout's body-acceleration H2 norm is finite
CAR = dict(sprung_mass=420.0, unsprung_mass=45.0, tyre_stiffness=250e3, tyre_damping=0.0)
SMALL = dict(
    **CAR,
    stiffness=30e3,
    springs=1,
    dampers=1,
    inerters=1,
    objective="body_acc",
    roads=12,
    tune_roads=3,
    horizon=8.0,
    top=3,
    recheck=1,
)


def test_expected_value_interval_closed_form():
    # values 1..4: mean 2.5, s = sqrt(5/3), t(0.975, 3) = 3.182446305284263
    e = expected([1.0, 2.0, 3.0, 4.0])
    s = math.sqrt(5.0 / 3.0)
    assert e["mean"] == pytest.approx(2.5)
    assert e["half_width"] == pytest.approx(3.182446305284263 * s / 2.0, rel=1e-12)
    assert e["single_road"] == pytest.approx(3.182446305284263 * s * math.sqrt(1.25), rel=1e-12)
    g = paired_gain([0.9, 0.8], [1.0, 1.0])
    assert g["mean"] == pytest.approx(15.0)


def test_weighted_objective_of_reference_is_one():
    m = {"rms_body_acc": np.array([1.0, 2.0]), "rms_tyre_load": np.array([3.0, 4.0]),
         "rms_deflection": np.array([0.01, 0.02])}  # fmt: skip
    assert np.allclose(objective_of(m, "weighted", m), 1.0)


def test_road_scale_against_time_domain_roads():
    """H2 norm x the road scale predicts the RMS body acceleration of a linear car on
    ISO 8608 roads: the expected value over 16 roads (time domain, model core) agrees
    within its interval plus 3 % (the road's band limits and interpolation)."""
    from inerterlab.suspension.network_linear import network_quarter_car

    params = {"k": 30e3, "c": 1300.0}
    norm = network_quarter_car("k | c", **CAR).h2(params)["body_acc"]
    pred = norm * road_velocity_scale("C", 25.0)
    cand = {"network": "k | c", "params": params}
    v = [simulate_candidate(cand, CAR, "C", 25.0, 20.0, s)["rms_body_acc"] for s in range(16)]
    e = expected(v)
    assert abs(e["mean"] - pred) <= e["half_width"] + 0.03 * pred


def _bisection(gain, lo, hi, halvings):
    """The requirement's former search: bisection in the logarithm, midpoint of the last
    bracket."""
    a, b = math.log(lo), math.log(hi)
    for _ in range(halvings):
        m = 0.5 * (a + b)
        a, b = (m, b) if gain(math.exp(m)) > 0 else (a, m)
    return math.exp(0.5 * (a + b))


@pytest.mark.parametrize("root", [3.7, 150.0, 1999.0])
@pytest.mark.parametrize("shape", ["smooth", "kinked", "fails above"])
def test_requirement_crossing_as_accurate_as_bisection(root, shape):
    """The ITP search on the logarithm ends within the 8 halvings' accuracy of the
    crossing, log(2000) / 2^9, as bisection does, in at most one gain evaluation more than
    bisection's 10 (both ends and 8 halvings) and in fewer where the gain is smooth."""
    calls = []

    def gain(x):
        calls.append(x)
        u = math.log(x / root)
        if shape == "fails above" and x > 3 * root:
            return -math.inf  # a road beyond max_steps: counted as a loss
        return -0.2 * math.tanh(u) - (0.5 * u * u if shape == "kinked" and u > 0 else 0.0)

    value, bracket, g_lo, g_hi = crossing(gain, 1.0, 2000.0, 8)
    evaluations = len(calls)
    assert bracket == 0 and g_lo > 0 >= g_hi
    half = math.log(2000.0) / 2**9
    assert abs(math.log(value / root)) <= half
    assert abs(math.log(_bisection(gain, 1.0, 2000.0, 8) / root)) <= half
    assert evaluations <= (8 if shape == "smooth" else 11), evaluations
    assert crossing(lambda x: -1.0, 1.0, 2000.0, 8)[:2] == (1.0, -1.0)
    assert crossing(lambda x: 1.0, 1.0, 2000.0, 8)[:2] == (2000.0, 1.0)


def test_device_network_replaces_the_inerter():
    net, elp = device_network("k | (c - b)", {"k": 3e4, "c": 1e3, "b": 200.0}, "hydraulic",
                              friction=10.0)  # fmt: skip
    assert "k_dev" in net and elp["b"] == 200.0 and elp["fric_dev"]["force"] == 10.0
    net, elp = device_network("k | (c - b1)", {"k": 3e4, "c": 1e3, "b1": 200.0}, "screw")
    assert "b1" not in net and elp["b"] == 200.0


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("design") / "out"
    st = DesignSettings(**SMALL, devices=("screw",))
    return run_design(st, out, workers=1), out, st


@pytest.mark.slow
def test_device_optimum_inside_its_interval_on_fresh_roads(study):
    """The device-in-the-loop optimum, re-simulated on 24 fresh roads (seeds never used
    by the study), has a mean inside the interval the study states."""
    res, _, st = study
    row = next(r for r in res["ranking"] if r["kind"] == "device")
    cand = row["core"]
    fresh = [
        simulate_candidate(cand, CAR, st.road_class, st.speed, st.horizon, 5000 + s)["rms_body_acc"]
        for s in range(24)
    ]
    m = float(np.mean(fresh))
    assert abs(m - row["expected"]) <= row["interval95"], (m, row["expected"], row["interval95"])


@pytest.mark.slow
def test_ranking_consistent_with_h2_on_linear_candidates(study):
    """Where the H2 optimiser separates two linear candidates by more than 3 %, the
    time-domain expected values rank them the same way."""
    res, _, _ = study
    lin = [r for r in res["ranking"] if r["kind"] in ("layout", "reference")]
    assert len(lin) >= 3
    for a in lin:
        for b in lin:
            if a["h2"] < b["h2"] * 0.97:
                assert a["expected"] < b["expected"], (a["label"], b["label"])


@pytest.mark.slow
def test_study_resumes_from_its_stores(study):
    res, out, st = study
    again = run_design(st, out, workers=1)
    assert sum(again["points_computed"].values()) == 0
    assert [r["label"] for r in again["ranking"]] == [r["label"] for r in res["ranking"]]
    assert again["ranking"][0]["expected"] == res["ranking"][0]["expected"]


@pytest.mark.slow
def test_a_changed_setting_recomputes_only_the_stages_it_changes(study, tmp_path):
    """More scoring roads: the layouts and the devices resume from their stores, the
    scores and the requirements (which read the roads) are computed into new stores; the
    old ones are left as they were."""
    import shutil

    res, out, st = study
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    before = sorted(p.name for p in (copy / "stores").iterdir())
    assert all(re.fullmatch(r"[a-z_]+-[0-9a-f]{12}[.]zarr", n) for n in before), before
    again = run_design(DesignSettings(**{**SMALL, "roads": SMALL["roads"] + 2},
                                      devices=("screw",)), copy, workers=1)  # fmt: skip
    done = again["points_computed"]
    assert done["design-layout"] == 0
    assert done["design-device-linear"] == 0 and done["design-device"] == 0
    assert done["design-score"] > 0
    after = sorted(p.name for p in (copy / "stores").iterdir())
    assert set(before) < set(after)
    new = set(after) - set(before)
    assert {n.split("-")[0] for n in new} <= {"scores", "requirements"}
    # the result names the first study's stores this one did not read: those of the
    # stages it computed anew
    assert again["unread_stores"] == sorted(
        n for n in before if n.split("-")[0] in {m.split("-")[0] for m in new}
    )
    assert again["unread_stores"]
    # the first study's scores still resume, and it names the second's
    first = run_design(st, copy, workers=1)
    assert sum(first["points_computed"].values()) == 0
    assert first["unread_stores"] == sorted(new)
    assert run_design(st, out, workers=1)["unread_stores"] == []


@pytest.mark.slow
def test_requirement_is_a_crossing(study):
    """The friction the study names as the limit: a device with friction a little below
    it still gains on the tuning roads, a little above it does not."""
    res, _, _ = study
    req = [q for q in res["requirements"] if q["parameter"] == "friction"]
    assert req
    q = req[0]
    # None: the top of the range could not be simulated within the step limit (no gain)
    high = q["gain_at_high_percent"]
    assert high is None or q["gain_at_low_percent"] > high
    if q["bracket"] == 0:
        assert q["gain_at_low_percent"] > 0 > (high if high is not None else -math.inf)


def _err(argv, capsys):
    rc = main(argv)
    err = capsys.readouterr().err.strip()
    return rc, err


@pytest.mark.parametrize(
    "argv, word",
    [
        (["--budget", "springs=9"], "--budget"),
        (["--objective", "seat_wk"], "--objective"),
        (["--objective", "comfort"], "--objective"),
        (["--model", "full"], "--model"),
        (["--max-inertance", "3 m"], "--max-inertance"),
        (["--limit", "stroke=0.1"], "--limit"),
        (["--limit", "deflection=-1"], "deflection"),
        (["--sprung-mass", "-5"], "sprung"),
        (["--devices", "magic"], "--devices"),
        (["--road-class", "Z"], "--road-class"),
        (["--roads", "1"], "--roads"),
        (["--corner", "middle", "--vehicle", "nonexistent.toml"], "--corner"),
        (["--max-minutes", "0.1", "--roads", "1000", "--horizon", "600"], "--max-minutes"),
    ],
)
def test_bad_input_one_line_exit_2(argv, word, capsys, tmp_path):
    rc, err = _err(["design", "--out", str(tmp_path / "o"), *argv], capsys)
    assert rc == 2, err
    assert len(err.splitlines()) == 1 and word in err, err


def test_foreign_out_folder_refused(tmp_path, capsys):
    (tmp_path / "mine.txt").write_text("keep")
    rc, err = _err(["design", "--out", str(tmp_path)], capsys)
    assert rc == 2 and "mine.txt" in err and len(err.splitlines()) == 1


@pytest.mark.slow
def test_cli_end_to_end_report(tmp_path, capsys):
    out = tmp_path / "d"
    rc = main([
        "design", "--sprung-mass", "420kg", "--unsprung-mass", "45", "--tyre-stiffness",
        "250 kN/m", "--tyre-damping", "0", "--spring-stiffness", "30e3",
        "--budget", "springs=1,dampers=1,inerters=1", "--objective", "body_acc",
        "--devices", "screw", "--roads", "4", "--tune-roads", "2", "--horizon", "5",
        "--top", "2", "--workers", "1", "--max-inertance", "300kg", "--out", str(out), "--json",
    ])  # fmt: skip
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    res = json.loads(cap.out)
    assert res["settings"]["max_inertance"] == 300.0
    assert all(v <= 300.0 * (1 + 1e-9) for r in res["ranking"]
               for k, v in r["parameters"].items() if k.startswith("b"))  # fmt: skip
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") >= 4
    assert json.loads((out / "design.json").read_text())["ranking"][0]["unit"] == "m/s^2"


def test_vehicle_file_corner_values():
    """A full car's front corner: the body's share on the front axle (l_r / L), half of
    it per wheel; the corner's unsprung mass, tyre and wheel rate."""
    from inerterlab.cli.design import _car_from_vehicle
    from inerterlab.vehicles.config import example_vehicle_path

    c = _car_from_vehicle(example_vehicle_path(), "front")
    assert c["sprung_mass"] == pytest.approx(1200.0 * 1.45 / 2.6 / 2.0)
    assert (c["unsprung_mass"], c["tyre_stiffness"], c["tyre_damping"], c["stiffness"]) == (
        40.0,
        200e3,
        50.0,
        28e3,
    )
    r = _car_from_vehicle(example_vehicle_path(), "rear")
    assert r["sprung_mass"] + c["sprung_mass"] == pytest.approx(600.0)


def test_out_is_required(capsys):
    rc, err = _err(["design", "--roads", "4"], capsys)
    assert rc == 2 and "--out" in err and len(err.splitlines()) == 1


# the thesis car (the default study's)
THESIS = dict(sprung_mass=370.0, unsprung_mass=25.0, tyre_stiffness=120e3, tyre_damping=1300.0)


@pytest.mark.slow
@pytest.mark.parametrize(
    "device, override",
    [("hydraulic", {}), ("rectifier", {}), ("screw", {}), ("fluid", {}),
     ("hydraulic", {"friction": 800.0})],
)  # fmt: skip
def test_scoring_tolerance_far_inside_the_intervals(device, override):
    """The scoring simulations' tolerance (SCORE_RTOL) against a reference 1000 times
    tighter, for each device in the default study's k | (c - b) (and a friction that
    sticks): body_acc_wk within 1e-6 relative on every road, the mean over the roads
    moved by less than 1e-4 of its 95 % interval (measured: 3e-8 and 5e-7)."""
    from inerterlab.design.scoring import SCORE_RTOL

    net, elp = device_network("k | (c - b)", {"k": 9e4, "c": 3078.8, "b": 1153.2}, device,
                              **override)  # fmt: skip
    cand = {"network": net, "params": elp}

    def wk(rtol):
        return np.array([simulate_candidate(cand, THESIS, "C", 25.0, 5.0, s, rtol=rtol)
                         ["rms_body_acc_wk"] for s in range(4)])  # fmt: skip

    assert SCORE_RTOL >= 1e-7  # what this test measures: the looser of the two
    v, ref = wk(SCORE_RTOL), wk(1e-10)
    assert np.max(np.abs(v / ref - 1.0)) < 1e-6
    assert abs(v.mean() - ref.mean()) < 1e-4 * expected(ref)["half_width"]


def test_device_shorted_by_its_linear_optimum_is_named():
    """The hydraulic device in k | (c - (k1 | b)) on the thesis car: its H2 optimum (the
    device's series stiffness and parallel damping held) makes k1 rigid, which shorts
    the device; the design names that optimum a simpler layout (and rechecks the device
    only where it acts, pipeline stage 3), whereas the ideal inerter's optimum there has
    a soft k1."""
    from inerterlab.design.pipeline import _simpler
    from inerterlab.design.scoring import _device_linear_point, _layout_point

    lay = "k | (c - (k1 | b))"
    settings = {"car": THESIS, "stiffness": 9e4, "h2_objective": "body_acc_wk",
                "constraints": {}, "bounds_of": {lay: {"b": [10.0, 2000.0]}}, "seed": 0}  # fmt: skip
    ideal = _layout_point({"network": lay, "settings": json.dumps(settings)})
    names = ("b", "c", "k", "k1")
    ideal_vals = {n: ideal[f"p{i}"] for i, n in enumerate(names)}
    st = DesignSettings()
    assert _simpler(lay, ideal_vals, settings["bounds_of"][lay], st) == ""
    out = _device_linear_point({"layout": lay, "device": "hydraulic",
                                "ideal": json.dumps({lay: ideal_vals}),
                                "settings": json.dumps(settings)})  # fmt: skip
    vals = {n: out[f"p{i}"] for i, n in enumerate(names)}
    assert vals["k1"] >= 0.99e7
    assert _simpler(lay, vals, settings["bounds_of"][lay], st) == "k1 rigid"
