"""The harmonic balance's route to a model-core system's right-hand side and outputs
(:func:`inerterlab.frequency.quarter_car.buffered_rhs`, ``buffered_outputs``, and the
same two compiled for the structure, ``first_order_rhs`` and ``first_order_outputs`` of
its module in :mod:`inerterlab.systems._compiled`): the work array in the caller's
buffer instead of an allocation per call. Oracle: the core's own
:func:`inerterlab.systems._kernel.rhs` and ``outputs`` on the same arguments, which
allocate their work array; the values must agree to the last bit, with the buffer long
enough and with one too short (then the buffered functions fall back to the core's)."""

from __future__ import annotations

import numpy as np
import pytest

from inerterlab.frequency.quarter_car import (
    buffer_size,
    buffered_outputs,
    buffered_rhs,
    from_core_system,
)
from inerterlab.systems import _compiled, _kernel
from inerterlab.systems import quarter_car as core_quarter_car
from inerterlab.systems.observers import ride, with_observers


def _systems():
    out = [core_quarter_car(kind, sprung_mass=370.0) for kind in ("afw", "traditional", "device")]
    base = core_quarter_car("afw", sprung_mass=370.0)
    out.append(with_observers(base, ride(base)))  # observers: derivatives past the motion's
    return out


@pytest.mark.parametrize("sys", _systems(), ids=lambda s: s.description)
def test_buffered_evaluation_equals_the_cores_bit_for_bit(sys):
    _compare(sys, buffered_rhs, buffered_outputs)


def test_the_structures_own_first_order_form_equals_the_cores_bit_for_bit():
    # one structure (compiling one costs seconds): the afw car the benchmarks run
    sys = core_quarter_car("afw", sprung_mass=370.0)
    _compiled.specialised(sys.itab)
    mod = _compiled._structure_module(sys.itab, _compiled.structure_key(sys.itab))
    _compare(sys, mod.first_order_rhs, mod.first_order_outputs)


def _compare(sys, buffered_rhs, buffered_outputs):
    itab, ftab = (np.array(a) for a in sys.tables)
    n = sys.n_states
    size = buffer_size(itab)
    assert size == n + _kernel.work_size(itab)
    rng = np.random.default_rng(7)
    scales = np.asarray(sys.state_scales, dtype=float)
    for trial in range(40):
        x = np.zeros(size)
        x[:n] = np.asarray(sys.initial_state(), dtype=float) + scales * rng.normal(0, 2, n)
        road = np.array([0.05 * rng.normal(), rng.normal(), 30.0 * rng.normal(), 6.0 + trial])
        t = 0.01 * trial
        want = np.zeros(size)
        ok0 = _kernel.rhs(t, x, road, itab, ftab, want)
        for length in (size, size + 5, n):  # the buffer, a longer one, one too short
            got = np.full(length, np.nan)
            ok = buffered_rhs(t, x, road, itab, ftab, got)
            assert ok == ok0
            np.testing.assert_array_equal(got[:n], want[:n])
        no = 3 * int(itab[_kernel.I_NN]) + int(itab[_kernel.I_NE])
        want_o = np.zeros(no)
        ok0 = _kernel.outputs(t, x, road, itab, ftab, want_o)
        for length in (size, no):
            got = np.full(length, np.nan)
            assert buffered_outputs(t, x, road, itab, ftab, got) == ok0
            np.testing.assert_array_equal(got[:no], want_o)


def test_a_core_systems_first_order_form_takes_the_tier_of_the_time_integration(monkeypatch):
    sys = core_quarter_car("afw", sprung_mass=370.0)
    monkeypatch.setenv("INERTERLAB_SPECIALISE", "never")
    monkeypatch.setattr(_compiled, "_specialised", {})
    fo = from_core_system(sys)
    assert fo.rhs is buffered_rhs and fo.compiled_outputs is buffered_outputs
    assert fo.work_size == buffer_size(fo.int_table)
    monkeypatch.setenv("INERTERLAB_SPECIALISE", "always")
    fo = from_core_system(sys)
    mod = _compiled._structure_module(sys.itab, _compiled.structure_key(sys.itab))
    assert fo.rhs is mod.first_order_rhs and fo.compiled_outputs is mod.first_order_outputs


def test_a_response_on_the_generic_code_counts_towards_the_structures_own(monkeypatch):
    """The tier policy of the time integration, for the harmonic balance too: a response
    computed on the generic code adds its CPU time to the structure's account
    (``_compiled.record``; not a call that compiled a kernel), and once the account
    passes ``SPECIALISE_AFTER_SECONDS`` the next response takes the structure's own
    code, with the same numbers to the last bit. Before, only integrations counted: a
    user computing frequency responses alone stayed on the generic code (3.5-3.9 s
    for the benchmark's 4000 solves on the afw car, against 2.3-2.4 s)."""
    from inerterlab.frequency import chapter7_system, frequency_response

    sys = core_quarter_car("afw", sprung_mass=370.0)
    freqs = np.linspace(1.0, 6.0, 25)
    monkeypatch.setattr(_compiled, "_specialised", {})
    monkeypatch.setattr(_compiled, "_spent", {})
    monkeypatch.setattr(_compiled, "_seen", set())
    monkeypatch.setenv("INERTERLAB_SPECIALISE", "never")  # the generic code, still counted
    key = sys.itab.tobytes()
    generic = frequency_response(sys, "sihb", freq_hz=freqs, amplitude=0.01)  # may compile
    spent = _compiled._spent.get(key, 0.0)
    again = frequency_response(sys, "sihb", freq_hz=freqs, amplitude=0.01)
    assert _compiled._spent[key] > spent  # a warm call on the generic code counted
    assert from_core_system(sys).rhs is buffered_rhs  # still under the threshold
    # a built-in first-order form of another kind counts nowhere
    before = dict(_compiled._spent)
    frequency_response(chapter7_system(0.01), "sihb", freq_hz=[1.0, 1.1], harmonics=5)
    assert _compiled._spent == before
    # past the threshold: the structure's own code, the same numbers
    monkeypatch.setattr(_compiled, "SPECIALISE_AFTER_SECONDS", _compiled._spent[key])
    monkeypatch.setenv("INERTERLAB_SPECIALISE", "auto")
    fo = from_core_system(sys)
    assert fo.rhs is not buffered_rhs and fo.on_generic is None
    own = frequency_response(sys, "sihb", freq_hz=freqs, amplitude=0.01)
    for r in (generic, own):
        np.testing.assert_array_equal(r.coefficients, again.coefficients)
        np.testing.assert_array_equal(r.max_multiplier.data, again.max_multiplier.data)
        for name in again.outputs:
            np.testing.assert_array_equal(r.outputs[name].data, again.outputs[name].data)


def test_the_work_estimate_of_a_first_order_system_follows_its_engine():
    """The bound checked before a frequency response starts: for a first-order system,
    the Newton system of its unknowns (the states less the velocities of positions) and
    the Hill matrix of its states on the stability harmonics, not the states on every
    harmonic. The afw quarter car's 3901 points scanned both ways (about 3 s) were
    refused as 0.29 h of work; a request beyond the limit is still refused, naming the
    setting."""
    from inerterlab.errors import ParameterError
    from inerterlab.frequency import frequency_response
    from inerterlab.frequency.response import estimate_operations
    from inerterlab.resources import WORK_LIMIT

    base = estimate_operations(3901, "sihb", 13, direction="both", n_dof=4)
    tight = estimate_operations(3901, "sihb", 13, direction="both", n_dof=2, hill=(4, 1, 256))
    assert base > WORK_LIMIT > 10 * tight
    # the Hill part: the states on harmonics 0..1 (12 x 12) and 5 x 256 evaluations
    per = estimate_operations(1, "sihb", 13, direction="up", n_dof=2, hill=(4, 1, 256))
    newton = estimate_operations(1, "sihb", 13, direction="up", n_dof=2, stability=False)
    assert per - newton == 10 * 12**3 + 5 * 256 * 400
    car = core_quarter_car("afw", sprung_mass=370.0)
    with pytest.raises(ParameterError, match="df"):
        frequency_response(car, "sihb", fmin=0.5, fmax=20.0, df=1e-5, amplitude=0.01)
    with pytest.raises(ParameterError, match="harmonics"):
        frequency_response(car, "sihb", freq_hz=[1.0, 2.0], harmonics=2000, amplitude=0.01)


def test_patterned_evaluation_keeps_its_road_vector_in_the_buffer():
    """A car of several roads driven by a pattern (gain, phase, delay per road): the
    road vector of every wheel is kept in the engine's buffer past the work array. The
    evaluation with the buffer, with a longer one and with one too short (then it
    allocates the road vector) equals the core's own evaluation on the road vector
    spread by hand, to the last bit."""
    import math

    from inerterlab.frequency.quarter_car import (
        _pattern_tables,
        pattern_size,
        patterned_outputs,
        patterned_rhs,
    )
    from inerterlab.systems.vehicle import vehicle
    from inerterlab.vehicles import example_vehicle_path, load_vehicle

    sys = vehicle(load_vehicle(example_vehicle_path()), lift_off=False)
    m = int(sys.info["roads"])
    P = np.column_stack([np.linspace(1.0, 0.5, m), np.linspace(0.0, 2.0, m), np.r_[0.0, 0.1, 0.0, 0.1][:m]])
    itab, ftab = _pattern_tables(sys, P)
    fo = from_core_system(sys, pattern=P)
    n = sys.n_states
    free = pattern_size(itab) - 1
    size = buffer_size(itab) + pattern_size(itab)
    assert fo.work_size == size and free == _kernel.road_layout_of(itab)[1]
    rng = np.random.default_rng(11)
    scales = np.asarray(sys.state_scales, dtype=float)
    no = 3 * int(itab[_kernel.I_NN]) + int(itab[_kernel.I_NE])
    for trial in range(20):
        x = np.zeros(size)
        x[:n] = np.asarray(sys.initial_state(), dtype=float) + scales * rng.normal(0, 1, n)
        a, w, tau = 0.02, 2 * math.pi * (1.0 + trial), rng.uniform(0, 2 * math.pi)
        road = np.array([a * math.sin(tau), a * w * math.cos(tau), -a * w * w * math.sin(tau), w])
        r = np.zeros(free + 1)  # the pattern by hand: A g sin(tau + phase - w delay)
        for k in range(m):
            g, ph = P[k, 0], tau + P[k, 1] - w * P[k, 2]
            r[3 * k : 3 * k + 3] = g * a * np.array([math.sin(ph), w * math.cos(ph), -w * w * math.sin(ph)])
        r[free] = w
        want = np.zeros(size)
        ok0 = _kernel.rhs(0.0, x, r, itab, ftab, want)
        want_o = np.zeros(no)
        oko = _kernel.outputs(0.0, x, r, itab, ftab, want_o)
        for length in (size, size + 3, n):
            got = np.full(length, np.nan)
            assert patterned_rhs(0.0, x, road, itab, ftab, got) == ok0
            np.testing.assert_allclose(got[:n], want[:n], rtol=1e-12, atol=1e-12 * np.abs(want[:n]).max())
            if length == size:
                keep = got[:n].copy()
            else:
                np.testing.assert_array_equal(got[:n], keep)
        for length in (max(size, no), no):
            got = np.full(length, np.nan)
            assert patterned_outputs(0.0, x, road, itab, ftab, got) == oko
            np.testing.assert_allclose(got[:no], want_o, rtol=1e-12, atol=1e-12 * np.abs(want_o).max())
