"""Quarter-car simulation: the model core against the scipy oracle (tests/_quarter_car_oracle.py), inputs, results."""

import math

import numpy as np
import pytest

import _quarter_car_oracle as oracle
from inerterlab import quarter_car
from inerterlab.errors import ParameterError
from inerterlab.excitation import bump, drop, iso8608, road_series, sine
from inerterlab.metrics import METRIC_KEYS, h2_norms, series_metrics
from inerterlab.simulate import SimulationOptions, simulate, simulate_metrics

FAST = SimulationOptions()  # numba, default rtol 1e-8
_REF_CACHE: dict = {}


def _fast():
    return SimulationOptions()  # numba, default rtol 1e-8


def _reference(car, ex, horizon, key):
    """scipy rtol 1e-10 metrics, computed once per case."""
    if key not in _REF_CACHE:
        _REF_CACHE[key] = oracle.simulate_metrics(car, ex, horizon, rtol=1e-10)
    return _REF_CACHE[key]


INPUTS = {
    "drop": drop(),
    "bump": bump(),
    "bump-1cos": bump(shape="1-cos", duration=0.05),
    "sine": sine(),
    "series": road_series([0.0, 0.05, 0.1, 0.2], [0.0, 0.01, -0.005, 0.0]),
}
SUSPENSIONS = ["traditional", "cfw", "afw", "device", "device-afw"]
NUMERIC_KEYS = [k for k in METRIC_KEYS if k != "tyre_lift_off"]


def _assert_close(fast, ref, rtol, load=(370.0 + 25.0) * 9.81):
    for k in NUMERIC_KEYS:
        if ref[k] is None:  # not finite across a road step: both backends must say so
            assert fast[k] is None, k
            continue
        # the least tyre force is the static load less the largest dynamic force: its
        # error is relative to the load, not to the (small) difference
        tol = rtol * load if k == "min_tyre_force" else 1e-12
        assert fast[k] == pytest.approx(ref[k], rel=rtol, abs=tol), k
    assert fast["tyre_lift_off"] == ref["tyre_lift_off"]


@pytest.mark.parametrize("suspension", SUSPENSIONS)
@pytest.mark.parametrize("name", list(INPUTS))
def test_core_matches_the_scipy_oracle(suspension, name):
    car = quarter_car(suspension)
    ex = INPUTS[name]
    horizon = 0.25
    ref = _reference(car, ex, horizon, ("short", suspension, name))
    fast = simulate_metrics(car, ex, horizon, options=_fast())
    _assert_close(fast, ref, 1e-6)


@pytest.mark.parametrize("suspension", ["traditional", "cfw"])
def test_exact_steps_match_tight_scipy_reference(suspension):
    """The linear presets run on exact steps: every metric, the peaks located inside a
    step included (on the exact solution; 1.1e-6 off on the polynomial through the
    step's points before), within 1e-9 of scipy at rtol 1e-12 for every input."""
    car = quarter_car(suspension)
    for name, ex in INPUTS.items():
        if name == "series":
            continue  # held past its end: the same segments as "bump" for this purpose
        ref = oracle.simulate_metrics(car, ex, 0.25, rtol=1e-12)
        fast = simulate_metrics(car, ex, 0.25, options=_fast())
        _assert_close(fast, ref, 1e-9)


@pytest.mark.parametrize("law", ["momentum", "slider-dynamics"])
@pytest.mark.parametrize("suspension", ["afw", "device-afw"])
def test_other_inertia_laws_match_reference(suspension, law):
    car = quarter_car(suspension, law=law, changing_ratio=0.4)
    for name, ex in (("bump", bump()), ("sine", sine())):
        ref = _reference(car, ex, 0.2, ("law", suspension, law, name))
        fast = simulate_metrics(car, ex, 0.2, options=_fast())
        _assert_close(fast, ref, 1e-6)


def test_lift_off_model_matches_reference_and_sets_flag():
    car = quarter_car("afw", tyre_lift_off=True)
    ref = _reference(car, drop(), 0.3, ("lift-off",))
    fast = simulate_metrics(car, drop(), 0.3, options=_fast())
    _assert_close(fast, ref, 1e-6)
    # 0.05 m up stretches the tyre by more than the static load: the wheel leaves the road,
    # and the contact force, capped at zero, reports zero (not the uncapped negative value)
    assert fast["tyre_lift_off"] and fast["min_tyre_force"] == 0.0


@pytest.mark.slow
@pytest.mark.parametrize("suspension", SUSPENSIONS)
@pytest.mark.parametrize("name", ["drop", "bump", "sine"])
def test_core_matches_the_oracle_full_horizon(suspension, name):
    car = quarter_car(suspension, sprung_mass=340)
    ref = _reference(car, INPUTS[name], 3.0, ("full", suspension, name))
    fast = simulate_metrics(car, INPUTS[name], 3.0, options=_fast())
    _assert_close(fast, ref, 1e-6)


def test_samples_match_reference():
    # samples come from the continuous extension (and, for the Wk states,
    # from the exact low-pass response inside the step)
    car = quarter_car("afw")
    opts = SimulationOptions(rtol=1e-10, sample_rate=2000.0)
    a = simulate(car, sine(), 0.5, options=opts)
    b = oracle.simulate(car, sine(), 0.5, rtol=1e-10, sample_rate=2000.0)
    np.testing.assert_allclose(a.states, b.states, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(a.body_acc_wk, b.body_acc_wk, rtol=1e-6, atol=1e-6)


def test_every_saturation_crossing_ends_a_step_even_with_long_steps():
    # at a loose tolerance a step can hold a whole reversal (|v| leaves the saturation
    # speed, v passes zero, |v| saturates again) with both ends saturated: the kernel
    # must still see both crossings. Count them on a fine reference series
    car = quarter_car("afw")
    ref = oracle.simulate(car, sine(), 1.0, rtol=1e-10, sample_rate=2e4)
    v = ref.states[:, 3] - ref.states[:, 1]
    v_sat = car.info["model"].flywheel.saturation_speed / car.info["model"].transmission.ratio
    sat = np.abs(v) > v_sat
    crossings = int(np.count_nonzero(sat[1:] != sat[:-1]))
    assert crossings >= 10
    for rtol in (1e-4, 1e-6, 1e-8):
        run = simulate(car, sine(), 1.0, options=SimulationOptions(rtol=rtol), output="metrics")
        assert run.stats["events"] >= crossings, rtol


@pytest.mark.parametrize(
    ("suspension", "kwargs"),
    [("afw", {"law": "slider-dynamics"}), ("device", {}), ("device-afw", {})],
)
def test_a_sampled_series_keeps_every_sample(suspension, kwargs):
    res = simulate(quarter_car(suspension, **kwargs), sine(), 0.3, options=_fast())
    assert res.time.size == 301


@pytest.mark.parametrize("suspension", ["cfw", "afw"])
def test_sparse_samples_match_the_reference(suspension):
    # at 200 Hz the steps are shorter than the sample interval: the samples come from
    # the continuous extension of the step that holds them
    car = quarter_car(suspension)
    opts = SimulationOptions(sample_rate=200.0)
    a = simulate(car, bump(), 0.5, options=opts)
    b = oracle.simulate(car, bump(), 0.5, rtol=1e-10, sample_rate=200.0)
    np.testing.assert_allclose(a.states, b.states, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(a.body_acc_wk, b.body_acc_wk, rtol=1e-6, atol=1e-6)


def test_sampled_series_reproduce_the_integrated_metrics():
    car = quarter_car("afw")
    res = simulate(car, sine(), 2.0, options=SimulationOptions(sample_rate=20000.0))
    m = res.metrics()
    s = series_metrics(
        res.time, res.body_acc, res.tyre_grip, res.deflection, res.tyre_force, res.body_acc_wk
    )
    for k in ("rms_body_acc", "rms_tyre_grip", "rms_deflection", "rms_body_acc_wk", "vdv"):
        assert s[k] == pytest.approx(m[k], rel=1e-5), k
    # sampled maxima cannot exceed the located peaks, and come close at 20 kHz
    assert s["peak_body_acc"] <= m["peak_body_acc"] * (1 + 1e-9)
    assert s["peak_body_acc"] == pytest.approx(m["peak_body_acc"], rel=1e-4)
    # the Wk filter run on the sampled signal (scipy lsim) agrees with the states
    s2 = series_metrics(res.time, res.body_acc, res.tyre_grip, res.deflection)
    assert s2["rms_body_acc_wk"] == pytest.approx(m["rms_body_acc_wk"], rel=1e-4)


def test_series_backends_agree_on_samples():
    car = quarter_car("device-afw")
    a = simulate(car, bump(), 0.2, options=SimulationOptions(rtol=1e-10))
    b = oracle.simulate(car, bump(), 0.2, rtol=1e-10)
    assert a.time.size == 201 and a.time[-1] == pytest.approx(0.2)
    # the wheel and body states (the device's own are laid out differently)
    np.testing.assert_allclose(a.states[:, :4], b.states[:, :4], rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(a.body_acc, b.body_acc, rtol=1e-6, atol=1e-6)


def test_bump_edge_passes_tyre_damper_impulse():
    # traditional car: the unsprung mass jumps by C_t h / M_t at the road step
    car = quarter_car("traditional")
    res = simulate(car, bump(duration=0.5), 0.1, options=SimulationOptions(sample_rate=1e4))
    q = car.info["model"].parameters
    assert res.states[0, 1] == pytest.approx(q.tyre_damping * 0.05 / q.unsprung_mass, rel=1e-12)


def test_inerter_shares_the_impulse_and_conserves_momentum():
    for law in ("thesis", "momentum"):
        car = quarter_car("afw", law=law)
        res = simulate(car, bump(duration=0.5), 0.01, options=SimulationOptions(sample_rate=1e4))
        q = car.info["model"].parameters
        v2, v3 = res.states[0, 1], res.states[0, 3]
        assert q.unsprung_mass * v2 + q.sprung_mass * v3 == pytest.approx(
            q.tyre_damping * 0.05, rel=1e-12
        )
        assert 0 < v3 < v2


def test_linear_metrics_scale_with_amplitude():
    car = quarter_car("cfw")
    a = simulate_metrics(car, sine(0.01), 1.0)
    b = simulate_metrics(car, sine(0.03), 1.0)
    for k in ("rms_body_acc", "rms_deflection", "rms_body_acc_wk", "peak_deflection"):
        assert b[k] == pytest.approx(3 * a[k], rel=1e-6)


@pytest.mark.slow
def test_iso8608_time_rms_matches_h2_index():
    # linear car without tyre damping (finite body-acceleration norm), class C at 20 m/s
    car = quarter_car("traditional", tyre_damping=0.0)
    h2 = h2_norms(car).ride_indices("C", 20.0)
    vals = {k: [] for k in ("rms_deflection", "rms_tyre_grip", "rms_body_acc")}
    for seed in range(4):
        road = iso8608("C", 20.0, seed=seed, length=2400.0)
        m = simulate_metrics(car, road, 120.0)
        for k in vals:
            vals[k].append(m[k])
    for key, h2key in (
        ("rms_deflection", "suspension_deflection"),
        ("rms_tyre_grip", "tyre_grip"),
        ("rms_body_acc", "body_acc"),
    ):
        ms = np.sqrt(np.mean(np.square(vals[key])))
        # 4 x 120 s of a response with ~1 Hz bandwidth: a few per cent statistical error;
        # the road band (0.01-10 cycle/m) and linear interpolation add a little more
        assert ms == pytest.approx(h2[h2key], rel=0.08), key


def test_result_to_pandas_and_errors():
    res = simulate(quarter_car("traditional"), drop(), 0.1)
    df = res.to_pandas()
    assert {"body_acc", "deflection", "tyre_force", "tyre_grip", "road"} <= set(df.columns)
    assert df.index.name == "time" and len(df) == 101
    assert math.isclose(df["deflection"].iloc[0], 0.0)
    m = simulate(quarter_car("traditional"), drop(), 0.1, output="metrics")
    assert m.time is None
    with pytest.raises(ParameterError, match="output"):
        m.to_pandas()
    with pytest.raises(ParameterError, match="horizon"):
        simulate(quarter_car("traditional"), drop(), -1.0)
    with pytest.raises(ParameterError, match="method"):
        SimulationOptions(method="julia")
    with pytest.raises(ParameterError, match="excitation"):
        simulate(quarter_car("traditional"), "drop", 1.0)


