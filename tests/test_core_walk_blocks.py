"""The linear walk's observers, summed a block of steps at a time
(``_integrate._observe_steps``): their values at every sample, across blocks, against
Dormand-Prince steps with the observers in the stages; steps of many lengths; samples
closer than a step."""

from __future__ import annotations

import numpy as np
import pytest

from _probes import OBS, probes
from inerterlab.excitation import iso8608, road_displacement, road_series
from inerterlab.systems import quarter_car
from inerterlab.systems._integrate import WALK_BLOCK
from inerterlab.systems.observers import with_observers


def _car():
    return with_observers(quarter_car("k | (c - b)", {"k": 9e4, "c": 5e3, "b": 200.0}), probes())


def _road(T):
    """An ISO 8608 class C road as samples every 0.7 ms (a road that does not depend on
    the horizon a run asks of it)."""
    t = np.arange(int(T / 7e-4) + 2) * 7e-4
    x, _ = road_displacement(iso8608("C", 20.0, seed=3).segments(t[-1]), t)
    return road_series(t, x)


def _observed(res):
    names = res.system.state_names
    return res.states[:, [names.index(n) for n in OBS]]


@pytest.mark.parametrize("grid", ["1 kHz", "irregular"])
def test_observers_at_every_sample(grid):
    """The observers' values at the samples of exact steps (more than two blocks of
    steps; at 1 kHz one step length, at irregular times hundreds, some with fewer steps
    than a matrix product takes): the integrals against Dormand-Prince at rtol 1e-12 at
    every sample, to 1e-9 of their largest value; every observer at samples in
    several blocks equal to the observed values of the run that ends there to 1e-9 (its
    steps the same but for their lengths' rounding to a quantum of the horizon: 1e-11;
    a step too many or too few moves an integral by about 1e-3)."""
    sys = _car()
    T = 1.4
    road = _road(T)
    if grid == "1 kHz":
        times = np.arange(1401) / 1000.0
    else:
        times = np.r_[np.sort(np.random.default_rng(5).uniform(0.0, T, 900)), T]
    x0 = np.zeros(sys.n_states)
    ex = sys.simulate(road, T, x0=x0, times=times, method="exact")
    assert ex.stats["exact_steps"] > 2 * WALK_BLOCK
    if grid == "irregular":
        assert ex.stats["distinct_step_sizes"] > 100
    a = _observed(ex)
    ref = sys.simulate(road, T, x0=x0, times=times, method="adaptive", rtol=1e-12)
    b = _observed(ref)[:, :3]  # the integrals (a peak's samples there lag its location)
    assert np.all(np.abs(a[:, :3] - b).max(axis=0) <= 1e-9 * np.abs(b).max(axis=0))
    n = times.size
    for k in (40, n // 3, n // 3 + 7, (3 * n) // 4, n - 1):
        end = sys.simulate(road, times[k], x0=x0, times=times[: k + 1], method="exact")
        assert a[k].tolist() == pytest.approx([end.observed[n] for n in OBS], rel=1e-9, abs=0)


def test_samples_closer_than_a_step():
    """Hundreds of samples closer together than the shortest step (more than a block
    holds between two steps): each holds the state and the observers at that instant,
    and the run's observed values are those of the same run without them (to 1e-12:
    the next step starts from the last of them, 1.4e-13 s later, so the road's value
    there moves by its rate times that)."""
    sys = _car()
    T = 1.0
    road = _road(T)
    x0 = np.zeros(sys.n_states)
    base = np.arange(1001) / 1000.0
    extra = 0.5 + np.arange(1, WALK_BLOCK + 200) * 2e-16
    times = np.union1d(base, extra)
    plain = sys.simulate(road, T, x0=x0, times=base, method="exact")
    dense = sys.simulate(road, T, x0=x0, times=times, method="exact")
    assert dense.stats["exact_steps"] == plain.stats["exact_steps"]
    k = int(np.searchsorted(times, 0.5))
    cluster = dense.states[k : k + extra.size + 1]
    assert np.array_equal(cluster, np.broadcast_to(cluster[0], cluster.shape))
    assert np.array_equal(cluster[0], plain.states[500])
    assert dense.observed == pytest.approx(plain.observed, rel=1e-12, abs=0)
