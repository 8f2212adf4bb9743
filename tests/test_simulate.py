"""Quarter-car simulation: compiled backend against the scipy reference, inputs, results."""

import math

import numpy as np
import pytest

from inerterlab import quarter_car
from inerterlab.errors import ParameterError
from inerterlab.excitation import bump, drop, iso8608, road_series, sine
from inerterlab.metrics import METRIC_KEYS, h2_norms, series_metrics
from inerterlab.simulate import SimulationOptions, simulate, simulate_metrics

REF = SimulationOptions(backend="scipy", rtol=1e-10)
FAST = SimulationOptions()  # numba, default rtol 1e-8
_REF_CACHE: dict = {}


def _fast():
    return SimulationOptions()  # numba, default rtol 1e-8


def _reference(car, ex, horizon, key):
    """scipy rtol 1e-10 metrics, computed once per case."""
    if key not in _REF_CACHE:
        _REF_CACHE[key] = simulate_metrics(car, ex, horizon, options=REF)
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


def _assert_close(fast, ref, rtol):
    for k in NUMERIC_KEYS:
        if ref[k] is None:  # not finite across a road step: both backends must say so
            assert fast[k] is None, k
            continue
        assert fast[k] == pytest.approx(ref[k], rel=rtol, abs=1e-12), k
    assert fast["tyre_lift_off"] == ref["tyre_lift_off"]


@pytest.mark.parametrize("suspension", SUSPENSIONS)
@pytest.mark.parametrize("name", list(INPUTS))
def test_fast_backend_matches_scipy_reference(suspension, name):
    car = quarter_car(suspension)
    ex = INPUTS[name]
    horizon = 0.25
    ref = _reference(car, ex, horizon, ("short", suspension, name))
    fast = simulate_metrics(car, ex, horizon, options=_fast())
    _assert_close(fast, ref, 1e-6)


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
def test_fast_backend_matches_reference_full_horizon(suspension, name):
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
    b = simulate(
        car, sine(), 0.5, options=SimulationOptions(backend="scipy", rtol=1e-10, sample_rate=2000.0)
    )
    np.testing.assert_allclose(a.states, b.states, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(a.body_acc_wk, b.body_acc_wk, rtol=1e-6, atol=1e-6)


def test_every_saturation_crossing_ends_a_step_even_with_long_steps():
    # at a loose tolerance a step can hold a whole reversal (|v| leaves the saturation
    # speed, v passes zero, |v| saturates again) with both ends saturated: the kernel
    # must still see both crossings. Count them on a fine reference series
    car = quarter_car("afw")
    ref = simulate(
        car, sine(), 1.0, options=SimulationOptions(backend="scipy", rtol=1e-10, sample_rate=2e4)
    )
    v = ref.states[:, 3] - ref.states[:, 1]
    v_sat = car.info["model"].flywheel.saturation_speed / car.info["model"].transmission.ratio
    sat = np.abs(v) > v_sat
    crossings = int(np.count_nonzero(sat[1:] != sat[:-1]))
    assert crossings >= 10
    for rtol in (1e-4, 1e-6, 1e-8):
        run = simulate(car, sine(), 1.0, options=SimulationOptions(rtol=rtol), output="metrics")
        assert run.stats["kink_steps"] >= crossings, rtol


def test_exact_step_tables_match_scipy_expm_and_the_right_hand_side():
    # the linear model of the exact steps is the compiled right-hand side itself while
    # the flywheel is saturated, and its tables are matrix exponentials
    from scipy.linalg import expm

    from inerterlab.simulate import _initial_state, _wk_sections
    from inerterlab.suspension import _kernels as K

    car = quarter_car("afw").info["model"]
    p = car.kernel_parameters
    ex = sine(0.05, 5.0)
    seg = np.ascontiguousarray(ex.segments(1.0), dtype=float)[0]
    wk = _wk_sections()
    me = p[K.P_R2] * K.inertia(p, p[K.P_WSAT])
    nz, no, npm = K.X_NZ, K.X_NO, K.X_N_POINTS_MAX
    M = np.empty((nz, nz))
    rows = np.empty((no, nz))
    E = np.empty((K.X_N_LEVELS, nz, nz))
    P = np.empty((2 ** (K.X_N_LEVELS - 1) + 1, nz, nz))
    RT = np.empty((K.X_N_LEVELS, nz, npm * no))
    T = np.empty((K.X_N_TAYLOR, no, nz))
    K.x_setup(p, wk, me, 0.0, seg[6], M, rows, E, P, RT, T, np.empty((no, nz)), np.empty((nz, nz)))
    for lev in range(K.X_N_LEVELS):
        h = K.X_H_EXACT / 2**lev
        ref = expm(M * h)
        assert np.abs(E[lev] - ref).max() <= 1e-12 * np.abs(ref).max()
        for i in range(K.X_NPTS[lev]):
            r = rows @ expm(M * K.X_XS[lev, i] * h)
            got = RT[lev][:, i * no : (i + 1) * no].T
            assert np.abs(got - r).max() <= 1e-11 * np.abs(r).max()
    # a saturated state: M z against the right-hand side
    y, _ = _initial_state(car, ex, 1.0)
    rng = np.random.default_rng(1)
    y[:4] += 0.01 * rng.standard_normal(4)
    y[3] = y[1] + 3.0 * p[K.P_WSAT] / p[K.P_R]
    n = car.n_states
    y[n + 3 : n + 11] = rng.standard_normal(8)
    t = 0.123
    dy = np.empty_like(y)
    a3 = K.rhs(t, y, dy, p, seg, wk)
    arg = seg[6] * t + seg[7]
    z = np.r_[y[:4], y[n + 3 : n + 11], seg[3], seg[5] * np.sin(arg), seg[5] * seg[6] * np.cos(arg)]
    dz = M @ z
    np.testing.assert_allclose(dz[:4], dy[:4], rtol=1e-12, atol=1e-12 * np.abs(dy[:4]).max())
    np.testing.assert_allclose(dz[4:12], dy[n + 3 : n + 11], rtol=1e-12, atol=1e-9)
    assert rows[K.X_O_A3] @ z == pytest.approx(a3, rel=1e-12)
    assert dz[12] == 0.0 and dz[13] == pytest.approx(z[14])  # the road generator


@pytest.mark.parametrize("suspension", ["traditional", "cfw"])
@pytest.mark.parametrize("name", ["drop", "bump", "sine"])
def test_exact_steps_meet_a_tight_reference_on_linear_cars(suspension, name):
    # no inerter or a constant one: the car is linear and nearly every step is a matrix
    # exponential, with no truncation error, so the metric integrals meet a reference at
    # rtol 1e-12 to 1e-10, far closer than the default tolerance would (2e-11 seen)
    car = quarter_car(suspension)
    ex = INPUTS[name]
    run = simulate(car, ex, 0.5, options=_fast(), output="metrics")
    # Runge-Kutta steps only for the last < 1.25 ms of each road segment
    assert run.stats["steps"] - run.stats["exact_steps"] <= 5 * run.stats["segments"]
    ref = simulate_metrics(car, ex, 0.5, options=SimulationOptions(backend="scipy", rtol=1e-12))
    got = run.metrics()
    for k in ("rms_body_acc", "rms_tyre_grip", "rms_deflection", "rms_body_acc_wk", "vdv"):
        if ref[k] is None:
            assert got[k] is None, k
            continue
        assert got[k] == pytest.approx(ref[k], rel=1e-10), k
    # peaks: located on interpolating polynomials (and by scipy's scalar search)
    for k in ("peak_body_acc", "peak_body_acc_wk", "peak_deflection", "min_tyre_force"):
        if ref[k] is None:
            assert got[k] is None, k
            continue
        assert got[k] == pytest.approx(ref[k], rel=1e-8), k


@pytest.mark.parametrize("name", ["bump", "sine"])
def test_exact_steps_agree_with_runge_kutta_throughout(name):
    car = quarter_car("afw")
    rk = simulate_metrics(car, INPUTS[name], 2.0, options=SimulationOptions(exact_steps=False))
    run = simulate(car, INPUTS[name], 2.0, options=_fast(), output="metrics")
    assert run.stats["exact_steps"] > 0
    _assert_close(run.metrics(), rk, 1e-7)


@pytest.mark.parametrize(
    ("suspension", "kwargs", "linear_phases"),
    [
        ("afw", {}, True),
        ("afw", {"law": "momentum"}, True),
        ("afw", {"law": "slider-dynamics"}, False),
        ("afw", {"tyre_lift_off": True}, False),
        ("device", {}, False),
        ("device-afw", {}, False),
    ],
)
def test_exact_steps_only_where_the_car_is_linear(suspension, kwargs, linear_phases):
    run = simulate(
        quarter_car(suspension, **kwargs), sine(), 1.0, options=_fast(), output="metrics"
    )
    assert (run.stats["exact_steps"] > 0) == linear_phases
    # a sampled series keeps every sample: steps never jump over one
    res = simulate(quarter_car(suspension, **kwargs), sine(), 0.3, options=_fast())
    assert res.time.size == 301


@pytest.mark.parametrize("suspension", ["cfw", "afw"])
def test_exact_steps_between_sparse_samples(suspension):
    # at 200 Hz exact steps fit between the samples; the samples themselves come from
    # Runge-Kutta steps ending past them
    car = quarter_car(suspension)
    opts = SimulationOptions(sample_rate=200.0)
    a = simulate(car, bump(), 0.5, options=opts)
    assert a.stats["exact_steps"] > 0
    b = simulate(
        car, bump(), 0.5, options=SimulationOptions(backend="scipy", rtol=1e-10, sample_rate=200.0)
    )
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
    b = simulate(car, bump(), 0.2, options=REF)
    assert a.time.size == 201 and a.time[-1] == pytest.approx(0.2)
    np.testing.assert_allclose(a.states, b.states, rtol=1e-6, atol=1e-9)
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
    with pytest.raises(ParameterError, match="backend"):
        SimulationOptions(backend="julia")
    with pytest.raises(ParameterError, match="excitation"):
        simulate(quarter_car("traditional"), "drop", 1.0)


def test_exact_step_setup_is_built_once_per_system_and_never_stale():
    # the set-up is kept between runs (per thread) and rebuilt only when the linear
    # system or the road kind changes: a sequence of runs over three cars gives exactly
    # the numbers of the same runs each made with an empty cache (a new thread)
    import threading

    cars = [quarter_car("afw", changing_ratio=0.2), quarter_car("afw", changing_ratio=0.4),
            quarter_car("cfw")]  # fmt: skip
    # consecutive runs on different cars with the same road kind: only the key's car
    # part tells them apart
    order = [(c, r) for c in cars for r in (drop(), bump())] + [(c, sine()) for c in cars]

    def run(car, road):
        r = simulate(car, road, 2.0, output="metrics")
        return r.metrics(), r.stats["exact_setups"]

    seq = [run(c, r) for c, r in order]
    # drop: a new system; bump: the same system and road kind (reused); sine: new each
    assert [s for _, s in seq] == [1, 0] * len(cars) + [1] * len(cars)
    for i, (c, r) in enumerate(order):
        out = {}
        th = threading.Thread(target=lambda c=c, r=r, o=out: o.setdefault("m", run(c, r)))
        th.start()
        th.join()
        assert out["m"][1] == 1
        assert out["m"][0] == seq[i][0]
