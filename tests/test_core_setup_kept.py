"""What a simulation keeps between runs: the prepared road, a system's state space,
rest states and plans of exact steps, and the sampled outputs computed when first read.
Each kept thing must give exactly what building it again gives."""

from __future__ import annotations

import copy
import dataclasses
import pickle

import numpy as np
import pytest

from inerterlab import quarter_car
from inerterlab.excitation import (
    PREPARED_MAX_BYTES,
    bump,
    drive_series,
    drop,
    iso8608,
    road_scale,
    road_series,
    road_steps,
    sine,
)
from inerterlab.systems import rig
from inerterlab.systems.core import _memo


def test_prepared_road_is_what_the_input_gives():
    for ex, T in ((iso8608("C", 20.0, seed=3), 2.0), (bump(), 1.0), (sine(), 1.0), (drop(), 1.0)):
        road = ex.prepared(T)
        segs = ex.segments(T)
        assert np.array_equal(road.segments, segs)
        assert road.segments.flags.c_contiguous and road.segments.dtype == float
        assert road.initial_road == ex.initial_road(T)
        assert road.initial_velocity == ex.initial_road_velocity(T)
        assert road.piecewise_linear == bool(np.all(segs[:, 2] == 0.0))
        assert road.jump_tolerance == 1e-12 * road_scale(segs)
        assert road.steps == tuple(road_steps(segs, ex.initial_road(T), T))


def test_prepared_road_kept_by_value_and_horizon():
    a, b = iso8608("C", 20.0, seed=3), iso8608("C", 20.0, seed=3)
    assert a is not b and a.prepared(2.0) is b.prepared(2.0)  # equal inputs share it
    assert a.prepared(2.0) is not a.prepared(3.0)
    assert iso8608("C", 20.0, seed=4).prepared(2.0).key != a.prepared(2.0).key
    # an input that cannot be hashed (arrays as fields) is built each time
    t = np.linspace(0.0, 1.0, 11)
    d = drive_series(t, 0.01 * t, 0.01 + 0 * t)
    assert d.prepared(1.0) is not d.prepared(1.0)
    assert np.array_equal(d.prepared(1.0).segments, d.segments(1.0))
    # a road too large is not kept (memory stays bounded)
    n = PREPARED_MAX_BYTES // 64 + 10
    big = road_series(np.arange(n + 1) * 1e-3, np.zeros(n + 1))
    assert big.prepared(n * 1e-3) is not big.prepared(n * 1e-3)


def _same(a, b):
    assert a.method == b.method and a.stats == b.stats and a.metrics == b.metrics
    assert a.observed == b.observed and a.road_steps == b.road_steps
    assert np.array_equal(a.time, b.time) and np.array_equal(a.states, b.states)
    assert list(a.outputs) == list(b.outputs)
    for k in a.outputs:
        assert np.array_equal(a.outputs[k], b.outputs[k], equal_nan=True), k


@pytest.mark.parametrize("method", ["exact", "adaptive"])
def test_runs_again_and_on_a_fresh_system_are_identical(method):
    net, prm = "k | (c - b)", {"k": 90e3, "c": 5e3, "b": 200.0}
    road = iso8608("C", 20.0, seed=1)
    car = quarter_car(net, prm)
    first = car.simulate(road, 1.0, method=method)
    again = car.simulate(iso8608("C", 20.0, seed=1), 1.0, method=method)  # all kept
    fresh = quarter_car(net, prm).simulate(road, 1.0, method=method)  # nothing kept
    _same(first, again)
    _same(first, fresh)


def test_outputs_computed_when_read_are_the_run_s_own():
    car = quarter_car("k | (c - b)", {"k": 90e3, "c": 5e3, "b": 200.0})
    res = car.simulate(bump(), 0.5)
    states = res.states.copy()
    res.states[:] = 0.0  # the outputs come from the run, not from the returned array
    out = dict(res.outputs)
    ref = car.simulate(bump(), 0.5, x0=car.initial_state())
    assert np.array_equal(out["body.x"], states[:, car.state_names.index("body.x")])
    assert np.allclose(out["body_acc"], ref.outputs["body_acc"], rtol=0, atol=1e-9)
    # the mapping: a dict once copied or pickled, writable like the dict it was
    assert type(pickle.loads(pickle.dumps(res.outputs))) is dict
    assert type(copy.deepcopy(res.outputs)) is dict
    res.outputs["extra"] = np.zeros(3)
    assert "extra" in res.outputs and len(res.outputs) == len(out) + 1
    del res.outputs["extra"]
    assert list(res.outputs) == list(out)


def test_state_space_is_a_fresh_copy_each_call():
    car = quarter_car("k | c", {"k": 9e4, "c": 5e3})
    A, B, C, D = car.linear_state_space()
    A0 = A.copy()
    A[:] = np.nan
    assert np.array_equal(car.linear_state_space()[0], A0)


def test_a_system_with_new_tables_does_not_read_the_old_one_s_store():
    sys1 = rig("k | (c - b)", {"k": 1e4, "c": 100.0, "b": 5.0})
    assert sys1.n_states
    ex = bump(0.01, duration=0.1, edge="ramp", edge_width=0.01)
    sys1.simulate(ex, 0.5, method="exact")
    ft = np.array(sys1.ftab, copy=True)
    ft[ft == 100.0] = 200.0  # the damping doubled, the info dict shared
    ft.setflags(write=False)
    sys2 = dataclasses.replace(sys1, ftab=ft)
    assert sys2.info is sys1.info
    assert not np.array_equal(sys2.linear_state_space()[0], sys1.linear_state_space()[0])
    assert _memo(sys2) is not _memo(sys1)
    f1 = sys1.simulate(ex, 0.5, method="exact").outputs["force"]
    f2 = sys2.simulate(ex, 0.5, method="exact").outputs["force"]
    assert not np.allclose(f1, f2)
    # and each as a system built with its own values
    f3 = rig("k | (c - b)", {"k": 1e4, "c": 200.0, "b": 5.0}).simulate(ex, 0.5, method="exact")
    assert np.allclose(f2, f3.outputs["force"], rtol=1e-12, atol=1e-12 * np.abs(f2).max())


def test_derived_systems_do_not_run_on_the_original_s_caches():
    """A system with new element rows (the Gaussian equivalent, a rebuilt equilibrium)
    simulated after its original gives what it gives when the original never ran: the
    original's regime tables, state space and ride observers are not carried over."""
    from inerterlab.systems.gaussian import equivalent_system, gaussian_gains, nonlinear_elements

    net, prm = "k | c | afw", {"k": 22e3, "c": 1.5e3}
    ex = sine(0.05, 5.0)

    def derived(car):
        return equivalent_system(car, {e: gaussian_gains(car, e, 0.0)
                                       for e, _, _ in nonlinear_elements(car)})  # fmt: skip

    car = quarter_car(net, prm)
    car.simulate(ex, 1.0)  # fills the original's caches
    after = derived(car).simulate(ex, 1.0)
    alone = derived(quarter_car(net, prm)).simulate(ex, 1.0)
    _same(after, alone)
    # and the original is not changed by its derived system's runs
    again = car.simulate(ex, 1.0)
    _same(again, quarter_car(net, prm).simulate(ex, 1.0))


def test_derived_from_an_observed_system_is_observed_on_its_own_linear_part():
    """The Gaussian equivalent of a system with observers: its linear part
    (``info["base"]``, read by the exact steps and the state space) is the equivalent's,
    and it runs as the equivalent of the plain system with the same observers added."""
    from inerterlab.systems.gaussian import equivalent_system, gaussian_gains, nonlinear_elements
    from inerterlab.systems.observers import energy, with_observers

    car = quarter_car("k | c | fric", {"k": 22e3, "c": 1.5e3, "fric": {"force": 80.0}})
    gains = {e: 0.5 * gaussian_gains(car, e, 0.05) for e, _, _ in nonlinear_elements(car)}
    plain = equivalent_system(car, gains)
    observed = equivalent_system(with_observers(car, energy(car)), gains)
    assert np.array_equal(observed.info["base"].ftab, plain.ftab)
    assert not np.array_equal(observed.info["base"].ftab, car.ftab)
    ex = sine(0.05, 5.0)
    _same(observed.simulate(ex, 1.0), with_observers(plain, energy(plain)).simulate(ex, 1.0))
