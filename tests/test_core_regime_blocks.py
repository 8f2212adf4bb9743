"""The observers over a nonlinear system's exact regime steps, summed a block of steps at
a time (``_integrate._observe_steps`` from ``_advance``): their values at every sample,
across blocks (more steps in one regime phase than a block holds), against
Dormand-Prince steps throughout, and against the run that ends at the sample."""

from __future__ import annotations

import numpy as np
import pytest

from _probes import OBS, probes
from inerterlab.excitation import sine
from inerterlab.systems import quarter_car
from inerterlab.systems._integrate import X_BLOCK
from inerterlab.systems.observers import with_observers


def _car():
    return with_observers(quarter_car("afw", sprung_mass=370.0), probes())


def _observed(res):
    names = res.system.state_names
    return res.states[:, [names.index(n) for n in OBS]]


@pytest.mark.parametrize("grid", ["1 kHz", "irregular"])
def test_observers_at_every_sample_across_blocks(grid):
    """At 1 kHz every exact step ends on a sample and a saturated phase of the flywheel
    holds more steps of one length than a block (summed by columns); at irregular times
    the steps have many lengths (runs summed step by step). The observers at every
    sample against Dormand-Prince throughout at rtol 1e-11 (the integrals to 1e-7 of
    their largest value; the peaks at the end, to 1e-7). At 1 kHz, at samples in
    several blocks of saturated phases, equal to the observed values of the run that
    ends there (its steps are the same: 1e-12; at irregular times a sample can fall in
    an adaptive step, whose peaks a sample reads as they were at the step's start)."""
    sys = _car()
    T = 1.0
    ex = sine(0.05, 5.0)
    if grid == "1 kHz":
        times = np.arange(1001) / 1000.0
    else:
        times = np.r_[np.sort(np.random.default_rng(5).uniform(0.0, T, 700)), T]
    res = sys.simulate(ex, T, times=times, rtol=1e-8)
    assert res.stats["exact_steps"] > 2 * X_BLOCK
    a = _observed(res)
    ref = sys.simulate(ex, T, times=times, method="adaptive", rtol=1e-11)
    assert ref.stats.get("exact_steps", 0) == 0
    b = _observed(ref)
    # the integrals at every sample; the peaks at the end (a sample inside an adaptive
    # step holds the peak as it was at the step's start)
    assert np.all(np.abs(a[:, :3] - b[:, :3]).max(axis=0) <= 1e-7 * np.abs(b[:, :3]).max(axis=0))
    assert np.all(np.abs(a[-1, 3:] - b[-1, 3:]) <= 1e-7 * np.abs(b[-1, 3:]))
    if grid != "1 kHz":
        return
    n = times.size
    for k in (90, n // 3, n // 2 + 7, (3 * n) // 4, n - 1):  # samples in saturated phases
        end = sys.simulate(ex, times[k], times=times[: k + 1], rtol=1e-8)
        assert a[k].tolist() == pytest.approx([end.observed[o] for o in OBS], rel=1e-12, abs=0)
