"""The derivatives of the core car's state space in its design values
(vehicles.design.state_space_derivatives), which the exact H2 gradients of the vehicle
design use.

Oracle: central differences of the core car's own state space with Richardson's
extrapolation (independent of the rank-one form the derivatives rely on), on plain
struts (a stiffness and a damping enter linearly, an inertance through the mass
matrix; an inertance at 0, where the corner has no inerter, in the value itself) and on
network struts with internal nodes (``k | (c - b)``, ``k | c | (k2 - b)``), for a half
and a full car (both corners of an axle)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from inerterlab.vehicles import NetworkStrut, example_vehicle_path, linear_vehicle, load_vehicle
from inerterlab.vehicles.design import (
    _blocks,
    design_parameters,
    state_space_derivatives,
    vehicle_with,
)

FULL = load_vehicle(example_vehicle_path())


def _networks(p):
    front = NetworkStrut("k | (c - b)", {"k": 28e3, "c": 2200.0, "b": 150.0})
    rear = NetworkStrut("k | c | (k2 - b)", {"k": 20e3, "c": 1800.0, "k2": 15e3, "b": 90.0})
    return dataclasses.replace(p, front=dataclasses.replace(p.front, strut=front),
                               rear=dataclasses.replace(p.rear, strut=rear))  # fmt: skip


CASES = [
    ("full struts", vehicle_with(FULL, front_inertance=0.0, rear_inertance=40.0)),
    ("half struts", vehicle_with(FULL.half_car(), rear_inertance=40.0)),
    ("full networks", _networks(FULL)),
]


def _value(p, name):
    axle, _, field = name.partition("_")
    strut = getattr(p, axle).strut
    return float(strut.parameters[field] if hasattr(strut, "parameters") else getattr(strut, field))


def _difference(p, n, x0):
    """d state space / d value of ``n`` at ``x0`` by Richardson's extrapolation of
    central differences (one-sided of second order at 0)."""
    h = 1e-3 * max(x0, 50.0)

    def ss(dx):
        return _blocks(linear_vehicle(vehicle_with(p, **{n: x0 + dx}))._ss)

    def fd(k):
        if x0 == 0.0:  # no inerter below 0
            return [(-3 * a + 4 * b - c) / (2 * k * h)
                    for a, b, c in zip(ss(0.0), ss(k * h), ss(2 * k * h), strict=True)]  # fmt: skip
        return [(a - b) / (2 * k * h) for a, b in zip(ss(k * h), ss(-k * h), strict=True)]

    return [(4 * a - b) / 3 for a, b in zip(fd(0.5), fd(1.0), strict=True)]


@pytest.mark.parametrize(("label", "p"), CASES, ids=[c[0] for c in CASES])
def test_state_space_derivatives_equal_central_differences(label, p):
    names = list(design_parameters(p))
    veh = linear_vehicle(p)
    exact = state_space_derivatives(p, veh, names, log=False)
    logged = state_space_derivatives(p, veh, names, log=True)
    for n, d, dl in zip(names, exact, logged, strict=True):
        x0 = _value(p, n)
        ref = _difference(p, n, x0)
        scale = max(float(np.abs(r).max(initial=0.0)) for r in ref)
        assert scale > 0.0, n
        err = max(float(np.abs(a - r).max(initial=0.0)) for a, r in zip(_blocks(d), ref, strict=True))
        assert err <= 1e-8 * scale, (label, n, err / scale)
        for a, b in zip(_blocks(dl), _blocks(d), strict=True):
            np.testing.assert_allclose(a, x0 * b, rtol=1e-15, atol=0.0)
