"""Exact gradients of the vehicle design's H2 objective (adjoint Lyapunov equations, the
state space's derivatives by complex steps) against central differences."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from inerterlab.design.vehicle import (
    axle_stiffness,
    linear_objective,
    linear_objective_gradient,
    vehicle_car,
)
from inerterlab.h2 import variance_gradient
from inerterlab.vehicles import example_vehicle_path

TEXT = example_vehicle_path().read_text()
SPEED = 25.0


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


@pytest.mark.parametrize("delay", [None, (0.3, [0, 1], [2, 3])])
def test_variance_gradient_is_the_derivative(delay):
    """dJ along a random direction of (A, B, c) equals the central difference of J, for
    the plain variance and with a delayed second pair of inputs (the wheelbase)."""
    rng = np.random.default_rng(1)
    n = 6
    A = rng.normal(size=(n, n)) - 4.0 * np.eye(n)
    B, c = rng.normal(size=(n, 4)), rng.normal(size=n)
    J, gA, gB, gc = variance_gradient(A, B, c, delay=delay)
    assert J == pytest.approx(variance_gradient(A, B, c, delay=delay, gradient=False)[0], rel=1e-12)
    dA, dB, dc = rng.normal(size=A.shape), rng.normal(size=B.shape), rng.normal(size=n)

    def at(t):
        return variance_gradient(A + t * dA, B + t * dB, c + t * dc, delay=delay, gradient=False)[0]

    h = 1e-5
    fd = (at(h) - at(-h)) / (2 * h)
    exact = np.sum(gA * dA) + np.sum(gB * dB) + gc @ dc
    assert exact == pytest.approx(fd, rel=1e-6)


def _values(car, network, base):
    ks = axle_stiffness(car)
    values = {f"{a}_k": ks[a] for a in ("front", "rear")}
    for a, f in (("front", 1.0), ("rear", 1.3)):
        values.update({f"{a}_{n}": v * f for n, v in base.items()})
    return values


@pytest.mark.parametrize(
    ("model", "network", "base", "objective"),
    [
        ("half", "k | (b - (k1 | c))", {"b": 150.0, "k1": 2e4, "c": 2500.0}, "seat_wk"),
        ("file", "k | (c - b)", {"c": 3000.0, "b": 200.0}, "body_acc"),
        ("file", "k | c | b", {"c": 2000.0, "b": 60.0}, "body_acc_wk"),
    ],
)
def test_vehicle_objective_gradient_equals_central_differences(model, network, base, objective):
    """The design's objective (RMS [m/s^2], wheelbase delay, Wk states) and its exact
    derivatives in the logarithms of the per-axle values against central differences
    (Richardson-extrapolated, steps 2e-3 and 4e-3: the Lyapunov norm's rounding of about
    1e-10 forbids small steps): 1e-6 of the gradient's largest entry."""
    car = vehicle_car(TEXT, model)
    values = _values(car, network, base)
    names = [n for n in values if not n.endswith("_k")]
    v, g = linear_objective_gradient(car, network, values, objective, "C", SPEED, names)
    assert v == pytest.approx(linear_objective(car, network, values, objective, "C", SPEED), rel=1e-10)

    def fd(n, h):
        up = linear_objective(car, network, {**values, n: values[n] * math.exp(h)}, objective, "C", SPEED)
        dn = linear_objective(car, network, {**values, n: values[n] * math.exp(-h)}, objective, "C", SPEED)
        return (up - dn) / (2 * h)

    ref = np.array([(4 * fd(n, 2e-3) - fd(n, 4e-3)) / 3 for n in names])
    assert np.max(np.abs(g - ref)) <= 1e-6 * np.max(np.abs(ref)), (g, ref)


def test_strut_vehicle_gradient_in_the_values():
    """``vehicle optimize``'s route: a vehicle file of plain struts, the derivatives in
    the values themselves (not their logarithms), the inertance at 0 included."""
    from inerterlab.vehicles import load_vehicle
    from inerterlab.vehicles.design import h2_metric_gradient, h2_metrics, vehicle_with

    base = vehicle_with(load_vehicle(example_vehicle_path()), front_inertance=0.0, rear_inertance=40.0)
    names = ["front_damping", "rear_stiffness", "front_inertance", "rear_inertance"]
    v, g = h2_metric_gradient(base, "seat_wk", names, "C", SPEED, log=False)
    assert v == pytest.approx(h2_metrics(base, "C", SPEED, ["seat_wk"])["seat_wk"], rel=1e-10)
    x0 = {"front_damping": base.front.strut.damping, "rear_stiffness": base.rear.strut.stiffness,
          "front_inertance": 0.0, "rear_inertance": 40.0}

    def at(n, d):
        return h2_metrics(vehicle_with(base, **{n: x0[n] + d}), "C", SPEED, ["seat_wk"])["seat_wk"]

    for n, gi in zip(names, g, strict=True):
        h = 2e-3 * max(x0[n], 50.0)
        if n == "front_inertance":  # one-sided at 0: second-order forward difference
            ref = (-3 * at(n, 0.0) + 4 * at(n, h) - at(n, 2 * h)) / (2 * h)
            assert gi == pytest.approx(ref, rel=1e-4)
        else:
            ref = (4 * (at(n, h) - at(n, -h)) / (2 * h) - (at(n, 2 * h) - at(n, -2 * h)) / (4 * h)) / 3
            assert gi == pytest.approx(ref, rel=1e-6, abs=1e-6 * np.max(np.abs(g)))
