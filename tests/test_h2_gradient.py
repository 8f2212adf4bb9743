"""Exact gradient of the quarter car's Wk-weighted H2 norm (``body_acc_wk``: the car's
companion form cascaded with the ISO 2631-1 Wk filter, adjoint Lyapunov equations)
against fourth-order central differences of the compiled value, in the polynomial
coefficients and in the logarithms of a network's parameters, and the optimiser's use
of it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from inerterlab import network_design as nd
from inerterlab.h2 import h2_rational_filtered, h2_rational_filtered_gradient
from inerterlab.suspension.network_linear import MAXC, network_quarter_car

THESIS = {"sprung_mass": 370.0, "unsprung_mass": 25.0, "tyre_stiffness": 120e3,
          "tyre_damping": 1300.0}  # fmt: skip


def _d4(f, x, h):
    """Fourth-order central difference of f at x (truncation ~h^4)."""
    return (-f(x + 2 * h) + 8 * f(x + h) - 8 * f(x - h) + f(x - 2 * h)) / (12 * h)


def _polys(roots, num, lead=1.0):
    """Rows Delta (from its roots, times ``lead``) and the row ``num`` (ascending)."""
    den = np.real(np.poly(roots))[::-1] * lead
    n = len(den) - 1
    p = np.zeros((2, MAXC + 1))
    p[0, : n + 1] = den
    p[1, : len(num)] = num
    return p, n


@pytest.mark.parametrize(
    "roots, num",
    [
        # a quarter car's two modes (1.3 Hz, 11 Hz) and a network's real pole
        ([-1.5 + 8j, -1.5 - 8j, -9 + 70j, -9 - 70j, -40.0], [0.0, 3e5, 2e4, 40.0]),
        # with a feed-through: the row of Delta's degree (the weighted norm stays finite)
        ([-2 + 7j, -2 - 7j, -15 + 60j, -15 - 60j], [0.0, 1e5, 5e3, 30.0, 0.4]),
    ],
)
def test_coefficient_gradient_is_the_derivative(roots, num):
    fA, fB, fC, _ = nd._wk()
    p, n = _polys(roots, num, lead=3.7)
    g = np.zeros((2, n + 1))
    J = h2_rational_filtered_gradient(p, n, 1, fA, fB, fC, g)
    assert J == pytest.approx(h2_rational_filtered(p, n, 1, fA, fB, fC), rel=1e-11)
    # each coefficient's natural size: Delta_n w0^(n - i), w0 = (Delta_0 / Delta_n)^(1/n)
    w0 = (p[0, 0] / p[0, n]) ** (1.0 / n)
    size = p[0, n] * w0 ** (n - np.arange(n + 1.0))
    exact, fd = [], []
    for row in (0, 1):
        for i in range(len(num) if row else n + 1):

            def f(x, row=row, i=i):
                q = p.copy()
                q[row, i] = x
                return h2_rational_filtered(q, n, 1, fA, fB, fC)

            exact.append(g[row, i] * size[i])
            fd.append(_d4(f, p[row, i], 1e-3 * size[i]) * size[i])
    exact, fd = np.array(exact), np.array(fd)
    # to 1e-7 of each derivative, or of the largest where one is near zero
    assert np.all(np.abs(exact - fd) <= 1e-7 * np.maximum(np.abs(fd), 1e-3 * np.abs(fd).max()))


@pytest.mark.parametrize(
    "network, params, car",
    [
        ("k | c", {"k": 9e4, "c": 3e3}, THESIS),
        ("k | (c - b)", {"k": 9e4, "c": 4e3, "b": 250.0}, THESIS),
        # an inerter across the suspension with a damped tyre: body_acc has a
        # feed-through (infinite), body_acc_wk is finite
        ("k | c | b", {"k": 9e4, "c": 3e3, "b": 150.0}, THESIS),
        ("k | (b - (k1 | c))", {"k": 3e4, "k1": 2e4, "c": 2e3, "b": 120.0},
         {"sprung_mass": 420.0, "unsprung_mass": 45.0, "tyre_stiffness": 250e3,
          "tyre_damping": 0.0}),
        ("k | c | (k1 - b) | (c1 - k2)",
         {"k": 5e4, "c": 2e3, "k1": 3e4, "b": 80.0, "c1": 900.0, "k2": 4e4}, THESIS),
    ],
)  # fmt: skip
def test_body_acc_wk_gradient_in_the_parameters(network, params, car):
    """d(body_acc_wk^2)/d log(theta) of :func:`network_design.gradient` equals the
    fourth-order central difference of the compiled value to 1e-7 relative."""
    q = network_quarter_car(network, **car)
    val, g = nd.gradient(q, params, "body_acc_wk")
    assert math.sqrt(val) == pytest.approx(
        nd.evaluate(network, params, ["body_acc_wk"], **car)["body_acc_wk"], rel=1e-12
    )
    gmax = max(abs(v) for v in g.values())
    for name in params:

        def f(u, name=name):
            p = dict(params)
            p[name] = params[name] * math.exp(u)
            return nd.evaluate(network, p, ["body_acc_wk"], **car)["body_acc_wk"] ** 2

        fd = _d4(f, 0.0, 2e-3)
        assert g[name] == pytest.approx(fd, rel=1e-7, abs=1e-9 * gmax), name


def test_gradient_refuses_what_it_has_not():
    q = network_quarter_car("k | c", **THESIS)
    with pytest.raises(nd.NetworkError, match="peak:body_acc"):
        nd.gradient(q, {"k": 9e4, "c": 3e3}, "peak:body_acc")


def test_optimiser_uses_the_exact_gradient():
    """The body_acc_wk polish counts one evaluation per gradient (exact) and ends at a
    point where the projected gradient meets the exact gradients' tolerance, with the
    same optimum from two seeds."""
    a = nd.optimize_network("k | (c - b)", "body_acc_wk", fixed={"k": 9e4}, compare=False,
                            seed=0, **THESIS)  # fmt: skip
    b = nd.optimize_network("k | (c - b)", "body_acc_wk", fixed={"k": 9e4}, compare=False,
                            seed=7, **THESIS)  # fmt: skip
    assert a.converged and b.converged
    assert a.objective == pytest.approx(b.objective, rel=1e-9)
    pb = nd._Problem("k | (c - b)", "body_acc_wk", {"k": 9e4}, {}, {}, {}, THESIS)
    u = np.log([a.parameters[n] for n in pb.free])
    pb.neval = 0
    v, g = pb.f_and_g(u)
    assert pb.neval == 1
    assert math.sqrt(v) == pytest.approx(a.objective, rel=1e-12)
    assert nd._kkt(pb, u, v)
