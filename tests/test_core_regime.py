"""Model core: exact steps while every nonlinear element sits in its linear regime.

The adaptive flywheel above its saturation speed is an ideal inerter of r^2 I_max
(closed form from its inertia law); the integrator then takes matrix-exponential steps
of the system with the road as the output of a linear generator. Checked against an
independent reference: scipy's DOP853 at rtol 1e-12 on the core's right-hand side."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from inerterlab.elements import AdaptiveFlywheelInerter
from inerterlab.elements.adaptive_flywheel import flywheel_inertance, flywheel_switch
from inerterlab.excitation import bump, drop, iso8608, sine
from inerterlab.systems import QUARTER_CAR_PRESETS, quarter_car
from inerterlab.systems._integrate import road_at


@pytest.mark.parametrize("law", ["thesis", "momentum"])
def test_saturated_flywheel_is_an_inerter(law):
    el = AdaptiveFlywheelInerter(law=law)
    lin, arg, thr = el.linear_regime()
    row = el.row()
    assert arg == "velocity"
    # the switching function changes sign at the threshold
    assert abs(flywheel_switch(row, 0, thr)) <= 1e-12 * row[8]
    for v in (1.0001 * thr, 1.5 * thr, -3.0 * thr):
        me, g = flywheel_inertance(row, 0, v, 0.0, 0.0)
        assert g == 0.0
        assert me == pytest.approx(lin.inertance, rel=1e-14)
    # below it the inertance is smaller (the sliders are not yet on their stops)
    assert flywheel_inertance(row, 0, 0.5 * thr, 0.0, 0.0)[0] < lin.inertance
    assert AdaptiveFlywheelInerter(law="slider-dynamics").linear_regime() is None


def _reference(sys, ex, T, ts, x0):
    """scipy DOP853 at rtol 1e-12 on the core's right-hand side, segment by segment
    (roads continuous in displacement), sampled by its dense output."""
    segs = np.ascontiguousarray(ex.segments(T), float)
    road = np.empty(3)
    dx = np.empty(sys.n_states)
    out = np.empty((ts.size, sys.n_states))
    atol = 1e-14 * np.maximum(sys.state_scales, 1e-12)
    y = np.array(x0, float)
    for i in range(len(segs)):
        t0, t1 = segs[i, 0], min(segs[i, 1], T)
        if t0 >= T:
            break
        if t1 <= t0:
            continue

        def f(t, x, i=i):
            road_at(segs, i, t, road)
            sys.rhs(t, x, road, sys.itab, sys.ftab, dx)
            return dx.copy()

        sol = solve_ivp(f, (t0, t1), y, method="DOP853", rtol=1e-12, atol=atol,
                        dense_output=True)  # fmt: skip
        sel = (ts >= t0) & (ts <= t1)
        if sel.any():
            out[sel] = sol.sol(np.clip(ts[sel], t0, t1)).T
        y = sol.y[:, -1]
    return out


def _error(res, ref):
    return float((np.abs(res - ref).max(axis=0) / np.abs(ref).max(axis=0)).max())


@pytest.mark.parametrize("name", list(QUARTER_CAR_PRESETS))
def test_presets_on_a_sine_against_scipy(name):
    """1e-7 of each state's peak at rtol 1e-8; the two device presets (friction, no
    linear regime, Dormand-Prince throughout) at rtol 1e-9: at 1e-8 their wheel
    velocity is 2.4e-7 off (measured; 2.8e-8 at 1e-9, so the error follows rtol)."""
    car = quarter_car(name)
    ex, T = sine(0.05, 5.0), 2.0
    # given sample times: no ride observers, whose filter and sums take adaptive steps
    res = car.simulate(ex, T, rtol=1e-9 if name.startswith("device") else 1e-8,
                       times=np.arange(2001) / 1000.0)  # fmt: skip
    ref = _reference(car, ex, T, res.time, res.states[0])
    assert _error(res.states, ref) <= 1e-7, name
    if name in ("traditional", "cfw", "afw"):  # linear, or nonlinear with a linear regime
        assert res.stats["exact_steps"] > 0.5 * res.time.size
    else:  # friction: no linear regime, Dormand-Prince throughout
        assert res.stats["exact_steps"] == 0


@pytest.mark.slow
def test_afw_on_a_random_road_against_scipy():
    """A rough road driven slowly (segments of 20 ms, the flywheel in and out of
    saturation). At rtol 1e-9: at 1e-8 the Dormand-Prince steps alone (``adaptive``) are
    1.5e-7 of a peak off here, the runs with exact steps 1e-7 to 2e-7 (measured), so a
    bound of 1e-7 there would test the step sequence, not the method; the error follows
    rtol (2e-8 at 1e-9, 3e-9 at 1e-10, either way)."""
    car = quarter_car("afw")
    ex, T = iso8608("E", 1.0, seed=1), 0.5
    # given sample times: no ride observers, whose filter and sums take adaptive steps
    res = car.simulate(ex, T, rtol=1e-9, times=np.arange(501) / 1000.0)
    assert res.stats["exact_steps"] > 0 and res.stats["events"] > 0
    ref = _reference(car, ex, T, res.time, res.states[0])
    assert _error(res.states, ref) <= 1e-7


def test_exact_steps_across_the_edges_of_a_sampled_road():
    """A road sampled every millisecond (ISO 8608 at 20 m/s): the exact steps in the
    regime run across its edges, each ending on the next edge and reading that
    segment's input. Against the scipy reference (segment by segment at rtol 1e-12)
    as the adaptive steps alone are; with the ride observers, the metrics agree with the
    adaptive run's to the step control's level; and fewer Dormand-Prince steps."""
    car = quarter_car("afw")
    ex, T = iso8608("C", 20.0, seed=1), 0.5
    segs = ex.prepared(T).segments
    assert np.count_nonzero(segs[:, 0] < T) >= 500  # 1 ms segments
    ts = np.arange(501) / 1000.0
    res = car.simulate(ex, T, rtol=1e-9, times=ts)
    ada = car.simulate(ex, T, rtol=1e-9, times=ts, method="adaptive")
    assert res.stats["exact_steps"] > 100 and ada.stats["exact_steps"] == 0
    ref = _reference(car, ex, T, res.time, res.states[0])
    assert _error(res.states, ref) <= 1e-7
    assert _error(ada.states, ref) <= 1e-7
    a = car.simulate(ex, T)  # the ride observers, metrics
    b = car.simulate(ex, T, method="adaptive")
    assert a.stats["exact_steps"] > 100 and b.stats["exact_steps"] == 0
    assert a.stats["steps"] - a.stats["exact_steps"] < 0.8 * b.stats["steps"]
    for k, v in b.metrics.items():
        if isinstance(v, float) and v != 0.0:
            assert a.metrics[k] == pytest.approx(v, rel=1e-6), k


def test_exact_and_adaptive_steps_agree_at_tight_tolerance():
    """The regime steps change only the step sequence: at rtol 1e-11 both ways agree to
    round-off level (sample times given: no ride observers, which take adaptive steps)."""
    car = quarter_car("afw")
    ex, T = sine(0.05, 5.0), 3.0
    ts = np.arange(3001) / 1000.0
    a = car.simulate(ex, T, rtol=1e-11, times=ts)
    b = car.simulate(ex, T, rtol=1e-11, method="adaptive", times=ts)
    assert a.stats["exact_steps"] > 0 and b.stats["exact_steps"] == 0
    assert _error(a.states, b.states) <= 1e-9


@pytest.mark.parametrize("name", ["afw", "cfw"])
def test_outputs_in_the_regime_equal_the_evaluator(name):
    """Samples where the flywheel is saturated (every sample of a linear car) take their
    outputs from the regime's C x + D u: equal to the evaluator's to round-off, NaN
    where it leaves them undefined."""
    import math

    from inerterlab.systems._integrate import outputs_many

    car = quarter_car(name)
    ex, T = sine(0.05, 5.0), 1.0
    res = car.simulate(ex, T)
    segs = np.ascontiguousarray(ex.segments(T), float)
    O = np.empty((res.time.size, len(car.output_names)))
    outputs_many(res.time, res.states, segs, car.itab, car.ftab, O)
    for j, nm in enumerate(car.output_names):
        got, want = res.outputs[nm], O[:, j]
        assert np.array_equal(np.isnan(got), np.isnan(want)), nm
        ok = ~np.isnan(want)
        scale = max(float(np.abs(want[ok]).max()) if ok.any() else 0.0, math.ulp(1.0))
        assert np.abs(got[ok] - want[ok]).max() <= 1e-12 * scale, nm


def test_saturation_event_against_the_closed_form():
    """A body of mass m on an adaptive flywheel over a base moving as A sin(w t), the
    flywheel saturated at the start: while saturated the relative velocity is
    v_r(t) = v_r0 + m / (m + b_sat) A w (cos w t - 1) (a constant inertance), so it
    reaches the saturation threshold at t* = arccos(1 + (v_thr - v_r0)(m + b_sat) /
    (m A w)) / w. Before t* the core (exact steps) follows the closed form; after it,
    an rtol-1e-12 DOP853 run of the flywheel's own law started at t* from the closed
    form: so the switch was located at t*."""
    from inerterlab.systems import base_excited

    m = 100.0
    sys = base_excited(m, "afw")
    lin, _, v_thr = sys.elements[0].linear_regime()
    b = lin.inertance
    f = 2.0
    w = 2.0 * np.pi * f
    vr0 = 3.0 * v_thr
    A = 3.0 * v_thr * (m + b) / (m * w)  # the swing of v_r reaches below v_thr
    c = m / (m + b)
    t_star = np.arccos(1.0 + (v_thr - vr0) / (c * A * w)) / w

    def closed(t):  # body displacement and velocity while saturated (body.x(0) = 0)
        vb = A * w * np.cos(w * t) - vr0 - c * A * w * (np.cos(w * t) - 1.0)
        xb = (1.0 - c) * A * np.sin(w * t) + (c * A * w - vr0) * t
        return xb, vb

    i_x, i_v = sys.state_names.index("body.x"), sys.state_names.index("body.v")
    x0 = np.zeros(sys.n_states)
    x0[i_v] = A * w - vr0
    T = t_star + 0.01
    res = sys.simulate(sine(A, f), T, rtol=1e-10, sample_rate=10_000.0, x0=x0)
    assert res.stats["exact_steps"] > 0 and res.stats["events"] >= 1
    before = res.time < t_star
    xb, vb = closed(res.time[before])
    assert np.abs(res.states[before, i_v] - vb).max() <= 1e-9 * np.abs(vb).max()
    assert np.abs(res.states[before, i_x] - xb).max() <= 1e-9 * np.abs(xb).max()
    # after the switch: the flywheel's law from the closed-form state at t*
    segs = np.ascontiguousarray(sine(A, f).segments(T), float)
    road = np.empty(3)
    dx = np.empty(sys.n_states)

    def rhs(t, x):
        road_at(segs, 0, t, road)
        sys.rhs(t, x, road, sys.itab, sys.ftab, dx)
        return dx.copy()

    y_star = np.zeros(sys.n_states)
    y_star[i_x], y_star[i_v] = closed(t_star)
    after = res.time > t_star
    ref = solve_ivp(rhs, (t_star, T), y_star, method="DOP853", rtol=1e-12, atol=1e-15,
                    t_eval=res.time[after]).y  # fmt: skip
    scale = np.abs(res.states[:, i_v]).max()
    assert np.abs(res.states[after, i_v] - ref[i_v]).max() <= 1e-8 * scale


def test_regime_tables_kept_per_road_and_bounded():
    """The tables of the regime steps are built once per (road, horizon, samples) of a
    system and kept for the last few: a second run on the same road reuses them and
    gives the same result to the last bit; other roads push the oldest out."""
    from inerterlab.systems import core

    car = quarter_car("afw")
    ex, T = sine(0.05, 5.0), 0.5
    a = car.simulate(ex, T)
    ride = car.info["ride_system"]
    kept = ride.info["regime_tables"]
    assert len(kept) == 1
    first = next(iter(kept.values()))
    b = car.simulate(ex, T)
    assert len(kept) == 1 and next(iter(kept.values())) is first
    assert a.stats["exact_steps"] > 0
    assert np.array_equal(a.states, b.states)
    assert a.metrics == b.metrics
    for k in range(core.REGIME_TABLES_KEPT + 2):
        car.simulate(sine(0.05, 5.0 + 0.1 * (k + 1)), T)
    assert len(kept) == core.REGIME_TABLES_KEPT
    assert all(v is not first for v in kept.values())


@pytest.mark.parametrize(
    "ex",
    [drop(), bump(), bump(shape="1-cos"), bump(edge="half-cosine", edge_width=0.005)],
    ids=["drop", "bump", "1-cos bump", "half-cosine edges"],
)
def test_no_regime_steps_where_the_car_decays_freely(ex):
    """A road that stops driving the car early in the horizon (its last segment a
    constant rate from before half the horizon): ``auto`` takes no exact steps in the
    flywheel's regime, so it is the adaptive run to the last bit, and builds no tables;
    the linear car still takes exact steps throughout."""
    car = quarter_car("afw")
    T = 2.0
    a = car.simulate(ex, T)
    b = car.simulate(ex, T, method="adaptive")
    assert a.stats["exact_steps"] == 0
    assert np.array_equal(a.states, b.states) and a.metrics == b.metrics
    ride = car.info["ride_system"].info
    assert not ride.get("regime_tables") and "regime" not in ride  # nothing built for it
    lin = quarter_car("cfw").simulate(ex, T)
    assert lin.stats["exact_steps"] > 0


def test_regime_steps_where_the_road_drives_the_car():
    """The rule of :func:`core._regime_pays` on the road's last segment: a sine, or a
    constant rate that starts past half the horizon (a bump late in the horizon, a
    sampled road), takes exact steps; a bump at its start does not."""
    from inerterlab.systems.core import REGIME_FREE_DECAY, _regime_pays

    car = quarter_car("afw")
    T = 1.0
    late = bump(start=0.6 * T)
    assert car.simulate(late, T).stats["exact_steps"] > 0
    assert car.simulate(bump(start=0.1 * T), T).stats["exact_steps"] == 0
    ride = car.info["ride_system"]
    for ex, want in ((sine(), True), (iso8608("E", 1.0, seed=1), True), (drop(), False)):
        segs = np.ascontiguousarray(ex.prepared(T).segments, float)
        assert _regime_pays(ride, segs, T) is want
    # the boundary: a last edge just past the fraction drives, at it does not
    for t_edge, want in (
        (REGIME_FREE_DECAY * T, False),
        (np.nextafter(REGIME_FREE_DECAY * T, 1.0), True),
    ):
        segs = np.array([[0.0, t_edge, 0.0, 0.0, 0.1], [t_edge, np.inf, 0.0, 0.0, 0.0]])
        assert _regime_pays(ride, segs, T) is want
