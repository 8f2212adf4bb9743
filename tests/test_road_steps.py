"""Road steps: the impulse an inerter passes to the body, and the metrics across a step.

At a step of the road the tyre damper passes the impulse C_t * step to the wheel. With an
inerter between wheel and body the body velocity jumps as well, so the body acceleration
holds a Dirac impulse: its plain RMS and peak are infinite, while the Wk-weighted
acceleration (a strictly proper filter) stays finite. Checks here: the jump against the
closed form of momentum conservation, the Wk metrics against the limit of an
edge-smoothed pulse (which needs no jump handling at all), and the reporting.
"""

import json
import math

import numpy as np
import pytest

import _quarter_car_oracle as oracle
from inerterlab import quarter_car
from inerterlab.cli import main
from inerterlab.errors import ParameterError
from inerterlab.excitation import bump, drop, road_steps, sine
from inerterlab.simulate import simulate

FINITE = (
    "rms_body_acc_wk",
    "vdv",
    "crest_factor",
    "peak_body_acc_wk",
    "rms_tyre_grip",
    "rms_deflection",
    "peak_deflection",
)


def test_body_velocity_jump_equals_the_closed_form_for_a_constant_inerter():
    # impulse J = C_t h on the wheel; the inerter b couples the two velocity jumps:
    # M dv3 = b (dv2 - dv3) and M_t dv2 + M dv3 = J
    car = quarter_car("cfw", sprung_mass=355.0)
    q = car.info["model"].parameters
    b = car.info["model"].transmission.ratio ** 2 * car.info["model"].flywheel.inertia_min
    J = q.tyre_damping * 0.05
    dv2 = J / (q.unsprung_mass + q.sprung_mass * b / (q.sprung_mass + b))
    dv3 = b * dv2 / (q.sprung_mass + b)
    for run in (simulate, lambda *a, **k: oracle.simulate(*a, rtol=1e-10, **k)):
        res = run(car, bump(), 0.5, output="metrics")
        (t0, up), (t1, down) = res.body_velocity_jumps
        assert (t0, t1) == (0.0, 0.01)
        assert up == pytest.approx(dv3, rel=1e-12)
        assert down == pytest.approx(-dv3, rel=1e-12)


def test_no_body_jump_without_an_inerter_straight_to_the_body():
    for s in ("traditional", "device", "device-afw"):
        res = simulate(quarter_car(s), bump(), 0.2, output="metrics")
        assert res.body_velocity_jumps == ()
        assert res.metrics()["rms_body_acc"] is not None


@pytest.mark.parametrize("suspension", ["cfw", "afw"])
@pytest.mark.parametrize("edge", ["ramp", "half-cosine"])
def test_smoothed_pulse_converges_to_the_step_pulse(suspension, edge):
    # an independent check of the jump handling: the smoothed pulse has no jump at all,
    # its body acceleration is finite, and as the edges sharpen every finite metric
    # tends to the step pulse's, while the plain RMS acceleration grows like 1/sqrt(width)
    car = quarter_car(suspension, sprung_mass=355.0)
    step = simulate(car, bump(), 2.0, output="metrics")
    ref = step.metrics()
    assert ref["rms_body_acc"] is None and ref["peak_body_acc"] is None
    assert set(step.not_finite) >= {"rms_body_acc", "peak_body_acc"}
    errors, plain = [], []
    for width in (1e-4, 1e-5, 1e-6):
        sm = simulate(car, bump(edge=edge, edge_width=width), 2.0, output="metrics")
        assert sm.body_velocity_jumps == () and not sm.not_finite
        m = sm.metrics()
        errors.append(max(abs(m[k] / ref[k] - 1.0) for k in FINITE))
        plain.append(m["rms_body_acc"])
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 2e-5
    # unweighted RMS: ~ sqrt(10) per decade of width, without bound
    assert plain[1] / plain[0] == pytest.approx(math.sqrt(10.0), rel=0.05)
    assert plain[2] / plain[1] == pytest.approx(math.sqrt(10.0), rel=0.05)


def test_weighted_metrics_across_the_step_match_an_independent_review():
    # values of an independent check (its own quarter car and its own Wk filter written
    # from the model description), 355 kg, bump 0.05 m x 10 ms, 10 s: with the jump
    # driving the filter the inerter car is worse than the traditional one on Wk comfort
    got = {
        s: simulate(quarter_car(s, sprung_mass=355.0), bump(), 10.0, output="metrics").metrics()
        for s in ("traditional", "cfw", "afw")
    }
    review = {
        "traditional": (0.3589, 2.983),
        "cfw": (0.4582, 3.899),
        "afw": (0.4740, 4.009),
    }
    for s, (wk, vdv) in review.items():
        assert got[s]["rms_body_acc_wk"] == pytest.approx(wk, abs=1e-4)
        assert got[s]["vdv"] == pytest.approx(vdv, abs=1e-3)
    assert got["cfw"]["rms_body_acc_wk"] > got["traditional"]["rms_body_acc_wk"]


def test_min_tyre_force_is_not_finite_at_a_downward_step_with_tyre_damping():
    res = simulate(quarter_car("traditional"), bump(), 0.5, output="metrics")
    m = res.metrics()
    assert m["min_tyre_force"] is None and m["tyre_lift_off"]
    assert "steps down" in res.not_finite["min_tyre_force"]
    # the smoothed pulse shows why: the contact force goes ever more negative
    mins = [
        simulate(
            quarter_car("traditional"), bump(edge="ramp", edge_width=w), 0.5, output="metrics"
        ).metrics()["min_tyre_force"]
        for w in (1e-3, 1e-4)
    ]
    assert mins[1] < mins[0] < 0
    # with lift-off modelled the tyre cannot pull: finite, capped at zero (the tyre
    # element takes no road step: the edges smoothed)
    lifted = simulate(quarter_car("traditional", tyre_lift_off=True),
                      bump(edge="ramp", edge_width=1e-4), 0.5)  # fmt: skip
    assert lifted.metrics()["min_tyre_force"] >= 0.0


def test_road_steps_and_round_off():
    assert road_steps(bump().segments(1.0), 0.0, 1.0) == [(0.0, 0.05), (0.01, -0.05)]
    # a ramp's end differs from the next level by round-off only: no step
    assert road_steps(bump(edge="ramp", edge_width=1e-3).segments(1.0), 0.0, 1.0) == []
    # and the simulation takes none there either (the same threshold in both backends)
    smooth = bump(edge="ramp", edge_width=1e-3)
    assert simulate(quarter_car("cfw"), smooth, 0.1, output="metrics").body_velocity_jumps == ()


@pytest.mark.parametrize(
    "road",
    [
        drop(),
        bump(),
        bump(height=-0.03, start=0.2, duration=0.05),
        bump(edge="ramp", edge_width=1e-3),
        bump(edge="half-cosine", edge_width=2e-3),
        bump(shape="1-cos", duration=0.1),
        sine(),
    ],
)
@pytest.mark.parametrize("initial", [0.0, 0.05, -0.01])
def test_road_helpers_small_path_equals_the_array_path(monkeypatch, road, initial):
    # a few segments are handled element by element in Python (a sweep point's
    # overhead); the results are the same floats as the array path's
    import inerterlab.excitation as ex

    segs = road.segments(1.0)
    fast = (ex.road_scale(segs), ex.road_steps(segs, initial, 1.0), ex.road_steps(segs, initial, 0.005))
    monkeypatch.setattr(ex, "_SMALL", -1)
    slow = (ex.road_scale(segs), ex.road_steps(segs, initial, 1.0), ex.road_steps(segs, initial, 0.005))
    assert fast == slow


def test_bad_edge_options_are_refused():
    with pytest.raises(ParameterError, match="edge_width"):
        bump(edge="ramp")
    with pytest.raises(ParameterError, match="edge_width"):
        bump(edge="ramp", edge_width=0.02)
    with pytest.raises(ParameterError, match="edge_width"):
        bump(edge_width=0.001)
    with pytest.raises(ParameterError, match="edge"):
        bump(shape="1-cos", edge="ramp", edge_width=0.001)


def test_cli_reports_null_with_a_reason_and_the_jumps(capsys):
    rc = main(["simulate", "--suspension", "cfw", "--input", "bump", "--horizon", "1", "--json"])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    assert out["rms_body_acc"] is None and out["peak_body_acc"] is None
    assert "Dirac" in out["not_finite"]["rms_body_acc"]
    assert [j["time"] for j in out["body_velocity_jumps"]] == [0.0, 0.01]
    assert np.isfinite(out["rms_body_acc_wk"])
    rc = main(
        ["simulate", "--suspension", "cfw", "--input", "bump", "--horizon", "1",
         "--edge", "half-cosine", "--edge-width", "0.001", "--json"]
    )  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["rms_body_acc"] > 0 and out["body_velocity_jumps"] == []


def test_sweep_point_keeps_a_not_finite_metric_as_missing_not_failed():
    from inerterlab.studies.points import point_function
    from inerterlab.studies.sweep import STATUS_OK, ChunkTask, evaluate_chunk

    pf = point_function("quarter-car")
    fixed = {**pf.defaults, "input": "bump", "horizon": 0.5}
    del fixed["suspension"]
    task = ChunkTask(
        point=pf,
        names=("suspension",),
        values=(("traditional", "cfw"),),
        fixed=tuple(fixed.items()),
        indices=(0, 1),
        chunk=0,
    )
    res = evaluate_chunk(task)
    assert np.all(res.status == STATUS_OK)
    i = pf.metrics.index("rms_body_acc")
    assert np.isfinite(res.values[0, i]) and np.isnan(res.values[1, i])
    assert res.reasons == ("", "not finite across a road step: rms_body_acc, peak_body_acc")
    assert np.isfinite(res.values[1, pf.metrics.index("rms_body_acc_wk")])


def test_min_tyre_force_is_finite_at_a_downward_step_without_tyre_damping():
    # without a tyre damper nothing pulls the wheel with a Dirac at the step down: the
    # contact force falls by k_t x step, a finite value; the network path said "not
    # finite" here while the named suspension gave the value
    named = simulate(quarter_car("afw", tyre_damping=0.0), bump(), 2.0, output="metrics")
    net = quarter_car("k | c | afw", {"k": 90000.0, "c": 5000.0}, tyre_damping=0.0)
    core = net.simulate(bump(), 2.0)
    for m, nf in ((named.metrics(), named.not_finite), (core.metrics, core.not_finite)):
        assert "min_tyre_force" not in nf
        assert np.isfinite(m["min_tyre_force"]) and not m["tyre_lift_off"]
    # the same car both ways: the same least contact force [N]
    assert core.metrics["min_tyre_force"] == pytest.approx(
        named.metrics()["min_tyre_force"], rel=1e-9
    )
    # its value is above static load less k_t x step (the spring alone cannot pull more)
    p = net.info["car"]
    static = (p["sprung_mass"] + p["unsprung_mass"]) * p["gravity"]
    assert core.metrics["min_tyre_force"] > static - p["tyre_stiffness"] * 0.05 - 1e-6
    # with a tyre damper both paths say why, in the same words, and the contact is lost
    damped = quarter_car("k | c | afw", {"k": 90000.0, "c": 5000.0}).simulate(bump(), 2.0)
    named_d = simulate(quarter_car("afw"), bump(), 2.0, output="metrics")
    assert damped.metrics["min_tyre_force"] is None and damped.metrics["tyre_lift_off"]
    assert damped.not_finite["min_tyre_force"] == named_d.not_finite["min_tyre_force"]
    assert "-0.05 m at t = 0.01 s" in damped.not_finite["min_tyre_force"]


def test_a_step_with_no_finite_response_names_the_element_on_the_road():
    # a tyre that can lift off is a contact: a step has no finite response through it
    from inerterlab.errors import ConvergenceError

    with pytest.raises(ConvergenceError, match=r"through the element 'tyre' \(a contact"):
        simulate(quarter_car("traditional", tyre_lift_off=True), bump(), 0.5)
    # and the same car, its edges smoothed as the message says, runs
    smooth = bump(edge="ramp", edge_width=1e-3)
    res = simulate(quarter_car("traditional", tyre_lift_off=True), smooth, 0.5, output="metrics")
    assert res.metrics()["min_tyre_force"] >= 0.0
