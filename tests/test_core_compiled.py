"""Model core, compilation: the right-hand side compiled for a structure gives the
generic code's results to the last bit; the structure key follows the structure, not
the parameters; exact steps in a linear regime between far-apart samples (level
lengths) against the adaptive steps at a tight tolerance."""

import numpy as np
import pytest

from inerterlab.excitation import iso8608, sine
from inerterlab.systems import _compiled, _integrate, quarter_car, rig


def _with(rhs, run):
    """``run()`` with every integration on ``rhs``."""
    _integrate.rhs_for = lambda itab, count=True: rhs
    try:
        return run()
    finally:
        _integrate.rhs_for = _compiled.rhs_for


@pytest.mark.parametrize(
    "make, road, T",
    [
        (lambda: quarter_car("afw"), sine(0.05, 5.0), 0.6),  # kinks, exact steps
        (  # friction and a massless velocity node (the balance solved by Newton)
            lambda: rig("k | (c - (k2 | fric))", {"k": 2e4, "c": 800.0, "k2": 5e4, "fric": 40.0}),
            sine(0.01, 3.0),
            0.5,
        ),
    ],
)
def test_structure_code_equals_generic_code(make, road, T):
    sys_ = make()
    spec = _compiled.specialised(sys_.itab)
    assert spec.specialised and not _compiled.generic().specialised
    a = _with(_compiled.generic(), lambda: sys_.simulate(road, T))
    b = _with(spec, lambda: sys_.simulate(road, T))
    assert np.array_equal(a.states, b.states)
    for k in a.outputs:
        assert np.array_equal(a.outputs[k], b.outputs[k], equal_nan=True), k
    assert a.stats == b.stats


def test_structure_key_is_the_structure_not_the_parameters():
    a = quarter_car("k | c", {"k": 2e4, "c": 1e3})
    b = quarter_car("k | c", {"k": 5e4, "c": 3e3})
    c = quarter_car("k | c | b", {"k": 2e4, "c": 1e3, "b": 100.0})
    assert np.array_equal(a.itab, b.itab) and not np.array_equal(a.ftab, b.ftab)
    assert _compiled.structure_key(a.itab) == _compiled.structure_key(b.itab)
    assert _compiled.structure_key(a.itab) != _compiled.structure_key(c.itab)


class _Built:
    """What :func:`_compiled.specialised` returned in the test below (the choice of tier
    is under test there, not the compilation, which the test above checks)."""

    specialised = True


def test_tier_follows_the_setting(monkeypatch):
    sys_ = quarter_car("k | (c - b)", {"k": 9e4, "c": 5e3, "b": 200.0})
    monkeypatch.setattr(_compiled, "_specialised", {})
    monkeypatch.setattr(_compiled, "_spent", {})
    monkeypatch.setattr(_compiled, "_seen", set())
    monkeypatch.setattr(_compiled, "specialised", lambda itab: _Built())
    monkeypatch.setenv("INERTERLAB_SPECIALISE", "never")
    assert not _compiled.rhs_for(sys_.itab).specialised
    monkeypatch.setenv("INERTERLAB_SPECIALISE", "auto")
    _compiled.record(sys_.itab, _compiled.SPECIALISE_AFTER_SECONDS)  # enough work done
    assert _compiled.rhs_for(sys_.itab).specialised


@pytest.mark.parametrize("road", [sine(0.05, 5.0), iso8608("C", 20.0, seed=3)])
def test_level_steps_between_far_samples(road):
    """Samples 0.137 s apart (no step length of the table reaches them): exact steps
    of the level lengths while the flywheel is saturated, Dormand-Prince to each
    sample, within 1e-7 of each state's peak of the adaptive steps at rtol 1e-12."""
    car = quarter_car("afw")
    T = 2.0
    ts = np.arange(0.0, T, 0.137)
    fine = car.simulate(road, T, rtol=1e-12, method="adaptive")
    ref = car.simulate(road, T, rtol=1e-12, method="adaptive", times=ts)
    res = car.simulate(road, T, rtol=1e-8, times=ts)
    if road.name == "sine":
        assert res.stats["exact_steps"] > 100
    peak = np.abs(fine.states).max(axis=0)
    assert (np.abs(res.states - ref.states).max(axis=0) / peak).max() < 1e-7
