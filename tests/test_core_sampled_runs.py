"""Model core: a sampled road (linear between samples) integrated as one run of
adaptive steps that end on every sample, against exact matrix-exponential steps."""

import numpy as np

from inerterlab.excitation import road_series
from inerterlab.systems import quarter_car

CAR = ("k | c", {"k": 20000.0, "c": 1500.0})


def _road(n=500, dt=2e-3, seed=3):
    rng = np.random.default_rng(seed)
    t = dt * np.arange(n + 1)
    x = np.r_[0.0, np.cumsum(2e-4 * rng.standard_normal(n))]
    return road_series(t, x), t


def test_sampled_road_run_equals_exact_steps_with_ride_observers():
    """The ride observers leave no exact steps in linear regimes, so the adaptive path
    integrates the samples as one run (first stage renewed at each kink); it must agree
    with the exact steps, an independent method, to far below its tolerance's scale."""
    road, t = _road()
    car = quarter_car(*CAR)
    T = float(t[-1])
    ada = car.simulate(road, T, method="adaptive", rtol=1e-11)
    ex = car.simulate(road, T, method="exact")
    assert ada.method == "adaptive" and ex.method == "exact"
    err = np.abs(ada.states - ex.states).max(axis=0) / np.ptp(ex.states, axis=0)
    assert err.max() < 1e-8
    for k, v in ex.metrics.items():
        if isinstance(v, float) and v != 0.0:
            assert abs(ada.metrics[k] - v) <= 1e-7 * abs(v), k
    # the road's kinks are break points: no step crosses a sample
    assert ada.stats["steps"] >= t.size - 1
