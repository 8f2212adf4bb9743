"""The body resonance of a linearised quarter car (a propagated ride metric): the peak of
|X3 / X1| found on one batched frequency grid and refined, against an independent
search of the transfer function written out from the matrices."""

import importlib
import math

import numpy as np
import pytest

from inerterlab import quarter_car

propagate = importlib.import_module("inerterlab.identify.propagate")


def _gain(lin, f):
    """|1 + s c^T (s I - A)^-1 B| at one frequency f [Hz], one dense solve (c picks the
    body's displacement over the road's, X3 - X1: the tyre's deflection and the
    suspension's)."""
    n = lin.A.shape[0]
    c = lin.C["tyre_deflection"] + lin.C["suspension_deflection"]
    s = 2j * math.pi * f
    return abs(1.0 + s * (c @ np.linalg.solve(s * np.eye(n) - lin.A, np.asarray(lin.B, float))))


@pytest.mark.parametrize(("damping", "stiffness"), [(1500.0, 30e3), (5000.0, 90e3), (9000.0, 30e3)])
def test_body_resonance_is_the_peak_of_the_transmissibility(damping, stiffness):
    lin = propagate.linearised_car(quarter_car("traditional", damping=damping, stiffness=stiffness))
    f = propagate._body_resonance(lin)
    assert 0.2 < f < 5.0
    # an independent search: golden sections on the written-out gain, to 1e-9 Hz
    a, b = f - 0.05, f + 0.05
    g = (math.sqrt(5.0) - 1.0) / 2.0
    while b - a > 1e-9:
        x1, x2 = b - g * (b - a), a + g * (b - a)
        if _gain(lin, x1) > _gain(lin, x2):
            b = x2
        else:
            a = x1
    peak = 0.5 * (a + b)
    # the refinement's tolerance is 1e-7 Hz; the peak is flat to second order there
    assert f == pytest.approx(peak, abs=2e-6)
    assert _gain(lin, f) == pytest.approx(_gain(lin, peak), rel=1e-9)
    # a maximum: higher than a step either side
    assert _gain(lin, f) > _gain(lin, f - 0.01) and _gain(lin, f) > _gain(lin, f + 0.01)
