"""Model core, exact steps of linear systems on piecewise-linear roads: against
scipy.signal.lsim (an independent exact discretisation), against the adaptive steps,
and the compiled Wk observer against the metrics module's filter."""

import numpy as np
import pytest
from scipy import signal

from inerterlab.excitation import iso8608, road_displacement, road_series
from inerterlab.metrics import weighted_acceleration
from inerterlab.systems import quarter_car
from inerterlab.systems._integrate import outputs_many
from inerterlab.systems.core import EXACT_MAX_STEP_SIZES

CAR = ("k | (c - b)", {"k": 90e3, "c": 5e3, "b": 200.0})


def _lsim_states(car, road, T, rate, x0):
    """States at the samples by scipy's first-order hold on the core's state space, the
    road displacement the only input (z = x - B_v X1), exact on a road linear between
    the samples. From the core's initial state x0."""
    A, B, _, _ = car.linear_state_space()
    assert not B[:, 2].any()
    t = np.arange(int(round(T * rate)) + 1) / rate
    x1, _ = road_displacement(road.segments(T), t)
    ss = signal.StateSpace(A, (A @ B[:, 1] + B[:, 0])[:, None], np.eye(len(A)), B[:, 1:2])
    return signal.lsim(ss, x1, t, X0=x0 - B[:, 1] * x1[0], interp=True)[1]


def test_exact_steps_equal_lsim_on_an_iso_road():
    car = quarter_car(*CAR)
    road, T = iso8608("C", 20.0, seed=3), 2.0
    res = car.simulate(road, T)
    assert res.method == "exact"
    ref = _lsim_states(car, road, T, 1000.0, res.states[0])
    err = np.abs(res.states - ref).max(axis=0) / np.ptp(ref, axis=0)
    assert err.max() < 1e-10
    ad = car.simulate(road, T, method="adaptive", rtol=1e-11).states
    assert (np.abs(res.states - ad).max(axis=0) / np.ptp(ref, axis=0)).max() < 1e-8


def test_linear_outputs_equal_the_right_hand_side_outputs():
    """The outputs of exact steps (C x + D u) against the compiled outputs at the same
    states, NaN pattern included (the massless node of k | (k1 - c))."""
    car = quarter_car("k | (k1 - c)", {"k": 80e3, "k1": 40e3, "c": 4e3})
    road, T = iso8608("B", 15.0, seed=2), 1.0
    res = car.simulate(road, T)
    assert res.method == "exact"
    segs = np.ascontiguousarray(road.segments(T))
    O = np.empty((res.time.size, len(car.output_names)))
    outputs_many(res.time, res.states, segs, car.itab, car.ftab, O)
    for j, name in enumerate(car.output_names):
        a, b = res.outputs[name], O[:, j]
        assert np.array_equal(np.isnan(a), np.isnan(b)), name
        ok = ~np.isnan(b)
        scale = max(np.abs(b[ok]).max(initial=0.0), 1e-300)
        assert np.abs(a[ok] - b[ok]).max(initial=0.0) <= 1e-11 * scale, name


def test_auto_falls_back_to_adaptive_steps_on_incommensurate_grids():
    """A road sampled at irregular times: every step length differs, exact steps would
    pay one matrix exponential each; ``auto`` integrates adaptively, ``exact`` agrees."""
    rng = np.random.default_rng(0)
    t = np.cumsum(rng.uniform(0.5e-3, 1.5e-3, 600))
    road = road_series(np.r_[0.0, t], np.r_[0.0, 0.01 * rng.standard_normal(600)])
    car = quarter_car(*CAR)
    auto = car.simulate(road, 0.5)
    assert auto.method == "adaptive"
    exact = car.simulate(road, 0.5, method="exact")
    assert exact.stats["distinct_step_sizes"] > EXACT_MAX_STEP_SIZES
    err = np.abs(auto.states - exact.states).max(axis=0) / np.ptp(exact.states, axis=0)
    assert err.max() < 1e-6


@pytest.mark.parametrize("rate", [500.0, 1000.0, 4096.0])
def test_compiled_wk_filter_equals_scipy_lsim(rate):
    from scipy.signal import StateSpace, lsim

    from inerterlab.metrics import wk_state_space

    t = np.arange(int(3 * rate) + 1) / rate
    a = np.sin(2 * np.pi * 3.0 * t) + 0.3 * np.random.default_rng(1).standard_normal(t.size)
    A, B, C, D = wk_state_space()
    _, ref, _ = lsim(StateSpace(A, B[:, None], C[None, :], np.array([[D]])), a, t, interp=True)
    assert np.abs(weighted_acceleration(t, a) - ref).max() <= 1e-12 * np.abs(ref).max()


def test_point_rows_equal_the_exponential_at_every_point():
    """The observers' point rows of a step as long as m panels (its start, the nodes of
    its one Gauss-Legendre rule from the step's Taylor rows, its end from the
    exponential) against S exp(M theta h) at each point, to 1e-12 of the rows' size; the
    points increase from 0 to 1, the nodes and weights are a Gauss-Legendre rule on
    [0, 1] of _gauss_count(m) nodes (5, 9, 15 for m = 1, 3, 8): exact for the
    polynomials of degree 2n - 1."""
    from scipy.linalg import expm

    from inerterlab.systems.core import _gauss_count, _nodes, _points, _step_tables

    rng = np.random.default_rng(3)
    n = 6
    M = rng.normal(size=(n, n)) * 40.0 - 60.0 * np.eye(n)
    S = rng.normal(size=(3, n))
    hs = np.array([1e-3, 4e-3, 1e-2])
    assert [_gauss_count(m) for m in (1, 3, 4, 8, 16)] == [5, 9, 10, 15, 24]
    for m in (1, 3, 8):
        th = _points(m)
        assert th[0] == 0.0 and th[-1] == 1.0 and np.all(np.diff(th) > 0)
        w, x = _nodes(m)
        nq = _gauss_count(m)
        assert w.size == x.size == nq == th.size - 2 and abs(w.sum() - 1.0) < 1e-14
        assert abs(w @ x ** (2 * nq - 1) - 1.0 / (2 * nq)) < 1e-14
        R = _step_tables(M, S, hs, m, expm(hs[:, None, None] * M[None]))[2]
        for p, t in enumerate(th):
            for j, h in enumerate(hs):
                ref = S @ expm(M * t * h)
                assert np.abs(R[p, j] - ref).max() <= 1e-12 * np.abs(ref).max()
